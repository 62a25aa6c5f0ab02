//! Contact: rigid projectiles against nodes and membrane faces ([`projectile`]), and
//! general node-to-surface contact with friction between the parts of a model
//! ([`surface`], defined by `contacts.parquet`).
pub mod projectile;
pub mod staleness;
pub mod surface;

pub use projectile::*;
pub use surface::{ContactReport, SurfaceContact};
