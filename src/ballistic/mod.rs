//! Ballistic limits from impact runs: the runs gathered and grouped ([`runs`]), the
//! Lambert–Jonas fit of residual against striking velocity ([`lambert_jonas`]), the
//! probability of perforation ([`probability`]), the limit of each group and its tables
//! ([`limit`]), a search that runs the impacts itself, bracketing the limit
//! ([`search`]), the failed zone of impacts ([`zone`]), the backing clay's drop calibration
//! ([`clay`]) and the armour test's verdict on a shot on the clay ([`nij`]).
//! The physics and the practice behind them: docs/theory.md, "Failure, perforation and
//! the ballistic limit".

pub mod clay;
pub mod lambert_jonas;
pub mod limit;
pub mod nij;
pub mod probability;
pub mod runs;
pub mod search;
pub mod zone;
