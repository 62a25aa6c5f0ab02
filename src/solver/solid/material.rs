//! Materials of the solid elements, at one integration point: isotropic hypoelasticity,
//! J2 (von Mises) plasticity with isotropic hardening (bilinear or tabulated) by radial
//! return, and Johnson–Cook (strain hardening, strain rate, thermal softening with
//! adiabatic heating from plastic work), with optional erosion at an equivalent plastic
//! strain. Pure functions of the point's state and its strain increment.
//!
//! Glossary: σ Cauchy stress [Pa], Voigt order [xx, yy, zz, xy, yz, zx], TENSOR
//! components for stress and strain alike (dε_xy = D_xy Δt, half the engineering shear
//! increment); s = σ + p I the deviator; p = −tr σ/3 the pressure (compression positive);
//! σ̄ = √(3/2 s:s) the von Mises stress (s:s counts each shear component twice); ε_p the
//! equivalent plastic strain, Δε_p its increment in a step; E, ν Young's modulus and
//! Poisson's ratio; λ = Eν/((1 + ν)(1 − 2ν)), μ = E/(2(1 + ν)) the Lamé constants;
//! K = λ + ⅔μ the bulk modulus; σ_y(ε_p, ε̇_p, T) the flow stress; W_p the plastic work
//! per unit volume [J/m³]; T the temperature [K].
//!
//! Elasticity (hypoelastic, the rotated-frame update of the kernel's Hughes–Winget step):
//!   σ_tr = σ + λ tr(dε) I + 2μ dε      (so σ_xy += 2μ dε_xy with tensor dε_xy).
//! Plasticity (Simo & Hughes, *Computational Inelasticity*, §3.3: the radial
//! return, backward Euler on the associative J2 flow rule; BLM *Nonlinear Finite
//! Elements* ch. 5): with σ̄_tr the von Mises stress of the trial deviator s_tr, if
//! σ̄_tr ≤ σ_y(ε_p) the step is elastic; otherwise Δε_p solves the consistency condition
//!   r(Δε_p) = σ̄_tr − 3μ Δε_p − σ_y(ε_p + Δε_p, Δε_p/Δt, T_n) = 0,
//! and s = (1 − 3μΔε_p/σ̄_tr) s_tr, p unchanged (J2 flow is deviatoric, so the radial
//! return leaves the pressure of the trial state). For linear hardening σ_y = σ_y0 + H ε_p
//! the root is explicit, Δε_p = (σ̄_tr − σ_y(ε_p))/(3μ + H) (S&H §3.3); for the
//! tabulated law and Johnson–Cook a scalar Newton iteration on Δε_p, safeguarded by
//! bisection on the bracket [0, (σ̄_tr − σ_y(ε_p))/(3μ)] (r is decreasing in Δε_p for a
//! non-softening σ_y, r(0) > 0 and r ≤ 0 at the right end), converges to
//! |r| ≤ 1e-14 σ̄_tr. After the return σ̄ = σ̄_tr − 3μΔε_p = σ_y at the converged point.
//!
//! Johnson–Cook (Johnson & Cook, 7th Int. Symp. Ballistics, The Hague, 1983, eq. (1)):
//!   σ_y = (A + B ε_pⁿ)(1 + C ln ε̇*)(1 − T*ᵐ),
//! ε̇* = max(ε̇_p/ε̇₀, 1) with ε̇_p = Δε_p/Δt the step's plastic strain rate (LS-DYNA
//! *MAT_JOHNSON_COOK's convention: no rate softening below the reference rate, so the
//! factor is ≥ 1; with Δt ≤ 0 the factor is 1), T* = (T − T_room)/(T_melt − T_room)
//! clamped to [0, 1] (below room temperature no extra strength; at the melting
//! temperature no deviatoric strength: σ_y = 0, the point flows as a fluid, LS-DYNA's
//! MAT_015 behaviour). The thermal factor uses the temperature at the start of the step,
//! T_n (heating is explicit; its change in one step is small).
//!
//! Plastic work and heating: ΔW_p = σ̄_{n+1} Δε_p with the END-of-step flow stress. This is
//! exactly σ_{n+1}:Δε^p of the backward-Euler plastic strain increment
//! Δε^p = Δε_p (3/2) s_{n+1}/σ̄_{n+1} (the return's normal), so Σ ΔW_p = Σ σ_{n+1}:Δε^p, the
//! rectangle rule for ∫σ:dε^p that the radial return itself implies (it differs from the
//! trapezoid rule by ½ Σ Δσ̄ Δε_p, first order in the step). Adiabatic heating (Johnson–
//! Cook only): ΔT = χ ΔW_p/(ρ c_p), χ the Taylor–Quinney coefficient (0.9 by default:
//! Taylor & Quinney, Proc. R. Soc. A 143 (1934) 307; LS-DYNA's default), ρ the reference
//! density (plastic flow is isochoric; the elastic volume change of a metal is ≲ 1 %).
//!
//! Erosion: when ε_p ≥ `erosion_plastic_strain` the point is flagged `eroded` (the family
//! deletes the element); an eroded point carries no stress in later updates.

