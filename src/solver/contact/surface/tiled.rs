//! The tiled broad phase: the candidate lists of each tile of cells rebuilt alone, when
//! its own test finds them stale, instead of every list when one region is
//! ([`super::super::tiles`] holds the pieces and the proof that no pair within reach is
//! missed; [`super::super::staleness`] is its special case of one tile).
//!
//! Per step, before the narrow phase ([`TileSearch::check`], then
//! [`TileSearch::rebuild`]):
//! 1. (W): the widest live thickness box, exact from the step's boxes; past the cap, a
//!    re-grid (new cells sized for it, every tile rebuilt);
//! 2. (B): the nodes re-binned; a node that changes cell marks the tiles whose N(T) holds
//!    its old or new cell, (M) then holding once they rebuild; a coordinate past
//!    [`X_ABS_LIMIT`] times the largest at the last grid also re-grids (the cells'
//!    round-off allowance);
//! 3. every tile's test; its cells' spreads |S| go to the narrow phase's skip test;
//! 4. the stale tiles rebuild: their node sets and references, then per side the faces
//!    with every node in V_T, their envelope directions refreshed, and the candidate
//!    lists and margins of the side's slaves whose cell is in T, each tile's lists one
//!    list of the side's (`Side::lists`).
//!
//! **Not the default** ([`super::Search`]): on the woven impacts it is slower than the
//! global search (measured in docs/benchmarks.md, "The tiled search"). Two costs that the
//! design did not foresee: the yarns, drawn in toward the impact along their length,
//! carry their nodes across the fixed cells, and each change of cell rebuilds the tiles
//! around it (93 % of the tile builds at U = 4 skins); and the test reads every node once
//! per tile whose N(T) holds it ((t + 2)²/t² times the global test's reads). The global
//! search's builds, the cost this search removes, are 14 % of the band patch's wall time
//! on today's tip (4.3 of 30.6 s).
//!
//! The narrow phase is unchanged: each slave reads its candidates, ascending, from its
//! tile's list, and its margin and cell from the tile's build. Its results are the same
//! bits as with the global search: both lists hold every face the slave can penetrate in
//! ascending order, the filters reject only faces the closest-point test rejects, and a
//! slave is skipped only when no candidate can pass them.
//!
//! Envelope directions are refreshed at a tile's build for its faces only, so a face
//! shared with a tile that is not rebuilt changes direction under that tile's margins.
//! The margins stay valid: `Side::margin`'s bound holds for the direction m_b it was
//! taken with (v_F(n) ≥ v_F^b − |S| along any fixed unit m_b), and along any unit
//! direction the filter is sound, so a slave past its margin penetrates nothing whatever
//! direction the filter now uses.

use rayon::prelude::*;

use super::boxes::MasterBoxes;
use super::side::Side;
use crate::solver::contact::tiles::{Binning, CellGrid, FaceIndex, Reach, Tiling};

/// Cells per tile side in the two tiled axes (every cell along the third), and the
/// binning's hysteresis U in skins (a node changes cell only once it is U past it; the
/// cells grow by 2U). Measured on the 60 × 60 band quarter to 60 µs (2 threads): with
/// U = 2 skins and 4 × 4 tiles, 20 217 of 20 459 tile builds were asked for by nodes
/// changing cell (the yarns drawn in toward the impact carry their nodes across the
/// fixed cells), 46.6 s; with U = 4, 3 × 3 tiles: 6 587 of 7 064, 42.9 s; 2 × 2 tiles:
/// 10 509 of 11 599, 43.6 s. The global search took 30.6 s in the same sitting.
pub const TILE_CELLS: usize = 3;
pub const TILE_U_PER_SKIN: f64 = 4.0;

/// A re-grid when a coordinate passes this multiple of the largest at the last grid plus
/// the cell size the lemma needs: the cells' round-off allowance ([`Reach::cell_size`])
/// holds to about 1600.
const X_ABS_LIMIT: f64 = 1000.0;

/// What the tiled search did over a run.
#[derive(Debug, Clone, Copy, Default)]
pub struct TileStats {
    /// Tiles of the grid (at the last re-grid).
    pub tiles: usize,
    /// Tile builds (the setup's included), and the steps with at least one.
    pub tile_builds: u64,
    pub steps_with_builds: u64,
    /// Of the tile builds, those a node's change of cell asked for (the others: the
    /// tile's own test, or a re-grid).
    pub marked: u64,
    /// Grids after the setup's: a box past the width cap, or a coordinate past
    /// [`X_ABS_LIMIT`].
    pub regrids: u64,
}

