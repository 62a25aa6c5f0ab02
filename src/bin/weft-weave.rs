//! `weft-weave`: generate canonical models as folders of Parquet tables.

use std::path::PathBuf;
use std::process::ExitCode;

use clap::{Parser, Subcommand};

use weft::generate::rod::RodParams;
use weft::generate::square::{GirderParams, GirderZone, LoadCase, MembraneParams, Square};
use weft::generate::weave::{self, Spec};
use weft::generate::zones::{
    Centre, CombinedParams, Interface, MembraneProps, PretensionStart, SurroundParams, WovenParams,
};

/// Axes of the reduced model's links.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
enum LinkAxes {
    /// Global x, y, z.
    Global,
    /// The crossing's frame: warp direction, weft direction, their normal.
    Local,
    /// The crossing's frame, its ends points of the two yarns that slide along them when
    /// the link slips (the yarns slide across each other).
    Sliding,
}
use weft::model::ProjectileShape;

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
    /// default girder (s = b²/a, ρ = ρ_g(2 − b/a), G = E(b/a)²/2 with b/a = 0.1). With
    /// --girder-cells, the paper's combined model (Fig. 5b): a girder zone at the centre.
    Membrane(MembraneArgs),
    /// A dense centre zone (rigid girder or fine membrane) inside a coarse membrane whose
    /// elements grow with distance from the centre, joined by tied interfaces; pinned outer
    /// edge; a transverse force pulse at the centre.
    Combined(CombinedArgs),
    /// The reduced woven model (the paper's §5): warp and weft trusses joined at every
    /// crossing by a link (springs, dashpots, optional friction slider), inside a graded
    /// equivalent membrane tied to the yarn ends, hit by a rigid projectile.
    WovenReduced(WovenArgs),
    /// The yarn-level plain-weave patch (the paper's §2 reference): every yarn a band of
    /// orthotropic membrane quads with the lenticular nodal thickness, warp along x and
    /// weft along y crimped over and under each other, yarn–yarn contact with friction
    /// within and between layers, a round-nosed 9 mm, 8 g projectile at 400 m/s.
    /// Quarter model (symmetry planes x = 0, y = 0) unless --full. Node sets: axis_x,
    /// axis_x_weft, diagonal, diagonal_weft (centre-line nodes at the crossings), edge.
    /// --yarn-model chain: truss chains along the bands' centre lines instead (faster).
    Woven(WovenBandArgs),
}

