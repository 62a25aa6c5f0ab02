//! Time series of chosen nodes ([`Series`]), read from a model folder and its
//! `history.parquet`: what the wave speeds, the mismatch T and the interpolation between
//! meshes take.

use std::collections::HashMap;
use std::path::Path;

use crate::error::{Result, WeftError};
use crate::model::io::read_model;
use crate::table::history::History;
pub use crate::table::history::COMPONENTS;

/// Time series of the nodes of one node set, read from a history table.
#[derive(Debug, Clone)]
pub struct Series {
    pub t: Vec<f64>,
    pub node_id: Vec<i64>,
    /// Initial positions of the nodes [m].
    pub x0: Vec<[f64; 3]>,
    /// `values[k][j][c]`: component c (ux, uy, uz, vx, vy, vz) of node j at sample k.
    pub values: Vec<Vec<[f64; 6]>>,
}

/// Parse a list like `ux,uy` into component indices.
pub fn components(list: &str) -> Result<Vec<usize>> {
    list.split(',')
        .map(|c| {
            let c = c.trim();
            COMPONENTS.iter().position(|n| *n == c).ok_or_else(|| {
                WeftError::input(format!("unknown component `{c}`"))
                    .expected("some of ux, uy, uz, vx, vy, vz, comma-separated")
            })
        })
        .collect()
}

/// Read the nodes of `set` (in set order) from a model folder and its history table.
pub fn read_series(model: &Path, history: &Path, set: &str) -> Result<Series> {
    read_series_of(model, history, set, &[0, 1, 2, 3, 4, 5])
}

/// [`read_series`] needing only components `needed` (0..6 = ux … vz): a history without
/// the others (a displacement-only table) reads with them NaN.
pub fn read_series_of(model: &Path, history: &Path, set: &str, needed: &[usize]) -> Result<Series> {
    let m = read_model(model)?;
    let nodes = m.node_sets.get(set).ok_or_else(|| {
        WeftError::input(format!(
            "model `{}` has no node set `{set}`",
            model.display()
        ))
        .expected(format!("one of {}", m.node_set_names()))
    })?;
    read_nodes_of(&m, history, nodes, &format!("of set `{set}`"), needed)
}

/// Read the history of model nodes `nodes` (indices, in that order) from a history
/// table; `what` names them in errors (e.g. "of set `axis_x`").
pub fn read_nodes(
    m: &crate::model::Model,
    history: &Path,
    nodes: &[usize],
    what: &str,
) -> Result<Series> {
    read_nodes_of(m, history, nodes, what, &[0, 1, 2, 3, 4, 5])
}

/// [`read_nodes`] needing only components `needed`; absent others read NaN.
pub fn read_nodes_of(
    m: &crate::model::Model,
    history: &Path,
    nodes: &[usize],
    what: &str,
    needed: &[usize],
) -> Result<Series> {
    let h = History::read_components(history, needed)?;
    // T sums squares: a value whose square overflows would give T = NaN, named nowhere.
    h.refuse_overflowing_squares("|value| < 1e150 (its square must not overflow)")?;
    let want: HashMap<i64, usize> = nodes
        .iter()
        .enumerate()
        .map(|(j, &i)| (m.node_id[i], j))
        .collect();
    let mut values: Vec<Vec<[f64; 6]>> = vec![];
    let mut seen = vec![0usize; nodes.len()];
    let times = h.by_time(|k, r| {
        if k == values.len() {
            values.push(vec![[f64::NAN; 6]; nodes.len()]);
        }
        if let Some(&j) = want.get(&h.node_id[r]) {
            values[k][j] = h.row(r);
            seen[j] += 1;
        }
        Ok(())
    })?;
    if let Some(j) = (0..nodes.len()).find(|&j| seen[j] != times.len()) {
        return Err(WeftError::input(format!(
            "node `{}` {what} has {} of {} samples in the history",
            m.node_id[nodes[j]],
            seen[j],
            times.len()
        ))
        .in_file(history)
        .expected("every node of the set at every output time")
        .hint("write the history of this set: weft-simulate --history-set NAME (or all nodes)"));
    }
    Ok(Series {
        t: times,
        node_id: nodes.iter().map(|&i| m.node_id[i]).collect(),
        x0: nodes.iter().map(|&i| m.coords[i]).collect(),
        values,
    })
}
