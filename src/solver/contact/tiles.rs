//! Tiles of the surface contact's broad phase, each with its own build epoch and its own
//! reference positions, so that a stale region rebuilds its candidate lists alone: the
//! data and the proof of the tiled search ([`super::surface::tiled`], which uses them).
//!
//! Glossary (as in [`super::staleness`]): s a slave node, F a master face, t_a the nodal
//! contact thickness; a face's thickness box is the bounding box of the balls of radius
//! t_a/2 about its nodes; e_d(s, F) the distance of x_s from that box along component d
//! (0 inside); ρ = t_s,max/2 + η the farthest (per component) a slave the narrow phase
//! evaluates can be from a box, skin the broad phase's skin, r = ρ + skin the reach of a
//! build (a slave's list holds the faces with every e_d ≤ r at the build), U the absolute
//! bound of the binning ([`super::staleness::ABSOLUTE_PER_SKIN`] skins), W_cap a cap on
//! every live face's box width per component.
//!
//! **The pieces.**
//! - [`CellGrid`]: fixed cells of size h ≥ r + W_cap + 2U (plus a round-off allowance,
//!   [`Reach::cell_size`]) over the contact nodes' bounds at setup; indices are clamped,
//!   so a node that leaves the grid counts in its border cell, and a component of one cell
//!   puts every node in the same index.
//! - [`Binning`]: per contact node i a bin position x̂_i and its cell κ(i) = cell(x̂_i).
//!   [`Binning::rebin`] moves a node whose |x_i,d − x̂_i,d| > U in a component d of more
//!   than one cell to x̂_i := x_i, and reports the tiles that go stale: those whose N(T)
//!   holds its old or its new cell.
//! - [`Tiling`] and [`Tile`]: a tile T is a t × t block of cells in the two axes of most
//!   cells, every cell along the third; N(T) is T plus one ring of cells (clamped), N(c)
//!   the 3 × 3 × 3 cells around a cell c. A tile keeps its node set V_T = {i : κ(i) ∈
//!   N(T)} and their positions y^T at its last build b_T ([`Tile::gather_refs`]), and its
//!   FaceSet(T), the faces with every node in V_T ([`Tile::face_set`]).
//! - [`WidthMonitor`]: the widest box, exact on demand ([`max_box_width`]), bounded between
//!   by W(n₀) + 2 Σ Δt v_max (a box's width in d grows by at most the spread of its nodes'
//!   steps in d).
//!
//! **Invariants**, restored every step before a narrow phase:
//! - (B) binning: |x_i,d − x̂_i,d| ≤ U for every node and every component of more than
//!   one cell ([`Binning::rebin`]); with hysteresis ([`Binning::with_hysteresis`], the
//!   solver's), (B') instead: x_i,d lies within U of κ(i)'s cell, [o_d + k_d h − U,
//!   o_d + (k_d + 1) h + U] with k = κ(i)'s indices (unbounded past a border cell);
//! - (W) width: every live face's thickness box is at most W_cap wide in each component
//!   ([`WidthMonitor`]; past the cap, a re-grid with a larger h);
//! - (M) membership: no node has entered or left N(T) since b_T (a tile marked stale by a
//!   re-bin rebuilds before its lists are used).
//!
//! **Criterion** ([`Tile::test`]): T is fresh when, for every cell c of T and component
//! d, max − min over {i : κ(i) ∈ N(c)} of (x_i,d − y^T_i,d) ≤ skin − 4ε̂, with
//! ε̂ = 2⁻⁵² max(|x_i|, |y^T_i|) over V_T (the round-off of the differences, below).
//! Otherwise T rebuilds. A tile that moves as a whole, or not at all, never fails it.
//!
//! **Lemma (locality).** If e_d(s, F) ≤ R for every d and R + W_cap + 2U ≤ h, then
//! |κ(a) − κ(s)|∞ ≤ 1 (per index) for every node a of F.
//! *Proof.* The ball about x_a lies in F's box, so |x_a,d − x_s,d| ≤ e_d + W_d ≤ R + W_cap.
//! In a component of more than one cell, (B) gives |x̂_a,d − x̂_s,d| ≤ R + W_cap + 2U ≤ h,
//! so the floors of (x̂_d − o_d)/h differ by at most one (for the rounded quotients too:
//! see the allowance in [`Reach::cell_size`]). Clamping to [0, dims_d − 1] is monotone and
//! does not widen a difference; a component of one cell gives equal indices. ∎
//! *With (B').* If κ(a)_d ≥ κ(s)_d + 2, then x_a,d ≥ o_d + (κ(s)_d + 2) h − U and
//! x_s,d ≤ o_d + (κ(s)_d + 1) h + U, so |x_a,d − x_s,d| ≥ h − 2U ≥ R + W_cap, against
//! the first line (the windows' rounding, a few units in the last place of |x|, is far
//! inside the allowance of [`Reach::cell_size`]; a border cell's window is unbounded only
//! outward, where no other cell lies). The same cell size serves both.
//!
//! **Theorem.** If (B), (W), (M) hold at step n and T passes the test, then every face F
//! that the narrow phase can evaluate for a slave s with κ(s) ∈ T (e_d(s, F) ≤ t_s/2 + η
//! ≤ ρ for every d) is in s's list L_s, built at b_T ≤ n.
//! *Proof.*
//! 1. The lemma with R = ρ (ρ ≤ r) puts F's nodes in N(κ(s)) ⊂ N(T), as κ(s) ∈ T.
//! 2. By (M) they and s were in V_T at b_T, with references y^T from b_T; so every node
//!    of F was in V_T at the build, and F ∈ FaceSet(T).
//! 3. The box is the bounding box of balls of fixed radii about the nodes, so it moves
//!    with them: with Δ = x − y^T, e_d at b_T ≤ e_d(n) + max_a |Δ_a,d − Δ_s,d| (the
//!    nearest side of the box moved by the displacement of one of F's nodes).
//! 4. s and every a lie in N(κ(s)), and κ(s) is a cell of T, so the test bounds
//!    |Δ_a,d − Δ_s,d| by the skin: e_d at b_T ≤ ρ + skin = r.
//! 5. L_s holds every face of FaceSet(T) with every e_d ≤ r at b_T (the build's test).
//!    So F ∈ L_s. ∎
//!
//! The 4ε̂ of the test: a computed difference fl(x − y) is within 2⁻⁵³|x − y| ≤ ε̂ of the
//! exact one, so a computed spread within 2ε̂ (plus its own rounding, 2⁻⁵³ of the skin) of
//! the exact spread; the computed spread ≤ skin − 4ε̂ makes the exact one < skin.
//!
//! **Consequences.** At a build the lemma with R = r puts every face within r of a slave
//! of T in FaceSet(T), so the build loses nothing by looking only there. A slave re-binned
//! out of T marks T and its new tile stale. A tile holding both the old and the new cell
//! is marked too: its test groups V_T by the cells at its build, and step 4 needs the
//! current ones. Marking on a re-bin that keeps the cell is not needed by the proof (the
//! cells are all a tile depends on); it is kept so that one tile is exactly today's test
//! (below). Re-bins happen wherever nodes travel U from their bin positions, also in a
//! region that moves as a whole (x̂ is not reset at a tile's build, unlike today's x^b at a
//! global build), each node at its own step: in the brute-force test's drifting sheet
//! (tests/contact_tiles.rs) re-bin marks caused 854 of 992 tile rebuilds; re-bins into
//! another cell alone would have marked 768 of them.
//!
//! **Hysteresis.** A node re-binned by (B) lands at x̂ = x, possibly next to a cell face,
//! and then changes cell at every small excursion across it. With (B') a node changes
//! cell only once it is U past its cell, and every re-bin is a change of cell; only those
//! mark tiles ([`Rebin::crossing_tiles`]). In the drifting sheet: 384 re-bins against
//! 4 208 (911 into another cell). On the woven impacts (60 × 60 quarter to 60 µs) the
//! changes of cell still asked for most tile builds (93 % of them at U = 4 skins): the
//! yarns are drawn in toward the impact along their length, and carry every node across
//! the fixed cells in turn (see [`super::surface::tiled::TILE_CELLS`]).
//!
//! **[`super::staleness`] is the special case of one tile** over all cells: V_T holds
//! every node, FaceSet(T) every face, x̂ = y^T = x^b (every re-bin marks the one tile, as
//! today's absolute bound does), W_cap = W + 2U (the box widths at the build plus what U
//! can add), h = ρ + W + 4U; step 1 of the theorem needs only R = ρ. Its test is this one
//! with the skin in place of skin − 4ε̂, and with the absolute bound also in components of
//! one cell, which the clamped grid does not need.
//!
//! Determinism: re-binning, the test and the sets decide by exact comparisons, minima and
//! maxima, and keep their lists in node, cell or face order: the same on any thread count.

