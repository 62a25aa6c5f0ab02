//! Setting a solver up ([`Solver::new`], [`Solver::from_validated`]): the element
//! families and their lumped masses, the rotational nodes, ties, projectile and surface
//! contact, the fixed directions and output nodes, and the time step (mass scaling, the
//! stable step with the contact guard, a fixed or target step), with the checks that
//! refuse a model the run could not integrate (a free node without mass, a step beyond
//! the stable one, a tied node given its own velocity).

use super::energy::{energy_floor, Ledger};
use super::family;
use super::integrator::NodePartial;
use super::{
    contact, crater, rotations, ties, watch, FailureLog, Families, Operator, Solver, StableStep,
    State, CHUNK,
};
use crate::error::{Result, WeftError};
use crate::model::{ElementKind, Model, ValidatedModel};

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
    /// Check a model ([`Model::validate`]) and set up a solver for it
    /// ([`Solver::from_validated`]).
    pub fn new(m: &Model) -> Result<Solver> {
        m.validate()?;
        Self::build(m)
    }

    /// Set up a solver for a validated model: element families and masses, ties,
    /// contact, the gather index, the stable step and (when asked) mass scaling.
    pub fn from_validated(m: &ValidatedModel) -> Result<Solver> {
        Self::build(m)
    }

    /// [`Solver::from_validated`] for a model known to be valid.
    fn build(m: &Model) -> Result<Solver> {
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
                slow: family::SlowStep::NONE,
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
            crater: None,
            sampled_to: f64::NAN,
            subcycle: None,
        };
        s.failures = FailureLog::new(&s.op.el, nn);
        s.crater = crater::CraterWatch::new(m, &s.x0);
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
        s.start_subcycle();
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
        let dt = match a.time_step {
            Some(dt) => self.check_fixed_step(dt, dt_stable, node)?,
            None => {
                let safe = safe_step(&a, dt_stable, kappa)?;
                a.target_time_step.map_or(safe, |target| target.min(safe))
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

    /// A fixed step `dt` (analysis `time_step`) no larger than the stable one, else an
    /// error naming the node and its stiffest element.
    fn check_fixed_step(&self, dt: f64, dt_stable: f64, node: usize) -> Result<f64> {
        if dt <= dt_stable {
            return Ok(dt);
        }
        let a = &self.analysis;
        let (k, id) = self
            .controlling_element(node)
            .unwrap_or((ElementKind::PointMass, -1));
        Err(WeftError::input(format!(
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
        }))
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
}

/// The step the safety factor s leaves of the stable one: s Δt_stable, or with contact
/// Δt_stable √(s² − κ/2) (κ the largest sum of penalty factors on one node; see
/// [`Solver::set_time_step`]), an error when κ leaves none.
fn safe_step(a: &crate::model::Analysis, dt_stable: f64, kappa: f64) -> Result<f64> {
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
    Ok(if kappa > 0.0 {
        dt_stable * s2.sqrt()
    } else {
        a.dt_safety * dt_stable
    })
}
