//! `weft-wavespeed`: arrival times and wave speeds along an ordered line of nodes.

use std::path::PathBuf;
use std::process::ExitCode;

use clap::Parser;
use weft::analysis::wavespeed;

#[derive(Parser)]
#[command(
    name = "weft-wavespeed",
    version,
    about = "Wave arrival times and speeds along an ordered node set (the paper's §3)",
    long_about = "For each node of an ordered node set (e.g. `axis_x`), the first time the chosen component reaches a \
                  level, linearly interpolated between output samples: by default one level for all nodes, \
                  --line-level (0.2) of the largest |value| on the line; or an absolute --level; or a fraction of each \
                  node's own peak (--relative-level, for a clean single pulse only). The incident front only: from \
                  the node reached first, arrival times must not decrease outwards along the line; the first node \
                  where one does, and every node beyond, count as not reached (a later crossing is a reflection). \
                  Then the speed of each segment Δx/Δt, and each node's speed over its two segments together, (x₊ − x₋)/(t₊ − t₋) (an offset that alternates from node to node, as on a crimped yarn's crossings, cancels). Speeds \
                  are signed: positive when the wave runs in the set's order. Nodes the incident front does not \
                  reach are kept, with null times and speeds.\n\nExample:\n  weft-wavespeed --model runs/rod --history runs/rod-out/history.parquet \
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
    /// One level for all nodes: this fraction of the largest |value| anywhere on the
    /// line (the paper's pre-selected level).
    #[arg(long, default_value_t = 0.2)]
    line_level: f64,
    /// Instead, a fraction of each node's own peak |value| (a clean single pulse only:
    /// near a clamp the reflection, or the first ripple, reaches it).
    #[arg(long, conflicts_with = "level")]
    relative_level: Option<f64>,
    /// Instead, one absolute level [m or m/s] for all nodes.
    #[arg(long)]
    level: Option<f64>,
    /// How far [s] an arrival may fall back outwards and still count as the incident
    /// front: a node reached a little early (e.g. a tied interface node on a flat
    /// membrane beside a crimped crossing) then no longer cuts the line there; a segment
    /// that does not advance gets no speed. Default 0: any fall-back ends the front.
    #[arg(long, default_value_t = 0.0)]
    slack: f64,
    /// Output table.
    #[arg(long)]
    out: PathBuf,
}

fn main() -> ExitCode {
    weft::cli::main(run)
}

fn run() -> anyhow::Result<ExitCode> {
    let cli: Cli = weft::cli::parse();
    let r = wavespeed::run(&wavespeed::Config {
        model: cli.model,
        history: cli.history,
        set: cli.set,
        component: cli.component,
        line_level: cli.line_level,
        relative_level: cli.relative_level,
        level: cli.level,
        slack: cli.slack,
        out: cli.out.clone(),
    })?;
    let n = r.speeds.node_id.len();
    eprintln!(
        "weft-wavespeed: {n} nodes, {} reached, {} never -> {}",
        r.reached,
        n - r.reached,
        cli.out.display()
    );
    Ok(ExitCode::SUCCESS)
}
