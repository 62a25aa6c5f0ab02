//! The narrow phase: per slave, its candidate faces past the box and envelope filters,
//! the closest point on each, and over the faces it penetrates the shared normal, the
//! penalty and friction force and the shares of the reaction; in parallel fixed chunks
//! of slaves (`Side::narrow`).

use rayon::prelude::*;

use super::boxes::MasterBoxes;
use super::gather::{block_size, ChunkParts};
use super::kernels::{
    box_distance2, fmax, pair_force, release, thickness_gradient, Friction, Hit, SlaveState,
};
use super::side::{ChunkContribs, ChunkSums, PairOut, Reaction, Side, SLAVE_CHUNK};
use super::solid::evaluate_solid;
use crate::model::contacts::InitialPenetration;
use crate::solver::contact::closest::closest_on_face;
use crate::solver::vec3::{cross, dot, sub};

/// Most slave chunks of one narrow-phase task (see `Side::narrow`).
const NARROW_TASK_CHUNKS: usize = 4;

/// Most faces one slave's reaction is shared over (a node at a quad vertex penetrates the
/// four faces around it; more only in crushed regions, where the deepest are kept).
const MAX_SHARED: usize = 8;

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

/// The faces a slave penetrates, gathered over its candidates: the deepest, the
/// penetration-weighted sums of the normals and of the thickness gradients, and how many
/// of the shares (the chunk's scratch [`Shares`]) are filled.
struct Found {
    /// The candidate of largest raw penetration: (face, g, normal).
    best: Option<(u32, f64, [f64; 3])>,
    /// Its foot's weights, and its thickness gradient (zero for a slave on its
    /// mid-surface, which adds nothing to the sums below either).
    best_w: [f64; 4],
    best_tg: [f64; 3],
    /// Σ g n over the faces the node penetrates (off their mid-surface), and how many: in
    /// a concave crease (a node under a tent of two faces) both feet are valid and the
    /// nearer one's normal flips as the node crosses the bisector; the
    /// penetration-weighted normal turns continuously instead.
    n_sum: [f64; 3],
    n_count: u32,
    /// Σ g ∇t_F and Σ g over the same faces.
    tg_sum: [f64; 3],
    g_sum: f64,
    /// Shares filled.
    n_pen: usize,
}

/// The faces a slave penetrates (face, weights, g), the deepest [`MAX_SHARED`]: the
/// reaction is shared over them as the normal is, so that a node over a vertex or a
/// ridge, whose faces tie, pushes them all alike (the deepest alone, ties to the first in
/// face order, pushed one side only, and the reaction jumped between faces as the node
/// moved: measured, a formed weave tiled from its mirror-symmetric cell was out of balance
/// by 0.10 of the crossing force at the vertex's neighbours, and drifted when left alone).
/// Scratch of a chunk of slaves (only the first `Found::n_pen` entries are read): declared
/// once per chunk, not zeroed per slave.
type Shares = [Share; MAX_SHARED];

/// A face a slave penetrates: (face, the foot's weights, g, the direction n − ½∇t_F of
/// its own force −∂(½kg²)/∂x_s; the last read only by the per-face law).
type Share = (u32, [f64; 4], f64, [f64; 3]);

impl Found {
    /// Nothing found yet.
    #[inline(always)]
    fn new() -> Found {
        Found {
            best: None,
            best_w: [0.0; 4],
            best_tg: [0.0; 3],
            n_sum: [0.0; 3],
            n_count: 0,
            tg_sum: [0.0; 3],
            g_sum: 0.0,
            n_pen: 0,
        }
    }

