//! When the candidate lists of the surface contact's broad phase go stale: a test on the
//! relative displacement of nearby nodes since the last build, so that a patch that moves
//! as a whole (the fabric under a projectile's nose) keeps its lists.
//!
//! Glossary: u_i = x_i − x_i^b the displacement of contact node i since the build (b); a
//! side's candidates of slave s are the faces F whose thickness box, inflated by
//! r = t_s,max/2 + η + skin, contains x_s^b per component (`surface::Side::build`); the
//! narrow phase evaluates a face only when x_s is within ρ = t_s,max/2 + η of its
//! thickness box at the current step (per component at least).
//!
//! **Why relative displacement suffices.** The thickness box of F moves with its nodes
//! (the radii t_a/2 are fixed), so per component d its distance e_d from x_s satisfies
//! e_d^b ≤ e_d + max_{a∈F} |u_a,d − u_s,d|. A pair that the narrow phase evaluates has
//! e_d ≤ ρ, hence e_d^b ≤ ρ + skin, and it is a candidate, as long as every pair that can
//! come that close has max_a |u_a,d − u_s,d| ≤ skin. The old criterion (every |u_i| ≤
//! skin/2) is one way to ensure it; here it is ensured locally:
//! - the nodes are binned at the build into cells of size h ≥ ρ + W + 4U (W the widest
//!   thickness box per component at the build, U below), on their build positions;
//! - **absolute bound**: every |u_i,d| ≤ U. Then a pair with e_d ≤ ρ has, for every node
//!   a of F, |x_s,d − x_a,d| ≤ ρ + W_d(F) with W_d(F) ≤ W + 2U (the box widens by at most
//!   the spread of its nodes' displacements), so |x_s,d^b − x_a,d^b| ≤ ρ + W + 4U ≤ h:
//!   their cells differ by at most one in each index;
//! - **spread in a neighbourhood**: for every cell c and component d, the spread max − min
//!   of u_d over the nodes of the 3 × 3 × 3 cells around c is ≤ skin. Both s and every a of
//!   F lie in the neighbourhood of s's cell, so |u_a,d − u_s,d| ≤ skin. ∎
//!
//! Nodes moving together (a rigid translation of a region of size ~3h) keep their lists
//! until they have moved U, instead of skin/2. The per-cell minima and maxima are exact
//! (no sums), so the test gives the same answer on any thread count.
//!
//! **The cells** ([`CellGrid`]): the origin at the lower bounds of the nodes' build
//! positions, the size h grown by 1.5 from ρ + W + 4U until there are at most 4 cells per
//! node (+64; [`cell_counts`]): a larger h keeps the argument above. A cell index is
//! ⌊(x_d − o_d)/h⌋ clamped to [0, dims_d − 1]; clamping is monotone, so it never widens a
//! difference of indices, and a component of one cell gives every node the same index.
//! The build positions lie within the bounds, so their indices need no clamping but for
//! round-off.
//!
//! Round-off: the test compares the computed spreads with the skin itself. A computed
//! difference fl(x − x^b) is within 2⁻⁵³|x − x^b| of the exact one, so a computed spread
//! is within ~2ε̂ of the exact spread, ε̂ = 2⁻⁵² max(|x|, |x^b|) (~10⁻¹⁶ of the
//! coordinates); the retired tiled search (git history, last in 2491c90) tested against
//! skin − 4ε̂ to make the bound strict, this test does not.

use rayon::prelude::*;

/// Most cells of the staleness grid per node (past it, the cells grow: a patch far apart
/// in one direction would otherwise ask for a huge, empty grid).
const CELLS_PER_NODE: usize = 4;

/// A cell's empty range of displacements: min Δ (3) at +∞, max Δ (3) at −∞, ready for
/// min/max folds.
pub const EMPTY_RANGE: [f64; 6] = [
    f64::INFINITY,
    f64::INFINITY,
    f64::INFINITY,
    f64::NEG_INFINITY,
    f64::NEG_INFINITY,
    f64::NEG_INFINITY,
];

/// The cells per axis over (lo, hi) at the cell size `h` (finite, > 0), and the cell size:
/// h grown by 1.5 until there are at most `cap` cells (a set far apart in one direction
/// would otherwise ask for a huge, empty grid). Shared by the staleness grid and the
/// surface contact's face grid (`surface::grid`).
pub fn cell_counts(lo: &[f64; 3], hi: &[f64; 3], mut h: f64, cap: usize) -> ([usize; 3], f64) {
    let mut dims = [1usize; 3];
    loop {
        for d in 0..3 {
            // Saturating: a span of 2^64 cells (positions running away, before the
            // run's health check stops it) must not wrap to 0 cells.
            let n = ((hi[d] - lo[d]) / h).floor();
            dims[d] = if n < cap as f64 {
                n as usize + 1
            } else {
                cap + 1
            };
        }
        if dims[0].saturating_mul(dims[1]).saturating_mul(dims[2]) <= cap {
            break;
        }
        h *= 1.5;
    }
    (dims, h)
}

