//! Part properties, each defined once: the [`PartProps`] struct and the descriptor table
//! [`PROPERTIES`] are generated from the same list by `part_properties!`.
//!
//! A property's descriptor gives its column of `parts.parquet` (also its field name and
//! its name in `weft-fit --param PART.PROPERTY`), its type (float64 or bool, always
//! nullable), its unit, the element kinds it applies to with the [`Rule`] its value must
//! satisfy for each, what a null means and why, the short aliases `weft-fit` accepts, and
//! a one-line meaning. Everything that lists part properties is driven by the table:
//! reading and writing `parts.parquet` ([`read_columns`], [`columns`]), the checks and
//! their messages ([`Property::check`], used by [`super::validate_part`]), the properties
//! and aliases `weft-fit` accepts ([`fittable`], [`resolve_alias`]), and the
//! `parts.parquet` section of `docs/tables.md` ([`parts_table_markdown`]; the test
//! `tests/docs_drift.rs` fails when the two differ, and `WEFT_BLESS=1 cargo test --release
//! --test docs_drift` rewrites the section).
//!
//! The table's order is the column order of `parts.parquet` as written.

use super::kinds::ElementKind::{self, Beam, Hex, Link, PointMass, Quad, Tri, Truss};
use crate::error::{Result, WeftError};
use crate::table::{Col, Table};

/// What a property's value must satisfy for one element kind.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Rule {
    /// Must be given, finite and > 0.
    Required,
    /// Must be given, finite and ≥ 0 (a truss's density: 0 makes it a massless spring).
    RequiredNonNegative,
    /// May be null; when given, finite and > 0.
    Positive,
    /// May be null; when given, finite and ≥ 0.
    NonNegative,
    /// May be null; when given, lo < value < hi. `expected` says so in the property's
    /// symbols.
    Open {
        lo: f64,
        hi: f64,
        expected: &'static str,
    },
    /// May be null; when given, finite.
    Finite,
    /// No check of its own (booleans; ν₁₂, which `validate_part` checks against E₂/E₁).
    Free,
}

/// What a null means for an optional property, and why that default.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Null {
    /// The value or behaviour a null stands for (`0.1`, `false`, `no slider`).
    pub means: &'static str,
    /// Why that default.
    pub reason: &'static str,
}

/// Get and set one field of [`PartProps`], by the property's type.
#[derive(Clone, Copy)]
pub enum Access {
    F64 {
        get: fn(&PartProps) -> Option<f64>,
        slot: fn(&mut PartProps) -> &mut Option<f64>,
    },
    Bool {
        get: fn(&PartProps) -> Option<bool>,
        slot: fn(&mut PartProps) -> &mut Option<bool>,
    },
    /// A name (the `material` law); its column is written only when some part sets it.
    Str {
        get: fn(&PartProps) -> Option<String>,
        slot: fn(&mut PartProps) -> &mut Option<String>,
    },
}

/// One part property (a nullable column of `parts.parquet`).
#[derive(Clone, Copy)]
pub struct Property {
    /// Column name, field name of [`PartProps`], and name in `weft-fit --param`.
    pub name: &'static str,
    /// SI unit; empty when dimensionless.
    pub unit: &'static str,
    /// Element kinds the property applies to, each with the rule its value obeys.
    pub kinds: &'static [(ElementKind, Rule)],
    /// What a null means; `None` when the property is required wherever it applies.
    pub null: Option<Null>,
    /// Short names `weft-fit --param` accepts (`E`, `G12`).
    pub aliases: &'static [&'static str],
    /// One-line meaning, with its symbol.
    pub meaning: &'static str,
    pub access: Access,
}

impl std::fmt::Debug for Property {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Property")
            .field("name", &self.name)
            .field("unit", &self.unit)
            .field("kinds", &self.kinds)
            .finish_non_exhaustive()
    }
}

