//! The `error` stage behind `weft-error`: the mismatch T (the paper's eq. 2) between a
//! candidate's and a reference's histories, written to `error.parquet` (per node) and
//! `error_summary.parquet`.

use std::path::PathBuf;

use serde::Serialize;

use super::{components, mismatch, read_series, Mismatch, Series};
use crate::error::Result;
use crate::table::{batch, write_table, Col, Provenance};

/// Settings of one comparison, as `weft-error`'s flags give them (and as its tables'
/// provenance records them).
#[derive(Debug, Clone, Serialize)]
pub struct Config {
    pub reference_model: PathBuf,
    pub reference_history: PathBuf,
    /// Candidate model folder (the reduced model).
    pub model: PathBuf,
    pub history: PathBuf,
    /// Node set compared (in both models).
    pub set: String,
    /// Node set of the candidate, when it differs.
    pub candidate_set: Option<String>,
    /// Components, comma-separated (ux, uy, uz, vx, vy, vz).
    pub components: String,
    /// Matching tolerance on node positions [m].
    pub tolerance: f64,
    /// Compare the last samples only (static solutions).
    pub static_mode: bool,
    /// Output folder for error.parquet and error_summary.parquet.
    pub out_dir: PathBuf,
}

/// What a comparison reports back to the binary.
#[derive(Debug, Clone)]
pub struct Report {
    pub mismatch: Mismatch,
    /// The reference's history over the set.
    pub reference: Series,
}

/// Run the stage.
pub fn run(c: &Config) -> Result<Report> {
    let comps = components(&c.components)?;
    let q = read_series(&c.reference_model, &c.reference_history, &c.set)
        .map_err(|e| e.context("reference"))?;
    let p = read_series(
        &c.model,
        &c.history,
        c.candidate_set.as_deref().unwrap_or(&c.set),
    )
    .map_err(|e| e.context("candidate"))?;
    let r = mismatch(&q, &p, &comps, c.tolerance, c.static_mode)?;
    let prov = Provenance::new("error", serde_json::to_value(c).expect("config serialises"))
        .with_input(&c.reference_history)?
        .with_input(&c.history)?;
    write_table(
        &c.out_dir.join("error.parquet"),
        &batch(vec![
            Col::I64("node_id", r.per_node.iter().map(|x| x.0).collect()),
            Col::F64("x", q.x0.iter().map(|x| x[0]).collect()),
            Col::F64("y", q.x0.iter().map(|x| x[1]).collect()),
            Col::F64("z", q.x0.iter().map(|x| x[2]).collect()),
            Col::I64(
                "candidate_node_id",
                r.per_node.iter().map(|x| x.1).collect(),
            ),
            Col::OptF64(
                "peak_relative_error",
                r.per_node
                    .iter()
                    .map(|x| x.2.is_finite().then_some(x.2))
                    .collect(),
            ),
        ]),
        &prov,
    )?;
    write_table(
        &c.out_dir.join("error_summary.parquet"),
        &batch(vec![
            Col::F64("T", vec![r.t_value]),
            Col::F64("max_peak_relative_error", vec![r.max_peak_relative_error]),
            Col::I64("nodes", vec![r.per_node.len() as i64]),
            Col::I64("samples", vec![r.samples as i64]),
            Col::Str("components", vec![c.components.clone()]),
            Col::Bool("static", vec![c.static_mode]),
        ]),
        &prov,
    )?;
    Ok(Report {
        mismatch: r,
        reference: q,
    })
}
