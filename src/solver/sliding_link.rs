//! Sliding crossing link: the link of [`super::link`] between two yarns that may slide
//! across each other, its ends material points of the yarns that move along them when
//! its slider slips.
//!
//! Glossary: yarn A is the chain of trusses through the link's node 1 (the lower yarn),
//! yarn B through node 2; a window is the stretch of a yarn within [`HALF`] nodes of the
//! link's node, X₀ … X_{L−1} in chain order; an end (anchor) is a point of a window at
//! the coordinate ξ ∈ [ξ_min, ξ_max] (node k at ξ = k), on segment s = ⌊ξ⌋ at
//! t = ξ − s: P(ξ) = (1 − t) X_s + t X_{s+1}; the chord of node k is
//! c_k = X_{k+1} − X_{k−1}, at a yarn's end X₂ − X₀ (the crimp's period is two segments,
//! so that chord is level where a one-sided one would tilt by the crimp's slope), or,
//! where that end lies on a symmetry plane across the yarn (the quarter model's centre
//! lines), the mirrored neighbour's 2ê ê·(X₁ − X₀), ê the plane's normal; the end's
//! tangent u(ξ) = (1 − t) c_s + t c_{s+1}, continuous along the yarn, kinks included;
//! r = P_B(ξ_B) − P_A(ξ_A); the frame R = [e₁ e₂ n]ᵀ of σ u_A and u_B as in
//! [`super::link::local_frame`] (σ = ±1 so that n points from node 1 towards node 2 at
//! the reference); d = R r − (d₀₁, d₀₂, g), d₀ = R₀ r₀ the reference offset and g the
//! normal spring's rest gap (d₀₃ at the start).
//!
//! Stick: the ends stay at their material points, and the link is the local-frame link
//! of [`super::link`] between two points of the yarns: W = ½ Σ k d² (a unilateral
//! normal as there), the force on every node minus ∂W/∂x (through P, the weights
//! (1 − t, t) of the segment nodes, and through R, the chord nodes: the frame's turn
//! with the lever |r|), the dashpots on ḋ = R (V_B − V_A) at the ends.
//!
//! Slip (Coulomb μ·N or a constant force, as [`super::link`]): when the trial tangential
//! force |−k ∘ d_t| exceeds its limit F, the ends move so that d_t comes back to the
//! limit (elastic–perfectly-plastic, radial return; Wriggers, *Computational Contact
//! Mechanics*, §5.2): moving end A by δ_A and B by δ_B changes r by δ_B g_B − δ_A g_A
//! (g = X_{s+1} − X_s), so δ solves the 2 × 2 system e_i·(δ_B g_B − δ_A g_A) = Δd_i,
//! i = 1, 2, repeated (at most [`SLIP_ITERATIONS`] times) while the frame and the segment
//! change under the move. An end stops at its window's reach (a yarn's end, or [`HALF`]
//! nodes away). The rest gap g moves with the ends so that the slip leaves d_z as it
//! was: a yarn's crimp is the zigzag of its nodes, and an end sliding from a crest down
//! a segment would otherwise open or close the gap by up to the crimp amplitude (k_z
//! times 0.1 mm: kN, and the reduced model's crossings then slid on their own, measured);
//! the crimp is carried with the crossing, and the normal spring reads what the yarns
//! press, wherever they cross. The slider dissipates what the slip releases at the
//! step's positions, W(x, ξ_old) − W(x, ξ_new), less the elastic predictor's overshoot
//! ½ Σ k Δd_t² (which no force did work for): μN·|Δd_t| on a straight yarn, the
//! two-node link's f·Δs.
//!
//! Why: a link between two nodes, as the paper's, measures its spring across the
//! distance its yarns have slid. In global axes a slide down the cone of a deflected
//! fabric has a z component that k_z locks; in the local frame of [`super::link`] the
//! normal spring reads n·r across a curved fabric, and the frame's turn acts with the
//! lever |r| on the frame nodes: with a slide of a millimetre at a 1 mm spacing the
//! reduced woven model's impact went unstable at 35–41 µs, and its stable step, bounded
//! for a slide of half a chord, was already 2.2 × shorter than the global links' (5.5
//! against 12.0 ns, measured). Here |r| stays the offset of the crossing, however far
//! the yarns slide.
//!
//! Stable step: each end's segment nodes take 2k·w (1 + [`CROWDING`]) (the weights w
//! sum to one), the chord nodes the frame's terms 4(ρ + ρ²) k w with ρ = |r|/|u|, at
//! the reference ends with |r| allowed to 2|d₀| (or [`LEVER_FLOOR`] of the chord);
//! [`Family::add_stiffening`] adds, every few steps of a run, what the ends where
//! they are add beyond that (yarns bunched closer than half a spacing, a link stretched
//! with its yarns in contact), to the same check as the membranes' stiffening, which
//! stops the run naming the link.

