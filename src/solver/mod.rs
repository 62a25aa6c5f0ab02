//! The explicit solver: a physics operator (forces at a state), a time integrator
//! (central difference), an energy ledger and an output sampler, over the element
//! families of a model.
//!
//! Glossary: n step index; t_n time; x^n positions; v^{n−½} half-step velocities;
//! Δt^{n+½} = t_{n+1} − t_n; a^n = M⁻¹(f_ext^n + f_int^n); α mass-proportional damping
//! [1/s]; u = x − X displacement.
//!
//! Where things live:
//! - [`family`]: the element-family vocabulary; [`families`]: [`Families`], the list of
//!   families (one module each: [`truss`], [`link`], [`sliding_link`], [`point_mass`],
//!   [`membrane`] (triangles and quads), [`beam`]); [`rotations`]: the rotational nodes
//!   the beams create;
//! - [`operator`]: loads, element forces, contact and tie transfer → nodal forces;
//! - [`integrator`]: central difference for the nodes, the rotations and (through
//!   [`contact`]) the rigid projectiles;
//! - [`stable`]: the stable step (nodal Gershgorin bound) and mass scaling;
//! - [`ties`], [`contact`]: tied interfaces, projectile and surface contact;
//! - [`failure`]: the failure laws, and [`collapse`], the membranes' removal when their
//!   own step falls below the run's; [`erosion`]: what failures leave (the log, the
//!   contact surfaces' erosion) and the per-layer [`watch`] of an impact;
//! - [`energy`]: the energies and the ledger; [`output`]: the sampling onto the output
//!   grid and the sinks;
//! - [`statics`], [`relax`]: linear statics and dynamic relaxation on the same model;
//! - this module: setup ([`Solver::new`]) and the time loop ([`Solver::run`]), a short
//!   list of named steps.
//!
//! Phases of a step: loads (f_ext at t_n, external work) → element forces (per element,
//! in parallel chunks, into a per-element force buffer) → contact and ties → node
//! update (each node gathers its elements' forces in a fixed order, then advances).
//! Every sum runs in an order that does not depend on the thread count, and reductions
//! use fixed chunks summed in chunk order, so results are bit-identical for any number
//! of threads. Buffers are allocated once at setup; the step allocates nothing.

pub mod beam;
pub mod chain_strain;
pub mod collapse;
pub mod contact;
pub mod crater;
pub mod energy;
pub mod erosion;
pub mod failure;
pub mod families;
pub mod family;
mod health;
pub mod integrator;
pub mod link;
pub mod membrane;
pub mod operator;
pub mod output;
pub mod point_mass;
pub mod relax;
pub mod rotations;
mod setup;
pub mod sliding_link;
pub mod solid;
pub mod stable;
pub mod statics;
pub mod subcycle;
pub mod ties;
mod time_loop;
pub mod truss;
mod variable_step;
/// The small vector helpers, shared below the solver ([`crate::vec3`]).
pub use crate::vec3;
pub mod plies;
pub mod watch;

use std::time::Duration;

use crate::error::Result;
use crate::model::{ElementKind, Model};

use energy::Ledger;
pub use energy::{ElementEnergies, Energies, ENERGY_CHECK_AFTER};
pub use families::Families;
use family::ForceCtx;
pub use family::CHUNK;
use integrator::NodePartial;
pub use operator::{Operator, State};
pub use output::Sink;
pub use stable::{MassScaling, StableStep};
pub use ties::tie_weights;

/// Wall time per phase.
#[derive(Debug, Clone, Default)]
pub struct PhaseTimes {
    pub setup: Duration,
    pub loads: Duration,
    pub forces: Duration,
    pub update: Duration,
    pub output: Duration,
    /// Contact search and forces (part of `forces`).
    pub contact: Duration,
}

/// What a run did.
#[derive(Debug, Clone)]
pub struct RunStats {
    pub steps: u64,
    pub end_time: f64,
    pub times: PhaseTimes,
    pub threads: usize,
    pub max_balance_error_relative: f64,
    pub final_energies: Energies,
    pub elements: usize,
    pub nodes: usize,
}

impl RunStats {
    /// Element updates per second over the force and node-update phases.
    pub fn element_updates_per_second(&self) -> f64 {
        let s = (self.times.forces + self.times.update + self.times.loads).as_secs_f64();
        if s > 0.0 {
            self.steps as f64 * self.elements as f64 / s
        } else {
            0.0
        }
    }
}

