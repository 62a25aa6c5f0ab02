//! Contact: rigid projectiles against nodes and membrane faces ([`projectile`]), and
//! general node-to-surface contact with friction between the parts of a model
//! ([`surface`], defined by `contacts.parquet`).
pub mod closest;
pub mod projectile;
pub mod staleness;
pub mod surface;

pub use projectile::*;
pub use surface::{ContactReport, SurfaceContact};

/// A small deterministic generator (SplitMix64) for the contact tests, so that they need
/// no crate: uniform in [0, 1).
#[cfg(test)]
fn uniform(state: &mut u64) -> f64 {
    *state = state.wrapping_add(0x9E37_79B9_7F4A_7C15);
    let mut z = *state;
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
}

/// The rectangle 1 × `width` in the xy plane (nodes counter-clockwise from the origin),
/// each coordinate moved by up to ±`amp`/2 at random: a warped quad (for the contact
/// tests).
#[cfg(test)]
fn jittered_rectangle(width: f64, amp: f64, st: &mut u64) -> [[f64; 3]; 4] {
    let mut x = [
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [1.0, width, 0.0],
        [0.0, width, 0.0],
    ];
    for a in &mut x {
        for c in a.iter_mut() {
            *c += amp * (uniform(st) - 0.5);
        }
    }
    x
}