use super::family::{
    chunk_partials, for_chunks_of, Build, EnergyGroup, EnergyPartial, Family, ForceCtx, Per,
    StiffCtx, Stiffened, CHUNK,
};
use super::link::{
    bound_stiffness, energy_law, force_update_parts, frame_kin, framed_node_forces, link_props,
    normal_spring, FrameKin, LinkLaw, LinkProps, LinkState,
};
use super::vec3::{dot, mv, norm, scale, sub, Vec3};
use crate::error::{Result, WeftError};
use crate::model::ElementKind;

/// Nodes of a window on each side of the link's node (owned by the model, which builds
/// the windows: [`crate::model::yarn::HALF`]).
pub use crate::model::yarn::HALF;
/// Nodes of a window.
pub const WIN: usize = 2 * HALF + 1;
/// Return-mapping passes per step: the first is exact on straight segments under a
/// fixed frame; the others follow a change of segment or frame.
pub const SLIP_ITERATIONS: usize = 3;
/// The stable-step bound's least lever |r|, as a fraction of the chord: links whose
/// ends start together (d₀ = 0) still turn their frame with an elastic offset.
pub const LEVER_FLOOR: f64 = 0.05;
/// The share of a second link's end the bound allows on each node besides its own: a
/// yarn that slides half a spacing towards its neighbour puts half its crossing's
/// stiffness on the neighbour's node (the yarn-level reference's warps bunched to
/// 0.54 mm at a 1 mm spacing under the nose's rim by 50 µs, measured); closer bunching
/// stops the run with the link named ([`Family::add_stiffening`]).
pub const CROWDING: f64 = 0.5;

/// A window of a yarn as the kernel sees it: its length, whether its first and last
/// nodes end the yarn, and, where such an end lies on a symmetry plane across the yarn,
/// that plane's normal axis (the chord there is the mirrored neighbour's).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Window {
    pub len: usize,
    pub ends: [bool; 2],
    pub mirror: [Option<usize>; 2],
}

impl Window {
    /// The anchor's range [ξ_min, ξ_max]: to the yarn's end, or one node short of the
    /// window's reach (the chord there needs the node beyond).
    #[inline(always)]
    pub fn range(&self) -> (f64, f64) {
        let lo = if self.ends[0] { 0 } else { 1 };
        let hi = if self.ends[1] {
            self.len - 1
        } else {
            self.len - 2
        };
        (lo as f64, hi as f64)
    }

    /// The chord of window node k as (p, m, axis): c_k = X_p − X_m, or, on a symmetry
    /// plane of normal ê (axis), the mirrored neighbour's chord 2 ê ê·(X_p − X_m).
    #[inline(always)]
    pub fn chord(&self, k: usize) -> (usize, usize, Option<usize>) {
        let last = self.len - 1;
        if k == 0 && self.ends[0] {
            match self.mirror[0] {
                Some(ax) => (1, 0, Some(ax)),
                None => (2.min(last), 0, None),
            }
        } else if k == last && self.ends[1] {
            match self.mirror[1] {
                Some(ax) => (last, last - 1, Some(ax)),
                None => (last, last.saturating_sub(2), None),
            }
        } else {
            (k + 1, k - 1, None)
        }
    }

    /// The chord vector c_k at positions `x`.
    #[inline(always)]
    fn chord_vec(&self, x: &[Vec3; WIN], k: usize) -> Vec3 {
        let (p, m, axis) = self.chord(k);
        let c = sub(&x[p], &x[m]);
        match axis {
            Some(ax) => std::array::from_fn(|i| if i == ax { 2.0 * c[ax] } else { 0.0 }),
            None => c,
        }
    }

    /// Segment and parameter of the anchor ξ (clamped to the range).
    #[inline(always)]
    pub fn locate(&self, xi: f64) -> (usize, f64) {
        let (lo, hi) = self.range();
        let xi = xi.clamp(lo, hi);
        let s = (xi.floor() as usize).clamp(lo as usize, hi as usize - 1);
        (s, xi - s as f64)
    }
}