    /// A face `fi` the slave penetrates.
    #[inline(always)]
    fn add(&mut self, fi: u32, hit: Hit, pen: &mut Shares) {
        let Hit {
            w,
            g,
            dist,
            r,
            tg,
            flat,
        } = hit;
        let dir = if dist > 0.0 {
            std::array::from_fn(|d| r[d] / dist - 0.5 * tg[d])
        } else {
            flat
        };
        if self.n_pen < MAX_SHARED {
            pen[self.n_pen] = (fi, w, g, dir);
            self.n_pen += 1;
        } else {
            // Full: replace the shallowest (the first of equals).
            let mut k = 0;
            for j in 1..MAX_SHARED {
                if pen[j].2 < pen[k].2 {
                    k = j;
                }
            }
            if g > pen[k].2 {
                pen[k] = (fi, w, g, dir);
            }
        }
        if dist > 0.0 {
            for d in 0..3 {
                self.n_sum[d] += g * r[d] / dist;
                self.tg_sum[d] += g * tg[d];
            }
            self.g_sum += g;
            self.n_count += 1;
        }
        if self.best.as_ref().is_none_or(|b| g > b.1) {
            let n = if dist > 0.0 {
                [r[0] / dist, r[1] / dist, r[2] / dist]
            } else {
                flat
            };
            self.best = Some((fi, g, n));
            self.best_w = w;
            self.best_tg = if dist > 0.0 { tg } else { [0.0; 3] };
        }
    }
}

/// One narrow phase of a side: what it reads (the positions and velocities, the step,
/// the side's slaves, faces and candidates), borrowed apart from the slaves' results and
/// states, which it writes chunk by chunk.
struct Narrow<'a> {
    x: &'a [[f64; 3]],
    v: &'a [[f64; 3]],
    /// Δt² of the penalty, and Δt^{n−½} of the friction slip.
    dt2: f64,
    dt_prev: f64,
    /// Setup: report penetrations instead of pushing.
    initial: bool,
    /// Per cell of the staleness test, |S| of `Side::margin` (None: no slave skipped).
    spread: Option<&'a [f64]>,
    face_box: &'a [[f64; 8]],
    face_dir: &'a [[f32; 6]],
    margin: &'a [f64],
    slave_cell: &'a [u32],
    faces: &'a [[u32; 4]],
    face_t: &'a [[f64; 4]],
    face_m: &'a [[f64; 4]],
    slaves: &'a [u32],
    slave_t: &'a [f64],
    slave_m: &'a [f64],
    cand_at: &'a [[u32; 2]],
    cand: &'a [u32],
    fr: Friction,
    kappa: f64,
    zeta: f64,
    /// The definition's initial penetrations are `keep`: the penalty acts on their full
    /// depth from the start (no g₀ tracked).
    keep: bool,
    /// Round-off allowance η of the box tests [m].
    eta: f64,
    /// A solid's faces: their contact thickness t_F (see [`super::solid`]; 0 otherwise).
    solid_t: f64,
    /// Every penetrated face is a pair of its own (see [`Side::per_face`]).
    per_face: bool,
    /// Nodes per face, and whether the faces are a solid's (one-sided).
    nf: usize,
    one_sided: bool,
}

/// One fixed chunk of slaves as the narrow phase writes it: (chunk index, ((((results,
/// (states, held)), slaves in contact), reaction shares), sums)).
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

/// One chunk of one side's slaves as a task of the fused narrow phase: (side, the
/// chunk, its forces on the nodes by node block where the gather is parallel).
type Task<'c> = (usize, Chunk<'c>, Option<&'c mut ChunkContribs>);

impl Side {
    /// Narrow phase and friction for every slave of this side alone, into `out`, with
    /// the thickness boxes and envelope bounds `boxes` of its master surface (the setup,
    /// the erosion probe and the oracle; a step runs every side at once, [`narrow_sides`]).
    /// `initial`: report penetrations instead of pushing (setup).
    /// `spread`: per cell of the staleness test, |S| of `Side::margin` at this step
    /// (None: no slave is skipped).
    #[allow(clippy::too_many_arguments)]
    pub(super) fn narrow(
        &mut self,
        boxes: &MasterBoxes,
        x: &[[f64; 3]],
        v: &[[f64; 3]],
        dt: f64,
        dt_prev: f64,
        initial: bool,
        spread: Option<&[f64]>,
    ) {
        narrow_sides(
            std::iter::once((self, boxes)),
            x,
            v,
            dt,
            dt_prev,
            initial,
            spread,
        );
    }

