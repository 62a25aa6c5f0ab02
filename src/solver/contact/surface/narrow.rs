//! The narrow phase: per slave, its candidate faces past the box and envelope filters,
//! the closest point on each, and over the faces it penetrates the shared normal, the
//! penalty and friction force and the shares of the reaction; in parallel fixed chunks
//! of slaves (`Side::narrow`).

use rayon::prelude::*;

use super::kernels::{box_distance2, fmax, pair_force, release, thickness_gradient, SlaveState};
use super::side::{ChunkSums, PairOut, Reaction, Side, SLAVE_CHUNK};
use crate::model::contacts::InitialPenetration;
use crate::solver::contact::closest::closest_on_face;
use crate::solver::vec3::{cross, dot, sub};

/// Most slave chunks of one narrow-phase task (see `Side::narrow`).
const NARROW_TASK_CHUNKS: usize = 4;

/// Most faces one slave's reaction is shared over (a node at a quad vertex penetrates the
/// four faces around it; more only in crushed regions, where the deepest are kept).
const MAX_SHARED: usize = 8;

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

impl Side {
    /// Narrow phase and friction for every slave, in parallel chunks, into `out`.
    /// `initial`: report penetrations instead of pushing (setup).
    /// `spread`: per cell of the staleness test, |S| of `Side::margin` at this step
    /// (None: no slave is skipped).
    pub(super) fn narrow(
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
