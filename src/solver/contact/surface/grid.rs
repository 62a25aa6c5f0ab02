//! The broad phase: a uniform grid over the faces' inflated thickness boxes (`Grid`), and
//! each side's candidate lists built from it, with the margins by which the narrow phase
//! skips the slaves that no candidate can reach yet (`Side::margin`).

use rayon::prelude::*;

use super::boxes::MasterBoxes;
use super::kernels::{excess, fmin};
use super::side::{Side, SLAVE_CHUNK};
use crate::solver::contact::staleness::cell_counts;

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
        let (lo, hi, h) = extent(boxes);
        if boxes.is_empty() || !(0..3).all(|d| (hi[d] - lo[d]).is_finite()) {
            return Grid {
                origin: [0.0; 3],
                h: 1.0,
                dims: [0; 3],
                ptr: vec![0],
                items: vec![],
            };
        }
        // (At most a few cells per box: a patch whose faces are far apart in one
        // direction would otherwise ask for a huge, empty grid.)
        let (dims, h) = cell_counts(&lo, &hi, h, GRID_CELLS_PER_BOX * boxes.len() + 64);
        // Truncation is the floor here: every coordinate is ≥ the origin.
        let cell = |p: &[f64; 3]| -> [u32; 3] {
            std::array::from_fn(|d| {
                (((p[d] - lo[d]) / h).max(0.0) as usize).min(dims[d] - 1) as u32
            })
        };
        // Each box's cell range (first, last per axis).
        let span: Vec<[[u32; 3]; 2]> = boxes.par_iter().map(|(a, b)| [cell(a), cell(b)]).collect();
        let blocks = Blocks::new(dims);
        let members = blocks.members(&span);
        let (ptr, totals, offsets) = blocks.count(&span, &members);
        let items = blocks.fill(&span, &members, &ptr, &totals, &offsets);
        Grid {
            origin: lo,
            h,
            dims,
            ptr,
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

/// The bounds (lo, hi) of the boxes and the grid's cell size ([`GRID_CELL_FRACTION`] of
/// the largest box's largest side, at least 10⁻¹² of it).
fn extent(boxes: &[([f64; 3], [f64; 3])]) -> ([f64; 3], [f64; 3], f64) {
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
    (lo, hi, h)
}

/// The row (the cells of one (j, k)) of the grid's cell indices j, k.
#[inline(always)]
fn grid_row(dims: &[usize; 3], j: u32, k: u32) -> usize {
    k as usize * dims[1] + j as usize
}

/// The grid's cells split for the parallel fill: whole rows (a row: the cells of one
/// (j, k)) in blocks of `rows_per` rows. Each block takes the boxes that reach its rows,
/// in box order, so a cell lists its boxes in box order whatever the blocks (a counting
/// sort).
struct Blocks {
    dims: [usize; 3],
    ncell: usize,
    nrows: usize,
    rows_per: usize,
    nblocks: usize,
    /// Cells per block (the last may have fewer).
    block_cells: usize,
    /// The block of each row.
    block_of: Vec<u32>,
}

impl Blocks {
    fn new(dims: [usize; 3]) -> Blocks {
        let nrows = dims[1] * dims[2];
        let rows_per = nrows.div_ceil(GRID_BLOCKS).max(1);
        Blocks {
            dims,
            ncell: dims[0] * dims[1] * dims[2],
            nrows,
            rows_per,
            nblocks: nrows.div_ceil(rows_per),
            block_cells: rows_per * dims[0],
            // Each row's block looked up rather than divided for (measured: the loop of
            // `members` was most of the rebuild's serial time).
            block_of: (0..nrows).map(|r| (r / rows_per) as u32).collect(),
        }
    }

    /// The rows of block `b`, [first, last).
    fn rows(&self, b: usize) -> (usize, usize) {
        (b * self.rows_per, ((b + 1) * self.rows_per).min(self.nrows))
    }

    /// The boxes that reach each block, in box order: found in parallel over fixed ranges
    /// of boxes (`members[r][b]`, read range after range; the same lists for any number of
    /// threads).
    fn members(&self, span: &[[[u32; 3]; 2]]) -> Vec<Vec<Vec<u32>>> {
        let (dims, block_of) = (&self.dims, &self.block_of);
        let row_of = |j: u32, k: u32| grid_row(dims, j, k);
        let per_range = span.len().div_ceil(GRID_BLOCKS).max(1);
        span.par_chunks(per_range)
            .enumerate()
            .map(|(ri, range)| {
                let f0 = ri * per_range;
                let mut m: Vec<Vec<u32>> = vec![Vec::new(); self.nblocks];
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
            .collect()
    }

    /// The cells' counts as CSR pointers (`ncell + 1`: each block's running sums, then the
    /// blocks' offsets added), with each block's total and offset.
    fn count(
        &self,
        span: &[[[u32; 3]; 2]],
        members: &[Vec<Vec<u32>>],
    ) -> (Vec<u32>, Vec<u32>, Vec<u32>) {
        let mut count = vec![0u32; self.ncell + 1];
        let totals: Vec<u32> = count[1..]
            .par_chunks_mut(self.block_cells)
            .enumerate()
            .map(|(b, cnt)| {
                for fi in block_members(members, b) {
                    visit(&span[fi as usize], self.rows(b), &self.dims, |c| {
                        cnt[c] += 1
                    });
                }
                let mut run = 0u32;
                for c in cnt.iter_mut() {
                    run += *c;
                    *c = run;
                }
                run
            })
            .collect();
        let mut offsets = Vec::with_capacity(self.nblocks);
        let mut run = 0u32;
        for t in &totals {
            offsets.push(run);
            run += t;
        }
        count[1..]
            .par_chunks_mut(self.block_cells)
            .zip(&offsets)
            .for_each(|(cnt, &o)| cnt.iter_mut().for_each(|c| *c += o));
        (count, totals, offsets)
    }

    /// The cells' lists of boxes (CSR items, at the pointers `ptr`): each block writes its
    /// own slice of the items.
    fn fill(
        &self,
        span: &[[[u32; 3]; 2]],
        members: &[Vec<Vec<u32>>],
        ptr: &[u32],
        totals: &[u32],
        offsets: &[u32],
    ) -> Vec<u32> {
        let run: u32 = totals.iter().sum();
        let mut items = vec![0u32; run as usize];
        let mut slices: Vec<&mut [u32]> = Vec::with_capacity(self.nblocks);
        let mut rest: &mut [u32] = &mut items;
        for t in totals {
            let (head, tail) = rest.split_at_mut(*t as usize);
            slices.push(head);
            rest = tail;
        }
        let (block_cells, ncell) = (self.block_cells, self.ncell);
        slices.into_par_iter().enumerate().for_each(|(b, out)| {
            let c0 = b * block_cells;
            let base = offsets[b];
            let mut fill: Vec<u32> = ptr[c0..(c0 + block_cells).min(ncell)]
                .iter()
                .map(|&p| p - base)
                .collect();
            for fi in block_members(members, b) {
                visit(&span[fi as usize], self.rows(b), &self.dims, |c| {
                    out[fill[c] as usize] = fi;
                    fill[c] += 1;
                });
            }
        });
        items
    }
}

/// The boxes that reach block `b`, in box order (see [`Blocks::members`]).
fn block_members(members: &[Vec<Vec<u32>>], b: usize) -> impl Iterator<Item = u32> + '_ {
    members.iter().flat_map(move |m| m[b].iter().copied())
}

/// Visit the cells of the block of rows (r0, r1) that a box of cell range `span` covers
/// (a generic function, not a closure taking `dyn FnMut`: the visits inline, without a
/// call per cell).
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

/// How a side's slaves find their candidates in a [`Grid`] over the thickness boxes of
/// some of its faces, inflated by r or more (`to_face` maps the grid's entries to face
/// indices, in face order; None: all faces, the identity).
struct Lister<'a> {
    grid: &'a Grid,
    to_face: Option<&'a [u32]>,
    /// The side's own inflation r of the boxes [m].
    r: f64,
    x: &'a [[f64; 3]],
    side: &'a Side,
    boxes: &'a MasterBoxes,
}

impl Lister<'_> {
    /// Slave `si`'s candidates pushed onto `list` (ascending), and its margin (see
    /// `Side::margin`). (Pushes directly: a closure taking `dyn FnMut` made a call per
    /// candidate.) Not inlined: with its one caller (`Side::build`'s chunks), inlined it
    /// cost 1.3 % more instructions on two chain layers, 20 × 20 to 10 µs (4.407·10⁹
    /// against 4.351·10⁹, cachegrind), and 0.5 % on the band patch.
    #[inline(never)]
    fn candidates(&self, si: usize, list: &mut Vec<u32>) -> f64 {
        let sd = self.side;
        let (r, nf) = (self.r, sd.nf);
        let s = sd.slaves[si];
        let p = &self.x[s as usize];
        let mut near = f64::INFINITY;
        for &gi in self.grid.cell_of(p) {
            let fi = self.to_face.map_or(gi, |l| l[gi as usize]);
            // (The box inflated by the side's own reach: the grid's may be inflated more,
            // for another side of the surface. A box inflated by r that holds p is held by
            // p's cell, as it lies in the larger one: the same candidates, in face order.)
            let b = &self.boxes.face_box[fi as usize];
            if (0..3).all(|d| p[d] >= b[d] - r && p[d] <= b[d + 3] + r)
                && !sd.faces[fi as usize][..nf].contains(&s)
            {
                list.push(fi);
                near = fmin(near, excess(p, b, &self.boxes.face_dir[fi as usize], nf));
            }
        }
        near - 0.5 * sd.slave_t[si] - 2.0 * sd.box_margin
    }
}

