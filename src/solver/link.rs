//! Two-node discrete link: a spring and a dashpot per axis and an optional friction
//! slider in the tangential (x–y) plane; the axes are global, or a local frame that
//! follows the fabric.
//!
//! Glossary: d = (x₂ − x₁) − (X₂ − X₁) relative displacement [m] (the initial offset
//! X₂ − X₁ is removed, so the nodes need not coincide); ḋ = v₂ − v₁ relative velocity
//! [m/s]; k = (k_x, k_y, k_z) [N/m]; c = (c_x, c_y, c_z) [N·s/m]; s = (s_x, s_y) slip of
//! the slider [m]; F_s slip force [N]; μ Coulomb coefficient; N normal force [N];
//! R = [e₁ e₂ n]ᵀ the link's frame (rows), I in global axes.
//!
//! Axes. Global: d and ḋ as above, in x, y, z. Local (`local_frame`): the frame of the
//! crossing, rebuilt each step from four frame nodes, e₁ = (x_f2 − x_f1)/|·| (the warp),
//! n = e₁ × (x_f4 − x_f3)/|·| (the normal to the two yarn directions), e₂ = n × e₁; the
//! link works on the components d = R (x₂ − x₁) − R₀ (X₂ − X₁), ḋ = R (v₂ − v₁), R₀ the
//! frame at the reference coordinates, and its force goes back to global axes as Rᵀ f.
//! A rigid motion of the crossing gives d = 0 and no force, so a tilted fabric slides in
//! its own plane against k_x, k_y only (in global axes a slide along a tilted yarn has a
//! z component that k_z locks). The frame nodes take no force: the frame is kinematic
//! (for coincident link nodes the force pair has no moment). The neglected terms, of
//! order (K d)·(Ω d) for a frame turning at Ω, are not zero when k_z ≠ k_x: in the
//! reduced woven model's impact (crimp 50 µm, 10 µs) the energy ledger's error was
//! 0.028 J of the 160 J impact with local links against 8·10⁻⁴ J with global ones
//! (measured), far inside the 1 % the runs are held to.
//!
//! Force on node 2 (node 1 gets the opposite), in the link's axes:
//! - normal (z): spring f_n = −k_z d_z; unilateral (`unilateral`): the spring pushes and
//!   never pulls, f_n = −k_z min(d_z, 0) (node 1 is the lower yarn, node 2 the upper:
//!   d_z < 0 presses them together), and the dashpot acts only while d_z < 0, clipped so
//!   that the normal force −k_z d_z − c_z ḋ_z stays ≥ 0;
//! - tangential (x, y): the spring acts on the elastic part d − s; trial force
//!   f_t = −k ∘ (d_t − s); if |f_t| > F_lim the slider slips: f_t is returned radially
//!   to |f_t| = F_lim and s is updated so that f_t = −k ∘ (d_t − s) holds (elastic–
//!   perfectly-plastic); F_lim = F_s (`slip_force`, a constant limit) or μ·N
//!   (`friction`, Coulomb) with N = max(0, spring part of f_n), the compressive normal
//!   spring force at this step; the dashpot adds −c ∘ ḋ_t.
//!
//! Energy: stored W = ½ Σ k (d − s)² (s = 0 along z; min(d_z, 0) for a unilateral
//! spring); dissipated by the slider Σ −f_t·Δs; by the dashpots Σ Δt f_d·ḋ with ḋ the
//! half-step velocity v^{n−½} the explicit scheme uses.
//!
//! In global axes the link is exact for coincident nodes (the yarn crossings of the
//! reduced woven model), where a rigid rotation gives d = 0 and no force; links between
//! distant nodes are not rotation invariant unless local. Reference for the slider: Simo
//! & Hughes, *Computational Inelasticity*, §1.2 (1-D frictional model, return mapping);
//! for Coulomb friction with a penalty normal: Wriggers, *Computational Contact
//! Mechanics*, §5.2 (slip at μ·p_N, return mapping of the tangential trial force).

use super::vec3::{cross, mv, sub, unit, Mat3, Vec3};

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

/// The link's law beyond its springs, dashpots and constant slip force.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct LinkLaw {
    /// Coulomb coefficient μ: the slider's limit is μ·N (`None`: the constant
    /// `LinkProps::slip_force`).
    pub friction: Option<f64>,
    /// The normal spring and dashpot push, never pull.
    pub unilateral: bool,
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

/// Force on node 2 at the current positions and half-step velocities (global axes,
/// two-way normal spring, constant slip force); advances the slider and the dissipated
/// energies in `state` (call once per time step). `dt_prev` is the step Δt^{n−½} over
/// which the velocities v^{n−½} acted.
#[inline(always)]
pub fn force_update(
    d: &[f64; 3],
    ddot: &[f64; 3],
    p: &LinkProps,
    state: &mut LinkState,
    dt_prev: f64,
) -> [f64; 3] {
    force_update_law(d, ddot, p, &LinkLaw::default(), state, dt_prev)
}