use rayon::prelude::*;

/// Most cells per node (past it, the cells grow: a patch far apart in one direction
/// would otherwise ask for a huge, empty grid).
const CELLS_PER_NODE: usize = 4;

/// Nodes per parallel chunk of [`Binning::rebin`].
const NODE_CHUNK: usize = 4096;

/// The round-off allowance of the cell size relative to the coordinates' size
/// ([`Reach::cell_size`]).
const CELL_ROUND_OFF: f64 = 1.0 / (1u64 << 40) as f64;

/// The distances that size the cells: ρ, the skin, W_cap and U [m].
#[derive(Debug, Clone, Copy)]
pub struct Reach {
    /// ρ = t_s,max/2 + η: the farthest a slave the narrow phase evaluates is from a
    /// thickness box, per component.
    pub rho: f64,
    pub skin: f64,
    /// The cap on every live face's thickness-box width per component.
    pub w_cap: f64,
    /// The absolute bound U of the binning.
    pub u: f64,
}

impl Reach {
    /// The reach of a build, r = ρ + skin.
    pub fn r(&self) -> f64 {
        self.rho + self.skin
    }

    /// The smallest cell size for the lemma with R = r: r + W_cap + 2U, plus 2⁻⁴⁰ of
    /// (that + `x_abs`), `x_abs` the largest coordinate at setup. The allowance covers the
    /// rounding of the cell index: the computed quotients fl(fl(x̂ − o)/h) of two bin
    /// positions at most L apart differ by at most (L + 5·2⁻⁵³ X)/h, X the larger
    /// |x̂ − o|, so by at most one while X stays below ~1600 times `x_abs` (the origin o
    /// being a coordinate at setup).
    pub fn cell_size(&self, x_abs: f64) -> f64 {
        let need = self.r() + self.w_cap + 2.0 * self.u;
        need + CELL_ROUND_OFF * (need + x_abs)
    }
}

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
/// would otherwise ask for a huge, empty grid). Shared by the tiles, the staleness test
/// and the surface contact's face grid.
pub fn cell_counts(lo: &[f64; 3], hi: &[f64; 3], mut h: f64, cap: usize) -> ([usize; 3], f64) {
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
    (dims, h)
}

