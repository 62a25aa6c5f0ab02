//! `symmetry.parquet`: symmetry planes, by their normal axis, position and tolerance.

use super::codec::{Reading, Writing};
use crate::error::Result;
use crate::model::types::{Model, SymmetryPlane};
use crate::table::{batch, Col};

pub const FILE: &str = "symmetry.parquet";
/// Expected columns, for error messages.
const COLS: &str = "normal (+ position, tolerance)";

/// Reads the planes; a null position is 0, a null tolerance 1e-9 m.
pub fn read(r: &mut Reading) -> Result<()> {
    let Some(t) = r.optional(FILE)? else {
        return Ok(());
    };
    let normal = t.str("normal", COLS)?;
    let n = normal.len();
    let pos = t.f64_opt("position")?.unwrap_or_else(|| vec![None; n]);
    let tol = t.f64_opt("tolerance")?.unwrap_or_else(|| vec![None; n]);
    for row in 0..n {
        let axis = ["x", "y", "z"]
            .iter()
            .position(|a| *a == normal[row])
            .ok_or_else(|| {
                t.value_error(
                    "normal",
                    row,
                    format!("unknown symmetry plane normal `{}`", normal[row]),
                )
                .expected("`x`, `y` or `z` (the plane x = position, ...)")
            })?;
        r.model.symmetry.push(SymmetryPlane {
            normal: axis,
            position: pos[row].unwrap_or(0.0),
            tolerance: tol[row].unwrap_or(1e-9),
        });
    }
    Ok(())
}

/// Writes the planes when the model has any.
pub fn write(m: &Model, w: &Writing) -> Result<()> {
    if m.symmetry.is_empty() {
        return Ok(());
    }
    let s = &m.symmetry;
    w.table(
        FILE,
        &batch(vec![
            Col::Str(
                "normal",
                s.iter()
                    .map(|x| ["x", "y", "z"][x.normal].to_string())
                    .collect(),
            ),
            Col::F64("position", s.iter().map(|x| x.position).collect()),
            Col::F64("tolerance", s.iter().map(|x| x.tolerance).collect()),
        ]),
    )
}
