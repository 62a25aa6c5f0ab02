//! General contact: slave nodes against master surfaces — membrane faces offset by
//! ± half their nodal thickness (LS-DYNA's shell contact thickness), or truss and beam
//! segments with a radius — with penalty forces and Coulomb friction.
//!
//! Glossary: s a slave node, x_s its position, t_s its contact thickness; F a master face
//! (2 nodes: a segment, 3: a triangle, 4: a quad), q = Σ_a w_a x_a the closest point of
//! its mid-surface to x_s, d = |x_s − q|, n = (x_s − q)/d the normal from the face to the
//! node, t_F = Σ_a w_a t_a the face thickness at q; g = (t_s + t_F)/2 − d − g₀ the
//! penetration (g₀: the depth at which a node started inside, see below); m* = min(m_s,
//! m_F) with m_F the faces' nodal masses interpolated at the feet (λ-weighted, below);
//! κ_c = 0.1 × penalty_scale.
//!
//! Phases, after the DESIGN notes §11 and LS-DYNA's contact:
//! - **thickness box** of a face: the bounding box of the balls of radius t_a/2 about its
//!   nodes, lo = min_a (x_a − t_a/2), hi = max_a (x_a + t_a/2) per component. It holds
//!   every ball of radius t_F/2 about a point q = Σ w_a x_a of the face (w_a ≥ 0, Σ w_a =
//!   1, t_F = Σ w_a t_a), so a slave farther than t_s/2 from it cannot penetrate the face.
//! - **broad phase** ([`Grid`]): the faces' thickness boxes, inflated by
//!   r = t_s,max/2 + skin + η (η a 10⁻⁹ round-off allowance), in a dense uniform grid
//!   whose cell is half the largest inflated box (each face in ≤ 27 cells); each slave's
//!   candidates are the faces of its cell whose box contains it (never a face it belongs
//!   to), in face order.
//!   Rebuilt only when the displacements since the last build could have brought a pair
//!   within reach that is not a candidate: some node has moved more than 2 skins, or the
//!   displacements of the nodes near one another differ by more than the skin
//!   ([`super::staleness`]); a region that moves as a whole (the fabric under the nose)
//!   keeps its lists. A pair that can touch is never missed and the cost is amortised
//!   (Teschner et al., *Optimized spatial hashing for collision detection of deformable
//!   objects*, VMV 2003).
//! - **envelope bounds**: along a unit direction m, every such ball lies below
//!   h = max_a (m·x_a + t_a/2) (its support m·q + t_F/2 = Σ w_a (m·x_a + t_a/2)). Each
//!   face keeps two directions m± = (±n̂ − ½∇t_F)/|…|, the outward normals of the two
//!   sides of a flat face's envelope with a linear thickness, taken at each broad phase
//!   (any unit direction is sound), and its bounds h± every step: a lenticular band's
//!   quad thins to 0 at the band's edge, where the thickness box stays as high as the
//!   thick nodes.
//! - **narrow phase** (pure kernels [`closest_on_face`], [`pair_force`]): the faces'
//!   thickness boxes and envelope bounds once per step; a slave whose margin at the
//!   build (its distance beyond reach from all its candidates) exceeds how far the nodes
//!   around it have since moved apart is skipped, as no candidate can pass (`Side::margin`:
//!   the same results); per other slave, the candidates whose
//!   thickness box is within t_s/2 + η of it and that are not beyond either envelope
//!   bound by t_s/2 + η (branch-free passes), then the closest point on each of those;
//!   of the faces it penetrates, the one of largest penetration sets g, and all of
//!   them share the rest:
//!   the normal is their penetration-weighted mean, and the reaction −f goes to each
//!   penetrated face F in the share λ_F = g_F/Σg (to its nodes by the foot's weights), the
//!   foot's mass and velocity being the λ-weighted ones, so that a node over a vertex or
//!   in a crease, whose faces tie, pushes them all alike and nothing jumps as faces come
//!   and go; normal force
//!   f_n = k g with k = κ_c m*/Δt² (LS-DYNA's SOFT = 1 idea: the contact spring alone has
//!   ω Δt ≤ √(2κ_c), so it does not cut the step; the step is still reduced by
//!   √(s² − κ_c/2)/s as a guard, see `Solver::set_time_step`); one geometry evaluation gives the
//!   force and the stored energy ½ k g².
//! - **friction**: Coulomb with an elastic stick spring of the normal stiffness k
//!   (Wriggers, *Computational Contact Mechanics*, §5.2, return mapping): trial
//!   f_t* = P_t f_t^{old} − k Δu_t with Δu_t the tangential slip increment of the slave
//!   over the face over the last step; slip when |f_t*| > μ f_n, then f_t = μ f_n f_t*/|f_t*|
//!   and the dissipated work μ f_n (|f_t*| − μ f_n)/k; μ = μ_d + (μ_s − μ_d) e^{−d_c|v_t|}.
//!   The stored stick energy |f_t|²/(2k) is part of the contact energy; what is stored
//!   when a pair opens is dissipated.
//! - **initial penetration**: a slave inside at t = 0 (g > 0 with g₀ = 0) is recorded with
//!   its depth g₀ (the force acts only beyond it, and g₀ shrinks as the node leaves), or
//!   stops the run when the definition says `error`.
//! - **determinism**: slaves are processed in parallel fixed chunks, each writing only its
//!   own result slot and its chunk's list of reaction shares; the results are gathered
//!   onto the nodes in chunk order (the slaves, then their reactions), so 1 and N threads
//!   give bit-identical forces.

use rayon::prelude::*;

use super::staleness::Staleness;
use super::PENALTY_FACTOR;
use crate::error::{Result, WeftError};
use crate::model::contacts::{InitialPenetration, Slave};
use crate::model::{ElementKind, Model};
use crate::solver::vec3::{add, cross, dot, sub};

/// Slaves per parallel chunk of the narrow phase.
const SLAVE_CHUNK: usize = 256;

/// Most slave chunks of one narrow-phase task (see [`Side::narrow`]).
const NARROW_TASK_CHUNKS: usize = 4;

/// Gradient in the face's plane of its interpolated nodal thickness, at the face centre
/// (exact for a thickness linear over the face, as across a lenticular band's quads); zero
/// for a uniform thickness or a segment.
pub fn thickness_gradient(t: &[f64; 4], xa: &[[f64; 3]; 4], nf: usize) -> [f64; 3] {
    if nf < 3 || (0..nf).all(|a| t[a] == t[0]) {
        return [0.0; 3];
    }
    // Tangents and thickness derivatives in the face's parameters.
    let (xs, xe, ts, te) = if nf == 4 {
        (
            std::array::from_fn::<f64, 3, _>(|d| {
                0.25 * (-xa[0][d] + xa[1][d] + xa[2][d] - xa[3][d])
            }),
            std::array::from_fn::<f64, 3, _>(|d| {
                0.25 * (-xa[0][d] - xa[1][d] + xa[2][d] + xa[3][d])
            }),
            0.25 * (-t[0] + t[1] + t[2] - t[3]),
            0.25 * (-t[0] - t[1] + t[2] + t[3]),
        )
    } else {
        (
            sub(&xa[1], &xa[0]),
            sub(&xa[2], &xa[0]),
            t[1] - t[0],
            t[2] - t[0],
        )
    };
    let (a, b, c) = (dot(&xs, &xs), dot(&xs, &xe), dot(&xe, &xe));
    let det = a * c - b * b;
    if det <= 0.0 {
        return [0.0; 3];
    }
    // G = [x_ξ x_η] g⁻¹ [t_ξ, t_η]ᵀ with g the metric.
    let (u, v) = ((c * ts - b * te) / det, (a * te - b * ts) / det);
    let g: [f64; 3] = std::array::from_fn(|d| u * xs[d] + v * xe[d]);
    // A face crushed under the projectile (det → 0) would give an unbounded gradient:
    // the envelope's slope ½|G| is capped at 1 (a lenticular band's is ≤ 0.21; without
    // the cap the 60 × 60 impact went non-finite at 58 µs, measured).
    let m = dot(&g, &g).sqrt();
    if m > MAX_THICKNESS_GRADIENT {
        let s = MAX_THICKNESS_GRADIENT / m;
        [g[0] * s, g[1] * s, g[2] * s]
    } else {
        g
    }
}

/// Largest |∇t_F| the contact force takes (an envelope slope of 1).
pub const MAX_THICKNESS_GRADIENT: f64 = 2.0;

/// Closest point of the mid-surface of a face (`n` = 2, 3 or 4 nodes) to `p`: the weights
/// of its nodes. Quads average the two diagonal splits, so the result has no handedness.
#[inline]
pub fn closest_on_face(p: &[f64; 3], x: &[[f64; 3]; 4], n: usize) -> [f64; 4] {
    match n {
        2 => {
            let t = super::closest_on_segment(p, &x[0], &x[1]);
            [1.0 - t, t, 0.0, 0.0]
        }
        3 => {
            let w = super::closest_on_triangle(p, &x[0], &x[1], &x[2]);
            [w[0], w[1], w[2], 0.0]
        }
        _ => closest_on_quad(p, x),
    }
}

/// [`closest_on_face`] for a quad.
#[inline]
pub fn closest_on_quad(p: &[f64; 3], x: &[[f64; 3]; 4]) -> [f64; 4] {
    let a = super::closest_on_triangle(p, &x[0], &x[1], &x[2]);
    let b = super::closest_on_triangle(p, &x[0], &x[2], &x[3]);
    let c = super::closest_on_triangle(p, &x[1], &x[2], &x[3]);
    let d = super::closest_on_triangle(p, &x[1], &x[3], &x[0]);
    // Split 0-2: triangles (0,1,2), (0,2,3); split 1-3: (1,2,3), (1,3,0). Each split
    // takes its nearer triangle; the two splits are averaged.
    // Each triangle's weights on the quad's nodes and the squared distance to its foot.
    // The foot is summed over the triangle's three nodes in node order: the four-term
    // sum less its zero term (the node `skip` not in the triangle), so the same bits.
    let q = |w: [f64; 3], i: [usize; 3]| -> ([f64; 4], f64) {
        let mut ww = [0.0; 4];
        for k in 0..3 {
            ww[i[k]] = w[k];
        }
        let skip = 6 - i[0] - i[1] - i[2];
        let qp: [f64; 3] = std::array::from_fn(|dd| {
            (0..4)
                .filter(|&k| k != skip)
                .fold(-0.0, |s, k| s + ww[k] * x[k][dd])
        });
        let r = sub(p, &qp);
        (ww, dot(&r, &r))
    };
    let (wa, da) = q(a, [0, 1, 2]);
    let (wb, db) = q(b, [0, 2, 3]);
    let (wc, dc) = q(c, [1, 2, 3]);
    let (wd, dd) = q(d, [1, 3, 0]);
    let s1 = if da <= db { wa } else { wb };
    let s2 = if dc <= dd { wc } else { wd };
    std::array::from_fn(|k| 0.5 * (s1[k] + s2[k]))
}

/// What one slave's contact gives at one step.
#[derive(Debug, Clone, Copy, Default)]
pub struct PairOut {
    /// Face of largest penetration (u32::MAX: no contact).
    pub face: u32,
    /// Force on the slave [N] (the nodes of each penetrated face F get −λ_F w_{F,a} f,
    /// see [`Reaction`]).
    pub f: [f64; 3],
    /// Stored energy ½ k g² + |f_t|²/(2k) [J].
    pub stored: f64,
    /// Friction work dissipated this step [J].
    pub dissipated: f64,
    /// Penetration g (beyond a tracked initial one) [m].
    pub g: f64,
}

