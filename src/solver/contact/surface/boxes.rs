//! A master surface's geometry of the step ([`MasterBoxes`]): its faces' thickness boxes,
//! their envelope directions and bounds, computed once for every side whose master it is.
//!
//! The boxes and directions depend on the faces alone (their nodes, nodal thicknesses and
//! whether their elements are still in the model), never on the slaves. A multi-layer pack
//! has each yarn surface as the master of up to five sides (its own layer's crossing yarns
//! and the two surfaces of each neighbouring layer): those sides share one `MasterBoxes`,
//! one set of boxes per step and one broad-phase grid per build
//! (`super::SurfaceContact::rebuild`). Each side still lists its own candidates with its
//! own reach, so its lists, margins and results are what a side alone would give.

use std::sync::atomic::{AtomicU32, Ordering::Relaxed};

use rayon::prelude::*;

use super::kernels::{envelope_directions, thickness_box, DEAD_BOX};
use super::side::{Side, SLAVE_CHUNK};

/// Faces per parallel task of the box updates.
const FACE_CHUNK: usize = 4096;

/// Stamps written in parallel (each slot by whoever needs it, all with the same value).
#[derive(Debug, Default)]
pub(super) struct Stamps(pub(super) Vec<AtomicU32>);

impl Clone for Stamps {
    fn clone(&self) -> Stamps {
        Stamps(
            self.0
                .iter()
                .map(|a| AtomicU32::new(a.load(Relaxed)))
                .collect(),
        )
    }
}

/// The geometry of the step of one master surface, shared by the sides that have it as
/// master (module docs).
#[derive(Debug, Clone, Default)]
pub struct MasterBoxes {
    /// The faces' thickness boxes at the current step (lo, hi) [m], and their envelope
    /// bounds h₊, h₋ along `face_dir` (see [`MasterBoxes::set_directions_of`]).
    pub(super) face_box: Vec<[f64; 8]>,
    /// Per face, the unit directions m₊, m₋ of its envelope bounds, from the last broad
    /// phase (zero for a segment or a face too distorted to have them).
    pub(super) face_dir: Vec<[f32; 6]>,
    /// Per face, the force evaluation whose narrow phase last needed its box, on any of
    /// the sides ([`stamp_sides`]).
    pub(super) stamp: Stamps,
    /// The sides that have this surface as master, ascending (the first gives the faces).
    pub(super) sides: Vec<usize>,
}

/// Whether two sides have the same master surface: the same faces, of the same kind and
/// elements, with the same nodal thicknesses (bits) — the same boxes and directions at
/// every step, and the same faces eroded.
fn same_surface(a: &Side, b: &Side) -> bool {
    let bits = |s: &Side| -> Vec<u64> { s.face_t.iter().flatten().map(|t| t.to_bits()).collect() };
    a.nf == b.nf
        && a.master_kind == b.master_kind
        && a.solid.map(f64::to_bits) == b.solid.map(f64::to_bits)
        && a.faces == b.faces
        && a.face_elem == b.face_elem
        && bits(a) == bits(b)
}

impl MasterBoxes {
    /// The distinct master surfaces of `sides`, in the order of their first side; each
    /// side's `surface` set to its own. Before the first broad phase there are no
    /// directions yet: zero ones never reject.
    pub(super) fn group(sides: &mut [Side]) -> Vec<MasterBoxes> {
        let mut out: Vec<MasterBoxes> = Vec::new();
        for k in 0..sides.len() {
            let found = out
                .iter()
                .position(|g| same_surface(&sides[g.sides[0]], &sides[k]));
            let g = found.unwrap_or_else(|| {
                let n = sides[k].faces.len();
                out.push(MasterBoxes {
                    // (A dormant face's box stays empty until it wakes.)
                    face_box: sides[k]
                        .face_alive
                        .iter()
                        .map(|&a| if a { [0.0; 8] } else { DEAD_BOX })
                        .collect(),
                    face_dir: vec![[0.0; 6]; n],
                    stamp: Stamps((0..n).map(|_| AtomicU32::new(0)).collect()),
                    sides: vec![],
                });
                out.len() - 1
            });
            out[g].sides.push(k);
            sides[k].surface = g;
        }
        out
    }