    /// What this side's narrow phase reads (borrowed from the side and its surface's
    /// `boxes`), and its fixed chunks of slaves, each with the results, states and lists
    /// it writes (`by_block`: with its forces by node block, for the parallel gather).
    #[allow(clippy::too_many_arguments)]
    fn narrow_parts<'a>(
        &'a mut self,
        boxes: &'a MasterBoxes,
        x: &'a [[f64; 3]],
        v: &'a [[f64; 3]],
        dt: f64,
        dt_prev: f64,
        initial: bool,
        spread: Option<&'a [f64]>,
        by_block: bool,
    ) -> (Narrow<'a>, Vec<(Chunk<'a>, Option<&'a mut ChunkContribs>)>) {
        let nchunks = self.slaves.len().div_ceil(SLAVE_CHUNK);
        self.chunk_active.resize_with(nchunks, Vec::new);
        self.chunk_reactions.resize_with(nchunks, Vec::new);
        self.chunk_sums.resize(nchunks, ChunkSums::default());
        self.chunk_contribs
            .resize_with(if by_block { nchunks } else { 0 }, Default::default);
        let Side {
            ref margin,
            ref slave_cell,
            ref faces,
            ref face_t,
            ref face_m,
            ref slaves,
            ref slave_t,
            ref slave_m,
            ref cand_at,
            ref cand,
            friction,
            kappa,
            damping,
            on_initial,
            box_margin,
            solid,
            per_face,
            nf,
            ref mut out,
            ref mut state,
            ref mut held,
            ref mut chunk_active,
            ref mut chunk_reactions,
            ref mut chunk_sums,
            ref mut chunk_contribs,
            ..
        } = *self;
        let nar = Narrow {
            x,
            v,
            dt2: dt * dt,
            dt_prev,
            initial,
            spread,
            face_box: &boxes.face_box,
            face_dir: &boxes.face_dir,
            margin,
            slave_cell,
            faces,
            face_t,
            face_m,
            slaves,
            slave_t,
            slave_m,
            cand_at,
            cand,
            fr: friction,
            kappa,
            zeta: damping,
            keep: on_initial == InitialPenetration::Keep,
            eta: box_margin,
            solid_t: solid.unwrap_or(0.0),
            per_face,
            nf,
            one_sided: solid.is_some(),
        };
        let mut contribs = chunk_contribs.iter_mut();
        let chunks = out
            .chunks_mut(SLAVE_CHUNK)
            .zip(
                state
                    .chunks_mut(SLAVE_CHUNK)
                    .zip(held.chunks_mut(SLAVE_CHUNK)),
            )
            .zip(chunk_active.iter_mut())
            .zip(chunk_reactions.iter_mut())
            .zip(chunk_sums.iter_mut())
            .enumerate()
            .map(|c| (c, contribs.next()))
            .collect();
        (nar, chunks)
    }
}