/// Fixed cells over the contact nodes: origin, size h, counts per axis; indices clamped
/// (module docs, "The cells").
#[derive(Debug, Clone, Default, PartialEq)]
pub struct CellGrid {
    origin: [f64; 3],
    h: f64,
    dims: [usize; 3],
}

impl CellGrid {
    /// Cells of size at least `h_min` from `lo` covering up to `hi` (the nodes' bounds),
    /// grown by 1.5 until there are at most 4 per node (+64). Without nodes, or with a
    /// non-finite bound, span or size: one cell.
    pub fn covering(lo: [f64; 3], hi: [f64; 3], h_min: f64, nodes: usize) -> CellGrid {
        let mut h = h_min;
        let mut origin = lo;
        if nodes == 0 || !(h > 0.0) || !(0..3).all(|d| (hi[d] - lo[d]).is_finite()) {
            origin = [0.0; 3];
            h = f64::INFINITY;
        }
        let mut dims = [1usize; 3];
        if h.is_finite() {
            (dims, h) = cell_counts(&lo, &hi, h, CELLS_PER_NODE * nodes + 64);
        }
        CellGrid { origin, h, dims }
    }

    /// The cell of a position.
    pub fn cell(&self, p: &[f64; 3]) -> usize {
        if !self.h.is_finite() {
            return 0;
        }
        let i: [usize; 3] = std::array::from_fn(|d| {
            (((p[d] - self.origin[d]) / self.h).max(0.0) as usize).min(self.dims[d] - 1)
        });
        (i[2] * self.dims[1] + i[1]) * self.dims[0] + i[0]
    }

    pub fn dims(&self) -> [usize; 3] {
        self.dims
    }

    pub fn cells(&self) -> usize {
        self.dims[0] * self.dims[1] * self.dims[2]
    }
}

/// The absolute bound U as a multiple of the skin: larger U means larger cells, so
/// larger neighbourhoods whose spread reaches the skin sooner. Measured on the 60 × 60
/// woven quarter to 60 µs (2281 steps; the old test, every |u| ≤ skin/2, built 796
/// times): U = 0.5, 1, 2, 4 skins build 746, 510, 510, 516 times (at 0.5 and 1 mostly
/// for a node past U, at 2 and 4 never: the spread under the nose's rim decides).
pub const ABSOLUTE_PER_SKIN: f64 = 2.0;

/// Cells per parallel chunk of the per-cell ranges.
const CELL_CHUNK: usize = 256;

/// The build positions of the contact nodes, their cells, and scratch for the test.
#[derive(Debug, Clone, Default)]
pub struct Staleness {
    /// Skin of the broad phase and the absolute bound U [m].
    skin: f64,
    u_max: f64,
    /// Positions at the build of the nodes in `cell_nodes`, in the same (cell) order.
    x_ref: Vec<[f64; 3]>,
    /// Cells: origin, size h, counts per axis.
    grid: CellGrid,
    /// Nodes (indices into the positions) per cell (CSR).
    cell_ptr: Vec<u32>,
    cell_nodes: Vec<u32>,
    /// Per cell: min u (3), max u (3); then the same over its neighbourhood.
    range: Vec<[f64; 6]>,
    scratch: Vec<[f64; 6]>,
    /// Per cell, the Euclidean norm |S| of the spreads (S_x, S_y, S_z) of the
    /// displacements over its neighbourhood at the last test that found the lists fresh
    /// (zero after a build; +∞ for an empty neighbourhood).
    spread: Vec<f64>,
    /// Whether the last [`Staleness::stale`] stopped at a node past U (`range` then holds
    /// the cells' own ranges, not their neighbourhoods').
    last_far: bool,
}

impl Staleness {
    pub fn new(skin: f64) -> Staleness {
        Staleness {
            skin,
            u_max: ABSOLUTE_PER_SKIN * skin,
            ..Default::default()
        }
    }