/// The normal spring force f_n = −k_z d_z, or −k_z min(d_z, 0) when unilateral.
#[inline(always)]
fn normal_spring(dz: f64, kz: f64, unilateral: bool) -> f64 {
    if unilateral && dz >= 0.0 {
        0.0
    } else {
        -kz * dz
    }
}

/// [`force_update`] with a law: Coulomb friction and a unilateral normal (see the module
/// docs). `d` and `ddot` are in the link's axes (global or local); so is the force.
#[inline(always)]
pub fn force_update_law(
    d: &[f64; 3],
    ddot: &[f64; 3],
    p: &LinkProps,
    law: &LinkLaw,
    state: &mut LinkState,
    dt_prev: f64,
) -> [f64; 3] {
    let fn_spring = normal_spring(d[2], p.k[2], law.unilateral);
    let limit = match law.friction {
        Some(mu) => mu * fn_spring.max(0.0),
        None => p.slip_force,
    };
    let mut ft = [
        -p.k[0] * (d[0] - state.slip[0]),
        -p.k[1] * (d[1] - state.slip[1]),
    ];
    if limit.is_finite() {
        let mag = (ft[0] * ft[0] + ft[1] * ft[1]).sqrt();
        if mag > limit {
            let r = limit / mag;
            ft = [ft[0] * r, ft[1] * r];
            let s_new = [d[0] + ft[0] / p.k[0], d[1] + ft[1] / p.k[1]];
            let ds = [s_new[0] - state.slip[0], s_new[1] - state.slip[1]];
            state.friction_energy -= ft[0] * ds[0] + ft[1] * ds[1];
            state.slip = s_new;
        }
    }
    let mut fd = [-p.c[0] * ddot[0], -p.c[1] * ddot[1], -p.c[2] * ddot[2]];
    if law.unilateral {
        // In contact only, and never pulling: −c ḋ ≥ −f_n.
        fd[2] = if d[2] < 0.0 {
            fd[2].max(-fn_spring)
        } else {
            0.0
        };
    }
    state.damping_energy -= dt_prev * (fd[0] * ddot[0] + fd[1] * ddot[1] + fd[2] * ddot[2]);
    [ft[0] + fd[0], ft[1] + fd[1], fn_spring + fd[2]]
}

/// Elastic force only (no dashpot, no slider update): the force the stored energy
/// [`energy`] derives, at a fixed slip.
#[inline(always)]
pub fn elastic_force(d: &[f64; 3], p: &LinkProps, slip: &[f64; 2]) -> [f64; 3] {
    elastic_force_law(d, p, &LinkLaw::default(), slip)
}

/// [`elastic_force`] with a law (a unilateral normal spring).
#[inline(always)]
pub fn elastic_force_law(d: &[f64; 3], p: &LinkProps, law: &LinkLaw, slip: &[f64; 2]) -> [f64; 3] {
    [
        -p.k[0] * (d[0] - slip[0]),
        -p.k[1] * (d[1] - slip[1]),
        normal_spring(d[2], p.k[2], law.unilateral),
    ]
}

/// Stored elastic energy ½ Σ k (d − s)² [J].
#[inline(always)]
pub fn energy(d: &[f64; 3], p: &LinkProps, slip: &[f64; 2]) -> f64 {
    energy_law(d, p, &LinkLaw::default(), slip)
}

/// [`energy`] with a law: a unilateral normal spring stores ½ k_z min(d_z, 0)².
#[inline(always)]
pub fn energy_law(d: &[f64; 3], p: &LinkProps, law: &LinkLaw, slip: &[f64; 2]) -> f64 {
    let ex = d[0] - slip[0];
    let ey = d[1] - slip[1];
    let ez = if law.unilateral { d[2].min(0.0) } else { d[2] };
    0.5 * (p.k[0] * ex * ex + p.k[1] * ey * ey + p.k[2] * ez * ez)
}

/// The local frame R = [e₁ e₂ n]ᵀ (rows) of two directions: e₁ = u/|u|,
/// n = u × w/|u × w|, e₂ = n × e₁; `None` when u = 0 or u ∥ w.
#[inline(always)]
pub fn local_frame(u: &Vec3, w: &Vec3) -> Option<Mat3> {
    let e1 = unit(*u)?;
    let n = unit(cross(u, w))?;
    Some([e1, cross(&n, &e1), n])
}

