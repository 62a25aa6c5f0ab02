//! `weft-weave`: generate canonical models as folders of Parquet tables.
//!
//! Each subcommand's flags take their defaults from its generator's parameters
//! (`Default`) and map onto those parameters in one conversion (`params`, or `options`
//! where the library derives what a flag left out implies, `resolve`); `run` dispatches.
//! `woven` and `woven-reduced` (their own modules) declare the flags they share once, in
//! the groups of `fabric`.

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use clap::{Parser, Subcommand};

mod bullet;
mod clay;
mod fabric;
mod taylor;
mod woven;
mod woven_reduced;
use clay::ClayDropArgs;
use taylor::TaylorArgs;
use woven::WovenBandArgs;
use woven_reduced::WovenArgs;

use weft::generate::rod::RodParams;
use weft::generate::square::{
    GirderParams, GirderZoneOptions, LoadCase, MembraneOptions, MembraneParams, Square,
};
use weft::generate::weave::{self, Spec};
use weft::generate::zones::{Centre, CombinedOptions};

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
    #[command(after_help = "Example:\n  weft-weave rod --elements 200 --out runs/rod")]
    Rod(RodArgs),
    /// A square L × L grid of rods (the paper's §4 girder), N cells per side, clamped at
    /// x = 0 and loaded at x = L; rods as beams (rigid joints) or trusses (pinned joints).
    #[command(
        after_help = "Example:\n  weft-weave girder --cells 10 --load-case shear --out runs/girder"
    )]
    Girder(GirderArgs),
    /// The same square meshed with N × N membrane quads (the equivalent membrane),
    /// clamped at x = 0 and loaded at x = L. Defaults: the closed-form equivalent of the
    /// default girder (s = b²/a, ρ = ρ_g(2 − b/a), G = E(b/a)²/2 with b/a = 0.1). With
    /// --girder-cells, the paper's combined model (Fig. 5b): a girder zone at the centre.
    #[command(
        after_help = "Example:\n  weft-weave membrane --cells 10 --load-case shear --out runs/membrane"
    )]
    Membrane(MembraneArgs),
    /// A dense centre zone (rigid girder or fine membrane) inside a coarse membrane whose
    /// elements grow with distance from the centre, joined by tied interfaces; pinned outer
    /// edge; a transverse force pulse at the centre.
    #[command(after_help = "Example:\n  weft-weave combined --out runs/combined")]
    Combined(CombinedArgs),
    /// The reduced woven model (the paper's §5): warp and weft trusses joined at every
    /// crossing by a link (springs, dashpots, optional friction slider), inside a graded
    /// equivalent membrane tied to the yarn ends, hit by a rigid projectile.
    #[command(after_help = "Example:\n  weft-weave woven-reduced --yarns 10 --out runs/reduced")]
    WovenReduced(WovenArgs),
    /// The yarn-level plain-weave patch (the paper's §2 reference): every yarn a band of
    /// orthotropic membrane quads with the lenticular nodal thickness, warp along x and
    /// weft along y crimped over and under each other, yarn–yarn contact with friction
    /// within and between layers, a round-nosed 9 mm, 8 g projectile at 400 m/s.
    /// Quarter model (symmetry planes x = 0, y = 0) unless --full. Node sets: axis_x,
    /// axis_x_weft, diagonal, diagonal_weft (centre-line nodes at the crossings), edge.
    /// --yarn-model chain: truss chains along the bands' centre lines instead (faster).
    #[command(
        after_help = "Example:\n  weft-weave woven --yarns 10 --out runs/woven\n  weft-weave woven --yarns 10 --layers 2 --failure-strain 0.036 --projectile-velocity 100 \\\n    --out runs/two"
    )]
    Woven(WovenBandArgs),
    /// The Taylor test: a flat-ended metal cylinder (hexahedra, Johnson–Cook) strikes a
    /// rigid frictionless wall at U. Quarter model (symmetry planes x = 0, y = 0); the
    /// rod along z from the wall at z = 0; the step follows the crushed foot. Node sets:
    /// axis, impact_face, impact_edge (the foot's rim), rear_face. Default: Johnson &
    /// Cook's OFHC copper rod, 25.4 mm × 7.6 mm at 190 m/s.
    #[command(
        after_help = "Example:\n  weft-weave taylor --radial 8 --material aluminium --velocity 200 --out runs/taylor"
    )]
    Taylor(TaylorArgs),
    /// The drop calibration of the armour test's backing clay (NIJ Standard-0101.06): a
    /// steel sphere 63.5 mm across, 1043 g, dropped 2.0 m onto a block of Roma Plastilina
    /// No. 1 (hexahedra of the plasticine law) in the standard's 610 × 610 × 140 mm box;
    /// the clay is fit when the indentation is 19 ± 3 mm. Quarter model; the cells fine
    /// only under the drop. Node sets: clay_top, clay_axis_top (the crater's depth),
    /// clay_profile (the top surface along x). `weft-ballistic clay-calibration` runs it
    /// and writes clay_calibration.parquet.
    #[command(
        after_help = "Example:\n  weft-weave clay-drop --out runs/drop && weft-simulate --model runs/drop --out runs/drop-run"
    )]
    ClayDrop(ClayDropArgs),
}