/// A share of a slave's reaction: the nodes of `face` get −w_a f_slave (w already
/// multiplied by the face's share λ_F = g_F/Σg of the penetrations).
#[derive(Debug, Clone, Copy)]
pub struct Reaction {
    pub slave: u32,
    pub face: u32,
    pub w: [f64; 4],
}

/// Most faces one slave's reaction is shared over (a node at a quad vertex penetrates the
/// four faces around it; more only in crushed regions, where the deepest are kept).
const MAX_SHARED: usize = 8;

/// Per-slave history.
#[derive(Debug, Clone, Copy, Default)]
pub struct SlaveState {
    /// Tangential (stick spring) force [N].
    pub ft: [f64; 3],
    /// Penalty of the last contact [N/m].
    pub k: f64,
    /// Initial penetration still being tracked [m].
    pub g0: f64,
}

/// Friction coefficients of a definition.
#[derive(Debug, Clone, Copy)]
pub struct Friction {
    pub mu_s: f64,
    pub mu_d: f64,
    pub decay: f64,
}

/// Normal and friction force of a slave in contact: the return-mapped tangential force
/// and the pair's output. `g` > 0 the penetration, `n` the normal, `k` the penalty,
/// `vt` the tangential relative velocity over the last step Δt^{n−½}.
#[inline]
pub fn pair_force(
    g: f64,
    n: &[f64; 3],
    k: f64,
    vt: &[f64; 3],
    dt_prev: f64,
    fr: &Friction,
    st: &mut SlaveState,
) -> ([f64; 3], f64, f64) {
    if !(k > 0.0) {
        // A pair whose nodes all have no mass of their own (tie slaves, whose mass their
        // masters carry) has no penalty: no force, and nothing stored or dissipated
        // (friction's μ f_n (|f_t*| − μ f_n)/k would be 0/0).
        st.ft = [0.0; 3];
        st.k = 0.0;
        return ([0.0; 3], 0.0, 0.0);
    }
    let fnorm = k * g;
    let mut stored = 0.5 * k * g * g;
    let mut diss = 0.0;
    let mut ft = [0.0; 3];
    if fr.mu_s > 0.0 {
        // Old tangential force, in the current tangent plane.
        let o = st.ft;
        let on = dot(&o, n);
        let mut trial = [o[0] - on * n[0], o[1] - on * n[1], o[2] - on * n[2]];
        for d in 0..3 {
            trial[d] -= k * vt[d] * dt_prev;
        }
        let vtm = dot(vt, vt).sqrt();
        let mu = fr.mu_d + (fr.mu_s - fr.mu_d) * (-fr.decay * vtm).exp();
        let limit = mu * fnorm;
        let tm = dot(&trial, &trial).sqrt();
        if tm > limit {
            let r = if tm > 0.0 { limit / tm } else { 0.0 };
            ft = [trial[0] * r, trial[1] * r, trial[2] * r];
            diss = limit * (tm - limit) / k;
        } else {
            ft = trial;
        }
        stored += dot(&ft, &ft) / (2.0 * k);
    }
    st.ft = ft;
    st.k = k;
    (
        [
            n[0] * fnorm + ft[0],
            n[1] * fnorm + ft[1],
            n[2] * fnorm + ft[2],
        ],
        stored,
        diss,
    )
}

/// A recorded initial penetration.
#[derive(Debug, Clone)]
pub struct InitialPen {
    pub contact_id: i64,
    pub node: usize,
    pub element: i64,
    pub depth: f64,
}

/// What a run's contact did.
#[derive(Debug, Clone, Default)]
pub struct ContactReport {
    pub definitions: usize,
    /// Slave nodes and master faces over all sides (a two-way definition counts twice).
    pub slaves: usize,
    pub faces: usize,
    /// Broad-phase builds.
    pub builds: u64,
    /// Slaves in contact at the end.
    pub active: usize,
    pub initial_penetrations: usize,
    /// Deepest initial penetration: (contact id, node id, element id, depth [m]).
    pub deepest: Option<(i64, i64, i64, f64)>,
    /// Friction work dissipated [J].
    pub friction_work: f64,
    /// Broad-phase skin [m].
    pub skin: f64,
    /// Wall time of the broad phase (with the per-step face boxes and the staleness
    /// check) and of the narrow phase with the scatter [s].
    pub build_seconds: f64,
    pub narrow_seconds: f64,
    /// The same wall time by phase [s]: the faces' thickness boxes (every step), the
    /// staleness test (every step), the broad-phase builds, the narrow phase proper, and
    /// the scatter of the forces onto the nodes.
    pub phases: ContactPhases,
    /// Slave-steps (slaves × force evaluations), and over them: candidate faces whose
    /// box was tested, faces past the box and envelope filters (whose closest point was
    /// computed), and faces found penetrated.
    pub slave_steps: u64,
    pub tested: u64,
    pub evaluated: u64,
    pub penetrated: u64,
    /// Slave-steps skipped whole: the slave was farther from every candidate at the
    /// build than its neighbourhood's nodes have since moved apart (see `Side::margin`).
    pub skipped: u64,
}

/// Wall time of the contact's phases [s] (see [`ContactReport::phases`]).
#[derive(Debug, Clone, Copy, Default)]
pub struct ContactPhases {
    pub boxes: f64,
    pub staleness: f64,
    pub builds: f64,
    pub narrow: f64,
    pub scatter: f64,
}

/// One direction of one contact definition: slaves against a master surface.
#[derive(Debug, Clone)]
pub struct Side {
    pub contact_id: i64,
    pub row: usize,
    pub slaves: Vec<u32>,
    pub slave_t: Vec<f64>,
    slave_m: Vec<f64>,
    /// Face nodes (unused entries 0), node count per face (2, 3 or 4).
    pub faces: Vec<[u32; 4]>,
    pub nf: usize,
    face_t: Vec<[f64; 4]>,
    /// Nodal masses of each face [kg] (the penalty uses their interpolation at the
    /// contact point, continuous from face to face).
    face_m: Vec<[f64; 4]>,
    pub face_id: Vec<i64>,
    friction: Friction,
    kappa: f64,
    /// Normal viscous damping as a fraction ζ of the pair's critical damping
    /// 2√(k m*) (0 in impact runs; `set_normal_damping` sets it for a relaxation).
    damping: f64,
    on_initial: InitialPenetration,
    /// Contact distance of the thickest slave and face, t_s,max/2 + t_F,max/2 [m].
    reach: f64,
    /// Largest slave thickness: the thickness boxes are inflated by half of it and the
    /// skin for the broad phase [m].
    slave_t_max: f64,
    /// Round-off allowance η of the thickness-box tests [m] (see [`BOX_MARGIN`]).
    box_margin: f64,
    /// Candidates per slave (CSR), from the last broad phase.
    cand_ptr: Vec<u32>,
    cand: Vec<u32>,
    /// Per slave, from the last broad phase: its margin [m] (+∞ without candidates), so
    /// that the narrow phase can skip a slave that no candidate can reach yet.
    ///
    /// Let e_F be the Euclidean distance from x_s to the thickness box of a candidate F,
    /// and v_F = max over its two envelope directions m of m·x_s − h (the narrow phase's
    /// filter passes F only when e_F ≤ t_s/2 + η and v_F < t_s/2 + η). Between builds
    /// the directions are fixed, |m| ≤ 1, and for a pair that passes the box test every
    /// component d of the displacement since the build of a node a of F differs from the
    /// slave's by at most S_d, the spread of the displacements over the 3 × 3 × 3 cells
    /// around the slave's cell ([`super::staleness`]: F's nodes lie in them). The box's
    /// faces then move by at most S_d relative to the slave, so e_F ≥ e_F^b − |S|
    /// (b: at the build); and h = max_a (m·x_a + t_a/2) grows by at most m·u_s + |S|, so
    /// v_F ≥ v_F^b − |S|. With the margin min_F max(e_F^b, v_F^b) − t_s/2 − 2η, a slave
    /// whose margin exceeds |S| at a step passes no candidate, finds no penetration and
    /// opens (its stick spring released, a tracked initial penetration dropped): exactly
    /// what the full test gives; the second η covers the round-off of the margin, 10⁶
    /// times it as in the box test. Measured on the 60 × 60 woven quarter: 86 % of the
    /// slave-steps skipped to 10 µs, 43 % to 60 µs.
    margin: Vec<f64>,
    /// Per slave, its cell of the staleness test at the last build.
    slave_cell: Vec<u32>,
    /// The faces' thickness boxes at the current step (lo, hi) [m], and their envelope
    /// bounds h₊, h₋ along `face_dir` (see [`Side::set_directions`]).
    face_box: Vec<[f64; 8]>,
    /// Per face, the unit directions m₊, m₋ of its envelope bounds, from the last broad
    /// phase (zero for a segment or a face too distorted to have them).
    face_dir: Vec<[f32; 6]>,
    pub state: Vec<SlaveState>,
    /// Per slave: whether its state differs from the default (a stick spring or a
    /// tracked initial penetration).
    held: Vec<bool>,
    /// Per slave, its contact at the last step; valid only for the slaves in
    /// `chunk_active` (after the setup's narrow phase: for every slave).
    pub out: Vec<PairOut>,
    /// Per fixed chunk of slaves: the slaves in contact (indices), ...
    chunk_active: Vec<Vec<u32>>,
    /// ... the shares of their reactions over the faces they penetrate, in slave order ...
    chunk_reactions: Vec<Vec<Reaction>>,
    /// ... and the chunk's energies and counts, summed in chunk order.
    chunk_sums: Vec<ChunkSums>,
}

/// What one chunk of slaves adds up in a narrow phase: the stored energy and the friction
/// work [J], the slaves skipped whole, the candidate faces whose box was tested, the faces
/// past the filters (whose closest point was computed), and the faces found penetrated.
#[derive(Debug, Clone, Copy, Default)]
struct ChunkSums {
    stored: f64,
    dissipated: f64,
    skipped: u64,
    tested: u64,
    evaluated: u64,
    penetrated: u64,
}

/// Nodal contact thickness from a part's elements (None = all parts): membranes their
/// nodal thickness, trusses the diameter √(4A/π), beams the section height; the mean over
/// a node's elements.
fn nodal_thickness(m: &Model, part: Option<usize>) -> Vec<f64> {
    let nn = m.num_nodes();
    let (mut sum, mut cnt) = (vec![0.0; nn], vec![0u32; nn]);
    for (kind, b) in &m.elements {
        let npe = kind.nodes_per_element();
        for e in 0..b.len() {
            if part.is_some_and(|p| p != b.part[e]) {
                continue;
            }
            let p = &m.parts[b.part[e]].props;
            for a in 0..npe {
                let t = match kind {
                    ElementKind::Tri | ElementKind::Quad => {
                        if b.thickness.is_empty() {
                            p.thickness.unwrap_or(0.0)
                        } else {
                            b.thickness[npe * e + a]
                        }
                    }
                    ElementKind::Truss => {
                        (4.0 * b.truss_area(&m.parts, e) / std::f64::consts::PI).sqrt()
                    }
                    ElementKind::Beam => p.height.unwrap_or(0.0),
                    _ => continue,
                };
                let n = b.nodes[npe * e + a];
                sum[n] += t;
                cnt[n] += 1;
            }
        }
    }
    (0..nn)
        .map(|i| {
            if cnt[i] > 0 {
                sum[i] / cnt[i] as f64
            } else {
                0.0
            }
        })
        .collect()
}

