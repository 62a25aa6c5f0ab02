//! `weft-wavespeed`: arrival times and wave speeds along an ordered line of nodes.

use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::Context;
use clap::Parser;
use weft::analysis::{components, read_series, wave_speeds, Level};
use weft::table::{batch, write_table, Col, Provenance};

#[derive(Parser, serde::Serialize)]
#[command(
    name = "weft-wavespeed",
    version,
    about = "Wave arrival times and speeds along an ordered node set (the paper's §3)",
    long_about = "For each node of an ordered node set (e.g. `axis_x`), the first time the chosen component reaches a \
                  level (absolute, or a fraction of that node's peak), linearly interpolated between output samples; \
                  the speed of each segment Δx/Δt, and each node's speed as the mean of its two segments. Speeds are \
                  signed: positive when the wave runs in the set's order. Nodes the wave never reaches are kept, with \
                  null times and speeds.\n\nExample:\n  weft-wavespeed --model runs/rod --history runs/rod-out/history.parquet \
                  --set axis_x --component vx --relative-level 0.5 --out runs/rod-out/wavespeeds.parquet"
)]
struct Cli {
    /// Model folder (for the node set and the node positions).
    #[arg(long)]
    model: PathBuf,
    /// history.parquet of a run of that model.
    #[arg(long)]
    history: PathBuf,
    /// Ordered node set along the line.
    #[arg(long, default_value = "axis_x")]
    set: String,
    /// Component: ux, uy, uz, vx, vy or vz.
    #[arg(long, default_value = "uz")]
    component: String,
    /// Level as a fraction of each node's peak |value|.
    #[arg(long, conflicts_with = "level", default_value_t = 0.5)]
    relative_level: f64,
    /// Absolute level [m or m/s] instead of a fraction of the peak.
    #[arg(long)]
    level: Option<f64>,
    /// Output table.
    #[arg(long)]
    out: PathBuf,
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
    let comp = components(&cli.component)?;
    anyhow::ensure!(
        comp.len() == 1,
        "--component takes one component, got `{}`",
        cli.component
    );
    let level = match cli.level {
        Some(a) => Level::Absolute(a),
        None => Level::Relative(cli.relative_level),
    };
    let s = read_series(&cli.model, &cli.history, &cli.set)
        .context("cannot read the node set's history")?;
    let w = wave_speeds(&s, comp[0], level);
    let reached = w.arrival.iter().filter(|a| a.is_some()).count();
    let prov =
        Provenance::new("wavespeed", serde_json::to_value(&cli)?).with_input(&cli.history)?;
    write_table(
        &cli.out,
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
    eprintln!(
        "weft-wavespeed: {} nodes, {reached} reached, {} never -> {}",
        w.node_id.len(),
        w.node_id.len() - reached,
        cli.out.display()
    );
    Ok(())
}
