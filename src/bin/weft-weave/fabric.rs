//! The flags that `woven` and `woven-reduced` share, each declared once in a group that
//! both flatten into their arguments: the output folder ([`OutArgs`]), the patch's
//! extent and spacing ([`PatchArgs`]), the membrane surround ([`SurroundArgs`]), the
//! projectile ([`ProjectileArgs`], the deformable bullet's flags within), the run
//! ([`RunArgs`]) and the ballistic flags ([`BallisticArgs`]: failure delay, contact
//! damping, the stop at the outcome).
//!
//! A group whose defaults differ between the two generators is generic over the
//! generator's parameters `G` ([`Fabric`]), each flag's default taken from `G::default()`:
//! `woven`'s from [`WovenBandParams`], `woven-reduced`'s from [`WovenParams`]. (Those
//! defaults are given as `default_value`, not `default_value_t`: clap's derive caches a
//! `default_value_t` in a static, which a generic group's two instances would share.)
//! The groups carry `//` comments, not doc comments: clap takes a flattened struct's
//! doc comment as the subcommand's about.

use std::marker::PhantomData;
use std::path::PathBuf;

use clap::ValueEnum;

use super::bullet::BulletArgs;
use weft::generate::surround::SurroundParams;
use weft::generate::woven::WovenBandParams;
use weft::generate::woven_reduced::WovenParams;
use weft::model::ProjectileShape;

/// What a woven generator's parameters give the shared flags as their defaults.
pub struct Shared {
    pub spacing: f64,
    pub projectile_shape: ProjectileShape,
    pub projectile_radius: f64,
    pub projectile_mass: f64,
    pub projectile_velocity: f64,
    pub projectile_friction: f64,
    pub end_time: f64,
    pub output_interval: f64,
    pub dt_safety: f64,
}

/// A woven generator's parameters, whose defaults its shared flags show.
pub trait Fabric: 'static {
    /// The shared flags' defaults: this generator's `Default`.
    fn shared() -> Shared;
}

/// Both generators name the shared fields alike.
macro_rules! fabric {
    ($($params:ty),*) => {$(
        impl Fabric for $params {
            fn shared() -> Shared {
                let d = <$params>::default();
                Shared {
                    spacing: d.spacing,
                    projectile_shape: d.projectile_shape,
                    projectile_radius: d.projectile_radius,
                    projectile_mass: d.projectile_mass,
                    projectile_velocity: d.projectile_velocity,
                    projectile_friction: d.projectile_friction,
                    end_time: d.end_time,
                    output_interval: d.output_interval,
                    dt_safety: d.dt_safety,
                }
            }
        }
    )*};
}
fabric!(WovenBandParams, WovenParams);

/// A default as clap shows and parses it (as `default_value_t` writes it). The string
/// lives as long as the program: a few per subcommand, made once per parse.
fn shown(v: impl ToString) -> &'static str {
    Box::leak(v.to_string().into_boxed_str())
}

/// A value enum's default, by its flag value's name.
fn shown_enum(v: impl ValueEnum) -> &'static str {
    shown(v.to_possible_value().expect("not skipped").get_name())
}

// Where the model is written.
#[derive(clap::Args)]
pub struct OutArgs {
    /// Output model folder (replaced atomically if it exists).
    #[arg(long)]
    pub out: PathBuf,
}

// The patch's extent (a quarter or the whole) and its yarn spacing.
#[derive(clap::Args)]
pub struct PatchArgs<G: Fabric> {
    /// The full model instead of the quarter (symmetry planes x = 0, y = 0).
    #[arg(long)]
    pub full: bool,
    /// Yarn spacing p [m].
    #[arg(long, default_value = shown(G::shared().spacing))]
    pub spacing: f64,
    #[arg(skip)]
    fabric: PhantomData<G>,
}

// The membrane around the patch, relative to it: the paper's §3 ratios, its thickness
// and failure ([`SurroundParams`]). `woven` asks for --membrane-length with any of them.
#[derive(clap::Args)]
pub struct SurroundArgs {
    /// Membrane surround: its surface density over the woven patch's [–] (per layer: the
    /// yarns' mass per unit area, 2ρA/p for straight yarns; the paper's §3: 0.8).
    #[arg(long, default_value_t = SurroundParams::default().density_ratio)]
    pub membrane_density_ratio: f64,
    /// Membrane surround: its Young's modulus E₁ = E₂ over the yarns' E [–] (the paper's
    /// §3: 0.3).
    #[arg(long, default_value_t = SurroundParams::default().modulus_ratio)]
    pub membrane_modulus_ratio: f64,
    /// Membrane surround: its shear modulus G₁₂ over its Young's modulus [–] (the paper's
    /// §3: 0.0042).
    #[arg(long, default_value_t = SurroundParams::default().shear_ratio)]
    pub membrane_shear_ratio: f64,
    /// Membrane surround: thickness s [m], an assumption (its density follows: ratio × the
    /// patch's surface density / s) [default: 2A/p per layer, the yarns' section per unit
    /// width of both families].
    #[arg(long)]
    pub membrane_thickness: Option<f64>,
    /// Membrane surround: it fails too, removed once the engineering strain of either
    /// fibre direction (x or y) reaches this, after the yarns' failure delay [default: it
    /// cannot fail]. The membrane is the fabric homogenised: the yarn's failure strain is
    /// its natural value, for a patch so small that the zone where yarns break reaches it.
    #[arg(long)]
    pub membrane_failure_strain: Option<f64>,
}

