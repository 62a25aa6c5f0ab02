//! The time step of a model loaded by a force pulse: shortened, where the stable step
//! would sample the pulse too coarsely, so that it resolves the pulse (the square models,
//! the combined zones).

use crate::error::Result;
use crate::model::{Model, TimeLaw};

/// Steps per load pulse: the stable step of the coarse square models would sample the
/// paper's pulse (T_F = T/2 spans N/2 cells) with about five steps, too few for the
/// response and for the energy account (the trapezoidal work is then off by
/// ~(π/5)²/12 ≈ 3 %).
pub const STEPS_PER_PULSE: f64 = 40.0;

/// Choose a time step that resolves the pulse when the stable step does not.
pub(crate) fn resolve_pulse(m: &mut Model) -> Result<()> {
    let t_f = m.loads.iter().find_map(|l| match l.law {
        TimeLaw::SinePulse { duration, .. } => Some(duration),
        _ => None,
    });
    if let Some(t_f) = t_f {
        let stable = crate::solver::Solver::new(m)?.time_step().clone();
        let dt = t_f / STEPS_PER_PULSE;
        if dt < stable.dt {
            m.analysis.time_step = Some(dt);
        }
    }
    Ok(())
}
