//! The `error` stage behind `weft-error`: the mismatch T (the paper's eq. 2) between a
//! candidate's and a reference's histories, written to `error.parquet` (per node) and
//! `error_summary.parquet`.

use std::path::PathBuf;

use serde::Serialize;

use super::{
    components, interpolation, mismatch_paired, pair, read_nodes_of, read_series_of, Matching,
    Mismatch, Series,
};
use crate::error::Result;
use crate::model::io::read_model;
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
    /// How reference nodes find their candidate values (position, id, interpolate).
    pub matching: Matching,
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
    let q = read_series_of(&c.reference_model, &c.reference_history, &c.set, &comps)
        .map_err(|e| e.context("reference"))?;
    let (p, pairs) = candidate(c, &q, &comps).map_err(|e| e.context("candidate"))?;
    let r = mismatch_paired(&q, &p, &pairs, &comps, c.static_mode)?;
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

/// The candidate's history over the nodes the comparison needs, and the pairing of the
/// reference's nodes onto it.
fn candidate(c: &Config, q: &Series, comps: &[usize]) -> Result<(Series, super::Pairing)> {
    if c.matching != Matching::Interpolate {
        let p = read_series_of(
            &c.model,
            &c.history,
            c.candidate_set.as_deref().unwrap_or(&c.set),
            comps,
        )?;
        let pairs = pair(q, &p, c.tolerance, c.matching)?;
        return Ok((p, pairs));
    }
    let m = read_model(&c.model)?;
    let restrict = match &c.candidate_set {
        Some(s) => Some(m.node_sets.get(s).cloned().ok_or_else(|| {
            crate::error::WeftError::input(format!(
                "model `{}` has no node set `{s}`",
                c.model.display()
            ))
            .expected("the --candidate-set whose elements to interpolate in")
        })?),
        None => None,
    };
    let (nodes, pairs) = interpolation(&m, restrict.as_deref(), &q.x0, &q.node_id, c.tolerance)?;
    let p = read_nodes_of(
        &m,
        &c.history,
        &nodes,
        "of an element containing a reference node",
        comps,
    )?;
    Ok((p, pairs))
}