/// Fixed cells over the contact nodes: origin, size h, counts per axis; indices clamped.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct CellGrid {
    origin: [f64; 3],
    h: f64,
    dims: [usize; 3],
}

impl CellGrid {
    /// Cells of size at least `h_min` from `lo` covering up to `hi` (the nodes' bounds),
    /// grown by 1.5 until there are at most 4 per node (+64), as
    /// [`super::staleness::Staleness::reset`] sizes its cells (with these). Without nodes,
    /// or with a non-finite bound or size: one cell.
    pub fn covering(lo: [f64; 3], hi: [f64; 3], h_min: f64, nodes: usize) -> CellGrid {
        let mut h = h_min;
        let mut origin = lo;
        if nodes == 0 || !(h > 0.0) || !(0..3).all(|d| lo[d].is_finite() && hi[d].is_finite()) {
            origin = [0.0; 3];
            h = f64::INFINITY;
        }
        let mut dims = [1usize; 3];
        if h.is_finite() {
            (dims, h) = cell_counts(&lo, &hi, h, CELLS_PER_NODE * nodes + 64);
        }
        CellGrid { origin, h, dims }
    }

    /// The grid for the tiles over the positions `x` of `nodes`: [`CellGrid::covering`]
    /// their bounds with h = [`Reach::cell_size`].
    pub fn for_nodes(nodes: &[u32], x: &[[f64; 3]], reach: &Reach) -> CellGrid {
        let mut lo = [f64::INFINITY; 3];
        let mut hi = [f64::NEG_INFINITY; 3];
        for &n in nodes {
            for d in 0..3 {
                lo[d] = lo[d].min(x[n as usize][d]);
                hi[d] = hi[d].max(x[n as usize][d]);
            }
        }
        let x_abs = (0..3)
            .map(|d| lo[d].abs().max(hi[d].abs()))
            .fold(0.0, f64::max);
        CellGrid::covering(lo, hi, reach.cell_size(x_abs), nodes.len())
    }

    /// The cell of a position (also `Staleness::cell`).
    pub fn cell(&self, p: &[f64; 3]) -> usize {
        if !self.h.is_finite() {
            return 0;
        }
        let c: [usize; 3] = std::array::from_fn(|d| {
            (((p[d] - self.origin[d]) / self.h).max(0.0) as usize).min(self.dims[d] - 1)
        });
        self.flat(c)
    }

    /// A cell's indices per axis.
    pub fn index(&self, c: usize) -> [usize; 3] {
        let d = self.dims;
        [c % d[0], (c / d[0]) % d[1], c / (d[0] * d[1])]
    }

    /// The cell of indices `i`.
    pub fn flat(&self, i: [usize; 3]) -> usize {
        (i[2] * self.dims[1] + i[1]) * self.dims[0] + i[0]
    }

    pub fn dims(&self) -> [usize; 3] {
        self.dims
    }

    pub fn h(&self) -> f64 {
        self.h
    }

    pub fn origin(&self) -> [f64; 3] {
        self.origin
    }

    pub fn cells(&self) -> usize {
        self.dims[0] * self.dims[1] * self.dims[2]
    }
}

/// A node whose bin moved at a [`Binning::rebin`]: its index in the binning's nodes, and
/// its cells before and after (equal when it moved within its cell).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Moved {
    pub node: u32,
    pub from: u32,
    pub to: u32,
}

/// What a [`Binning::rebin`] did.
#[derive(Debug, Clone, Default)]
pub struct Rebin {
    /// The nodes re-binned, in node order.
    pub moved: Vec<Moved>,
    /// The tiles whose N(T) holds a moved node's old or new cell, ascending.
    pub stale_tiles: Vec<u32>,
    /// The tiles whose N(T) holds the old or new cell of a node that changed cell,
    /// ascending: all the proof needs marked (module docs, "Consequences").
    pub crossing_tiles: Vec<u32>,
    /// The largest |x_i,d| over the contact nodes (to check the grid's round-off
    /// allowance, [`Reach::cell_size`]).
    pub x_abs: f64,
}

