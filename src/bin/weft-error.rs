//! `weft-error`: the mismatch T (the paper's eq. 2) between a candidate and a reference.

use std::path::PathBuf;
use std::process::ExitCode;

use clap::Parser;
use weft::analysis::error;

#[derive(Parser)]
#[command(
    name = "weft-error",
    version,
    about = "Displacement mismatch T between two models' histories (the paper's eq. 2) and per-node errors",
    long_about = "T = ∫Σ‖p − q‖² dt / ∫Σ(‖p‖² + ‖q‖²) dt over the reference node set, with p the candidate (reduced \
                  model) and q the reference, for the chosen components; trapezoidal in time on the reference's grid \
                  (the candidate is resampled linearly). 0 is a perfect match, 1 uncorrelated, 2 opposite. --static \
                  compares the last samples without the integral. Nodes are matched by position (nearest within \
                  --tolerance; an unmatched node, or two candidate nodes within the tolerance, is an error), by id \
                  (--match id), or the candidate is interpolated at each reference node's position with the shape \
                  functions of the candidate element containing it (--match interpolate: meshes that differ). Only \
                  the compared components need be in the histories. Writes error.parquet (per node: the peak relative \
                  error peak‖p − q‖/peak‖q‖) and error_summary.parquet (T, the maximum node error).\n\nExample:\n  \
                  weft-error --reference-model g --reference-history go/history.parquet \\\n    \
                  --model m --history mo/history.parquet --set reference --components ux,uy --out-dir runs/err"
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
    /// How reference nodes find their candidate values: position (the node there), id
    /// (the node of the same id), interpolate (the candidate's shape functions at the
    /// reference position; meshes that differ).
    #[arg(long = "match", value_enum, default_value = "position")]
    matching: weft::analysis::Matching,
    /// Compare the last samples only (static solutions).
    #[arg(long = "static")]
    static_mode: bool,
    /// Output folder for error.parquet and error_summary.parquet.
    #[arg(long)]
    out_dir: PathBuf,
}

fn main() -> ExitCode {
    weft::cli::main(run)
}

fn run() -> anyhow::Result<ExitCode> {
    let cli: Cli = weft::cli::parse();
    let r = error::run(&error::Config {
        reference_model: cli.reference_model,
        reference_history: cli.reference_history,
        model: cli.model,
        history: cli.history,
        set: cli.set,
        candidate_set: cli.candidate_set,
        components: cli.components,
        tolerance: cli.tolerance,
        matching: cli.matching,
        static_mode: cli.static_mode,
        out_dir: cli.out_dir,
    })?;
    let m = &r.mismatch;
    eprintln!(
        "weft-error: T = {:.6e} over {} nodes and {} samples; max peak relative error {:.3e}",
        m.t_value,
        m.per_node.len(),
        m.samples,
        m.max_peak_relative_error
    );
    Ok(ExitCode::SUCCESS)
}