use crate::error::{Result, WeftError};

/// Taylor–Quinney coefficient χ (fraction of plastic work converted to heat): 0.9,
/// Taylor & Quinney (1934), LS-DYNA's default.
pub const TAYLOR_QUINNEY: f64 = 0.9;
/// Temperature of a point whose material has no thermal law [K] (20 °C).
pub const DEFAULT_TEMPERATURE: f64 = 293.15;
/// Relative tolerance on the consistency residual |r| / σ̄_tr of the Newton return.
pub const RETURN_TOLERANCE: f64 = 1e-14;

/// Isotropic hardening of J2 plasticity: σ_y(ε_p).
#[derive(Debug, Clone, PartialEq)]
pub enum Hardening {
    /// σ_y = σ_y0 + H ε_p, H the plastic modulus [Pa].
    Linear { plastic_modulus: f64 },
    /// σ_y(ε_p) piecewise linear through (strain[i], stress[i]) [–, Pa], constant beyond
    /// the last point; strain strictly increasing from 0; stress the ABSOLUTE flow stress
    /// (LS-DYNA *MAT_PIECEWISE_LINEAR_PLASTICITY's LCSS curve), non-decreasing, its first
    /// value the initial yield stress (the J2 `yield_stress` must equal it).
    Table { strain: Vec<f64>, stress: Vec<f64> },
}

impl Hardening {
    /// Bilinear hardening from the tangent modulus E_t of the uniaxial stress–strain
    /// curve: H = E E_t/(E − E_t) (so that the uniaxial slope after yield,
    /// E H/(E + H), is E_t). Requires 0 ≤ E_t < E.
    pub fn from_tangent_modulus(youngs_modulus: f64, tangent_modulus: f64) -> Result<Hardening> {
        let (e, et) = (youngs_modulus, tangent_modulus);
        if !(et >= 0.0 && et < e) {
            return Err(
                WeftError::input(format!("tangent modulus E_t = {et} Pa with E = {e} Pa"))
                    .expected(
                        "0 ≤ E_t < E (E_t is the slope of the stress–strain curve after yield)",
                    ),
            );
        }
        Ok(Hardening::Linear {
            plastic_modulus: e * et / (e - et),
        })
    }

    /// A validated table (see [`Hardening::Table`]).
    pub fn table(strain: Vec<f64>, stress: Vec<f64>) -> Result<Hardening> {
        let h = Hardening::Table { strain, stress };
        h.validate_shape()?;
        Ok(h)
    }