/// Global components Rᵀ f of local components f.
#[inline(always)]
pub fn to_global(r: &Mat3, f: &Vec3) -> Vec3 {
    std::array::from_fn(|i| r[0][i] * f[0] + r[1][i] * f[1] + r[2][i] * f[2])
}

/// The frame of link `f` (frame nodes) at positions `x`; `r0` where it degenerates.
#[inline(always)]
fn frame_at(x: &[Vec3], f: &[u32; 4], r0: &Mat3) -> Mat3 {
    let u = sub(&x[f[1] as usize], &x[f[0] as usize]);
    let w = sub(&x[f[3] as usize], &x[f[2] as usize]);
    local_frame(&u, &w).unwrap_or(*r0)
}

// ---------------------------------------------------------------------------------------
// The link family.

use rayon::prelude::*;

use super::family::{
    chunk_partials, Build, EnergyGroup, EnergyPartial, Family, ForceCtx, StiffCtx, CHUNK,
};
use crate::error::Result;
use crate::model::ElementKind;

/// A link's local frame: its frame nodes and the frame R₀ at the reference coordinates.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FrameRef {
    pub nodes: [u32; 4],
    pub r0: Mat3,
}

/// The stiffnesses the stable-step bound takes for a link: k, with a unilateral normal
/// spring's k_z counted 4 × (half the step). Why: a unilateral spring closes and opens
/// within a step or two when ω Δt is near the central difference's limit 2, and such
/// short contacts return more energy than they took (the discrete bounce's
/// restitution exceeds 1; the reduced woven model with unilateral links gained 3.1 J of
/// its 160 J impact at ω Δt ≈ 1.8, and 8·10⁻³ J at half that step, measured); at
/// ω Δt ≤ 0.9 a contact lasts ≥ 3 steps.
#[inline(always)]
fn bound_stiffness(p: &LinkProps, law: &LinkLaw) -> [f64; 3] {
    if law.unilateral {
        [p.k[0], p.k[1], 4.0 * p.k[2]]
    } else {
        p.k
    }
}

/// Links, struct-of-arrays.
#[derive(Debug, Clone, Default)]
pub struct LinkGroup {
    pub id: Vec<i64>,
    pub nodes: Vec<[u32; 2]>,
    pub props: Vec<LinkProps>,
    /// The law of each link; empty when every link has the default law (so that plain
    /// links read no more memory per step than before).
    pub law: Vec<LinkLaw>,
    /// The local frame of each link (`None`: global axes); empty when no link has one.
    pub frame: Vec<Option<FrameRef>>,
    /// Initial offset X₂ − X₁ [m], in the link's axes (R₀ (X₂ − X₁) for a local frame).
    pub d0: Vec<[f64; 3]>,
    pub state: Vec<LinkState>,
    partials: Vec<EnergyPartial>,
}

const DEFAULT_LAW: LinkLaw = LinkLaw {
    friction: None,
    unilateral: false,
};

/// The law of link `e` (the default when the group stores none).
#[inline(always)]
fn law_of(law: &[LinkLaw], e: usize) -> &LinkLaw {
    law.get(e).unwrap_or(&DEFAULT_LAW)
}

/// The frame of link `e` at positions `x` (`None`: global axes).
#[inline(always)]
fn frame_of(frame: &[Option<FrameRef>], e: usize, x: &[Vec3]) -> Option<Mat3> {
    match frame.get(e) {
        Some(Some(f)) => Some(frame_at(x, &f.nodes, &f.r0)),
        _ => None,
    }
}

/// Relative displacement of link nodes `a`, `b` in the link's axes.
#[inline(always)]
fn rel_disp_in(r: &Option<Mat3>, x: &[Vec3], a: usize, b: usize, d0: &Vec3) -> Vec3 {
    match r {
        None => rel_disp(&x[a], &x[b], d0),
        Some(r) => sub(&mv(r, &sub(&x[b], &x[a])), d0),
    }
}

