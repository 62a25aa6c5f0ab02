//! The `wavespeed` stage behind `weft-wavespeed`: arrival times and wave speeds along an
//! ordered node set, written to one table.

use std::path::PathBuf;

use serde::Serialize;

use super::{components, read_series, wave_speeds_with, Level, WaveSpeeds};
use crate::error::{Result, WeftError};
use crate::table::{batch, write_table, Col, Provenance};

/// Settings of one measurement, as `weft-wavespeed`'s flags give them (and as its
/// table's provenance records them).
#[derive(Debug, Clone, Serialize)]
pub struct Config {
    /// Model folder (for the node set and the node positions).
    pub model: PathBuf,
    /// history.parquet of a run of that model.
    pub history: PathBuf,
    /// Ordered node set along the line.
    pub set: String,
    /// Component: ux, uy, uz, vx, vy or vz.
    pub component: String,
    /// One level for all nodes: this fraction of the largest |value| on the line (unless
    /// one of the two below is given).
    pub line_level: f64,
    /// A fraction of each node's own peak |value| instead (a clean single pulse only).
    pub relative_level: Option<f64>,
    /// One absolute level [m or m/s] instead.
    pub level: Option<f64>,
    /// How far [s] an arrival may fall back outwards and still count as the incident
    /// front (0: not at all).
    pub slack: f64,
    /// Output table.
    pub out: PathBuf,
}

/// What a measurement reports back to the binary.
#[derive(Debug, Clone)]
pub struct Report {
    pub speeds: WaveSpeeds,
    /// Nodes the wave reaches.
    pub reached: usize,
}

/// Run the stage.
pub fn run(c: &Config) -> Result<Report> {
    let comp = components(&c.component)?;
    if comp.len() != 1 {
        return Err(WeftError::input(format!(
            "--component takes one component, got `{}`",
            c.component
        )));
    }
    let level = match (c.level, c.relative_level) {
        (Some(a), _) => Level::Absolute(a),
        (None, Some(f)) => Level::Relative(f),
        (None, None) => Level::Line(c.line_level),
    };
    for (name, v) in [
        ("--line-level", Some(c.line_level)),
        ("--relative-level", c.relative_level),
    ] {
        if let Some(v) = v {
            if !(v > 0.0 && v < 1.0) {
                return Err(WeftError::input(format!("{name} = `{v}`"))
                    .expected("a fraction of the peak, 0 < f < 1"));
            }
        }
    }
    if let Some(a) = c.level {
        if !(a.is_finite() && a > 0.0) {
            return Err(WeftError::input(format!("--level = `{a}`"))
                .expected("a level > 0 in the component's unit (m or m/s)"));
        }
    }
    if !(c.slack.is_finite() && c.slack >= 0.0) {
        return Err(WeftError::input(format!("--slack = `{}`", c.slack))
            .expected("a time ≥ 0 in s (e.g. one output interval)"));
    }
    let s = read_series(&c.model, &c.history, &c.set)
        .map_err(|e| e.context("cannot read the node set's history"))?;
    let w = wave_speeds_with(&s, comp[0], level, c.slack);
    let reached = w.arrival.iter().filter(|a| a.is_some()).count();
    let prov = Provenance::new(
        "wavespeed",
        serde_json::to_value(c).expect("config serialises"),
    )
    .with_input(&c.history)?;
    write_table(
        &c.out,
        &batch(vec![
            Col::I64("node_id", w.node_id.clone()),
            Col::I64("order", (0..w.node_id.len() as i64).collect()),
            Col::F64("position", w.position.clone()),
            Col::Bool("reached", w.arrival.iter().map(|a| a.is_some()).collect()),
            Col::OptF64("arrival_time", w.arrival.clone()),
            Col::OptF64("segment_speed", w.segment_speed.clone()),
            Col::OptF64("node_speed", w.node_speed.clone()),
        ]),
        &prov,
    )?;
    Ok(Report { speeds: w, reached })
}