/// The largest total penalty factor that can act on one node: Σ κ_c over the contact
/// roles it has (slave of a definition, node of a master surface, both in two-way
/// contact), plus 2 × 0.1 when the model has projectiles (their node and face contact).
/// The stable-step guard of `Solver::set_time_step` uses it.
pub fn guard_kappa(m: &Model) -> f64 {
    if m.contacts.is_empty() {
        return 0.0;
    }
    let mut k = vec![0.0; m.num_nodes()];
    for d in &m.contacts {
        let kappa = PENALTY_FACTOR * d.penalty_scale;
        let slaves: Vec<u32> = match &d.slave {
            Slave::Part(p) => part_nodes(m, *p),
            Slave::Set(s) => m
                .node_sets
                .get(s)
                .map(|v| v.iter().map(|&n| n as u32).collect())
                .unwrap_or_default(),
        };
        let roles = if d.two_way { 2.0 } else { 1.0 };
        for n in slaves {
            k[n as usize] += roles * kappa;
        }
        for n in part_nodes(m, d.master) {
            k[n as usize] += roles * kappa;
        }
    }
    let proj = if m.projectiles.is_empty() {
        0.0
    } else {
        2.0 * PENALTY_FACTOR
    };
    k.iter().cloned().fold(0.0, f64::max) + proj
}

/// The nodes of a part's elements, sorted.
fn part_nodes(m: &Model, part: usize) -> Vec<u32> {
    let kind = m.parts[part].kind;
    let mut v: Vec<u32> = match m.elements.get(&kind) {
        Some(b) => {
            let npe = kind.nodes_per_element();
            (0..b.len())
                .filter(|&e| b.part[e] == part)
                .flat_map(|e| b.nodes[npe * e..npe * e + npe].iter().map(|&n| n as u32))
                .collect()
        }
        None => vec![],
    };
    v.sort_unstable();
    v.dedup();
    v
}

impl Side {
    fn new(m: &Model, row: usize, slave: &Slave, master: usize, mass: &[f64]) -> Side {
        let d = &m.contacts[row];
        let slaves: Vec<u32> = match slave {
            Slave::Part(p) => part_nodes(m, *p),
            Slave::Set(s) => {
                let mut v: Vec<u32> = m.node_sets[s].iter().map(|&n| n as u32).collect();
                v.sort_unstable();
                v.dedup();
                v
            }
        };
        let st = nodal_thickness(
            m,
            match slave {
                Slave::Part(p) => Some(*p),
                Slave::Set(_) => None,
            },
        );
        let slave_t: Vec<f64> = slaves
            .iter()
            .map(|&s| d.slave_thickness.unwrap_or(st[s as usize]))
            .collect();
        let kind = m.parts[master].kind;
        let b = &m.elements[&kind];
        let npe = kind.nodes_per_element();
        let mt = nodal_thickness(m, Some(master));
        let (mut faces, mut face_t, mut face_m, mut face_id) = (vec![], vec![], vec![], vec![]);
        for e in 0..b.len() {
            if b.part[e] != master {
                continue;
            }
            let mut f = [0u32; 4];
            let mut t = [0.0; 4];
            let mut fm = [0.0; 4];
            for a in 0..npe {
                let n = b.nodes[npe * e + a];
                f[a] = n as u32;
                t[a] = d.master_thickness.unwrap_or(match kind {
                    ElementKind::Tri | ElementKind::Quad if !b.thickness.is_empty() => {
                        b.thickness[npe * e + a]
                    }
                    _ => mt[n],
                });
                fm[a] = mass[n];
            }
            faces.push(f);
            face_t.push(t);
            face_m.push(fm);
            face_id.push(b.id[e]);
        }
        let ts_max = slave_t.iter().cloned().fold(0.0, f64::max);
        let tf_max = face_t.iter().flatten().cloned().fold(0.0, f64::max);
        // The largest coordinate of the side's nodes, the scale of the round-off.
        let x_max = slaves
            .iter()
            .chain(faces.iter().flat_map(|f| f[..npe].iter()))
            .flat_map(|&n| m.coords[n as usize])
            .fold(0.0, |a: f64, c| a.max(c.abs()));
        let n_faces = faces.len();
        Side {
            contact_id: d.id,
            row,
            slave_m: slaves.iter().map(|&s| mass[s as usize]).collect(),
            state: vec![SlaveState::default(); slaves.len()],
            held: vec![false; slaves.len()],
            out: vec![
                PairOut {
                    face: u32::MAX,
                    ..Default::default()
                };
                slaves.len()
            ],
            slaves,
            slave_t,
            faces,
            nf: npe,
            face_t,
            face_m,
            face_id,
            friction: Friction {
                mu_s: d.static_friction,
                mu_d: d.dynamic_friction,
                decay: d.friction_decay,
            },
            kappa: PENALTY_FACTOR * d.penalty_scale,
            damping: 0.0,
            on_initial: d.initial_penetration,
            reach: 0.5 * (ts_max + tf_max),
            slave_t_max: ts_max,
            box_margin: BOX_MARGIN * (x_max + 0.5 * (ts_max + tf_max)),
            cand_ptr: vec![],
            cand: vec![],
            margin: vec![],
            slave_cell: vec![],
            // Before the first broad phase there are no directions yet: zero ones never
            // reject.
            face_box: vec![[0.0; 8]; n_faces],
            face_dir: vec![[0.0; 6]; n_faces],
            chunk_active: vec![],
            chunk_reactions: vec![],
            chunk_sums: vec![],
        }
    }

    /// Mean of the largest extent of the faces [m].
    fn mean_face_size(&self, x: &[[f64; 3]]) -> f64 {
        if self.faces.is_empty() {
            return 0.0;
        }
        let mut s = 0.0;
        for f in &self.faces {
            let (lo, hi) = bbox(f, self.nf, x);
            s += (0..3).map(|d| hi[d] - lo[d]).fold(0.0, f64::max);
        }
        s / self.faces.len() as f64
    }

    /// The faces' thickness boxes at `x`, once per step, in parallel (each candidate of
    /// the narrow phase then reads one box instead of gathering its face's nodes; measured:
    /// those gathers were ~40 % of the narrow phase of the woven patch).
    fn update_boxes(&mut self, x: &[[f64; 3]]) {
        let (faces, face_t, nf) = (&self.faces, &self.face_t, self.nf);
        let dirs = &self.face_dir;
        self.face_box
            .par_chunks_mut(4096)
            .enumerate()
            .for_each(|(c, bs)| {
                for (j, b) in bs.iter_mut().enumerate() {
                    let fi = c * 4096 + j;
                    *b = thickness_box(&faces[fi], &face_t[fi], &dirs[fi], nf, x);
                }
            });
    }

    /// The directions of the faces' envelope bounds at `x`, then their bounds (at a broad
    /// phase). For a face of unit normal n̂ and in-plane thickness gradient ∇t_F
    /// ([`thickness_gradient`]), m± = (±n̂ − ½∇t_F)/|±n̂ − ½∇t_F|: the outward normals of the
    /// two sides of the thickness envelope of a flat face with a linear thickness (a
    /// lenticular band's quad thins to its edge, where the thickness box stays as high as
    /// its thickest node). Any unit direction gives a sound bound, so they are refreshed
    /// only here, while the bounds follow the nodes every step.
    fn set_directions(&mut self, x: &[[f64; 3]]) {
        let (faces, face_t, nf) = (&self.faces, &self.face_t, self.nf);
        if nf < 3 {
            return;
        }
        // (The boxes are up to date: only the bounds along the new directions change.)
        self.face_dir
            .par_chunks_mut(4096)
            .zip(self.face_box.par_chunks_mut(4096))
            .enumerate()
            .for_each(|(c, (ds, bs))| {
                for (j, (d, b)) in ds.iter_mut().zip(bs.iter_mut()).enumerate() {
                    let fi = c * 4096 + j;
                    *d = envelope_directions(&faces[fi], &face_t[fi], nf, x);
                    let fb = thickness_box(&faces[fi], &face_t[fi], d, nf, x);
                    (b[6], b[7]) = (fb[6], fb[7]);
                }
            });
    }

    /// Broad phase: candidates of every slave at the positions `x`, whose face boxes
    /// [`Side::update_boxes`] has computed.
    fn build(&mut self, x: &[[f64; 3]], skin: f64) {
        // A slave within t_s/2 + η of a thickness box at some step before the next build
        // was within this of it per component at the build (see `super::staleness`).
        let r = 0.5 * self.slave_t_max + skin + self.box_margin;
        let nf = self.nf;
        let boxes: Vec<([f64; 3], [f64; 3])> = self
            .face_box
            .par_iter()
            .map(|b| {
                (
                    [b[0] - r, b[1] - r, b[2] - r],
                    [b[3] + r, b[4] + r, b[5] + r],
                )
            })
            .collect();
        let grid = Grid::new(&boxes);
        // Candidates: count, then fill, each in parallel over fixed slave chunks.
        let faces = &self.faces;
        let slaves = &self.slaves;
        let (slave_t, face_box, face_dir) = (&self.slave_t, &self.face_box, &self.face_dir);
        let eta = self.box_margin;
        // A slave's candidates, and its margin (see `Side::margin`).
        // (Pushes directly: a closure taking `dyn FnMut` made a call per candidate.)
        let candidates = |si: usize, list: &mut Vec<u32>| -> f64 {
            let s = slaves[si];
            let p = &x[s as usize];
            let mut near = f64::INFINITY;
            for &fi in grid.cell_of(p) {
                // (The inflated box, as `boxes` holds it.)
                let b = &face_box[fi as usize];
                if (0..3).all(|d| p[d] >= b[d] - r && p[d] <= b[d + 3] + r)
                    && !faces[fi as usize][..nf].contains(&s)
                {
                    list.push(fi);
                    near = fmin(near, excess(p, b, &face_dir[fi as usize], nf));
                }
            }
            near - 0.5 * slave_t[si] - 2.0 * eta
        };
        let ns = slaves.len();
        // One pass: each fixed chunk of slaves collects its candidates, the chunks are
        // then joined in order.
        self.margin.resize(ns, 0.0);
        let chunks: Vec<(Vec<u32>, Vec<u32>)> = self
            .margin
            .par_chunks_mut(SLAVE_CHUNK)
            .enumerate()
            .map(|(ci, ms)| {
                let c0 = ci * SLAVE_CHUNK;
                let mut counts = Vec::with_capacity(ms.len());
                let mut list = Vec::new();
                for (j, m) in ms.iter_mut().enumerate() {
                    let before = list.len();
                    *m = candidates(c0 + j, &mut list);
                    counts.push((list.len() - before) as u32);
                }
                (counts, list)
            })
            .collect();
        // The chunks' offsets, then each chunk writes its own slices of the lists and of
        // the pointers, in parallel.
        let mut offsets = Vec::with_capacity(chunks.len());
        let mut total = 0u32;
        for (_, list) in &chunks {
            offsets.push(total);
            total += list.len() as u32;
        }
        let mut ptr = vec![0u32; ns + 1];
        let mut cand = vec![0u32; total as usize];
        let (mut ptr_rest, mut cand_rest) = (&mut ptr[1..], &mut cand[..]);
        let mut jobs = Vec::with_capacity(chunks.len());
        for ((counts, list), &o) in chunks.iter().zip(&offsets) {
            let (p, pt) = std::mem::take(&mut ptr_rest).split_at_mut(counts.len());
            let (c, ct) = std::mem::take(&mut cand_rest).split_at_mut(list.len());
            (ptr_rest, cand_rest) = (pt, ct);
            jobs.push((counts, list, o, p, c));
        }
        jobs.into_par_iter().for_each(|(counts, list, o, p, c)| {
            c.copy_from_slice(list);
            let mut run = o;
            for (q, &n) in p.iter_mut().zip(counts) {
                run += n;
                *q = run;
            }
        });
        self.cand_ptr = ptr;
        self.cand = cand;
    }

