//! `weft-energy`: energy per region over time and the reflection fraction of a pulse at
//! an interface (`measure`), and the pulse itself (`pulse`). The analysis is
//! [`weft::analysis::energy`]'s; this parses the flags and prints the summary.

use std::path::PathBuf;
use std::process::ExitCode;

use clap::{Args, Parser, Subcommand};
use weft::analysis::{energy, pulse};

#[derive(Parser)]
#[command(
    name = "weft-energy",
    version,
    about = "Energy per region over time, and the reflection fraction of a pulse at an interface",
    long_about = "Where a pulse's energy goes: `pulse` writes a copy of a model with an in-plane pulse (an initial \
                  velocity on a strip of nodes) instead of its projectile; `measure` reads a run of a model \
                  (weft-simulate --all-nodes) and writes the kinetic and elastic energy of each region (parts, \
                  groups of parts, node sets) at every output time, and, given the region the pulse starts in, the \
                  fraction of its energy still there after the pulse has passed the interface: the reflection \
                  fraction R (≈ 0 for a well-matched interface; ((Z₁ − Z₂)/(Z₁ + Z₂))² between two bars of \
                  impedances Z = A√(Eρ)).\n\nExample:\n  \
                  weft-energy pulse --model runs/combined --part warp_1 --axis x --from 0 --to 2e-3 \\\n    \
                  --velocity 5 --out runs/pulse\n  \
                  weft-simulate --all-nodes --model runs/pulse --out runs/pulse-out\n  \
                  weft-energy measure --model runs/pulse --history runs/pulse-out/history.parquet \\\n    \
                  --region patch=warp_1,weft_1 --region coarse_membrane --source patch \\\n    \
                  --launch 0 --window-start 1.8e-6 --window-end 2.2e-6 --out-dir runs/pulse-energy"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Energy per region over time (region_energy.parquet) and, with --source, the
    /// reflection fraction (reflection.parquet).
    #[command(
        long_about = "Kinetic and elastic energy of each region at every output time of a history that holds every \
        node (weft-simulate --all-nodes), into OUT_DIR/region_energy.parquet. Kinetic: ½ m v² of each node with \
        the region's share of its lumped mass (the solver's lumping, before ties move a tied node's mass to its \
        masters), so that a node two parts share is counted once overall. Elastic: the elements' stored energy \
        as elements.parquet has it (a node set takes the fraction of each element's nodes it holds). With \
        --source, R = E_left / E_launch into OUT_DIR/reflection.parquet: E_launch the source's total at --launch \
        (default: where it is largest), E_left its mean over the samples in [--window-start, --window-end] \
        (default: the single sample after the launch where it is smallest). Choose the window after the pulse \
        has passed the interface and before anything returns from the model's outer boundary (or the reflected \
        part comes back to the interface).\n\nExample:\n  \
        weft-energy measure --model runs/bar --history runs/bar-out/history.parquet \\\n    \
        --region bar1 --region bar2 \\\n    \
        --source bar1 --window-start 4e-5 --window-end 6e-5 --out-dir runs/bar-energy"
    )]
    Measure(MeasureArgs),
    /// Write a copy of a model with a pulse on a strip of nodes instead of its projectile.
    #[command(
        long_about = "Write a copy of a model folder whose projectiles are removed and whose nodes of --part lying in \
        the strip --from ≤ x ≤ --to along --axis start with the velocity --velocity · sin²(π (x − from)/(to − from)) \
        along that axis: a smooth in-plane (longitudinal) pulse. Nodes held in that direction (constraints, a \
        symmetry plane) and tied nodes get none. A strip that starts on a symmetry plane sends the whole pulse \
        outwards (the half that runs towards the plane comes back from it).\n\nExample:\n  \
        weft-energy pulse --model runs/combined --part warp_1 --axis x --from 0 --to 2e-3 \\\n    \
        --velocity 5 --out runs/pulse"
    )]
    Pulse(PulseArgs),
}

