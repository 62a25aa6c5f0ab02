//! Failure of the reduced woven model (`woven-reduced --failure-strain`): its rods fail by
//! the yarn-level patch's law (an axial strain compared after a delay), its membrane
//! surround may fail along its fibre directions, and its elements carry the fabric's
//! `layer` and `yarn` tags, so that a run is watched and judged as a yarn-level patch's
//! (per-layer energies, broken yarns, the projectile's outcome; docs/theory.md, "Failure,
//! perforation and the ballistic limit").

use serde::Serialize;

use crate::error::{Result, WeftError};
use crate::generate::woven::{DELAY_TRANSITS, FAILURE_CONTACT_DAMPING};
use crate::model::{ElementKind, Model};

/// How the reduced model's rods fail.
#[derive(Debug, Clone, Default, Serialize)]
pub struct ReducedFailure {
    /// Failure strain ε_f of the rods, their engineering axial strain (0: they never
    /// fail, as in the paper's §5). A reduced rod spans a whole crossing spacing and is
    /// straight: its strain is not the yarn's, and the strain that matches the
    /// yarn-level reference's perforation is a parameter to fit (`weft-fit --objective
    /// projectile`).
    pub strain: f64,
    /// Delay τ of the failure [s] (None: ten transits of a rod, p/√(E/ρ) each, the
    /// yarn-level patch's rule for its own elements).
    pub delay: Option<f64>,
    /// The projectile's contact damping ζ (None: 0.5 when the rods can fail, as the
    /// yarn-level patch's, else 0).
    pub contact_damping: Option<f64>,
}

impl ReducedFailure {
    /// The delay: the one given, or ten transits of a rod of length `spacing`.
    pub fn delay_for(&self, spacing: f64, modulus: f64, density: f64) -> f64 {
        self.delay
            .unwrap_or_else(|| DELAY_TRANSITS * spacing / (modulus / density).sqrt())
    }

    /// The projectile's contact damping: the one given, or 0.5 when the rods can fail.
    pub fn contact_damping(&self) -> f64 {
        self.contact_damping.unwrap_or(if self.strain > 0.0 {
            FAILURE_CONTACT_DAMPING
        } else {
            0.0
        })
    }

    /// A finite strain ≥ 0, a delay ≥ 0, a damping in [0, 1].
    pub fn check(&self) -> Result<()> {
        if !(self.strain >= 0.0 && self.strain.is_finite()) {
            return Err(
                WeftError::input(format!("--failure-strain = `{}`", self.strain)).expected(
                    "a failure strain ≥ 0 of the rods (0: no failure; the yarn's: 0.036)",
                ),
            );
        }
        if let Some(d) = self.delay {
            if !(d >= 0.0 && d.is_finite()) {
                return Err(WeftError::input(format!("--failure-delay = `{d}`"))
                    .expected("a delay ≥ 0 in s"));
            }
        }
        if let Some(z) = self.contact_damping {
            if !((0.0..=1.0).contains(&z)) {
                return Err(
                    WeftError::input(format!("--projectile-contact-damping = `{z}`"))
                        .expected("a fraction of critical damping in [0, 1]"),
                );
            }
        }
        Ok(())
    }
}

/// A membrane failure strain, if given, must be a strain > 0.
pub fn check_membrane_strain(strain: Option<f64>) -> Result<()> {
    match strain {
        Some(e) if !(e > 0.0 && e.is_finite()) => Err(WeftError::input(format!(
            "--membrane-failure-strain = `{e}`"
        ))
        .expected("a failure strain > 0 of the membrane's fibre directions (the yarns': 0.036)")
        .hint("leave it out for a membrane that cannot fail")),
        _ => Ok(()),
    }
}

/// Every membrane quad part of `m` (the surround: parts named `coarse_membrane…`) fails
/// at `strain` along either fibre direction, after the failure `delay` [s], and is then
/// removed (OpenRadioss' /FAIL/FABRIC with NDIR = 1). Keeping an element whose one
/// direction has failed (NDIR = 2) leaves a quad with no stiffness along that direction,
/// which the nose then stretches without bound (a Green strain of 9 within 110 µs,
/// measured), and its stable step with it.
pub fn fail_membranes(m: &mut Model, strain: f64, delay: f64) {
    for part in m
        .parts
        .iter_mut()
        .filter(|q| q.kind == ElementKind::Quad && q.name.starts_with("coarse_membrane"))
    {
        part.props.failure_strain = Some(strain);
        part.props.failure_strain_2 = Some(strain);
        part.props.failure_delay = Some(delay);
    }
}

/// The rod parts `rods` fail at `strain` after `delay`.
pub fn fail_rods(m: &mut Model, rods: &[usize], strain: f64, delay: f64) {
    for &r in rods {
        let props = &mut m.parts[r].props;
        props.failure_strain = Some(strain);
        props.failure_delay = Some(delay);
    }
}

/// Tags the fabric's one layer: every truss and membrane quad in layer 1; each truss its
/// yarn (`yarn` column), from `yarn_of` (its index within its part, from 1).
pub fn tag_layer(m: &mut Model, yarn_of: &[i64]) {
    if let Some(b) = m.elements.get_mut(&ElementKind::Truss) {
        b.layer = vec![Some(1); b.len()];
        b.yarn = yarn_of.iter().map(|&y| Some(y)).collect();
    }
    if let Some(b) = m.elements.get_mut(&ElementKind::Quad) {
        b.layer = vec![Some(1); b.len()];
    }
}
