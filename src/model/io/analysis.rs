//! `analysis.parquet`: the analysis settings, one row; a null or absent optional setting
//! takes its default ([`Analysis::default`]).

use super::codec::{Reading, Writing};
use crate::error::{Result, WeftError};
use crate::model::types::{Analysis, Model};
use crate::table::{batch, Col};

pub const FILE: &str = "analysis.parquet";
/// Expected columns, for error messages.
const COLS: &str = "end_time, output_interval (+ optional settings)";

/// Reads the settings when the folder has them (the defaults otherwise).
pub fn read(r: &mut Reading) -> Result<()> {
    let Some(t) = r.optional(FILE)? else {
        return Ok(());
    };
    if t.num_rows() != 1 {
        return Err(
            WeftError::input(format!("analysis table has {} rows", t.num_rows()))
                .in_file(&t.path)
                .expected("exactly one row"),
        );
    }
    let d = Analysis::default();
    let get = |c: &str, dflt: Option<f64>| -> Result<Option<f64>> {
        Ok(t.f64_opt(c)?.and_then(|v| v[0]).or(dflt))
    };
    let sets = t
        .str_opt("history_sets")?
        .and_then(|v| v[0].clone())
        .unwrap_or_default();
    r.model.analysis = Analysis {
        end_time: t.f64("end_time", COLS)?[0],
        output_interval: t.f64("output_interval", COLS)?[0],
        dt_safety: get("dt_safety", Some(d.dt_safety))?.unwrap(),
        mass_damping: get("mass_damping", Some(d.mass_damping))?.unwrap(),
        time_step: get("time_step", None)?,
        target_time_step: get("target_time_step", None)?,
        history_sets: sets
            .split(',')
            .map(str::trim)
            .filter(|s| !s.is_empty())
            .map(String::from)
            .collect(),
        max_energy_error: get("max_energy_error", Some(d.max_energy_error))?.unwrap(),
        stop_on_outcome: t
            .bool_opt("stop_on_outcome")?
            .and_then(|v| v[0])
            .unwrap_or(d.stop_on_outcome),
        variable_time_step: t
            .bool_opt("variable_time_step")?
            .and_then(|v| v[0])
            .unwrap_or(d.variable_time_step),
        subcycle: t
            .bool_opt("subcycle")?
            .and_then(|v| v[0])
            .unwrap_or(d.subcycle),
    };
    Ok(())
}

/// Writes the settings, every one (`subcycle` only when on).
pub fn write(m: &Model, w: &Writing) -> Result<()> {
    let a = &m.analysis;
    let mut cols = vec![
        Col::F64("end_time", vec![a.end_time]),
        Col::F64("output_interval", vec![a.output_interval]),
        Col::F64("dt_safety", vec![a.dt_safety]),
        Col::F64("mass_damping", vec![a.mass_damping]),
        Col::OptF64("time_step", vec![a.time_step]),
        Col::OptF64("target_time_step", vec![a.target_time_step]),
        Col::Str("history_sets", vec![a.history_sets.join(",")]),
        Col::F64("max_energy_error", vec![a.max_energy_error]),
        Col::Bool("stop_on_outcome", vec![a.stop_on_outcome]),
        Col::Bool("variable_time_step", vec![a.variable_time_step]),
    ];
    // Written only when on: the tables of a model without it stay as they were.
    if a.subcycle {
        cols.push(Col::Bool("subcycle", vec![true]));
    }
    w.table(FILE, &batch(cols))
}