/// An anchor on a window: segment s at t, point P, tangent u (unnormalised), segment
/// vector g = X_{s+1} − X_s.
#[derive(Debug, Clone, Copy)]
struct Anchor {
    s: usize,
    t: f64,
    p: Vec3,
    u: Vec3,
    g: Vec3,
}

#[inline(always)]
fn lerp(a: &Vec3, b: &Vec3, t: f64) -> Vec3 {
    std::array::from_fn(|i| (1.0 - t) * a[i] + t * b[i])
}

#[inline(always)]
fn anchor(w: &Window, x: &[Vec3; WIN], xi: f64) -> Anchor {
    let (s, t) = w.locate(xi);
    Anchor {
        s,
        t,
        p: lerp(&x[s], &x[s + 1], t),
        u: lerp(&w.chord_vec(x, s), &w.chord_vec(x, s + 1), t),
        g: sub(&x[s + 1], &x[s]),
    }
}

/// The frame's kinematics at two anchors (None where it degenerates).
#[inline(always)]
fn kin(a: &Anchor, b: &Anchor, sigma: f64) -> Option<FrameKin> {
    frame_kin(&[a.p, b.p, [0.0; 3], scale(&a.u, sigma), [0.0; 3], b.u])
}

/// Per-link state that persists between steps.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct SlidingState {
    /// Anchor coordinates ξ_A, ξ_B in their windows.
    pub xi: [f64; 2],
    /// The normal spring's rest gap [m]: d₀'s normal part, carried along by the slips
    /// (see the module docs).
    pub gap: f64,
    /// Energy dissipated by the dashpots [J].
    pub damping_energy: f64,
    /// Energy dissipated by the slider [J].
    pub friction_energy: f64,
}

/// The constant description of one sliding link for the kernel.
#[derive(Debug, Clone, Copy)]
pub struct SlidingGeom {
    pub win: [Window; 2],
    /// Orientation of yarn A's tangent (±1): n from node 1 towards node 2.
    pub sigma: f64,
    /// Reference offset d₀ = R₀ r₀ at the reference anchors [m].
    pub d0: Vec3,
}

impl SlidingGeom {
    /// The rest offset: d₀'s tangential part and the rest gap of the state.
    #[inline(always)]
    fn rest(&self, st: &SlidingState) -> Vec3 {
        [self.d0[0], self.d0[1], st.gap]
    }
}

/// Positions (or velocities) of a link's two windows, A then B.
pub type SlidingX = [[Vec3; WIN]; 2];

/// Relative displacement d = R r − (d₀₁, d₀₂, gap) at the state's anchors (None where
/// the frame degenerates).
pub fn rel_disp(x: &SlidingX, g: &SlidingGeom, st: &SlidingState) -> Option<Vec3> {
    let a = anchor(&g.win[0], &x[0], st.xi[0]);
    let b = anchor(&g.win[1], &x[1], st.xi[1]);
    let k = kin(&a, &b, g.sigma)?;
    Some(sub(&mv(&k.r_mat, &k.r), &g.rest(st)))
}

/// Stored energy at the state's anchors [J].
pub fn energy(
    x: &SlidingX,
    g: &SlidingGeom,
    p: &LinkProps,
    law: &LinkLaw,
    st: &SlidingState,
) -> f64 {
    rel_disp(x, g, st).map_or(0.0, |d| energy_law(&d, p, law, &[0.0; 2]))
}

/// Forces on the window nodes (A's then B's) from the elastic force `fs` and the
/// dashpot force `fd` (the link's axes) at anchors `a`, `b`: minus ∂W/∂x through P and
/// through the chords (see the module docs).
#[inline(always)]
fn scatter(
    g: &SlidingGeom,
    a: &Anchor,
    b: &Anchor,
    k: &FrameKin,
    fs: &Vec3,
    fd: &Vec3,
    out: &mut [Vec3],
) {
    for f in out.iter_mut() {
        *f = [0.0; 3];
    }
    let six = framed_node_forces(k, fs, fd);
    // six: [on P_A, on P_B, ∂W/∂(σu_A), −, ∂W/∂u_B, −].
    for (side, (an, fp, gu, sg)) in [(a, six[0], six[2], g.sigma), (b, six[1], six[4], 1.0)]
        .into_iter()
        .enumerate()
    {
        let off = side * WIN;
        let w = &g.win[side];
        for i in 0..3 {
            out[off + an.s][i] += (1.0 - an.t) * fp[i];
            out[off + an.s + 1][i] += an.t * fp[i];
        }
        for (node, wk) in [(an.s, 1.0 - an.t), (an.s + 1, an.t)] {
            let (p, m, axis) = w.chord(node);
            for i in 0..3 {
                let f = match axis {
                    None => wk * sg * gu[i],
                    Some(ax) if ax == i => 2.0 * wk * sg * gu[i],
                    Some(_) => 0.0,
                };
                out[off + p][i] -= f;
                out[off + m][i] += f;
            }
        }
    }
}

