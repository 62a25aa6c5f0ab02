//! `ties.parquet`: tied nodes, each with the 2 (an edge) to 4 (a face) master nodes it
//! follows.

use std::sync::Arc;

use super::codec::{append_columns, Reading, Writing};
use crate::error::Result;
use crate::model::types::{Model, Tie};
use crate::table::{batch, Col, Table};

pub const FILE: &str = "ties.parquet";
/// Expected columns, for error messages.
const COLS: &str = "slave, m1, m2 (+ m3, m4)";

/// Reads the ties: a slave and two masters on every row, a third and fourth master
/// where the nullable `m3`, `m4` give them.
pub fn read(r: &mut Reading) -> Result<()> {
    let Some(t) = r.optional(FILE)? else {
        return Ok(());
    };
    let sl = t.i64("slave", COLS)?;
    let n = sl.len();
    let sl = r.node_refs(&t, "slave", &sl)?;
    let m1 = t.i64("m1", COLS)?;
    let m1 = r.node_refs(&t, "m1", &m1)?;
    let m2 = t.i64("m2", COLS)?;
    let m2 = r.node_refs(&t, "m2", &m2)?;
    let (m3, m4) = (
        optional_nodes(r, &t, "m3", n)?,
        optional_nodes(r, &t, "m4", n)?,
    );
    for row in 0..n {
        let mut masters = vec![m1[row], m2[row]];
        masters.extend(m3[row]);
        masters.extend(m4[row]);
        r.model.ties.push(Tie {
            slave: sl[row],
            masters,
        });
    }
    Ok(())
}

/// A nullable node column as node indices (all null when the table has no such column).
fn optional_nodes(r: &Reading, t: &Table, c: &str, n: usize) -> Result<Vec<Option<usize>>> {
    let Some(a) = t.batch.column_by_name(c) else {
        return Ok(vec![None; n]);
    };
    let a = arrow_cast::cast(a, &arrow_schema::DataType::Int64)
        .map_err(|e| t.value_error(c, 0, format!("cannot read column `{c}` as integers: {e}")))?;
    let a = a
        .as_any()
        .downcast_ref::<arrow_array::Int64Array>()
        .expect("int64");
    (0..n)
        .map(|row| {
            if arrow_array::Array::is_null(a, row) {
                Ok(None)
            } else {
                let id = a.value(row);
                r.node_index.get(&id).copied().map(Some).ok_or_else(|| {
                    t.value_error(
                        c,
                        row,
                        format!("node id `{id}` does not exist in nodes.parquet"),
                    )
                    .expected("the id of a node in nodes.parquet, or null")
                })
            }
        })
        .collect()
}

/// Writes the ties when the model has any; `m3`, `m4` null where a tie has fewer masters.
pub fn write(m: &Model, w: &Writing) -> Result<()> {
    if m.ties.is_empty() {
        return Ok(());
    }
    let ti = &m.ties;
    let mid = |k: usize| {
        ti.iter()
            .map(|x| x.masters.get(k).map(|&i| m.node_id[i]))
            .collect::<Vec<_>>()
    };
    let opt = |name: &'static str, v: Vec<Option<i64>>| {
        (
            arrow_schema::Field::new(name, arrow_schema::DataType::Int64, true),
            Arc::new(arrow_array::Int64Array::from(v)) as arrow_array::ArrayRef,
        )
    };
    let b = batch(vec![
        Col::I64("slave", ti.iter().map(|x| m.node_id[x.slave]).collect()),
        Col::I64(
            "m1",
            mid(0).into_iter().map(|v| v.unwrap_or_default()).collect(),
        ),
        Col::I64(
            "m2",
            mid(1).into_iter().map(|v| v.unwrap_or_default()).collect(),
        ),
    ]);
    let b = append_columns(b, vec![opt("m3", mid(2)), opt("m4", mid(3))]);
    w.table(FILE, &b)
}
