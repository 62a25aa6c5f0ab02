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
pub mod collapse;
pub mod contact;
pub mod energy;
pub mod erosion;
pub mod failure;
pub mod families;
pub mod family;
pub mod integrator;
pub mod link;
pub mod membrane;
pub mod operator;
pub mod output;
pub mod point_mass;
pub mod relax;
pub mod rotations;
pub mod sliding_link;
pub mod solid;
pub mod stable;
pub mod statics;
pub mod ties;
pub mod truss;
mod variable_step;
/// The small vector helpers, shared below the solver ([`crate::vec3`]).
pub use crate::vec3;
pub mod watch;

use std::time::{Duration, Instant};

use crate::error::{Result, WeftError};
use crate::model::{ElementKind, Model};

use energy::{energy_floor, Ledger};
pub use energy::{ElementEnergies, Energies, ENERGY_CHECK_AFTER};
pub use families::Families;
use family::ForceCtx;
pub use family::CHUNK;
use integrator::{Nodal, NodePartial};
pub use operator::{Operator, State};
use output::Sampler;
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

/// The explicit solver: owns the state and scratch buffers of one model.
pub struct Solver {
    pub node_id: Vec<i64>,
    /// Reference positions X [m].
    pub x0: Vec<[f64; 3]>,
    /// Positions, velocities, rotations, time.
    pub state: State,
    /// Forces at a state.
    pub op: Operator,
    /// Lumped nodal masses (with mass scaling) [kg].
    pub mass: Vec<f64>,
    /// Physical model mass (without scaling) [kg].
    pub physical_mass: f64,
    inv_m: Vec<f64>,
    /// Bit d set when direction d is fixed.
    fixed: Vec<u8>,
    partials: Vec<NodePartial>,
    alpha: f64,
    /// Output nodes (indices).
    pub output_nodes: Vec<usize>,
    pub stable: StableStep,
    pub scaling: Option<MassScaling>,
    pub analysis: crate::model::Analysis,
    ledger: Ledger,
    /// Element failures and what they leave (empty when nothing can fail).
    pub failures: FailureLog,
    /// Layers and the projectile's outcome (see [`watch`]).
    pub watch: watch::Watch,
    /// The last output time sent to the sink (NaN before the first): where the tables of
    /// a run that stopped end.
    pub sampled_to: f64,
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

/// Fixed translations: constraints and symmetry planes.
fn fixed_dofs(m: &Model) -> Vec<u8> {
    let mut fixed = vec![0u8; m.num_nodes()];
    for (n, f) in &m.constraints {
        for d in 0..3 {
            if f[d] {
                fixed[*n] |= 1 << d;
            }
        }
    }
    for sp in &m.symmetry {
        for i in 0..m.num_nodes() {
            if (m.coords[i][sp.normal] - sp.position).abs() <= sp.tolerance {
                fixed[i] |= 1 << sp.normal;
            }
        }
    }
    fixed
}

/// The output nodes: those of the history sets, or every node.
fn output_nodes(m: &Model) -> Result<Vec<usize>> {
    let nn = m.num_nodes();
    if m.analysis.history_sets.is_empty() {
        return Ok((0..nn).collect());
    }
    let mut sel = vec![false; nn];
    for s in &m.analysis.history_sets {
        let set = m.node_sets.get(s).ok_or_else(|| {
            WeftError::input(format!("history node set `{s}` does not exist"))
                .in_file("analysis.parquet")
                .in_column("history_sets")
                .expected(format!(
                    "one of the model's node sets: {}",
                    m.node_set_names()
                ))
        })?;
        for &i in set {
            sel[i] = true;
        }
    }
    Ok((0..nn).filter(|&i| sel[i]).collect())
}

impl Solver {
    /// Set up a solver for a validated model: element families and masses, ties,
    /// contact, the gather index, the stable step and (when asked) mass scaling.
    pub fn new(m: &Model) -> Result<Solver> {
        m.validate()?;
        let nn = m.num_nodes();
        if nn >= u32::MAX as usize {
            return Err(WeftError::input(format!(
                "{nn} nodes exceed the solver's limit of 2³²−1"
            )));
        }
        let mut mass = vec![0.0; nn];
        let mut rot = rotations::Rotations::new(nn);
        let el = Families::build(&mut family::Build {
            model: m,
            mass: &mut mass,
            rot: &mut rot,
        })?;
        rot.finish(m, el.rotational().0);
        let projectiles = contact::ProjectileContact::new(m, &el.contact_faces());
        let fixed = fixed_dofs(m);
        let ties = ties::Ties::build(m, &mut mass)?;
        let op = Operator::new(el, ties, projectiles, &m.loads, nn);
        Self::check_masses(m, &op, &mass, &fixed)?;
        let physical_mass: f64 = mass.iter().sum();
        let mut v = vec![[0.0; 3]; nn];
        for (n, vel) in &m.initial_velocities {
            v[*n] = *vel;
        }
        // A formed state starts displaced from the elements' reference; outputs measure
        // displacements from where it starts.
        let start: Vec<[f64; 3]> = if m.initial_displacement.is_empty() {
            m.coords.clone()
        } else {
            m.coords
                .iter()
                .zip(&m.initial_displacement)
                .map(|(x, u)| [x[0] + u[0], x[1] + u[1], x[2] + u[2]])
                .collect()
        };
        let mut s = Solver {
            node_id: m.node_id.clone(),
            x0: start.clone(),
            state: State {
                x: start,
                v,
                xn: vec![[0.0; 3]; nn],
                vn: vec![[0.0; 3]; nn],
                rot,
                t: 0.0,
                step: 0,
                dt_prev: 0.0,
            },
            op,
            inv_m: vec![0.0; nn],
            mass,
            physical_mass,
            fixed,
            partials: vec![NodePartial::default(); nn.div_ceil(CHUNK)],
            alpha: m.analysis.mass_damping,
            output_nodes: output_nodes(m)?,
            stable: StableStep {
                dt: 0.0,
                dt_stable: 0.0,
                node: 0,
                element: None,
                dt_min: 0.0,
            },
            scaling: None,
            analysis: m.analysis.clone(),
            ledger: Ledger::default(),
            failures: FailureLog::default(),
            watch: watch::Watch::new(m),
            sampled_to: f64::NAN,
        };
        s.failures = FailureLog::new(&s.op.el, nn);
        let kappa = contact::surface::guard_kappa(m);
        s.set_time_step(kappa)?;
        // The membranes' collapse criterion reads the masses as the step was set with.
        s.op.el.step_was_set(&m.coords, &s.mass, &s.fixed);
        s.ledger.floor = energy_floor(&s.x0, &s.mass, s.stable.dt);
        s.op.projectiles.set_step(&s.mass, s.stable.dt);
        if !m.contacts.is_empty() {
            s.op.surfaces = contact::SurfaceContact::new(m, &s.mass);
            s.op.surfaces.start(m, &s.state.x)?;
        }
        if s.watch.n_layers > 0 {
            s.op.surfaces.track_friction(nn);
            s.op.projectiles.node_friction = Some(vec![0.0; nn]);
        }
        s.op.ties
            .update_slaves(&mut s.state.x, &mut s.state.v, None);
        s.check_slave_velocities(m)?;
        Ok(s)
    }

