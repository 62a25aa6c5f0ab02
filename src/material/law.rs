//! The vocabulary every material law shares: the trait [`MaterialLaw`], the elastic
//! constants, the state of an integration point, and how a law reads a part's columns
//! (glossary in the module above).

use crate::error::Result;

/// Temperature of a point whose law has no thermal state [K] (20 °C).
pub const DEFAULT_TEMPERATURE: f64 = 293.15;

/// A part's constants by column name (`parts.parquet`; the model's part properties
/// implement it). A law reads only the columns it lists in [`MaterialLaw::COLUMNS`].
pub trait Columns {
    /// The value of column `name`, `None` when null (or not a column).
    fn f64(&self, name: &str) -> Option<f64>;
}

/// How a part comes to take a law (besides naming it in its `material` column).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Selection {
    /// The law of a part that selects no other (one law only: the elastic one).
    Default,
    /// Taken when the part sets this column (`yield_stress` for j2).
    ByColumn(&'static str),
    /// Only when the part's `material` column names it.
    ByName,
}

/// The isotropic elastic constants every law shares.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Elastic {
    /// E [Pa].
    pub youngs_modulus: f64,
    /// ν.
    pub poisson_ratio: f64,
    /// ρ (reference) [kg/m³].
    pub density: f64,
}

impl Elastic {
    /// (λ, μ) = (Eν/((1 + ν)(1 − 2ν)), E/(2(1 + ν))).
    #[inline]
    pub fn lame(&self) -> (f64, f64) {
        let (e, nu) = (self.youngs_modulus, self.poisson_ratio);
        (
            e * nu / ((1.0 + nu) * (1.0 - 2.0 * nu)),
            e / (2.0 * (1.0 + nu)),
        )
    }
}

/// One material law (see the module docs): its name and constants, how a part selects
/// it, its virgin state and its update of one integration point. Pure: the update reads
/// the law's constants and the point's old state and writes the new one (Ferrite's
/// `(strain, params, old state) → (stress, new state)`).
pub trait MaterialLaw: Sized + Clone + std::fmt::Debug + PartialEq {
    /// The name the `material` column of `parts.parquet` gives it (`j2`).
    const NAME: &'static str;
    /// How a part that names no law comes to take this one.
    const SELECTION: Selection;
    /// The `parts.parquet` columns it reads (each a property of `src/model/props.rs`
    /// that applies to hexahedra; a test checks it).
    const COLUMNS: &'static [&'static str];
    /// Its constants from a part's columns (`elastic`: the part's E, ν, ρ); an error
    /// names the column and the value.
    fn from_columns(cols: &dyn Columns, elastic: &Elastic) -> Result<Self>;
    /// The constants' ranges; an error names the constant and the value.
    fn validate(&self) -> Result<()>;
    /// The temperature of the virgin state [K].
    fn initial_temperature(&self) -> f64 {
        DEFAULT_TEMPERATURE
    }
    /// Advances one point (not eroded) by the strain increment `deps` = D Δt (tensor
    /// components, Voigt order) over the step `dt`: stress, plastic strain, plastic work,
    /// temperature. The stress is in the frame already rotated by the element's
    /// objective update.
    fn update(&self, elastic: &Elastic, st: &mut PointState, deps: &[f64; 6], dt: f64);
}

/// The state of one integration point.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct PointState {
    /// σ [Pa], Voigt [xx, yy, zz, xy, yz, zx].
    pub stress: [f64; 6],
    /// ε_p, the equivalent plastic strain.
    pub plastic_strain: f64,
    /// T [K].
    pub temperature: f64,
    /// W_p, plastic work per unit volume [J/m³].
    pub plastic_work: f64,
    pub eroded: bool,
}