/// The anchors' slides (Δξ_A, Δξ_B) along their yarns that move the link's tangential
/// offset d_t by δ = (r − 1) d_t (the radial return to r = F/|f_t| of it): the 2 × 2
/// system of the frame's tangents e₁, e₂ against the yarn tangents g_A, g_B at the
/// anchors. `None` when the yarn tangents are (nearly) parallel in the frame's plane.
#[inline]
fn anchor_slides(d: &Vec3, r: f64, k: &FrameKin, a: &Anchor, b: &Anchor) -> Option<(f64, f64)> {
    let delta = [d[0] * (r - 1.0), d[1] * (r - 1.0)];
    let [e1, e2, _] = k.r_mat;
    let m = [
        [-dot(&e1, &a.g), dot(&e1, &b.g)],
        [-dot(&e2, &a.g), dot(&e2, &b.g)],
    ];
    let det = m[0][0] * m[1][1] - m[0][1] * m[1][0];
    if !(det.abs() > 1e-12 * norm(&a.g) * norm(&b.g)) {
        return None;
    }
    let da = (delta[0] * m[1][1] - delta[1] * m[0][1]) / det;
    let db = (m[0][0] * delta[1] - m[1][0] * delta[0]) / det;
    Some((da, db))
}

/// Forces of a sliding link on its window nodes (`out`: A's [`WIN`] then B's) at
/// positions `x` and half-step velocities `v` (v^{n−½}); moves the anchors when the
/// slider slips and advances the dissipated energies (call once per step). `dt_prev` is
/// Δt^{n−½}. Where the frame degenerates the link exerts no force.
#[allow(clippy::too_many_arguments)]
pub fn force_update(
    x: &SlidingX,
    v: &SlidingX,
    g: &SlidingGeom,
    p: &LinkProps,
    law: &LinkLaw,
    st: &mut SlidingState,
    dt_prev: f64,
    out: &mut [Vec3],
) {
    let mut a = anchor(&g.win[0], &x[0], st.xi[0]);
    let mut b = anchor(&g.win[1], &x[1], st.xi[1]);
    let Some(mut k) = kin(&a, &b, g.sigma) else {
        out.iter_mut().for_each(|f| *f = [0.0; 3]);
        return;
    };
    let mut d = sub(&mv(&k.r_mat, &k.r), &g.rest(st));
    let limit_of = |d: &Vec3| match law.friction {
        Some(mu) => mu * normal_spring(d[2], p.k[2], law.unilateral).max(0.0),
        None => p.slip_force,
    };
    if limit_of(&d).is_finite() {
        let (w_before, d_before) = (energy_law(&d, p, law, &[0.0; 2]), d);
        let mut moved = false;
        for _ in 0..SLIP_ITERATIONS {
            let limit = limit_of(&d);
            let ft = [-p.k[0] * d[0], -p.k[1] * d[1]];
            let mag = ft[0].hypot(ft[1]);
            if mag <= limit * (1.0 + 1e-12) {
                break;
            }
            // Radial return: the elastic part comes back to d_t · F/|f_t|.
            let Some((da, db)) = anchor_slides(&d, limit / mag, &k, &a, &b) else {
                break;
            };
            let (lo_a, hi_a) = g.win[0].range();
            let (lo_b, hi_b) = g.win[1].range();
            let xi = [
                (st.xi[0] + da).clamp(lo_a, hi_a),
                (st.xi[1] + db).clamp(lo_b, hi_b),
            ];
            if xi == st.xi {
                break;
            }
            st.xi = xi;
            a = anchor(&g.win[0], &x[0], xi[0]);
            b = anchor(&g.win[1], &x[1], xi[1]);
            let Some(k2) = kin(&a, &b, g.sigma) else {
                out.iter_mut().for_each(|f| *f = [0.0; 3]);
                return;
            };
            k = k2;
            // The normal spring keeps its compression through the slip: the rest gap
            // moves with the anchors.
            let dz = d[2];
            d = sub(&mv(&k.r_mat, &k.r), &g.rest(st));
            st.gap += d[2] - dz;
            d[2] = dz;
            moved = true;
        }
        if moved {
            // What the slip released at these positions, less the elastic predictor's
            // overshoot ½ k Δd_t², which no force did work for (the return-mapped force
            // acts over the step): μ N |Δd_t| on a straight yarn, as the two-node link's
            // f·Δs; the normal spring's change as the crimp moves with the anchors is in
            // it too.
            let overshoot: f64 = (0..2)
                .map(|i| 0.5 * p.k[i] * (d_before[i] - d[i]).powi(2))
                .sum();
            st.friction_energy += w_before - energy_law(&d, p, law, &[0.0; 2]) - overshoot;
        }
    }
    // Springs at the (moved) anchors and the dashpots: the link law without its slider.
    let va = lerp(&v[0][a.s], &v[0][a.s + 1], a.t);
    let vb = lerp(&v[1][b.s], &v[1][b.s + 1], b.t);
    let dd = mv(&k.r_mat, &sub(&vb, &va));
    let stuck = LinkProps {
        slip_force: f64::INFINITY,
        ..*p
    };
    let stuck_law = LinkLaw {
        friction: None,
        ..*law
    };
    let mut ls = LinkState {
        slip: [0.0; 2],
        damping_energy: st.damping_energy,
        friction_energy: 0.0,
    };
    let (fs, fd) = force_update_parts(&d, &dd, &stuck, &stuck_law, &mut ls, dt_prev);
    st.damping_energy = ls.damping_energy;
    scatter(g, &a, &b, &k, &fs, &fd, out);
}

