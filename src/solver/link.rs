//! Two-node discrete link: a spring and a dashpot per global axis, and an optional
//! friction slider in the global x–y (fabric) plane.
//!
//! Glossary: d = (x₂ − x₁) − (X₂ − X₁) relative displacement [m] (the initial offset
//! X₂ − X₁ is removed, so the nodes need not coincide); ḋ = v₂ − v₁ relative velocity
//! [m/s]; k = (k_x, k_y, k_z) [N/m]; c = (c_x, c_y, c_z) [N·s/m]; s = (s_x, s_y) slip of
//! the slider [m]; F_s slip force [N].
//!
//! Force on node 2 (node 1 gets the opposite):
//! - normal (z): f_z = −k_z d_z − c_z ḋ_z;
//! - tangential (x, y): the spring acts on the elastic part d − s; trial force
//!   f_t = −k ∘ (d_t − s); if |f_t| > F_s the slider slips: f_t is returned radially
//!   to |f_t| = F_s and s is updated so that f_t = −k ∘ (d_t − s) holds (elastic–
//!   perfectly-plastic, Coulomb-like with a constant limit); the dashpot adds −c ∘ ḋ_t.
//!
//! Energy: stored W = ½ Σ k (d − s)² (s = 0 along z); dissipated by the slider
//! Σ −f_t·Δs; by the dashpots Σ Δt c ḋ² with ḋ the half-step velocity v^{n−½} the
//! explicit scheme uses.
//!
//! The axes are global: exact for links between coincident nodes (the yarn crossings
//! of the reduced woven model), where a rigid rotation gives d = 0 and no force; links
//! between distant nodes are not rotation invariant. Reference for the slider: Simo &
//! Hughes, *Computational Inelasticity*, §1.2 (1-D frictional model, return mapping).

/// Per-element state that persists between steps.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct LinkState {
    /// Slider slip (x, y) [m].
    pub slip: [f64; 2],
    /// Energy dissipated by the dashpots [J].
    pub damping_energy: f64,
    /// Energy dissipated by the slider [J].
    pub friction_energy: f64,
}

/// Constant link properties.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LinkProps {
    pub k: [f64; 3],
    pub c: [f64; 3],
    /// Slip force; `f64::INFINITY` when the link has no slider.
    pub slip_force: f64,
}

/// Relative displacement d = (x₂ − x₁) − d₀.
#[inline(always)]
pub fn rel_disp(x1: &[f64; 3], x2: &[f64; 3], d0: &[f64; 3]) -> [f64; 3] {
    [
        x2[0] - x1[0] - d0[0],
        x2[1] - x1[1] - d0[1],
        x2[2] - x1[2] - d0[2],
    ]
}

/// Force on node 2 at the current positions and half-step velocities; advances the
/// slider and the dissipated energies in `state` (call once per time step).
/// `dt_prev` is the step Δt^{n−½} over which the velocities v^{n−½} acted.
#[inline(always)]
pub fn force_update(
    d: &[f64; 3],
    ddot: &[f64; 3],
    p: &LinkProps,
    state: &mut LinkState,
    dt_prev: f64,
) -> [f64; 3] {
    let mut ft = [
        -p.k[0] * (d[0] - state.slip[0]),
        -p.k[1] * (d[1] - state.slip[1]),
    ];
    if p.slip_force.is_finite() {
        let mag = (ft[0] * ft[0] + ft[1] * ft[1]).sqrt();
        if mag > p.slip_force {
            let r = p.slip_force / mag;
            ft = [ft[0] * r, ft[1] * r];
            let s_new = [d[0] + ft[0] / p.k[0], d[1] + ft[1] / p.k[1]];
            let ds = [s_new[0] - state.slip[0], s_new[1] - state.slip[1]];
            state.friction_energy -= ft[0] * ds[0] + ft[1] * ds[1];
            state.slip = s_new;
        }
    }
    let fd = [-p.c[0] * ddot[0], -p.c[1] * ddot[1], -p.c[2] * ddot[2]];
    state.damping_energy -= dt_prev * (fd[0] * ddot[0] + fd[1] * ddot[1] + fd[2] * ddot[2]);
    [ft[0] + fd[0], ft[1] + fd[1], -p.k[2] * d[2] + fd[2]]
}

/// Elastic force only (no dashpot, no slider update): the force the stored energy
/// [`energy`] derives, at a fixed slip.
#[inline(always)]
pub fn elastic_force(d: &[f64; 3], p: &LinkProps, slip: &[f64; 2]) -> [f64; 3] {
    [
        -p.k[0] * (d[0] - slip[0]),
        -p.k[1] * (d[1] - slip[1]),
        -p.k[2] * d[2],
    ]
}

/// Stored elastic energy ½ Σ k (d − s)² [J].
#[inline(always)]
pub fn energy(d: &[f64; 3], p: &LinkProps, slip: &[f64; 2]) -> f64 {
    let ex = d[0] - slip[0];
    let ey = d[1] - slip[1];
    0.5 * (p.k[0] * ex * ex + p.k[1] * ey * ey + p.k[2] * d[2] * d[2])
}

// ---------------------------------------------------------------------------------------
// The link family.

use rayon::prelude::*;

use super::family::{
    chunk_partials, Build, EnergyGroup, EnergyPartial, Family, ForceCtx, StiffCtx, CHUNK,
};
use crate::error::Result;
use crate::model::ElementKind;