    /// A build at the positions `x` of `nodes`; `rho_w` = ρ + W (see the module docs).
    pub fn reset(&mut self, nodes: &[u32], x: &[[f64; 3]], rho_w: f64) {
        // Bounds: minima and maxima, exact in any order.
        type Bounds = ([f64; 3], [f64; 3]);
        let none: Bounds = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
        let merge = |p: Bounds, q: Bounds| -> Bounds {
            (
                std::array::from_fn(|d| p.0[d].min(q.0[d])),
                std::array::from_fn(|d| p.1[d].max(q.1[d])),
            )
        };
        let (lo, hi) = nodes
            .par_iter()
            .fold(
                || none,
                |acc, &n| merge(acc, (x[n as usize], x[n as usize])),
            )
            .reduce(|| none, merge);
        // (Nothing to bin, or a non-finite position, which stops the run elsewhere: one
        // cell, so that every pair is in one neighbourhood.)
        self.grid = CellGrid::covering(lo, hi, rho_w + 4.0 * self.u_max, nodes.len());
        let ncell = self.grid.cells();
        // Nodes by cell: a counting sort; the nodes' indices and build positions are kept
        // in cell order, so that the test reads them in sequence.
        let cells: Vec<u32> = nodes
            .par_iter()
            .map(|&n| self.cell(&x[n as usize]) as u32)
            .collect();
        self.cell_ptr.clear();
        self.cell_ptr.resize(ncell + 1, 0);
        for &c in &cells {
            self.cell_ptr[c as usize + 1] += 1;
        }
        for c in 0..ncell {
            self.cell_ptr[c + 1] += self.cell_ptr[c];
        }
        let mut fill = self.cell_ptr.clone();
        self.cell_nodes.clear();
        self.cell_nodes.resize(nodes.len(), 0);
        for (&n, &c) in nodes.iter().zip(&cells) {
            self.cell_nodes[fill[c as usize] as usize] = n;
            fill[c as usize] += 1;
        }
        self.x_ref.clear();
        self.x_ref
            .par_extend(self.cell_nodes.par_iter().map(|&n| x[n as usize]));
        self.range.resize(ncell, [0.0; 6]);
        self.scratch.resize(ncell, [0.0; 6]);
        self.spread.clear();
        self.spread.resize(ncell, 0.0);
    }

    /// The cell of a build position.
    pub fn cell(&self, p: &[f64; 3]) -> usize {
        // (Truncation is the floor: every build position is ≥ the origin.)
        self.grid.cell(p)
    }

    /// Whether the lists built at `reset` may miss a pair at the positions `x` (of every
    /// node, indexed as in `reset`): some node has moved more than U in a component, or
    /// the displacements within some cell's neighbourhood spread more than the skin in a
    /// component.
    pub fn stale(&mut self, x: &[[f64; 3]]) -> bool {
        let (x_ref, cell_ptr, cell_nodes, u_max) =
            (&self.x_ref, &self.cell_ptr, &self.cell_nodes, self.u_max);
        // Per cell, the range of the displacements of its nodes, and whether one of them
        // has gone past U.
        let far = self
            .range
            .par_chunks_mut(CELL_CHUNK)
            .enumerate()
            .map(|(k, rs)| {
                let mut far = false;
                for (j, r) in rs.iter_mut().enumerate() {
                    let c = k * CELL_CHUNK + j;
                    *r = EMPTY_RANGE;
                    for i in cell_ptr[c] as usize..cell_ptr[c + 1] as usize {
                        let (p, q) = (&x[cell_nodes[i] as usize], &x_ref[i]);
                        for d in 0..3 {
                            let u = p[d] - q[d];
                            r[d] = r[d].min(u);
                            r[d + 3] = r[d + 3].max(u);
                        }
                    }
                    // (An empty cell's range is [∞, −∞]: never far.)
                    far |= !(0..3).all(|d| r[d] >= -u_max && r[d + 3] <= u_max);
                }
                far
            })
            .reduce(|| false, |a, b| a | b);
        self.last_far = far;
        if far {
            return true;
        }
        self.neighbourhood_ranges();
        // After three passes (range → scratch → range → scratch) the neighbourhoods'
        // ranges are in `scratch` (an empty neighbourhood's spread is −∞).
        // (Every cell's |S| is kept for the narrow phase, so no early exit.)
        let skin = self.skin;
        !self
            .spread
            .par_chunks_mut(CELL_CHUNK)
            .zip(self.scratch.par_chunks(CELL_CHUNK))
            .map(|(ss, rs)| {
                let mut fresh = true;
                for (s, r) in ss.iter_mut().zip(rs) {
                    let sd: [f64; 3] = std::array::from_fn(|d| r[d + 3] - r[d]);
                    fresh &= sd.iter().all(|&e| e <= skin);
                    // (An empty neighbourhood: −∞ spreads, an infinite norm.)
                    *s = (sd[0] * sd[0] + sd[1] * sd[1] + sd[2] * sd[2]).sqrt();
                }
                fresh
            })
            .reduce(|| true, |a, b| a & b)
    }