/// Elastic forces (no dashpot, no slip) on the window nodes at anchors `xi`: minus the
/// gradient of [`energy`].
pub fn elastic_forces(
    x: &SlidingX,
    g: &SlidingGeom,
    p: &LinkProps,
    law: &LinkLaw,
    st: &SlidingState,
    out: &mut [Vec3],
) {
    let a = anchor(&g.win[0], &x[0], st.xi[0]);
    let b = anchor(&g.win[1], &x[1], st.xi[1]);
    let Some(k) = kin(&a, &b, g.sigma) else {
        out.iter_mut().for_each(|f| *f = [0.0; 3]);
        return;
    };
    let d = sub(&mv(&k.r_mat, &k.r), &g.rest(st));
    let fs = super::link::elastic_force_law(&d, p, law, &[0.0; 2]);
    scatter(g, &a, &b, &k, &fs, &[0.0; 3], out);
}

/// The stable-step rows a link adds at anchors `xi` with the lever |r| (see the module
/// docs), as (window slot, stiffness row) pairs, into `rows` (returns how many).
fn rows(
    x: &SlidingX,
    g: &SlidingGeom,
    xi: &[f64; 2],
    lever: impl Fn(f64) -> f64,
    crowding: f64,
    kmax: f64,
    rows: &mut [(usize, f64); 12],
) {
    let mut n = 0;
    for side in 0..2 {
        let an = anchor(&g.win[side], &x[side], xi[side]);
        let lu = norm(&an.u).max(f64::MIN_POSITIVE);
        let rho = lever(lu) / lu;
        for (node, wk) in [(an.s, 1.0 - an.t), (an.s + 1, an.t)] {
            rows[n] = (side * WIN + node, 2.0 * wk * kmax * (1.0 + crowding));
            let (p, m, _) = g.win[side].chord(node);
            let frame = 4.0 * (rho + rho * rho) * kmax * wk;
            rows[n + 1] = (side * WIN + p, frame);
            rows[n + 2] = (side * WIN + m, frame);
            n += 3;
        }
    }
}

/// The lever |r| the static bound allows: 2|d₀|, at least [`LEVER_FLOOR`] of the chord.
fn static_lever(d0: &Vec3) -> impl Fn(f64) -> f64 {
    let d0 = norm(d0);
    move |lu: f64| (2.0 * d0).max(LEVER_FLOOR * lu)
}