/// The narrow phase and friction of every side of `sides` (each with the boxes of its
/// master surface) at one step, in one parallel loop over all their chunks of slaves: a
/// pack's many sides, most of whose slaves are skipped, would otherwise each be a short
/// parallel region, the idle thread asleep at its start (docs/benchmarks.md, "Two
/// threads"). Each chunk writes only its own results, states and lists, so the bits do
/// not depend on which thread takes it or when.
#[allow(clippy::too_many_arguments)]
pub(super) fn narrow_sides<'a>(
    sides: impl Iterator<Item = (&'a mut Side, &'a MasterBoxes)>,
    x: &'a [[f64; 3]],
    v: &'a [[f64; 3]],
    dt: f64,
    dt_prev: f64,
    initial: bool,
    spread: Option<&'a [f64]>,
) {
    // On more than one thread, each chunk also sorts its forces on the nodes by node
    // block for the parallel gather, while its results are in cache.
    let by_block = rayon::current_num_threads() > 1;
    let bs = block_size(x.len());
    let mut nars = Vec::new();
    let mut tasks: Vec<Task> = Vec::new();
    for (k, (side, boxes)) in sides.enumerate() {
        let (nar, chunks) = side.narrow_parts(boxes, x, v, dt, dt_prev, initial, spread, by_block);
        tasks.extend(chunks.into_iter().map(|(c, cc)| (k, c, cc)));
        nars.push(nar);
    }
    let body = |(k, c, contribs): Task| {
        let nar = &nars[k];
        let (ci, ((((outs, (sts, held)), active), reactions), sums)) = c;
        let c = (
            ci,
            (
                (((&mut *outs, (sts, held)), &mut *active), &mut *reactions),
                sums,
            ),
        );
        // One copy per face kind, so that the loops over a face's nodes are unrolled
        // (and the solid's one-sided faces are a copy of their own: no branch in the
        // others).
        match (nar.nf, nar.one_sided) {
            (4, true) => nar.chunk::<4, true>(c),
            (2, _) => nar.chunk::<2, false>(c),
            (3, _) => nar.chunk::<3, false>(c),
            _ => nar.chunk::<4, false>(c),
        }
        if let Some(cc) = contribs {
            let p = ChunkParts {
                slaves: nar.slaves,
                faces: nar.faces,
                nf: nar.nf,
                first: ci * SLAVE_CHUNK,
                outs,
                active,
                reactions,
            };
            cc.fill(&p, bs);
        }
    };
    if tasks.len() <= 1 {
        tasks.into_iter().for_each(body);
    } else {
        tasks
            .into_par_iter()
            // A task per few chunks: the slaves in contact cluster under the nose, and
            // rayon's default split leaves quarters of the range that a second thread
            // cannot steal from (measured by thread in perf: the narrow phase's
            // samples 14.8 % against 13.2 %, the second thread idle meanwhile).
            .with_max_len(NARROW_TASK_CHUNKS)
            .for_each(body);
    }
}

