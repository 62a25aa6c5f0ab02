//! The reduced woven model's parameters ([`WovenParams`], the paper's §5 model by
//! default), how a pretensioned model starts ([`PretensionStart`]), where the patch meets
//! its membrane surround ([`Interface`]), and their checks.

use serde::Serialize;

use crate::error::{Result, WeftError};
use crate::generate::reduced_failure::ReducedFailure;
use crate::generate::surround::{MembraneProps, SurroundParams};
use crate::model::striker::check_striking_speed;
use crate::model::ProjectileShape;

/// How a pretensioned reduced model starts.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, clap::ValueEnum)]
#[serde(rename_all = "lowercase")]
pub enum PretensionStart {
    /// In equilibrium: the yarns carry E·A·ε₀ and the surrounding membrane the same
    /// tension per unit length, N = E·A·ε₀/p in both directions, as an initial stress N/s
    /// (a uniformly pre-stressed sheet held at its outer edge), so that the yarn ends
    /// pull on a membrane that pulls back as much. Exact for straight yarns (no crimp).
    Balanced,
    /// Balanced, then relaxed: the crimped crossings, which a pretension presses against
    /// their links, settle by dynamic relaxation (local damping, `Solver::relax`, the
    /// projectile set aside, the links' sliders held stuck so that the start owes
    /// nothing to a slip the run would not inherit, and unilateral normals relaxed as
    /// two-way springs, then checked to be all in compression, where the two laws
    /// agree: the kink at contact made the damped relaxation chatter without
    /// converging, measured), and the settled positions become the model's initial
    /// displacements u₀. For crimped yarns.
    Relaxed,
    /// The yarns alone pre-strained (the membrane unstressed): an unbalanced start that
    /// pulls the membrane in and rings (the behaviour before the fix, kept to compare).
    Unbalanced,
}

/// Where the reduced patch meets its membrane surround.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, clap::ValueEnum)]
#[serde(rename_all = "kebab-case")]
pub enum Interface {
    /// On the last crossing line (x = c = np): the yarns along it are halved (the membrane
    /// carries the other half of their strip) and its crossings lie flat on the membrane.
    Crossing,
    /// As the yarn-level patch tied by `woven --membrane-length`: every crossing line
    /// 0 … np a full yarn (halved only on a symmetry plane), crimped, and the rods run on
    /// half a spacing past the last crossing to the membrane's edge at c = (n + ½)p, where
    /// their ends are tied; the membrane's cells there are p/2 wide. Quarter models only.
    BandEnds,
}