    fn validate_shape(&self) -> Result<()> {
        match self {
            Hardening::Linear { plastic_modulus: h } => {
                if !(*h >= 0.0 && h.is_finite()) {
                    return Err(WeftError::input(format!("plastic modulus H = {h} Pa"))
                        .expected("0 ≤ H < ∞ (no softening)"));
                }
            }
            Hardening::Table { strain, stress } => {
                if strain.is_empty() || strain.len() != stress.len() {
                    return Err(WeftError::input(format!(
                        "hardening table with {} plastic strains and {} stresses",
                        strain.len(),
                        stress.len()
                    ))
                    .expected("as many stresses as plastic strains, at least one point"));
                }
                if strain[0] != 0.0 {
                    return Err(WeftError::input(format!(
                        "hardening table starts at ε_p = {}",
                        strain[0]
                    ))
                    .expected("the first point at ε_p = 0 (the initial yield stress)"));
                }
                for i in 1..strain.len() {
                    if !(strain[i] > strain[i - 1]) || !strain[i].is_finite() {
                        return Err(WeftError::input(format!(
                            "hardening table plastic strain {} at point {} after {}",
                            strain[i],
                            i + 1,
                            strain[i - 1]
                        ))
                        .expected("strictly increasing, finite plastic strains"));
                    }
                    if !(stress[i] >= stress[i - 1]) || !stress[i].is_finite() {
                        return Err(WeftError::input(format!(
                            "hardening table flow stress {} Pa at point {} after {} Pa",
                            stress[i],
                            i + 1,
                            stress[i - 1]
                        ))
                        .expected("non-decreasing, finite flow stresses (no softening)"));
                    }
                }
                if !(stress[0] > 0.0) {
                    return Err(WeftError::input(format!(
                        "hardening table initial yield stress {} Pa",
                        stress[0]
                    ))
                    .expected("> 0"));
                }
            }
        }
        Ok(())
    }

    /// σ_y(ε_p) and its slope dσ_y/dε_p (right derivative at a table's break point).
    #[inline]
    pub fn flow_stress(&self, yield_stress: f64, ep: f64) -> (f64, f64) {
        match self {
            Hardening::Linear { plastic_modulus: h } => (yield_stress + h * ep, *h),
            Hardening::Table { strain, stress } => {
                // i: the last point with strain[i] ≤ ep.
                let i = strain.partition_point(|&e| e <= ep).max(1) - 1;
                if i + 1 >= strain.len() {
                    (stress[stress.len() - 1], 0.0)
                } else {
                    let slope = (stress[i + 1] - stress[i]) / (strain[i + 1] - strain[i]);
                    (stress[i] + slope * (ep - strain[i]), slope)
                }
            }
        }
    }
}

/// Johnson–Cook constants (Johnson & Cook 1983), SI units.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct JohnsonCook {
    /// A: the yield stress at ε_p = 0, reference rate, room temperature [Pa].
    pub a: f64,
    /// B: the hardening modulus [Pa].
    pub b: f64,
    /// n: the hardening exponent, 0 < n ≤ 1.
    pub n: f64,
    /// C: the strain-rate constant.
    pub c: f64,
    /// ε̇₀: the reference plastic strain rate [1/s].
    pub reference_rate: f64,
    /// m: the thermal-softening exponent.
    pub m: f64,
    /// T_room [K].
    pub room_temperature: f64,
    /// T_melt [K].
    pub melt_temperature: f64,
    /// c_p [J/(kg K)].
    pub specific_heat: f64,
    /// χ: the fraction of plastic work turned into heat ([`TAYLOR_QUINNEY`] = 0.9).
    pub taylor_quinney: f64,
}

impl JohnsonCook {
    /// T* = (T − T_room)/(T_melt − T_room) clamped to [0, 1].
    #[inline]
    pub fn homologous_temperature(&self, t: f64) -> f64 {
        ((t - self.room_temperature) / (self.melt_temperature - self.room_temperature))
            .clamp(0.0, 1.0)
    }

    /// σ_y = (A + B ε_pⁿ)(1 + C ln max(ε̇_p/ε̇₀, 1))(1 − T*ᵐ) (module header).
    pub fn flow_stress(&self, ep: f64, rate: f64, t: f64) -> f64 {
        (self.a + self.b * ep.powf(self.n))
            * (1.0 + self.c * (rate / self.reference_rate).max(1.0).ln())
            * (1.0 - self.homologous_temperature(t).powf(self.m))
    }

    /// σ_y at ε_p + Δ with the rate Δ/Δt, temperature t, and ∂σ_y/∂Δ.
    #[inline]
    fn flow_stress_step(&self, ep: f64, d: f64, dt: f64, t: f64) -> (f64, f64) {
        let e = ep + d;
        let en = e.powf(self.n);
        let strain = self.a + self.b * en;
        let dstrain = if e > 0.0 {
            self.n * self.b * en / e
        } else {
            f64::INFINITY
        };
        let x = if dt > 0.0 {
            d / (dt * self.reference_rate)
        } else {
            0.0
        };
        let (rate, drate) = if x > 1.0 {
            (1.0 + self.c * x.ln(), self.c / d)
        } else {
            (1.0, 0.0)
        };
        let theta = 1.0 - self.homologous_temperature(t).powf(self.m);
        let dsy = if self.b == 0.0 {
            0.0
        } else {
            dstrain * rate * theta
        };
        (strain * rate * theta, dsy + strain * drate * theta)
    }