/// Bin positions x̂ and cells κ of the contact nodes, and the nodes of each cell.
#[derive(Debug, Clone)]
pub struct Binning {
    /// The contact nodes (model indices), and per model node its index here
    /// (u32::MAX: not a contact node).
    nodes: Vec<u32>,
    local: Vec<u32>,
    x_bin: Vec<[f64; 3]>,
    cell: Vec<u32>,
    /// Indices (into `nodes`) per cell, ascending (CSR).
    cell_ptr: Vec<u32>,
    cell_nodes: Vec<u32>,
    /// The absolute bound U [m].
    u: f64,
    /// With hysteresis ([`Binning::with_hysteresis`]): per node, the window of its cell
    /// widened by U on each side (lo 3, hi 3; infinite past a border cell and in a
    /// component of one cell); without, unused.
    hysteresis: bool,
    window: Vec<[f64; 6]>,
}

impl CellGrid {
    /// The window of cell `c` widened by `delta` on each side (lo, hi per component),
    /// infinite past the border cells and in a component of one cell.
    pub fn window(&self, c: usize, delta: f64) -> [f64; 6] {
        let i = self.index(c);
        let mut w = [
            f64::NEG_INFINITY,
            f64::NEG_INFINITY,
            f64::NEG_INFINITY,
            f64::INFINITY,
            f64::INFINITY,
            f64::INFINITY,
        ];
        for d in 0..3 {
            if i[d] > 0 {
                w[d] = (self.origin[d] + i[d] as f64 * self.h) - delta;
            }
            if i[d] + 1 < self.dims[d] {
                w[d + 3] = (self.origin[d] + (i[d] + 1) as f64 * self.h) + delta;
            }
        }
        w
    }
}

impl Binning {
    /// [`Binning::new`] with hysteresis: a node keeps its cell while it lies in the cell
    /// widened by `u` on each side, and is re-binned (x̂ := x, the cell of x) only when it
    /// leaves that window, so that every re-bin changes its cell and a node that
    /// oscillates about a cell's face by less than `u` never does. Invariant (B) then
    /// reads: x_i,d lies within u of κ(i)'s cell (module docs, "Hysteresis"), and the
    /// lemma holds with the same cell size.
    pub fn with_hysteresis(grid: &CellGrid, nodes: &[u32], x: &[[f64; 3]], u: f64) -> Binning {
        let mut b = Binning::new(grid, nodes, x, u);
        b.hysteresis = true;
        b.window = b.cell.iter().map(|&c| grid.window(c as usize, u)).collect();
        b
    }

    /// Every node of `nodes` binned at its position in `x` (indexed by model node).
    pub fn new(grid: &CellGrid, nodes: &[u32], x: &[[f64; 3]], u: f64) -> Binning {
        let n_model = nodes.iter().map(|&n| n as usize + 1).max().unwrap_or(0);
        let mut local = vec![u32::MAX; n_model];
        for (k, &n) in nodes.iter().enumerate() {
            local[n as usize] = k as u32;
        }
        let x_bin: Vec<[f64; 3]> = nodes.iter().map(|&n| x[n as usize]).collect();
        let cell = x_bin.iter().map(|p| grid.cell(p) as u32).collect();
        let mut b = Binning {
            nodes: nodes.to_vec(),
            local,
            x_bin,
            cell,
            cell_ptr: Vec::new(),
            cell_nodes: Vec::new(),
            u,
            hysteresis: false,
            window: vec![[0.0; 6]; nodes.len()],
        };
        b.sort_cells(grid.cells());
        b
    }

    /// The nodes of each cell, by a counting sort in node order.
    fn sort_cells(&mut self, ncell: usize) {
        self.cell_ptr.clear();
        self.cell_ptr.resize(ncell + 1, 0);
        for &c in &self.cell {
            self.cell_ptr[c as usize + 1] += 1;
        }
        for c in 0..ncell {
            self.cell_ptr[c + 1] += self.cell_ptr[c];
        }
        let mut fill = self.cell_ptr.clone();
        self.cell_nodes.clear();
        self.cell_nodes.resize(self.cell.len(), 0);
        for (k, &c) in self.cell.iter().enumerate() {
            self.cell_nodes[fill[c as usize] as usize] = k as u32;
            fill[c as usize] += 1;
        }
    }