#[derive(clap::Args)]
struct CombinedArgs {
    /// Output model folder.
    #[arg(long)]
    out: PathBuf,
    /// Dense centre zone: girder or membrane.
    #[arg(long, value_enum, default_value_t = CombinedOptions::default().centre)]
    centre: Centre,
    /// Side of the centre zone L_m [m].
    #[arg(long, default_value_t = CombinedOptions::default().centre_length)]
    centre_length: f64,
    /// Cells across the centre zone (even).
    #[arg(long, default_value_t = CombinedOptions::default().centre_cells)]
    centre_cells: usize,
    /// Side of the whole model L [m].
    #[arg(long, default_value_t = CombinedOptions::default().length)]
    length: f64,
    /// Coarse cell size at the centre zone, in centre cells (divides centre-cells/2).
    #[arg(long, default_value_t = CombinedOptions::default().coarsening)]
    coarsening: usize,
    /// Growth ratio of the coarse cells away from the centre.
    #[arg(long, default_value_t = CombinedOptions::default().growth)]
    growth: f64,
    /// Full model instead of the quarter with symmetry planes x = 0, y = 0.
    #[arg(long)]
    full: bool,
    /// Girder Young's modulus E [Pa] (also the membrane's).
    #[arg(long, default_value_t = CombinedOptions::default().youngs_modulus)]
    youngs_modulus: f64,
    /// Girder density ρ [kg/m³].
    #[arg(long, default_value_t = CombinedOptions::default().density)]
    density: f64,
    /// Girder rod width = thickness b [m] [default: cell size / 10].
    #[arg(long)]
    rod_width: Option<f64>,
    /// Membrane shear modulus G [Pa] [default: E(b/a)²/2].
    #[arg(long)]
    shear_modulus: Option<f64>,
    /// Membrane thickness s [m] [default: b²/a].
    #[arg(long)]
    thickness: Option<f64>,
    /// Membrane density [kg/m³] [default: ρ(2 − b/a)].
    #[arg(long)]
    membrane_density: Option<f64>,
    /// Transverse force at the centre [N] (the full model's; a quarter carries F/4). The
    /// default keeps the girder's local rotations small, where the beam element is exact
    /// to its energy (at 100 N the 0.1 mm rods turn by ~1 rad per cell and the energy
    /// balance degrades to 1.6 %).
    #[arg(long, default_value_t = CombinedOptions::default().force)]
    force: f64,
    /// Pulse duration T_F [s] [default: L_m·√(ρ/E)].
    #[arg(long)]
    pulse: Option<f64>,
    /// Simulated time [s] [default: L/2·√(ρ/E)·4].
    #[arg(long)]
    end_time: Option<f64>,
    /// Output interval [s] [default: end time / 100].
    #[arg(long)]
    output_interval: Option<f64>,
}

