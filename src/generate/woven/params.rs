//! The yarn-level patch's parameters ([`WovenBandParams`], every default a documented
//! aramid plain weave): the yarns' representation ([`YarnModel`]), the edge condition of
//! their ends ([`Edge`]) and the paper's §3 membrane around the patch ([`Surround`]).

use serde::Serialize;

use crate::generate::failure::{contact_damping, DELAY_TRANSITS};
use crate::generate::surround::SurroundParams;
use crate::model::ProjectileShape;

/// Edge condition of the yarn ends at the patch edge.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, clap::ValueEnum)]
#[serde(rename_all = "lowercase")]
pub enum Edge {
    /// Every node of a yarn end held in x, y and z.
    Clamped,
    /// Only the centre-line node of a yarn end held (the band can turn about it).
    Pinned,
    /// Nothing held.
    Free,
}

/// How a yarn is represented.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, clap::ValueEnum)]
#[serde(rename_all = "lowercase")]
pub enum YarnModel {
    /// A band of orthotropic membrane quads with the lenticular nodal thickness (the
    /// paper's reference; contact on the band faces).
    Band,
    /// A chain of trusses along the band's centre line, of the band's section and mass,
    /// with the band's centre thickness t_c as contact thickness (nodes and segments: a
    /// chain with a contact radius in place of the band): 4–6 × faster, for studies that
    /// need no yarn width (measured against the bands in docs/woven_patch.md, "The chain
    /// representation").
    Chain,
}

/// What a statistical strength is drawn for.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, clap::ValueEnum)]
#[serde(rename_all = "lowercase")]
pub enum StrengthPer {
    /// One draw per yarn: every element of the yarn has its strength.
    Yarn,
    /// One draw per element (weakest-link: a yarn's weakest element sets where it breaks).
    Element,
}

/// Yarn failure (docs/theory.md, "Failure, perforation and the ballistic limit").
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct YarnFailure {
    /// Failure strain ε_f along the yarn (0: the yarns never fail; aramid yarn: 0.036):
    /// with a Weibull modulus, the Weibull scale at the gauge length.
    pub strain: f64,
    /// Weibull modulus m of the strengths (None: every yarn fails at ε_f).
    pub weibull_modulus: Option<f64>,
    /// Gauge length L₀ of the Weibull scale [m] (None: each yarn's modelled length).
    pub gauge_length: Option<f64>,
    /// Drawn per yarn or per element.
    pub per: StrengthPer,
    /// Seed of the draws: the same seed, the same strengths, on any machine and thread count.
    pub seed: u64,
    /// The rate law's C and ε̇₀ [1/s] (C = 0: rate-independent).
    pub rate_coefficient: f64,
    pub reference_rate: f64,
    /// Delay τ of the failure [s] (None: ten element transits, L_e/c each; see
    /// `failure_delay` in docs/tables.md).
    pub delay: Option<f64>,
    /// The projectile's contact damping ζ (None: 0.5 when the yarns can fail, else 0).
    pub contact_damping: Option<f64>,
    /// Length ℓ of yarn a chain's strain is averaged over for its failure [m]
    /// (`failure_length` in docs/tables.md; None: 0, each element's own strain).
    pub length: Option<f64>,
}

impl Default for YarnFailure {
    fn default() -> Self {
        YarnFailure {
            // No failure by default: the paper's studies (§3, §5) model none, and a
            // ballistic study asks for it (`--failure-strain 0.036`, the aramid yarn's).
            strain: 0.0,
            weibull_modulus: None,
            gauge_length: None,
            per: StrengthPer::Yarn,
            seed: 1,
            rate_coefficient: 0.0,
            reference_rate: 1.0,
            delay: None,
            contact_damping: None,
            length: None,
        }
    }
}

impl WovenBandParams {
    /// The failure delay: the one given, or [`DELAY_TRANSITS`] element transits
    /// (spacing/per_spacing)/√(E/ρ) ([`crate::generate::failure`]).
    pub fn failure_delay(&self) -> f64 {
        self.failure.delay.unwrap_or_else(|| {
            DELAY_TRANSITS * self.spacing
                / self.per_spacing as f64
                / (self.modulus / self.density).sqrt()
        })
    }
    /// The projectile's contact damping: the one given, or 0.5 when the yarns can fail
    /// ([`contact_damping`]).
    pub fn contact_damping(&self) -> f64 {
        contact_damping(self.failure.contact_damping, self.failure.strain)
    }
}

