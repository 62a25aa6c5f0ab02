//! `initial_velocities.parquet`: the velocity of a node at t = 0, one row per node.

use super::codec::{Reading, Writing};
use crate::error::Result;
use crate::model::types::Model;
use crate::table::{batch, Col};

pub const FILE: &str = "initial_velocities.parquet";
/// Expected columns, for error messages.
const COLS: &str = "node_id, vx, vy, vz";

/// Reads the initial velocities.
pub fn read(r: &mut Reading) -> Result<()> {
    let Some(t) = r.optional(FILE)? else {
        return Ok(());
    };
    let ids = t.i64("node_id", COLS)?;
    let idx = r.node_refs(&t, "node_id", &ids)?;
    let (vx, vy, vz) = (t.f64("vx", COLS)?, t.f64("vy", COLS)?, t.f64("vz", COLS)?);
    r.model.initial_velocities = (0..idx.len())
        .map(|i| (idx[i], [vx[i], vy[i], vz[i]]))
        .collect();
    Ok(())
}

/// Writes the initial velocities when the model has any.
pub fn write(m: &Model, w: &Writing) -> Result<()> {
    if m.initial_velocities.is_empty() {
        return Ok(());
    }
    let v = &m.initial_velocities;
    w.table(
        FILE,
        &batch(vec![
            Col::I64("node_id", v.iter().map(|x| m.node_id[x.0]).collect()),
            Col::F64("vx", v.iter().map(|x| x.1[0]).collect()),
            Col::F64("vy", v.iter().map(|x| x.1[1]).collect()),
            Col::F64("vz", v.iter().map(|x| x.1[2]).collect()),
        ]),
    )
}