/// Sliding links, struct-of-arrays: [`WIN`] force slots per yarn, 2 [`WIN`] each.
#[derive(Debug, Clone, Default)]
pub struct SlidingLinkGroup {
    pub id: Vec<i64>,
    /// Window nodes, A's then B's (a short window padded with its last node, whose
    /// padding slots get no force).
    pub nodes: Vec<[u32; 2 * WIN]>,
    pub geom: Vec<SlidingGeom>,
    pub props: Vec<LinkProps>,
    pub law: Vec<LinkLaw>,
    /// The anchors at the reference, ξ = the link nodes' places in their windows.
    pub home: Vec<[f64; 2]>,
    /// The stable-step rows at the reference anchors, (window slot, row) (see `rows`).
    pub base: Vec<[(usize, f64); 12]>,
    /// The anchor nodes' weights in `base` (every third entry's), for the dashpots' rows.
    pub base_weight: Vec<[f64; 4]>,
    pub state: Vec<SlidingState>,
    partials: Vec<EnergyPartial>,
}

impl SlidingLinkGroup {
    #[inline(always)]
    fn gather(x: &[Vec3], nodes: &[u32; 2 * WIN]) -> SlidingX {
        std::array::from_fn(|s| std::array::from_fn(|k| x[nodes[s * WIN + k] as usize]))
    }

    /// Link `e`'s state at the reference: anchors at its nodes, the reference gap.
    pub fn home_state(&self, e: usize) -> SlidingState {
        SlidingState {
            xi: self.home[e],
            gap: self.geom[e].d0[2],
            ..Default::default()
        }
    }

    /// The largest stiffness the bound takes for link `e`.
    fn kmax(&self, e: usize) -> f64 {
        bound_stiffness(&self.props[e], &self.law[e])
            .iter()
            .cloned()
            .fold(0.0, f64::max)
    }

    /// Elastic force of every sliding link on the point of yarn B where its node 2's end
    /// is (global axes), at positions `x` and the current anchors: −Rᵀ k ∘ d.
    pub fn elastic_forces_on_b(&self, x: &[Vec3]) -> Vec<Vec3> {
        (0..self.id.len())
            .map(|e| {
                let xe = Self::gather(x, &self.nodes[e]);
                let g = &self.geom[e];
                let a = anchor(&g.win[0], &xe[0], self.state[e].xi[0]);
                let b = anchor(&g.win[1], &xe[1], self.state[e].xi[1]);
                kin(&a, &b, g.sigma).map_or([0.0; 3], |k| {
                    let d = sub(&mv(&k.r_mat, &k.r), &g.rest(&self.state[e]));
                    let f =
                        super::link::elastic_force_law(&d, &self.props[e], &self.law[e], &[0.0; 2]);
                    super::link::to_global(&k.r_mat, &f)
                })
            })
            .collect()
    }

    /// The normal spring's force −k_z d_z of link `e` at positions `x` (anchors where
    /// they are), as a two-way spring (> 0: the link presses its yarns apart).
    pub fn normal_spring_force(&self, e: usize, x: &[Vec3]) -> f64 {
        let xe = Self::gather(x, &self.nodes[e]);
        rel_disp(&xe, &self.geom[e], &self.state[e]).map_or(0.0, |d| -self.props[e].k[2] * d[2])
    }

    /// The elastic forces of link `e` on its window nodes at positions `xe`, anchors at
    /// the reference, springs only (a unilateral normal linearised as closed, no slip):
    /// what the linear statics assembles (by finite differences about the reference).
    pub fn reference_forces(&self, e: usize, xe: &SlidingX) -> [Vec3; 2 * WIN] {
        let mut out = [[0.0; 3]; 2 * WIN];
        elastic_forces(
            xe,
            &self.geom[e],
            &self.props[e],
            &LinkLaw::default(),
            &self.home_state(e),
            &mut out,
        );
        out
    }
}

