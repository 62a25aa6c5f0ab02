//! `constraints.parquet`: fixed translations and, for nodes with beams, fixed rotations,
//! one row per constrained node.

use std::collections::BTreeMap;

use super::codec::{Reading, Writing};
use crate::error::Result;
use crate::model::types::Model;
use crate::table::{batch, Col};

pub const FILE: &str = "constraints.parquet";
/// Expected columns, for error messages.
const COLS: &str = "node_id, fix_x, fix_y, fix_z";

/// Reads the fixed translations of every row, and the fixed rotations of the rows that
/// fix any (the rotation columns may be absent, a null is free).
pub fn read(r: &mut Reading) -> Result<()> {
    let Some(t) = r.optional(FILE)? else {
        return Ok(());
    };
    let ids = t.i64("node_id", COLS)?;
    let idx = r.node_refs(&t, "node_id", &ids)?;
    let (fx, fy, fz) = (
        t.bool("fix_x", COLS)?,
        t.bool("fix_y", COLS)?,
        t.bool("fix_z", COLS)?,
    );
    let m = &mut r.model;
    m.constraints = (0..idx.len())
        .map(|i| (idx[i], [fx[i], fy[i], fz[i]]))
        .collect();
    let rot = |c: &str| -> Result<Vec<bool>> {
        Ok(t.bool_opt(c)?
            .map(|v| v.into_iter().map(|b| b.unwrap_or(false)).collect())
            .unwrap_or_else(|| vec![false; idx.len()]))
    };
    let (rx, ry, rz) = (rot("fix_rx")?, rot("fix_ry")?, rot("fix_rz")?);
    m.rot_constraints = (0..idx.len())
        .filter(|&i| rx[i] || ry[i] || rz[i])
        .map(|i| (idx[i], [rx[i], ry[i], rz[i]]))
        .collect();
    Ok(())
}

/// Writes the constraints when the model has any, the rotation columns when it fixes
/// rotations.
pub fn write(m: &Model, w: &Writing) -> Result<()> {
    if m.constraints.is_empty() && m.rot_constraints.is_empty() {
        return Ok(());
    }
    // One row per node: translations and rotations merged.
    let mut rows: BTreeMap<usize, [bool; 6]> = BTreeMap::new();
    for (n, f) in &m.constraints {
        let r = rows.entry(*n).or_default();
        for d in 0..3 {
            r[d] |= f[d];
        }
    }
    for (n, f) in &m.rot_constraints {
        let r = rows.entry(*n).or_default();
        for d in 0..3 {
            r[3 + d] |= f[d];
        }
    }
    let col = |k: usize| rows.values().map(|r| r[k]).collect::<Vec<_>>();
    let mut cols = vec![
        Col::I64("node_id", rows.keys().map(|&n| m.node_id[n]).collect()),
        Col::Bool("fix_x", col(0)),
        Col::Bool("fix_y", col(1)),
        Col::Bool("fix_z", col(2)),
    ];
    if !m.rot_constraints.is_empty() {
        cols.push(Col::Bool("fix_rx", col(3)));
        cols.push(Col::Bool("fix_ry", col(4)));
        cols.push(Col::Bool("fix_rz", col(5)));
    }
    w.table(FILE, &batch(cols))
}