    /// Restores (B) at the positions `x`: a node with |x_d − x̂_d| > U in a component of
    /// more than one cell gets x̂ := x and the cell of x. Returns the nodes moved and the
    /// tiles of `tiling` whose N(T) holds a moved node's old or new cell (see the module
    /// docs on re-bins that keep the cell).
    pub fn rebin(&mut self, tiling: &Tiling, x: &[[f64; 3]]) -> Rebin {
        let grid = &tiling.grid;
        let multi: [bool; 3] = std::array::from_fn(|d| grid.dims[d] > 1);
        let (nodes, u) = (&self.nodes, self.u);
        // Per chunk: the moves, in node order, and the largest coordinate.
        let hysteresis = self.hysteresis;
        let parts: Vec<(Vec<Moved>, f64)> = self
            .x_bin
            .par_chunks_mut(NODE_CHUNK)
            .zip(self.cell.par_chunks_mut(NODE_CHUNK))
            .zip(self.window.par_chunks_mut(NODE_CHUNK))
            .enumerate()
            .map(|(k, ((xb, cs), ws))| {
                let mut moved = Vec::new();
                let mut x_abs = 0.0f64;
                for (j, (b, c)) in xb.iter_mut().zip(cs.iter_mut()).enumerate() {
                    let i = k * NODE_CHUNK + j;
                    let p = &x[nodes[i] as usize];
                    for d in 0..3 {
                        x_abs = x_abs.max(p[d].abs());
                    }
                    let leaves = if hysteresis {
                        // (A NaN coordinate is outside every window.)
                        !(0..3).all(|d| p[d] >= ws[j][d] && p[d] <= ws[j][d + 3])
                    } else {
                        (0..3).any(|d| multi[d] && (p[d] - b[d]).abs() > u)
                    };
                    if leaves {
                        let to = grid.cell(p) as u32;
                        moved.push(Moved {
                            node: i as u32,
                            from: *c,
                            to,
                        });
                        (*b, *c) = (*p, to);
                        if hysteresis {
                            ws[j] = grid.window(to as usize, u);
                        }
                    }
                }
                (moved, x_abs)
            })
            .collect();
        let x_abs = parts.iter().map(|p| p.1).fold(0.0, f64::max);
        let moved: Vec<Moved> = parts.into_iter().flat_map(|p| p.0).collect();
        let mut marked = vec![false; tiling.tiles.len()];
        let mut crossing = vec![false; tiling.tiles.len()];
        for m in &moved {
            for c in [m.from, m.to] {
                tiling.for_tiles_holding(c as usize, |t| {
                    marked[t] = true;
                    crossing[t] |= m.from != m.to;
                });
            }
        }
        if moved.iter().any(|m| m.from != m.to) {
            self.sort_cells(grid.cells());
        }
        let stale_tiles = (0..marked.len() as u32)
            .filter(|&t| marked[t as usize])
            .collect();
        let crossing_tiles = (0..crossing.len() as u32)
            .filter(|&t| crossing[t as usize])
            .collect();
        Rebin {
            moved,
            stale_tiles,
            crossing_tiles,
            x_abs,
        }
    }

    /// The contact nodes (model indices).
    pub fn nodes(&self) -> &[u32] {
        &self.nodes
    }

    /// The cell κ of a model node (None: not a contact node).
    pub fn cell_of(&self, node: u32) -> Option<u32> {
        match self.local.get(node as usize) {
            Some(&k) if k != u32::MAX => Some(self.cell[k as usize]),
            _ => None,
        }
    }

    /// The bin position x̂ of a model node (None: not a contact node).
    pub fn bin_position(&self, node: u32) -> Option<[f64; 3]> {
        match self.local.get(node as usize) {
            Some(&k) if k != u32::MAX => Some(self.x_bin[k as usize]),
            _ => None,
        }
    }

    /// The contact nodes (model indices) of a cell, in node order.
    fn in_cell(&self, c: usize) -> impl Iterator<Item = u32> + '_ {
        let (a, b) = (self.cell_ptr[c] as usize, self.cell_ptr[c + 1] as usize);
        self.cell_nodes[a..b]
            .iter()
            .map(|&k| self.nodes[k as usize])
    }
}

/// The faces of a side by their first node, for [`Tile::face_set`].
#[derive(Debug, Clone)]
pub struct FaceIndex {
    /// Face nodes and node count per face.
    faces: Vec<[u32; 4]>,
    nf: usize,
    /// Faces (ascending) per contact node of the binning, by their first node (CSR).
    ptr: Vec<u32>,
    of: Vec<u32>,
}

impl FaceIndex {
    /// Every face's nodes must be contact nodes of `binning` (the caller bins the slaves
    /// and the face nodes of every side).
    pub fn new(faces: &[[u32; 4]], nf: usize, binning: &Binning) -> FaceIndex {
        let first = |f: &[u32; 4]| {
            let k = binning
                .local
                .get(f[0] as usize)
                .copied()
                .unwrap_or(u32::MAX);
            assert!(
                k != u32::MAX && f[..nf].iter().all(|&a| binning.cell_of(a).is_some()),
                "a face node outside the binning: the tiles bin every face node"
            );
            k as usize
        };
        let mut ptr = vec![0u32; binning.nodes.len() + 1];
        for f in faces {
            ptr[first(f) + 1] += 1;
        }
        for k in 0..binning.nodes.len() {
            ptr[k + 1] += ptr[k];
        }
        let mut fill = ptr.clone();
        let mut of = vec![0u32; faces.len()];
        for (fi, f) in faces.iter().enumerate() {
            let k = first(f);
            of[fill[k] as usize] = fi as u32;
            fill[k] += 1;
        }
        FaceIndex {
            faces: faces.to_vec(),
            nf,
            ptr,
            of,
        }
    }
}