#[derive(clap::Args)]
struct SquareArgs {
    /// Output model folder (replaced atomically if it exists).
    #[arg(long)]
    out: PathBuf,
    /// Side length L [m].
    #[arg(long, default_value_t = Square::default().length)]
    length: f64,
    /// Cells per side N.
    #[arg(long, default_value_t = Square::default().cells)]
    cells: usize,
    /// Load case: tension (+x on the edge x = L), shear (+y on x = L), transverse (+z at the centre).
    #[arg(long, value_enum, default_value_t = Square::default().load_case)]
    load_case: LoadCase,
    /// Total force F [N] (the pulse amplitude; a static solve uses it as the load).
    #[arg(long, default_value_t = Square::default().force)]
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

/// Joints of a girder's rods.
#[derive(Clone, Copy, PartialEq, clap::ValueEnum)]
enum Joints {
    Rigid,
    Pinned,
}

impl Joints {
    /// `Rigid` for rigid joints, `Pinned` otherwise.
    fn of(rigid: bool) -> Joints {
        if rigid {
            Joints::Rigid
        } else {
            Joints::Pinned
        }
    }
}

#[derive(clap::Args)]
struct GirderArgs {
    #[command(flatten)]
    square: SquareArgs,
    /// Young's modulus E [Pa].
    #[arg(long, default_value_t = GirderParams::default().youngs_modulus)]
    youngs_modulus: f64,
    /// Density ρ [kg/m³].
    #[arg(long, default_value_t = GirderParams::default().density)]
    density: f64,
    /// Rod width b, in the plane [m] [default: L/(10N); the paper's range is L/(20N) … L/(8N)].
    #[arg(long)]
    rod_width: Option<f64>,
    /// Rod thickness h, out of the plane [m] [default: b].
    #[arg(long)]
    rod_thickness: Option<f64>,
    /// Joints: rigid (beams, shear stiffness E·h·b³/(2a³)) or pinned (trusses, none).
    #[arg(long, value_enum, default_value_t = Joints::of(GirderParams::default().rigid))]
    joints: Joints,
    /// Give the boundary rods full properties [default: half the modulus and density, as
    /// half a cell of the lattice, so that the girder matches its equivalent membrane of side L].
    #[arg(long)]
    full_edge_rods: bool,
    /// Clamp at x = 0: `built-in` holds translations and rotations; `translations` holds the
    /// translations only, as the membrane's clamp does.
    #[arg(long, value_enum, default_value_t = Clamp::of(GirderParams::default().clamp_rotations))]
    clamp: Clamp,
}

/// The girder's clamp at x = 0.
#[derive(Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
enum Clamp {
    BuiltIn,
    Translations,
}

impl Clamp {
    /// `BuiltIn` where the clamp holds the rotations too, `Translations` otherwise.
    fn of(clamp_rotations: bool) -> Clamp {
        if clamp_rotations {
            Clamp::BuiltIn
        } else {
            Clamp::Translations
        }
    }
}

#[derive(clap::Args)]
struct MembraneArgs {
    #[command(flatten)]
    square: SquareArgs,
    /// Young's modulus E = E₁ = E₂ [Pa].
    #[arg(long, default_value_t = MembraneOptions::default().youngs_modulus)]
    youngs_modulus: f64,
    /// Poisson's ratio ν₁₂.
    #[arg(long, default_value_t = MembraneOptions::default().poisson_ratio)]
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
    /// The paper's combined model (Fig. 5b): a girder zone of side --zone-length at the
    /// centre, the rods of a girder of this many cells per side L (N_g), tied to the
    /// membrane (N_m = --cells) around it. The membrane's defaults then follow the zone's
    /// girder: s = b²/a, ρ = ρ_g(2 − b/a), G = E(b/a)²/2 with a = L/N_g. Node set
    /// `centre`: the zone's nodes (the paper's reference nodes).
    #[arg(long)]
    girder_cells: Option<usize>,
    /// Side of the girder zone L_m [m] [default: L/2]; its edges must lie on both grids.
    #[arg(long, requires = "girder_cells")]
    zone_length: Option<f64>,
    /// Girder zone: rod width = thickness b [m] [default: L/(10 N_g)].
    #[arg(long, requires = "girder_cells")]
    rod_width: Option<f64>,
    /// Girder zone: the rods' Young's modulus [Pa] [default: --youngs-modulus].
    #[arg(long, requires = "girder_cells")]
    rod_modulus: Option<f64>,
    /// Girder zone: the rods' density ρ_g [kg/m³].
    #[arg(long, default_value_t = zone_default().density, requires = "girder_cells")]
    rod_density: f64,
    /// Girder zone: joints rigid (beams) or pinned (trusses).
    #[arg(long, value_enum, default_value_t = Joints::of(zone_default().rigid), requires = "girder_cells")]
    joints: Joints,
}

#[derive(clap::Args)]
struct RodArgs {
    /// Output model folder (replaced atomically if it exists).
    #[arg(long)]
    out: PathBuf,
    /// Rod length L [m].
    #[arg(long, default_value_t = RodParams::default().length)]
    length: f64,
    /// Number of truss elements.
    #[arg(long, default_value_t = RodParams::default().elements)]
    elements: usize,
    /// Young's modulus E [Pa] (default: steel, as in the paper's §4).
    #[arg(long, default_value_t = RodParams::default().youngs_modulus)]
    youngs_modulus: f64,
    /// Density ρ [kg/m³].
    #[arg(long, default_value_t = RodParams::default().density)]
    density: f64,
    /// Cross-section width [m].
    #[arg(long, default_value_t = RodParams::default().width)]
    width: f64,
    /// Cross-section thickness [m].
    #[arg(long, default_value_t = RodParams::default().thickness)]
    thickness: f64,
    /// Pulse amplitude F0 [N] (positive pulls along +x).
    #[arg(long, default_value_t = RodParams::default().force)]
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

/// The girder zone's defaults (`--girder-cells` has none).
fn zone_default() -> GirderZoneOptions {
    GirderZoneOptions::new(0)
}

impl RodArgs {
    fn params(&self) -> RodParams {
        RodParams {
            length: self.length,
            elements: self.elements,
            youngs_modulus: self.youngs_modulus,
            density: self.density,
            width: self.width,
            thickness: self.thickness,
            force: self.force,
            pulse_duration: self.pulse_duration,
            end_time: self.end_time,
            output_interval: self.output_interval,
            tension_only: self.tension_only,
        }
    }