impl SurroundArgs {
    /// The surround's parameters, its Poisson's ratio `poisson_ratio` (a flag of
    /// `woven-reduced` alone).
    pub fn params(&self, poisson_ratio: f64) -> SurroundParams {
        SurroundParams {
            density_ratio: self.membrane_density_ratio,
            modulus_ratio: self.membrane_modulus_ratio,
            shear_ratio: self.membrane_shear_ratio,
            poisson_ratio,
            thickness: self.membrane_thickness,
            failure_strain: self.membrane_failure_strain,
        }
    }
}

// The projectile: a rigid shape, or the deformable bullet of the same size and mass.
#[derive(clap::Args)]
pub struct ProjectileArgs<G: Fabric> {
    /// Projectile nose shape.
    #[arg(long, value_enum, default_value = shown_enum(G::shared().projectile_shape))]
    pub projectile_shape: ProjectileShape,
    /// Projectile radius [m] (9 mm calibre).
    #[arg(long, default_value = shown(G::shared().projectile_radius))]
    pub projectile_radius: f64,
    /// Projectile mass [kg] (of the whole projectile; a quarter model carries a quarter).
    #[arg(long, default_value = shown(G::shared().projectile_mass))]
    pub projectile_mass: f64,
    /// Impact velocity [m/s].
    #[arg(long, default_value = shown(G::shared().projectile_velocity))]
    pub projectile_velocity: f64,
    /// Projectile–yarn Coulomb friction coefficient (the yarn-level `woven` patch's
    /// default is 0.1, the reduced model's 0, as the paper's §5).
    #[arg(long, default_value = shown(G::shared().projectile_friction))]
    pub projectile_friction: f64,
    #[command(flatten)]
    pub bullet: BulletArgs,
    #[arg(skip)]
    fabric: PhantomData<G>,
}

// The run: the analysis written to the model.
#[derive(clap::Args)]
pub struct RunArgs<G: Fabric> {
    /// Simulated time [s].
    #[arg(long, default_value = shown(G::shared().end_time))]
    pub end_time: f64,
    /// Output interval [s].
    #[arg(long, default_value = shown(G::shared().output_interval))]
    pub output_interval: f64,
    /// Safety factor on the stable time step, 0 < f ≤ 1 (written to the model's
    /// analysis.parquet; the projectile's contact penalty κ m/Δt² stiffens with a shorter
    /// step). The step is set from the undeformed yarns, which stiffen as they stretch
    /// under the nose: the yarn-level bands, which do not fail, reach 20 % Green strain by
    /// 60 µs, and 0.8 keeps such runs stable.
    #[arg(long, default_value = shown(G::shared().dt_safety))]
    pub dt_safety: f64,
    #[arg(skip)]
    fabric: PhantomData<G>,
}

// Failure's delay and the nose's damping once yarns fail, and the run's end at the
// projectile's outcome.
#[derive(clap::Args)]
pub struct BallisticArgs {
    /// Delay τ of the failure [s]: the strain is compared with the failure strain after
    /// a low-pass filter of time τ [default: ten transits of an element, L_e/√(E/ρ) each:
    /// 0.34 µs for the yarn-level patch at 4 elements per mm (a struck yarn's first
    /// elements overshoot Smith's strain for about ten steps), 1.34 µs for the reduced
    /// model's rods of the aramid at 1 mm].
    #[arg(long)]
    pub failure_delay: Option<f64>,
    /// Viscous damping of the projectile's contact springs, a fraction of critical
    /// [default: 0.5 when the yarns can fail (--failure-strain > 0), 0 otherwise].
    #[arg(long)]
    pub projectile_contact_damping: Option<f64>,
    /// End the run once the projectile is arrested or has perforated (analysis.parquet's
    /// stop_on_outcome: for ballistic sweeps, `weft-ballistic search`).
    #[arg(long)]
    pub stop_on_outcome: bool,
}