/// Declares the part properties once: generates the fields of [`PartProps`] (each an
/// `Option` of the property's type, documented with its meaning and unit) and the
/// descriptor table [`PROPERTIES`], in the same order.
macro_rules! part_properties {
    ($(
        $field:ident: $ty:ident {
            unit: $unit:literal,
            kinds: [$($kind:ident: $rule:expr),+ $(,)?],
            null: $null:expr,
            aliases: [$($alias:literal),* $(,)?],
            meaning: $meaning:literal $(,)?
        }
    ),+ $(,)?) => {
        /// Part properties. Which ones apply depends on the part's element kind (see
        /// [`PROPERTIES`] and `docs/tables.md`); the others stay `None`.
        #[derive(Debug, Clone, Default, PartialEq)]
        pub struct PartProps {
            $(
                #[doc = concat!($meaning, " [", $unit, "]")]
                pub $field: Option<$ty>,
            )+
        }

        /// Every part property, in the column order of `parts.parquet`.
        pub const PROPERTIES: &[Property] = &[$(
            Property {
                name: stringify!($field),
                unit: $unit,
                kinds: &[$(($kind, $rule)),+],
                null: $null,
                aliases: &[$($alias),*],
                meaning: $meaning,
                access: part_properties!(@access $ty $field),
            },
        )+];
    };
    (@access f64 $field:ident) => {
        Access::F64 {
            get: {
                fn get(p: &PartProps) -> Option<f64> {
                    p.$field
                }
                get
            },
            slot: {
                fn slot(p: &mut PartProps) -> &mut Option<f64> {
                    &mut p.$field
                }
                slot
            },
        }
    };
    (@access String $field:ident) => {
        Access::Str {
            get: {
                fn get(p: &PartProps) -> Option<String> {
                    p.$field.clone()
                }
                get
            },
            slot: {
                fn slot(p: &mut PartProps) -> &mut Option<String> {
                    &mut p.$field
                }
                slot
            },
        }
    };
    (@access bool $field:ident) => {
        Access::Bool {
            get: {
                fn get(p: &PartProps) -> Option<bool> {
                    p.$field
                }
                get
            },
            slot: {
                fn slot(p: &mut PartProps) -> &mut Option<bool> {
                    &mut p.$field
                }
                slot
            },
        }
    };
}

const fn null(means: &'static str, reason: &'static str) -> Option<Null> {
    Some(Null { means, reason })
}

const NO_SPRING: Option<Null> = null("0", "no spring along that axis");
const NO_DASHPOT: Option<Null> = null("0", "no dashpot along that axis");
const NO_FAILURE: Option<Null> = null(
    "no failure",
    "elements stay elastic unless a failure law is given, as in the paper's studies",
);

