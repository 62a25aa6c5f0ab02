//! `weft-weave`: generate canonical models as folders of Parquet tables.
//!
//! Each subcommand's flags take their defaults from its generator's parameters
//! (`Default`) and map onto those parameters in one conversion (`params`, or `options`
//! where the library derives what a flag left out implies, `resolve`); `run` dispatches.

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use clap::{Parser, Subcommand};

mod bullet;
mod taylor;
use bullet::BulletArgs;
use taylor::TaylorArgs;

use weft::generate::rod::RodParams;
use weft::generate::square::{
    GirderParams, GirderZoneOptions, LoadCase, MembraneOptions, MembraneParams, Square,
};
use weft::generate::weave::{self, Spec};
use weft::generate::woven::{Edge, StrengthPer, Surround, WovenBandParams, YarnFailure, YarnModel};
use weft::generate::woven_reduced::{Interface, PretensionStart, SurroundParams, WovenParams};
use weft::generate::zones::{Centre, CombinedOptions};
use weft::model::ProjectileShape;

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

impl LinkAxes {
    /// The axes of `p`'s links.
    fn of(p: &WovenParams) -> LinkAxes {
        match (p.local_frame, p.sliding) {
            (_, true) => LinkAxes::Sliding,
            (true, false) => LinkAxes::Local,
            (false, false) => LinkAxes::Global,
        }
    }
}

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
}