    /// The constants' ranges (module errors name the constant).
    pub fn validate(&self) -> Result<()> {
        let bad = |what: String, exp: &str| Err(WeftError::input(what).expected(exp.to_string()));
        let j = self;
        if !(j.a > 0.0 && j.a.is_finite()) {
            return bad(
                format!("Johnson–Cook A = {} Pa", j.a),
                "A > 0 (the initial yield stress)",
            );
        }
        if !(j.b >= 0.0 && j.b.is_finite()) {
            return bad(format!("Johnson–Cook B = {} Pa", j.b), "B ≥ 0");
        }
        if !(j.n > 0.0 && j.n <= 1.0) {
            return bad(
                format!("Johnson–Cook hardening exponent n = {}", j.n),
                "0 < n ≤ 1",
            );
        }
        if !(j.c >= 0.0 && j.c.is_finite()) {
            return bad(
                format!("Johnson–Cook strain-rate constant C = {}", j.c),
                "C ≥ 0",
            );
        }
        if !(j.reference_rate > 0.0 && j.reference_rate.is_finite()) {
            return bad(
                format!(
                    "Johnson–Cook reference strain rate ε̇₀ = {} 1/s",
                    j.reference_rate
                ),
                "ε̇₀ > 0",
            );
        }
        if !(j.m > 0.0 && j.m.is_finite()) {
            return bad(
                format!("Johnson–Cook thermal exponent m = {}", j.m),
                "m > 0",
            );
        }
        if !(j.room_temperature < j.melt_temperature
            && j.room_temperature.is_finite()
            && j.melt_temperature.is_finite())
        {
            return bad(
                format!(
                    "Johnson–Cook T_room = {} K, T_melt = {} K",
                    j.room_temperature, j.melt_temperature
                ),
                "T_room < T_melt",
            );
        }
        if !(j.specific_heat > 0.0 && j.specific_heat.is_finite()) {
            return bad(
                format!(
                    "Johnson–Cook specific heat c_p = {} J/(kg K)",
                    j.specific_heat
                ),
                "c_p > 0",
            );
        }
        if !(j.taylor_quinney >= 0.0 && j.taylor_quinney <= 1.0) {
            return bad(
                format!("Taylor–Quinney coefficient χ = {}", j.taylor_quinney),
                "0 ≤ χ ≤ 1",
            );
        }
        Ok(())
    }

    /// An initial (or prescribed) temperature must be below melt: at T ≥ T_melt the
    /// material has no strength.
    pub fn check_temperature(&self, t: f64) -> Result<()> {
        if !(t < self.melt_temperature) {
            return Err(WeftError::input(format!(
                "temperature {t} K at or above the Johnson–Cook melting temperature {} K",
                self.melt_temperature
            ))
            .expected(format!("T < T_melt = {} K", self.melt_temperature)));
        }
        Ok(())
    }
}

/// The constitutive model.
#[derive(Debug, Clone, PartialEq)]
pub enum Model {
    Elastic,
    /// J2 plasticity with isotropic hardening, σ_y(ε_p) = `hardening` from σ_y0 =
    /// `yield_stress` [Pa]; rate- and temperature-independent, no heating.
    J2 {
        yield_stress: f64,
        hardening: Hardening,
    },
    JohnsonCook(JohnsonCook),
}

/// A solid material: isotropic elasticity and a plasticity model.
#[derive(Debug, Clone, PartialEq)]
pub struct Material {
    /// E [Pa].
    pub youngs_modulus: f64,
    /// ν.
    pub poisson_ratio: f64,
    /// ρ (reference) [kg/m³].
    pub density: f64,
    pub model: Model,
    /// Flag the point eroded when ε_p reaches this value (None: never).
    pub erosion_plastic_strain: Option<f64>,
}

