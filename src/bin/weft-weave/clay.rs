//! `weft-weave clay-drop`'s flags: the backing clay (shared with the armour test's
//! packs) and the standard's drop.

use std::path::PathBuf;

use weft::generate::clay::{Clay, ClayBlock, ClayDropParams};
use weft::generate::weave::Spec;

/// The clay cells' integration (--clay-formulation).
#[derive(Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum ClayFormulation {
    OnePoint,
    SelectiveReduced,
}

/// The backing clay's constants and its block (defaults: Roma Plastilina No. 1 as the
/// model calibrates it, in NIJ Standard-0101.06's 610 × 610 × 140 mm box).
#[derive(clap::Args)]
pub struct ClayArgs {
    /// Clay density ρ [kg/m³].
    #[arg(long, default_value_t = Clay::roma().density)]
    clay_density: f64,
    /// Clay Young's modulus E [Pa].
    #[arg(long, default_value_t = Clay::roma().youngs_modulus)]
    clay_modulus: f64,
    /// Clay Poisson's ratio ν.
    #[arg(long, default_value_t = Clay::roma().poisson_ratio)]
    clay_poisson: f64,
    /// Plasticine A [Pa]: the flow stress at the reference rate, σ_y = (A + B ε_pⁿ)
    /// max(ε̇_p/ε̇₀, 1)ᵐ.
    #[arg(long, default_value_t = Clay::roma().a)]
    clay_a: f64,
    /// Plasticine B [Pa].
    #[arg(long, default_value_t = Clay::roma().b)]
    clay_b: f64,
    /// Plasticine hardening exponent n.
    #[arg(long, default_value_t = Clay::roma().n)]
    clay_n: f64,
    /// Plasticine rate exponent m (0: rate-independent).
    #[arg(long, default_value_t = Clay::roma().m)]
    clay_m: f64,
    /// Plasticine reference strain rate ε̇₀ [1/s].
    #[arg(long, default_value_t = Clay::roma().reference_rate)]
    clay_reference_rate: f64,
    /// Hourglass coefficient Q_hg of the clay's hexahedra [default: 0.1 for the drop,
    /// 0.3 under a pack (woven --backing clay)].
    #[arg(long)]
    clay_hourglass: Option<f64>,
    /// Erode (remove) a clay cell when its equivalent plastic strain reaches this: the
    /// cells a narrow load crushes toward inversion; the cells beneath then meet the pack
    /// [default: never for the drop, 1.5 under a pack; 0: never] (docs/theory.md,
    /// "The backing clay", "The pack on the clay").
    #[arg(long)]
    clay_erosion_strain: Option<f64>,
    /// The clay cells' integration: `one-point` (one point with the viscous hourglass
    /// control of --clay-hourglass) or `selective-reduced` (eight points for the
    /// deviatoric stress, the mean for the pressure: no hourglass modes and no
    /// coefficient, at several times the cost) (docs/theory.md, "The pack on the clay").
    #[arg(long, value_enum, default_value_t = ClayFormulation::OnePoint)]
    clay_formulation: ClayFormulation,
    /// Half the clay box's width [m] (quarter model: the block spans 0 to it in x and y)
    /// [default: 0.305, the standard's box].
    #[arg(long)]
    clay_half_width: Option<f64>,
    /// The clay block's depth [m] [default: 0.14, the standard's box].
    #[arg(long)]
    clay_depth: Option<f64>,
    /// The cells' size under the shot [m] [default: 3 mm for the drop, 1 mm under a
    /// pack].
    #[arg(long)]
    clay_fine: Option<f64>,
    /// Half-width of the fine zone [m] (from the axis) [default: 40 mm for the drop,
    /// 15 mm under a pack].
    #[arg(long)]
    clay_fine_half: Option<f64>,
    /// Depth of the fine zone [m] [default: 40 mm for the drop, 30 mm under a pack].
    #[arg(long)]
    clay_fine_depth: Option<f64>,
    /// Growth ratio of the cells beyond the fine zone [default: 1.4].
    #[arg(long)]
    clay_growth: Option<f64>,
}

impl ClayArgs {
    /// The clay, with `hourglass` and `erosion` where --clay-hourglass and
    /// --clay-erosion-strain are not given (an erosion strain of 0 is none).
    pub fn clay(&self, hourglass: f64, erosion: Option<f64>) -> Clay {
        Clay {
            density: self.clay_density,
            youngs_modulus: self.clay_modulus,
            poisson_ratio: self.clay_poisson,
            a: self.clay_a,
            b: self.clay_b,
            n: self.clay_n,
            m: self.clay_m,
            reference_rate: self.clay_reference_rate,
            hourglass: self.clay_hourglass.unwrap_or(hourglass),
            erosion_plastic_strain: self.clay_erosion_strain.or(erosion).filter(|&e| e != 0.0),
            selective_reduced: self.clay_formulation == ClayFormulation::SelectiveReduced,
        }
    }
    /// The block, `d`'s values where the flags are not given.
    pub fn block(&self, d: ClayBlock) -> ClayBlock {
        ClayBlock {
            half_width: self.clay_half_width.unwrap_or(d.half_width),
            depth: self.clay_depth.unwrap_or(d.depth),
            fine: self.clay_fine.unwrap_or(d.fine),
            fine_half: self.clay_fine_half.unwrap_or(d.fine_half),
            fine_depth: self.clay_fine_depth.unwrap_or(d.fine_depth),
            growth: self.clay_growth.unwrap_or(d.growth),
        }
    }
}

#[derive(clap::Args)]
pub struct ClayDropArgs {
    /// Output model folder (replaced atomically if it exists).
    #[arg(long)]
    out: PathBuf,
    #[command(flatten)]
    clay: ClayArgs,
    /// The sphere's diameter [m] (the standard's 63.5 mm).
    #[arg(long, default_value_t = ClayDropParams::default().diameter)]
    diameter: f64,
    /// The sphere's mass [kg] (the standard's 1043 g).
    #[arg(long, default_value_t = ClayDropParams::default().mass)]
    mass: f64,
    /// The drop height [m] (the standard's 2.0 m): the sphere strikes at √(2gh).
    #[arg(long, default_value_t = ClayDropParams::default().height)]
    height: f64,
    /// Coulomb friction between the sphere and the clay.
    #[arg(long, default_value_t = ClayDropParams::default().friction)]
    friction: f64,
    /// Simulated time [s]: long enough for the sphere to rebound off the clay.
    #[arg(long, default_value_t = ClayDropParams::default().end_time)]
    end_time: f64,
    /// Output interval [s].
    #[arg(long, default_value_t = ClayDropParams::default().output_interval)]
    output_interval: f64,
}

impl ClayDropArgs {
    pub fn params(&self) -> ClayDropParams {
        ClayDropParams {
            clay: self.clay.clay(Clay::roma().hourglass, None),
            block: self.clay.block(ClayBlock::default()),
            diameter: self.diameter,
            mass: self.mass,
            height: self.height,
            friction: self.friction,
            end_time: self.end_time,
            output_interval: self.output_interval,
        }
    }

    pub fn weave(&self) -> anyhow::Result<()> {
        let p = self.params();
        let m = super::weave(&Spec::ClayDrop(p.clone()), &self.out)?;
        eprintln!(
            "weft-weave clay-drop: {} nodes, {} hexahedra; a {} kg sphere {} m across at {:.3} m/s (dropped {} m) -> {}",
            m.num_nodes(),
            m.num_elements(),
            p.mass,
            p.diameter,
            p.velocity(),
            p.height,
            self.out.display()
        );
        Ok(())
    }
}
