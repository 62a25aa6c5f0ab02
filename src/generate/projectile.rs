//! What the projectile of both woven generators shares: the check of its striking speed
//! (`--projectile-velocity`), one wording wherever a speed is given.

use crate::error::{Result, WeftError};

/// A striking speed `v` [m/s], given by `flag`, must be finite and ≥ 0: the projectile
/// flies along its axis, towards the fabric, so the speed carries no sign.
pub fn check_striking_speed(flag: &str, v: f64) -> Result<()> {
    if v.is_finite() && v >= 0.0 {
        return Ok(());
    }
    Err(WeftError::input(format!("{flag} = `{v}`"))
        .expected("a finite striking speed ≥ 0 in m/s")
        .hint("give the speed without a sign: the projectile flies along its axis, towards the fabric (0: at rest)"))
}
