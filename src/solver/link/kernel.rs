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
//! z component that k_z locks). The frame nodes take the reaction of the turning frame:
//! every node's force is minus the gradient of the stored energy W(d(x)) through R too
//! (see [`framed_force_update`]), so the link is conservative and objective. (With the
//! frame nodes left out, as a kinematic frame, the work of the neglected terms, of order
//! (K d)·(Ω d) when k_z ≠ k_x, made the reduced woven model's impact with 50 µm crimp
//! unstable at 17 µs, measured.) Local links form their own family, six force slots per
//! link; links in global axes keep two.
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

use crate::model::PartProps;
use crate::solver::vec3::{cross, dot, mv, norm, scale, sub, unit, Mat3, Vec3};

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
pub(crate) fn normal_spring(dz: f64, kz: f64, unilateral: bool) -> f64 {
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
    let (fs, fd) = force_update_parts(d, ddot, p, law, state, dt_prev);
    [fs[0] + fd[0], fs[1] + fd[1], fs[2] + fd[2]]
}

/// [`force_update_law`] in its two parts: the elastic force (springs after the slider's
/// return mapping, −∂W/∂d at the updated slip) and the dashpots'.
#[inline(always)]
pub fn force_update_parts(
    d: &[f64; 3],
    ddot: &[f64; 3],
    p: &LinkProps,
    law: &LinkLaw,
    state: &mut LinkState,
    dt_prev: f64,
) -> ([f64; 3], [f64; 3]) {
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
    ([ft[0], ft[1], fn_spring], fd)
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

/// Positions of a framed link: node 1, node 2, frame nodes f1…f4.
pub type FramedX = [Vec3; 6];

/// The local frame's kinematics of a framed link at positions `x`: R (rows e₁, e₂, n),
/// r = x₂ − x₁, u = x_f2 − x_f1, w = x_f4 − x_f3, |u|, c = u × w, |c|.
pub(crate) struct FrameKin {
    pub(crate) r_mat: Mat3,
    pub(crate) r: Vec3,
    u: Vec3,
    w: Vec3,
    pub(crate) lu: f64,
    lc: f64,
}

#[inline(always)]
pub(crate) fn frame_kin(x: &FramedX) -> Option<FrameKin> {
    let r = sub(&x[1], &x[0]);
    let u = sub(&x[3], &x[2]);
    let w = sub(&x[5], &x[4]);
    let lu = norm(&u);
    let c = cross(&u, &w);
    let lc = norm(&c);
    if !(lu > 0.0 && lc > 0.0) {
        return None;
    }
    let e1 = scale(&u, 1.0 / lu);
    let n = scale(&c, 1.0 / lc);
    Some(FrameKin {
        r_mat: [e1, cross(&n, &e1), n],
        r,
        u,
        w,
        lu,
        lc,
    })
}

/// Relative displacement of a framed link in its axes, d = R r − d₀ (`None` where the
/// frame degenerates).
#[inline(always)]
pub fn framed_rel_disp(x: &FramedX, d0: &Vec3) -> Option<Vec3> {
    let k = frame_kin(x)?;
    Some(sub(&mv(&k.r_mat, &k.r), d0))
}

/// Forces on the six nodes of a framed link from its elastic force `fs` in its axes
/// (fs = −∂W/∂d): the exact gradient of W(x) = W(d(x)), d = R(u, w) r − d₀, so that the
/// link is conservative and objective (no force or moment under rigid motion) although
/// its frame turns. With g = −fs (g = ∂W/∂d), e₂·r = n·(e₁ × r):
/// - node 2: −Σ gᵢ eᵢ, node 1 the opposite;
/// - ∂W/∂u = g₁ P₁ r/|u| + g₂ (P₁ (r × n)/|u| + w × q₂) + g₃ w × q₃, with
///   P₁ = I − e₁e₁ᵀ, q₂ = Pₙ (e₁ × r)/|u × w|, q₃ = Pₙ r/|u × w|, Pₙ = I − nnᵀ;
/// - ∂W/∂w = g₂ q₂ × u + g₃ q₃ × u;
/// - f2 −∂W/∂u, f1 +∂W/∂u, f4 −∂W/∂w, f3 +∂W/∂w.
///
/// Forces sum to zero, and their moment too (W is rotation invariant). The dashpot
/// force `fd` (in the link's axes) acts on nodes 1 and 2 only.
#[inline(always)]
pub(crate) fn framed_node_forces(k: &FrameKin, fs: &Vec3, fd: &Vec3) -> [Vec3; 6] {
    let [e1, _e2, n] = k.r_mat;
    let g = [-fs[0], -fs[1], -fs[2]];
    let ftot = [fs[0] + fd[0], fs[1] + fd[1], fs[2] + fd[2]];
    let f2 = to_global(&k.r_mat, &ftot);
    let p1 = |a: &Vec3| {
        let t = dot(&e1, a);
        [a[0] - t * e1[0], a[1] - t * e1[1], a[2] - t * e1[2]]
    };
    let pn = |a: &Vec3| {
        let t = dot(&n, a);
        let s = 1.0 / k.lc;
        [
            (a[0] - t * n[0]) * s,
            (a[1] - t * n[1]) * s,
            (a[2] - t * n[2]) * s,
        ]
    };
    let q2 = pn(&cross(&e1, &k.r));
    let q3 = pn(&k.r);
    let a1 = p1(&k.r);
    let a2 = p1(&cross(&k.r, &n));
    let w_q2 = cross(&k.w, &q2);
    let w_q3 = cross(&k.w, &q3);
    let q2_u = cross(&q2, &k.u);
    let q3_u = cross(&q3, &k.u);
    let inv_lu = 1.0 / k.lu;
    let gu: Vec3 = std::array::from_fn(|i| {
        g[0] * a1[i] * inv_lu + g[1] * (a2[i] * inv_lu + w_q2[i]) + g[2] * w_q3[i]
    });
    let gw: Vec3 = std::array::from_fn(|i| g[1] * q2_u[i] + g[2] * q3_u[i]);
    [
        [-f2[0], -f2[1], -f2[2]],
        f2,
        gu,
        [-gu[0], -gu[1], -gu[2]],
        gw,
        [-gw[0], -gw[1], -gw[2]],
    ]
}

/// Forces on the six nodes of a framed link (node 1, node 2, f1…f4) at positions `x`
/// and velocities `v` (v^{n−½}); advances the slider and the dissipated energies (call
/// once per step). The dashpots act on ḋ = R (v₂ − v₁). Where the frame degenerates
/// (u = 0 or u ∥ w) the link exerts no force.
#[inline(always)]
pub fn framed_force_update(
    x: &FramedX,
    v: &[Vec3; 2],
    d0: &Vec3,
    p: &LinkProps,
    law: &LinkLaw,
    state: &mut LinkState,
    dt_prev: f64,
) -> [Vec3; 6] {
    let Some(k) = frame_kin(x) else {
        return [[0.0; 3]; 6];
    };
    let d = sub(&mv(&k.r_mat, &k.r), d0);
    let dd = mv(&k.r_mat, &sub(&v[1], &v[0]));
    let (fs, fd) = force_update_parts(&d, &dd, p, law, state, dt_prev);
    framed_node_forces(&k, &fs, &fd)
}

/// The elastic forces (no dashpot, slip fixed) on the six nodes of a framed link: minus
/// the gradient of [`energy_law`] at d = R r − d₀.
#[inline(always)]
pub fn framed_elastic_forces(
    x: &FramedX,
    d0: &Vec3,
    p: &LinkProps,
    law: &LinkLaw,
    slip: &[f64; 2],
) -> [Vec3; 6] {
    let Some(k) = frame_kin(x) else {
        return [[0.0; 3]; 6];
    };
    let d = sub(&mv(&k.r_mat, &k.r), d0);
    let fs = elastic_force_law(&d, p, law, slip);
    framed_node_forces(&k, &fs, &[0.0; 3])
}

/// The stiffnesses the stable-step bound takes for a link: k, with a unilateral normal
/// spring's k_z counted 4 × (half the step). Why: a unilateral spring closes and opens
/// within a step or two when ω Δt is near the central difference's limit 2, and such
/// short contacts return more energy than they took (the discrete bounce's
/// restitution exceeds 1; the reduced woven model with unilateral links gained 3.1 J of
/// its 160 J impact at ω Δt ≈ 1.8, and 8·10⁻³ J at half that step, measured); at
/// ω Δt ≤ 0.9 a contact lasts ≥ 3 steps.
#[inline(always)]
pub(crate) fn bound_stiffness(p: &LinkProps, law: &LinkLaw) -> [f64; 3] {
    if law.unilateral {
        [p.k[0], p.k[1], 4.0 * p.k[2]]
    } else {
        p.k
    }
}

pub(crate) const DEFAULT_LAW: LinkLaw = LinkLaw {
    friction: None,
    unilateral: false,
};

/// The law of link `e` (the default when the group stores none).
#[inline(always)]
pub(crate) fn law_of(law: &[LinkLaw], e: usize) -> &LinkLaw {
    law.get(e).unwrap_or(&DEFAULT_LAW)
}

/// A part's link constants and law.
pub(crate) fn link_props(p: &PartProps) -> (LinkProps, LinkLaw) {
    let z = |v: Option<f64>| v.unwrap_or(0.0);
    (
        LinkProps {
            k: [z(p.kx), z(p.ky), z(p.kz)],
            c: [z(p.cx), z(p.cy), z(p.cz)],
            slip_force: p.slip_force.unwrap_or(f64::INFINITY),
        },
        LinkLaw {
            friction: p.friction,
            unilateral: p.unilateral == Some(true),
        },
    )
}