/// The explicit solver: owns the state and scratch buffers of one model. Other stages
/// read it through its methods (the state, the operator's families and contacts, the
/// step and what controls it, the failures and the layers' watch), never its fields.
pub struct Solver {
    node_id: Vec<i64>,
    /// Reference positions X [m].
    x0: Vec<[f64; 3]>,
    /// Positions, velocities, rotations, time.
    state: State,
    /// Forces at a state.
    op: Operator,
    /// Lumped nodal masses (with mass scaling) [kg].
    mass: Vec<f64>,
    /// Physical model mass (without scaling) [kg].
    physical_mass: f64,
    inv_m: Vec<f64>,
    /// Bit d set when direction d is fixed.
    fixed: Vec<u8>,
    partials: Vec<NodePartial>,
    alpha: f64,
    /// Output nodes (indices).
    output_nodes: Vec<usize>,
    stable: StableStep,
    scaling: Option<MassScaling>,
    analysis: crate::model::Analysis,
    ledger: Ledger,
    /// Element failures and what they leave (empty when nothing can fail).
    failures: FailureLog,
    /// Layers and the projectile's outcome (see [`watch`]).
    watch: watch::Watch,
    /// The backing clay's crater, when the model has one ([`crater`]).
    crater: Option<crater::CraterWatch>,
    /// The last output time sent to the sink (NaN before the first): where the tables of
    /// a run that stopped end.
    sampled_to: f64,
    /// The slow elements' step, when the analysis subcycles and some are slow
    /// ([`subcycle`]).
    subcycle: Option<subcycle::Subcycle>,
}

/// What other stages read of a solver.
impl Solver {
    /// The nodes' ids, in the model's node order (every per-node slice is in that order).
    pub fn node_ids(&self) -> &[i64] {
        &self.node_id
    }
    /// Reference positions X [m]: where the run started (a formed model's displaced
    /// start), which displacements are measured from.
    pub fn reference_positions(&self) -> &[[f64; 3]] {
        &self.x0
    }
    /// The slow step of a subcycled run ([`subcycle`]): its ratio (now and first), the
    /// slow elements, the samples taken; `None` when nothing is subcycled.
    pub fn subcycle(&self) -> Option<&subcycle::Subcycle> {
        self.subcycle.as_ref()
    }
    /// Positions, velocities, rotations, time and step.
    pub fn state(&self) -> &State {
        &self.state
    }
    /// The state, to set before a run (initial conditions of a test or a fit).
    pub fn state_mut(&mut self) -> &mut State {
        &mut self.state
    }
    /// The physics operator: element families, ties, contacts, loads, forces.
    pub fn operator(&self) -> &Operator {
        &self.op
    }
    /// The operator, to drive its phases one by one (tests of a phase).
    pub fn operator_mut(&mut self) -> &mut Operator {
        &mut self.op
    }
    /// The element families.
    pub fn families(&self) -> &Families {
        &self.op.el
    }
    /// Lumped nodal masses, with mass scaling [kg].
    pub fn masses(&self) -> &[f64] {
        &self.mass
    }
    /// The model's mass without scaling [kg].
    pub fn physical_mass(&self) -> f64 {
        self.physical_mass
    }
    /// The output nodes (indices), in the order of the history table.
    pub fn output_nodes(&self) -> &[usize] {
        &self.output_nodes
    }
    /// The step in use, the stable estimate and what controls it.
    pub fn time_step(&self) -> &StableStep {
        &self.stable
    }
    /// What mass scaling added, when the analysis asked for it.
    pub fn mass_scaling(&self) -> Option<&MassScaling> {
        self.scaling.as_ref()
    }
    /// The analysis settings the solver runs with.
    pub fn analysis(&self) -> &crate::model::Analysis {
        &self.analysis
    }
    /// The analysis settings, to run on from where a run ended (a later end time,
    /// another output interval; the step stays as it was set).
    pub fn analysis_mut(&mut self) -> &mut crate::model::Analysis {
        &mut self.analysis
    }
    /// Element failures so far and what they leave.
    pub fn failure_log(&self) -> &FailureLog {
        &self.failures
    }
    /// Node `i`'s displacement now, from its reference position [m].
    pub fn displacement(&self, i: usize) -> [f64; 3] {
        let (x, x0) = (self.state.xn[i], self.x0[i]);
        [x[0] - x0[0], x[1] - x0[1], x[2] - x0[2]]
    }
    /// The layers of a fabric and the projectile's outcome.
    pub fn watch(&self) -> &watch::Watch {
        &self.watch
    }
    /// The backing clay's crater now, one row per point of `clay_profile` (see
    /// [`crater::CraterRow`]); empty without clay.
    pub fn crater(&self) -> Vec<crater::CraterRow> {
        let mut rows = vec![];
        if let Some(c) = &self.crater {
            c.sample(&self.state.xn, |n| self.failures.is_attached(n), &mut rows);
        }
        rows
    }
    /// The last output time sent to the sink (NaN before the first).
    pub fn sampled_to(&self) -> f64 {
        self.sampled_to
    }
}