#[derive(clap::Args)]
struct WovenBandArgs {
    /// Output model folder.
    #[arg(long)]
    out: PathBuf,
    /// Yarns per side: of the quarter (the middle yarn counted once) or, with --full, of
    /// the whole patch (even). 60: the paper's 120 × 120 reference; a small patch alone
    /// at 400 m/s, without yarn failure, strains beyond validity within microseconds.
    #[arg(long, default_value_t = WovenBandParams::default().yarns)]
    yarns: usize,
    /// The whole patch instead of the quarter.
    #[arg(long)]
    full: bool,
    /// Yarn spacing p [m].
    #[arg(long, default_value_t = WovenBandParams::default().spacing)]
    spacing: f64,
    /// Yarn width w [m].
    #[arg(long, default_value_t = WovenBandParams::default().width)]
    width: f64,
    /// Yarn thickness h [m] (lenticular section: area ≈ (2/3)wh).
    #[arg(long, default_value_t = WovenBandParams::default().thickness)]
    thickness: f64,
    /// Crimp amplitude a [m] (default: crossing yarns just touch).
    #[arg(long)]
    crimp_amplitude: Option<f64>,
    /// Quads per spacing along a yarn (even, ≥ 4).
    #[arg(long, default_value_t = WovenBandParams::default().per_spacing)]
    per_spacing: usize,
    /// Quads across a yarn's width (even, ≥ 2).
    #[arg(long, default_value_t = WovenBandParams::default().across)]
    across: usize,
    /// How each yarn is modelled: `band`, the paper's reference (orthotropic membrane
    /// quads across the width, contact on the lenticular band faces), or `chain`, trusses
    /// along the band's centre line with the band's section and mass and its centre
    /// thickness as contact thickness (no width: 4–6 × faster; the yarn on a symmetry
    /// plane has half the section; the projectile's nose grows by half that thickness,
    /// its tip as much lower, so that it meets the yarns' surfaces).
    #[arg(long, value_enum, default_value_t = WovenBandParams::default().yarn_model)]
    yarn_model: YarnModel,
    /// Yarn Young's modulus along the yarn [Pa] (aramid, Kevlar 29 class).
    #[arg(long, default_value_t = WovenBandParams::default().modulus)]
    modulus: f64,
    /// Yarn modulus across its width [Pa] (a bundle of filaments: small).
    #[arg(long, default_value_t = WovenBandParams::default().transverse_modulus)]
    transverse_modulus: f64,
    /// Yarn in-plane shear modulus [Pa].
    #[arg(long, default_value_t = WovenBandParams::default().shear_modulus)]
    shear_modulus: f64,
    /// Yarn density [kg/m³].
    #[arg(long, default_value_t = WovenBandParams::default().density)]
    density: f64,
    /// Yarn–yarn Coulomb friction coefficient.
    #[arg(long, default_value_t = WovenBandParams::default().friction)]
    friction: f64,
    /// Yarns carry no compression (tension field; its stress has no potential, so the
    /// energy balance drifts where the yarns are crushed).
    #[arg(long)]
    tension_field: bool,
    /// Fabric layers.
    #[arg(long, default_value_t = WovenBandParams::default().layers)]
    layers: usize,
    /// Clearance between layers [m].
    #[arg(long, default_value_t = WovenBandParams::default().layer_gap)]
    layer_gap: f64,
    /// Yarn ends at the patch edge: clamped (all nodes held), pinned (centre-line node
    /// held) or free. Ignored with --membrane-length (the ends are tied).
    #[arg(long, value_enum, default_value_t = WovenBandParams::default().edge)]
    edge: Edge,
    /// The paper's §3 combined model: tie the quarter patch's yarn ends to a graded
    /// orthotropic membrane around it, out to this half-size [m] (e.g. 0.06, the
    /// 60 × 60-yarn reference's), clamped at its outer edge. Adds the node sets
    /// `interface` (the tied yarn ends) and `axis_x_all` (the x axis through both).
    #[arg(long)]
    membrane_length: Option<f64>,
    /// With --membrane-length: growth ratio of the membrane's cells (p/2 at the patch) outwards.
    #[arg(long, requires = "membrane_length", default_value_t = Surround::default().growth)]
    membrane_growth: f64,
    /// Membrane areal density / the patch's (the paper's §3: 0.8).
    #[arg(long, requires = "membrane_length", default_value_t = Surround::default().membrane.density_ratio)]
    membrane_density_ratio: f64,
    /// Membrane E₁ = E₂ / the yarns' E (the paper's §3: 0.3).
    #[arg(long, requires = "membrane_length", default_value_t = Surround::default().membrane.modulus_ratio)]
    membrane_modulus_ratio: f64,
    /// Membrane G₁₂ / its E (the paper's §3: 0.0042).
    #[arg(long, requires = "membrane_length", default_value_t = Surround::default().membrane.shear_ratio)]
    membrane_shear_ratio: f64,
    /// Membrane thickness [m] (an assumption; default 2A/p per layer, the yarns' section
    /// per unit width of both families).
    #[arg(long, requires = "membrane_length")]
    membrane_thickness: Option<f64>,
    /// With --membrane-length: the membrane fails too, removed once the engineering strain
    /// of either fibre direction (x or y) reaches this, after the yarns' failure delay
    /// [default: it cannot fail]. The membrane is
    /// the fabric homogenised: the yarns' --failure-strain is its natural value, for a
    /// patch so small that the zone where yarns break reaches it.
    #[arg(long, requires = "membrane_length")]
    membrane_failure_strain: Option<f64>,
    /// Projectile nose shape.
    #[arg(long, value_enum, default_value_t = WovenBandParams::default().projectile_shape)]
    projectile_shape: ProjectileShape,
    /// Projectile radius [m].
    #[arg(long, default_value_t = WovenBandParams::default().projectile_radius)]
    projectile_radius: f64,
    /// Projectile mass [kg] (of the whole projectile; a quarter model carries a quarter).
    #[arg(long, default_value_t = WovenBandParams::default().projectile_mass)]
    projectile_mass: f64,
    /// Impact velocity [m/s].
    #[arg(long, default_value_t = WovenBandParams::default().projectile_velocity)]
    projectile_velocity: f64,
    /// Projectile–yarn friction coefficient.
    #[arg(long, default_value_t = WovenBandParams::default().projectile_friction)]
    projectile_friction: f64,
    #[command(flatten)]
    bullet: BulletArgs,
    /// Simulated time [s].
    #[arg(long, default_value_t = WovenBandParams::default().end_time)]
    end_time: f64,
    /// Output interval [s].
    #[arg(long, default_value_t = WovenBandParams::default().output_interval)]
    output_interval: f64,
    /// Safety factor on the stable time step, 0 < f ≤ 1 (analysis.parquet). The step is
    /// set from the undeformed bands; yarns under the nose, which do not fail, stretch
    /// towards 20 % Green strain by 60 µs and stiffen: 0.8 keeps such runs stable.
    #[arg(long, default_value_t = WovenBandParams::default().dt_safety)]
    dt_safety: f64,
    /// Yarn failure strain along the yarn (0: the yarns never fail, as in the paper's
    /// studies). Aramid yarn: 0.036 (Kevlar 29 yarn, 2.92 GPa at 3.6 %; the fibre's 4.0 %
    /// is an upper bound); with --weibull-modulus, the Weibull scale at the gauge length.
    #[arg(long, default_value_t = YarnFailure::default().strain)]
    failure_strain: f64,
    /// Statistical strengths: the Weibull modulus m of the failure strains (Kevlar yarns:
    /// 8–22), drawn from --seed per yarn or per element; left out, every yarn fails at
    /// --failure-strain.
    #[arg(long)]
    weibull_modulus: Option<f64>,
    /// Gauge length L₀ [m] of the Weibull scale [default: each yarn's modelled length].
    #[arg(long)]
    weibull_gauge_length: Option<f64>,
    /// Draw the strengths per yarn or per element (weakest link).
    #[arg(long, value_enum, default_value_t = YarnFailure::default().per)]
    strength_per: StrengthPer,
    /// Seed of the strengths: the same seed gives the same model bit for bit.
    #[arg(long, default_value_t = YarnFailure::default().seed)]
    seed: u64,
    /// Rate law of the failure strain, ε_f(ε̇) = ε_f (1 + C ln(ε̇/ε̇₀)) above ε̇₀: C (0: none).
    #[arg(long, default_value_t = YarnFailure::default().rate_coefficient)]
    failure_rate_coefficient: f64,
    /// The rate law's reference rate ε̇₀ [1/s].
    #[arg(long, default_value_t = YarnFailure::default().reference_rate)]
    failure_reference_rate: f64,
    /// Delay τ of the failure [s]: the strain is compared with the failure strain after
    /// a low-pass filter of time τ [default: ten element transits, 0.34 µs at 4 elements
    /// per mm: a struck yarn's first elements overshoot Smith's strain for about ten steps].
    #[arg(long)]
    failure_delay: Option<f64>,
    /// Viscous damping of the projectile's contact springs, a fraction of critical
    /// [default: 0.5 when the yarns can fail, 0 otherwise].
    #[arg(long)]
    projectile_contact_damping: Option<f64>,
    /// End the run once the projectile is arrested or has perforated (for ballistic
    /// sweeps; analysis.parquet's stop_on_outcome).
    #[arg(long)]
    stop_on_outcome: bool,
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
struct WovenArgs {
    /// Output model folder.
    #[arg(long)]
    out: PathBuf,
    /// Yarns per side of the full patch (even).
    #[arg(long, default_value_t = WovenParams::default().yarns)]
    yarns: usize,
    /// Yarn spacing p [m].
    #[arg(long, default_value_t = WovenParams::default().spacing)]
    spacing: f64,
    /// Yarn Young's modulus [Pa] (aramid).
    #[arg(long, default_value_t = WovenParams::default().yarn_modulus)]
    yarn_modulus: f64,
    /// Yarn density [kg/m³].
    #[arg(long, default_value_t = WovenParams::default().yarn_density)]
    yarn_density: f64,
    /// Yarn cross-section area [m²] (190 g/m² fabric at 1 mm spacing).
    #[arg(long, default_value_t = WovenParams::default().yarn_area)]
    yarn_area: f64,
    /// Let yarns carry compression too.
    #[arg(long)]
    compressible_yarns: bool,
    /// Yarn pretension as an initial strain ε₀ [–] (the yarns start with the force E·A·ε₀;
    /// see --pretension-start).
    #[arg(long, default_value_t = WovenParams::default().pretension_strain)]
    pretension_strain: f64,
    /// How a pretensioned model starts: `balanced` (the membrane around carries the same
    /// tension per width, N = E·A·ε₀/p, as an initial stress N/s: in equilibrium at t = 0
    /// for straight yarns), `relaxed` (balanced, then the crimped crossings settled by
    /// dynamic relaxation and written as initial displacements: for --crimp > 0) or
    /// `unbalanced` (only the yarns pre-strained: the membrane is pulled in and rings;
    /// the behaviour before the fix).
    #[arg(long, value_enum, default_value_t = WovenParams::default().pretension_start)]
    pretension_start: PretensionStart,
    /// Crimp: z offset of warp and weft at the crossings, ± [m].
    #[arg(long, default_value_t = WovenParams::default().crimp)]
    crimp: f64,
    /// Link stiffness k_x = k_y [N/m] (the paper's fitted 3.8661·10³ N/mm).
    #[arg(long, default_value_t = WovenParams::default().k_xy)]
    k_xy: f64,
    /// Link stiffness k_z [N/m] (the paper's fitted 5.2448·10⁶ N/mm).
    #[arg(long, default_value_t = WovenParams::default().k_z)]
    k_z: f64,
    /// Link dashpots c_x = c_y [N·s/m].
    #[arg(long, default_value_t = WovenParams::default().c_xy)]
    c_xy: f64,
    /// Link dashpot c_z [N·s/m].
    #[arg(long, default_value_t = WovenParams::default().c_z)]
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
    #[arg(long, value_enum, default_value_t = LinkAxes::of(&WovenParams::default()))]
    link_axes: LinkAxes,
    /// Membrane surround: its surface density over the woven patch's 2ρA/p [–] (the
    /// paper's §3: 0.8).
    #[arg(long, default_value_t = WovenParams::default().surround.density_ratio)]
    membrane_density_ratio: f64,
    /// Membrane surround: its Young's modulus over the yarn's [–] (the paper's §3: 0.3).
    #[arg(long, default_value_t = WovenParams::default().surround.modulus_ratio)]
    membrane_modulus_ratio: f64,
    /// Membrane surround: its shear modulus over its Young's modulus [–] (the paper's §3:
    /// 0.0042).
    #[arg(long, default_value_t = WovenParams::default().surround.shear_ratio)]
    membrane_shear_ratio: f64,
    /// Membrane surround: Poisson's ratio ν [–].
    #[arg(long, default_value_t = WovenParams::default().surround.poisson_ratio, allow_hyphen_values = true)]
    membrane_poisson: f64,
    /// Membrane surround: thickness s [m] (its density follows: ratio × 2ρA/p / s)
    /// [default: 2A/p].
    #[arg(long)]
    membrane_thickness: Option<f64>,
    /// Side of the whole model [m].
    #[arg(long, default_value_t = WovenParams::default().length)]
    length: f64,
    /// Growth ratio of the membrane cells away from the patch.
    #[arg(long, default_value_t = WovenParams::default().growth)]
    growth: f64,
    /// Where the patch meets the membrane: `crossing` (on the last crossing line x = np,
    /// whose yarns are halved) or `band-ends` (as `woven --membrane-length`: the last
    /// crossing line a full yarn, the rods running on to the membrane at (n + ½)p; quarter
    /// only; for comparing with the yarn-level patch).
    #[arg(long, value_enum, default_value_t = WovenParams::default().interface)]
    interface: Interface,
    /// Full model instead of the quarter.
    #[arg(long)]
    full: bool,
    /// Projectile nose: flat, round or sphere.
    #[arg(long, value_enum, default_value_t = WovenParams::default().projectile_shape)]
    projectile_shape: ProjectileShape,
    /// Projectile radius [m] (9 mm calibre).
    #[arg(long, default_value_t = WovenParams::default().projectile_radius)]
    projectile_radius: f64,
    /// Projectile mass [kg] (a quarter model carries a quarter).
    #[arg(long, default_value_t = WovenParams::default().projectile_mass)]
    projectile_mass: f64,
    /// Impact velocity [m/s].
    #[arg(long, default_value_t = WovenParams::default().projectile_velocity)]
    projectile_velocity: f64,
    /// Projectile–yarn Coulomb friction coefficient (the yarn-level `woven` patch's
    /// default is 0.1).
    #[arg(long, default_value_t = WovenParams::default().projectile_friction)]
    projectile_friction: f64,
    #[command(flatten)]
    bullet: BulletArgs,
    /// Simulated time [s].
    #[arg(long, default_value_t = WovenParams::default().end_time)]
    end_time: f64,
    /// Output interval [s].
    #[arg(long, default_value_t = WovenParams::default().output_interval)]
    output_interval: f64,
    /// Safety factor on the stable time step, 0 < f ≤ 1 (written to the model's
    /// analysis.parquet; the projectile's contact penalty κ m/Δt² stiffens with a shorter
    /// step).
    #[arg(long, default_value_t = WovenParams::default().dt_safety)]
    dt_safety: f64,
    /// Failure strain of the rods, their engineering axial strain (0: they never fail, as
    /// in the paper's §5). A rod spans a crossing spacing and runs straight, so the strain
    /// at which the reduced model perforates as the yarn-level patch does is fitted
    /// (`weft-fit --objective projectile --param yarns.eps_f,half_yarns.eps_f:…`); the
    /// yarn's own 0.036 is the trial value.
    #[arg(long, default_value_t = 0.0)]
    failure_strain: f64,
    /// Delay τ of the rods' failure [s]: the strain is compared after a low-pass filter of
    /// time τ [default: ten transits of a rod, p/√(E/ρ) each: 1.34 µs for the aramid at
    /// 1 mm].
    #[arg(long)]
    failure_delay: Option<f64>,
    /// The membrane surround fails too, removed once the engineering strain of either
    /// fibre direction (x or y) reaches this, after the rods' delay [default: it cannot
    /// fail].
    #[arg(long)]
    membrane_failure_strain: Option<f64>,
    /// Viscous damping of the projectile's contact springs, a fraction of critical
    /// [default: 0.5 when the rods can fail, 0 otherwise].
    #[arg(long)]
    projectile_contact_damping: Option<f64>,
    /// End the run once the projectile is arrested or has perforated (for ballistic
    /// sweeps: `weft-ballistic search`).
    #[arg(long)]
    stop_on_outcome: bool,
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

impl WovenArgs {
    fn params(&self) -> WovenParams {
        WovenParams {
            yarns: self.yarns,
            spacing: self.spacing,
            yarn_modulus: self.yarn_modulus,
            yarn_density: self.yarn_density,
            yarn_area: self.yarn_area,
            tension_only: !self.compressible_yarns,
            pretension_strain: self.pretension_strain,
            pretension_start: self.pretension_start,
            crimp: self.crimp,
            k_xy: self.k_xy,
            k_z: self.k_z,
            c_xy: self.c_xy,
            c_z: self.c_z,
            slip_force: self.slip_force,
            friction: self.link_friction,
            unilateral: self.unilateral_links,
            local_frame: self.link_axes == LinkAxes::Local,
            sliding: self.link_axes == LinkAxes::Sliding,
            surround: SurroundParams {
                density_ratio: self.membrane_density_ratio,
                modulus_ratio: self.membrane_modulus_ratio,
                shear_ratio: self.membrane_shear_ratio,
                poisson_ratio: self.membrane_poisson,
                thickness: self.membrane_thickness,
                failure_strain: self.membrane_failure_strain,
            },
            length: self.length,
            growth: self.growth,
            quarter: !self.full,
            interface: self.interface,
            projectile_shape: self.projectile_shape,
            projectile_radius: self.projectile_radius,
            projectile_mass: self.projectile_mass,
            projectile_velocity: self.projectile_velocity,
            projectile_friction: self.projectile_friction,
            end_time: self.end_time,
            output_interval: self.output_interval,
            dt_safety: self.dt_safety,
            // (Checked in `weave`, before the model is built.)
            bullet: self.bullet.params().ok().flatten(),
            failure: weft::generate::reduced_failure::ReducedFailure {
                strain: self.failure_strain,
                delay: self.failure_delay,
                contact_damping: self.projectile_contact_damping,
            },
            stop_on_outcome: self.stop_on_outcome,
        }
    }