    /// The ranges of the displacements over each cell's 3 × 3 × 3 neighbourhood, from the
    /// cells' own ranges in `range`: a window of three along each axis in turn (range →
    /// scratch → range → scratch), the result in `scratch`.
    fn neighbourhood_ranges(&mut self) {
        let dims = self.grid.dims();
        let stride = [1, dims[0], dims[0] * dims[1]];
        for axis in 0..3 {
            let (src, dst) = if axis == 1 {
                (&self.scratch, &mut self.range)
            } else {
                (&self.range, &mut self.scratch)
            };
            dst.par_chunks_mut(CELL_CHUNK)
                .enumerate()
                .for_each(|(k, outs)| {
                    for (j, out) in outs.iter_mut().enumerate() {
                        let c = k * CELL_CHUNK + j;
                        let i = (c / stride[axis]) % dims[axis];
                        let mut r = src[c];
                        for n in [i.wrapping_sub(1), i + 1] {
                            if n < dims[axis] {
                                let o = &src[c - i * stride[axis] + n * stride[axis]];
                                for d in 0..3 {
                                    r[d] = r[d].min(o[d]);
                                    r[d + 3] = r[d + 3].max(o[d + 3]);
                                }
                            }
                        }
                        *out = r;
                    }
                });
        }
    }

    /// Whether the last [`Staleness::stale`] found a node past U.
    pub fn last_far(&self) -> bool {
        self.last_far
    }

    /// The cell counts per axis.
    pub fn dims(&self) -> [usize; 3] {
        self.grid.dims()
    }

    /// Per cell, the norm |S| of its neighbourhood's spreads of the displacements since
    /// the build, at the last [`Staleness::stale`] that found the lists fresh (zero right
    /// after a build).
    pub fn spread(&self) -> &[f64] {
        &self.spread
    }
}

#[cfg(test)]
mod tests {
    use super::super::uniform;
    use super::{cell_counts, CellGrid, Staleness, ABSOLUTE_PER_SKIN};

    /// The cells cover the nodes' bounds within the cap: `cell_counts` grows h by 1.5
    /// only while there are more cells than the cap (so h/1.5 would give too many), and
    /// `CellGrid::covering` puts the lower bound in the first cell, the upper in the last
    /// and every node in a cell whose box holds it (indices by hand from the origin and
    /// h); without nodes or with a non-finite bound or span, one cell.
    #[test]
    fn cells_cover_the_nodes_within_the_cap() {
        let (lo, hi) = ([0.0, -1.0, 0.0], [10.0, 1.0, 0.1]);
        let count = |h: f64| -> usize {
            (0..3)
                .map(|d| ((hi[d] - lo[d]) / h).floor() as usize + 1)
                .product()
        };
        let (dims, h) = cell_counts(&lo, &hi, 0.01, 500);
        assert!(dims.iter().product::<usize>() <= 500 && count(h) <= 500);
        assert!(h > 0.01 && count(h / 1.5) > 500, "h = {h}");
        assert_eq!(cell_counts(&lo, &hi, 5.0, 500), ([3, 1, 1], 5.0));
        let mut st = 11u64;
        let x: Vec<[f64; 3]> = (0..300)
            .map(|_| std::array::from_fn(|d| lo[d] + (hi[d] - lo[d]) * uniform(&mut st)))
            .collect();
        let g = CellGrid::covering(lo, hi, 0.05, x.len());
        let dims = g.dims();
        assert!(g.cells() <= 4 * x.len() + 64 && g.cells() > 1);
        assert_eq!(g.cell(&lo), 0);
        assert_eq!(g.cell(&hi), g.cells() - 1);
        for p in &x {
            let c = g.cell(p);
            let i = [
                c % dims[0],
                (c / dims[0]) % dims[1],
                c / (dims[0] * dims[1]),
            ];
            for d in 0..3 {
                let a = lo[d] + i[d] as f64 * g.h;
                assert!(p[d] >= a && p[d] < a + g.h, "node {p:?}, cell {i:?}");
            }
        }
        let one = CellGrid::covering([0.0; 3], [f64::NAN, 0.0, 0.0], 0.05, 10);
        assert_eq!((one.cells(), one.cell(&[3.0, 4.0, 5.0])), (1, 0));
        assert_eq!(CellGrid::covering(lo, hi, 0.05, 0).cells(), 1);
        // Finite bounds whose span is not (positions running away before the health
        // check stops the run): one cell, not a count that wrapped to none (it did,
        // and the build indexed past its table).
        let far = CellGrid::covering([-1e308, 0.0, 0.0], [1e308, 1.0, 1.0], 0.05, 10);
        assert_eq!((far.cells(), far.cell(&[1e300, 0.5, 0.5])), (1, 0));
        let (dims, _) = cell_counts(&[0.0; 3], &[1e300, 1.0, 1.0], 1e-3, 500);
        assert!(
            (1..=500).contains(&dims.iter().product::<usize>()),
            "{dims:?}"
        );
    }