    /// The widest thickness box of the step, per component [m] (eroded faces' boxes are
    /// empty: −∞). A maximum: exact in any order.
    pub(super) fn widest(&self) -> f64 {
        self.face_box
            .par_iter()
            .with_min_len(FACE_CHUNK)
            .map(|b| (b[3] - b[0]).max(b[4] - b[1]).max(b[5] - b[2]))
            .reduce(|| 0.0, f64::max)
    }

    /// Face `f` has left the surface: an empty thickness box from now on.
    pub(super) fn kill(&mut self, f: usize) {
        self.face_box[f] = DEAD_BOX;
    }

    /// The directions of the faces' envelope bounds at `x`, then their bounds (at a broad
    /// phase), for every live face (`sd`: a side of this surface). For a
    /// face of unit normal n̂ and in-plane thickness gradient ∇t_F
    /// ([`super::thickness_gradient`]), m± = (±n̂ − ½∇t_F)/|±n̂ − ½∇t_F|: the outward
    /// normals of the two sides of the thickness envelope of a flat face with a linear
    /// thickness (a lenticular band's quad thins to its edge, where the thickness box
    /// stays as high as its thickest node). Any unit direction gives a sound bound, so
    /// they are refreshed only here, while the bounds follow the nodes every step.
    pub(super) fn set_directions_of(&mut self, sd: &Side, x: &[[f64; 3]]) {
        let (faces, face_t, nf) = (&sd.faces, &sd.face_t, sd.nf);
        if nf < 3 {
            return;
        }
        // (The boxes are up to date: only the bounds along the new directions change.)
        let (alive, any_dead) = (&sd.face_alive, sd.dead_faces > 0);
        self.face_dir
            .par_chunks_mut(FACE_CHUNK)
            .zip(self.face_box.par_chunks_mut(FACE_CHUNK))
            .enumerate()
            .for_each(|(c, (ds, bs))| {
                for (j, (d, b)) in ds.iter_mut().zip(bs.iter_mut()).enumerate() {
                    let fi = c * FACE_CHUNK + j;
                    if any_dead && !alive[fi] {
                        continue;
                    }
                    *d = envelope_directions(&faces[fi], &face_t[fi], nf, x);
                    let fb = thickness_box(&faces[fi], &face_t[fi], d, nf, x);
                    (b[6], b[7]) = (fb[6], fb[7]);
                }
            });
    }
}

impl Side {
    /// The pending faces leave the surface: an empty thickness box from now on (in `mb`,
    /// its master surface's boxes).
    pub(super) fn drop_pending(&mut self, mb: &mut MasterBoxes) {
        for f in self.pending.drain(..) {
            let f = f as usize;
            self.face_alive[f] = false;
            mb.kill(f);
            self.dead_faces += 1;
        }
    }

    /// The faces uncovered at this step join the surface (an eroding solid's, see
    /// [`Side::erode`]); whether any did: their boxes and envelope directions come with
    /// the broad-phase build that must follow.
    pub(super) fn wake_uncovered(&mut self) -> bool {
        let mut any = false;
        for f in std::mem::take(&mut self.waking) {
            let f = f as usize;
            // (Its own element may have eroded at the same step.)
            if self.face_alive[f] || self.eroded_elems.contains(&self.face_elem[f]) {
                continue;
            }
            self.face_alive[f] = true;
            self.dead_faces -= 1;
            any = true;
        }
        any
    }
}