    fn weave(&self) -> anyhow::Result<()> {
        self.bullet.params()?;
        let p = self.params();
        let m = weave(&Spec::WovenReduced(p.clone()), &self.out)?;
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
            self.out.display()
        );
        Ok(())
    }
}

impl WovenBandArgs {
    fn params(&self) -> WovenBandParams {
        WovenBandParams {
            yarns: self.yarns,
            quarter: !self.full,
            spacing: self.spacing,
            width: self.width,
            thickness: self.thickness,
            crimp_amplitude: self.crimp_amplitude,
            per_spacing: self.per_spacing,
            across: self.across,
            yarn_model: self.yarn_model,
            modulus: self.modulus,
            transverse_modulus: self.transverse_modulus,
            shear_modulus: self.shear_modulus,
            density: self.density,
            friction: self.friction,
            tension_field: self.tension_field,
            layers: self.layers,
            layer_gap: self.layer_gap,
            edge: self.edge,
            projectile_shape: self.projectile_shape,
            projectile_radius: self.projectile_radius,
            projectile_mass: self.projectile_mass,
            projectile_velocity: self.projectile_velocity,
            projectile_friction: self.projectile_friction,
            end_time: self.end_time,
            output_interval: self.output_interval,
            dt_safety: self.dt_safety,
            surround: self.membrane_length.map(|length| Surround {
                length,
                growth: self.membrane_growth,
                membrane: SurroundParams {
                    density_ratio: self.membrane_density_ratio,
                    modulus_ratio: self.membrane_modulus_ratio,
                    shear_ratio: self.membrane_shear_ratio,
                    thickness: self.membrane_thickness,
                    failure_strain: self.membrane_failure_strain,
                    ..SurroundParams::default()
                },
            }),
            failure: YarnFailure {
                strain: self.failure_strain,
                weibull_modulus: self.weibull_modulus,
                gauge_length: self.weibull_gauge_length,
                per: self.strength_per,
                seed: self.seed,
                rate_coefficient: self.failure_rate_coefficient,
                reference_rate: self.failure_reference_rate,
                delay: self.failure_delay,
                contact_damping: self.projectile_contact_damping,
            },
            stop_on_outcome: self.stop_on_outcome,
            // (Checked in `weave`, before the model is built.)
            bullet: self.bullet.params().ok().flatten(),
        }
    }

    fn weave(&self) -> anyhow::Result<()> {
        self.bullet.params()?;
        let m = weave(&Spec::Woven(self.params()), &self.out)?;
        eprintln!(
            "weft-weave woven: {} nodes, {} elements, {} contact definitions -> {}",
            m.num_nodes(),
            m.num_elements(),
            m.contacts.len(),
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
    }?;
    Ok(ExitCode::SUCCESS)
}

#[cfg(test)]
mod tests;