    /// After a build at `x`: each slave's cell of the staleness test (`cell`).
    fn set_cells(&mut self, x: &[[f64; 3]], cell: impl Fn(&[f64; 3]) -> usize + Sync) {
        let slaves = &self.slaves;
        self.slave_cell.clear();
        self.slave_cell
            .par_extend(slaves.par_iter().map(|&s| cell(&x[s as usize]) as u32));
    }

    /// Narrow phase and friction for every slave, in parallel chunks, into `out`.
    /// `initial`: report penetrations instead of pushing (setup).
    /// `spread`: per cell of the staleness test, |S| of `Side::margin` at this step
    /// (None: no slave is skipped).
    fn narrow(
        &mut self,
        x: &[[f64; 3]],
        v: &[[f64; 3]],
        dt: f64,
        dt_prev: f64,
        initial: bool,
        spread: Option<&[f64]>,
    ) {
        // One copy per face kind, so that the loops over a face's nodes are unrolled.
        match self.nf {
            2 => self.narrow_n::<2>(x, v, dt, dt_prev, initial, spread),
            3 => self.narrow_n::<3>(x, v, dt, dt_prev, initial, spread),
            _ => self.narrow_n::<4>(x, v, dt, dt_prev, initial, spread),
        }
    }

    fn narrow_n<const NF: usize>(
        &mut self,
        x: &[[f64; 3]],
        v: &[[f64; 3]],
        dt: f64,
        dt_prev: f64,
        initial: bool,
        spread: Option<&[f64]>,
    ) {
        let (face_box, face_dir) = (&self.face_box, &self.face_dir);
        let (margin, slave_cell) = (&self.margin, &self.slave_cell);
        let (faces, nf, face_t, face_m) = (&self.faces, NF, &self.face_t, &self.face_m);
        let (slaves, slave_t, slave_m) = (&self.slaves, &self.slave_t, &self.slave_m);
        let (cand_ptr, cand) = (&self.cand_ptr, &self.cand);
        let (fr, kappa, zeta) = (self.friction, self.kappa, self.damping);
        let keep = self.on_initial == InitialPenetration::Keep;
        let eta = self.box_margin;
        let dt2 = dt * dt;
        let nchunks = self.slaves.len().div_ceil(SLAVE_CHUNK);
        self.chunk_active.resize_with(nchunks, Vec::new);
        self.chunk_reactions.resize_with(nchunks, Vec::new);
        self.chunk_sums.resize(nchunks, ChunkSums::default());
        type Chunk<'c> = (
            usize,
            (
                (
                    (
                        (&'c mut [PairOut], (&'c mut [SlaveState], &'c mut [bool])),
                        &'c mut Vec<u32>,
                    ),
                    &'c mut Vec<Reaction>,
                ),
                &'c mut ChunkSums,
            ),
        );
        let body = |(ci, ((((outs, (sts, held)), active), reactions), sums)): Chunk| {
            active.clear();
            reactions.clear();
            *sums = ChunkSums::default();
            // Scratch of the slaves (only the first n_pen, nn entries are read):
            // declared once per chunk, not zeroed per slave.
            let mut pen = [(0u32, [0.0f64; 4], 0.0f64); MAX_SHARED];
            let mut near = [0u32; 32];
            // (A slave that is open and holds no state is not written: its output is
            // read only while it is in contact, and its state is the default one. At the
            // setup every slave is written.)
            for (j, ((o, st), hd)) in outs
                .iter_mut()
                .zip(sts.iter_mut())
                .zip(held.iter_mut())
                .enumerate()
            {
                let si = ci * SLAVE_CHUNK + j;
                if spread.is_some_and(|sp| margin[si] > sp[slave_cell[si] as usize]) {
                    // No candidate can pass the filter (see `Side::margin`): what the
                    // full test gives a slave that finds no face.
                    sums.skipped += 1;
                    if *hd {
                        st.g0 = 0.0;
                        sums.dissipated += release(st);
                        *hd = false;
                    }
                    continue;
                }
                let s = slaves[si] as usize;
                let p = x[s];
                // The candidate of largest raw penetration.
                let mut best: Option<(u32, f64, [f64; 3])> = None;
                // Σ g n over the faces the node penetrates, and how many: in a concave
                // crease (a node under a tent of two faces) both feet are valid and the
                // nearer one's normal flips as the node crosses the bisector; the
                // penetration-weighted normal turns continuously instead.
                let (mut n_sum, mut n_count) = ([0.0f64; 3], 0u32);
                let (mut tg_sum, mut g_sum) = ([0.0f64; 3], 0.0f64);
                // The faces it penetrates (face, weights, g), the deepest MAX_SHARED: the
                // reaction is shared over them as the normal is, so that a node over a
                // vertex or a ridge, whose faces tie, pushes them all alike (the deepest
                // alone, ties to the first in face order, pushed one side only, and the
                // reaction jumped between faces as the node moved: measured, a formed weave
                // tiled from its mirror-symmetric cell was out of balance by 0.10 of the
                // crossing force at the vertex's neighbours, and drifted when left alone).
                let mut n_pen = 0usize;
                // A face can be penetrated only if the slave is within t_s/2 of its
                // thickness box: the foot q = Σ w_a x_a is a convex combination of the
                // nodes (each triangle's barycentric weights, averaged over a quad's
                // two splits), and t_F = Σ w_a t_a the same combination of their
                // thicknesses, so the ball of radius t_F/2 about q lies in the box, and
                // |x_s − q| < (t_s + t_F)/2 puts x_s within t_s/2 of it. The test in
                // floating point keeps η = 10⁻⁹ (|x|_max + reach) more, 10⁶ times the
                // round-off of the foot and the box, so that it rejects only faces
                // that the closest-point test below rejects too: the same bits.
                let reach = 0.5 * slave_t[si] + eta;
                let r2 = reach * reach;
                // Only faces the node penetrates (g > 0) matter: a node whose best g is
                // ≤ 0 is open whether or not some face was evaluated, and a tracked initial
                // penetration g₀ then drops to 0 either way.
                let list = &cand[cand_ptr[si] as usize..cand_ptr[si + 1] as usize];
                sums.tested += list.len() as u64;
                for block in list.chunks(32) {
                    let nn = filter_block::<NF>(
                        p[0], p[1], p[2], reach, r2, block, face_box, face_dir, &mut near,
                    );
                    sums.evaluated += nn as u64;
                    for &fi in &near[..nn] {
                        let Some(Hit {
                            w,
                            g,
                            dist,
                            r,
                            tg,
                            flat,
                        }) = evaluate_face::<NF>(
                            p[0],
                            p[1],
                            p[2],
                            slave_t[si],
                            &faces[fi as usize],
                            &face_t[fi as usize],
                            x,
                        )
                        else {
                            continue;
                        };
                        sums.penetrated += 1;
                        if n_pen < MAX_SHARED {
                            pen[n_pen] = (fi, w, g);
                            n_pen += 1;
                        } else {
                            // Full: replace the shallowest (the first of equals).
                            let mut k = 0;
                            for j in 1..MAX_SHARED {
                                if pen[j].2 < pen[k].2 {
                                    k = j;
                                }
                            }
                            if g > pen[k].2 {
                                pen[k] = (fi, w, g);
                            }
                        }
                        if dist > 0.0 {
                            for d in 0..3 {
                                n_sum[d] += g * r[d] / dist;
                                tg_sum[d] += g * tg[d];
                            }
                            g_sum += g;
                            n_count += 1;
                        }
                        if best.as_ref().is_none_or(|b| g > b.1) {
                            let n = if dist > 0.0 {
                                [r[0] / dist, r[1] / dist, r[2] / dist]
                            } else {
                                flat
                            };
                            best = Some((fi, g, n));
                        }
                    }
                }
                let mut out = PairOut {
                    face: u32::MAX,
                    ..Default::default()
                };
                let g_raw = best.as_ref().map_or(f64::NEG_INFINITY, |b| b.1);
                if initial {
                    st.g0 = if keep { 0.0 } else { g_raw.max(0.0) };
                    *hd = st.g0 != 0.0;
                    if let Some(b) = &best {
                        out.face = if g_raw > 0.0 { b.0 } else { u32::MAX };
                    }
                    *o = out;
                    continue;
                }
                if !*hd && !(g_raw > 0.0) {
                    // Open before and now, holding nothing (g₀ = 0, no stick spring):
                    // nothing changes.
                    continue;
                }
                // The tracked initial penetration shrinks as the node leaves.
                if g_raw < st.g0 {
                    st.g0 = g_raw.max(0.0);
                }
                let g = g_raw - st.g0;
                match best {
                    Some((fi, _, mut n)) if g > 0.0 => {
                        if n_count > 1 {
                            let l = dot(&n_sum, &n_sum).sqrt();
                            if l > 0.0 {
                                n = [n_sum[0] / l, n_sum[1] / l, n_sum[2] / l];
                            }
                        }
                        // Shares λ_F = g_F/Σg of the penetrated faces; the foot's mass
                        // and velocity are their λ-weighted interpolations, so that the
                        // penalty and the friction slip are continuous as faces come and
                        // go, and the power of the shared reaction is −f·v_foot.
                        let g_pen: f64 = pen[..n_pen].iter().map(|e| e.2).sum();
                        let ms = slave_m[si];
                        let (mut mf, mut vf) = (0.0f64, [0.0f64; 3]);
                        for &(fj, wj, gj) in &pen[..n_pen] {
                            let lam = gj / g_pen;
                            let fn_ = &faces[fj as usize];
                            let fm = &face_m[fj as usize];
                            for a in 0..nf {
                                let la = lam * wj[a];
                                mf += la * fm[a];
                                let va = &v[fn_[a] as usize];
                                for d in 0..3 {
                                    vf[d] += la * va[d];
                                }
                            }
                        }
                        let mstar = if ms > 0.0 { ms.min(mf) } else { mf };
                        let k = kappa * mstar / dt2;
                        let vr = sub(&v[s], &vf);
                        let vn = dot(&vr, &n);
                        let vt = [vr[0] - vn * n[0], vr[1] - vn * n[1], vr[2] - vn * n[2]];
                        let (mut force, stored, mut diss) =
                            pair_force(g, &n, k, &vt, dt_prev, &fr, st);
                        // Where the face's thickness varies (a lenticular band), the
                        // contact distance depends on where the foot lies: the force is
                        // −∂(½kg²)/∂x_s = k g (n − ½∇t_F), normal to the thickness
                        // envelope rather than to the mid-surface; ∇t_F is weighted over
                        // the penetrated faces like n, so that it turns continuously over
                        // the ridge of a band's centre line.
                        if g_sum > 0.0 {
                            for d in 0..3 {
                                force[d] -= 0.5 * k * g * tg_sum[d] / g_sum;
                            }
                        }
                        if zeta > 0.0 {
                            // Normal dashpot, never pulling the surfaces together.
                            let c = 2.0 * zeta * (k * mstar).sqrt();
                            let fd = (-c * vn).max(-k * g);
                            for d in 0..3 {
                                force[d] += fd * n[d];
                            }
                            diss -= fd * vn * dt_prev;
                        }
                        out = PairOut {
                            face: fi,
                            f: force,
                            stored,
                            dissipated: diss,
                            g,
                        };
                        for &(fj, wj, gj) in &pen[..n_pen] {
                            let lam = gj / g_pen;
                            reactions.push(Reaction {
                                slave: si as u32,
                                face: fj,
                                w: std::array::from_fn(|a| lam * wj[a]),
                            });
                        }
                    }
                    _ => out.dissipated = release(st),
                }
                *hd = st.k != 0.0 || st.g0 != 0.0 || st.ft != [0.0; 3];
                if out.face != u32::MAX {
                    active.push(si as u32);
                    sums.stored += out.stored;
                }
                sums.dissipated += out.dissipated;
                *o = out;
            }
        };
        if self.slaves.len() <= SLAVE_CHUNK {
            self.out
                .chunks_mut(SLAVE_CHUNK)
                .zip(
                    self.state
                        .chunks_mut(SLAVE_CHUNK)
                        .zip(self.held.chunks_mut(SLAVE_CHUNK)),
                )
                .zip(self.chunk_active.iter_mut())
                .zip(self.chunk_reactions.iter_mut())
                .zip(self.chunk_sums.iter_mut())
                .enumerate()
                .for_each(body);
        } else {
            self.out
                .par_chunks_mut(SLAVE_CHUNK)
                .zip(
                    self.state
                        .par_chunks_mut(SLAVE_CHUNK)
                        .zip(self.held.par_chunks_mut(SLAVE_CHUNK)),
                )
                .zip(self.chunk_active.par_iter_mut())
                .zip(self.chunk_reactions.par_iter_mut())
                .zip(self.chunk_sums.par_iter_mut())
                .enumerate()
                // A task per few chunks: the slaves in contact cluster under the nose, and
                // rayon's default split leaves quarters of the range that a second thread
                // cannot steal from (measured by thread in perf: the narrow phase's
                // samples 14.8 % against 13.2 %, the second thread idle meanwhile).
                .with_max_len(NARROW_TASK_CHUNKS)
                .for_each(body);
        }
    }
}

