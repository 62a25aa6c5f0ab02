//! `nodes.parquet`: node ids and reference coordinates, with the initial displacement of
//! a formed state.

use super::codec::{Reading, Writing};
use crate::error::{Result, WeftError};
use crate::model::types::Model;
use crate::table::{batch, Col};

pub const FILE: &str = "nodes.parquet";
/// Expected columns, for error messages.
const COLS: &str = "node_id, x, y, z";

/// Reads the nodes and indexes them by id; the model needs at least one node, each id once.
pub fn read(r: &mut Reading) -> Result<()> {
    let t = r.table(FILE)?;
    let m = &mut r.model;
    m.node_id = t.i64("node_id", COLS)?;
    let (x, y, z) = (t.f64("x", COLS)?, t.f64("y", COLS)?, t.f64("z", COLS)?);
    m.coords = (0..x.len()).map(|i| [x[i], y[i], z[i]]).collect();
    // Initial displacement ux0, uy0, uz0 (a formed state): all three or none, null → 0.
    let u0: Vec<_> = ["ux0", "uy0", "uz0"]
        .iter()
        .map(|c| t.f64_opt(c))
        .collect::<Result<Vec<_>>>()?;
    let present = u0.iter().filter(|c| c.is_some()).count();
    if present == 3 {
        let u: Vec<Vec<Option<f64>>> = u0.into_iter().flatten().collect();
        m.initial_displacement = (0..x.len())
            .map(|i| std::array::from_fn(|d| u[d][i].unwrap_or(0.0)))
            .collect();
    } else if present > 0 {
        return Err(WeftError::input(format!(
            "{present} of the initial displacement columns ux0, uy0, uz0 are present"
        ))
        .in_file(&t.path)
        .expected("all three or none"));
    }
    if m.node_id.is_empty() {
        return Err(WeftError::input("the model has no nodes")
            .in_file(&t.path)
            .expected("at least one node"));
    }
    // Duplicate node ids are checked here, where the file is known.
    let map = &mut r.node_index;
    for (row, id) in m.node_id.iter().enumerate() {
        if map.insert(*id, row).is_some() {
            return Err(t
                .value_error("node_id", row, format!("duplicate node id `{id}`"))
                .expected("unique node ids"));
        }
    }
    Ok(())
}

/// Writes the nodes, with the initial displacement columns when the model has one.
pub fn write(m: &Model, w: &Writing) -> Result<()> {
    let mut cols = vec![
        Col::I64("node_id", m.node_id.clone()),
        Col::F64("x", m.coords.iter().map(|c| c[0]).collect()),
        Col::F64("y", m.coords.iter().map(|c| c[1]).collect()),
        Col::F64("z", m.coords.iter().map(|c| c[2]).collect()),
    ];
    if !m.initial_displacement.is_empty() {
        for (d, c) in ["ux0", "uy0", "uz0"].into_iter().enumerate() {
            cols.push(Col::F64(
                c,
                m.initial_displacement.iter().map(|u| u[d]).collect(),
            ));
        }
    }
    w.table(FILE, &batch(cols))
}