/// The result of a [`Tile::test`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TileTest {
    /// Whether the lists of the tile's slaves hold every pair within reach.
    pub fresh: bool,
    /// The largest spread over its cells' neighbourhoods and the components (−∞: no
    /// node in any of them) [m].
    pub spread: f64,
    /// ε̂ = 2⁻⁵² max(|x|, |y^T|) over V_T [m].
    pub eps: f64,
}

/// A box of cells, inclusive bounds per axis.
#[derive(Debug, Clone, Copy, PartialEq)]
struct CellBox {
    lo: [usize; 3],
    hi: [usize; 3],
}

impl CellBox {
    fn contains(&self, i: [usize; 3]) -> bool {
        (0..3).all(|d| i[d] >= self.lo[d] && i[d] <= self.hi[d])
    }

    fn len(&self, d: usize) -> usize {
        self.hi[d] + 1 - self.lo[d]
    }

    /// The cells, in ascending flat index of `grid`.
    fn cells(&self, grid: &CellGrid) -> Vec<u32> {
        let mut out = Vec::new();
        for k in self.lo[2]..=self.hi[2] {
            for j in self.lo[1]..=self.hi[1] {
                for i in self.lo[0]..=self.hi[0] {
                    out.push(grid.flat([i, j, k]) as u32);
                }
            }
        }
        out
    }

    /// The index of a cell of the box among [`CellBox::cells`].
    fn local(&self, i: [usize; 3]) -> usize {
        ((i[2] - self.lo[2]) * self.len(1) + (i[1] - self.lo[1])) * self.len(0)
            + (i[0] - self.lo[0])
    }
}

/// One tile: its cells T, N(T), its nodes V_T and their references y^T at its last build.
#[derive(Debug, Clone)]
pub struct Tile {
    /// T and N(T) as boxes of cells, and N(T)'s cells in ascending order.
    core: CellBox,
    near: CellBox,
    near_cells: Vec<u32>,
    /// The cells of T, ascending.
    core_cells: Vec<u32>,
    /// Per cell of T (ascending): the indices into `near_cells` of its 3 × 3 × 3
    /// neighbourhood N(c) (clamped), CSR.
    nbr_ptr: Vec<u32>,
    nbr: Vec<u32>,
    /// V_T (model indices) in the order of `near_cells`, then node order; CSR per cell
    /// of `near_cells`.
    nodes: Vec<u32>,
    cell_ptr: Vec<u32>,
    y_ref: Vec<[f64; 3]>,
    /// Builds so far, and whether a re-bin has marked it since the last.
    epoch: u64,
    stale: bool,
}

impl Tile {
    fn new(grid: &CellGrid, core: CellBox) -> Tile {
        let dims = grid.dims;
        let near = CellBox {
            lo: std::array::from_fn(|d| core.lo[d].saturating_sub(1)),
            hi: std::array::from_fn(|d| (core.hi[d] + 1).min(dims[d] - 1)),
        };
        let mut nbr_ptr = vec![0u32];
        let mut nbr = Vec::new();
        for c in core.cells(grid) {
            let i = grid.index(c as usize);
            let around = CellBox {
                lo: std::array::from_fn(|d| i[d].saturating_sub(1)),
                hi: std::array::from_fn(|d| (i[d] + 1).min(dims[d] - 1)),
            };
            nbr.extend(
                around
                    .cells(grid)
                    .into_iter()
                    .map(|e| near.local(grid.index(e as usize)) as u32),
            );
            nbr_ptr.push(nbr.len() as u32);
        }
        let near_cells = near.cells(grid);
        Tile {
            core_cells: core.cells(grid),
            core,
            near,
            cell_ptr: vec![0; near_cells.len() + 1],
            near_cells,
            nbr_ptr,
            nbr,
            nodes: Vec::new(),
            y_ref: Vec::new(),
            epoch: 0,
            stale: true,
        }
    }

    /// A build of the tile's node set at `x`: V_T = the contact nodes whose cell is in
    /// N(T) (by cell, then node order), y^T = their positions. Clears the stale mark.
    pub fn gather_refs(&mut self, binning: &Binning, x: &[[f64; 3]]) {
        self.nodes.clear();
        self.cell_ptr.clear();
        self.cell_ptr.push(0);
        for &c in &self.near_cells {
            self.nodes.extend(binning.in_cell(c as usize));
            self.cell_ptr.push(self.nodes.len() as u32);
        }
        self.y_ref.clear();
        self.y_ref.extend(self.nodes.iter().map(|&n| x[n as usize]));
        self.epoch += 1;
        self.stale = false;
    }

    /// The criterion at `x` (module docs): for every cell c of T and component d, the
    /// spread of x_d − y^T_d over N(c) is at most skin − 4ε̂; false also when the tile is
    /// marked stale or has never been built.
    pub fn test(&self, x: &[[f64; 3]], skin: f64) -> TileTest {
        self.test_with(x, skin, &mut Vec::new(), &mut Vec::new())
    }