/// A broad-phase grid over the live faces of a master surface, their thickness boxes
/// inflated by `r`: one per surface at a build, for every side of it whose reach is at
/// most `r` ([`Side::build`]).
pub(super) struct SurfaceGrid {
    grid: Grid,
    /// The grid's entries as face indices, in face order (None: every face, the identity;
    /// eroded faces stay out of the grid).
    live: Option<Vec<u32>>,
    r: f64,
}

impl Side {
    /// The reach r of a build: a slave within t_s/2 + η of a thickness box at some step
    /// before the next build was within this of it per component at the build (see
    /// `super::super::staleness`).
    pub(super) fn build_reach(&self, skin: f64) -> f64 {
        0.5 * self.slave_t_max + skin + self.box_margin
    }

    /// The grid over the thickness boxes `boxes` of faces `set` (face indices in
    /// ascending order; None: every face), inflated by `r`.
    fn grid_over(boxes: &MasterBoxes, r: f64, set: Option<&[u32]>) -> Grid {
        let inflate = |b: &[f64; 8]| {
            (
                [b[0] - r, b[1] - r, b[2] - r],
                [b[3] + r, b[4] + r, b[5] + r],
            )
        };
        let boxes: Vec<([f64; 3], [f64; 3])> = match set {
            None => boxes.face_box.par_iter().map(inflate).collect(),
            Some(l) => l
                .iter()
                .map(|&f| inflate(&boxes.face_box[f as usize]))
                .collect(),
        };
        Grid::new(&boxes)
    }

