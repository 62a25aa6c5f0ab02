//! Ballistic limits from impact runs: the Lambert–Jonas fit of residual against striking
//! velocity ([`lambert_jonas`]) and the probability of perforation ([`probability`]).
//! The physics and the practice behind them: docs/theory.md, "Failure, perforation and
//! the ballistic limit".

pub mod lambert_jonas;
pub mod probability;