part_properties! {
    youngs_modulus: f64 {
        unit: "Pa",
        kinds: [Truss: Rule::Required, Beam: Rule::Required, Hex: Rule::Required],
        null: None,
        aliases: ["E"],
        meaning: "Young's modulus E",
    },
    density: f64 {
        unit: "kg/m³",
        // A truss may be a massless spring (SPRINGA in other codes) between nodes that
        // have mass from elsewhere (point masses): ρ = 0 is allowed, and the solver
        // refuses a free node that then has no mass at all.
        kinds: [Truss: Rule::RequiredNonNegative, Tri: Rule::Required, Quad: Rule::Required, Beam: Rule::Required, Hex: Rule::Required],
        null: None,
        aliases: ["rho"],
        meaning: "mass density ρ",
    },
    area: f64 {
        unit: "m²",
        kinds: [Truss: Rule::Required],
        null: None,
        aliases: ["A"],
        meaning: "cross-section area A",
    },
    ply_areal_density: f64 {
        unit: "kg/m²",
        kinds: [Truss: Rule::Positive, Tri: Rule::Positive, Quad: Rule::Positive],
        null: null("unknown", "the summary's `areal_density` is then null"),
        aliases: [],
        meaning: "the areal density of the fabric ply whose yarns the part models (weft-weave woven writes it on the yarn parts): the solver does not read it; the summary's `areal_density` sums it over the layers",
    },
    tension_only: bool {
        unit: "",
        kinds: [Truss: Rule::Free],
        null: null("false", "a truss carries compression unless told otherwise"),
        aliases: [],
        meaning: "true: the truss carries no compressive force",
    },
    kx: f64 {
        unit: "N/m",
        kinds: [Link: Rule::NonNegative],
        null: NO_SPRING,
        aliases: [],
        meaning: "spring stiffness along x (global x, or the local e₁ with `local_frame`)",
    },
    ky: f64 {
        unit: "N/m",
        kinds: [Link: Rule::NonNegative],
        null: NO_SPRING,
        aliases: [],
        meaning: "spring stiffness along y (global y, or the local e₂ with `local_frame`)",
    },
    kz: f64 {
        unit: "N/m",
        kinds: [Link: Rule::NonNegative],
        null: NO_SPRING,
        aliases: [],
        meaning: "normal spring stiffness along z (global z, or the local normal n with `local_frame`)",
    },
    cx: f64 {
        unit: "N·s/m",
        kinds: [Link: Rule::NonNegative],
        null: NO_DASHPOT,
        aliases: [],
        meaning: "dashpot coefficient along x (global, or local e₁)",
    },
    cy: f64 {
        unit: "N·s/m",
        kinds: [Link: Rule::NonNegative],
        null: NO_DASHPOT,
        aliases: [],
        meaning: "dashpot coefficient along y (global, or local e₂)",
    },
    cz: f64 {
        unit: "N·s/m",
        kinds: [Link: Rule::NonNegative],
        null: NO_DASHPOT,
        aliases: [],
        meaning: "dashpot coefficient along z (global, or the local normal n)",
    },
    slip_force: f64 {
        unit: "N",
        kinds: [Link: Rule::Positive],
        null: null("no slider", "a link slips only where a friction slider is asked for"),
        aliases: [],
        meaning: "friction slider: the tangential (x–y) force at which the link slips; needs `kx`, `ky` > 0; not with `friction`",
    },
    mass: f64 {
        unit: "kg",
        kinds: [PointMass: Rule::Required],
        null: None,
        aliases: [],
        meaning: "the point mass",
    },
    youngs_modulus_1: f64 {
        unit: "Pa",
        kinds: [Tri: Rule::Required, Quad: Rule::Required],
        null: None,
        aliases: ["E1"],
        meaning: "Young's modulus E₁ along material direction 1",
    },
    youngs_modulus_2: f64 {
        unit: "Pa",
        kinds: [Tri: Rule::Required, Quad: Rule::Required],
        null: None,
        aliases: ["E2"],
        meaning: "Young's modulus E₂ along material direction 2",
    },
    poisson_ratio_12: f64 {
        unit: "",
        kinds: [Tri: Rule::Free, Quad: Rule::Free],
        null: null("0", "no coupling of the two material directions"),
        aliases: ["nu12"],
        meaning: "Poisson's ratio ν₁₂ (ν₂₁ = ν₁₂E₂/E₁); needs −1 < ν₁₂ and ν₁₂²E₂/E₁ < 1",
    },
    shear_modulus_12: f64 {
        unit: "Pa",
        kinds: [Tri: Rule::Required, Quad: Rule::Required],
        null: None,
        aliases: ["G12", "G"],
        meaning: "in-plane shear modulus G₁₂",
    },
    thickness: f64 {
        unit: "m",
        kinds: [Tri: Rule::Required, Quad: Rule::Required],
        null: None,
        aliases: ["s"],
        meaning: "membrane thickness s",
    },
    no_compression: bool {
        unit: "",
        kinds: [Tri: Rule::Free, Quad: Rule::Free],
        null: null("false", "a membrane carries compression unless told otherwise"),
        aliases: [],
        meaning: "true: compressive principal stresses are dropped (wrinkling)",
    },
    hourglass: f64 {
        unit: "",
        kinds: [Quad: Rule::NonNegative, Hex: Rule::NonNegative],
        null: null("0.1", "LS-DYNA's default"),
        aliases: [],
        meaning: "hourglass coefficient κ of the one-point quad (stiffness form) and of the one-point hexahedron (Flanagan–Belytschko viscous form, Q_hg)",
    },
    material_angle: f64 {
        unit: "rad",
        kinds: [Tri: Rule::Finite, Quad: Rule::Finite],
        null: null("0", "material direction 1 along the projected global x"),
        aliases: [],
        meaning: "angle of material direction 1 from global x projected on the element, about its normal",
    },
    width: f64 {
        unit: "m",
        kinds: [Beam: Rule::Required],
        null: None,
        aliases: ["b"],
        meaning: "section width b, along the local e₂ (in the plane of a girder)",
    },
    height: f64 {
        unit: "m",
        kinds: [Beam: Rule::Required],
        null: None,
        aliases: ["h"],
        meaning: "section height h, along the local e₃ (global z unless the beam is parallel to z, then global y)",
    },
    poisson_ratio: f64 {
        unit: "",
        kinds: [
            Beam: Rule::Open { lo: -1.0, hi: 0.5, expected: "−1 < ν < 0.5" },
            Hex: Rule::Open { lo: -1.0, hi: 0.5, expected: "−1 < ν < 0.5" },
        ],
        null: null("0.3", "a typical structural metal's"),
        aliases: [],
        meaning: "Poisson's ratio ν: the beam's shear modulus G = E/(2(1 + ν)) in torsion; the hexahedron's isotropic elasticity",
    },
    prestrain: f64 {
        unit: "",
        kinds: [Truss: Rule::Open { lo: -0.5, hi: 0.5, expected: "a small strain, −0.5 < ε₀ < 0.5" }],
        null: null("0", "an unstressed truss"),
        aliases: [],
        meaning: "initial strain ε₀ (pretension): unstressed length = geometric length/(1 + ε₀), so the truss starts with the force E·A·ε₀",
    },
    friction: f64 {
        unit: "",
        kinds: [Link: Rule::NonNegative],
        null: null("no Coulomb friction", "a link slips only where friction is asked for"),
        aliases: [],
        meaning: "Coulomb friction coefficient μ: the tangential spring slips at μ·N, N = the normal spring's compressive force (`kz`·max(0, −d_z)); needs `kx`, `ky`, `kz` > 0; not with `slip_force`",
    },
    unilateral: bool {
        unit: "",
        kinds: [Link: Rule::Free],
        null: null("false", "a two-way normal spring, as the paper's links"),
        aliases: [],
        meaning: "true: the normal spring and dashpot push, never pull: they act only while node 2 is pressed towards node 1 (d_z < 0; node 1 the lower yarn), and the normal force is ≥ 0",
    },
    local_frame: bool {
        unit: "",
        kinds: [Link: Rule::Free],
        null: null("false", "global axes, as the paper's links along Ox, Oy, Oz"),
        aliases: [],
        meaning: "true: the springs, dashpots and slider act in the local frame (e₁, e₂, n) of the crossing, rebuilt every step from the frame nodes `f1`…`f4` of `elements_link.parquet` (e₁ along f2 − f1, n ⟂ e₁ and f4 − f3)",
    },
    sliding: bool {
        unit: "",
        kinds: [Link: Rule::Free],
        null: null("false", "a link joins its two nodes, as the paper's links"),
        aliases: [],
        meaning: "true: each end of the link is a point of a yarn (the chain of trusses through `n1`, and through `n2`) that stays put while the link sticks and moves along the yarn when its slider slips, so that the yarns slide across each other; the link acts in the frame of the two yarns' tangents at those points (e₁ along node 1's yarn, n ⟂ both towards node 2); needs `n1`, `n2` on truss chains; not with `local_frame`",
    },
    failure_strain: f64 {
        unit: "",
        kinds: [Truss: Rule::Positive, Tri: Rule::Positive, Quad: Rule::Positive],
        null: NO_FAILURE,
        aliases: ["eps_f"],
        meaning: "failure strain ε_f: a truss fails when its axial engineering strain (L − L_ref)/L_ref reaches it, a membrane when the engineering strain of its fibres along material direction 1, √(1 + 2E₁₁) − 1, does; times the element's `failure_strain_factor`",
    },
    failure_strain_2: f64 {
        unit: "",
        kinds: [Tri: Rule::Positive, Quad: Rule::Positive],
        null: null("no failure across", "a yarn band fails along its yarn; across, only where asked"),
        aliases: [],
        meaning: "failure strain along material direction 2, √(1 + 2E₂₂) − 1 (membranes), times the element's `failure_strain_factor`",
    },
    failure_all_directions: bool {
        unit: "",
        kinds: [Tri: Rule::Free, Quad: Rule::Free],
        null: null("false", "the first direction to fail removes the element (OpenRadioss /FAIL/FABRIC NDIR = 1)"),
        aliases: [],
        meaning: "true: a membrane is removed only when every direction with a failure strain has failed, and a direction that has failed carries no normal stress from then on (NDIR = 2)",
    },
    failure_rate_coefficient: f64 {
        unit: "",
        kinds: [Truss: Rule::NonNegative, Tri: Rule::NonNegative, Quad: Rule::NonNegative],
        null: null("0", "a rate-independent failure strain"),
        aliases: [],
        meaning: "C of the failure strain's rate law ε_f(ε̇) = ε_f (1 + C ln(ε̇/ε̇₀)) for ε̇ > ε̇₀ (ε̇ the element's strain rate along the failing direction)",
    },
    failure_reference_rate: f64 {
        unit: "1/s",
        kinds: [Truss: Rule::Positive, Tri: Rule::Positive, Quad: Rule::Positive],
        null: null("1", "the rate law's reference ε̇₀ matters only with `failure_rate_coefficient`"),
        aliases: [],
        meaning: "ε̇₀ of the failure strain's rate law",
    },
    failure_delay: f64 {
        unit: "s",
        kinds: [Truss: Rule::NonNegative, Tri: Rule::NonNegative, Quad: Rule::NonNegative],
        null: null("0", "the strain itself is compared with the failure strain"),
        aliases: [],
        meaning: "delay τ of the failure: the strain is compared after a low-pass filter dε̄/dt = (ε − ε̄)/τ, so that the transient of a discrete yarn struck by a nose (its first elements overshoot the strain of Smith's theory by about 40 % for a few steps) does not break it",
    },
    failure_length: f64 {
        unit: "m",
        kinds: [Truss: Rule::NonNegative],
        null: null("0", "each truss's own strain is compared with the failure strain"),
        aliases: [],
        meaning: "length ℓ of yarn a chain's strain is averaged over before it is compared with the failure strain: each truss's is the length-weighted mean over the trusses of its chain (the part's trusses joined end to end) within ℓ/2 of its centre, so that the few elements a discrete yarn overshoots under a nose do not break it, whatever the mesh (weft-weave: the crossing spacing)",
    },
    failure_force: f64 {
        unit: "N",
        kinds: [Link: Rule::Positive],
        null: NO_FAILURE,
        aliases: [],
        meaning: "a link breaks when the length of its spring force reaches it (times the element's `failure_strain_factor`)",
    },
    failure_opening: f64 {
        unit: "m",
        kinds: [Link: Rule::Positive],
        null: NO_FAILURE,
        aliases: [],
        meaning: "a link breaks when the length of its relative displacement d = x₂ − x₁ − d₀ reaches it (times the element's `failure_strain_factor`)",
    },
    yield_stress: f64 {
        unit: "Pa",
        kinds: [Hex: Rule::Positive],
        null: null("elastic", "a solid is elastic unless given a yield stress (or Johnson–Cook's A)"),
        aliases: [],
        meaning: "initial yield stress σ_y0 of J2 (von Mises) plasticity with isotropic hardening, by radial return",
    },
    tangent_modulus: f64 {
        unit: "Pa",
        kinds: [Hex: Rule::NonNegative],
        null: null("0", "perfectly plastic"),
        aliases: [],
        meaning: "tangent modulus E_t of the bilinear uniaxial curve (E_t < E): σ_y = σ_y0 + H ε_p with H = E E_t/(E − E_t)",
    },
    jc_a: f64 {
        unit: "Pa",
        kinds: [Hex: Rule::Positive],
        null: null("no Johnson–Cook", "a solid is J2 with `yield_stress`, or elastic"),
        aliases: [],
        meaning: "Johnson–Cook A: σ_y = (A + B ε_pⁿ)(1 + C ln max(ε̇_p/ε̇₀, 1))(1 − T*ᵐ), T* = (T − T_room)/(T_melt − T_room) (Johnson & Cook 1983)",
    },
    jc_b: f64 {
        unit: "Pa",
        kinds: [Hex: Rule::NonNegative],
        null: null("0", "no strain hardening"),
        aliases: [],
        meaning: "Johnson–Cook B",
    },
    jc_n: f64 {
        unit: "",
        kinds: [Hex: Rule::Positive],
        null: null("1", "linear hardening"),
        aliases: [],
        meaning: "Johnson–Cook hardening exponent n",
    },
    jc_c: f64 {
        unit: "",
        kinds: [Hex: Rule::NonNegative],
        null: null("0", "rate-independent"),
        aliases: [],
        meaning: "Johnson–Cook strain-rate coefficient C",
    },
    jc_reference_rate: f64 {
        unit: "1/s",
        kinds: [Hex: Rule::Positive],
        null: null("1", "Johnson & Cook's own reference rate"),
        aliases: [],
        meaning: "Johnson–Cook reference strain rate ε̇₀",
    },
    jc_m: f64 {
        unit: "",
        kinds: [Hex: Rule::Positive],
        null: null("no thermal softening", "the flow stress does not fall with temperature"),
        aliases: [],
        meaning: "Johnson–Cook thermal-softening exponent m",
    },
    room_temperature: f64 {
        unit: "K",
        kinds: [Hex: Rule::Positive],
        null: null("293.15", "20 °C"),
        aliases: [],
        meaning: "room (and initial) temperature T_room of Johnson–Cook's T*",
    },
    melt_temperature: f64 {
        unit: "K",
        kinds: [Hex: Rule::Positive],
        null: null("no thermal softening", "needed with `jc_m`"),
        aliases: [],
        meaning: "melting temperature T_melt of Johnson–Cook's T* (a temperature at or above it is refused)",
    },
    specific_heat: f64 {
        unit: "J/(kg·K)",
        kinds: [Hex: Rule::Positive],
        null: null("no heating", "the temperature stays at T_room"),
        aliases: [],
        meaning: "specific heat c_p for the adiabatic heating ΔT = χ ΔW_p/(ρ c_p)",
    },
    taylor_quinney: f64 {
        unit: "",
        // χ ≤ 1 is checked with the material (a fraction of the plastic work).
        kinds: [Hex: Rule::NonNegative],
        null: null("0.9", "Taylor & Quinney's measured fraction"),
        aliases: [],
        meaning: "Taylor–Quinney coefficient χ: the fraction of the plastic work that heats the material",
    },
    plasticine_a: f64 {
        unit: "Pa",
        kinds: [Hex: Rule::Positive],
        null: null("no plasticine", "a solid is Johnson–Cook with `jc_a`, J2 with `yield_stress`, or elastic"),
        aliases: [],
        meaning: "plasticine (the backing clay) A: σ_y = (A + B ε_pⁿ) max(ε̇_p/ε̇₀, 1)ᵐ, a flow stress rising as a power of the plastic strain rate (src/material/plasticine.rs)",
    },
    plasticine_b: f64 {
        unit: "Pa",
        kinds: [Hex: Rule::NonNegative],
        null: null("0", "no strain hardening"),
        aliases: [],
        meaning: "plasticine B",
    },
    plasticine_n: f64 {
        unit: "",
        kinds: [Hex: Rule::Positive],
        null: null("1", "linear hardening"),
        aliases: [],
        meaning: "plasticine hardening exponent n (0 < n ≤ 1)",
    },
    plasticine_m: f64 {
        unit: "",
        kinds: [Hex: Rule::NonNegative],
        null: null("0", "rate-independent"),
        aliases: [],
        meaning: "plasticine rate exponent m (0 ≤ m < 1): the flow stress rises by 10ᵐ per decade of plastic strain rate above ε̇₀",
    },
    plasticine_reference_rate: f64 {
        unit: "1/s",
        kinds: [Hex: Rule::Positive],
        null: null("1", "1/s"),
        aliases: [],
        meaning: "plasticine reference strain rate ε̇₀: below it the flow stress is (A + B ε_pⁿ)",
    },
    erosion_plastic_strain: f64 {
        unit: "",
        kinds: [Hex: Rule::Positive],
        null: NO_FAILURE,
        aliases: [],
        meaning: "a hexahedron is eroded (removed) when its equivalent plastic strain reaches it",
    },
    material: String {
        unit: "",
        // Checked against the laws' names when the part's material is built.
        kinds: [Hex: Rule::Free],
        null: null(
            "the law the part's columns select",
            "`yield_stress` selects j2, `jc_a` johnson_cook, `plasticine_a` plasticine, none the elastic law; the column is written only when some part names a law",
        ),
        aliases: [],
        meaning: "the material law of a solid part, by name: `elastic`, `j2`, `johnson_cook`, `plasticine` (src/material/)",
    },
    solid_formulation: String {
        unit: "",
        // Checked when the hexahedra are built.
        kinds: [Hex: Rule::Free],
        null: null(
            "one_point",
            "the one-point element with the viscous hourglass control; the column is written only when some part names a formulation",
        ),
        aliases: [],
        meaning: "the hexahedron's integration: `one_point` (one point, Flanagan–Belytschko hourglass control, `hourglass` its coefficient) or `selective_reduced` (eight points for the deviatoric stress, the mean for the pressure: no hourglass modes, no coefficient; several times the cost; src/solver/solid/selective.rs)",
    },
}

