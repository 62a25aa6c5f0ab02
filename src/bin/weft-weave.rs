//! `weft-weave`: generate canonical models as folders of Parquet tables.

use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::Context;
use clap::{Parser, Subcommand};

use weft::generate::rod::{build, RodParams};
use weft::generate::square::{girder, membrane, GirderParams, LoadCase, MembraneParams, Square};
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
    /// A square L × L grid of rods (the paper's §4 girder), N cells per side, clamped at
    /// x = 0 and loaded at x = L; rods as beams (rigid joints) or trusses (pinned joints).
    Girder(GirderArgs),
    /// The same square meshed with N × N membrane quads (the equivalent membrane),
    /// clamped at x = 0 and loaded at x = L. Defaults: the closed-form equivalent of the
    /// default girder (s = b²/a, ρ = ρ_g(2 − b/a), G = E(b/a)²/2 with b/a = 0.1).
    Membrane(MembraneArgs),
}

#[derive(clap::Args)]
struct SquareArgs {
    /// Output model folder (replaced atomically if it exists).
    #[arg(long)]
    out: PathBuf,
    /// Side length L [m].
    #[arg(long, default_value_t = 0.1)]
    length: f64,
    /// Cells per side N.
    #[arg(long, default_value_t = 10)]
    cells: usize,
    /// Load case: tension (+x on the edge x = L), shear (+y on x = L), transverse (+z at the centre).
    #[arg(long, value_enum, default_value_t = LoadCase::Tension)]
    load_case: LoadCase,
    /// Total force F [N] (the pulse amplitude; a static solve uses it as the load).
    #[arg(long, default_value_t = 100.0)]
    force: f64,
    /// Time scale T [s]: pulse duration T/2, default end time T [default: L·√(ρ/E) of this model's material].
    #[arg(long)]
    period: Option<f64>,
    /// Simulated time [s] [default: T].
    #[arg(long)]
    end_time: Option<f64>,
    /// Output interval [s] [default: end time / 100].
    #[arg(long)]
    output_interval: Option<f64>,
}

impl SquareArgs {
    fn square(&self) -> Square {
        Square {
            length: self.length,
            cells: self.cells,
            load_case: self.load_case,
            force: self.force,
            period: self.period,
            end_time: self.end_time,
            output_interval: self.output_interval,
        }
    }
}

#[derive(Clone, Copy, PartialEq, clap::ValueEnum)]
enum Joints {
    Rigid,
    Pinned,
}

#[derive(clap::Args)]
struct GirderArgs {
    #[command(flatten)]
    square: SquareArgs,
    /// Young's modulus E [Pa].
    #[arg(long, default_value_t = 1.5e11)]
    youngs_modulus: f64,
    /// Density ρ [kg/m³].
    #[arg(long, default_value_t = 7800.0)]
    density: f64,
    /// Rod width b, in the plane [m] [default: L/(10N); the paper's range is L/(20N) … L/(8N)].
    #[arg(long)]
    rod_width: Option<f64>,
    /// Rod thickness h, out of the plane [m] [default: b].
    #[arg(long)]
    rod_thickness: Option<f64>,
    /// Joints: rigid (beams, shear stiffness E·h·b³/(2a³)) or pinned (trusses, none).
    #[arg(long, value_enum, default_value_t = Joints::Rigid)]
    joints: Joints,
    /// Give the boundary rods the full section [default: half the height, as half a cell
    /// of the lattice, so that the girder matches its equivalent membrane of side L].
    #[arg(long)]
    full_edge_rods: bool,
}

#[derive(clap::Args)]
struct MembraneArgs {
    #[command(flatten)]
    square: SquareArgs,
    /// Young's modulus E = E₁ = E₂ [Pa].
    #[arg(long, default_value_t = 1.5e11)]
    youngs_modulus: f64,
    /// Poisson's ratio ν₁₂.
    #[arg(long, default_value_t = 0.0)]
    poisson_ratio: f64,
    /// Shear modulus G [Pa] [default: E(b/a)²/2 = 7.5e8 for b/a = 0.1].
    #[arg(long)]
    shear_modulus: Option<f64>,
    /// Thickness s [m] [default: b²/a with b = a/10].
    #[arg(long)]
    thickness: Option<f64>,
    /// Density ρ [kg/m³] [default: ρ_g(2 − b/a) = 14820].
    #[arg(long)]
    density: Option<f64>,
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
        Model::Girder(a) => {
            let p = GirderParams {
                square: a.square.square(),
                youngs_modulus: a.youngs_modulus,
                density: a.density,
                rod_width: a.rod_width,
                rod_thickness: a.rod_thickness,
                rigid: a.joints == Joints::Rigid,
                full_edge_rods: a.full_edge_rods,
            };
            let (m, warnings) = girder(&p).context("cannot build the girder")?;
            for w in warnings {
                eprintln!("warning: {w}");
            }
            let prov = Provenance::new("weave girder", serde_json::to_value(&p)?);
            write_model(&m, &a.square.out, &prov)
                .with_context(|| format!("cannot write model `{}`", a.square.out.display()))?;
            eprintln!(
                "weft-weave girder: {} nodes, {} {} rods, b = {:.3e} m, h = {:.3e} m -> {}",
                m.num_nodes(),
                m.num_elements(),
                if p.rigid { "beam" } else { "truss" },
                p.b(),
                p.h(),
                a.square.out.display()
            );
        }
        Model::Membrane(a) => {
            let d = MembraneParams::paper_default(a.square.square());
            let p = MembraneParams {
                youngs_modulus: a.youngs_modulus,
                poisson_ratio: a.poisson_ratio,
                shear_modulus: a.shear_modulus.unwrap_or(d.shear_modulus),
                thickness: a.thickness.unwrap_or(d.thickness),
                density: a.density.unwrap_or(d.density),
                ..d
            };
            let m = membrane(&p).context("cannot build the membrane")?;
            let prov = Provenance::new("weave membrane", serde_json::to_value(&p)?);
            write_model(&m, &a.square.out, &prov)
                .with_context(|| format!("cannot write model `{}`", a.square.out.display()))?;
            eprintln!(
                "weft-weave membrane: {} nodes, {} quads, s = {:.3e} m, ρ = {:.1} kg/m³, G = {:.3e} Pa -> {}",
                m.num_nodes(),
                m.num_elements(),
                p.thickness,
                p.density,
                p.shear_modulus,
                a.square.out.display()
            );
        }
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
