//! Contact: rigid projectiles against nodes and membrane faces ([`projectile`]).
pub mod projectile;

pub use projectile::*;