impl PartProps {
    /// Hourglass coefficient κ; 0.1, LS-DYNA's default, when not given (the `hourglass`
    /// descriptor's null; a unit test holds the two equal).
    pub fn hourglass_coefficient(&self) -> f64 {
        self.hourglass.unwrap_or(0.1)
    }
}

/// A part's numeric columns by name, as the material laws read them.
impl crate::material::Columns for PartProps {
    fn f64(&self, name: &str) -> Option<f64> {
        match property(name).map(|p| p.access) {
            Some(Access::F64 { get, .. }) => get(self),
            _ => None,
        }
    }
}

/// The descriptor of a property by column name.
pub fn property(name: &str) -> Option<&'static Property> {
    PROPERTIES.iter().find(|p| p.name == name)
}

/// The property an alias (`G12`) stands for; a name that is no alias comes back as is.
pub fn resolve_alias(name: &str) -> &str {
    PROPERTIES
        .iter()
        .find(|p| p.aliases.contains(&name))
        .map(|p| p.name)
        .unwrap_or(name)
}

/// The numeric properties of a kind's parts, which `weft-fit` can set, in table order.
pub fn fittable(kind: ElementKind) -> impl Iterator<Item = &'static Property> {
    PROPERTIES
        .iter()
        .filter(move |p| matches!(p.access, Access::F64 { .. }) && p.rule(kind).is_some())
}