    /// [`Tile::test`] with its scratch (`range`, per cell of N(T)) given, and the norm
    /// |S| of the spreads (S_x, S_y, S_z) over each cell's N(c) written to `spreads`, per
    /// cell of T in the order of [`Tile::cells`] (+∞ for an empty N(c)): the bound on how
    /// far the nodes around a slave have moved apart since b_T that the narrow phase's
    /// skip test reads (`Side::margin`).
    pub fn test_with(
        &self,
        x: &[[f64; 3]],
        skin: f64,
        range: &mut Vec<[f64; 6]>,
        spreads: &mut Vec<f64>,
    ) -> TileTest {
        // Per cell of N(T): min Δ (3), max Δ (3); and the largest |x|, |y|.
        range.clear();
        range.resize(self.near_cells.len(), EMPTY_RANGE);
        let mut big = 0.0f64;
        for (c, r) in range.iter_mut().enumerate() {
            for i in self.cell_ptr[c] as usize..self.cell_ptr[c + 1] as usize {
                let (p, q) = (&x[self.nodes[i] as usize], &self.y_ref[i]);
                for d in 0..3 {
                    let u = p[d] - q[d];
                    r[d] = r[d].min(u);
                    r[d + 3] = r[d + 3].max(u);
                    big = big.max(p[d].abs()).max(q[d].abs());
                }
            }
        }
        let eps = big * f64::EPSILON;
        let limit = skin - 4.0 * eps;
        let mut fresh = !self.stale && self.epoch > 0;
        let mut spread = f64::NEG_INFINITY;
        spreads.clear();
        for k in 0..self.nbr_ptr.len() - 1 {
            let mut m = range[self.nbr[self.nbr_ptr[k] as usize] as usize];
            for &e in &self.nbr[self.nbr_ptr[k] as usize + 1..self.nbr_ptr[k + 1] as usize] {
                let o = &range[e as usize];
                for d in 0..3 {
                    m[d] = m[d].min(o[d]);
                    m[d + 3] = m[d + 3].max(o[d + 3]);
                }
            }
            let sd: [f64; 3] = std::array::from_fn(|d| m[d + 3] - m[d]);
            for &s in &sd {
                // (A NaN spread is not ≤ the limit: stale.)
                fresh &= s <= limit;
                spread = spread.max(s);
            }
            // (An empty neighbourhood: −∞ spreads, an infinite norm.)
            spreads.push((sd[0] * sd[0] + sd[1] * sd[1] + sd[2] * sd[2]).sqrt());
        }
        TileTest { fresh, spread, eps }
    }

    /// FaceSet(T): the faces of `index` whose nodes are all in V_T (their cells in N(T)
    /// by `binning`, as at [`Tile::gather_refs`]) and that are `alive`, ascending.
    pub fn face_set(
        &self,
        index: &FaceIndex,
        binning: &Binning,
        grid: &CellGrid,
        alive: impl Fn(u32) -> bool,
    ) -> Vec<u32> {
        let inside = |a: u32| {
            binning
                .cell_of(a)
                .is_some_and(|c| self.near.contains(grid.index(c as usize)))
        };
        let mut out = Vec::new();
        for &n in &self.nodes {
            let k = binning.local[n as usize] as usize;
            for &fi in &index.of[index.ptr[k] as usize..index.ptr[k + 1] as usize] {
                let f = &index.faces[fi as usize];
                if f[1..index.nf].iter().all(|&a| inside(a)) && alive(fi) {
                    out.push(fi);
                }
            }
        }
        out.sort_unstable();
        out
    }

    /// V_T (model indices), by cell of N(T) then node order.
    pub fn nodes(&self) -> &[u32] {
        &self.nodes
    }

    /// The nodes of V_T whose cell is in T (the tile's slaves among them), ascending.
    pub fn core_nodes(&self, grid: &CellGrid) -> Vec<u32> {
        let mut out: Vec<u32> = (0..self.near_cells.len())
            .filter(|&c| self.core.contains(grid.index(self.near_cells[c] as usize)))
            .flat_map(|c| {
                self.nodes[self.cell_ptr[c] as usize..self.cell_ptr[c + 1] as usize]
                    .iter()
                    .copied()
            })
            .collect();
        out.sort_unstable();
        out
    }

    /// The cells of T, ascending.
    pub fn cells(&self, grid: &CellGrid) -> Vec<u32> {
        self.core.cells(grid)
    }

    /// The cells of T, ascending (as [`Tile::cells`], kept).
    pub fn core_cells(&self) -> &[u32] {
        &self.core_cells
    }

    /// The cells of N(T), ascending.
    pub fn near_cells(&self) -> &[u32] {
        &self.near_cells
    }

    /// Whether a re-bin has marked the tile since its last build (or it has none).
    pub fn is_stale(&self) -> bool {
        self.stale
    }

    /// Builds so far.
    pub fn epoch(&self) -> u64 {
        self.epoch
    }
}

/// The tiles over a grid: `t` × `t` cells in the two axes of most cells, every cell along
/// the third (the axis of fewest cells, the last of equals, as the gate of
/// [`super::staleness::tile_marks`]).
#[derive(Debug, Clone)]
pub struct Tiling {
    grid: CellGrid,
    t: usize,
    /// The two tiled axes, and the tiles along each.
    axes: [usize; 2],
    per: [usize; 2],
    tiles: Vec<Tile>,
}