/// The squared Euclidean distance from `p` to the box (lo, hi) = (b[0..3], b[3..6]),
/// without branches (the narrow phase's box test and the build's margins).
#[inline(always)]
fn box_distance2(p: &[f64; 3], b: &[f64; 8]) -> f64 {
    let mut d2 = 0.0;
    for d in 0..3 {
        let e = fmax(fmax(b[d] - p[d], p[d] - b[d + 3]), 0.0);
        d2 += e * e;
    }
    d2
}

/// How far a slave at `p` is from a face's thickness box (Euclidean distance) or beyond
/// either of its envelope bounds, whichever is more [m] (see [`Side::margin`]).
#[inline(always)]
fn excess(p: &[f64; 3], b: &[f64; 8], m: &[f32; 6], nf: usize) -> f64 {
    let e = box_distance2(p, b).sqrt();
    if nf < 3 {
        return e;
    }
    let m: [f64; 6] = std::array::from_fn(|k| m[k] as f64);
    let up = m[0] * p[0] + m[1] * p[1] + m[2] * p[2] - b[6];
    let dn = m[3] * p[0] + m[4] * p[1] + m[5] * p[2] - b[7];
    fmax(e, fmax(up, dn))
}

/// A slave opens: its stick spring is released, and what it stored is dissipated (the
/// returned work [J]).
#[inline]
fn release(st: &mut SlaveState) -> f64 {
    let w = if st.k > 0.0 {
        dot(&st.ft, &st.ft) / (2.0 * st.k)
    } else {
        0.0
    };
    st.ft = [0.0; 3];
    st.k = 0.0;
    w
}

/// A face a slave penetrates: the weights `w` of its foot q, the penetration `g` = c − |r|
/// (c = (t_s + t_F)/2), |r| and r = x_s − q, the face's in-plane thickness gradient (when
/// |r| > 0) and, for a slave on the mid-surface (|r| = 0), the face's unit normal.
struct Hit {
    w: [f64; 4],
    g: f64,
    dist: f64,
    r: [f64; 3],
    tg: [f64; 3],
    flat: [f64; 3],
}

/// The closest point of face `f` (thicknesses `ft`) to a slave at (px, py, pz) of
/// thickness `ts`, and whether the slave penetrates it. (A function of its own: inlined in
/// the slave loop, the gathers of the face's nodes went through the stack and were
/// reloaded as pairs spanning two stores; the compiler still reads the thicknesses only
/// after the projection, where perf puts most of this function's own samples.)
#[inline(never)]
#[allow(clippy::too_many_arguments)]
fn evaluate_face<const NF: usize>(
    px: f64,
    py: f64,
    pz: f64,
    ts: f64,
    f: &[u32; 4],
    ft: &[f64; 4],
    x: &[[f64; 3]],
) -> Option<Hit> {
    let (f, t) = (*f, *ft);
    let p = [px, py, pz];
    let xf: [[f64; 3]; 4] = [
        x[f[0] as usize],
        x[f[1] as usize],
        if NF > 2 { x[f[2] as usize] } else { [0.0; 3] },
        if NF > 3 { x[f[3] as usize] } else { [0.0; 3] },
    ];
    let nf = NF;
    let w = closest_on_face(&p, &xf, nf);
    let q: [f64; 3] = std::array::from_fn(|d| (0..nf).map(|a| w[a] * xf[a][d]).sum());
    let tf: f64 = (0..nf).map(|a| w[a] * t[a]).sum();
    let r = sub(&p, &q);
    let c = 0.5 * (ts + tf);
    let d2 = dot(&r, &r);
    if d2 >= c * c {
        return None;
    }
    let dist = d2.sqrt();
    let (tg, flat) = if dist > 0.0 {
        (thickness_gradient(&t, &xf, nf), [0.0; 3])
    } else {
        let c = cross(&sub(&xf[1], &xf[0]), &sub(&xf[nf - 1], &xf[0]));
        let cn = dot(&c, &c).sqrt();
        let n = if cn > 0.0 {
            [c[0] / cn, c[1] / cn, c[2] / cn]
        } else {
            [0.0, 0.0, 1.0]
        };
        ([0.0; 3], n)
    };
    Some(Hit {
        w,
        g: c - dist,
        dist,
        r,
        tg,
        flat,
    })
}

/// The larger and the smaller of two numbers by one comparison, for the per-step box
/// computation and the box test: `f64::max`'s NaN rule took a third of the box test's
/// instructions. For finite values the same results; positions are finite whenever
/// contact runs (the model's coordinates are checked, and the integrator stops the run on
/// the step a position goes non-finite).
#[inline(always)]
fn fmax(a: f64, b: f64) -> f64 {
    if a > b {
        a
    } else {
        b
    }
}

/// See [`fmax`].
#[inline(always)]
fn fmin(a: f64, b: f64) -> f64 {
    if a < b {
        a
    } else {
        b
    }
}

/// The candidates of `block` a slave at (px, py, pz) may penetrate, in order, into `near`;
/// returns how many. First, without branches, the distance to each face's thickness box
/// at this step (within `reach` = t_s/2 + η, r2 its square).
/// Then, of those, the faces whose envelope bounds h± along m± the slave is within
/// t_s/2 + η of: the ball of radius t_F/2 about the foot q = Σ w_a x_a has the support
/// m·q + t_F/2 = Σ w_a (m·x_a + t_a/2) ≤ max_a (m·x_a + t_a/2) = h along a unit m, so a
/// slave with m·x_s ≥ h + t_s/2 is at least (t_s + t_F)/2 from q (η as in the box test:
/// the same bits). Measured on the 60 × 60 to 20 µs: 60 % of the faces that pass the box
/// test fail this one, none penetrated. (A function of its own, with the slave's position
/// in registers: inlined, the position was spilled and reloaded across the loop.)
#[inline(never)]
#[allow(clippy::too_many_arguments)]
fn filter_block<const NF: usize>(
    px: f64,
    py: f64,
    pz: f64,
    reach: f64,
    r2: f64,
    block: &[u32],
    face_box: &[[f64; 8]],
    face_dir: &[[f32; 6]],
    near: &mut [u32; 32],
) -> usize {
    let p = [px, py, pz];
    let mut nn = 0;
    for &fi in block {
        let d2 = box_distance2(&p, &face_box[fi as usize]);
        near[nn] = fi;
        nn += (d2 <= r2) as usize;
    }
    if NF >= 3 {
        let mut kept = 0;
        for i in 0..nn {
            let fi = near[i];
            let (m, b) = (&face_dir[fi as usize], &face_box[fi as usize]);
            let m: [f64; 6] = std::array::from_fn(|k| m[k] as f64);
            let up = m[0] * p[0] + m[1] * p[1] + m[2] * p[2] - b[6];
            let dn = m[3] * p[0] + m[4] * p[1] + m[5] * p[2] - b[7];
            near[kept] = fi;
            kept += (fmax(up, dn) < reach) as usize;
        }
        nn = kept;
    }
    nn
}

/// The broad phase's skin as a fraction of the mean face size of the finest surface: a
/// larger skin means fewer builds but more candidates per slave. Measured on the 60 × 60
/// woven quarter to 60 µs (2 threads, alternately): at ¼, 510 builds and 47.6, 48.6 s
/// (broad phase 11.9, 12.4 s; narrow 26.2, 26.6 s); at ½, 274 builds and 44.1, 42.6 s
/// (broad 8.2, 7.9 s; narrow 26.6, 25.7 s); at ¾, 181 builds and 49.1 s (narrow 30.8 s:
/// the candidates' box tests outgrow what the builds save).
const SKIN_PER_FACE: f64 = 0.5;

/// Most cells a broad-phase grid may have per face box (past it, the cells grow).
const GRID_CELLS_PER_BOX: usize = 8;

/// Blocks of rows the broad-phase grid is filled by, in parallel (the grid is the same for
/// any number).
const GRID_BLOCKS: usize = 32;

/// Cell size of the broad-phase grid as a fraction of the largest inflated face box:
/// smaller cells list fewer boxes per lookup, but each box is entered in more cells
/// (≤ 27 at ½). Measured on the 30 × 30 woven quarter (1 thread, 1141 steps): broad
/// phase 1.0 s at 1, 0.9 s at ½ and at 0.35.
const GRID_CELL_FRACTION: f64 = 0.5;

/// Uniform grid over the inflated face boxes, as a dense array of cells (CSR): a cell is
/// [`GRID_CELL_FRACTION`] of the largest box, so each box lies in ≤ 27 cells, and a
/// point's candidates are the boxes listed in its own cell, in face order (a counting
/// sort: O(n), no sort, and no search per point; filled in parallel by blocks of rows).
struct Grid {
    origin: [f64; 3],
    h: f64,
    dims: [usize; 3],
    ptr: Vec<u32>,
    items: Vec<u32>,
}