impl Property {
    /// The rule for a kind's parts; `None` when the property does not apply to it.
    pub fn rule(&self, kind: ElementKind) -> Option<Rule> {
        self.kinds.iter().find(|k| k.0 == kind).map(|k| k.1)
    }

    /// The numeric default a null stands for, when it is a number.
    pub fn null_value(&self) -> Option<f64> {
        self.null.and_then(|n| n.means.parse().ok())
    }

    /// `in Pa`, or nothing when dimensionless: the unit as error messages write it.
    fn in_unit(&self) -> String {
        if self.unit.is_empty() {
            String::new()
        } else {
            format!(" in {}", self.unit)
        }
    }

    /// Check a part's value of this property against the rule for the part's kind:
    /// `part` is the part's name, `kind` its kind and `props` its properties. Errors name
    /// the part, its kind, the column and the value; the caller adds the file and row.
    pub fn check(&self, part: &str, kind: ElementKind, props: &PartProps) -> Result<()> {
        let Some(rule) = self.rule(kind) else {
            return Ok(());
        };
        let Access::F64 { get, .. } = self.access else {
            return Ok(());
        };
        let v = get(props);
        let col = self.name;
        let bad = |x: f64| {
            WeftError::input(format!(
                "part `{}` ({}) has {col} = `{x}`",
                part,
                kind.name()
            ))
            .in_column(col)
        };
        let or_null = |s: String| match self.null {
            Some(n) => format!("{s}, or null for {}", n.means),
            None => s,
        };
        match (rule, v) {
            (Rule::Required | Rule::RequiredNonNegative, None) => {
                Err(
                    WeftError::input(format!("part `{}` ({}) has no {col}", part, kind.name()))
                        .in_column(col)
                        .expected(format!(
                            "a value {}{}",
                            if rule == Rule::Required {
                                "> 0"
                            } else {
                                "≥ 0"
                            },
                            self.in_unit()
                        ))
                        .hint(format!("every {} part needs `{col}`", kind.name())),
                )
            }
            (Rule::Required | Rule::Positive, Some(x)) if !(x > 0.0 && x.is_finite()) => {
                Err(bad(x).expected(or_null(format!("a value > 0{}", self.in_unit()))))
            }
            (Rule::NonNegative | Rule::RequiredNonNegative, Some(x))
                if x < 0.0 || !x.is_finite() =>
            {
                Err(bad(x).expected(or_null(format!("a value ≥ 0{}", self.in_unit()))))
            }
            (Rule::Open { lo, hi, expected }, Some(x)) if !(x > lo && x < hi) => {
                Err(bad(x).expected(expected))
            }
            (Rule::Finite, Some(x)) if !x.is_finite() => {
                Err(bad(x).expected(format!("a finite value{}", self.in_unit())))
            }
            _ => Ok(()),
        }
    }