impl Narrow<'_> {
    /// The slaves of one chunk: each skipped, or its faces found, then its contact (or
    /// at the setup its initial penetration) into its result, state and the chunk's
    /// lists and sums.
    #[inline(always)]
    fn chunk<const NF: usize, const SOLID: bool>(&self, c: Chunk) {
        let (ci, ((((outs, (sts, held)), active), reactions), sums)) = c;
        active.clear();
        reactions.clear();
        *sums = ChunkSums::default();
        // Scratch of the slaves (only the first n_pen, nn entries are read):
        // declared once per chunk, not zeroed per slave.
        let mut pen: Shares = [(0u32, [0.0f64; 4], 0.0f64, [0.0f64; 3]); MAX_SHARED];
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
            if self
                .spread
                .is_some_and(|sp| self.margin[si] > sp[self.slave_cell[si] as usize])
            {
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
            let s = self.slaves[si] as usize;
            let found = self.search::<NF, SOLID>(si, &self.x[s], &mut near, &mut pen, sums);
            let mut out = PairOut {
                face: u32::MAX,
                ..Default::default()
            };
            let g_raw = found.best.as_ref().map_or(f64::NEG_INFINITY, |b| b.1);
            if self.initial {
                st.g0 = if self.keep { 0.0 } else { g_raw.max(0.0) };
                *hd = st.g0 != 0.0;
                if let Some(b) = &found.best {
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
            if SOLID && !*hd && g_raw > 0.5 * (self.slave_t[si] + self.solid_t) {
                // Open at the last step and now behind a solid's face (g > c): it came
                // in beside the face, past an edge of a crease, not through its front
                // (from open, crossing c takes many steps at any impact speed). Pushed
                // out by the full depth it would take the energy ½ k g² of a spring it
                // never compressed; tracked as an initial penetration instead.
                st.g0 = g_raw;
            }
            // The tracked initial penetration shrinks as the node leaves.
            if g_raw < st.g0 {
                st.g0 = g_raw.max(0.0);
            }
            let g = g_raw - st.g0;
            match found.best {
                Some((fi, _, _)) if g > 0.0 && self.per_face => {
                    let pen = &pen[..found.n_pen];
                    out = self.per_face_contact::<NF>(si, s, fi, pen, st, reactions);
                }
                Some((fi, _, n)) if g > 0.0 => {
                    // Shares λ_F = g_F/Σg of the penetrated faces.
                    let pen = &pen[..found.n_pen];
                    let g_pen: f64 = pen.iter().map(|e| e.2).sum();
                    out = self.contact::<NF>(si, s, fi, n, g, &found, pen, g_pen, st);
                    self.share_reaction(si, pen, g_pen, reactions);
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
    }

    /// The faces slave `si` at `p` penetrates, among its candidates (counted into `sums`),
    /// in candidate order.
    #[inline(always)]
    fn search<const NF: usize, const SOLID: bool>(
        &self,
        si: usize,
        p: &[f64; 3],
        near: &mut [u32; 32],
        pen: &mut Shares,
        sums: &mut ChunkSums,
    ) -> Found {
        let mut found = Found::new();
        // A face can be penetrated only if the slave is within t_s/2 of its
        // thickness box: the foot q = Σ w_a x_a is a convex combination of the
        // nodes (each triangle's barycentric weights, averaged over a quad's
        // two splits), and t_F = Σ w_a t_a the same combination of their
        // thicknesses, so the ball of radius t_F/2 about q lies in the box, and
        // |x_s − q| < (t_s + t_F)/2 puts x_s within t_s/2 of it. The test in
        // floating point keeps η = 10⁻⁹ (|x|_max + reach) more, 10⁶ times the
        // round-off of the foot and the box, so that it rejects only faces
        // that the closest-point test below rejects too: the same bits.
        let reach = 0.5 * self.slave_t[si] + self.eta;
        let r2 = reach * reach;
        // Only faces the node penetrates (g > 0) matter: a node whose best g is
        // ≤ 0 is open whether or not some face was evaluated, and a tracked initial
        // penetration g₀ then drops to 0 either way.
        let [a, b] = self.cand_at[si];
        let list = &self.cand[a as usize..b as usize];
        sums.tested += list.len() as u64;
        for block in list.chunks(32) {
            let nn = filter_block::<NF>(
                p[0],
                p[1],
                p[2],
                reach,
                r2,
                block,
                self.face_box,
                self.face_dir,
                near,
            );
            sums.evaluated += nn as u64;
            for &fi in &near[..nn] {
                let hit = if SOLID {
                    evaluate_solid(
                        p[0],
                        p[1],
                        p[2],
                        self.slave_t[si],
                        self.solid_t,
                        &self.faces[fi as usize],
                        &self.face_t[fi as usize],
                        self.x,
                    )
                } else {
                    evaluate_face::<NF>(
                        p[0],
                        p[1],
                        p[2],
                        self.slave_t[si],
                        &self.faces[fi as usize],
                        &self.face_t[fi as usize],
                        self.x,
                    )
                };
                let Some(hit) = hit else {
                    continue;
                };
                sums.penetrated += 1;
                found.add(fi, hit, pen);
            }
        }
        found
    }

    /// The contact of slave `si` (node `s`) with its deepest face `fi` of normal `n`, at
    /// the penetration `g` beyond its tracked initial one, over the penetrated faces `pen`
    /// (of total penetration `g_pen`): the normal (their penetration-weighted mean where
    /// it penetrates several), the penalty and friction force, the envelope's slope and
    /// the normal dashpot, into the slave's result.
    #[inline(always)]
    #[allow(clippy::too_many_arguments)]
    fn contact<const NF: usize>(
        &self,
        si: usize,
        s: usize,
        fi: u32,
        mut n: [f64; 3],
        g: f64,
        found: &Found,
        pen: &[Share],
        g_pen: f64,
        st: &mut SlaveState,
    ) -> PairOut {
        let (n_sum, tg_sum, g_sum) = (found.n_sum, found.tg_sum, found.g_sum);
        if found.n_count > 1 {
            let l = dot(&n_sum, &n_sum).sqrt();
            if l > 0.0 {
                n = [n_sum[0] / l, n_sum[1] / l, n_sum[2] / l];
            }
        }
        let (mf, vf) = self.foot::<NF>(pen, g_pen);
        let ms = self.slave_m[si];
        let mstar = if ms > 0.0 { ms.min(mf) } else { mf };
        let k = self.kappa * mstar / self.dt2;
        let vr = sub(&self.v[s], &vf);
        let vn = dot(&vr, &n);
        let vt = [vr[0] - vn * n[0], vr[1] - vn * n[1], vr[2] - vn * n[2]];
        let (mut force, stored, mut diss) = pair_force(g, &n, k, &vt, self.dt_prev, &self.fr, st);
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
        if self.zeta > 0.0 {
            // Normal dashpot, never pulling the surfaces together.
            let c = 2.0 * self.zeta * (k * mstar).sqrt();
            let fd = (-c * vn).max(-k * g);
            for d in 0..3 {
                force[d] += fd * n[d];
            }
            diss -= fd * vn * self.dt_prev;
        }
        PairOut {
            face: fi,
            f: force,
            stored,
            dissipated: diss,
            g,
        }
    }

    /// The contact of slave `si` (node `s`, deepest face `fi`) under the per-face law
    /// ([`Side::per_face`]): each face F it penetrates (`pen`) by g_F (beyond its tracked
    /// initial depth g₀) is a pair of its own, the penalty k_F = κ_c min(m_s, m_F)/Δt² of
    /// its foot's mass, its force k_F g_F (n_F − ½∇t_F) = −∂(½k_F g_F²)/∂x_s and its
    /// nodes the reaction by the foot's weights: the forces are the exact gradient of the
    /// stored Σ ½ k_F g_F², whatever the faces' normals. Friction (and the normal
    /// dashpot) act along the resultant's direction n̄ with f_n its length, against the
    /// λ-weighted foot (λ_F = g_F/Σg) as the shared law's, the deepest face's k for the
    /// stick spring; their reaction is shared in λ_F.
    #[inline(always)]
    fn per_face_contact<const NF: usize>(
        &self,
        si: usize,
        s: usize,
        fi: u32,
        pen: &[Share],
        st: &mut SlaveState,
        reactions: &mut Vec<Reaction>,
    ) -> PairOut {
        let ms = self.slave_m[si];
        let at = reactions.len();
        let (mut fsum, mut stored_n, mut g_pen) = ([0.0f64; 3], 0.0f64, 0.0f64);
        let (mut g_best, mut k_best, mut m_best) = (0.0f64, 0.0f64, 0.0f64);
        // Each face's penetration beyond g₀ where it pushes, 0 where it does not.
        let mut gs = [0.0f64; MAX_SHARED];
        for (j, &(fj, wj, gj, dir)) in pen.iter().enumerate() {
            let g = gj - st.g0;
            if !(g > 0.0) {
                continue;
            }
            gs[j] = g;
            let fm = &self.face_m[fj as usize];
            let mf: f64 = (0..NF).map(|a| wj[a] * fm[a]).sum();
            let mstar = if ms > 0.0 { ms.min(mf) } else { mf };
            let k = self.kappa * mstar / self.dt2;
            let own: [f64; 3] = std::array::from_fn(|d| k * g * dir[d]);
            for d in 0..3 {
                fsum[d] += own[d];
            }
            stored_n += 0.5 * k * g * g;
            g_pen += g;
            if g > g_best {
                (g_best, k_best, m_best) = (g, k, mstar);
            }
            reactions.push(Reaction {
                slave: si as u32,
                face: fj,
                w: wj,
                own: Some(own),
            });
        }
        let fn_ = dot(&fsum, &fsum).sqrt();
        if !(k_best > 0.0) {
            // Massless pairs (tie slaves): no force, as `pair_force` gives them.
            reactions.truncate(at);
            return PairOut {
                face: u32::MAX,
                dissipated: release(st),
                ..Default::default()
            };
        }
        if !(fn_ > 0.0) {
            // The faces' pushes cancel exactly on the slave: no direction for friction,
            // which lets go; the faces keep their own reactions and the springs their
            // energy.
            return PairOut {
                face: fi,
                f: fsum,
                stored: stored_n,
                dissipated: release(st),
                g: g_best,
            };
        }
        let nbar = [fsum[0] / fn_, fsum[1] / fn_, fsum[2] / fn_];
        // The foot in the shares λ_F = g_F/Σg of the faces that push.
        let (mut vf, mut lam) = ([0.0f64; 3], [0.0f64; MAX_SHARED]);
        for (j, &(fj, wj, _, _)) in pen.iter().enumerate() {
            if !(gs[j] > 0.0) {
                continue;
            }
            lam[j] = gs[j] / g_pen;
            let fnodes = &self.faces[fj as usize];
            for a in 0..NF {
                let va = &self.v[fnodes[a] as usize];
                for d in 0..3 {
                    vf[d] += lam[j] * wj[a] * va[d];
                }
            }
        }
        let vr = sub(&self.v[s], &vf);
        let vn = dot(&vr, &nbar);
        let vt = [
            vr[0] - vn * nbar[0],
            vr[1] - vn * nbar[1],
            vr[2] - vn * nbar[2],
        ];
        // Friction through the pair kernel at the penetration that gives f_n with the
        // deepest face's k; its normal part, ½ k g², replaced by the faces' own.
        let g_eff = fn_ / k_best;
        let (force, stored_pf, mut diss) =
            pair_force(g_eff, &nbar, k_best, &vt, self.dt_prev, &self.fr, st);
        let mut shared: [f64; 3] = std::array::from_fn(|d| force[d] - fn_ * nbar[d]);
        if self.zeta > 0.0 {
            let c = 2.0 * self.zeta * (k_best * m_best).sqrt();
            let fd = (-c * vn).max(-fn_);
            for d in 0..3 {
                shared[d] += fd * nbar[d];
            }
            diss -= fd * vn * self.dt_prev;
        }
        let mut j = 0;
        for i in 0..pen.len() {
            if gs[i] > 0.0 {
                let r = &mut reactions[at + j];
                for d in 0..3 {
                    r.own.as_mut().expect("own force")[d] += lam[i] * shared[d];
                }
                j += 1;
            }
        }
        PairOut {
            face: fi,
            f: std::array::from_fn(|d| fsum[d] + shared[d]),
            stored: stored_pf - 0.5 * k_best * g_eff * g_eff + stored_n,
            dissipated: diss,
            g: g_best,
        }
    }

    /// The foot's mass and velocity: over the penetrated faces `pen` (of total
    /// penetration `g_pen`) in the shares λ_F = g_F/Σg, their nodes' masses and
    /// velocities interpolated at their feet, so that the penalty and the friction slip
    /// are continuous as faces come and go, and the power of the shared reaction is
    /// −f·v_foot.
    #[inline(always)]
    fn foot<const NF: usize>(&self, pen: &[Share], g_pen: f64) -> (f64, [f64; 3]) {
        let (mut mf, mut vf) = (0.0f64, [0.0f64; 3]);
        for &(fj, wj, gj, _) in pen {
            let lam = gj / g_pen;
            let fn_ = &self.faces[fj as usize];
            let fm = &self.face_m[fj as usize];
            for a in 0..NF {
                let la = lam * wj[a];
                mf += la * fm[a];
                let va = &self.v[fn_[a] as usize];
                for d in 0..3 {
                    vf[d] += la * va[d];
                }
            }
        }
        (mf, vf)
    }

    /// The shares of slave `si`'s reaction over the faces it penetrates (`pen`, of total
    /// penetration `g_pen`), in the same shares λ_F = g_F/Σg as its foot.
    #[inline(always)]
    fn share_reaction(&self, si: usize, pen: &[Share], g_pen: f64, reactions: &mut Vec<Reaction>) {
        for &(fj, wj, gj, _) in pen {
            let lam = gj / g_pen;
            reactions.push(Reaction {
                slave: si as u32,
                face: fj,
                w: std::array::from_fn(|a| lam * wj[a]),
                own: None,
            });
        }
    }
}
