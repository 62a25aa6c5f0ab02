//! The backing clay's crater, read from the clay that is left.
//!
//! A model with clay names its top surface's points along a radius from the shot's axis
//! (node set `clay_profile`, outwards). Each point stands on a column of the clay's grid:
//! the nodes below it with the same reference x and y. The crater's floor at a point is
//! the column's highest node that still belongs to a live cell (the failure log's live-element counts):
//! the top node itself until every cell around it has eroded, then the next one down.
//! An eroded cell's orphaned node flies on as a free mass and says nothing of the crater.
//! Its depth is measured from the undisturbed top, −(z − Z_top), and its radius is where
//! that node is now. Without erosion every column's top node is attached and the crater
//! is the top's displacement.

use crate::error::{Result, WeftError};
use crate::model::{ElementKind, Model};

/// The node set whose points the crater is sampled at.
pub const PROFILE_SET: &str = "clay_profile";

/// One crater point: r0 [m] (its top's reference radius), r [m] (where its floor is
/// now), depth [m] (below the undisturbed top).
pub type CraterRow = [f64; 3];

/// The crater's points and their columns.
#[derive(Debug, Clone)]
pub struct CraterWatch {
    /// Per point: its column's nodes, top first, downwards.
    columns: Vec<Vec<u32>>,
    /// Per point: the top's reference radius and height [m].
    r0: Vec<f64>,
    z_top: Vec<f64>,
    /// Per point: the clay's depth under it at the setup (its column's top to bottom) [m].
    block_depth: Vec<f64>,
}

/// The fraction of the clay's depth under a point that its crater may reach before the
/// run stops: the block's floor (held, a symmetry plane of the box) would then be
/// shaping the crater, which a block thinner than the crater cannot measure.
pub const DEEPEST_FRACTION: f64 = 0.9;

impl CraterWatch {
    /// The crater of `m` along `clay_profile`, with reference positions `x0`; `None`
    /// without that set. A point's column holds the nodes of the hexahedra of its top
    /// node's part that share its reference x and y (to 1 nm) and lie below it.
    pub fn new(m: &Model, x0: &[[f64; 3]]) -> Option<CraterWatch> {
        let profile = m.node_sets.get(PROFILE_SET)?;
        let hex = m.elements.get(&ElementKind::Hex)?;
        const SAME: f64 = 1e-9;
        // The clay's nodes (those of hex cells of each top node's part), by part.
        let mut part_nodes: std::collections::BTreeMap<usize, Vec<u32>> = Default::default();
        let mut node_part = vec![usize::MAX; x0.len()];
        for e in 0..hex.len() {
            for &n in &hex.nodes[8 * e..8 * e + 8] {
                node_part[n] = hex.part[e];
            }
        }
        for (n, &p) in node_part.iter().enumerate() {
            if p != usize::MAX {
                part_nodes.entry(p).or_default().push(n as u32);
            }
        }
        let mut columns = Vec::with_capacity(profile.len());
        for &top in profile {
            let xt = x0[top];
            let mut col: Vec<u32> = part_nodes
                .get(&node_part[top])
                .map(|ns| {
                    ns.iter()
                        .copied()
                        .filter(|&n| {
                            let x = x0[n as usize];
                            (x[0] - xt[0]).abs() <= SAME
                                && (x[1] - xt[1]).abs() <= SAME
                                && x[2] <= xt[2] + SAME
                        })
                        .collect()
                })
                .unwrap_or_default();
            if col.is_empty() {
                // Not a clay node: the point is its own column.
                col.push(top as u32);
            }
            col.sort_by(|&a, &b| x0[b as usize][2].total_cmp(&x0[a as usize][2]));
            columns.push(col);
        }
        Some(CraterWatch {
            block_depth: columns
                .iter()
                .map(|c| x0[c[0] as usize][2] - x0[c[c.len() - 1] as usize][2])
                .collect(),
            r0: profile.iter().map(|&n| x0[n][0].hypot(x0[n][1])).collect(),
            z_top: profile.iter().map(|&n| x0[n][2]).collect(),
            columns,
        })
    }

    /// The number of points.
    pub fn len(&self) -> usize {
        self.columns.len()
    }

    pub fn is_empty(&self) -> bool {
        self.columns.is_empty()
    }

    /// The crater now, one row per point (see [`CraterRow`]), at positions `x`, with
    /// `attached(n)` whether node n still belongs to a live element
    /// (`FailureLog::is_attached`). A column eroded through reads its bottom node.
    pub fn sample(
        &self,
        x: &[[f64; 3]],
        attached: impl Fn(usize) -> bool,
        rows: &mut Vec<CraterRow>,
    ) {
        rows.clear();
        for (k, col) in self.columns.iter().enumerate() {
            let n = col
                .iter()
                .copied()
                .find(|&n| attached(n as usize))
                .unwrap_or(col[col.len() - 1]) as usize;
            rows.push([self.r0[k], x[n][0].hypot(x[n][1]), self.z_top[k] - x[n][2]]);
        }
    }

    /// Stops the run (at `step`, time `t`) when the crater `rows` (from
    /// [`CraterWatch::sample`]) reaches [`DEEPEST_FRACTION`] of the clay's depth under a
    /// point: the block is thinner than the crater.
    pub fn check_depth(&self, rows: &[CraterRow], step: u64, t: f64) -> Result<()> {
        for (row, &h) in rows.iter().zip(&self.block_depth) {
            if h > 0.0 && row[2] >= DEEPEST_FRACTION * h {
                return Err(WeftError::Numerical {
                    what: format!(
                        "the crater {r0:.4e} m from the shot's axis is {d:.4e} m deep, {p:.0} % of the clay block's depth {h:.4e} m there: the block is thinner than the crater (its floor, held, shapes it)",
                        r0 = row[0],
                        d = row[2],
                        p = 100.0 * row[2] / h
                    ),
                    step,
                    time: t,
                    hint: Some(
                        "a deeper block: weft-weave --clay-depth (NIJ Standard-0101.06's box is 0.14 m deep)".into(),
                    ),
                });
            }
        }
        Ok(())
    }
}
