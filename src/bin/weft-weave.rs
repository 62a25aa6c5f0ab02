//! `weft-weave`: generate canonical models as folders of Parquet tables.

use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::Context;
use clap::{Parser, Subcommand};

use weft::generate::rod::{build, RodParams};
use weft::model::io::write_model;
use weft::table::Provenance;

#[derive(Parser)]
#[command(
    name = "weft-weave",
    version,
    about = "Generate a model (a folder of Parquet tables, see docs/tables.md) ready for weft-simulate",
    long_about = "Generate a model (a folder of Parquet tables, see docs/tables.md) ready for weft-simulate.\n\n\
                  Every value is in SI units. Example:\n  weft-weave rod --out runs/rod && weft-simulate --model runs/rod --out runs/rod-out"
)]
struct Cli {
    #[command(subcommand)]
    model: Model,
}

#[derive(Subcommand)]
enum Model {
    /// A straight chain of trusses along x, fixed at x = 0, with an axial force pulse
    /// F0·sin(πt/T_F) on [0, T_F] at the free end x = L (transverse directions fixed).
    Rod(RodArgs),
}

#[derive(clap::Args)]
struct RodArgs {
    /// Output model folder (replaced atomically if it exists).
    #[arg(long)]
    out: PathBuf,
    /// Rod length L [m].
    #[arg(long, default_value_t = 0.1)]
    length: f64,
    /// Number of truss elements.
    #[arg(long, default_value_t = 200)]
    elements: usize,
    /// Young's modulus E [Pa] (default: steel, as in the paper's §4).
    #[arg(long, default_value_t = 1.5e11)]
    youngs_modulus: f64,
    /// Density ρ [kg/m³].
    #[arg(long, default_value_t = 7800.0)]
    density: f64,
    /// Cross-section width [m].
    #[arg(long, default_value_t = 1e-3)]
    width: f64,
    /// Cross-section thickness [m].
    #[arg(long, default_value_t = 1e-3)]
    thickness: f64,
    /// Pulse amplitude F0 [N] (positive pulls along +x).
    #[arg(long, default_value_t = 100.0)]
    force: f64,
    /// Pulse duration T_F [s] [default: 0.5·L·√(ρ/E)].
    #[arg(long)]
    pulse_duration: Option<f64>,
    /// Simulated time [s] [default: 2·L/c, c = √(E/ρ)].
    #[arg(long)]
    end_time: Option<f64>,
    /// Output interval [s] [default: end time / 400].
    #[arg(long)]
    output_interval: Option<f64>,
    /// Trusses carry no compression.
    #[arg(long)]
    tension_only: bool,
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
    match cli.model {
        Model::Rod(a) => {
            let p = RodParams {
                length: a.length,
                elements: a.elements,
                youngs_modulus: a.youngs_modulus,
                density: a.density,
                width: a.width,
                thickness: a.thickness,
                force: a.force,
                pulse_duration: a.pulse_duration,
                end_time: a.end_time,
                output_interval: a.output_interval,
                tension_only: a.tension_only,
            };
            let m = build(&p).context("cannot build the rod model")?;
            let prov = Provenance::new("weave rod", serde_json::to_value(&p)?);
            write_model(&m, &a.out, &prov)
                .with_context(|| format!("cannot write model `{}`", a.out.display()))?;
            eprintln!(
                "weft-weave rod: {} nodes, {} trusses, c = {:.1} m/s, T_F = {:.3e} s -> {}",
                m.num_nodes(),
                m.num_elements(),
                p.wave_speed(),
                p.pulse(),
                a.out.display()
            );
        }
    }
    Ok(())
}