/// `woven-reduced`: the reduced woven model of the paper's §5.
#[derive(Debug, Clone, Serialize)]
pub struct WovenParams {
    /// Yarns per side of the full patch (even).
    pub yarns: usize,
    /// Yarn spacing p [m].
    pub spacing: f64,
    /// Yarn: E [Pa], ρ [kg/m³], cross-section area [m²], tension only.
    pub yarn_modulus: f64,
    pub yarn_density: f64,
    pub yarn_area: f64,
    pub tension_only: bool,
    /// Initial yarn strain (pretension) ε₀.
    pub pretension_strain: f64,
    /// How a pretensioned model starts (ignored when ε₀ = 0).
    pub pretension_start: PretensionStart,
    /// Crimp: z offset ± of warp and weft nodes at the crossings [m].
    pub crimp: f64,
    /// Links: k_x = k_y, k_z [N/m], c_x, c_y, c_z [N·s/m], slip force [N] (None: none).
    pub k_xy: f64,
    pub k_z: f64,
    pub c_xy: f64,
    pub c_z: f64,
    pub slip_force: Option<f64>,
    /// Coulomb friction coefficient μ of the links (slip at μ·N, N the normal spring's
    /// compressive force) [–]; `None`: none. Not with `slip_force`.
    pub friction: Option<f64>,
    /// The links' normal spring pushes the yarns apart and never pulls them together.
    pub unilateral: bool,
    /// The links act in the crossing's local frame (the two yarn directions and their
    /// normal, following the fabric) instead of global x, y, z.
    pub local_frame: bool,
    /// The links' ends slide along their yarns when the links slip
    /// ([`crate::solver::sliding_link`]), in the frame of the yarns' tangents there.
    pub sliding: bool,
    /// Whole model side [m], coarse membrane growth ratio, quarter symmetry.
    pub length: f64,
    pub growth: f64,
    pub quarter: bool,
    /// Where the patch meets the membrane.
    pub interface: Interface,
    /// The equivalent membrane around the patch, relative to the yarns.
    pub surround: SurroundParams,
    /// Projectile: flat-nosed by default.
    pub projectile_shape: ProjectileShape,
    pub projectile_radius: f64,
    pub projectile_mass: f64,
    pub projectile_velocity: f64,
    /// Projectile–yarn Coulomb friction μ (0: frictionless, the paper's reduced model).
    pub projectile_friction: f64,
    pub end_time: f64,
    pub output_interval: f64,
    /// Safety factor on the stable step [–], 0 < f ≤ 1 (the model's `dt_safety`; 0.9 by
    /// default): the projectile's contact penalty is κ m*/Δt².
    pub dt_safety: f64,
    /// A deformable bullet of hexahedra instead of the rigid projectile (diameter twice
    /// `projectile_radius`, mass `projectile_mass`, at `projectile_velocity`, friction
    /// `projectile_friction`; its faces and nodes in contact with the yarns' trusses, of
    /// contact thickness √(4A/π)): [`crate::generate::bullet`]. None: rigid.
    pub bullet: Option<crate::generate::bullet::BulletParams>,
    /// The rods' failure (none by default, as in the paper's §5).
    pub failure: ReducedFailure,
    /// End the run at the projectile's outcome (analysis.parquet's `stop_on_outcome`: a
    /// ballistic sweep's runs).
    pub stop_on_outcome: bool,
}

impl Default for WovenParams {
    /// [`WovenParams::paper`].
    fn default() -> Self {
        WovenParams::paper()
    }
}

impl WovenParams {
    /// The paper's §5 model (docs/theory.md, "The paper's studies" and "Material data and
    /// defaults"): aramid yarns 1 mm apart (E = 80 GPa, ρ = 1440 kg/m³, 190 g/m²
    /// together: A = 6.6·10⁻⁸ m² per yarn), links at the fitted k_x = k_y = 3.8661·10⁶ N/m,
    /// k_z = 5.2448·10⁹ N/m (the paper's N/mm values, its exponents corrected), a 9 mm, 8 g
    /// flat-nosed projectile at 400 m/s; the equivalent membrane from the paper's §3
    /// ratios ([`SurroundParams::paper`]).
    pub fn paper() -> WovenParams {
        WovenParams {
            yarns: 20,
            spacing: 1e-3,
            yarn_modulus: 80e9,
            yarn_density: 1440.0,
            yarn_area: 6.6e-8,
            tension_only: true,
            pretension_strain: 0.0,
            pretension_start: PretensionStart::Balanced,
            crimp: 0.0,
            k_xy: 3.8661e6,
            k_z: 5.2448e9,
            c_xy: 0.0,
            c_z: 0.0,
            slip_force: None,
            friction: None,
            unilateral: false,
            local_frame: false,
            sliding: false,
            length: 0.1,
            growth: 1.25,
            quarter: true,
            interface: Interface::Crossing,
            surround: SurroundParams::paper(),
            projectile_shape: ProjectileShape::Flat,
            projectile_radius: 4.5e-3,
            projectile_mass: 8e-3,
            projectile_velocity: 400.0,
            projectile_friction: 0.0,
            end_time: 5e-5,
            output_interval: 1e-6,
            dt_safety: 0.9,
            bullet: None,
            failure: ReducedFailure::default(),
            stop_on_outcome: false,
        }
    }

