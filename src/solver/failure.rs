//! Element failure and erosion: the criteria the families test, the state they keep,
//! and the events they report.
//!
//! Glossary: ε_f the failure strain (a part's `failure_strain` × the element's
//! `failure_strain_factor`); ε̇ the element's strain rate; C, ε̇₀ the optional rate law's
//! coefficient and reference rate; E_ii a Green strain in material axes; λ_i the stretch of
//! a material line along axis i.
//!
//! - The rate law (optional): ε_f(ε̇) = ε_f (1 + C ln(ε̇/ε̇₀)) for ε̇ > ε̇₀, ε_f below.
//! - A membrane's fibre strain along material axis i: λ_i − 1 = √(1 + 2E_ii) − 1 (the
//!   engineering strain of the material line along the axis, exactly, at any rotation).
//! - A truss's: (L − L_ref)/L_ref, its own strain measure.
//!
//! An element that fails leaves the force loop from that step on; the strain energy it
//! held is kept as its eroded energy, which the ledger books so that the balance closes
//! (docs/theory.md, "Failure, perforation and the ballistic limit").

use crate::model::ElementKind;

/// A failure strain with its optional rate law.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FailureLaw {
    /// ε_f [-]; `f64::INFINITY` when the element cannot fail.
    pub strain: f64,
    /// C of the rate law (0: rate-independent).
    pub rate_coefficient: f64,
    /// ε̇₀ of the rate law [1/s].
    pub reference_rate: f64,
    /// Delay τ [s] of the strain compared with the limit (0: the strain itself).
    pub delay: f64,
}

impl FailureLaw {
    /// An element that cannot fail.
    pub const NONE: FailureLaw = FailureLaw {
        strain: f64::INFINITY,
        rate_coefficient: 0.0,
        reference_rate: 1.0,
        delay: 0.0,
    };

    pub fn can_fail(&self) -> bool {
        self.strain.is_finite()
    }

    /// The strain the limit is compared with: ε itself without a delay, else the filtered
    /// ε̄ advanced over `dt` by dε̄/dt = (ε − ε̄)/τ (explicit, the step capped at τ), kept
    /// in `filtered`.
    #[inline(always)]
    pub fn filter(&self, eps: f64, dt: f64, filtered: &mut f64) -> f64 {
        if self.delay > 0.0 {
            *filtered += (dt / self.delay).min(1.0) * (eps - *filtered);
            *filtered
        } else {
            eps
        }
    }

    /// ε_f at the strain rate ε̇ [1/s].
    ///
    /// ```
    /// use weft::solver::failure::FailureLaw;
    /// let law = FailureLaw { strain: 0.03, rate_coefficient: 0.14, reference_rate: 30.0, delay: 0.0 };
    /// assert_eq!(law.threshold(10.0), 0.03); // below the reference rate: ε_f
    /// let e = law.threshold(30.0 * std::f64::consts::E); // one e-fold above it
    /// assert!((e - 0.03 * 1.14).abs() < 1e-15);
    /// ```
    #[inline(always)]
    pub fn threshold(&self, rate: f64) -> f64 {
        if self.rate_coefficient != 0.0 && rate > self.reference_rate {
            self.strain * (1.0 + self.rate_coefficient * (rate / self.reference_rate).ln())
        } else {
            self.strain
        }
    }
}

/// The engineering strain of the material line along an axis from its Green strain E_ii:
/// √(1 + 2E_ii) − 1.
///
/// ```
/// // A stretch of 1.04: E₁₁ = (1.04² − 1)/2.
/// let e11 = 0.5 * (1.04f64 * 1.04 - 1.0);
/// assert!((weft::solver::failure::fibre_strain(e11) - 0.04).abs() < 1e-15);
/// ```
#[inline(always)]
pub fn fibre_strain(e_ii: f64) -> f64 {
    (1.0 + 2.0 * e_ii).max(0.0).sqrt() - 1.0
}

/// The energy a failure at t_n takes out of the model: the element's strain energy W(x^n)
/// plus ½ Δt^{n−½} Σ_a v_a^{n−½}·f_a(x^n), with f_a the forces it exerted at x^n.
///
/// Why the second term: the central difference conserves ½ Σ m v^{n−½}·v^{n+½} + U(x^n)
/// exactly for a linear system; when an element's force leaves at step n, that sum
/// changes by −½ (x^n − x^{n−1})·f(x^n) beyond what W(x^n) accounts for (half of the
/// trapezoid of its work over the last step is never done). Booking it keeps the balance
/// exact through the failure (measured: 10⁻¹⁵ J before, 4·10⁻⁴ of the failed truss's
/// energy without the term, round-off with it; `tests/failure.rs`).
pub fn taken_energy(w: f64, dt_prev: f64, v: &[[f64; 3]], f: &[[f64; 3]]) -> f64 {
    let mut p = 0.0;
    for (va, fa) in v.iter().zip(f) {
        p += va[0] * fa[0] + va[1] * fa[1] + va[2] * fa[2];
    }
    w + 0.5 * dt_prev * p
}

/// What made an element fail.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Criterion {
    /// A truss's axial strain.
    Axial,
    /// A membrane's fibre strain along material axis 1.
    Direction1,
    /// A membrane's fibre strain along material axis 2.
    Direction2,
    /// A link's spring force.
    Force,
    /// A link's opening.
    Opening,
    /// A membrane's own stable step, at its current shape, below half the run's step
    /// ([`super::collapse`]): the value is that step, the limit half the run's [s].
    TimeStep,
    /// A hexahedron's equivalent plastic strain (its part's `erosion_plastic_strain`).
    PlasticStrain,
    /// A selective-reduced hexahedron of an eroding part folded at an integration point
    /// (det J ≤ 0 there): the value is the point's det J over the element's mean, V/8.
    Inverted,
}