/// A vector in the link's axes back in global axes.
#[inline(always)]
fn global_in(r: &Option<Mat3>, f: Vec3) -> Vec3 {
    match r {
        None => f,
        Some(r) => to_global(r, &f),
    }
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
            g.law.push(LinkLaw {
                friction: p.friction,
                unilateral: p.unilateral == Some(true),
            });
            let d0 = sub(&m.coords[c], &m.coords[a]);
            let frame = if p.local_frame == Some(true) {
                // `Model::validate` checked that the frame nodes span a plane.
                let f = b.frame[e];
                let x = |k: usize| m.coords[f[k]];
                let r0 = local_frame(&sub(&x(1), &x(0)), &sub(&x(3), &x(2)))
                    .expect("validated frame nodes");
                Some(FrameRef {
                    nodes: f.map(|n| n as u32),
                    r0,
                })
            } else {
                None
            };
            g.d0.push(match &frame {
                Some(f) => mv(&f.r0, &d0),
                None => d0,
            });
            g.frame.push(frame);
            g.state.push(LinkState::default());
        }
        if g.law.iter().all(|l| *l == DEFAULT_LAW) {
            g.law.clear();
        }
        if g.frame.iter().all(|f| f.is_none()) {
            g.frame.clear();
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
        let k = bound_stiffness(p, law_of(&self.law, e));
        k.iter().chain(p.c.iter()).cloned().fold(0.0, f64::max)
    }
    fn forces(&mut self, ctx: &ForceCtx, fe: &mut [[f64; 3]]) {
        let (x, v, dt_prev) = (ctx.x, ctx.v, ctx.dt_prev);
        let (nodes, props, law, frame, d0) =
            (&self.nodes, &self.props, &self.law, &self.frame, &self.d0);
        // Plain links (global axes, default law: the group stores neither) take the
        // kernel without the per-link law and frame look-ups, as before those options
        // existed (with the look-ups the link benchmark ran 15–25 % slower on a shared
        // 2-core machine; with this path, best of 6: 5.8·10⁷ against 6.2·10⁷ updates/s
        // before, within that machine's noise).
        let plain = law.is_empty() && frame.is_empty();
        let body = |(ci, (out, st)): (usize, (&mut [[f64; 3]], &mut [LinkState]))| {
            let e0 = ci * CHUNK;
            if plain {
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
                return;
            }
            for (j, (pair, s)) in out.chunks_exact_mut(2).zip(st.iter_mut()).enumerate() {
                let e = e0 + j;
                let [a, b] = nodes[e];
                let (a, b) = (a as usize, b as usize);
                let r = frame_of(frame, e, x);
                let d = rel_disp_in(&r, x, a, b, &d0[e]);
                let dd = [v[b][0] - v[a][0], v[b][1] - v[a][1], v[b][2] - v[a][2]];
                let dd = match &r {
                    None => dd,
                    Some(r) => mv(r, &dd),
                };
                let f2 = global_in(
                    &r,
                    force_update_law(&d, &dd, &props[e], law_of(law, e), s, dt_prev),
                );
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
            let kmax = bound_stiffness(pr, law_of(&self.law, e))
                .iter()
                .cloned()
                .fold(0.0, f64::max);
            let cmax = pr.c.iter().cloned().fold(0.0, f64::max);
            for (n, o) in [(p[0], p[1]), (p[1], p[0])] {
                s[n as usize] += w(o) * kmax;
                c[n as usize] += w(o) * cmax;
            }
        }
    }
    fn energies(&mut self, ctx: &ForceCtx) -> &[EnergyPartial] {
        let (x, nodes, d0, props, state) = (ctx.x, &self.nodes, &self.d0, &self.props, &self.state);
        let (law, frame) = (&self.law, &self.frame);
        chunk_partials(&mut self.partials, nodes.len(), |r| {
            let mut acc = [0.0; 4];
            for k in r {
                let [a, b] = nodes[k];
                let rf = frame_of(frame, k, x);
                let d = rel_disp_in(&rf, x, a as usize, b as usize, &d0[k]);
                acc[0] += energy_law(&d, &props[k], law_of(law, k), &state[k].slip);
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
                let r = frame_of(&self.frame, e, x);
                let d = rel_disp_in(&r, x, a as usize, b as usize, &self.d0[e]);
                let mut st = self.state[e];
                global_in(
                    &r,
                    force_update_law(
                        &d,
                        &[0.0; 3],
                        &self.props[e],
                        law_of(&self.law, e),
                        &mut st,
                        0.0,
                    ),
                )
            })
            .collect()
    }

    /// The force on node 2 of link `e` with its nodes at `x1`, `x2` and its frame at the
    /// reference (R₀): springs only, a unilateral normal linearised as closed, no slip.
    /// What the linear statics assembles (by finite differences about the reference).
    pub fn reference_force(&self, e: usize, x1: &Vec3, x2: &Vec3) -> Vec3 {
        let r = self.frame.get(e).copied().flatten().map(|f| f.r0);
        let d = match &r {
            None => rel_disp(x1, x2, &self.d0[e]),
            Some(r) => sub(&mv(r, &sub(x2, x1)), &self.d0[e]),
        };
        global_in(&r, elastic_force(&d, &self.props[e], &[0.0; 2]))
    }

    /// Local frame R = [e₁ e₂ n]ᵀ of link `e` at positions `x`; `None` in global axes.
    pub fn frame_at(&self, e: usize, x: &[Vec3]) -> Option<Mat3> {
        frame_of(&self.frame, e, x)
    }
}