#[derive(clap::Args)]
struct WovenBandArgs {
    /// Output model folder.
    #[arg(long)]
    out: PathBuf,
    /// Yarns per side: of the quarter (the middle yarn counted once) or, with --full, of
    /// the whole patch (even). 60: the paper's 120 × 120 reference; a small patch alone
    /// at 400 m/s, without yarn failure, strains beyond validity within microseconds.
    #[arg(long, default_value_t = 60)]
    yarns: usize,
    /// The whole patch instead of the quarter.
    #[arg(long)]
    full: bool,
    /// Yarn spacing p [m].
    #[arg(long, default_value_t = 1e-3)]
    spacing: f64,
    /// Yarn width w [m].
    #[arg(long, default_value_t = 0.8e-3)]
    width: f64,
    /// Yarn thickness h [m] (lenticular section: area ≈ (2/3)wh).
    #[arg(long, default_value_t = 0.124e-3)]
    thickness: f64,
    /// Crimp amplitude a [m] (default: crossing yarns just touch).
    #[arg(long)]
    crimp_amplitude: Option<f64>,
    /// Quads per spacing along a yarn (even, ≥ 4).
    #[arg(long, default_value_t = 4)]
    per_spacing: usize,
    /// Quads across a yarn's width (even, ≥ 2).
    #[arg(long, default_value_t = 2)]
    across: usize,
    /// How each yarn is modelled: `band`, the paper's reference (orthotropic membrane
    /// quads across the width, contact on the lenticular band faces), or `chain`, trusses
    /// along the band's centre line with the band's section and mass and its centre
    /// thickness as contact thickness (no width: 4–6 × faster; the yarn on a symmetry
    /// plane has half the section; the projectile's nose grows by half that thickness,
    /// its tip as much lower, so that it meets the yarns' surfaces).
    #[arg(long, value_enum, default_value_t = weft::generate::woven::YarnModel::Band)]
    yarn_model: weft::generate::woven::YarnModel,
    /// Yarn Young's modulus along the yarn [Pa] (aramid, Kevlar 29 class).
    #[arg(long, default_value_t = 80e9)]
    modulus: f64,
    /// Yarn modulus across its width [Pa] (a bundle of filaments: small).
    #[arg(long, default_value_t = 1.6e9)]
    transverse_modulus: f64,
    /// Yarn in-plane shear modulus [Pa].
    #[arg(long, default_value_t = 0.8e9)]
    shear_modulus: f64,
    /// Yarn density [kg/m³].
    #[arg(long, default_value_t = 1440.0)]
    density: f64,
    /// Yarn–yarn Coulomb friction coefficient.
    #[arg(long, default_value_t = 0.15)]
    friction: f64,
    /// Yarns carry no compression (tension field; its stress has no potential, so the
    /// energy balance drifts where the yarns are crushed).
    #[arg(long)]
    tension_field: bool,
    /// Fabric layers.
    #[arg(long, default_value_t = 1)]
    layers: usize,
    /// Clearance between layers [m].
    #[arg(long, default_value_t = 0.01e-3)]
    layer_gap: f64,
    /// Yarn ends at the patch edge: clamped (all nodes held), pinned (centre-line node
    /// held) or free. Ignored with --membrane-length (the ends are tied).
    #[arg(long, value_enum, default_value_t = weft::generate::woven::Edge::Clamped)]
    edge: weft::generate::woven::Edge,
    /// The paper's §3 combined model: tie the quarter patch's yarn ends to a graded
    /// orthotropic membrane around it, out to this half-size [m] (e.g. 0.06, the
    /// 60 × 60-yarn reference's), clamped at its outer edge. Adds the node sets
    /// `interface` (the tied yarn ends) and `axis_x_all` (the x axis through both).
    #[arg(long)]
    membrane_length: Option<f64>,
    /// Growth ratio of the membrane's cells (p/2 at the patch) outwards.
    #[arg(long, default_value_t = 1.2)]
    membrane_growth: f64,
    /// Membrane areal density / the patch's (the paper's §3: 0.8).
    #[arg(long, default_value_t = 0.8)]
    membrane_density_ratio: f64,
    /// Membrane E₁ = E₂ / the yarns' E (the paper's §3: 0.3).
    #[arg(long, default_value_t = 0.3)]
    membrane_modulus_ratio: f64,
    /// Membrane G₁₂ / its E (the paper's §3: 0.0042).
    #[arg(long, default_value_t = 0.0042)]
    membrane_shear_ratio: f64,
    /// Membrane thickness [m] (an assumption; default 2A/p per layer, the yarns' section
    /// per unit width of both families).
    #[arg(long)]
    membrane_thickness: Option<f64>,
    /// Projectile nose shape.
    #[arg(long, value_enum, default_value_t = weft::model::ProjectileShape::Round)]
    projectile_shape: weft::model::ProjectileShape,
    /// Projectile radius [m].
    #[arg(long, default_value_t = 4.5e-3)]
    projectile_radius: f64,
    /// Projectile mass [kg] (of the whole projectile; a quarter model carries a quarter).
    #[arg(long, default_value_t = 8e-3)]
    projectile_mass: f64,
    /// Impact velocity [m/s].
    #[arg(long, default_value_t = 400.0)]
    projectile_velocity: f64,
    /// Projectile–yarn friction coefficient.
    #[arg(long, default_value_t = 0.1)]
    projectile_friction: f64,
    /// Simulated time [s].
    #[arg(long, default_value_t = 6e-5)]
    end_time: f64,
    /// Output interval [s].
    #[arg(long, default_value_t = 1e-6)]
    output_interval: f64,
    /// Safety factor on the stable time step, 0 < f ≤ 1 (analysis.parquet). The step is
    /// set from the undeformed bands; yarns under the nose, which do not fail, stretch
    /// towards 20 % Green strain by 60 µs and stiffen: 0.8 keeps such runs stable.
    #[arg(long, default_value_t = 0.9)]
    dt_safety: f64,
}