/// The faces' thickness boxes at `x` of each master surface in `surfaces` (with a side of
/// it, which gives its faces, and a stamp: only the faces stamped with it, None: every
/// face), once per step, in one parallel loop over all their chunks of faces (each
/// candidate of the narrow phase then reads one box instead of gathering its face's
/// nodes; measured: those gathers were ~40 % of the narrow phase of the woven patch).
/// One loop rather than one per surface: a pack's eight surfaces were each a short
/// parallel region, the idle thread asleep at its start (docs/benchmarks.md, "Two
/// threads"); each chunk writes its own boxes, in any order.
pub(super) fn update_surfaces<'a>(
    surfaces: impl Iterator<Item = (&'a mut MasterBoxes, &'a Side, Option<u32>)>,
    x: &[[f64; 3]],
) {
    let mut reads = Vec::new();
    let mut tasks = Vec::new();
    for (k, (mb, sd, stamp)) in surfaces.enumerate() {
        let MasterBoxes {
            ref mut face_box,
            ref face_dir,
            stamp: ref stamps,
            ..
        } = *mb;
        reads.push((sd, face_dir, &stamps.0, stamp));
        tasks.extend(
            face_box
                .chunks_mut(FACE_CHUNK)
                .enumerate()
                .map(|(c, bs)| (k, c, bs)),
        );
    }
    tasks.into_par_iter().for_each(|(k, c, bs)| {
        let (sd, dirs, stamps, stamp) = reads[k];
        let (faces, face_t, nf) = (&sd.faces, &sd.face_t, sd.nf);
        let (alive, any_dead) = (&sd.face_alive, sd.dead_faces > 0);
        for (j, b) in bs.iter_mut().enumerate() {
            let fi = c * FACE_CHUNK + j;
            // (A face that has left the surface keeps the empty box `kill` gave it; a
            // dormant one, an eroding solid's interior face, is in no grid and no list
            // until it wakes, when the build that follows computes its box.)
            if (any_dead && !alive[fi]) || stamp.is_some_and(|e| stamps[fi].load(Relaxed) != e) {
                continue;
            }
            *b = thickness_box(&faces[fi], &face_t[fi], &dirs[fi], nf, x);
        }
    });
}

/// Stamps with `epoch` (this force evaluation's number, > 0), for each side in `sides`
/// into the stamps of its master surface, the faces whose boxes this step's narrow phase
/// can read: the candidates of the slaves it does not skip (with the spreads `spread` of
/// the skip test, as the narrow phase decides). [`update_surfaces`] then computes those
/// boxes; the others keep older ones, which nothing reads before the next build computes
/// every box again. Measured on the four-layer chain patch, 60 × 60 to 30 µs, where 91 %
/// of the slave-steps are skipped: the boxes took 10.3 of its 40.7 s, 5.5 s of 33.6 s
/// this way (each side its own boxes then). One parallel loop over every side's chunks
/// of slaves, as [`update_surfaces`] is over the surfaces' (the stores are of one value:
/// their order does not matter).
pub(super) fn stamp_sides<'a>(
    sides: impl Iterator<Item = (&'a Side, &'a Stamps)>,
    spread: &[f64],
    epoch: u32,
) {
    let sides: Vec<(&Side, &Stamps)> = sides.collect();
    let tasks: Vec<(usize, usize)> = sides
        .iter()
        .enumerate()
        .flat_map(|(k, (sd, _))| (0..sd.slaves.len().div_ceil(SLAVE_CHUNK)).map(move |c| (k, c)))
        .collect();
    tasks.into_par_iter().for_each(|(k, ci)| {
        let (sd, stamps) = sides[k];
        let stamps = &stamps.0;
        let (margin, cell) = (&sd.margin, &sd.slave_cell);
        let (cand_at, cand) = (&sd.cand_at, &sd.cand);
        let s0 = ci * SLAVE_CHUNK;
        let s1 = (s0 + SLAVE_CHUNK).min(margin.len());
        for si in s0..s1 {
            if margin[si] > spread[cell[si] as usize] {
                continue;
            }
            let [a, b] = cand_at[si];
            for &fi in &cand[a as usize..b as usize] {
                stamps[fi as usize].store(epoch, Relaxed);
            }
        }
    });
}