/// The tiled search's state: the cells, the nodes' bins, the tiles, and per side the
/// faces by first node and each node's slave index.
#[derive(Debug, Clone)]
pub struct TileSearch {
    reach: Reach,
    /// The contact nodes (model indices, sorted).
    nodes: Vec<u32>,
    tiling: Tiling,
    /// Cells per tile side, and the width cap's slack in U (W_cap = W + slack U).
    cells: usize,
    slack: f64,
    binning: Binning,
    /// The largest |x_d| at the last grid.
    x_abs: f64,
    /// Per side: its faces by first node, and per model node its slave index
    /// (u32::MAX: not a slave of the side).
    index: Vec<FaceIndex>,
    slave_of: Vec<Vec<u32>>,
    /// Per cell of the grid, |S| of its neighbourhood since its tile's build.
    spread: Vec<f64>,
    /// The tiles to rebuild at this step ([`TileSearch::check`]), and whether a re-bin
    /// marked them.
    stale: Vec<u32>,
    pub stats: TileStats,
}

/// The widest live thickness box over the master surfaces, per component [m] (from the
/// step's boxes; eroded faces' boxes are empty).
fn widest(masters: &[MasterBoxes]) -> f64 {
    masters.iter().map(MasterBoxes::widest).fold(0.0, f64::max)
}

impl TileSearch {
    /// The search over `nodes` (every slave and face node of `sides`) at `x`, whose face
    /// boxes (`masters`) are up to date, with the broad phase's `skin`; every tile is
    /// stale until the first [`TileSearch::rebuild`].
    pub(super) fn new(
        sides: &[Side],
        masters: &[MasterBoxes],
        nodes: &[u32],
        x: &[[f64; 3]],
        skin: f64,
        (cells, u_per_skin, slack): (usize, f64, f64),
    ) -> TileSearch {
        let rho = sides
            .iter()
            .map(|s| 0.5 * s.slave_t_max + s.box_margin)
            .fold(0.0, f64::max);
        let u = u_per_skin * skin;
        let reach = Reach {
            rho,
            skin,
            w_cap: 0.0,
            u,
        };
        let grid = CellGrid::covering([0.0; 3], [0.0; 3], 1.0, 0);
        let binning = Binning::new(&grid, nodes, x, u);
        let index = sides
            .iter()
            .map(|s| FaceIndex::new(&s.faces, s.nf, &binning))
            .collect();
        let n_model = nodes.last().map_or(0, |&n| n as usize + 1);
        let slave_of = sides
            .iter()
            .map(|s| {
                let mut of = vec![u32::MAX; n_model];
                for (si, &n) in s.slaves.iter().enumerate() {
                    of[n as usize] = si as u32;
                }
                of
            })
            .collect();
        let mut t = TileSearch {
            reach,
            nodes: nodes.to_vec(),
            tiling: Tiling::new(grid, cells),
            cells,
            slack,
            binning,
            x_abs: 0.0,
            index,
            slave_of,
            spread: Vec::new(),
            stale: Vec::new(),
            stats: TileStats::default(),
        };
        t.regrid(x, widest(masters));
        t.stats.regrids = 0;
        t
    }

    /// New cells for the widest box `w` at `x` (the cap W_cap = w + 2U by default), every
    /// node binned at x, every tile stale.
    fn regrid(&mut self, x: &[[f64; 3]], w: f64) {
        self.reach.w_cap = w + self.slack * self.reach.u;
        let grid = CellGrid::for_nodes(&self.nodes, x, &self.reach);
        self.binning = Binning::with_hysteresis(&grid, &self.nodes, x, self.reach.u);
        self.x_abs = self
            .nodes
            .iter()
            .flat_map(|&n| x[n as usize])
            .fold(0.0, |a: f64, c| a.max(c.abs()));
        self.spread = vec![0.0; grid.cells()];
        self.tiling = Tiling::new(grid, self.cells);
        self.stats.tiles = self.tiling.tiles().len();
        self.stats.regrids += 1;
    }