impl Grid {
    fn new(boxes: &[([f64; 3], [f64; 3])]) -> Grid {
        // Bounds and the largest box: minima and maxima, exact in any order.
        type Bounds = ([f64; 3], [f64; 3], f64);
        let merge = |p: Bounds, q: Bounds| -> Bounds {
            (
                std::array::from_fn(|d| p.0[d].min(q.0[d])),
                std::array::from_fn(|d| p.1[d].max(q.1[d])),
                p.2.max(q.2),
            )
        };
        let none: Bounds = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3], 1e-12);
        let (lo, hi, mut h) = boxes
            .par_iter()
            .fold(
                || none,
                |acc, (a, b)| {
                    let w = (0..3)
                        .map(|d| b[d] - a[d])
                        .fold(f64::NEG_INFINITY, f64::max);
                    merge(acc, (*a, *b, w))
                },
            )
            .reduce(|| none, merge);
        h *= GRID_CELL_FRACTION;
        if boxes.is_empty() || !(0..3).all(|d| lo[d].is_finite() && hi[d].is_finite()) {
            return Grid {
                origin: [0.0; 3],
                h: 1.0,
                dims: [0; 3],
                ptr: vec![0],
                items: vec![],
            };
        }
        // A few cells per box at most (a patch whose faces are far apart in one
        // direction would otherwise ask for a huge, empty grid).
        let cap = GRID_CELLS_PER_BOX * boxes.len() + 64;
        let mut dims = [1usize; 3];
        loop {
            for d in 0..3 {
                dims[d] = ((hi[d] - lo[d]) / h).floor() as usize + 1;
            }
            if dims[0].saturating_mul(dims[1]).saturating_mul(dims[2]) <= cap {
                break;
            }
            h *= 1.5;
        }
        let ncell = dims[0] * dims[1] * dims[2];
        // Truncation is the floor here: every coordinate is ≥ the origin.
        let cell = |p: &[f64; 3]| -> [u32; 3] {
            std::array::from_fn(|d| {
                (((p[d] - lo[d]) / h).max(0.0) as usize).min(dims[d] - 1) as u32
            })
        };
        // Each box's cell range (first, last per axis).
        let span: Vec<[[u32; 3]; 2]> = boxes.par_iter().map(|(a, b)| [cell(a), cell(b)]).collect();
        // The cells are filled by blocks of whole rows (a row: the cells of one (j, k)),
        // in parallel: each block takes the boxes that reach its rows, in box order, so a
        // cell lists its boxes in box order whatever the blocks (a counting sort).
        let nrows = dims[1] * dims[2];
        let rows_per = nrows.div_ceil(GRID_BLOCKS).max(1);
        let nblocks = nrows.div_ceil(rows_per);
        let row_of = |j: u32, k: u32| grid_row(&dims, j, k);
        // The boxes that reach each block, in box order: found in parallel over fixed
        // ranges of boxes (`members[r][b]`, read range after range; the same lists for
        // any number of threads), each row's block looked up rather than divided for
        // (measured: this loop was most of the rebuild's serial time).
        let block_of: Vec<u32> = (0..nrows).map(|r| (r / rows_per) as u32).collect();
        let per_range = span.len().div_ceil(GRID_BLOCKS).max(1);
        let members: Vec<Vec<Vec<u32>>> = span
            .par_chunks(per_range)
            .enumerate()
            .map(|(ri, range)| {
                let f0 = ri * per_range;
                let mut m: Vec<Vec<u32>> = vec![Vec::new(); nblocks];
                for (j, [ca, cb]) in range.iter().enumerate() {
                    let mut last = usize::MAX;
                    for k in ca[2]..=cb[2] {
                        let (b0, b1) = (
                            block_of[row_of(ca[1], k)] as usize,
                            block_of[row_of(cb[1], k)] as usize,
                        );
                        for b in b0.max(last.wrapping_add(1))..=b1 {
                            m[b].push((f0 + j) as u32);
                            last = b;
                        }
                    }
                }
                m
            })
            .collect();
        let block_members = |b: usize| members.iter().flat_map(move |m| m[b].iter().copied());
        // Visit the cells of block `b` that box `fi` covers (a generic function, not a
        // closure taking `dyn FnMut`: the visits inline, without a call per cell).
        #[inline(always)]
        fn visit(
            span: &[[u32; 3]; 2],
            (r0, r1): (usize, usize),
            dims: &[usize; 3],
            mut f: impl FnMut(usize),
        ) {
            let [ca, cb] = span;
            for k in ca[2]..=cb[2] {
                for j in ca[1]..=cb[1] {
                    let r = grid_row(dims, j, k);
                    if r < r0 || r >= r1 {
                        continue;
                    }
                    for i in ca[0]..=cb[0] {
                        f((r - r0) * dims[0] + i as usize);
                    }
                }
            }
        }
        let rows = |b: usize| (b * rows_per, ((b + 1) * rows_per).min(nrows));
        // Counts, then each block's running sums, then the blocks' offsets.
        let block_cells = rows_per * dims[0];
        let mut count = vec![0u32; ncell + 1];
        let totals: Vec<u32> = count[1..]
            .par_chunks_mut(block_cells)
            .enumerate()
            .map(|(b, cnt)| {
                for fi in block_members(b) {
                    visit(&span[fi as usize], rows(b), &dims, |c| cnt[c] += 1);
                }
                let mut run = 0u32;
                for c in cnt.iter_mut() {
                    run += *c;
                    *c = run;
                }
                run
            })
            .collect();
        let mut offsets = Vec::with_capacity(nblocks);
        let mut run = 0u32;
        for t in &totals {
            offsets.push(run);
            run += t;
        }
        count[1..]
            .par_chunks_mut(block_cells)
            .zip(&offsets)
            .for_each(|(cnt, &o)| cnt.iter_mut().for_each(|c| *c += o));
        // Fill: each block writes its own slice of the items.
        let mut items = vec![0u32; run as usize];
        let mut slices: Vec<&mut [u32]> = Vec::with_capacity(nblocks);
        let mut rest: &mut [u32] = &mut items;
        for t in &totals {
            let (head, tail) = rest.split_at_mut(*t as usize);
            slices.push(head);
            rest = tail;
        }
        let ptr = &count;
        slices.into_par_iter().enumerate().for_each(|(b, out)| {
            let c0 = b * block_cells;
            let base = offsets[b];
            let mut fill: Vec<u32> = ptr[c0..(c0 + block_cells).min(ncell)]
                .iter()
                .map(|&p| p - base)
                .collect();
            for fi in block_members(b) {
                visit(&span[fi as usize], rows(b), &dims, |c| {
                    out[fill[c] as usize] = fi;
                    fill[c] += 1;
                });
            }
        });
        Grid {
            origin: lo,
            h,
            dims,
            ptr: count,
            items,
        }
    }

    /// The boxes listed in the cell of `p` (none outside the grid).
    fn cell_of(&self, p: &[f64; 3]) -> &[u32] {
        let mut c = [0usize; 3];
        for d in 0..3 {
            let v = (p[d] - self.origin[d]) / self.h;
            if !(v >= 0.0 && v < self.dims[d] as f64) {
                return &[];
            }
            // v ≥ 0: truncation is the floor.
            c[d] = v as usize;
        }
        let i = (c[2] * self.dims[1] + c[1]) * self.dims[0] + c[0];
        &self.items[self.ptr[i] as usize..self.ptr[i + 1] as usize]
    }
}

/// The row (the cells of one (j, k)) of the grid's cell indices j, k.
#[inline(always)]
fn grid_row(dims: &[usize; 3], j: u32, k: u32) -> usize {
    k as usize * dims[1] + j as usize
}

/// Round-off allowance of the thickness-box tests relative to the largest coordinate of a
/// side's nodes: its foot and box are computed within ~10⁻¹⁵ of that.
const BOX_MARGIN: f64 = 1e-9;

/// The thickness box of a face (`nf` nodes `f` of nodal thicknesses `t`) at `x`: the
/// bounding box of the balls of radius t_a/2 about its nodes, (lo, hi); then the bounds
/// h = max_a (m·x_a + t_a/2) of those balls along the face's two envelope directions
/// `m` (m₊ then m₋).
#[inline]
fn thickness_box(f: &[u32; 4], t: &[f64; 4], m: &[f32; 6], nf: usize, x: &[[f64; 3]]) -> [f64; 8] {
    let m: [f64; 6] = std::array::from_fn(|k| m[k] as f64);
    let mut b = [
        f64::INFINITY,
        f64::INFINITY,
        f64::INFINITY,
        f64::NEG_INFINITY,
        f64::NEG_INFINITY,
        f64::NEG_INFINITY,
        f64::NEG_INFINITY,
        f64::NEG_INFINITY,
    ];
    for a in 0..nf {
        let (xa, r) = (&x[f[a] as usize], 0.5 * t[a]);
        for d in 0..3 {
            b[d] = fmin(b[d], xa[d] - r);
            b[d + 3] = fmax(b[d + 3], xa[d] + r);
        }
        b[6] = fmax(b[6], m[0] * xa[0] + m[1] * xa[1] + m[2] * xa[2] + r);
        b[7] = fmax(b[7], m[3] * xa[0] + m[4] * xa[1] + m[5] * xa[2] + r);
    }
    b
}

/// The unit directions m₊, m₋ of a face's envelope bounds (see [`Side::set_directions`]);
/// zero where the face has no normal or the direction is ill-defined (a zero direction
/// never rejects: its bound is max_a t_a/2 ≥ 0).
fn envelope_directions(f: &[u32; 4], t: &[f64; 4], nf: usize, x: &[[f64; 3]]) -> [f32; 6] {
    let xf: [[f64; 3]; 4] =
        std::array::from_fn(|a| if a < nf { x[f[a] as usize] } else { [0.0; 3] });
    let n = if nf == 4 {
        cross(&sub(&xf[2], &xf[0]), &sub(&xf[3], &xf[1]))
    } else {
        cross(&sub(&xf[1], &xf[0]), &sub(&xf[2], &xf[0]))
    };
    let ln = dot(&n, &n).sqrt();
    if !ln.is_finite() || ln <= 0.0 {
        return [0.0; 6];
    }
    // Stored in single precision (half the memory traffic of the step's bounds), shrunk
    // by 2·10⁻⁷ first so that the rounded direction is still no longer than 1 (each
    // component rounds by at most 6·10⁻⁸ of itself): the bound stays sound.
    const SHRINK: f64 = 1.0 - 2e-7;
    let g = thickness_gradient(t, &xf, nf);
    let mut out = [0.0; 6];
    for (k, sign) in [1.0, -1.0].into_iter().enumerate() {
        let m: [f64; 3] = std::array::from_fn(|d| sign * n[d] / ln - 0.5 * g[d]);
        let l = dot(&m, &m).sqrt();
        // |m| ≥ 1 − ½|∇t_F| ≥ 0 (the gradient is capped at 2): a direction left nearly
        // undefined by cancellation is not used.
        if l > 1e-3 && l.is_finite() {
            for d in 0..3 {
                out[3 * k + d] = (SHRINK * m[d] / l) as f32;
            }
        }
    }
    out
}

fn bbox(f: &[u32; 4], nf: usize, x: &[[f64; 3]]) -> ([f64; 3], [f64; 3]) {
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for &n in &f[..nf] {
        for d in 0..3 {
            lo[d] = lo[d].min(x[n as usize][d]);
            hi[d] = hi[d].max(x[n as usize][d]);
        }
    }
    (lo, hi)
}

/// Every contact definition of a model, and the broad phase they share.
#[derive(Debug, Clone, Default)]
pub struct SurfaceContact {
    pub sides: Vec<Side>,
    /// Nodes that take part (slaves and face nodes), sorted.
    nodes: Vec<u32>,
    /// Their positions at the last broad phase, and the test of when the candidate lists
    /// go stale.
    motion: Staleness,
    /// Whether the narrow phase skips the slaves that no candidate can reach yet (see
    /// `Side::margin`; on by default, the same results either way).
    pub skip_far: bool,
    /// Skin of the broad phase [m].
    pub skin: f64,
    /// Largest κ_c of the definitions (stable-step guard).
    pub kappa_max: f64,
    /// Broad-phase builds so far, and the wall time of the builds and of the narrow
    /// phase with the scatter.
    pub builds: u64,
    pub build_time: std::time::Duration,
    pub narrow_time: std::time::Duration,
    /// The same by phase; slave-steps so far, and the chunks' counts summed over them
    /// (see [`ContactReport`]).
    phases: ContactPhases,
    slave_steps: u64,
    counts: ChunkSums,
    /// Friction work dissipated so far [J].
    pub dissipated: f64,
    /// Stored energy at the last force evaluation [J].
    pub stored: f64,
    pub initial: Vec<InitialPen>,
}