impl Family for SlidingLinkGroup {
    const KIND: ElementKind = ElementKind::Link;
    const SLOTS: usize = 2 * WIN;
    const GROUP: EnergyGroup = EnergyGroup::Line;
    /// Adds to the nodes' stable-step rows what the links add, with their anchors where
    /// they are and the lever |r| as it is, beyond what the static bound took, and keeps
    /// per node the link that adds most, as `(added, Link, id, [slide of A, slide of B,
    /// |r|])` (slides in segments from the reference): two anchors that crowd on one
    /// segment, or a link stretched beyond 2|d₀|, stiffen their nodes.
    fn add_stiffening(&self, x: &[Vec3], extra: &mut [f64], most: &mut [Option<Stiffened>]) {
        let mut now = [(0usize, 0.0); 12];
        let mut add = [0.0f64; 2 * WIN];
        for e in 0..self.id.len() {
            let xe = Self::gather(x, &self.nodes[e]);
            let g = &self.geom[e];
            let st = self.state[e].xi;
            let r = {
                let a = anchor(&g.win[0], &xe[0], st[0]);
                let b = anchor(&g.win[1], &xe[1], st[1]);
                norm(&sub(&b.p, &a.p))
            };
            // A unilateral link whose yarns have parted carries nothing, whatever |r|.
            let parted = self.law[e].unilateral
                && rel_disp(&xe, g, &self.state[e]).is_none_or(|d| d[2] >= 0.0);
            let r = if parted { 0.0 } else { r };
            let stat = static_lever(&g.d0);
            rows(
                &xe,
                g,
                &st,
                |lu| stat(lu).max(r),
                0.0,
                self.kmax(e),
                &mut now,
            );
            add.fill(0.0);
            for &(slot, v) in &now {
                add[slot] += v;
            }
            for &(slot, v) in &self.base[e] {
                add[slot] -= v;
            }
            for (slot, &v) in add.iter().enumerate() {
                if v == 0.0 {
                    continue;
                }
                let n = self.nodes[e][slot] as usize;
                extra[n] += v;
                if v > 0.0 && most[n].is_none_or(|m| v > m.added) {
                    let h = self.home[e];
                    most[n] = Some(Stiffened {
                        added: v,
                        id: self.id[e],
                        q: [st[0] - h[0], st[1] - h[1], r],
                        describe: Self::describe_stiffening,
                    });
                }
            }
        }
    }
    fn describe_stiffening(id: i64, q: [f64; 3], _dt_safety: f64) -> (String, Option<String>) {
        (
            format!(
                "sliding link `{id}` (its ends slid {:.2} and {:.2} segments, {:.3e} m apart)",
                q[0], q[1], q[2]
            ),
            None,
        )
    }

