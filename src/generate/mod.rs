//! Canonical model generators behind `weft-weave`. Each returns a validated [`Model`]
//! with named node sets, ready to simulate.

pub mod block;
pub mod bullet;
pub mod clay;
pub mod cylinder;
pub mod failure;
pub mod grid;
pub mod layers;
pub mod metals;
pub mod pulse;
pub mod reduced_failure;
pub mod rod;
pub mod square;
pub mod surround;
pub mod taylor;
pub mod weave;
pub mod woven;
pub mod woven_reduced;
pub mod zones;