    fn weave(&self) -> anyhow::Result<()> {
        let p = self.params();
        let m = weave(&Spec::Rod(p.clone()), &self.out)?;
        eprintln!(
            "weft-weave rod: {} nodes, {} trusses, c = {:.1} m/s, T_F = {:.3e} s -> {}",
            m.num_nodes(),
            m.num_elements(),
            p.wave_speed(),
            p.pulse(),
            self.out.display()
        );
        Ok(())
    }
}

impl GirderArgs {
    fn params(&self) -> GirderParams {
        GirderParams {
            square: self.square.square(),
            youngs_modulus: self.youngs_modulus,
            density: self.density,
            rod_width: self.rod_width,
            rod_thickness: self.rod_thickness,
            rigid: self.joints == Joints::Rigid,
            full_edge_rods: self.full_edge_rods,
            clamp_rotations: self.clamp == Clamp::BuiltIn,
        }
    }

    fn weave(&self) -> anyhow::Result<()> {
        let p = self.params();
        let m = weave(&Spec::Girder(p.clone()), &self.square.out)?;
        eprintln!(
            "weft-weave girder: {} nodes, {} {} rods, b = {:.3e} m, h = {:.3e} m -> {}",
            m.num_nodes(),
            m.num_elements(),
            if p.rigid { "beam" } else { "truss" },
            p.b(),
            p.h(),
            self.square.out.display()
        );
        Ok(())
    }
}

impl MembraneArgs {
    fn options(&self) -> MembraneOptions {
        MembraneOptions {
            square: self.square.square(),
            youngs_modulus: self.youngs_modulus,
            poisson_ratio: self.poisson_ratio,
            shear_modulus: self.shear_modulus,
            thickness: self.thickness,
            density: self.density,
            girder_zone: self.girder_cells.map(|cells| GirderZoneOptions {
                cells,
                length: self.zone_length,
                youngs_modulus: self.rod_modulus,
                density: self.rod_density,
                rod_width: self.rod_width,
                rigid: self.joints == Joints::Rigid,
            }),
        }
    }