    /// The grid of this side's master surface (its thickness boxes `boxes`, computed)
    /// over its live faces, inflated by `r` (at least the reach of every side that lists
    /// its candidates in it).
    pub(super) fn surface_grid(&self, boxes: &MasterBoxes, r: f64) -> SurfaceGrid {
        let live: Option<Vec<u32>> = (self.dead_faces > 0).then(|| {
            (0..self.faces.len() as u32)
                .filter(|&f| self.face_alive[f as usize])
                .collect()
        });
        SurfaceGrid {
            grid: Side::grid_over(boxes, r, live.as_deref()),
            live,
            r,
        }
    }

    /// Broad phase: candidates of every slave at the positions `x`, in the grid `sg` of
    /// its master surface, whose thickness boxes `boxes` are computed; one list for all
    /// slaves.
    pub(super) fn build(
        &mut self,
        x: &[[f64; 3]],
        skin: f64,
        boxes: &MasterBoxes,
        sg: &SurfaceGrid,
    ) {
        let r = self.build_reach(skin);
        assert!(
            r <= sg.r,
            "contact {}: a broad-phase grid inflated by {:e} m for a side of reach {r:e} m",
            self.contact_id,
            sg.r
        );
        let lister = Lister {
            grid: &sg.grid,
            to_face: sg.live.as_deref(),
            r,
            x,
            side: self,
            boxes,
        };
        // Candidates: count, then fill, each in parallel over fixed slave chunks.
        let ns = self.slaves.len();
        // One pass: each fixed chunk of slaves collects its candidates and margins, the
        // chunks are then joined in order.
        let chunks: Vec<(Vec<u32>, Vec<u32>, Vec<f64>)> = (0..ns.div_ceil(SLAVE_CHUNK))
            .into_par_iter()
            .map(|ci| {
                let c0 = ci * SLAVE_CHUNK;
                let n = SLAVE_CHUNK.min(ns - c0);
                let mut counts = Vec::with_capacity(n);
                let mut margins = Vec::with_capacity(n);
                let mut list = Vec::new();
                for si in c0..c0 + n {
                    let before = list.len();
                    margins.push(lister.candidates(si, &mut list));
                    counts.push((list.len() - before) as u32);
                }
                (counts, list, margins)
            })
            .collect();
        // The chunks' offsets, then each chunk writes its own slices of the list, the
        // ranges and the margins, in parallel.
        let mut offsets = Vec::with_capacity(chunks.len());
        let mut total = 0u32;
        for (_, list, _) in &chunks {
            offsets.push(total);
            total += list.len() as u32;
        }
        let mut at = vec![[0u32; 2]; ns];
        let mut margin = vec![0.0f64; ns];
        let mut cand = vec![0u32; total as usize];
        let mut cand_rest = &mut cand[..];
        let mut jobs = Vec::with_capacity(chunks.len());
        for (((counts, list, ms), &o), (a, m)) in chunks.iter().zip(&offsets).zip(
            at.chunks_mut(SLAVE_CHUNK)
                .zip(margin.chunks_mut(SLAVE_CHUNK)),
        ) {
            let (c, ct) = std::mem::take(&mut cand_rest).split_at_mut(list.len());
            cand_rest = ct;
            jobs.push((counts, list, ms, o, c, a, m));
        }
        jobs.into_par_iter()
            .for_each(|(counts, list, ms, o, c, a, m)| {
                c.copy_from_slice(list);
                let mut run = o;
                for ((q, &n), (mq, &mv)) in a.iter_mut().zip(counts).zip(m.iter_mut().zip(ms)) {
                    *q = [run, run + n];
                    run += n;
                    *mq = mv;
                }
            });
        self.cand_at = at;
        self.margin = margin;
        self.cand = cand;
    }

