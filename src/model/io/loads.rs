//! `loads.parquet`: nodal forces F·g(t), each with its time law (a sine pulse, a step, a
//! ramp, or a tabulated curve of `curves.parquet`).

use std::collections::BTreeMap;
use std::sync::Arc;

use super::codec::{Reading, Writing};
use crate::error::Result;
use crate::model::types::{Curve, Load, Model, TimeLaw};
use crate::table::{batch, Col, Table};

pub const FILE: &str = "loads.parquet";
/// Expected columns, for error messages.
const COLS: &str = "load_id, node_id, fx, fy, fz, law, start (+ duration, curve)";

/// The columns of `loads.parquet` that make a load's time law.
struct LawColumns<'a> {
    load_id: &'a [i64],
    law: Vec<String>,
    start: Vec<f64>,
    duration: Vec<Option<f64>>,
    curve: Vec<Option<String>>,
}

impl LawColumns<'_> {
    /// The time law of a row: a duration > 0 for sine_pulse and ramp, a curve that
    /// `curves` defines for tabulated.
    fn law(&self, t: &Table, row: usize, curves: &BTreeMap<String, Arc<Curve>>) -> Result<TimeLaw> {
        let (lid, law, start, duration, curve) = (
            self.load_id,
            &self.law,
            &self.start,
            &self.duration,
            &self.curve,
        );
        let need_duration = || {
            duration[row].filter(|d| *d > 0.0).ok_or_else(|| {
                t.value_error(
                    "duration",
                    row,
                    format!(
                        "load `{}` ({}) has duration {:?}",
                        lid[row], law[row], duration[row]
                    ),
                )
                .expected("a duration > 0 s for sine_pulse and ramp")
            })
        };
        let l = match law[row].as_str() {
            "sine_pulse" => TimeLaw::SinePulse {
                start: start[row],
                duration: need_duration()?,
            },
            "ramp" => TimeLaw::Ramp {
                start: start[row],
                duration: need_duration()?,
            },
            "step" => TimeLaw::Step { start: start[row] },
            "tabulated" => {
                let name = curve[row].clone().unwrap_or_default();
                let c = curves.get(&name).cloned().ok_or_else(|| {
                    t.value_error(
                        "curve",
                        row,
                        format!(
                            "load `{}` names curve `{name}`, which curves.parquet does not define",
                            lid[row]
                        ),
                    )
                    .expected("the name of a curve in curves.parquet")
                })?;
                TimeLaw::Tabulated { name, curve: c }
            }
            other => {
                return Err(t
                    .value_error("law", row, format!("unknown time law `{other}`"))
                    .expected("one of `sine_pulse`, `step`, `ramp`, `tabulated`"))
            }
        };
        Ok(l)
    }
}

/// Reads the loads (after the curves, which tabulated laws name).
pub fn read(r: &mut Reading) -> Result<()> {
    let Some(t) = r.optional(FILE)? else {
        return Ok(());
    };
    let lid = t.i64("load_id", COLS)?;
    let ids = t.i64("node_id", COLS)?;
    let idx = r.node_refs(&t, "node_id", &ids)?;
    let (fx, fy, fz) = (t.f64("fx", COLS)?, t.f64("fy", COLS)?, t.f64("fz", COLS)?);
    let law = t.str("law", COLS)?;
    let start = t.f64("start", COLS)?;
    let duration = t
        .f64_opt("duration")?
        .unwrap_or_else(|| vec![None; lid.len()]);
    let curve = t.str_opt("curve")?.unwrap_or_else(|| vec![None; lid.len()]);
    let laws = LawColumns {
        load_id: &lid,
        law,
        start,
        duration,
        curve,
    };
    let m = &mut r.model;
    for row in 0..lid.len() {
        let l = laws.law(&t, row, &m.curves)?;
        m.loads.push(Load {
            id: lid[row],
            node: idx[row],
            force: [fx[row], fy[row], fz[row]],
            law: l,
        });
    }
    Ok(())
}

/// Writes the loads when the model has any: `start` 0 and `duration` null where a law
/// has none, `curve` null but for tabulated laws.
pub fn write(m: &Model, w: &Writing) -> Result<()> {
    if m.loads.is_empty() {
        return Ok(());
    }
    let l = &m.loads;
    let start = |law: &TimeLaw| match law {
        TimeLaw::SinePulse { start, .. }
        | TimeLaw::Ramp { start, .. }
        | TimeLaw::Step { start } => *start,
        TimeLaw::Tabulated { .. } => 0.0,
    };
    let duration = |law: &TimeLaw| match law {
        TimeLaw::SinePulse { duration, .. } | TimeLaw::Ramp { duration, .. } => Some(*duration),
        _ => None,
    };
    let curve = |law: &TimeLaw| match law {
        TimeLaw::Tabulated { name, .. } => Some(name.clone()),
        _ => None,
    };
    let cols = vec![
        Col::I64("load_id", l.iter().map(|x| x.id).collect()),
        Col::I64("node_id", l.iter().map(|x| m.node_id[x.node]).collect()),
        Col::F64("fx", l.iter().map(|x| x.force[0]).collect()),
        Col::F64("fy", l.iter().map(|x| x.force[1]).collect()),
        Col::F64("fz", l.iter().map(|x| x.force[2]).collect()),
        Col::Str("law", l.iter().map(|x| x.law.name().to_string()).collect()),
        Col::F64("start", l.iter().map(|x| start(&x.law)).collect()),
        Col::OptF64("duration", l.iter().map(|x| duration(&x.law)).collect()),
        Col::OptStr("curve", l.iter().map(|x| curve(&x.law)).collect()),
    ];
    w.table(FILE, &batch(cols))
}
