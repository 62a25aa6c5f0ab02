//! The `wavespeed` stage behind `weft-wavespeed`: arrival times and wave speeds along an
//! ordered node set, written to one table.

use std::path::PathBuf;

use serde::Serialize;

use super::{components, read_series, wave_speeds, Level, WaveSpeeds};
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
    /// Level as a fraction of each node's peak |value| (when `level` is `None`).
    pub relative_level: f64,
    /// Absolute level [m or m/s].
    pub level: Option<f64>,
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
    let level = match c.level {
        Some(a) => Level::Absolute(a),
        None => Level::Relative(c.relative_level),
    };
    let s = read_series(&c.model, &c.history, &c.set)
        .map_err(|e| e.context("cannot read the node set's history"))?;
    let w = wave_speeds(&s, comp[0], level);
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