/// Links, struct-of-arrays.
#[derive(Debug, Clone, Default)]
pub struct LinkGroup {
    pub id: Vec<i64>,
    pub nodes: Vec<[u32; 2]>,
    pub props: Vec<LinkProps>,
    /// Initial offset X₂ − X₁ [m].
    pub d0: Vec<[f64; 3]>,
    pub state: Vec<LinkState>,
    partials: Vec<EnergyPartial>,
}

impl Family for LinkGroup {
    const KIND: ElementKind = ElementKind::Link;
    const SLOTS: usize = 2;
    const GROUP: EnergyGroup = EnergyGroup::Line;

    fn build(bd: &mut Build) -> Result<Self> {
        let m = bd.model;
        let mut g = LinkGroup::default();
        let Some(b) = m.block(ElementKind::Link) else {
            return Ok(g);
        };
        for e in 0..b.len() {
            let p = &m.parts[b.part[e]].props;
            let (a, c) = (b.nodes[2 * e], b.nodes[2 * e + 1]);
            let z = |v: Option<f64>| v.unwrap_or(0.0);
            g.id.push(b.id[e]);
            g.nodes.push([a as u32, c as u32]);
            g.props.push(LinkProps {
                k: [z(p.kx), z(p.ky), z(p.kz)],
                c: [z(p.cx), z(p.cy), z(p.cz)],
                slip_force: p.slip_force.unwrap_or(f64::INFINITY),
            });
            g.d0.push(super::vec3::sub(&m.coords[c], &m.coords[a]));
            g.state.push(LinkState::default());
        }
        Ok(g)
    }
    fn len(&self) -> usize {
        self.id.len()
    }
    fn id(&self, e: usize) -> i64 {
        self.id[e]
    }
    fn slot_nodes(&self, e: usize) -> &[u32] {
        &self.nodes[e]
    }
    fn stiffness(&self, e: usize) -> f64 {
        let p = &self.props[e];
        p.k.iter().chain(p.c.iter()).cloned().fold(0.0, f64::max)
    }
    fn forces(&mut self, ctx: &ForceCtx, fe: &mut [[f64; 3]]) {
        let (x, v, dt_prev) = (ctx.x, ctx.v, ctx.dt_prev);
        let (nodes, props, d0) = (&self.nodes, &self.props, &self.d0);
        let body = |(ci, (out, st)): (usize, (&mut [[f64; 3]], &mut [LinkState]))| {
            let e0 = ci * CHUNK;
            for (j, (pair, s)) in out.chunks_exact_mut(2).zip(st.iter_mut()).enumerate() {
                let e = e0 + j;
                let [a, b] = nodes[e];
                let (a, b) = (a as usize, b as usize);
                let d = rel_disp(&x[a], &x[b], &d0[e]);
                let dd = [v[b][0] - v[a][0], v[b][1] - v[a][1], v[b][2] - v[a][2]];
                let f2 = force_update(&d, &dd, &props[e], s, dt_prev);
                pair[0] = [-f2[0], -f2[1], -f2[2]];
                pair[1] = f2;
            }
        };
        if self.id.len() <= CHUNK {
            fe.chunks_mut(2 * CHUNK)
                .zip(self.state.chunks_mut(CHUNK))
                .enumerate()
                .for_each(body);
        } else {
            fe.par_chunks_mut(2 * CHUNK)
                .zip(self.state.par_chunks_mut(CHUNK))
                .enumerate()
                .for_each(body);
        }
    }
    fn stiffness_sums(&self, ctx: &StiffCtx, s: &mut [f64], c: &mut [f64], _r: &mut [f64]) {
        let w = |other: u32| {
            if ctx.fixed[other as usize] == 0b111 {
                1.0
            } else {
                2.0
            }
        };
        for (e, p) in self.nodes.iter().enumerate() {
            let pr = &self.props[e];
            let kmax = pr.k.iter().cloned().fold(0.0, f64::max);
            let cmax = pr.c.iter().cloned().fold(0.0, f64::max);
            for (n, o) in [(p[0], p[1]), (p[1], p[0])] {
                s[n as usize] += w(o) * kmax;
                c[n as usize] += w(o) * cmax;
            }
        }
    }
    fn energies(&mut self, ctx: &ForceCtx) -> &[EnergyPartial] {
        let (x, nodes, d0, props, state) = (ctx.x, &self.nodes, &self.d0, &self.props, &self.state);
        chunk_partials(&mut self.partials, nodes.len(), |r| {
            let mut acc = [0.0; 4];
            for k in r {
                let [a, b] = nodes[k];
                let d = rel_disp(&x[a as usize], &x[b as usize], &d0[k]);
                acc[0] += energy(&d, &props[k], &state[k].slip);
                acc[1] += state[k].damping_energy;
                acc[2] += state[k].friction_energy;
            }
            acc
        });
        &self.partials
    }
}

impl LinkGroup {
    /// Current force of every link on its node 2 at the positions `x`: spring and
    /// slider (the slider return-mapped on a copy of its state), without the dashpot.
    pub fn elastic_forces(&self, x: &[[f64; 3]]) -> Vec<[f64; 3]> {
        (0..self.id.len())
            .map(|e| {
                let [a, b] = self.nodes[e];
                let d = rel_disp(&x[a as usize], &x[b as usize], &self.d0[e]);
                let mut st = self.state[e];
                force_update(&d, &[0.0; 3], &self.props[e], &mut st, 0.0)
            })
            .collect()
    }
}