    /// Nodes that can move must have mass.
    fn check_masses(m: &Model, op: &Operator, mass: &[f64], fixed: &[u8]) -> Result<()> {
        let mut loaded = vec![false; m.num_nodes()];
        for l in &m.loads {
            loaded[l.node] = true;
        }
        for i in 0..m.num_nodes() {
            let attached = !op.gather.of(i).is_empty();
            if mass[i] <= 0.0
                && fixed[i] != 0b111
                && (attached || loaded[i])
                && !op.ties.is_slave[i]
            {
                return Err(WeftError::input(format!(
                    "node `{}` has no mass but can move and {}",
                    m.node_id[i],
                    if attached {
                        "has elements attached"
                    } else {
                        "carries a load"
                    }
                ))
                .in_file("nodes.parquet")
                .expected("mass > 0 at every free node that elements or loads act on")
                .hint(
                    "its elements give it no mass (links only, or trusses of density 0 in parts.parquet, column density): attach a point_mass, give a part a density, or fix the node",
                ));
            }
        }
        Ok(())
    }

    /// Mass scaling (when asked), then the step: fixed, target or safety × stable. With
    /// contact between parts the step is Δt_stable √(s² − κ/2) instead of s Δt_stable, κ
    /// the largest sum of penalty factors on one node (`contact::surface::guard_kappa`):
    /// a node's highest frequency then satisfies ω Δt ≤ 2s with the contact springs
    /// (k ≤ κ_c m/Δt² on each side of a pair) added to its elements.
    fn set_time_step(&mut self, kappa: f64) -> Result<()> {
        let a = self.analysis.clone();
        if a.time_step.is_some() && a.target_time_step.is_some() {
            return Err(
                WeftError::input("both time_step and target_time_step are set")
                    .in_file("analysis.parquet")
                    .expected(
                        "at most one: a fixed step, or a target step reached by mass scaling",
                    ),
            );
        }
        if let Some(target) = a.target_time_step {
            let (mass, rep) =
                self.nodal_bound()
                    .scale_mass(target, a.dt_safety, self.physical_mass);
            self.mass = mass;
            self.scaling = Some(rep);
        }
        for (im, m) in self.inv_m.iter_mut().zip(&self.mass) {
            *im = if *m > 0.0 { 1.0 / m } else { 0.0 };
        }
        if let Some(i) = self.mass.iter().position(|m| !m.is_finite()) {
            return Err(WeftError::input(format!(
                "node `{}` has mass {} kg",
                self.node_id[i], self.mass[i]
            ))
            .in_file("parts.parquet")
            .expected("finite masses: each element's density × area (or thickness) × size, and point masses, finite")
            .hint("a density, area, thickness or mass of the node's elements (parts.parquet), or an element's size (node coordinates in nodes.parquet), is far too large"));
        }
        let (dt_stable, node) = self.stable_step();
        if dt_stable.is_nan() {
            return Err(WeftError::input(format!(
                "the stable step of node `{}` is not a number",
                self.node_id[node]
            ))
            .in_file("parts.parquet")
            .expected("finite stiffness and mass at every node")
            .hint("a modulus, area, thickness or stiffness of the node's elements (parts.parquet), or their coordinates (nodes.parquet), far too large"));
        }
        if !dt_stable.is_finite() && a.time_step.is_none() {
            return Err(WeftError::input(
                "no element limits the time step (the model has no stiffness)",
            )
            .expected("at least one truss, or a link with stiffness or damping")
            .hint("set `time_step` in analysis.parquet for a model of free masses"));
        }
        let dt = match (a.time_step, a.target_time_step) {
            (Some(dt), _) => {
                if dt > dt_stable {
                    let (k, id) = self
                        .controlling_element(node)
                        .unwrap_or((ElementKind::PointMass, -1));
                    return Err(WeftError::input(format!(
                        "time_step {dt:.4e} s exceeds the stable step {dt_stable:.4e} s set by node `{}` ({} `{id}`)",
                        self.node_id[node],
                        k.name()
                    ))
                    .in_file("analysis.parquet")
                    .in_column("time_step")
                    .expected(format!("a step ≤ {dt_stable:.4e} s"))
                    .hint(if a.mass_damping * dt_stable > 0.1 {
                        format!("the mass damping α = {:e} 1/s (column mass_damping) shortens the stable step to about 2/α: lower it, or leave time_step empty", a.mass_damping)
                    } else {
                        "leave time_step empty to use the stable step, or use target_time_step for mass scaling; if the stable step is unexpectedly small, check that element's properties in parts.parquet".to_string()
                    }));
                }
                dt
            }
            (None, other) => {
                let s2 = a.dt_safety * a.dt_safety - 0.5 * kappa;
                if s2 <= 0.0 {
                    return Err(WeftError::input(format!(
                        "the contact penalty factors on one node add up to κ = {kappa} (0.1 × penalty_scale per contact role, two-way counted twice, 0.2 for projectiles), which leaves no stable step with dt_safety {}",
                        a.dt_safety
                    ))
                    .in_file("contacts.parquet")
                    .in_column("penalty_scale")
                    .expected(format!("κ < 2 dt_safety² = {}", 2.0 * a.dt_safety * a.dt_safety))
                    .hint("lower penalty_scale (1 is LS-DYNA's SOFT = 1 default)"));
                }
                let safe = if kappa > 0.0 {
                    dt_stable * s2.sqrt()
                } else {
                    a.dt_safety * dt_stable
                };
                match other {
                    Some(target) => target.min(safe),
                    None => safe,
                }
            }
        };
        self.stable = StableStep {
            dt,
            dt_stable,
            node,
            element: self.controlling_element(node),
            dt_min: dt,
        };
        Ok(())
    }

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

