//! The stable time step and selective mass scaling.
//!
//! A nodal Gershgorin bound. For elements joining nodes a, b with axial stiffness k_e,
//! Σ_e k_e (e·(u_a − u_b))² ≤ Σ_e k_e · 2(|u_a|² + |u_b|²), so the Rayleigh quotient of
//! M⁻¹K, hence ω_max², is bounded by max_i S_i/m_i with S_i = Σ_{e∋i} 2 k_e (k_e alone
//! when the other node is fully fixed); each family adds its own rows
//! ([`Family::stiffness_sums`](super::family::Family::stiffness_sums)). This is exact for
//! a uniform chain of trusses (Δt = L/c) and for a mass on a spring to ground
//! (Δt = 2√(m/k)), and accounts for point masses, links and mass scaling without special
//! cases. With dashpots (C_i = Σ 2 c_e, same rule) and mass damping,
//! ξ_i = (C_i/m_i + α)/(2ω_i) and Δt_i = (2/ω_i)(√(1+ξ_i²) − ξ_i) (Belytschko et al.
//! eq. 6.2.23). The step is safety × min_i Δt_i; the report names the node and its
//! stiffest element.

use super::family::{StiffCtx, Stiffened};
use super::operator::{Operator, State};
use crate::error::{Result, WeftError};
use crate::model::ElementKind;

/// The stable time step and what controls it.
#[derive(Debug, Clone)]
pub struct StableStep {
    /// The step used [s].
    pub dt: f64,
    /// The stable step estimate without the safety factor [s].
    pub dt_stable: f64,
    /// Node that controls the step (index).
    pub node: usize,
    /// Its stiffest element.
    pub element: Option<(ElementKind, i64)>,
    /// The smallest step taken so far [s]: `dt`, unless the analysis' variable step
    /// lowered it for crushed solids.
    pub dt_min: f64,
}

/// What [`NodalBound::check_stiffening`] keeps through a run: the stable step's nodal
/// stiffness and damping rows S_i, C_i, and its buffers (the stiffening added per node,
/// and the element that added most).
pub struct StiffeningCheck {
    s: Vec<f64>,
    c: Vec<f64>,
    extra: Vec<f64>,
    most: Vec<Option<Stiffened>>,
    /// The nodes of the families the variable step follows, ascending.
    variable_nodes: Vec<usize>,
}

/// Mass added by mass scaling.
#[derive(Debug, Clone, Default)]
pub struct MassScaling {
    /// Stable step before scaling [s] (without safety factor).
    pub dt_stable_unscaled: f64,
    pub added_mass: f64,
    /// Added mass over the model's physical mass.
    pub added_fraction: f64,
    pub nodes_scaled: usize,
    /// Largest nodal mass ratio m_scaled / m.
    pub max_ratio: f64,
}

/// Stable step of one node: Δt = (2/ω)(√(1+ξ²) − ξ), ω² = S/m, 2ξω = C/m + α.
pub fn nodal_dt(s: f64, c: f64, m: f64, alpha: f64) -> f64 {
    let damp = c / m + alpha;
    if s <= 0.0 {
        return if damp > 0.0 {
            2.0 / damp
        } else {
            f64::INFINITY
        };
    }
    let w = (s / m).sqrt();
    let xi = damp / (2.0 * w);
    // √(1+ξ²) − ξ = 1/(√(1+ξ²) + ξ), without the cancellation at large ξ, and with hypot so
    // that a huge damping gives a tiny step (which the step budget then refuses, naming
    // the node) rather than ∞ − ∞.
    (2.0 / w) / (1.0f64.hypot(xi) + xi)
}

/// What the nodal bound reads of a solver: the nodes' masses (scaled so far) and fixed
/// directions (bit d: direction d), the mass damping α [1/s], the node ids (for the
/// messages), and the operator (element families, ties, gather index) at a state.
pub struct NodalBound<'a> {
    pub op: &'a Operator,
    pub state: &'a State,
    pub mass: &'a [f64],
    pub fixed: &'a [u8],
    pub alpha: f64,
    pub node_id: &'a [i64],
}