    /// What "not stale" promises, checked by brute force over every pair of nodes (the
    /// oracle): any two nodes now within ρ + W + 2U of each other in every component
    /// have displacements since the build that differ by at most the skin in every
    /// component. Motions: a rigid translation of the whole cloud past the skin (which the
    /// old test, every |u| ≤ skin/2, called stale) must not be stale; one node moving
    /// past U, or two neighbours moving apart by more than the skin, must be; random
    /// smooth fields (a bend that varies over 5 mm) are checked against the promise.
    #[test]
    fn not_stale_means_nearby_nodes_moved_alike() {
        let mut st = 3u64;
        let skin = 1e-4;
        let u_max = ABSOLUTE_PER_SKIN * skin;
        let rho_w = 8e-4;
        let n = 1500;
        let x0: Vec<[f64; 3]> = (0..n)
            .map(|_| {
                [
                    2e-2 * uniform(&mut st),
                    2e-2 * uniform(&mut st),
                    2e-4 * uniform(&mut st),
                ]
            })
            .collect();
        let nodes: Vec<u32> = (0..n as u32).collect();
        let fresh = || {
            let mut s = Staleness::new(skin);
            s.reset(&nodes, &x0, rho_w);
            s
        };
        let moved = |f: &dyn Fn(&[f64; 3]) -> [f64; 3]| -> Vec<[f64; 3]> {
            x0.iter()
                .map(|p| {
                    let u = f(p);
                    [p[0] + u[0], p[1] + u[1], p[2] + u[2]]
                })
                .collect()
        };
        // Rigid translation by 1.5 skins (more than the old limit of skin/2).
        let x = moved(&|_| [1.5 * skin, -1.0 * skin, 0.5 * skin]);
        assert!(
            !fresh().stale(&x),
            "a rigid translation within U is not stale"
        );
        // Past U.
        let x = moved(&|_| [1.01 * u_max, 0.0, 0.0]);
        assert!(fresh().stale(&x), "a translation past U is stale");
        // Two nodes close together moving apart by 1.2 skins.
        let (i, j) = (0..n)
            .flat_map(|i| (i + 1..n).map(move |j| (i, j)))
            .find(|&(i, j)| (0..3).all(|d| (x0[i][d] - x0[j][d]).abs() < 1e-3))
            .expect("a close pair");
        let mut x = x0.clone();
        x[i][2] += 0.6 * skin;
        x[j][2] -= 0.6 * skin;
        assert!(fresh().stale(&x), "neighbours moving apart past the skin");
        // Smooth bends of growing amplitude: whenever not stale, the promise holds.
        let reach = rho_w + 2.0 * u_max;
        let (mut kept, mut checked) = (0, 0);
        for k in 1..=30 {
            let a = 0.1 * skin * k as f64;
            let x = moved(&|p| {
                let r = (p[0] * p[0] + p[1] * p[1]).sqrt();
                [0.3 * a, 0.0, a * (-r / 5e-3).exp() + 0.5 * a]
            });
            if fresh().stale(&x) {
                continue;
            }
            kept += 1;
            for i in 0..n {
                for j in i + 1..n {
                    if (0..3).all(|d| (x[i][d] - x[j][d]).abs() <= reach) {
                        checked += 1;
                        for d in 0..3 {
                            let du = (x[i][d] - x0[i][d]) - (x[j][d] - x0[j][d]);
                            assert!(du.abs() <= skin, "pair {i}, {j}: {du:e} in {d}");
                        }
                    }
                }
            }
        }
        assert!(
            kept > 0 && kept < 30,
            "the sweep must cross the limit: {kept} kept"
        );
        assert!(checked > 1000, "pairs checked: {checked}");
    }
}