/// What the failures of a run leave: every failure in order, and per node how many live
/// elements it still has (a node with none is a free mass).
#[derive(Debug, Clone, Default)]
pub struct FailureLog {
    /// Whether any element can fail.
    pub active: bool,
    pub events: Vec<failure::FailureEvent>,
    /// Per node, its live elements (force slots of elements that have not failed).
    pub attached: Vec<u32>,
    scratch: Vec<failure::Failure>,
    collected: Vec<failure::Collected>,
}

impl FailureLog {
    pub(super) fn new(el: &Families, nodes: usize) -> FailureLog {
        if !el.can_fail() {
            return FailureLog::default();
        }
        let mut attached = vec![0u32; nodes];
        for n in el.slot_nodes() {
            attached[n as usize] += 1;
        }
        FailureLog {
            active: true,
            attached,
            ..Default::default()
        }
    }
    /// Whether node i still has a live element.
    pub fn is_attached(&self, i: usize) -> bool {
        self.attached.get(i).is_none_or(|&a| a > 0)
    }
}

impl Solver {
    /// The nodes as the stable step's bound reads them (see [`stable::NodalBound`]).
    fn nodal_bound(&self) -> stable::NodalBound<'_> {
        stable::NodalBound {
            op: &self.op,
            state: &self.state,
            mass: &self.mass,
            fixed: &self.fixed,
            alpha: self.alpha,
            node_id: &self.node_id,
        }
    }

    /// The stable step (without safety factor) and its controlling node.
    pub fn stable_step(&self) -> (f64, usize) {
        self.nodal_bound().stable_step()
    }

    /// The stiffest element attached to a node.
    pub fn controlling_element(&self, node: usize) -> Option<(ElementKind, i64)> {
        self.nodal_bound().controlling_element(node)
    }

    /// Element energies at the positions `x` (and the current rotations and link
    /// states). Sums run over fixed chunks into preallocated partials, summed in
    /// chunk order.
    fn element_energies_at(&mut self, use_xn: bool) -> ElementEnergies {
        let x = if use_xn {
            &self.state.xn
        } else {
            &self.state.x
        };
        let ctx = ForceCtx {
            x,
            v: &self.state.v,
            rot_r: &self.state.rot.r,
            dt_prev: self.state.dt_prev,
            slow: self.state.slow,
        };
        let sums = self.op.el.energies(&ctx);
        ElementEnergies {
            internal: sums.total(0),
            damping: sums.total(1),
            friction: sums.total(2),
            hourglass: sums.total(3),
            // With what the contact on the eroded faces held (`SurfaceContact::eroded`).
            eroded: if self.failures.active {
                self.op.el.eroded_energy() + self.op.surfaces.eroded
            } else {
                0.0
            },
        }
    }

    /// Element energies at the current positions: (internal, damping, friction,
    /// hourglass).
    pub fn internal_energy(&mut self) -> (f64, f64, f64, f64) {
        let e = self.element_energies_at(false);
        (e.internal, e.damping, e.friction, e.hourglass)
    }

    /// Chooses the elements of kind `kind` (indices into their family, rows of its
    /// element table) whose path-dependent state the output samples carry
    /// ([`Sink::element_states`]); kinds without such a state ignore it.
    pub fn sample_states_of(&mut self, kind: ElementKind, elements: &[u32]) {
        self.op.el.set_state_output(kind, elements);
    }

    /// Current force of every link on its node 2 at the current positions: spring and
    /// slider (the slider return-mapped on a copy of its state), without the dashpot;
    /// the links in global axes first, then those in a local frame, then the sliding
    /// links (at their anchors, without slipping), each in table order.
    pub fn link_forces(&self) -> Vec<[f64; 3]> {
        let mut f = self.op.el.link.elastic_forces(&self.state.x);
        f.extend(
            self.op
                .el
                .framed_link
                .elastic_forces(&self.state.x)
                .iter()
                .map(|six| six[1]),
        );
        f.extend(self.op.el.sliding_link.elastic_forces_on_b(&self.state.x));
        f
    }

    /// Internal nodal forces at the current positions (the forces the elements exert;
    /// the dashpots see the current half-step velocities, and no element's state
    /// advances: sliders, plastic strains and failures are as they were).
    pub fn internal_forces(&mut self) -> Vec<[f64; 3]> {
        let saved = self.op.el.clone();
        self.op.element_forces(&self.state);
        self.op.el = saved;
        (0..self.x0.len())
            .map(|i| {
                let mut f = [0.0; 3];
                for &sl in self.op.gather.of(i) {
                    vec3::add(&mut f, &self.op.fe[sl as usize]);
                }
                f
            })
            .collect()
    }
}

/// Set up and run a model in the current thread pool, keeping every output sample in
/// memory (tests, and stages that run the solver in-process).
pub fn run_in_memory(m: &Model) -> Result<(Solver, output::MemorySink, RunStats)> {
    let mut s = Solver::new(m)?;
    let mut sink = output::MemorySink::default();
    let stats = s.run(&mut sink, &mut |_| {})?;
    Ok((s, sink, stats))
}