impl SurfaceContact {
    /// The definitions of `m`, sides built with the nodal masses `mass`.
    pub fn new(m: &Model, mass: &[f64]) -> SurfaceContact {
        let mut sides = Vec::new();
        for (row, d) in m.contacts.iter().enumerate() {
            sides.push(Side::new(m, row, &d.slave, d.master, mass));
            if d.two_way {
                if let Slave::Part(p) = d.slave {
                    sides.push(Side::new(m, row, &Slave::Part(d.master), p, mass));
                }
            }
        }
        let mut nodes: Vec<u32> = sides
            .iter()
            .flat_map(|s| {
                s.slaves
                    .iter()
                    .copied()
                    .chain(s.faces.iter().flat_map(|f| f[..s.nf].to_vec()))
            })
            .collect();
        nodes.sort_unstable();
        nodes.dedup();
        // Skin: [`SKIN_PER_FACE`] of the mean face size of the finest surface.
        let skin = sides
            .iter()
            .map(|s| s.mean_face_size(&m.coords))
            .filter(|&h| h > 0.0)
            .fold(f64::INFINITY, f64::min);
        let skin = if skin.is_finite() {
            SKIN_PER_FACE * skin
        } else {
            0.0
        };
        let kappa_max = sides.iter().map(|s| s.kappa).fold(0.0, f64::max);
        SurfaceContact {
            sides,
            nodes,
            motion: Staleness::new(skin),
            skip_far: true,
            skin,
            kappa_max,
            builds: 0,
            dissipated: 0.0,
            stored: 0.0,
            initial: vec![],
            ..Default::default()
        }
    }

    pub fn is_empty(&self) -> bool {
        self.sides.is_empty()
    }

    /// Normal viscous damping ζ (fraction of critical) on every pair of every side.
    pub fn set_normal_damping(&mut self, zeta: f64) {
        for s in &mut self.sides {
            s.damping = zeta;
        }
    }

    /// The deepest penetration at the last force evaluation, relative to the contact
    /// distance of the thickest slave and face of its side, (t_s,max + t_F,max)/2 (the
    /// centre-line distance of two crossing yarns; a thin band edge's own distance would
    /// make a sub-micrometre overlap look deep): (ratio, g [m], contact id, slave node,
    /// face element).
    pub fn deepest(&self) -> Option<(f64, f64, i64, usize, i64)> {
        let mut best: Option<(f64, f64, i64, usize, i64)> = None;
        for s in &self.sides {
            for (si, o) in s.out.iter().enumerate() {
                if o.face == u32::MAX || s.reach <= 0.0 {
                    continue;
                }
                let r = o.g / s.reach;
                if best.as_ref().is_none_or(|b| r > b.0) {
                    best = Some((
                        r,
                        o.g,
                        s.contact_id,
                        s.slaves[si] as usize,
                        s.face_id[o.face as usize],
                    ));
                }
            }
        }
        best
    }

    /// Broad phase for every side at `x` (whose thickness boxes are up to date).
    fn rebuild(&mut self, x: &[[f64; 3]]) {
        for s in &mut self.sides {
            s.set_directions(x);
            s.build(x, self.skin);
        }
        // ρ + W of the staleness test: the farthest a slave can be from a thickness box
        // that the narrow phase evaluates, and the widest box.
        let rho_w = self
            .sides
            .iter()
            .map(|s| {
                // (A maximum: exact in any order.)
                let w = s
                    .face_box
                    .par_iter()
                    .with_min_len(4096)
                    .map(|b| (b[3] - b[0]).max(b[4] - b[1]).max(b[5] - b[2]))
                    .reduce(|| 0.0, f64::max);
                0.5 * s.slave_t_max + s.box_margin + w
            })
            .fold(0.0, f64::max);
        self.motion.reset(&self.nodes, x, rho_w);
        let motion = &self.motion;
        for s in &mut self.sides {
            s.set_cells(x, |p| motion.cell(p));
        }
        self.builds += 1;
    }

    /// Whether the candidate lists may miss a pair at `x` (see [`Staleness`]).
    fn stale(&mut self, x: &[[f64; 3]]) -> bool {
        self.motion.stale(x)
    }

    /// Setup at the start positions `x` (the reference plus any initial displacement):
    /// the broad phase, and the nodes that start inside a surface (recorded, or an error
    /// when their definition says so).
    pub fn start(&mut self, m: &Model, x: &[[f64; 3]]) -> Result<()> {
        for s in &mut self.sides {
            s.update_boxes(x);
        }
        self.rebuild(x);
        let zero = vec![[0.0; 3]; m.num_nodes()];
        for s in &mut self.sides {
            s.narrow(x, &zero, 1.0, 0.0, true, None);
            for (si, o) in s.out.iter().enumerate() {
                if o.face == u32::MAX {
                    continue;
                }
                let node = s.slaves[si] as usize;
                if s.on_initial == InitialPenetration::Keep {
                    continue;
                }
                let pen = InitialPen {
                    contact_id: s.contact_id,
                    node,
                    element: s.face_id[o.face as usize],
                    depth: s.state[si].g0,
                };
                if s.on_initial == InitialPenetration::Error {
                    let kind = m.parts[m.contacts[s.row].master].kind;
                    return Err(WeftError::input(format!(
                        "node `{}` starts {:.3e} m inside the surface of {} `{}` (contact `{}`)",
                        m.node_id[node],
                        pen.depth,
                        kind.name(),
                        pen.element,
                        s.contact_id
                    ))
                    .in_file("contacts.parquet")
                    .in_column("initial_penetration")
                    .at_row(s.row)
                    .expected("no slave node closer to a face than half their thicknesses at t = 0")
                    .hint("move the node out, lower the thicknesses, or set initial_penetration to `track`"));
                }
                self.initial.push(pen);
            }
        }
        Ok(())
    }

    /// Contact forces at x^n added into `fcon` (which the caller has cleared); the stored
    /// energy and the dissipated work are booked.
    pub fn forces(
        &mut self,
        x: &[[f64; 3]],
        v: &[[f64; 3]],
        dt: f64,
        dt_prev: f64,
        fcon: &mut [[f64; 3]],
    ) {
        let t0 = std::time::Instant::now();
        for s in &mut self.sides {
            s.update_boxes(x);
        }
        let t_boxes = std::time::Instant::now();
        let stale = self.stale(x);
        let t_stale = std::time::Instant::now();
        if stale {
            self.rebuild(x);
        }
        let t1 = std::time::Instant::now();
        self.build_time += t1 - t0;
        let mut stored = 0.0;
        let spread = self.skip_far.then(|| self.motion.spread());
        for s in &mut self.sides {
            s.narrow(x, v, dt, dt_prev, false, spread);
            // Sums in chunk order: bit-identical for any thread count.
            for c in &s.chunk_sums {
                stored += c.stored;
                self.dissipated += c.dissipated;
                self.counts.skipped += c.skipped;
                self.counts.tested += c.tested;
                self.counts.evaluated += c.evaluated;
                self.counts.penetrated += c.penetrated;
            }
            self.slave_steps += s.slaves.len() as u64;
        }
        let t_narrow = std::time::Instant::now();
        let ph = &mut self.phases;
        ph.boxes += (t_boxes - t0).as_secs_f64();
        ph.staleness += (t_stale - t_boxes).as_secs_f64();
        ph.builds += (t1 - t_stale).as_secs_f64();
        ph.narrow += (t_narrow - t1).as_secs_f64();
        // Gather onto the nodes: the nodes are split into one block per thread, and each
        // block takes the contributions to its nodes in the canonical order (side, chunk,
        // the chunk's slaves, then their reactions' face nodes), so every node's sum is the
        // same whatever the split: bit-identical for any thread count, and parallel. `fcon`
        // must be zero at the slaves' and faces' nodes before (the operator clears it).
        let sides = &self.sides;
        let active: usize = sides
            .iter()
            .map(|s| s.chunk_active.iter().map(|a| a.len()).sum::<usize>())
            .sum();
        // Small jobs stay on one thread (same sums, no scheduling cost).
        let blocks = if active < 2048 {
            1
        } else {
            rayon::current_num_threads().max(1)
        };
        let bs = fcon.len().div_ceil(blocks).max(1);
        let gather = |(b, block): (usize, &mut [[f64; 3]])| {
            let (lo, hi) = (b * bs, b * bs + block.len());
            for s in sides {
                for (active, reactions) in s.chunk_active.iter().zip(&s.chunk_reactions) {
                    for &si in active {
                        let sl = s.slaves[si as usize] as usize;
                        if (lo..hi).contains(&sl) {
                            add(&mut block[sl - lo], &s.out[si as usize].f);
                        }
                    }
                    for r in reactions {
                        let f = &s.out[r.slave as usize].f;
                        let face = &s.faces[r.face as usize];
                        for a in 0..s.nf {
                            let n = face[a] as usize;
                            if (lo..hi).contains(&n) {
                                add(
                                    &mut block[n - lo],
                                    &[-r.w[a] * f[0], -r.w[a] * f[1], -r.w[a] * f[2]],
                                );
                            }
                        }
                    }
                }
            }
        };
        if blocks == 1 {
            gather((0, fcon));
        } else {
            fcon.par_chunks_mut(bs).enumerate().for_each(gather);
        }
        self.stored = stored;
        self.phases.scatter += t_narrow.elapsed().as_secs_f64();
        self.narrow_time += t1.elapsed();
    }

    /// A summary for reports.
    pub fn report(&self, node_id: &[i64]) -> ContactReport {
        let deepest = self
            .initial
            .iter()
            .max_by(|a, b| a.depth.total_cmp(&b.depth));
        ContactReport {
            definitions: self
                .sides
                .iter()
                .map(|s| s.row)
                .collect::<std::collections::BTreeSet<_>>()
                .len(),
            slaves: self.sides.iter().map(|s| s.slaves.len()).sum(),
            faces: self.sides.iter().map(|s| s.faces.len()).sum(),
            builds: self.builds,
            active: self.active(),
            initial_penetrations: self.initial.len(),
            deepest: deepest.map(|p| (p.contact_id, node_id[p.node], p.element, p.depth)),
            friction_work: self.dissipated,
            skin: self.skin,
            build_seconds: self.build_time.as_secs_f64(),
            narrow_seconds: self.narrow_time.as_secs_f64(),
            phases: self.phases,
            slave_steps: self.slave_steps,
            skipped: self.counts.skipped,
            tested: self.counts.tested,
            evaluated: self.counts.evaluated,
            penetrated: self.counts.penetrated,
        }
    }

    /// Slaves in contact after the last force evaluation.
    pub fn active(&self) -> usize {
        self.sides
            .iter()
            .map(|s| s.chunk_active.iter().map(|a| a.len()).sum::<usize>())
            .sum()
    }
}

#[cfg(test)]
mod tests {
    use super::super::uniform;
    use super::Grid;

    /// The rectangle 1 × `width` in the xy plane (nodes counter-clockwise from the origin),
    /// each coordinate moved by up to ±`amp`/2 at random: a warped quad.
    fn jittered_rectangle(width: f64, amp: f64, st: &mut u64) -> [[f64; 3]; 4] {
        let mut x = [
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [1.0, width, 0.0],
            [0.0, width, 0.0],
        ];
        for a in &mut x {
            for c in a.iter_mut() {
                *c += amp * (uniform(st) - 0.5);
            }
        }
        x
    }

