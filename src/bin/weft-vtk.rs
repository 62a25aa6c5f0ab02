//! `weft-vtk`: a model folder and its run as a VTK XML time series for ParaView.

use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::Context;
use clap::Parser;
use weft::vtk;

#[derive(Parser)]
#[command(
    name = "weft-vtk",
    version,
    about = "Write a model and its run as a VTK time series (.pvd + one .vtu per output time) for ParaView",
    long_about = "Writes the model's mesh at every output time of its history.parquet as VTK XML \
                  UnstructuredGrid files (.vtu, binary) and a collection (weft.pvd) that ParaView opens as a time \
                  series: File > Open > OUT/weft.pvd, then Apply and play.\n\n\
                  Cells: one per element (truss, link, beam: line; tri: triangle; quad: quad; point mass: vertex); \
                  points at the current positions (--reference-points: the initial ones, for Warp By Vector). \
                  Point data: displacement, velocity, node_id, and the membranes' nodal thickness. Cell data: \
                  element_id, part_id, kind (0 truss, 1 link, 2 point mass, 3 tri, 4 quad, 5 beam) and, when the \
                  run wrote elements.parquet (weft-simulate --element-results), those results. The projectiles' \
                  surfaces go in weft_projectile_*.vtu (part 1 of the collection) when projectile.parquet is \
                  beside the history.\n\n\
                  The history must hold every node of the mesh: run weft-simulate with --all-nodes.\n\n\
                  Example:\n  weft-simulate --model runs/rod --out runs/rod-out --all-nodes\n  \
                  weft-vtk --model runs/rod --history runs/rod-out/history.parquet --out runs/rod-vtk\n  \
                  paraview runs/rod-vtk/weft.pvd"
)]
struct Cli {
    /// Model folder.
    #[arg(long)]
    model: PathBuf,
    /// The run's history.parquet (its folder's projectile.parquet and elements.parquet
    /// are used when present).
    #[arg(long)]
    history: PathBuf,
    /// Output folder (replaced as a whole when the series is complete).
    #[arg(long)]
    out: PathBuf,
    /// Write every k-th output sample.
    #[arg(long, default_value_t = 1)]
    every: usize,
    /// Points at the initial positions instead of the current ones (apply ParaView's
    /// Warp By Vector with `displacement` to see the motion).
    #[arg(long)]
    reference_points: bool,
}

fn main() -> ExitCode {
    weft::cli::main(run)
}

fn run() -> anyhow::Result<ExitCode> {
    let cli: Cli = weft::cli::parse();
    let r = vtk::run(&vtk::Config {
        model: cli.model.clone(),
        history: cli.history.clone(),
        out: cli.out.clone(),
        every: cli.every,
        reference_points: cli.reference_points,
    })
    .with_context(|| {
        format!(
            "weft-vtk `{}` failed; nothing was written to `{}`",
            cli.model.display(),
            cli.out.display()
        )
    })?;
    let types: Vec<String> = r
        .cell_types
        .iter()
        .map(|(t, n)| format!("{n} of VTK type {t}"))
        .collect();
    eprintln!(
        "weft-vtk: {} times ({:e} .. {:e} s), {} points, {} cells ({}){}{}",
        r.times.len(),
        r.times.first().copied().unwrap_or(0.0),
        r.times.last().copied().unwrap_or(0.0),
        r.points,
        r.cells,
        types.join(", "),
        if r.projectiles > 0 {
            format!(", {} projectile surfaces", r.projectiles)
        } else {
            String::new()
        },
        if r.element_results.is_empty() {
            String::new()
        } else {
            format!(", cell data {}", r.element_results.join(", "))
        }
    );
    eprintln!("  open {}/weft.pvd in ParaView", cli.out.display());
    Ok(ExitCode::SUCCESS)
}