impl Tiling {
    pub fn new(grid: CellGrid, t: usize) -> Tiling {
        let t = t.max(1);
        let dims = grid.dims;
        let z = (0..3)
            .min_by_key(|&d| (dims[d], std::cmp::Reverse(d)))
            .unwrap_or(2);
        let axes = match z {
            0 => [1, 2],
            1 => [0, 2],
            _ => [0, 1],
        };
        let per = [dims[axes[0]].div_ceil(t), dims[axes[1]].div_ceil(t)];
        let mut tiles = Vec::with_capacity(per[0] * per[1]);
        for tb in 0..per[1] {
            for ta in 0..per[0] {
                let mut core = CellBox {
                    lo: [0; 3],
                    hi: [dims[0] - 1, dims[1] - 1, dims[2] - 1],
                };
                for (k, &ti) in [ta, tb].iter().enumerate() {
                    let a = axes[k];
                    core.lo[a] = ti * t;
                    core.hi[a] = ((ti + 1) * t).min(dims[a]) - 1;
                }
                tiles.push(Tile::new(&grid, core));
            }
        }
        Tiling {
            grid,
            t,
            axes,
            per,
            tiles,
        }
    }

    /// Calls `f` with every tile whose N(T) holds cell `c`: those within one cell of it
    /// along both tiled axes.
    pub fn for_tiles_holding(&self, c: usize, mut f: impl FnMut(usize)) {
        let i = self.grid.index(c);
        let range = |k: usize| {
            let a = self.axes[k];
            let lo = i[a].saturating_sub(1) / self.t;
            let hi = (i[a] + 1).min(self.grid.dims[a] - 1) / self.t;
            lo..=hi
        };
        for tb in range(1) {
            for ta in range(0) {
                f(tb * self.per[0] + ta);
            }
        }
    }

    /// Marks `tiles` stale (as a [`Rebin`] reports them).
    pub fn mark_stale(&mut self, tiles: &[u32]) {
        for &t in tiles {
            self.tiles[t as usize].stale = true;
        }
    }

    pub fn grid(&self) -> &CellGrid {
        &self.grid
    }

    pub fn tiles(&self) -> &[Tile] {
        &self.tiles
    }

    pub fn tiles_mut(&mut self) -> &mut [Tile] {
        &mut self.tiles
    }
}

/// The widest thickness box (the balls of radius t_a/2 about the nodes) over `faces` (`nf`
/// nodes each) and the three components, at `x`; faces not `alive` left out.
pub fn max_box_width(
    faces: &[[u32; 4]],
    face_t: &[[f64; 4]],
    nf: usize,
    x: &[[f64; 3]],
    alive: impl Fn(usize) -> bool + Sync,
) -> f64 {
    faces
        .par_iter()
        .zip(face_t)
        .enumerate()
        .filter(|(fi, _)| alive(*fi))
        .map(|(_, (f, t))| {
            let mut w = 0.0f64;
            for d in 0..3 {
                let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
                for a in 0..nf {
                    let (p, r) = (x[f[a] as usize][d], 0.5 * t[a]);
                    lo = lo.min(p - r);
                    hi = hi.max(p + r);
                }
                w = w.max(hi - lo);
            }
            w
        })
        .reduce(|| 0.0, f64::max)
}

/// What the [`WidthMonitor`] asks for at a step.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum WidthCheck {
    /// The running bound is within the cap: (W) holds.
    Bounded,
    /// Take the exact widths now ([`max_box_width`], then [`WidthMonitor::measured`]):
    /// the cadence is due or the bound has passed the cap.
    Measure,
}

/// The width monitor W of invariant (W): exact widths every `cadence` steps or when the
/// running bound W(n₀) + 2 Σ Δt v_max passes the cap (one step moves a box's side by at
/// most the largest step of its nodes, so its width by at most twice that).
#[derive(Debug, Clone)]
pub struct WidthMonitor {
    cap: f64,
    cadence: usize,
    bound: f64,
    since: usize,
}

impl WidthMonitor {
    /// A monitor of cap W_cap, with the exact widths `w0` at setup.
    pub fn new(cap: f64, cadence: usize, w0: f64) -> WidthMonitor {
        WidthMonitor {
            cap,
            cadence: cadence.max(1),
            bound: w0,
            since: 0,
        }
    }

    /// One step on which no contact node moved more than `step` (Δt v_max, |·|∞) in any
    /// component.
    pub fn advance(&mut self, step: f64) -> WidthCheck {
        self.bound += 2.0 * step;
        self.since += 1;
        // (A NaN bound is not within the cap: measure.)
        if self.since >= self.cadence || !(self.bound <= self.cap) {
            WidthCheck::Measure
        } else {
            WidthCheck::Bounded
        }
    }

    /// The exact widest box `w`: restarts the bound; false when it is past the cap (a
    /// re-grid with larger cells is due).
    pub fn measured(&mut self, w: f64) -> bool {
        self.bound = w;
        self.since = 0;
        w <= self.cap
    }

    /// The running bound on the widest box [m].
    pub fn bound(&self) -> f64 {
        self.bound
    }
}