    /// What the rule asks, for the docs: `required, > 0`, `≥ 0`.
    fn rule_text(rule: Rule) -> String {
        match rule {
            Rule::Required => "required, > 0".into(),
            Rule::Positive => "> 0".into(),
            Rule::NonNegative => "≥ 0".into(),
            Rule::RequiredNonNegative => "required, ≥ 0".into(),
            Rule::Open { expected, .. } => expected.into(),
            Rule::Finite => "finite".into(),
            Rule::Free => String::new(),
        }
    }
}

/// Read the property columns of `parts.parquet` (an absent column is all null), one
/// [`PartProps`] per row.
pub fn read_columns(t: &Table, rows: usize) -> Result<Vec<PartProps>> {
    let mut out = vec![PartProps::default(); rows];
    for p in PROPERTIES {
        match p.access {
            Access::F64 { slot, .. } => {
                if let Some(col) = t.f64_opt(p.name)? {
                    for (q, v) in out.iter_mut().zip(col) {
                        *slot(q) = v;
                    }
                }
            }
            Access::Bool { slot, .. } => {
                if let Some(col) = t.bool_opt(p.name)? {
                    for (q, v) in out.iter_mut().zip(col) {
                        *slot(q) = v;
                    }
                }
            }
            Access::Str { slot, .. } => {
                if let Some(col) = t.str_opt(p.name)? {
                    for (q, v) in out.iter_mut().zip(col) {
                        *slot(q) = v;
                    }
                }
            }
        }
    }
    Ok(out)
}