#[derive(clap::Args)]
struct CombinedArgs {
    /// Output model folder.
    #[arg(long)]
    out: PathBuf,
    /// Dense centre zone: girder or membrane.
    #[arg(long, value_enum, default_value_t = Centre::Girder)]
    centre: Centre,
    /// Side of the centre zone L_m [m].
    #[arg(long, default_value_t = 0.02)]
    centre_length: f64,
    /// Cells across the centre zone (even).
    #[arg(long, default_value_t = 20)]
    centre_cells: usize,
    /// Side of the whole model L [m].
    #[arg(long, default_value_t = 0.1)]
    length: f64,
    /// Coarse cell size at the centre zone, in centre cells (divides centre-cells/2).
    #[arg(long, default_value_t = 2)]
    coarsening: usize,
    /// Growth ratio of the coarse cells away from the centre.
    #[arg(long, default_value_t = 1.25)]
    growth: f64,
    /// Full model instead of the quarter with symmetry planes x = 0, y = 0.
    #[arg(long)]
    full: bool,
    /// Girder Young's modulus E [Pa] (also the membrane's).
    #[arg(long, default_value_t = 1.5e11)]
    youngs_modulus: f64,
    /// Girder density ρ [kg/m³].
    #[arg(long, default_value_t = 7800.0)]
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
    #[arg(long, default_value_t = 1.0)]
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
struct WovenArgs {
    /// Output model folder.
    #[arg(long)]
    out: PathBuf,
    /// Yarns per side of the full patch (even).
    #[arg(long, default_value_t = 20)]
    yarns: usize,
    /// Yarn spacing p [m].
    #[arg(long, default_value_t = 1e-3)]
    spacing: f64,
    /// Yarn Young's modulus [Pa] (aramid).
    #[arg(long, default_value_t = 80e9)]
    yarn_modulus: f64,
    /// Yarn density [kg/m³].
    #[arg(long, default_value_t = 1440.0)]
    yarn_density: f64,
    /// Yarn cross-section area [m²] (190 g/m² fabric at 1 mm spacing).
    #[arg(long, default_value_t = 6.6e-8)]
    yarn_area: f64,
    /// Let yarns carry compression too.
    #[arg(long)]
    compressible_yarns: bool,
    /// Yarn pretension as an initial strain ε₀ [–] (the yarns start with the force E·A·ε₀;
    /// see --pretension-start).
    #[arg(long, default_value_t = 0.0)]
    pretension_strain: f64,
    /// How a pretensioned model starts: `balanced` (the membrane around carries the same
    /// tension per width, N = E·A·ε₀/p, as an initial stress N/s: in equilibrium at t = 0
    /// for straight yarns), `relaxed` (balanced, then the crimped crossings settled by
    /// dynamic relaxation and written as initial displacements: for --crimp > 0) or
    /// `unbalanced` (only the yarns pre-strained: the membrane is pulled in and rings;
    /// the behaviour before the fix).
    #[arg(long, value_enum, default_value_t = PretensionStart::Balanced)]
    pretension_start: PretensionStart,
    /// Crimp: z offset of warp and weft at the crossings, ± [m].
    #[arg(long, default_value_t = 0.0)]
    crimp: f64,
    /// Link stiffness k_x = k_y [N/m] (the paper's fitted 3.8661·10³ N/mm).
    #[arg(long, default_value_t = 3.8661e6)]
    k_xy: f64,
    /// Link stiffness k_z [N/m] (the paper's fitted 5.2448·10⁶ N/mm).
    #[arg(long, default_value_t = 5.2448e9)]
    k_z: f64,
    /// Link dashpots c_x = c_y [N·s/m].
    #[arg(long, default_value_t = 0.0)]
    c_xy: f64,
    /// Link dashpot c_z [N·s/m].
    #[arg(long, default_value_t = 0.0)]
    c_z: f64,
    /// Link friction slider: tangential slip force [N] [default: none].
    #[arg(long)]
    slip_force: Option<f64>,
    /// Link Coulomb friction coefficient μ [–]: the tangential springs slip at μ·N, N the
    /// normal spring's compressive force (not with --slip-force) [default: none].
    #[arg(long)]
    link_friction: Option<f64>,
    /// Unilateral link normal: the normal spring (and dashpot) pushes the yarns apart and
    /// never pulls them together [default: two-way, as the paper's links].
    #[arg(long)]
    unilateral_links: bool,
    /// Link axes: `global` (x, y, z, as the paper's links), `local` (the crossing's two
    /// yarn directions and their normal, following the fabric as it tilts) or `sliding`
    /// (local, and the link's ends are points of the yarns that move along them when the
    /// link slips: the yarns slide across each other; give --link-friction or
    /// --slip-force).
    #[arg(long, value_enum, default_value_t = LinkAxes::Global)]
    link_axes: LinkAxes,
    /// Membrane surround: its surface density over the woven patch's 2ρA/p [–] (the
    /// paper's §3: 0.8).
    #[arg(long, default_value_t = 0.8)]
    membrane_density_ratio: f64,
    /// Membrane surround: its Young's modulus over the yarn's [–] (the paper's §3: 0.3).
    #[arg(long, default_value_t = 0.3)]
    membrane_modulus_ratio: f64,
    /// Membrane surround: its shear modulus over its Young's modulus [–] (the paper's §3:
    /// 0.0042).
    #[arg(long, default_value_t = 0.0042)]
    membrane_shear_ratio: f64,
    /// Membrane surround: Poisson's ratio ν [–].
    #[arg(long, default_value_t = 0.0, allow_hyphen_values = true)]
    membrane_poisson: f64,
    /// Membrane surround: thickness s [m] (its density follows: ratio × 2ρA/p / s)
    /// [default: 2A/p].
    #[arg(long)]
    membrane_thickness: Option<f64>,
    /// Side of the whole model [m].
    #[arg(long, default_value_t = 0.1)]
    length: f64,
    /// Growth ratio of the membrane cells away from the patch.
    #[arg(long, default_value_t = 1.25)]
    growth: f64,
    /// Where the patch meets the membrane: `crossing` (on the last crossing line x = np,
    /// whose yarns are halved) or `band-ends` (as `woven --membrane-length`: the last
    /// crossing line a full yarn, the rods running on to the membrane at (n + ½)p; quarter
    /// only; for comparing with the yarn-level patch).
    #[arg(long, value_enum, default_value_t = Interface::Crossing)]
    interface: Interface,
    /// Full model instead of the quarter.
    #[arg(long)]
    full: bool,
    /// Projectile nose: flat, round or sphere.
    #[arg(long, value_enum, default_value_t = ProjectileShape::Flat)]
    projectile_shape: ProjectileShape,
    /// Projectile radius [m] (9 mm calibre).
    #[arg(long, default_value_t = 4.5e-3)]
    projectile_radius: f64,
    /// Projectile mass [kg] (a quarter model carries a quarter).
    #[arg(long, default_value_t = 8e-3)]
    projectile_mass: f64,
    /// Impact velocity [m/s].
    #[arg(long, default_value_t = 400.0)]
    projectile_velocity: f64,
    /// Projectile–yarn Coulomb friction coefficient (the yarn-level `woven` patch's
    /// default is 0.1).
    #[arg(long, default_value_t = 0.0)]
    projectile_friction: f64,
    /// Simulated time [s].
    #[arg(long, default_value_t = 5e-5)]
    end_time: f64,
    /// Output interval [s].
    #[arg(long, default_value_t = 1e-6)]
    output_interval: f64,
    /// Safety factor on the stable time step, 0 < f ≤ 1 (written to the model's
    /// analysis.parquet; the projectile's contact penalty κ m/Δt² stiffens with a shorter
    /// step).
    #[arg(long, default_value_t = 0.9)]
    dt_safety: f64,
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
    /// Give the boundary rods full properties [default: half the modulus and density, as
    /// half a cell of the lattice, so that the girder matches its equivalent membrane of side L].
    #[arg(long)]
    full_edge_rods: bool,
    /// Clamp at x = 0: `built-in` holds translations and rotations; `translations` holds the
    /// translations only, as the membrane's clamp does.
    #[arg(long, value_enum, default_value_t = Clamp::BuiltIn)]
    clamp: Clamp,
}

#[derive(Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
enum Clamp {
    BuiltIn,
    Translations,
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
    #[arg(long, default_value_t = 7800.0, requires = "girder_cells")]
    rod_density: f64,
    /// Girder zone: joints rigid (beams) or pinned (trusses).
    #[arg(long, value_enum, default_value_t = Joints::Rigid, requires = "girder_cells")]
    joints: Joints,
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
    weft::cli::main(run)
}

fn run() -> anyhow::Result<ExitCode> {
    let cli: Cli = weft::cli::parse();
    let mut warn = |w: &str| match w.strip_prefix("note: ") {
        Some(n) => eprintln!("note: {n}"),
        None => eprintln!("warning: {w}"),
    };
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
                clamp_rotations: a.clamp == Clamp::BuiltIn,
            };
            let m = weave::run(&Spec::Girder(p.clone()), &a.square.out, &mut warn)?;
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
        Model::Combined(a) => {
            let cell = a.centre_length / a.centre_cells.max(1) as f64;
            let b = a.rod_width.unwrap_or(cell / 10.0);
            let c = a.length * 0.5 * (a.density / a.youngs_modulus).sqrt();
            let end = a.end_time.unwrap_or(4.0 * c);
            let p = CombinedParams {
                centre: a.centre,
                centre_length: a.centre_length,
                centre_cells: a.centre_cells,
                length: a.length,
                coarsening: a.coarsening,
                growth: a.growth,
                quarter: !a.full,
                youngs_modulus: a.youngs_modulus,
                density: a.density,
                rod_width: b,
                membrane: MembraneProps {
                    youngs_modulus: a.youngs_modulus,
                    poisson_ratio: 0.0,
                    shear_modulus: a
                        .shear_modulus
                        .unwrap_or(a.youngs_modulus * (b / cell).powi(2) / 2.0),
                    thickness: a.thickness.unwrap_or(b * b / cell),
                    density: a.membrane_density.unwrap_or(a.density * (2.0 - b / cell)),
                },
                force: a.force,
                pulse: a
                    .pulse
                    .unwrap_or(a.centre_length * (a.density / a.youngs_modulus).sqrt()),
                end_time: end,
                output_interval: a.output_interval.unwrap_or(end / 100.0),
            };
            let m = weave::run(&Spec::Combined(p.clone()), &a.out, &mut warn)?;
            eprintln!(
                "weft-weave combined: {} nodes, {} elements, {} ties -> {}",
                m.num_nodes(),
                m.num_elements(),
                m.ties.len(),
                a.out.display()
            );
        }
        Model::WovenReduced(a) => {
            let p = WovenParams {
                yarns: a.yarns,
                spacing: a.spacing,
                yarn_modulus: a.yarn_modulus,
                yarn_density: a.yarn_density,
                yarn_area: a.yarn_area,
                tension_only: !a.compressible_yarns,
                pretension_strain: a.pretension_strain,
                pretension_start: a.pretension_start,
                crimp: a.crimp,
                k_xy: a.k_xy,
                k_z: a.k_z,
                c_xy: a.c_xy,
                c_z: a.c_z,
                slip_force: a.slip_force,
                friction: a.link_friction,
                unilateral: a.unilateral_links,
                local_frame: a.link_axes == LinkAxes::Local,
                sliding: a.link_axes == LinkAxes::Sliding,
                surround: SurroundParams {
                    density_ratio: a.membrane_density_ratio,
                    modulus_ratio: a.membrane_modulus_ratio,
                    shear_ratio: a.membrane_shear_ratio,
                    poisson_ratio: a.membrane_poisson,
                    thickness: a.membrane_thickness,
                },
                length: a.length,
                growth: a.growth,
                quarter: !a.full,
                interface: a.interface,
                projectile_shape: a.projectile_shape,
                projectile_radius: a.projectile_radius,
                projectile_mass: a.projectile_mass,
                projectile_velocity: a.projectile_velocity,
                projectile_friction: a.projectile_friction,
                end_time: a.end_time,
                output_interval: a.output_interval,
                dt_safety: a.dt_safety,
            };
            let m = weave::run(&Spec::WovenReduced(p.clone()), &a.out, &mut warn)?;
            let mp = p.membrane();
            eprintln!(
                "weft-weave woven-reduced: {} nodes, {} elements, {} ties; membrane surround ρs = {:.4e} kg/m² ({:.3} × the patch's 2ρA/p = {:.4e}), E = {:.3e} Pa, G = {:.3e} Pa, s = {:.3e} m -> {}",
                m.num_nodes(),
                m.num_elements(),
                m.ties.len(),
                mp.density * mp.thickness,
                mp.density * mp.thickness / p.patch_surface_density(),
                p.patch_surface_density(),
                mp.youngs_modulus,
                mp.shear_modulus,
                mp.thickness,
                a.out.display()
            );
        }
        Model::Woven(a) => {
            let p = weft::generate::woven::WovenBandParams {
                yarns: a.yarns,
                quarter: !a.full,
                spacing: a.spacing,
                width: a.width,
                thickness: a.thickness,
                crimp_amplitude: a.crimp_amplitude,
                per_spacing: a.per_spacing,
                across: a.across,
                yarn_model: a.yarn_model,
                modulus: a.modulus,
                transverse_modulus: a.transverse_modulus,
                shear_modulus: a.shear_modulus,
                density: a.density,
                friction: a.friction,
                tension_field: a.tension_field,
                layers: a.layers,
                layer_gap: a.layer_gap,
                edge: a.edge,
                projectile_shape: a.projectile_shape,
                projectile_radius: a.projectile_radius,
                projectile_mass: a.projectile_mass,
                projectile_velocity: a.projectile_velocity,
                projectile_friction: a.projectile_friction,
                end_time: a.end_time,
                output_interval: a.output_interval,
                dt_safety: a.dt_safety,
                surround: a
                    .membrane_length
                    .map(|length| weft::generate::woven::Surround {
                        length,
                        growth: a.membrane_growth,
                        density_ratio: a.membrane_density_ratio,
                        modulus_ratio: a.membrane_modulus_ratio,
                        shear_ratio: a.membrane_shear_ratio,
                        thickness: a.membrane_thickness,
                    }),
            };
            let m = weave::run(&Spec::Woven(p), &a.out, &mut warn)?;
            eprintln!(
                "weft-weave woven: {} nodes, {} elements, {} contact definitions -> {}",
                m.num_nodes(),
                m.num_elements(),
                m.contacts.len(),
                a.out.display()
            );
        }
        Model::Membrane(a) => {
            let mut d = MembraneParams::paper_default(a.square.square());
            let l = a.square.length;
            let zone = a.girder_cells.map(|ng| GirderZone {
                length: a.zone_length.unwrap_or(0.5 * l),
                cells: ng,
                youngs_modulus: a.rod_modulus.unwrap_or(a.youngs_modulus),
                density: a.rod_density,
                rod_width: a.rod_width.unwrap_or(l / (10.0 * ng.max(1) as f64)),
                rigid: a.joints == Joints::Rigid,
            });
            if let Some(z) = &zone {
                (d.thickness, d.density, d.shear_modulus) = z.equivalent(l);
            }
            let p = MembraneParams {
                youngs_modulus: a.youngs_modulus,
                poisson_ratio: a.poisson_ratio,
                shear_modulus: a.shear_modulus.unwrap_or(d.shear_modulus),
                thickness: a.thickness.unwrap_or(d.thickness),
                density: a.density.unwrap_or(d.density),
                girder_zone: zone,
                ..d
            };
            let m = weave::run(&Spec::Membrane(p.clone()), &a.square.out, &mut warn)?;
            eprintln!(
                "weft-weave membrane: {} nodes, {} elements{}, s = {:.3e} m, ρ = {:.1} kg/m³, G = {:.3e} Pa -> {}",
                m.num_nodes(),
                m.num_elements(),
                if p.girder_zone.is_some() { " (quads and the girder zone's rods)" } else { " (quads)" },
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
            let m = weave::run(&Spec::Rod(p.clone()), &a.out, &mut warn)?;
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
    Ok(ExitCode::SUCCESS)
}
