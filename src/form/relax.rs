//! Relaxing the pulled model (step 2 of [`crate::form`]): dynamic relaxation with local
//! damping ([`crate::solver::relax`]) and the check that it reached equilibrium.

use crate::error::{Result, WeftError};
use crate::model::Model;
use crate::solver::relax::{RelaxOptions, RelaxStats};
use crate::solver::Solver;

use super::params::Params;

/// A relaxation under way: the solver at its state, the options it ran with, and what
/// it did.
pub struct Relaxation {
    pub solver: Solver,
    pub options: RelaxOptions,
    pub stats: RelaxStats,
}

/// What the relaxation at the patch's start needs besides the parameters.
pub struct RelaxSetup {
    /// The largest pull on an end node [N].
    pub force_scale: f64,
    /// The largest yarn thickness [m] (the rest test's tolerance is a fraction of it).
    pub thickness: f64,
    /// Forming work credited to the start [J].
    pub credited: f64,
    /// Degrees of freedom held in the rest test: the pulled ends, as the formed model
    /// holds them.
    pub hold: Vec<(usize, u8)>,
    /// Test at rest first (a start already in equilibrium).
    pub probe_first: bool,
}

/// Relax the pulled model `mm` until the kinetic energy, the residual force and the rest
/// test pass, or the step budget is spent.
pub fn relax(
    mm: &Model,
    p: &Params,
    setup: RelaxSetup,
    progress: &mut dyn FnMut(&RelaxStats),
) -> Result<Relaxation> {
    let mut solver = Solver::new(mm)?;
    let options = RelaxOptions {
        work_offset: setup.credited,
        // In the rest test, the pulled ends are held as the formed model holds them.
        hold_in_rest_test: setup.hold,
        // A patch tiled from its formed cell is in equilibrium as it is (to the
        // contacts' discretisation): test it at rest first.
        probe_first: setup.probe_first,
        ..p.relax_options(solver.time_step().dt, setup.force_scale, setup.thickness)
    };
    let stats = solver.relax(&options, progress)?;
    Ok(Relaxation {
        solver,
        options,
        stats,
    })
}

/// The energy account of a relaxation that reached equilibrium.
#[derive(Debug, Clone, Copy)]
pub struct Equilibrium {
    /// The forming work W: the energy the relaxation removed, the kinetic energy left
    /// and the work credited to the start [J].
    pub work: f64,
    /// K/W (0 without work).
    pub kinetic_over_work: f64,
}

/// The relaxation `st`'s energy account, or an error naming what did not converge
/// (`thickness`: the largest yarn thickness [m]).
pub fn equilibrium(
    m: &Model,
    p: &Params,
    st: &RelaxStats,
    credited: f64,
    thickness: f64,
) -> Result<Equilibrium> {
    let dt = st.dt;
    let work = st.removed + st.kinetic + credited;
    let ratio = if work > 0.0 { st.kinetic / work } else { 0.0 };
    if st.converged {
        return Ok(Equilibrium {
            work,
            kinetic_over_work: ratio,
        });
    }
    let creep_msg = if st.creep.is_finite() {
        format!(
            "; left alone at rest, node `{}` moved {:.3e} m within {:.1e} s (asked ≤ {:.3e} m)",
            m.node_id.get(st.creep_node).copied().unwrap_or(-1),
            st.creep,
            p.creep_time,
            p.creep_tolerance * thickness
        )
    } else {
        format!(
            "; the kinetic energy and residual force tests never passed together, so the rest test (a free run of {:.1e} s) never ran",
            p.creep_time
        )
    };
    Err(WeftError::input(format!(
        "forming did not reach equilibrium in {} steps ({:.3e} s): kinetic energy {:.2e} of the forming work (asked ≤ {:.1e}), largest residual force {:.3e} N on node `{}` against contact forces up to {:.3e} N (asked ≤ {:.1e} of them){creep_msg}",
        st.steps, st.steps as f64 * dt, ratio, p.kinetic_tolerance, st.residual, m.node_id[st.residual_node], st.contact_force, p.force_tolerance
    ))
    .hint("raise --max-steps, or loosen --kinetic-tolerance / --force-tolerance"))
}