/// The property columns of `parts.parquet` in table order: every numeric and boolean
/// one, and a name column (`material`) only when some part sets it.
pub fn columns<'a>(props: impl Iterator<Item = &'a PartProps> + Clone) -> Vec<Col> {
    PROPERTIES
        .iter()
        .filter_map(|p| match p.access {
            Access::F64 { get, .. } => Some(Col::OptF64(p.name, props.clone().map(get).collect())),
            Access::Bool { get, .. } => {
                Some(Col::OptBool(p.name, props.clone().map(get).collect()))
            }
            Access::Str { get, .. } => {
                let v: Vec<Option<String>> = props.clone().map(get).collect();
                v.iter()
                    .any(Option::is_some)
                    .then_some(Col::OptStr(p.name, v))
            }
        })
        .collect()
}

/// The column table of `parts.parquet` for `docs/tables.md`: the three identifying
/// columns, then one row per property.
pub fn parts_table_markdown() -> String {
    let mut s = String::from(
        "| column | type | unit | kinds | meaning |\n\
         |---|---|---|---|---|\n\
         | `part_id` | int64 | – | all | unique part id |\n\
         | `name` | string | – | all | part name (used by later stages to address properties, e.g. `links.kx`) |\n",
    );
    let kinds = ElementKind::ALL.map(|k| format!("`{}`", k.name()));
    let (last, rest) = kinds.split_last().expect("kinds");
    s += &format!(
        "| `kind` | string | – | all | element kind: {} or {last} |\n",
        rest.join(", ")
    );
    for p in PROPERTIES {
        let ty = match p.access {
            Access::F64 { .. } => "float64, nullable",
            Access::Bool { .. } => "bool, nullable",
            Access::Str { .. } => "string, nullable, optional",
        };
        let unit = if p.unit.is_empty() { "–" } else { p.unit };
        let kinds: Vec<&str> = ElementKind::ALL
            .into_iter()
            .filter(|k| p.rule(*k).is_some())
            .map(|k| k.name())
            .collect();
        // One rule text when every kind has the same rule, else one per kind.
        let texts: Vec<(ElementKind, String)> = p
            .kinds
            .iter()
            .map(|(k, r)| (*k, Property::rule_text(*r)))
            .collect();
        let mut notes = vec![];
        if texts.iter().all(|t| t.1 == texts[0].1) {
            if !texts[0].1.is_empty() {
                notes.push(texts[0].1.clone());
            }
        } else {
            notes.extend(
                texts
                    .iter()
                    .filter(|t| !t.1.is_empty())
                    .map(|(k, t)| format!("{}: {t}", k.name())),
            );
        }
        if let Some(n) = p.null {
            notes.push(format!("null = {}: {}", n.means, n.reason));
        }
        let mut meaning = p.meaning.to_string();
        if !notes.is_empty() {
            meaning += &format!(" ({})", notes.join("; "));
        }
        if !p.aliases.is_empty() {
            meaning += &format!(
                "; weft-fit alias {}",
                p.aliases
                    .iter()
                    .map(|a| format!("`{a}`"))
                    .collect::<Vec<_>>()
                    .join(", ")
            );
        }
        s += &format!(
            "| `{}` | {ty} | {unit} | {} | {meaning} |\n",
            p.name,
            kinds.join(", ")
        );
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_and_aliases_are_unique() {
        let mut seen = std::collections::HashSet::new();
        for p in PROPERTIES {
            assert!(seen.insert(p.name), "`{}` twice", p.name);
            for a in p.aliases {
                assert!(seen.insert(a), "alias `{a}` twice");
            }
            assert!(!p.kinds.is_empty(), "`{}` applies to no kind", p.name);
        }
    }

    #[test]
    fn accessors_reach_their_own_field() {
        for (k, p) in PROPERTIES.iter().enumerate() {
            let mut q = PartProps::default();
            match p.access {
                Access::F64 { get, slot } => {
                    *slot(&mut q) = Some(k as f64 + 0.5);
                    assert_eq!(get(&q), Some(k as f64 + 0.5), "{}", p.name);
                }
                Access::Bool { get, slot } => {
                    *slot(&mut q) = Some(true);
                    assert_eq!(get(&q), Some(true), "{}", p.name);
                }
                Access::Str { get, slot } => {
                    *slot(&mut q) = Some(p.name.to_string());
                    assert_eq!(get(&q).as_deref(), Some(p.name), "{}", p.name);
                }
            }
            // Exactly one field was set.
            let set = PROPERTIES
                .iter()
                .filter(|o| match o.access {
                    Access::F64 { get, .. } => get(&q).is_some(),
                    Access::Bool { get, .. } => get(&q).is_some(),
                    Access::Str { get, .. } => get(&q).is_some(),
                })
                .count();
            assert_eq!(set, 1, "{}", p.name);
        }
    }

    /// Every column a material law reads is a numeric property of hexahedra (a law
    /// reads its constants by name, so a misspelt name would read null).
    #[test]
    fn material_laws_read_hex_properties() {
        let shared: &[&str] = &[
            "youngs_modulus",
            "poisson_ratio",
            "density",
            "erosion_plastic_strain",
        ];
        for (law, _, cols) in crate::material::Law::ALL {
            for c in cols.iter().chain(shared) {
                let p = property(c).unwrap_or_else(|| panic!("law {law} reads `{c}`"));
                assert!(matches!(p.access, Access::F64 { .. }), "{law}: `{c}`");
                assert!(p.rule(Hex).is_some(), "{law}: `{c}` does not apply to hex");
            }
        }
    }

    #[test]
    fn defaults_used_in_code_match_the_table() {
        assert_eq!(
            property("hourglass").unwrap().null_value(),
            Some(PartProps::default().hourglass_coefficient())
        );
    }
}
