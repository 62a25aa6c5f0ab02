//! What the yarn failure of both woven generators shares (`woven`'s bands and chains,
//! `woven-reduced`'s rods; docs/theory.md, "Failure, perforation and the ballistic
//! limit"): the default delay's element transits, the nose's contact damping once the
//! yarns can fail, and the checks of the two flags that override them.

use crate::error::{Result, WeftError};

/// Element transits in the default failure delay: a struck yarn's first elements
/// overshoot Smith's strain by about 40 % for about ten steps whatever the element size;
/// with this delay (and the nose's contact damping) a struck chain and band break within
/// 1 % and 2 % of Smith's critical velocity (`tests/failure.rs`). The reduced model's
/// rods take the same rule for their own length.
pub const DELAY_TRANSITS: f64 = 10.0;

/// The nose's contact damping (fraction of critical) when the yarns can fail: the nodes
/// under a nose otherwise ring on their penalty springs at ±30 % of Smith's strain
/// (measured), which breaks a struck yarn below its critical velocity.
pub const FAILURE_CONTACT_DAMPING: f64 = 0.5;

/// The projectile's contact damping: the one `given`, or [`FAILURE_CONTACT_DAMPING`]
/// when the yarns can fail (a failure `strain` > 0), 0 otherwise (as before failure
/// existed).
pub fn contact_damping(given: Option<f64>, strain: f64) -> f64 {
    given.unwrap_or(if strain > 0.0 {
        FAILURE_CONTACT_DAMPING
    } else {
        0.0
    })
}

/// A failure delay ≥ 0 in s and a contact damping 0 ≤ ζ ≤ 1, where given
/// (`--failure-delay`, `--projectile-contact-damping`).
pub fn check_delay_and_damping(delay: Option<f64>, damping: Option<f64>) -> Result<()> {
    if let Some(d) = delay {
        if !(d.is_finite() && d >= 0.0) {
            return Err(
                WeftError::input(format!("--failure-delay = `{d}`")).expected("a delay ≥ 0 in s")
            );
        }
    }
    if let Some(z) = damping {
        if !(0.0..=1.0).contains(&z) {
            return Err(
                WeftError::input(format!("--projectile-contact-damping = `{z}`"))
                    .expected("a fraction 0 ≤ ζ ≤ 1 of critical damping"),
            );
        }
    }
    Ok(())
}