impl Material {
    /// A validated material.
    pub fn new(
        youngs_modulus: f64,
        poisson_ratio: f64,
        density: f64,
        model: Model,
        erosion_plastic_strain: Option<f64>,
    ) -> Result<Material> {
        let m = Material {
            youngs_modulus,
            poisson_ratio,
            density,
            model,
            erosion_plastic_strain,
        };
        m.validate()?;
        Ok(m)
    }

    /// E > 0, −1 < ν < ½, ρ > 0, erosion strain > 0, and the model's own ranges.
    pub fn validate(&self) -> Result<()> {
        let (e, nu, rho) = (self.youngs_modulus, self.poisson_ratio, self.density);
        if !(e > 0.0 && e.is_finite()) {
            return Err(WeftError::input(format!("Young's modulus E = {e} Pa")).expected("E > 0"));
        }
        if !(nu > -1.0 && nu < 0.5) {
            return Err(WeftError::input(format!("Poisson's ratio ν = {nu}"))
                .expected("−1 < ν < 0.5 (a positive bulk and shear modulus)"));
        }
        if !(rho > 0.0 && rho.is_finite()) {
            return Err(WeftError::input(format!("density ρ = {rho} kg/m³")).expected("ρ > 0"));
        }
        if let Some(ef) = self.erosion_plastic_strain {
            if !(ef > 0.0) {
                return Err(WeftError::input(format!("erosion plastic strain {ef}"))
                    .expected("> 0 (or no erosion)"));
            }
        }
        match &self.model {
            Model::Elastic => {}
            Model::J2 {
                yield_stress,
                hardening,
            } => {
                if !(*yield_stress > 0.0 && yield_stress.is_finite()) {
                    return Err(
                        WeftError::input(format!("yield stress σ_y0 = {yield_stress} Pa"))
                            .expected("σ_y0 > 0"),
                    );
                }
                hardening.validate_shape()?;
                if let Hardening::Table { stress, .. } = hardening {
                    if (stress[0] - yield_stress).abs() > 1e-12 * yield_stress {
                        return Err(WeftError::input(format!(
                            "yield stress σ_y0 = {yield_stress} Pa but the hardening table starts at {} Pa",
                            stress[0]
                        ))
                        .expected("σ_y0 equal to the table's flow stress at ε_p = 0"));
                    }
                }
            }
            Model::JohnsonCook(jc) => jc.validate()?,
        }
        Ok(())
    }

    /// (λ, μ) = (Eν/((1 + ν)(1 − 2ν)), E/(2(1 + ν))).
    pub fn lame(&self) -> (f64, f64) {
        let (e, nu) = (self.youngs_modulus, self.poisson_ratio);
        (
            e * nu / ((1.0 + nu) * (1.0 - 2.0 * nu)),
            e / (2.0 * (1.0 + nu)),
        )
    }

    /// μ = G.
    pub fn shear_modulus(&self) -> f64 {
        self.lame().1
    }

    /// K = E/(3(1 − 2ν)).
    pub fn bulk_modulus(&self) -> f64 {
        self.youngs_modulus / (3.0 * (1.0 - 2.0 * self.poisson_ratio))
    }

    /// c = √((λ + 2μ)/ρ), the dilatational (P-wave) speed, for the stable step, the bulk
    /// viscosity and the hourglass coefficient.
    pub fn dilatational_wave_speed(&self) -> f64 {
        let (l, m) = self.lame();
        ((l + 2.0 * m) / self.density).sqrt()
    }