    /// The triangle kernel's closest point is the projection onto the triangle: by the
    /// projection theorem for a convex set, q is the closest point of the triangle to p iff
    /// (p − q)·(y − q) ≤ 0 for each of its vertices y (the oracle, independent of the
    /// kernel's Voronoi regions), and its weights are barycentric (≥ 0, summing to 1).
    /// The four triangles of random quads' two splits, warped and flat, with points near
    /// and far; degenerate ones (coincident, collinear nodes) must give finite weights and
    /// a point no farther than any vertex.
    #[test]
    fn triangle_projection_satisfies_the_projection_theorem() {
        use super::super::closest_on_triangle;
        let mut st = 11u64;
        let tris = [[0, 1, 2], [0, 2, 3], [1, 2, 3], [1, 3, 0]];
        let (mut n_checked, mut worst) = (0usize, 0.0f64);
        for case in 0..40_000 {
            let mut x = jittered_rectangle(1.0, 0.4, &mut st);
            match case % 8 {
                // Coincident nodes, a collinear quad, a flat one.
                5 => x[2] = x[1],
                6 => {
                    for a in 0..4 {
                        x[a] = [a as f64 * 0.3, 0.0, 0.0];
                    }
                }
                7 => x.iter_mut().for_each(|a| a[2] = 0.0),
                _ => {}
            }
            let mut p: [f64; 3] = std::array::from_fn(|_| 3.0 * (uniform(&mut st) - 0.5) + 0.5);
            match case % 11 {
                // On a vertex, on an edge.
                9 => p = x[(case / 11) % 4],
                10 => p = std::array::from_fn(|d| 0.5 * (x[0][d] + x[1][d])),
                _ => {}
            }
            for t in &tris {
                let w = closest_on_triangle(&p, &x[t[0]], &x[t[1]], &x[t[2]]);
                assert!(
                    w.iter().all(|c| c.is_finite() && *c >= 0.0),
                    "case {case}: {w:?}"
                );
                assert!(
                    (w[0] + w[1] + w[2] - 1.0).abs() < 1e-15,
                    "case {case}: {w:?}"
                );
                let q: [f64; 3] = std::array::from_fn(|d| (0..3).map(|k| w[k] * x[t[k]][d]).sum());
                let r: [f64; 3] = std::array::from_fn(|d| p[d] - q[d]);
                let rr: f64 = r.iter().map(|c| c * c).sum();
                for &y in t {
                    let py: f64 = (0..3).map(|d| (p[d] - x[y][d]).powi(2)).sum();
                    assert!(
                        rr <= py * (1.0 + 1e-14),
                        "case {case}: farther than vertex {y}: {w:?}"
                    );
                }
                if case % 8 == 5 || case % 8 == 6 {
                    continue; // degenerate: the projection theorem needs a true triangle
                }
                for &y in t {
                    let e: f64 = (0..3).map(|d| r[d] * (x[y][d] - q[d])).sum();
                    worst = worst.max(e);
                }
                n_checked += 1;
            }
        }
        // Measured: worst (p − q)·(y − q) 7.6e-16 (round-off on unit-size triangles).
        assert!(n_checked >= 120_000, "{n_checked}");
        assert!(worst < 4e-15, "projection theorem violated by {worst}");
    }

    /// The envelope bounds are sound: no point that penetrates a face by the narrow
    /// phase's own test (closest point q, |x_s − q| < (t_s + t_F)/2) lies beyond either
    /// bound by t_s/2 (the support-function argument in `Side::narrow_n`), over random
    /// warped quads and triangles with random nodal thicknesses (lenticular ones, zero
    /// ones) and slave thicknesses, the directions taken at other, earlier positions as
    /// between broad phases. And they reject what the thickness box cannot: over a flat
    /// quad thinning linearly from h to 0 across its width w, the envelope's top is the
    /// plane of slope s = h/(2w) through the thick edge's top (closed form), so a point
    /// h/4 above the thin edge lies outside it, though inside the box (which is h/2 high).
    #[test]
    fn envelope_bounds_hold_every_penetrating_point() {
        use super::{closest_on_face, envelope_directions, thickness_box};
        let mut st = 5u64;
        let (mut penetrating, mut rejected, mut worst) = (0usize, 0usize, f64::NEG_INFINITY);
        for case in 0..60_000 {
            let nf = if case % 5 == 4 { 3 } else { 4 };
            let x = jittered_rectangle(0.4, 0.3, &mut st);
            let t: [f64; 4] = match case % 3 {
                0 => [0.2, 0.0, 0.0, 0.2],
                1 => std::array::from_fn(|_| 0.3 * uniform(&mut st)),
                _ => [0.1; 4],
            };
            let f = [0u32, 1, 2, 3];
            // Directions from positions a little away from the current ones.
            let earlier: Vec<[f64; 3]> = x
                .iter()
                .map(|a| std::array::from_fn(|d| a[d] + 0.05 * (uniform(&mut st) - 0.5)))
                .collect();
            let m32 = envelope_directions(&f, &t, nf, &earlier);
            let b = thickness_box(&f, &t, &m32, nf, &x);
            let m = m32.map(|v| v as f64);
            let xf: [[f64; 3]; 4] = std::array::from_fn(|a| x[a]);
            let ts = 0.2 * uniform(&mut st);
            for _ in 0..20 {
                let p: [f64; 3] = std::array::from_fn(|d| {
                    b[d] - 0.1 + (b[d + 3] - b[d] + 0.2) * uniform(&mut st)
                });
                let w = closest_on_face(&p, &xf, nf);
                let q: [f64; 3] = std::array::from_fn(|d| (0..nf).map(|a| w[a] * xf[a][d]).sum());
                let tf: f64 = (0..nf).map(|a| w[a] * t[a]).sum();
                let r: [f64; 3] = std::array::from_fn(|d| p[d] - q[d]);
                let c = 0.5 * (ts + tf);
                let beyond = (m[0] * p[0] + m[1] * p[1] + m[2] * p[2] - b[6])
                    .max(m[3] * p[0] + m[4] * p[1] + m[5] * p[2] - b[7])
                    - 0.5 * ts;
                if r[0] * r[0] + r[1] * r[1] + r[2] * r[2] < c * c {
                    penetrating += 1;
                    worst = worst.max(beyond);
                } else if beyond >= 0.0 {
                    rejected += 1;
                }
            }
        }
        // Measured: 306 935 penetrating points, the nearest 7.2e-4 inside its bound;
        // 486 367 of the others rejected.
        assert!(
            penetrating > 100_000 && rejected > 100_000,
            "{penetrating} {rejected}"
        );
        assert!(
            worst < 0.0,
            "a penetrating point beyond its bound by {worst:e}"
        );

        // The closed form: h = 0.1, w = 1, t = h at y = 0 and 0 at y = w.
        let (h, wd) = (0.1, 1.0);
        let x = [
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [1.0, wd, 0.0],
            [0.0, wd, 0.0],
        ];
        let t = [h, h, 0.0, 0.0];
        let f = [0u32, 1, 2, 3];
        let m32 = envelope_directions(&f, &t, 4, &x);
        let b = thickness_box(&f, &t, &m32, 4, &x);
        let m = m32.map(|v| v as f64);
        let slope = h / (2.0 * wd);
        let top = [
            0.0,
            slope / (1.0 + slope * slope).sqrt(),
            1.0 / (1.0 + slope * slope).sqrt(),
        ];
        let k = if m[2] > 0.0 { 0 } else { 3 };
        // (Stored in single precision, shrunk by 2e-7: 2.6e-7 at most.)
        for d in 0..3 {
            assert!((m[k + d] - top[d]).abs() < 5e-7, "{m:?} against {top:?}");
        }
        let p = [0.5, wd, 0.25 * h];
        assert!(p[2] <= b[5], "inside the thickness box");
        let beyond = m[k] * p[0] + m[k + 1] * p[1] + m[k + 2] * p[2] - b[6 + k / 3];
        // (s w + h/4)/√(1 + s²) − h/2 = 0.02497 (closed form); measured error 1.7e-8, of the
        // single-precision directions.
        let expected = (slope * wd + 0.25 * h) / (1.0 + slope * slope).sqrt() - 0.5 * h;
        assert!(
            (beyond - expected).abs() < 1e-7 && beyond > 0.0,
            "{beyond} {expected}"
        );
    }

    /// The grid's candidates of a point, filtered by box containment, are exactly the
    /// boxes that contain it by brute force (the oracle), in box order; points outside
    /// every box, on box faces and beyond the grid included.
    #[test]
    fn grid_finds_every_box_that_contains_a_point() {
        let mut st = 7u64;
        // Flat, patch-like boxes of mixed sizes, some far out in z.
        let boxes: Vec<([f64; 3], [f64; 3])> = (0..2000)
            .map(|i| {
                let c = [
                    40.0 * uniform(&mut st),
                    40.0 * uniform(&mut st),
                    if i % 97 == 0 { 30.0 } else { uniform(&mut st) },
                ];
                let e = [
                    0.2 + 1.5 * uniform(&mut st),
                    0.2 + 1.5 * uniform(&mut st),
                    0.1 + 0.3 * uniform(&mut st),
                ];
                (
                    [c[0] - e[0], c[1] - e[1], c[2] - e[2]],
                    [c[0] + e[0], c[1] + e[1], c[2] + e[2]],
                )
            })
            .collect();
        let grid = Grid::new(&boxes);
        // Boxes spanning several blocks of rows of the parallel fill.
        assert!(
            grid.dims[1] * grid.dims[2] > 4 * super::GRID_BLOCKS,
            "{:?}",
            grid.dims
        );
        let inside = |p: &[f64; 3], b: &([f64; 3], [f64; 3])| {
            (0..3).all(|d| p[d] >= b.0[d] && p[d] <= b.1[d])
        };
        let mut points: Vec<[f64; 3]> = (0..20000)
            .map(|_| {
                [
                    -2.0 + 44.0 * uniform(&mut st),
                    -2.0 + 44.0 * uniform(&mut st),
                    -0.5 + 2.0 * uniform(&mut st),
                ]
            })
            .collect();
        // Corners of boxes: on the boundary of the box, and of the grid.
        points.extend(boxes.iter().flat_map(|b| [b.0, b.1]));
        let mut found = 0;
        for p in &points {
            let got: Vec<u32> = grid
                .cell_of(p)
                .iter()
                .copied()
                .filter(|&i| inside(p, &boxes[i as usize]))
                .collect();
            let want: Vec<u32> = (0..boxes.len() as u32)
                .filter(|&i| inside(p, &boxes[i as usize]))
                .collect();
            assert_eq!(got, want, "point {p:?}");
            found += want.len();
        }
        assert!(
            found > points.len(),
            "the test must exercise overlaps: {found}"
        );
    }

    /// A pair with no penalty (all its nodes massless: tie slaves) gives no force and
    /// nothing stored or dissipated, instead of friction's 0/0 (which made a patch tied
    /// into a membrane report NaN contact energy).
    #[test]
    fn a_pair_without_penalty_is_inert() {
        use super::{pair_force, Friction, SlaveState};
        let fr = Friction {
            mu_s: 0.2,
            mu_d: 0.15,
            decay: 0.0,
        };
        let mut st = SlaveState {
            ft: [0.1, 0.0, 0.0],
            k: 1.0,
            g0: 0.0,
        };
        let (f, stored, diss) = pair_force(
            1e-6,
            &[0.0, 0.0, 1.0],
            0.0,
            &[1.0, 0.0, 0.0],
            1e-8,
            &fr,
            &mut st,
        );
        assert_eq!((f, stored, diss), ([0.0; 3], 0.0, 0.0));
        assert_eq!((st.ft, st.k), ([0.0; 3], 0.0));
    }

    #[test]
    fn empty_grid_has_no_candidates() {
        let grid = Grid::new(&[]);
        assert!(grid.cell_of(&[0.0; 3]).is_empty());
    }
}
