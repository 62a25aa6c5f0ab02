//! `weft-export`: a model folder as a CalculiX or LS-DYNA input deck.

use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::Context;
use clap::Parser;
use weft::export;

#[derive(Parser)]
#[command(
    name = "weft-export",
    version,
    about = "Write a model as a CalculiX (.inp) or LS-DYNA (.k) explicit-dynamics deck, to check weft against another code",
    long_about = "Writes the model folder as an input deck of another explicit code: nodes, elements, \
                  materials and sections, boundary conditions, loads with their time laws as curves, initial \
                  velocities, displacement output for the history nodes (the model's history sets, or all), \
                  and the end time. Units are SI throughout, as in weft.\n\n\
                  --format calculix: a ccx 2.20 deck for *DYNAMIC, EXPLICIT. Only what CalculiX's explicit \
                  scheme runs faithfully is written: trusses (as SPRINGA springs with lumped MASS elements; \
                  prestrained or tension-only trusses as nonlinear springs), links between nodes (one SPRING2 \
                  per axis), point masses, fixed translations, symmetry planes, loads, initial velocities, \
                  mass damping. \
                  Beams, membranes, link dashpots, friction sliders, projectiles, contacts, ties and formed \
                  models are refused with the reason (measured: B31 and M3D4 are expanded into C3D8I bricks, \
                  wrong in explicit; DASHPOTA is ignored in explicit). The deck's step is fixed and divides \
                  the output interval; run weft with the same --time-step to compare step for step \
                  (CalculiX's explicit scheme is not pure central difference: expect 1e-4..1e-3 of max|u|).\n\n\
                  --format lsdyna: an LS-DYNA keyword deck (checked for structure only: LS-DYNA is not run by \
                  weft's tests).\n\nExample:\n  weft-weave rod --out runs/rod\n  \
                  weft-export --model runs/rod --format calculix --out runs/rod.inp\n  \
                  ccx -i runs/rod        # writes runs/rod.dat with the displacements"
)]
struct Cli {
    /// Model folder.
    #[arg(long)]
    model: PathBuf,
    /// Deck format.
    #[arg(long, value_enum)]
    format: export::Format,
    /// The deck to write (.inp for CalculiX, .k for LS-DYNA).
    #[arg(long)]
    out: PathBuf,
    /// Time step [s] (default: weft's, lowered to divide the output interval).
    #[arg(long)]
    time_step: Option<f64>,
}

fn main() -> ExitCode {
    weft::cli::main(run)
}

fn run() -> anyhow::Result<ExitCode> {
    let cli: Cli = weft::cli::parse();
    let r = export::run(&export::Config {
        model: cli.model.clone(),
        out: cli.out.clone(),
        format: cli.format,
        time_step: cli.time_step,
    })
    .with_context(|| {
        format!(
            "weft-export `{}` failed; `{}` was not written",
            cli.model.display(),
            cli.out.display()
        )
    })?;
    let cards: Vec<String> = r.written.iter().map(|(w, n)| format!("{n} {w}")).collect();
    eprintln!(
        "weft-export: {} nodes; {}; step {:e} s ({} per output sample) to {:e} s; output of {} nodes -> {}",
        r.nodes,
        cards.join(", "),
        r.dt,
        r.increments_per_output,
        r.end_time,
        r.output_nodes,
        cli.out.display()
    );
    if cli.format == export::Format::Calculix {
        eprintln!("  compare with weft: weft-simulate --time-step {:e}", r.dt);
    }
    Ok(ExitCode::SUCCESS)
}
