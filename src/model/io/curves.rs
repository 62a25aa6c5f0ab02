//! `curves.parquet`: tabulated curves g(t) by name, one row per point, times strictly
//! increasing within a curve.

use std::collections::BTreeMap;
use std::sync::Arc;

use super::codec::{Reading, Writing};
use crate::error::Result;
use crate::model::types::{Curve, Model};
use crate::table::{batch, Col};

pub const FILE: &str = "curves.parquet";
/// Expected columns, for error messages.
const COLS: &str = "curve, t, value";

/// Reads the curves (before the loads, which name them).
pub fn read(r: &mut Reading) -> Result<()> {
    let Some(t) = r.optional(FILE)? else {
        return Ok(());
    };
    let names = t.str("curve", COLS)?;
    let ts = t.f64("t", COLS)?;
    let vs = t.f64("value", COLS)?;
    let mut curves: BTreeMap<String, Curve> = BTreeMap::new();
    for row in 0..names.len() {
        let c = curves.entry(names[row].clone()).or_insert(Curve {
            t: vec![],
            value: vec![],
        });
        if let Some(&last) = c.t.last() {
            if ts[row] <= last {
                return Err(t
                    .value_error(
                        "t",
                        row,
                        format!(
                            "curve `{}` time `{}` does not increase (previous {last})",
                            names[row], ts[row]
                        ),
                    )
                    .expected("strictly increasing times within a curve"));
            }
        }
        c.t.push(ts[row]);
        c.value.push(vs[row]);
    }
    r.model.curves = curves.into_iter().map(|(k, v)| (k, Arc::new(v))).collect();
    Ok(())
}

/// Writes the curves when the model has any.
pub fn write(m: &Model, w: &Writing) -> Result<()> {
    if m.curves.is_empty() {
        return Ok(());
    }
    let (mut n, mut t, mut v) = (vec![], vec![], vec![]);
    for (name, c) in &m.curves {
        for k in 0..c.t.len() {
            n.push(name.clone());
            t.push(c.t[k]);
            v.push(c.value[k]);
        }
    }
    w.table(
        FILE,
        &batch(vec![
            Col::Str("curve", n),
            Col::F64("t", t),
            Col::F64("value", v),
        ]),
    )
}