    /// The unstressed virgin state: at T_room for Johnson–Cook, [`DEFAULT_TEMPERATURE`]
    /// otherwise.
    pub fn initial_state(&self) -> PointState {
        let t = match &self.model {
            Model::JohnsonCook(jc) => jc.room_temperature,
            _ => DEFAULT_TEMPERATURE,
        };
        PointState {
            temperature: t,
            ..PointState::default()
        }
    }
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

/// p = −tr σ/3 (compression positive).
#[inline]
pub fn pressure(s: &[f64; 6]) -> f64 {
    -(s[0] + s[1] + s[2]) / 3.0
}

/// σ̄ = √(3/2 s:s) = √(½((σ₁₁−σ₂₂)² + (σ₂₂−σ₃₃)² + (σ₃₃−σ₁₁)²) + 3(σ₁₂² + σ₂₃² + σ₃₁²)).
#[inline]
pub fn von_mises(s: &[f64; 6]) -> f64 {
    let (a, b, c) = (s[0] - s[1], s[1] - s[2], s[2] - s[0]);
    (0.5 * (a * a + b * b + c * c) + 3.0 * (s[3] * s[3] + s[4] * s[4] + s[5] * s[5])).sqrt()
}

/// Solve r(Δ) = σ̄_tr − 3μΔ − σ_y(Δ) = 0 for Δ ∈ (0, hi], hi = r(0)/(3μ) (then r(hi) ≤ 0
/// for non-decreasing σ_y): Newton from hi, bisection whenever Newton leaves the bracket
/// (module header). `sy(Δ)` returns (σ_y, dσ_y/dΔ).
fn newton_return(sbar_tr: f64, mu3: f64, r0: f64, sy: impl Fn(f64) -> (f64, f64)) -> f64 {
    let (mut lo, mut hi) = (0.0, r0 / mu3);
    let mut d = hi;
    for _ in 0..200 {
        let (s, ds) = sy(d);
        let r = sbar_tr - mu3 * d - s;
        if r.abs() <= RETURN_TOLERANCE * sbar_tr {
            return d;
        }
        if r > 0.0 {
            lo = d;
        } else {
            hi = d;
        }
        let dn = d + r / (mu3 + ds);
        d = if dn > lo && dn < hi {
            dn
        } else {
            0.5 * (lo + hi)
        };
        if hi - lo <= 4.0 * f64::EPSILON * hi {
            return d;
        }
    }
    d
}

/// Advance one integration point by the strain increment `deps` = D Δt (tensor
/// components, Voigt order) over the step `dt` (module header: hypoelastic trial, radial
/// return, plastic work, heating, erosion flag). The stress is in the frame already
/// rotated by the kernel's Hughes–Winget step.
pub fn update(mat: &Material, st: &mut PointState, deps: &[f64; 6], dt: f64) {
    if st.eroded {
        st.stress = [0.0; 6];
        return;
    }
    let (lam, mu) = mat.lame();
    let tr = deps[0] + deps[1] + deps[2];
    let mut s = st.stress;
    for i in 0..3 {
        s[i] += lam * tr + 2.0 * mu * deps[i];
    }
    for i in 3..6 {
        s[i] += 2.0 * mu * deps[i];
    }
    let ep = st.plastic_strain;
    let t = st.temperature;
    let sbar = von_mises(&s);
    // σ_y at the start (Δ = 0: no rate effect) and the return.
    let d = match &mat.model {
        Model::Elastic => 0.0,
        Model::J2 {
            yield_stress,
            hardening,
        } => {
            let (sy0, _) = hardening.flow_stress(*yield_stress, ep);
            if sbar <= sy0 {
                0.0
            } else {
                match hardening {
                    Hardening::Linear { plastic_modulus: h } => (sbar - sy0) / (3.0 * mu + h),
                    Hardening::Table { .. } => newton_return(sbar, 3.0 * mu, sbar - sy0, |d| {
                        hardening.flow_stress(*yield_stress, ep + d)
                    }),
                }
            }
        }
        Model::JohnsonCook(jc) => {
            let sy0 = jc.flow_stress(ep, 0.0, t);
            if sbar <= sy0 {
                0.0
            } else {
                newton_return(sbar, 3.0 * mu, sbar - sy0, |d| {
                    jc.flow_stress_step(ep, d, dt, t)
                })
            }
        }
    };
    if d > 0.0 {
        let p = pressure(&s);
        let k = (1.0 - 3.0 * mu * d / sbar).max(0.0);
        for v in s[..3].iter_mut() {
            *v = k * (*v + p) - p;
        }
        for v in s[3..].iter_mut() {
            *v *= k;
        }
        let dw = (sbar - 3.0 * mu * d).max(0.0) * d;
        st.plastic_strain = ep + d;
        st.plastic_work += dw;
        if let Model::JohnsonCook(jc) = &mat.model {
            st.temperature += jc.taylor_quinney * dw / (mat.density * jc.specific_heat);
        }
        if let Some(ef) = mat.erosion_plastic_strain {
            if st.plastic_strain >= ef {
                st.eroded = true;
            }
        }
    }
    st.stress = s;
}

#[cfg(test)]
#[path = "material_tests.rs"]
mod tests;