    /// A slave's initial velocity must be its masters'.
    fn check_slave_velocities(&self, m: &Model) -> Result<()> {
        for (n, v) in &m.initial_velocities {
            if let Some(t) = self.op.ties.of_slave(*n) {
                let vs = self.state.v[*n];
                if (0..3).any(|d| (vs[d] - v[d]).abs() > 1e-9 * (1.0 + v[d].abs())) {
                    return Err(WeftError::input(format!(
                        "tied node `{}` is given the initial velocity {v:?}, but its masters move with {vs:?}",
                        m.node_id[*n]
                    ))
                    .in_file("initial_velocities.parquet")
                    .expected(format!("no initial velocity on a slave, or the masters' ({} nodes)", t.masters.len()))
                    .hint("give the initial velocity to the master nodes"));
                }
            }
        }
        Ok(())
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

    fn nan_error(&self, node: usize) -> WeftError {
        let mut culprit = String::new();
        for &slot in self.op.gather.of(node) {
            let f = self.op.fe[slot as usize];
            if !(f[0] + f[1] + f[2]).is_finite() {
                if let Some((k, id, _)) = self.op.el.slot_element(slot as usize) {
                    culprit = format!("; the force of {} `{id}` is not finite", k.name());
                }
                break;
            }
        }
        let fx = self.op.fext[node];
        if culprit.is_empty() && !(fx[0] + fx[1] + fx[2]).is_finite() {
            culprit = "; its external load is not finite".into();
        }
        if culprit.is_empty() {
            // A load on the node (or the largest one in the model) too large for the
            // model is the next suspect: name it.
            let big = self
                .op
                .loads
                .loads
                .iter()
                .map(|l| (l, l.force.iter().map(|f| f.abs()).fold(0.0, f64::max)))
                .max_by(|a, b| {
                    (a.0.node == node, a.1)
                        .partial_cmp(&(b.0.node == node, b.1))
                        .unwrap_or(std::cmp::Ordering::Equal)
                });
            if let Some((l, f)) = big {
                culprit = format!(
                    "; {} load `{}` (loads.parquet, node `{}`) peaks at {f:.3e} N",
                    if l.node == node { "its" } else { "the largest" },
                    l.id,
                    self.node_id[l.node]
                );
            }
        }
        WeftError::Numerical {
            what: format!("velocity or position of node `{}` became NaN or infinite{culprit}", self.node_id[node]),
            step: self.state.step,
            time: self.state.t,
            hint: Some(format!(
                "the step is {:.4e} s against a stable estimate of {:.4e} s; check for extreme properties or loads near this node",
                self.stable.dt, self.stable.dt_stable
            )),
        }
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

    /// Run to the end time, sending samples on the output grid to `sink`. `progress` is
    /// called now and then with the fraction of simulated time done.
    pub fn run(
        &mut self,
        sink: &mut (dyn Sink + Send),
        progress: &mut (dyn FnMut(f64) + Send),
    ) -> Result<RunStats> {
        let a = self.analysis.clone();
        let n_out = (a.end_time / a.output_interval).round() as u64;
        let dt = self.stable.dt;
        let mut times = PhaseTimes::default();
        let mut sampler = Sampler::new(self.output_nodes.len());
        let proj_ids: Vec<i64> = self
            .op
            .projectiles
            .projectiles
            .iter()
            .map(|p| p.id)
            .collect();
        let mut k = 0u64;
        let progress_every = (n_out / 200).max(1);
        let mut last_e = Energies::default();
        let mut stiffening = self.nodal_bound().stiffening_check();
        // The step of the integration; `dt`, the first, stays the contact penalties' step.
        let mut dt_step = self.stable.dt_min.min(dt);
        while k <= n_out {
            if a.variable_time_step {
                dt_step = self.follow_solids(&mut stiffening, dt_step)?;
            }
            if self.state.step % STIFFENING_CHECK_EVERY == 0 {
                self.nodal_bound()
                    .check_stiffening(&mut stiffening, dt_step, a.dt_safety)?;
            }
            let t2 = self.compute_forces(dt, &mut times);
            let dt_next = dt_step;
            let snap = k as f64 * a.output_interval <= self.state.t + dt_next;
            let (ke, dp) = self.advance_nodes(snap, dt_next)?;
            // Element energies at t_n (x^n is in xn), before the rotations advance.
            let el_e = if snap {
                self.element_energies_at(true)
            } else {
                ElementEnergies::default()
            };
            let (ke_rot, dp_rot) = self.advance_rotations(dt_next)?;
            let (ke, dp) = (ke + ke_rot, dp + dp_rot);
            self.ledger.mass_damping += 0.5 * self.state.dt_prev * dp;
            self.update_tie_slaves(snap);
            let (contact_e, ke_proj) =
                self.advance_projectiles(snap, dt, dt_next, &mut sampler.cur.proj);
            let ke = ke + ke_proj;
            let t3 = Instant::now();
            times.update += t3 - t2;
            if snap {
                last_e = self.book_sample(ke, &el_e, contact_e, &mut sampler)?;
                self.op.el.sample_states(&mut sampler.cur.states);
                if self.watch.is_active() {
                    self.watch_sample(&mut sampler.cur.layers);
                }
                sampler.emit(
                    &mut k,
                    n_out,
                    a.output_interval,
                    &proj_ids,
                    &self.output_nodes,
                    sink,
                    |kk, tk| {
                        if kk % progress_every == 0 {
                            progress(tk / a.end_time);
                        }
                    },
                )?;
                if k > 0 {
                    self.sampled_to = (k - 1) as f64 * a.output_interval;
                }
                times.output += t3.elapsed();
            }
            self.ledger.mass_damping += 0.5 * dt_next * dp;
            self.state.t += dt_next;
            self.state.dt_prev = dt_next;
            self.state.step += 1;
            if snap && a.stop_on_outcome && self.watch.outcome.is_decided() {
                // Past the outcome's sample: the output grid ends at the last time sent.
                break;
            }
        }
        progress(1.0);
        let end_time = if self.watch.outcome.is_decided() && a.stop_on_outcome {
            (k.saturating_sub(1)) as f64 * a.output_interval
        } else {
            a.end_time
        };
        Ok(RunStats {
            steps: self.state.step,
            end_time,
            times,
            threads: rayon::current_num_threads(),
            max_balance_error_relative: self.ledger.reported(self.state.step),
            final_energies: last_e,
            elements: self.op.el.updated_elements(),
            nodes: self.x0.len(),
        })
    }

    /// The forces at t_n: loads, element forces, then contact and ties, timed into
    /// `times`; the instant they were done.
    fn compute_forces(&mut self, dt: f64, times: &mut PhaseTimes) -> Instant {
        let t0 = Instant::now();
        self.op.apply_loads(&self.state);
        let t1 = Instant::now();
        self.op.element_forces(&self.state);
        if self.failures.active {
            self.apply_failures();
        }
        let t1c = Instant::now();
        self.op.contact_and_ties(&self.state, &self.mass, dt);
        let t2 = Instant::now();
        times.contact += t2 - t1c;
        times.loads += t1 - t0;
        times.forces += t2 - t1;
        t2
    }

    /// What the run did so far (for a run that stopped: its steps, the last output time
    /// sent, its worst balance), without the phase times.
    pub fn stats_so_far(&self) -> RunStats {
        RunStats {
            steps: self.state.step,
            end_time: if self.sampled_to.is_nan() {
                0.0
            } else {
                self.sampled_to
            },
            times: PhaseTimes::default(),
            threads: rayon::current_num_threads(),
            max_balance_error_relative: self.ledger.reported(self.state.step),
            final_energies: Energies::default(),
            elements: self.op.el.updated_elements(),
            nodes: self.x0.len(),
        }
    }

    /// The nodes' update over `dt` (at a sample step, `snap`, also x^n and v^n kept): the
    /// kinetic energy and the mass-damping power, or the error that names a node gone
    /// non-finite.
    fn advance_nodes(&mut self, snap: bool, dt: f64) -> Result<(f64, f64)> {
        let nd = Nodal {
            inv_m: &self.inv_m,
            mass: &self.mass,
            fixed: &self.fixed,
            alpha: self.alpha,
        };
        let r = if snap {
            integrator::advance_nodes::<true>(
                &mut self.state,
                &self.op,
                &nd,
                dt,
                &mut self.partials,
            )
        } else {
            integrator::advance_nodes::<false>(
                &mut self.state,
                &self.op,
                &nd,
                dt,
                &mut self.partials,
            )
        };
        r.map_err(|node| self.nan_error(node))
    }

    /// The rotational nodes' update over `dt`: their kinetic energy and mass-damping
    /// power (zero without beams).
    fn advance_rotations(&mut self, dt: f64) -> Result<(f64, f64)> {
        if self.state.rot.is_empty() {
            return Ok((0.0, 0.0));
        }
        integrator::advance_rotations(
            &mut self.state,
            self.op.el.rotational().1,
            self.alpha,
            dt,
            &self.node_id,
        )
    }

    /// The tied slaves follow their masters (at a sample step, their v^n too).
    fn update_tie_slaves(&mut self, snap: bool) {
        if !self.op.ties.is_empty() {
            let st = &mut self.state;
            self.op
                .ties
                .update_slaves(&mut st.x, &mut st.v, snap.then_some(&mut st.vn[..]));
        }
    }

    /// The projectiles' update from `dt_prev` to `dt_next` (`dt`: the step of their
    /// penalty): their kinetic energy, and at a sample step their state at t_n into `rows`
    /// (tip and contact force, before the update) and their contact energy at t_n.
    /// Returns (contact energy, kinetic energy).
    fn advance_projectiles(
        &mut self,
        snap: bool,
        dt: f64,
        dt_next: f64,
        rows: &mut Vec<[f64; 9]>,
    ) -> (f64, f64) {
        let mut contact_e = 0.0;
        if snap {
            // Projectile states at t_n: tip and contact force before their update.
            rows.clear();
            for p in &self.op.projectiles.projectiles {
                rows.push([
                    p.tip[0], p.tip[1], p.tip[2], 0.0, 0.0, 0.0, p.force[0], p.force[1], p.force[2],
                ]);
            }
            if !self.op.projectiles.is_empty() {
                contact_e = self.op.projectiles.energy(&self.state.xn, &self.mass, dt);
            }
        }
        let ke_proj = if self.op.projectiles.is_empty() {
            0.0
        } else {
            self.op.projectiles.advance(self.state.dt_prev, dt_next)
        };
        (contact_e, ke_proj)
    }

    /// A sample at t_n: the projectiles' velocities, the energies booked in the ledger
    /// and checked (finite, balanced), and the output nodes' displacements and velocities,
    /// into the sampler's current snapshot. Returns the energies.
    fn book_sample(
        &mut self,
        ke: f64,
        el_e: &ElementEnergies,
        contact_e: f64,
        sampler: &mut Sampler,
    ) -> Result<Energies> {
        for (row, p) in sampler
            .cur
            .proj
            .iter_mut()
            .zip(&self.op.projectiles.projectiles)
        {
            row[3..6].copy_from_slice(&p.v_full);
        }
        let contact = contact_e
            + self.op.projectiles.friction_work
            + self.op.projectiles.damping_work
            + (self.op.surfaces.stored + self.op.surfaces.dissipated);
        let w_ext = self.op.loads.work + self.op.projectiles.prescribed_work;
        let e = self.ledger.book(ke, el_e, contact, w_ext, self.state.step);
        sampler.cur.t = self.state.t;
        sampler.cur.e = e;
        self.check_finite_energies(ke, el_e, contact, w_ext)?;
        self.check_balance(&e)?;
        for (j, &i) in self.output_nodes.iter().enumerate() {
            let (x, x0) = (self.state.xn[i], self.x0[i]);
            sampler.cur.u[j] = [x[0] - x0[0], x[1] - x0[1], x[2] - x0[2]];
            sampler.cur.v[j] = self.state.vn[i];
        }
        Ok(e)
    }

    /// A non-finite energy is a broken run even when the nodes are finite (a comparison
    /// with NaN is false: it would pass the balance check): the error names the term and
    /// its likely cause.
    fn check_finite_energies(
        &self,
        ke: f64,
        el_e: &ElementEnergies,
        contact: f64,
        w_ext: f64,
    ) -> Result<()> {
        let terms = [
            ("kinetic", ke),
            ("internal", el_e.internal),
            ("damping", el_e.damping),
            ("friction", el_e.friction),
            ("hourglass", el_e.hourglass),
            ("contact (stored and friction work)", contact),
            ("external work", w_ext),
        ];
        let Some((name, v)) = terms.iter().find(|(_, v)| !v.is_finite()) else {
            return Ok(());
        };
        let hint = if *name == "external work" {
            let big = self.op.loads.loads.iter().max_by(|a, b| {
                let m =
                    |l: &crate::model::Load| l.force.iter().map(|f| f.abs()).fold(0.0, f64::max);
                m(a).total_cmp(&m(b))
            });
            match big {
                Some(l) => format!(
                    "the loads' work overflowed: the largest is load `{}` (loads.parquet, node `{}`, force {:?} N)",
                    l.id, self.node_id[l.node], l.force
                ),
                None => "a projectile with prescribed velocity did non-finite work".to_string(),
            }
        } else if *name == "kinetic" {
            "a mass × velocity² overflowed: check the initial velocities, the element and point masses (parts.parquet) and the projectiles' mass and velocity (projectile.parquet)".to_string()
        } else {
            "a penalty or element with zero mass or zero length somewhere; the contact report names the definitions (run with the same model and a shorter end time to look at it)".to_string()
        };
        Err(WeftError::Numerical {
            what: format!("the {name} energy is {v}"),
            step: self.state.step,
            time: self.state.t,
            hint: Some(hint),
        })
    }

    /// The energy balance stops the run once its error passes the analysis' limit
    /// (from [`ENERGY_CHECK_AFTER`] steps on).
    fn check_balance(&self, e: &Energies) -> Result<()> {
        let a = &self.analysis;
        if e.balance_error_relative > a.max_energy_error && self.state.step >= ENERGY_CHECK_AFTER {
            return Err(WeftError::Numerical {
                what: format!(
                    "energy balance error {:.3e} J is {:.1} % of the reference energy {:.3e} J (limit {:.1} %): the run is unstable or a force is not conservative",
                    e.balance_error, 100.0 * e.balance_error_relative, self.ledger.reference, 100.0 * a.max_energy_error
                ),
                step: self.state.step,
                time: self.state.t,
                hint: Some(format!(
                    "the step is {:.4e} s (stable estimate {:.4e} s); lower dt_safety, or raise max_energy_error if the loss is physical",
                    self.stable.dt, self.stable.dt_stable
                )),
            });
        }
        Ok(())
    }
}

/// Steps between two checks of the membranes' stiffening against the step
/// (`NodalBound::check_stiffening`, in `stable.rs`): often enough that a strain growing
/// towards the margin (1/dt_safety² − 1 = 0.23 at 0.9, in 1 + 3E₁₁) is caught before it
/// has run away; one check costs about one membrane force pass without the forces.
const STIFFENING_CHECK_EVERY: u64 = 20;

/// Set up and run a model in the current thread pool, keeping every output sample in
/// memory (tests, and stages that run the solver in-process).
pub fn run_in_memory(m: &Model) -> Result<(Solver, output::MemorySink, RunStats)> {
    let mut s = Solver::new(m)?;
    let mut sink = output::MemorySink::default();
    let stats = s.run(&mut sink, &mut |_| {})?;
    Ok((s, sink, stats))
}