    /// Restores (W) and (B) at `x` (the step's face boxes `masters` computed), tests
    /// every tile and keeps its cells' spreads; returns how many tiles must rebuild.
    pub(super) fn check(&mut self, masters: &[MasterBoxes], x: &[[f64; 3]]) -> usize {
        let w = widest(masters);
        let mut regrid = !(w <= self.reach.w_cap);
        let mut marked: Vec<u32> = Vec::new();
        if !regrid {
            let rb = self.binning.rebin(&self.tiling, x);
            // (The allowance's scale is the coordinates at the grid plus the cell size the
            // lemma needs, see `Reach::cell_size`.)
            let need = self.reach.r() + self.reach.w_cap + 2.0 * self.reach.u;
            if rb.x_abs <= X_ABS_LIMIT * (self.x_abs + need) {
                self.tiling.mark_stale(&rb.crossing_tiles);
                marked = rb.crossing_tiles;
            } else {
                regrid = true;
            }
        }
        if regrid {
            self.regrid(x, w);
        }
        let skin = self.reach.skin;
        let tests: Vec<(bool, Vec<f64>)> = self
            .tiling
            .tiles()
            .par_iter()
            .map_init(Vec::new, |range, t| {
                let mut sp = Vec::new();
                let r = t.test_with(x, skin, range, &mut sp);
                (r.fresh, sp)
            })
            .collect();
        self.stale.clear();
        for (k, (fresh, sp)) in tests.iter().enumerate() {
            let tile = &self.tiling.tiles()[k];
            if *fresh {
                for (&c, &s) in tile.core_cells().iter().zip(sp) {
                    self.spread[c as usize] = s;
                }
            } else {
                self.stale.push(k as u32);
                // (Rebuilt at x: no node has moved since.)
                for &c in tile.core_cells() {
                    self.spread[c as usize] = 0.0;
                }
            }
        }
        self.stats.marked += marked
            .iter()
            .filter(|t| self.stale.binary_search(t).is_ok())
            .count() as u64;
        self.stale.len()
    }

    /// Rebuilds the tiles [`TileSearch::check`] found stale, at `x`: their node sets and
    /// references, then per side the candidate lists of their slaves (module docs), the
    /// envelope directions of their faces refreshed in the side's master surface (the
    /// same faces and values for every side of it).
    pub(super) fn rebuild(
        &mut self,
        sides: &mut [Side],
        masters: &mut [MasterBoxes],
        x: &[[f64; 3]],
    ) {
        if self.stale.is_empty() {
            return;
        }
        let stale = std::mem::take(&mut self.stale);
        let mut is_stale = vec![false; self.tiling.tiles().len()];
        for &t in &stale {
            is_stale[t as usize] = true;
        }
        let binning = &self.binning;
        self.tiling
            .tiles_mut()
            .par_iter_mut()
            .zip(&is_stale)
            .filter(|(_, &s)| s)
            .for_each(|(t, _)| t.gather_refs(binning, x));
        let (tiling, grid) = (&self.tiling, self.tiling.grid());
        let core: Vec<Vec<u32>> = stale
            .par_iter()
            .map(|&t| tiling.tiles()[t as usize].core_nodes(grid))
            .collect();
        let ntiles = tiling.tiles().len();
        let skin = self.reach.skin;
        for (k, side) in sides.iter_mut().enumerate() {
            let index = &self.index[k];
            let sets: Vec<Vec<u32>> = stale
                .par_iter()
                .map(|&t| {
                    let alive = &side.face_alive;
                    tiling.tiles()[t as usize].face_set(index, binning, grid, |f| alive[f as usize])
                })
                .collect();
            let mut mask = vec![false; side.faces.len()];
            for set in &sets {
                for &f in set {
                    mask[f as usize] = true;
                }
            }
            let sd: &Side = side;
            masters[sd.surface].set_directions_of(sd, x, Some(&mask));
            let boxes = &masters[sd.surface];
            let slave_of = &self.slave_of[k];
            let built: Vec<_> = core
                .par_iter()
                .zip(&sets)
                .map(|(nodes, set)| {
                    let slaves: Vec<u32> = nodes
                        .iter()
                        .map(|&n| slave_of[n as usize])
                        .filter(|&si| si != u32::MAX)
                        .collect();
                    sd.build_tile(x, skin, boxes, set, &slaves)
                })
                .collect();
            let ns = side.slaves.len();
            side.lists.resize_with(ntiles, Vec::new);
            side.cand_at.resize(ns, [0; 3]);
            side.margin.resize(ns, f64::INFINITY);
            side.slave_cell.resize(ns, 0);
            for (&t, lists) in stale.iter().zip(built) {
                for &(si, a, b, m) in &lists.slaves {
                    let si = si as usize;
                    side.cand_at[si] = [t, a, b];
                    side.margin[si] = m;
                    side.slave_cell[si] = binning.cell_of(side.slaves[si]).unwrap_or(0);
                }
                side.lists[t as usize] = lists.cand;
            }
        }
        self.stats.tile_builds += stale.len() as u64;
        self.stats.steps_with_builds += 1;
    }

    /// Per cell of the grid, |S| of its neighbourhood since its tile's build (at the
    /// last [`TileSearch::check`]), for the narrow phase's skip test.
    pub(super) fn spread(&self) -> &[f64] {
        &self.spread
    }
}
