//! `weft-error`: the mismatch T (the paper's eq. 2) between a candidate and a reference.

use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::Context;
use clap::Parser;
use weft::analysis::{components, mismatch, read_series};
use weft::table::{batch, write_table, Col, Provenance};

#[derive(Parser, serde::Serialize)]
#[command(
    name = "weft-error",
    version,
    about = "Displacement mismatch T between two models' histories (the paper's eq. 2) and per-node errors",
    long_about = "T = ∫Σ‖p − q‖² dt / ∫Σ(‖p‖² + ‖q‖²) dt over the reference node set, with p the candidate (reduced \
                  model) and q the reference, for the chosen components; trapezoidal in time on the reference's grid \
                  (the candidate is resampled linearly). 0 is a perfect match, 1 uncorrelated, 2 opposite. --static \
                  compares the last samples without the integral. Nodes are matched by position (nearest within \
                  --tolerance); an unmatched node is an error. Writes error.parquet (per node: the peak relative \
                  error peak‖p − q‖/peak‖q‖) and error_summary.parquet (T, the maximum node error).\n\nExample:\n  \
                  weft-error --reference-model g --reference-history go/history.parquet --model m --history mo/history.parquet \
                  --set reference --components ux,uy --out-dir runs/err"
)]
struct Cli {
    #[arg(long)]
    reference_model: PathBuf,
    #[arg(long)]
    reference_history: PathBuf,
    /// Candidate model folder (the reduced model).
    #[arg(long)]
    model: PathBuf,
    #[arg(long)]
    history: PathBuf,
    /// Node set compared (in both models).
    #[arg(long, default_value = "reference")]
    set: String,
    /// Node set of the candidate, when it differs.
    #[arg(long)]
    candidate_set: Option<String>,
    /// Components, comma-separated (ux, uy, uz, vx, vy, vz).
    #[arg(long, default_value = "ux,uy,uz")]
    components: String,
    /// Matching tolerance on node positions [m].
    #[arg(long, default_value_t = 1e-9)]
    tolerance: f64,
    /// Compare the last samples only (static solutions).
    #[arg(long = "static")]
    static_mode: bool,
    /// Output folder for error.parquet and error_summary.parquet.
    #[arg(long)]
    out_dir: PathBuf,
}

fn main() -> ExitCode {
    match run() {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e:#}");
            ExitCode::FAILURE
        }
    }
}

fn run() -> anyhow::Result<()> {
    let cli = Cli::parse();
    let comps = components(&cli.components)?;
    let q =
        read_series(&cli.reference_model, &cli.reference_history, &cli.set).context("reference")?;
    let p = read_series(
        &cli.model,
        &cli.history,
        cli.candidate_set.as_deref().unwrap_or(&cli.set),
    )
    .context("candidate")?;
    let r = mismatch(&q, &p, &comps, cli.tolerance, cli.static_mode)?;
    let prov = Provenance::new("error", serde_json::to_value(&cli)?)
        .with_input(&cli.reference_history)?
        .with_input(&cli.history)?;
    write_table(
        &cli.out_dir.join("error.parquet"),
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
        &cli.out_dir.join("error_summary.parquet"),
        &batch(vec![
            Col::F64("T", vec![r.t_value]),
            Col::F64("max_peak_relative_error", vec![r.max_peak_relative_error]),
            Col::I64("nodes", vec![r.per_node.len() as i64]),
            Col::I64("samples", vec![r.samples as i64]),
            Col::Str("components", vec![cli.components.clone()]),
            Col::Bool("static", vec![cli.static_mode]),
        ]),
        &prov,
    )?;
    eprintln!(
        "weft-error: T = {:.6e} over {} nodes and {} samples; max peak relative error {:.3e}",
        r.t_value,
        r.per_node.len(),
        r.samples,
        r.max_peak_relative_error
    );
    Ok(())
}