    fn build(bd: &mut Build) -> Result<Self> {
        let m = bd.model;
        let mut g = SlidingLinkGroup::default();
        let Some(b) = m.block(ElementKind::Link) else {
            return Ok(g);
        };
        let mut nb = None;
        for e in (0..b.len()).filter(|&e| super::link::is_sliding(m, e)) {
            let nb = nb.get_or_insert_with(|| m.truss_neighbours());
            let (n1, n2) = (b.nodes[2 * e], b.nodes[2 * e + 1]);
            let (props, law) = link_props(&m.parts[b.part[e]].props);
            let mut nodes = [0u32; 2 * WIN];
            let mut win = [Window {
                len: 0,
                ends: [true; 2],
                mirror: [None; 2],
            }; 2];
            let mut home = [0.0; 2];
            for (side, n) in [n1, n2].into_iter().enumerate() {
                // `Model::validate` checked the windows.
                let w = m.yarn_window(nb, n, HALF).map_err(|why| {
                    WeftError::input(format!("sliding link `{}`: {why}", b.id[e]))
                })?;
                for k in 0..WIN {
                    nodes[side * WIN + k] = w.nodes[k.min(w.nodes.len() - 1)] as u32;
                }
                // A yarn's end on a symmetry plane across it (the quarter model's
                // centre lines): its tangent there is the plane's normal.
                let l = w.nodes.len();
                let mirror = [(0, 1), (l - 1, l - 2)].map(|(end, nb)| {
                    let (xe, xn) = (m.coords[w.nodes[end]], m.coords[w.nodes[nb]]);
                    let dir = sub(&xn, &xe);
                    m.symmetry.iter().find_map(|pl| {
                        let on = (xe[pl.normal] - pl.position).abs() <= pl.tolerance;
                        let across = dir[pl.normal].abs() >= 0.5 * norm(&dir);
                        (on && across).then_some(pl.normal)
                    })
                });
                win[side] = Window {
                    len: l,
                    ends: w.ends,
                    mirror: [
                        mirror[0].filter(|_| w.ends[0]),
                        mirror[1].filter(|_| w.ends[1]),
                    ],
                };
                home[side] = w.home as f64;
            }
            let xe = Self::gather(&m.coords, &nodes);
            let a = anchor(&win[0], &xe[0], home[0]);
            let c = anchor(&win[1], &xe[1], home[1]);
            let k = kin(&a, &c, 1.0).ok_or_else(|| {
                WeftError::input(format!(
                    "sliding link `{}`: its yarns are parallel at the reference",
                    b.id[e]
                ))
                .expected("two yarns that cross")
            })?;
            let r0 = mv(&k.r_mat, &k.r);
            // n from node 1 towards node 2: flip yarn A's tangent (which flips e₁ and n).
            let sigma = if r0[2] < 0.0 { -1.0 } else { 1.0 };
            let k = kin(&a, &c, sigma).expect("a frame that exists with σ = 1");
            g.id.push(b.id[e]);
            g.nodes.push(nodes);
            g.geom.push(SlidingGeom {
                win,
                sigma,
                d0: mv(&k.r_mat, &k.r),
            });
            let kmax = bound_stiffness(&props, &law)
                .iter()
                .cloned()
                .fold(0.0, f64::max);
            let mut base = [(0usize, 0.0); 12];
            let lever = static_lever(&g.geom[g.geom.len() - 1].d0);
            rows(
                &xe,
                &g.geom[g.geom.len() - 1],
                &home,
                lever,
                CROWDING,
                kmax,
                &mut base,
            );
            let ta = win[0].locate(home[0]).1;
            let tb = win[1].locate(home[1]).1;
            g.base.push(base);
            g.base_weight.push([1.0 - ta, ta, 1.0 - tb, tb]);
            g.props.push(props);
            g.law.push(law);
            g.home.push(home);
            let d0 = g.geom[g.geom.len() - 1].d0;
            g.state.push(SlidingState {
                xi: home,
                gap: d0[2],
                ..Default::default()
            });
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
        let k = bound_stiffness(p, &self.law[e]);
        k.iter().chain(p.c.iter()).cloned().fold(0.0, f64::max)
    }
    fn forces(&mut self, ctx: &ForceCtx, fe: &mut [Vec3]) {
        let (x, v, dt_prev) = (ctx.x, ctx.v, ctx.dt_prev);
        let (nodes, geom, props, law) = (&self.nodes, &self.geom, &self.props, &self.law);
        let n = nodes.len();
        for_chunks_of(
            n,
            (Per(fe, 2 * WIN), Per(&mut self.state[..], 1)),
            |ci, (out, st)| {
                let e0 = ci * CHUNK;
                for (j, (slots, s)) in out.chunks_exact_mut(2 * WIN).zip(st.iter_mut()).enumerate()
                {
                    let e = e0 + j;
                    let xe = Self::gather(x, &nodes[e]);
                    let ve = Self::gather(v, &nodes[e]);
                    force_update(&xe, &ve, &geom[e], &props[e], &law[e], s, dt_prev, slots);
                }
            },
        );
    }
    fn stiffness_sums(&self, _ctx: &StiffCtx, s: &mut [f64], c: &mut [f64], _r: &mut [f64]) {
        // The rows at the reference anchors, made at build (`base`); the two-node links'
        // rule of k alone when the other end is fully fixed is not taken here: the other
        // end is a point of a yarn. The dashpots act on the anchors only: 2c·w there.
        for e in 0..self.id.len() {
            let cmax = self.props[e].c.iter().cloned().fold(0.0, f64::max);
            for (j, &(slot, v)) in self.base[e].iter().enumerate() {
                let n = self.nodes[e][slot] as usize;
                s[n] += v;
                if j % 3 == 0 {
                    c[n] += self.base_weight[e][j / 3] * 2.0 * cmax * (1.0 + CROWDING);
                }
            }
        }
    }
    fn energies(&mut self, ctx: &ForceCtx) -> &[EnergyPartial] {
        let (x, nodes, geom, props, law, state) = (
            ctx.x,
            &self.nodes,
            &self.geom,
            &self.props,
            &self.law,
            &self.state,
        );
        chunk_partials(&mut self.partials, nodes.len(), |r| {
            let mut acc = [0.0; 4];
            for k in r {
                let xe = Self::gather(x, &nodes[k]);
                acc[0] += energy(&xe, &geom[k], &props[k], &law[k], &state[k]);
                acc[1] += state[k].damping_energy;
                acc[2] += state[k].friction_energy;
            }
            acc
        });
        &self.partials
    }
}