    fn weave(&self) -> anyhow::Result<()> {
        let p: MembraneParams = self.options().resolve();
        let m = weave(&Spec::Membrane(p.clone()), &self.square.out)?;
        eprintln!(
            "weft-weave membrane: {} nodes, {} elements{}, s = {:.3e} m, ρ = {:.1} kg/m³, G = {:.3e} Pa -> {}",
            m.num_nodes(),
            m.num_elements(),
            if p.girder_zone.is_some() { " (quads and the girder zone's rods)" } else { " (quads)" },
            p.thickness,
            p.density,
            p.shear_modulus,
            self.square.out.display()
        );
        Ok(())
    }
}

impl CombinedArgs {
    fn options(&self) -> CombinedOptions {
        CombinedOptions {
            centre: self.centre,
            centre_length: self.centre_length,
            centre_cells: self.centre_cells,
            length: self.length,
            coarsening: self.coarsening,
            growth: self.growth,
            quarter: !self.full,
            youngs_modulus: self.youngs_modulus,
            density: self.density,
            rod_width: self.rod_width,
            shear_modulus: self.shear_modulus,
            thickness: self.thickness,
            membrane_density: self.membrane_density,
            force: self.force,
            pulse: self.pulse,
            end_time: self.end_time,
            output_interval: self.output_interval,
        }
    }

    fn weave(&self) -> anyhow::Result<()> {
        let p = self.options().resolve();
        let m = weave(&Spec::Combined(p), &self.out)?;
        eprintln!(
            "weft-weave combined: {} nodes, {} elements, {} ties -> {}",
            m.num_nodes(),
            m.num_elements(),
            m.ties.len(),
            self.out.display()
        );
        Ok(())
    }
}

/// Build the model and write it to `out`, the generator's warnings and notes on stderr.
fn weave(spec: &Spec, out: &Path) -> weft::error::Result<weft::model::Model> {
    weave::run(spec, out, &mut |w: &str| match w.strip_prefix("note: ") {
        Some(n) => eprintln!("note: {n}"),
        None => eprintln!("warning: {w}"),
    })
}

fn main() -> ExitCode {
    weft::cli::main(run)
}

fn run() -> anyhow::Result<ExitCode> {
    let cli: Cli = weft::cli::parse();
    match cli.model {
        Model::Rod(a) => a.weave(),
        Model::Girder(a) => a.weave(),
        Model::Membrane(a) => a.weave(),
        Model::Combined(a) => a.weave(),
        Model::WovenReduced(a) => a.weave(),
        Model::Woven(a) => a.weave(),
        Model::Taylor(a) => a.weave(),
        Model::ClayDrop(a) => a.weave(),
    }?;
    Ok(ExitCode::SUCCESS)
}

#[cfg(test)]
mod tests;