impl NodalBound<'_> {
    /// Per-node stiffness and damping sums S_i, C_i.
    pub fn nodal_sums(&self) -> (Vec<f64>, Vec<f64>) {
        let nn = self.mass.len();
        let (mut s, mut c) = (vec![0.0; nn], vec![0.0; nn]);
        let mut rrow = vec![0.0; nn];
        let ctx = StiffCtx {
            fixed: &self.fixed,
            mass: &self.mass,
            rot_j: &self.state.rot.j,
        };
        self.op.el.stiffness_sums(&ctx, &mut s, &mut c, &mut rrow);
        for n in 0..nn {
            s[n] = s[n].max(rrow[n] * self.mass[n]);
        }
        // A slave's stiffness acts on its masters: |u_s|² ≤ Σ w_a |u_a|² (Jensen, w ≥ 0).
        for t in &self.op.ties.ties {
            for (a, &mn) in t.masters.iter().enumerate() {
                s[mn] += t.w[a] * s[t.slave];
                c[mn] += t.w[a] * c[t.slave];
            }
        }
        (s, c)
    }

    /// The stable step (without safety factor) and its controlling node.
    pub fn stable_step(&self) -> (f64, usize) {
        let (s, c) = self.nodal_sums();
        let mut best = (f64::INFINITY, 0);
        for i in 0..self.mass.len() {
            if self.fixed[i] == 0b111 || self.mass[i] <= 0.0 {
                continue;
            }
            let dt = nodal_dt(s[i], c[i], self.mass[i], self.alpha);
            if dt < best.0 {
                best = (dt, i);
            }
        }
        best
    }

    /// The stable step's nodal rows and the buffers of [`NodalBound::check_stiffening`],
    /// made once per run so that the check allocates nothing.
    /// (With a subcycle the nodes of slow cells stay in the variable step's list: their
    /// slow cells add no stiffening to it, and a cell that leaves the slow step, the
    /// crater's floor, is followed from then on.)
    pub fn stiffening_check(&self) -> StiffeningCheck {
        let (s, c) = self.nodal_sums();
        let nn = s.len();
        let mut variable = vec![false; nn];
        self.op.el.mark_variable_step_nodes(&mut variable);
        StiffeningCheck {
            s,
            c,
            extra: vec![0.0; nn],
            most: vec![None; nn],
            variable_nodes: (0..nn).filter(|&i| variable[i]).collect(),
        }
    }

    /// The variable step's bound: the nodal rows of the families it follows
    /// ([`Family::VARIABLE_STEP`](super::family::Family::VARIABLE_STEP): the hexahedra) at
    /// their current shape (the reference rows plus what each element's deformation
    /// added, as in [`NodalBound::check_stiffening`]), and the smallest stable step of
    /// their nodes with the node's index and the element that stiffened it most (its
    /// [`Stiffened`] record). `None` when no family is followed.
    pub fn variable_step(
        &self,
        k: &mut StiffeningCheck,
    ) -> Option<(f64, usize, Option<Stiffened>)> {
        if k.variable_nodes.is_empty() {
            return None;
        }
        for &i in &k.variable_nodes {
            k.extra[i] = 0.0;
            k.most[i] = None;
        }
        self.op
            .el
            .add_stiffening(&self.state.x, &mut k.extra, &mut k.most, true);
        self.smallest_step(k, &k.variable_nodes)
    }

    /// The slow step's bound ([`super::subcycle`]): the slow elements' rows at their
    /// current shape (the reference rows plus their stiffening) at their nodes `nodes`,
    /// and the smallest stable step of those nodes with the node's index and the element
    /// that stiffened it most. `None` without nodes.
    pub fn slow_step(
        &self,
        k: &mut StiffeningCheck,
        nodes: &[usize],
    ) -> Option<(f64, usize, Option<Stiffened>)> {
        for &i in nodes {
            k.extra[i] = 0.0;
            k.most[i] = None;
        }
        self.op
            .el
            .add_slow_stiffening(&self.state.x, &mut k.extra, &mut k.most);
        self.smallest_step(k, nodes)
    }

    /// The smallest stable step of `nodes` with their rows and stiffening in `k`, the
    /// node's index and the element that stiffened it most (free nodes with mass only).
    fn smallest_step(
        &self,
        k: &StiffeningCheck,
        nodes: &[usize],
    ) -> Option<(f64, usize, Option<Stiffened>)> {
        let mut best: Option<(f64, usize)> = None;
        for &i in nodes {
            if self.fixed[i] == 0b111 || self.mass[i] <= 0.0 {
                continue;
            }
            let dt_i = nodal_dt(k.s[i] + k.extra[i], k.c[i], self.mass[i], self.alpha);
            if best.is_none_or(|b| dt_i < b.0) {
                best = Some((dt_i, i));
            }
        }
        best.map(|(dt, i)| (dt, i, k.most[i]))
    }

    /// Stops a run whose membranes have stretched so far that the fixed step no longer
    /// suits them. The stable step is set once, from the undeformed model, and an St
    /// Venant–Kirchhoff membrane stiffens as it stretches (uniaxially by 1 + 3E₁₁): each
    /// element's stiffening, (ratio − 1) k_max, is added to its nodes' rows of the same
    /// Gershgorin bound (through ties to their masters, as the bound does), and a node
    /// whose step with those rows falls below the step in use stops the run, naming the
    /// element that stiffened it most: a clear message instead of the blow-up a few
    /// steps later. (`dt_safety`: the analysis' safety factor, which the message names.)
    pub fn check_stiffening(&self, k: &mut StiffeningCheck, dt: f64, dt_safety: f64) -> Result<()> {
        let x = &self.state.x;
        k.extra.fill(0.0);
        k.most.fill(None);
        self.op
            .el
            .add_stiffening(x, &mut k.extra, &mut k.most, false);
        for t in &self.op.ties.ties {
            for (a, &mn) in t.masters.iter().enumerate() {
                k.extra[mn] += t.w[a] * k.extra[t.slave];
            }
        }
        for i in 0..x.len() {
            if k.extra[i] <= 0.0 || self.fixed[i] == 0b111 || self.mass[i] <= 0.0 {
                continue;
            }
            let dt_i = nodal_dt(k.s[i] + k.extra[i], k.c[i], self.mass[i], self.alpha);
            if dt_i >= dt {
                continue;
            }
            // The element that stiffened this node most (a master's may sit on its slave).
            let who = k.most[i].or_else(|| {
                self.op
                    .ties
                    .ties
                    .iter()
                    .filter(|t| t.masters.contains(&i))
                    .filter_map(|t| k.most[t.slave])
                    .max_by(|a, b| a.added.total_cmp(&b.added))
            });
            let (what, hint) = match who {
                Some(w) => w.describe(dt_safety),
                None => ("its membranes have stretched".to_string(), None),
            };
            return Err(WeftError::Numerical {
                what: format!(
                    "{what}, which stiffens node `{}` so far that its stable step {dt_i:.4e} s is now below the step {dt:.4e} s in use",
                    self.node_id[i]
                ),
                step: self.state.step,
                time: self.state.t,
                hint: Some(hint.unwrap_or_else(|| format!(
                    "the stable step is set once, from the undeformed model; strains this large are beyond what most materials bear (aramid yarns break near 3.6 %; give the part a failure law, `failure_strain`, to remove such elements): shorten end_time, lower the load or the impact velocity, or lower dt_safety (now {}) to run on",
                    dt_safety
                ))),
            });
        }
        Ok(())
    }

    /// The stiffest element attached to a node.
    pub fn controlling_element(&self, node: usize) -> Option<(ElementKind, i64)> {
        let mut best: Option<(f64, ElementKind, i64)> = None;
        for &slot in self.op.gather.of(node) {
            let Some((kind, id, k)) = self.op.el.slot_element(slot as usize) else {
                continue;
            };
            if best.map_or(true, |b| k > b.0) {
                best = Some((k, kind, id));
            }
        }
        best.map(|b| (b.1, b.2))
    }

    /// Conventional mass scaling applied selectively: only nodes whose stable step is
    /// below the target get mass, just enough to reach it (with the safety factor). The
    /// scaled masses and what was added (`physical_mass`: the model's mass unscaled).
    pub fn scale_mass(
        &self,
        target: f64,
        safety: f64,
        physical_mass: f64,
    ) -> (Vec<f64>, MassScaling) {
        let (s, c) = self.nodal_sums();
        let dt_before = {
            let mut best = f64::INFINITY;
            for i in 0..self.mass.len() {
                if self.fixed[i] != 0b111 && self.mass[i] > 0.0 {
                    best = best.min(nodal_dt(s[i], c[i], self.mass[i], self.alpha));
                }
            }
            best
        };
        let mut mass = self.mass.to_vec();
        let mut rep = MassScaling {
            dt_stable_unscaled: dt_before,
            max_ratio: 1.0,
            ..Default::default()
        };
        for i in 0..self.mass.len() {
            if self.fixed[i] == 0b111 || self.mass[i] <= 0.0 {
                continue;
            }
            let m0 = mass[i];
            let mut m = m0;
            // Δt grows like √m (faster with damping): a few multiplicative passes converge.
            for _ in 0..60 {
                let dt = safety * nodal_dt(s[i], c[i], m, self.alpha);
                if dt >= target {
                    break;
                }
                m *= (target / dt).powi(2) * (1.0 + 1e-12);
            }
            if m > m0 {
                rep.added_mass += m - m0;
                rep.nodes_scaled += 1;
                rep.max_ratio = rep.max_ratio.max(m / m0);
                mass[i] = m;
            }
        }
        rep.added_fraction = rep.added_mass / physical_mass.max(f64::MIN_POSITIVE);
        (mass, rep)
    }
}