    /// After a build at `x`: each slave's cell of the staleness test (`cell`).
    pub(super) fn set_cells(&mut self, x: &[[f64; 3]], cell: impl Fn(&[f64; 3]) -> usize + Sync) {
        let slaves = &self.slaves;
        self.slave_cell.clear();
        self.slave_cell
            .par_extend(slaves.par_iter().map(|&s| cell(&x[s as usize]) as u32));
    }
}

#[cfg(test)]
mod tests {
    use super::Grid;
    use crate::solver::contact::uniform;

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
        // Per point, the grid's entries whose box (among `bs`) holds it must be exactly the
        // boxes that hold it by brute force; returns how many there were.
        let check = |bs: &[([f64; 3], [f64; 3])], what: &str| -> usize {
            let mut found = 0;
            for p in &points {
                let got: Vec<u32> = grid
                    .cell_of(p)
                    .iter()
                    .copied()
                    .filter(|&i| inside(p, &bs[i as usize]))
                    .collect();
                let want: Vec<u32> = (0..bs.len() as u32)
                    .filter(|&i| inside(p, &bs[i as usize]))
                    .collect();
                assert_eq!(got, want, "point {p:?}, {what}");
                found += want.len();
            }
            found
        };
        let found = check(&boxes, "the grid's boxes");
        assert!(
            found > points.len(),
            "the test must exercise overlaps: {found}"
        );
        // A side of smaller reach lists its candidates in a grid built for a larger one
        // (the sides of a master surface share the grid of the largest, see
        // `SurfaceContact::rebuild`): the boxes it filters by are the grid's less the
        // difference d of the reaches, and the cell's entries so filtered must be exactly
        // the smaller boxes that contain the point, by brute force.
        let d = 0.15;
        let small: Vec<([f64; 3], [f64; 3])> = boxes
            .iter()
            .map(|(a, b)| (a.map(|v| v + d), b.map(|v| v - d)))
            .collect();
        let found_small = check(&small, "the boxes less d = 0.15");
        assert!(
            found_small > points.len() / 10 && found_small < found,
            "the smaller boxes must hold fewer points, and some: {found_small} of {found}"
        );
    }

    #[test]
    fn empty_grid_has_no_candidates() {
        let grid = Grid::new(&[]);
        assert!(grid.cell_of(&[0.0; 3]).is_empty());
    }
}