    /// Surface density of the woven patch, 2ρA/p [kg/m²]: two yarn families, one yarn of
    /// section A per spacing p each.
    pub fn patch_surface_density(&self) -> f64 {
        2.0 * self.yarn_density * self.yarn_area / self.spacing
    }

    /// The surrounding membrane's properties from the yarns and the ratios of
    /// [`SurroundParams`]: s (2A/p unless given), ρ_m = r_ρ (2ρA/p)/s, E_m = r_E E_y,
    /// G_m = r_G E_m.
    pub fn membrane(&self) -> MembraneProps {
        self.surround.props(
            self.yarn_modulus,
            self.patch_surface_density(),
            2.0 * self.yarn_area / self.spacing,
        )
    }

    /// Yarn tension per unit width of the patch at the pretension, N = E A ε₀/p [N/m].
    pub fn pretension_per_width(&self) -> f64 {
        self.yarn_modulus * self.yarn_area * self.pretension_strain / self.spacing
    }

    /// Every parameter in its range, the first one out named by its flag.
    pub(super) fn check(&self) -> Result<()> {
        if self.yarns < 2 || !self.yarns.is_multiple_of(2) {
            return Err(WeftError::input(format!("--yarns = `{}`", self.yarns))
                .expected("an even number ≥ 2 (a crossing at the centre)"));
        }
        if self.interface == Interface::BandEnds && !self.quarter {
            return Err(
                WeftError::input("--interface band-ends with --full".to_string())
                    .expected("a quarter model (the band ends of a full patch lie on both sides)")
                    .hint("leave out --full, or use --interface crossing"),
            );
        }
        let positive = [
            ("spacing", "m", self.spacing),
            ("yarn-modulus", "Pa", self.yarn_modulus),
            ("yarn-density", "kg/m³", self.yarn_density),
            ("yarn-area", "m²", self.yarn_area),
            ("k-z", "N/m", self.k_z),
            ("k-xy", "N/m", self.k_xy),
            ("projectile-mass", "kg", self.projectile_mass),
            ("projectile-radius", "m", self.projectile_radius),
        ];
        for (n, unit, v) in positive {
            if !(v > 0.0 && v.is_finite()) {
                return Err(WeftError::input(format!("--{n} = `{v}`"))
                    .expected(format!("a value > 0 in {unit}")));
            }
        }
        self.surround.check()?;
        self.failure.check()?;
        if !(self.dt_safety > 0.0 && self.dt_safety <= 1.0) {
            return Err(
                WeftError::input(format!("--dt-safety = `{}`", self.dt_safety))
                    .expected("a safety factor 0 < f ≤ 1 on the stable step"),
            );
        }
        check_striking_speed("--projectile-velocity", self.projectile_velocity)?;
        if !(self.crimp >= 0.0 && self.crimp < self.spacing) {
            return Err(
                WeftError::input(format!("--crimp = `{}`", self.crimp)).expected(format!(
                    "an offset 0 ≤ a < the spacing {} m (warp and weft at ±a, alternating)",
                    self.spacing
                )),
            );
        }
        let pf = self.projectile_friction;
        if !(pf >= 0.0 && pf.is_finite()) {
            return Err(WeftError::input(format!("--projectile-friction = `{pf}`"))
                .expected("a Coulomb coefficient μ ≥ 0"));
        }
        if let Some(mu) = self.friction {
            if !(mu >= 0.0 && mu.is_finite()) {
                return Err(WeftError::input(format!("--link-friction = `{mu}`"))
                    .expected("a Coulomb coefficient μ ≥ 0"));
            }
            if let Some(f) = self.slip_force {
                return Err(WeftError::input(format!(
                    "--link-friction = `{mu}` and --slip-force = `{f}` together"
                ))
                .expected("one slip law: Coulomb friction μ·N or a constant slip force")
                .hint("drop one of the two"));
            }
        }
        Ok(())
    }
}