impl Criterion {
    /// The `criterion` column of `failures.parquet`.
    pub fn name(self) -> &'static str {
        match self {
            Criterion::Axial => "axial_strain",
            Criterion::Direction1 => "strain_1",
            Criterion::Direction2 => "strain_2",
            Criterion::Force => "force",
            Criterion::Opening => "opening",
            Criterion::TimeStep => "time_step",
            Criterion::PlasticStrain => "plastic_strain",
            Criterion::Inverted => "inverted",
        }
    }
}

/// One failure, as the family saw it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Failure {
    /// The element's kind.
    pub kind: ElementKind,
    /// Index of the element in its family.
    pub element: usize,
    pub criterion: Criterion,
    /// The strain (or force [N], or opening [m], or a membrane's stable step [s]) that
    /// reached the limit.
    pub value: f64,
    /// The limit it reached (with the rate law applied).
    pub limit: f64,
    /// Whether the element left the model (a membrane direction that fails alone under
    /// `failure_all_directions` leaves it standing).
    pub eroded: bool,
    /// The strain energy the failure took [J].
    pub energy: f64,
}

/// A failure with the element's id and nodes, as the families hand it to the solver.
#[derive(Debug, Clone, PartialEq)]
pub struct Collected {
    pub failure: Failure,
    /// Element id (the `element_id` column of its table).
    pub id: i64,
    /// The element's nodes (its force slots').
    pub nodes: Vec<u32>,
}

/// A failure with where and when it happened, as the solver reports it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FailureEvent {
    pub time: f64,
    pub step: u64,
    /// Element id (the `element_id` column of its table).
    pub id: i64,
    pub failure: Failure,
}

/// What became of one element, written by the force pass of the chunk that owns it.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Fate {
    /// Whether the element has left the model.
    pub eroded: bool,
    /// Bit i set: material direction i + 1 has failed (a membrane that stays under
    /// `failure_all_directions`).
    pub dirs: u8,
    /// A failure at the last force pass, not collected yet.
    pub fresh: Option<Failure>,
    /// The strain energy the element's failures took with them so far [J].
    pub energy: f64,
    /// The filtered strains ε̄ of a delayed failure (a truss's in the first, a membrane's
    /// two directions).
    pub filtered: [f64; 2],
}

impl Fate {
    /// Books a failure found by a force pass: the element is eroded when the failure
    /// says so, keeps the energy it took, holds it until it is collected, and sets the
    /// family's flag `any` (its [`Erosion::any`]).
    #[inline]
    pub fn fail(&mut self, failure: Failure, any: &std::sync::atomic::AtomicBool) {
        self.eroded = failure.eroded;
        self.energy += failure.energy;
        self.fresh = Some(failure);
        any.store(true, std::sync::atomic::Ordering::Relaxed);
    }
}

/// The erosion state of a family: its elements' failure laws and fates. Empty (and
/// `active` false) when none of its elements can fail: the family then runs its loops
/// as they were.
#[derive(Debug, Default)]
pub struct Erosion {
    /// Per element, its failure law (strain, or a link's force and opening).
    pub law: Vec<FailureLaw>,
    pub fate: Vec<Fate>,
    /// Set by a force pass that failed an element (read and cleared by [`Erosion::collect`]).
    pub any: std::sync::atomic::AtomicBool,
    /// Elements eroded so far.
    pub eroded: usize,
}

impl Clone for Erosion {
    fn clone(&self) -> Self {
        Erosion {
            law: self.law.clone(),
            fate: self.fate.clone(),
            any: std::sync::atomic::AtomicBool::new(
                self.any.load(std::sync::atomic::Ordering::Relaxed),
            ),
            eroded: self.eroded,
        }
    }
}

impl Erosion {
    /// Erosion for elements with the laws `law`; inactive (and empty) when none can fail.
    pub fn new(law: Vec<FailureLaw>) -> Erosion {
        if !law.iter().any(FailureLaw::can_fail) {
            return Erosion::default();
        }
        Erosion::watching(law)
    }
    /// Erosion that watches every element, whatever its law says (links, whose limits
    /// the family keeps itself).
    pub fn watching(law: Vec<FailureLaw>) -> Erosion {
        let n = law.len();
        Erosion {
            law,
            fate: vec![Fate::default(); n],
            any: Default::default(),
            eroded: 0,
        }
    }
    /// Whether any element can fail.
    #[inline(always)]
    pub fn active(&self) -> bool {
        !self.law.is_empty()
    }
    /// Whether element e is still in the model.
    #[inline(always)]
    pub fn alive(&self, e: usize) -> bool {
        self.fate.get(e).is_none_or(|f| !f.eroded)
    }
    /// Moves the failures of the last force pass, in element order, to `out`.
    pub fn collect(&mut self, out: &mut Vec<Failure>) {
        if !self.any.swap(false, std::sync::atomic::Ordering::Relaxed) {
            return;
        }
        for f in self.fate.iter_mut() {
            if let Some(x) = f.fresh.take() {
                if x.eroded {
                    self.eroded += 1;
                }
                out.push(x);
            }
        }
    }
    /// The strain energy the failures have taken so far [J], summed in element order.
    pub fn eroded_energy(&self) -> f64 {
        self.fate.iter().map(|f| f.energy).sum()
    }
}