#[derive(Args)]
struct MeasureArgs {
    /// Model folder.
    #[arg(long)]
    model: PathBuf,
    /// history.parquet of a run of that model with every node (weft-simulate --all-nodes).
    #[arg(long)]
    history: PathBuf,
    /// A region (repeat): NAME=PART[,PART…] (a group of parts), set:SET (a node set),
    /// NAME=box:XMIN,XMAX,YMIN,YMAX,ZMIN,ZMAX (the nodes in a box of reference
    /// coordinates [m], as a node set; inf allowed) or PART. Default: one region per part.
    #[arg(long)]
    region: Vec<String>,
    /// The region the pulse starts in: measure its reflection fraction.
    #[arg(long)]
    source: Option<String>,
    /// Time [s] at which the source's energy is the launched one (default: where the
    /// source's total energy is largest).
    #[arg(long)]
    launch: Option<f64>,
    /// Start [s] of the window over which the energy left in the source is averaged
    /// (with --window-end; default: the sample after the launch where it is smallest).
    #[arg(long)]
    window_start: Option<f64>,
    /// End [s] of that window.
    #[arg(long)]
    window_end: Option<f64>,
    /// Output folder.
    #[arg(long)]
    out_dir: PathBuf,
}

#[derive(Args)]
struct PulseArgs {
    /// Model folder.
    #[arg(long)]
    model: PathBuf,
    /// Part whose nodes carry the pulse (repeat, or comma-separated).
    #[arg(long, required = true, value_delimiter = ',')]
    part: Vec<String>,
    /// Axis along which the strip lies and the nodes move: x, y or z.
    #[arg(long, default_value = "x")]
    axis: String,
    /// Start of the strip along the axis [m].
    #[arg(long)]
    from: f64,
    /// End of the strip along the axis [m].
    #[arg(long)]
    to: f64,
    /// Peak velocity [m/s] (at the middle of the strip).
    #[arg(long)]
    velocity: f64,
    /// Only the nodes in this box of reference coordinates: XMIN,XMAX,YMIN,YMAX,ZMIN,ZMAX
    /// [m] (inf allowed), e.g. the yarns of a reference's inner patch only.
    #[arg(long)]
    within: Option<String>,
    /// Start the pulse from the model's reference geometry, its formed state (initial
    /// displacements and stresses, `weft-form`) dropped. A formed model is refused
    /// without it: the energy of a region of a pre-stressed model holds the pre-stress's
    /// first-order work, as large as a small pulse's energy, which `measure` cannot tell
    /// apart from the pulse's.
    #[arg(long)]
    unformed: bool,
    /// Output model folder.
    #[arg(long)]
    out: PathBuf,
}

fn main() -> ExitCode {
    weft::cli::main(run)
}

fn run() -> anyhow::Result<ExitCode> {
    let cli: Cli = weft::cli::parse();
    match cli.command {
        Command::Measure(a) => {
            let r = energy::run(&energy::Config {
                model: a.model,
                history: a.history,
                regions: a.region,
                source: a.source,
                launch: a.launch,
                window_start: a.window_start,
                window_end: a.window_end,
                out_dir: a.out_dir.clone(),
            })?;
            eprintln!(
                "weft-energy: {} regions × {} output times -> {}",
                r.energies.names.len(),
                r.energies.t.len(),
                a.out_dir.join("region_energy.parquet").display()
            );
            if let Some(f) = r.reflection {
                eprintln!(
                    "weft-energy: `{}`: launched {:.4e} J at {:.3e} s, left {:.4e} J over {:.3e}–{:.3e} s: R = {:.4}",
                    f.source,
                    f.energy_launched,
                    f.launch_time,
                    f.energy_left,
                    f.window_start,
                    f.window_end,
                    f.reflection
                );
            }
        }
        Command::Pulse(a) => {
            let n = pulse::run_pulse(&pulse::PulseConfig {
                model: a.model,
                parts: a.part,
                axis: a.axis,
                from: a.from,
                to: a.to,
                velocity: a.velocity,
                within: a.within,
                unformed: a.unformed,
                out: a.out.clone(),
            })?;
            eprintln!(
                "weft-energy: a pulse on {n} nodes, projectiles removed -> {}",
                a.out.display()
            );
        }
    }
    Ok(ExitCode::SUCCESS)
}
