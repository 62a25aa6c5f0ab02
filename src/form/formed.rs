//! The formed model (step 4 of [`crate::form`]): the model to form with the formed
//! positions as its initial displacement.

use crate::error::Result;
use crate::model::contacts::InitialPenetration;
use crate::model::Model;
use crate::solver::vec3::sub;

use super::membrane::PreStress;

/// The formed model and how far the fabric's top rose.
pub struct Formed {
    pub model: Model,
    /// How far the fabric's top rose [m] (the projectile is moved up by as much).
    pub top_rise: f64,
}

/// The formed model of `m` at the formed positions `x`: the reference geometry
/// unchanged, the formed positions as the nodes' initial displacement u₀ (so strains,
/// contact overlaps and hourglass forces are exactly those of the equilibrium), the
/// yarn ends held again where they came to rest (as `m` holds them), the membrane
/// pre-stressed by `pre` (tied ends), contacts `keep` with their friction back, the
/// projectile moved up by as much as the fabric's top rose.
pub fn formed_model(m: &Model, x: &[[f64; 3]], pre: Option<&PreStress>) -> Result<Formed> {
    let mut out = m.clone();
    out.initial_displacement = x.iter().zip(&m.coords).map(|(a, b)| sub(a, b)).collect();
    if let Some(pre) = pre {
        pre.apply(&mut out);
    }
    for c in &mut out.contacts {
        c.initial_penetration = InitialPenetration::Keep;
    }
    let top =
        |xs: &[[f64; 3]]| -> f64 { xs.iter().map(|x| x[2]).fold(f64::NEG_INFINITY, f64::max) };
    let rise = (top(x) - top(&m.coords)).max(0.0);
    for pr in &mut out.projectiles {
        pr.tip[2] += rise;
    }
    out.validate()?;
    Ok(Formed {
        model: out,
        top_rise: rise,
    })
}
