//! `node_sets.parquet`: named, ordered node sets, one row per member.

use std::collections::BTreeMap;

use super::codec::{Reading, Writing};
use crate::error::Result;
use crate::model::types::Model;
use crate::table::{batch, Col};

pub const FILE: &str = "node_sets.parquet";
/// Expected columns, for error messages.
const COLS: &str = "set, node_id, order";

/// Reads the sets, each member in the order of its `order` column.
pub fn read(r: &mut Reading) -> Result<()> {
    let Some(t) = r.optional(FILE)? else {
        return Ok(());
    };
    let names = t.str("set", COLS)?;
    let ids = t.i64("node_id", COLS)?;
    let order = t.i64("order", COLS)?;
    let idx = r.node_refs(&t, "node_id", &ids)?;
    let mut sets: BTreeMap<String, Vec<(i64, usize)>> = BTreeMap::new();
    for row in 0..names.len() {
        sets.entry(names[row].clone())
            .or_default()
            .push((order[row], idx[row]));
    }
    for (name, mut v) in sets {
        v.sort_by_key(|p| p.0);
        r.model
            .node_sets
            .insert(name, v.into_iter().map(|p| p.1).collect());
    }
    Ok(())
}

/// Writes the sets when the model has any.
pub fn write(m: &Model, w: &Writing) -> Result<()> {
    if m.node_sets.is_empty() {
        return Ok(());
    }
    let (mut s, mut n, mut o) = (vec![], vec![], vec![]);
    for (name, set) in &m.node_sets {
        for (k, &i) in set.iter().enumerate() {
            s.push(name.clone());
            n.push(m.node_id[i]);
            o.push(k as i64);
        }
    }
    w.table(
        FILE,
        &batch(vec![
            Col::Str("set", s),
            Col::I64("node_id", n),
            Col::I64("order", o),
        ]),
    )
}