/// Parameters of the yarn-level patch; every default is a documented aramid plain weave
/// (docs/theory.md, "Material data and defaults" and "The yarn-level woven patch").
#[derive(Debug, Clone, Serialize)]
pub struct WovenBandParams {
    /// Yarns per side: of the quarter (the middle yarn, on the symmetry plane, counted
    /// once) or of the full patch (even).
    pub yarns: usize,
    /// Quarter model with symmetry planes x = 0, y = 0.
    pub quarter: bool,
    /// Yarn spacing p [m]: 1 mm, the reduced model's (10 yarns/cm; docs/theory.md,
    /// "Material data and defaults": ≈ 8.5).
    pub spacing: f64,
    /// Yarn width w [m] and thickness h [m]: 0.8 mm × 0.124 mm, a lenticular area of
    /// 6.6·10⁻⁸ m², the reduced model's yarn area (190 g/m² with p = 1 mm).
    pub width: f64,
    pub thickness: f64,
    /// Crimp amplitude a [m] (None: crossing yarns just touch).
    pub crimp_amplitude: Option<f64>,
    /// Quads per spacing along a yarn (≥ 4) and across its width (≥ 2, even).
    pub per_spacing: usize,
    pub across: usize,
    /// Bands (the reference) or truss chains.
    pub yarn_model: YarnModel,
    /// Yarn material: E along the yarn [Pa] (Kevlar 29 class, 70–90 GPa), E across and
    /// the in-plane shear modulus [Pa] (a bundle of filaments: small; assumed E/50 and
    /// E/100), density [kg/m³].
    pub modulus: f64,
    pub transverse_modulus: f64,
    pub shear_modulus: f64,
    pub density: f64,
    /// Yarn–yarn Coulomb friction (docs/theory.md, "Material data and defaults": 0.1–0.2).
    pub friction: f64,
    /// Yarns carry no compressive stress (tension field).
    pub tension_field: bool,
    /// Layers, and the clearance between them [m].
    pub layers: usize,
    pub layer_gap: f64,
    pub edge: Edge,
    /// Projectile: 9 mm, 8 g, round-nosed at 400 m/s (docs/theory.md, "Material data and
    /// defaults": 360–430 m/s); friction against the yarns.
    pub projectile_shape: ProjectileShape,
    pub projectile_radius: f64,
    pub projectile_mass: f64,
    pub projectile_velocity: f64,
    pub projectile_friction: f64,
    /// Simulated time [s] (the paper's Fig. 4: 6·10⁻⁵ s) and output interval [s].
    pub end_time: f64,
    pub output_interval: f64,
    /// Safety factor on the stable step (0.9, the solver's default: the yarns under the
    /// nose, which do not fail, stiffen as they stretch; 0.8 carries the §3 models to
    /// 60 µs).
    pub dt_safety: f64,
    /// The paper's §3 combined model: the patch's yarn ends tied to a graded orthotropic
    /// membrane around it (None: the patch alone, its ends held by `edge`).
    pub surround: Option<Surround>,
    /// Yarn failure and statistical strengths.
    pub failure: YarnFailure,
    /// End the run once the projectile is arrested or has perforated (analysis
    /// `stop_on_outcome`: a ballistic sweep's runs).
    pub stop_on_outcome: bool,
    /// A deformable bullet of hexahedra instead of the rigid projectile (its diameter
    /// twice `projectile_radius`, its mass `projectile_mass`, at `projectile_velocity`,
    /// friction `projectile_friction`): [`crate::generate::bullet`]. None: rigid.
    pub bullet: Option<crate::generate::bullet::BulletParams>,
    /// The armour test's backing: the pack laid on a block of clay (its edges then free:
    /// the clay holds it), [`crate::generate::clay`]. None: the pack in air.
    pub backing: Option<crate::generate::clay::Backing>,
}

/// A graded orthotropic membrane around a quarter patch (the paper's §3: a small woven
/// patch coupled to a membrane whose ρ, E and G carry the waves on). The band ends at
/// x = c and y = c, c = (N − ½)p, are tied to the membrane's inner edge (each end node to
/// the membrane edge it lies on, linear weights); the membrane is clamped at its outer
/// edge; `edge` no longer applies. Membrane cells are p/2 at the patch and grow by
/// `growth` outwards; one sheet per layer, each with one layer's share of the patch's
/// surface density ([`SurroundParams`], the reduced model's surround too).
#[derive(Debug, Clone, Serialize)]
pub struct Surround {
    /// Outer half-size of the model [m] (the reference patch's: 60 mm for 60 yarns).
    pub length: f64,
    /// Growth ratio of the membrane cells away from the patch (≥ 1).
    pub growth: f64,
    /// The membrane's properties relative to the yarns, and its failure (defaults: the
    /// paper's §3 ratios).
    #[serde(flatten)]
    pub membrane: SurroundParams,
}

impl Default for Surround {
    /// The paper's §3 ratios around the 60 × 60-yarn reference patch, out to 60 mm
    /// ([`Surround::paper`]).
    fn default() -> Self {
        Surround::paper(0.06)
    }
}

impl Surround {
    /// The paper's §3 ratios ([`SurroundParams::paper`]) around a patch, out to `length`,
    /// its cells growing by 1.2.
    pub fn paper(length: f64) -> Surround {
        Surround {
            length,
            growth: 1.2,
            membrane: SurroundParams::paper(),
        }
    }
}

impl Default for WovenBandParams {
    fn default() -> Self {
        WovenBandParams {
            // The paper's 120 × 120 reference (Fig. 2b) as a quarter. A 10 × 10 quarter
            // (its small patch) alone, clamped, at 400 m/s strains its yarns beyond 50 %
            // within 16 µs (no failure is modelled) and the run breaks down: it is meant to
            // be tied into a membrane (the §3 study).
            yarns: 60,
            quarter: true,
            spacing: 1e-3,
            width: 0.8e-3,
            thickness: 0.124e-3,
            crimp_amplitude: None,
            per_spacing: 4,
            across: 2,
            yarn_model: YarnModel::Band,
            modulus: 80e9,
            transverse_modulus: 1.6e9,
            shear_modulus: 0.8e9,
            density: 1440.0,
            friction: 0.15,
            tension_field: false,
            layers: 1,
            layer_gap: 0.01e-3,
            edge: Edge::Clamped,
            projectile_shape: ProjectileShape::Round,
            projectile_radius: 4.5e-3,
            projectile_mass: 8e-3,
            projectile_velocity: 400.0,
            projectile_friction: 0.1,
            end_time: 6e-5,
            output_interval: 1e-6,
            dt_safety: 0.9,
            surround: None,
            failure: YarnFailure::default(),
            stop_on_outcome: false,
            bullet: None,
            backing: None,
        }
    }
}
