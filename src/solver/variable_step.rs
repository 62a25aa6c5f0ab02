//! The variable step (`Analysis::variable_time_step`): the step follows the solids as they
//! are crushed (docs/theory.md, "Solid elements").

use super::{stable, Solver};
use crate::error::{Result, WeftError};

/// The smallest variable step, as a fraction of the first, before a run stops.
const MIN_STEP_FRACTION: f64 = 1e-2;

impl Solver {
    /// The variable step (`Analysis::variable_time_step`): the step lowered, never
    /// raised, to the hexahedra's current stable step times the margin the first step
    /// had (dt/dt_stable: the safety factor, and the contact guard); a step fallen below
    /// [`MIN_STEP_FRACTION`] of the first stops the run, naming the element.
    pub(super) fn follow_solids(
        &mut self,
        k: &mut stable::StiffeningCheck,
        dt_step: f64,
    ) -> Result<f64> {
        let Some((dt_now, node, most)) = self.nodal_bound().variable_step(k) else {
            return Ok(dt_step);
        };
        let margin = self.stable.dt / self.stable.dt_stable;
        let dt = dt_step.min(margin * dt_now);
        if dt < MIN_STEP_FRACTION * self.stable.dt {
            let what = match most {
                Some(w) => w.describe(self.analysis.dt_safety).0,
                None => "its elements".to_string(),
            };
            return Err(WeftError::Numerical {
                what: format!(
                    "the variable step fell to {dt:.4e} s, below {MIN_STEP_FRACTION} of the first {:.4e} s, at node `{}`: {what}",
                    self.stable.dt, self.node_id[node]
                ),
                step: self.state.step,
                time: self.state.t,
                hint: Some("an element this crushed is near inversion: a finer mesh at the impact face, a stiffer hourglass or erosion (the part's erosion_plastic_strain) lets the run go on".into()),
            });
        }
        self.stable.dt_min = self.stable.dt_min.min(dt);
        Ok(dt)
    }
}
