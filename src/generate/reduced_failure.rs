//! Failure of the reduced woven model (`woven-reduced --failure-strain`): its rods fail by
//! the yarn-level patch's law (an axial strain compared after a delay; the shared pieces
//! in [`super::failure`]), its membrane surround may fail along its fibre directions
//! ([`super::surround::fail_membranes`]), and its elements carry the fabric's
//! `layer` and `yarn` tags, so that a run is watched and judged as a yarn-level patch's
//! (per-layer energies, broken yarns, the projectile's outcome; docs/theory.md, "Failure,
//! perforation and the ballistic limit").

use serde::Serialize;

use crate::error::{Result, WeftError};
use crate::generate::failure::{check_delay_and_damping, contact_damping, DELAY_TRANSITS};
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

    /// The projectile's contact damping: the one given, or 0.5 when the rods can fail
    /// ([`contact_damping`]).
    pub fn contact_damping(&self) -> f64 {
        contact_damping(self.contact_damping, self.strain)
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
        check_delay_and_damping(self.delay, self.contact_damping)
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
