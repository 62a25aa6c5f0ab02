//! Johnson–Cook plasticity (Johnson & Cook, 7th Int. Symp. Ballistics, The Hague, 1983,
//! eq. (1)) with adiabatic heating, by the radial return of [`super::radial_return`]:
//!   σ_y = (A + B ε_pⁿ)(1 + C ln ε̇*)(1 − T*ᵐ),
//! ε̇* = max(ε̇_p/ε̇₀, 1) with ε̇_p = Δε_p/Δt the step's plastic strain rate (LS-DYNA
//! *MAT_JOHNSON_COOK's convention: no rate softening below the reference rate, so the
//! factor is ≥ 1; with Δt ≤ 0 the factor is 1), T* = (T − T_room)/(T_melt − T_room)
//! clamped to [0, 1] (below room temperature no extra strength; at the melting
//! temperature no deviatoric strength: σ_y = 0, the point flows as a fluid, LS-DYNA's
//! MAT_015 behaviour). The thermal factor uses the temperature at the start of the step,
//! T_n (heating is explicit; its change in one step is small). Δε_p solves the
//! consistency condition by the safeguarded Newton iteration [`newton_return`].
//!
//! Adiabatic heating: ΔT = χ ΔW_p/(ρ c_p), ΔW_p the step's plastic work (the radial
//! return's), χ the Taylor–Quinney coefficient (0.9 by default: Taylor & Quinney,
//! Proc. R. Soc. A 143 (1934) 307; LS-DYNA's default), ρ the reference density (plastic
//! flow is isochoric; the elastic volume change of a metal is ≲ 1 %).
//!
//! Columns: `jc_a` A (selects the law), `jc_b` B (0), `jc_n` n (1), `jc_c` C (0),
//! `jc_reference_rate` ε̇₀ (1/s), `jc_m` m and `melt_temperature` T_melt (both or
//! neither: without them no thermal softening), `room_temperature` T_room
//! ([`DEFAULT_TEMPERATURE`]), `specific_heat` c_p (none: no heating), `taylor_quinney` χ
//! ([`TAYLOR_QUINNEY`]); in brackets what a null means.

use super::law::{Columns, Elastic, MaterialLaw, PointState, Selection, DEFAULT_TEMPERATURE};
use super::radial_return::{newton_return, radial_return};
use crate::error::{Result, WeftError};

/// Taylor–Quinney coefficient χ (fraction of plastic work converted to heat): 0.9,
/// Taylor & Quinney (1934), LS-DYNA's default.
pub const TAYLOR_QUINNEY: f64 = 0.9;

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

    /// The constants' ranges (each error names the constant).
    fn check_constants(&self) -> Result<()> {
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

impl MaterialLaw for JohnsonCook {
    const NAME: &'static str = "johnson_cook";
    const SELECTION: Selection = Selection::ByColumn("jc_a");
    const COLUMNS: &'static [&'static str] = &[
        "jc_a",
        "jc_b",
        "jc_n",
        "jc_c",
        "jc_reference_rate",
        "jc_m",
        "room_temperature",
        "melt_temperature",
        "specific_heat",
        "taylor_quinney",
    ];

    fn from_columns(cols: &dyn Columns, _elastic: &Elastic) -> Result<Self> {
        let (m, melt) = (cols.f64("jc_m"), cols.f64("melt_temperature"));
        // Without m (or T_melt) no thermal softening, without c_p no heating: T_melt and
        // c_p then stand at f64::MAX, which makes T* = 0 and ΔT = 0 (to round-off)
        // without a second code path.
        if m.is_some() != melt.is_some() {
            let (has, lacks) = if m.is_some() {
                ("`jc_m`", "`melt_temperature`")
            } else {
                ("`melt_temperature`", "`jc_m`")
            };
            return Err(WeftError::input(format!("has {has} without {lacks}"))
                .expected("both (thermal softening) or neither"));
        }
        Ok(JohnsonCook {
            a: cols.f64("jc_a").unwrap_or(f64::NAN),
            b: cols.f64("jc_b").unwrap_or(0.0),
            n: cols.f64("jc_n").unwrap_or(1.0),
            c: cols.f64("jc_c").unwrap_or(0.0),
            reference_rate: cols.f64("jc_reference_rate").unwrap_or(1.0),
            m: m.unwrap_or(1.0),
            room_temperature: cols.f64("room_temperature").unwrap_or(DEFAULT_TEMPERATURE),
            melt_temperature: melt.unwrap_or(f64::MAX),
            specific_heat: cols.f64("specific_heat").unwrap_or(f64::MAX),
            taylor_quinney: cols.f64("taylor_quinney").unwrap_or(TAYLOR_QUINNEY),
        })
    }
    fn validate(&self) -> Result<()> {
        self.check_constants()
    }
    fn initial_temperature(&self) -> f64 {
        self.room_temperature
    }
    #[inline]
    fn update(&self, elastic: &Elastic, st: &mut PointState, deps: &[f64; 6], dt: f64) {
        let (ep, t) = (st.plastic_strain, st.temperature);
        // σ_y at the start (Δ = 0: no rate effect), then the return.
        let sy0 = self.flow_stress(ep, 0.0, t);
        let dw = radial_return(elastic, st, deps, |sbar, mu| {
            if sbar <= sy0 {
                0.0
            } else {
                newton_return(sbar, 3.0 * mu, sbar - sy0, |d| {
                    self.flow_stress_step(ep, d, dt, t)
                })
            }
        });
        if dw > 0.0 {
            st.temperature += self.taylor_quinney * dw / (elastic.density * self.specific_heat);
        }
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::super::radial_return::{pressure, von_mises, RETURN_TOLERANCE};
    use super::super::tests::elastic;
    use super::super::{Law, Material};
    use super::*;
    use crate::random::Stream;

    /// OFHC copper, Johnson & Cook (1983) Table 1: A = 90 MPa, B = 292 MPa, n = 0.31,
    /// C = 0.025, m = 1.09, T_melt = 1356 K, c_p = 383 J/(kg K), ρ = 8960 kg/m³
    /// (ε̇₀ = 1/s, T_room = 294 K as in their tests); E = 124 GPa, ν = 0.34 (handbook).
    pub(crate) fn copper() -> Material {
        let jc = JohnsonCook {
            a: 90e6,
            b: 292e6,
            n: 0.31,
            c: 0.025,
            reference_rate: 1.0,
            m: 1.09,
            room_temperature: 294.0,
            melt_temperature: 1356.0,
            specific_heat: 383.0,
            taylor_quinney: TAYLOR_QUINNEY,
        };
        Material::new(elastic(124e9, 0.34, 8960.0), Law::JohnsonCook(jc), None).unwrap()
    }

    fn jc(m: &Material) -> JohnsonCook {
        match m.law {
            Law::JohnsonCook(j) => j,
            _ => unreachable!(),
        }
    }

    /// Johnson–Cook at two plastic strain rates and a raised temperature: the returned
    /// stress equals (A + B ε_pⁿ)(1 + C ln ε̇*)(1 − T*ᵐ) written out here (Johnson & Cook
    /// 1983, eq. (1)) at the converged ε_p, ε̇_p = Δε_p/Δt, T_n, to 1e-10 and, tighter,
    /// to the return's own bound: |r| ≤ 1e-14 σ̄_tr, i.e. 1e-14 σ̄_tr/σ_y relative (×2 for
    /// round-off); measured 4.8e-14 with σ̄_tr/σ_y ≈ 5.
    #[test]
    fn johnson_cook_matches_the_formula() {
        let mat = copper();
        let j = jc(&mat);
        let formula = |ep: f64, rate: f64, t: f64| {
            let ts: f64 = ((t - 294.0) / (1356.0 - 294.0)).clamp(0.0, 1.0);
            (90e6 + 292e6 * ep.powf(0.31))
                * (1.0 + 0.025 * (rate / 1.0).max(1.0).ln())
                * (1.0 - ts.powf(1.09))
        };
        let mut results = vec![];
        for (dt, t) in [
            (1e-3, 294.0),
            (1e-6, 294.0),
            (1e-3, 700.0),
            (1e-6, 700.0),
            (100.0, 294.0),
        ] {
            for ep0 in [0.0, 0.2] {
                let mut st = mat.initial_state();
                st.plastic_strain = ep0;
                st.temperature = t;
                // An isochoric increment well past yield.
                let de = 0.01;
                mat.update(&mut st, &[de, -0.5 * de, -0.5 * de, 0.0, 0.0, 0.0], dt);
                let d = st.plastic_strain - ep0;
                assert!(d > 0.0);
                let rate = d / dt;
                let expect = formula(st.plastic_strain, rate, t);
                let got = von_mises(&st.stress);
                assert!(
                    (got - expect).abs() < 1e-10 * expect
                        && (got - expect).abs()
                            < 2.0 * RETURN_TOLERANCE * (got + 3.0 * mat.shear_modulus() * d),
                    "dt {dt} T {t}: {got} vs {expect}"
                );
                assert_eq!(expect, j.flow_stress(st.plastic_strain, rate, t));
                assert!(pressure(&st.stress).abs() < 1e-6);
                results.push((dt, t, ep0, rate, got));
            }
        }
        // The rate factor raised the stress at the fast rate (≈ 1e4/s vs ≈ 10/s: ×(1 + C ln 1e3)
        // ≈ 1.17 at equal strain, nearly), the temperature lowered it, and ε̇_p < ε̇₀ (dt =
        // 100 s) gives the quasi-static curve (rate factor 1).
        let (slow, fast, hot) = (results[0], results[2], results[4]);
        assert!(
            slow.3 > 5.0 && fast.3 > 5e3 && results[8].3 < 1.0,
            "{results:?}"
        );
        assert!(fast.4 > 1.1 * slow.4 && hot.4 < 0.8 * slow.4);
        let qs = results[8];
        assert!((qs.4 - formula(qs.2 + qs.3 * 100.0, 0.0, 294.0)).abs() < 1e-13 * qs.4); // 5.7e-16
                                                                                         // Melted: no deviatoric stress.
        let mut st = mat.initial_state();
        st.temperature = 1400.0;
        mat.update(&mut st, &[0.01, -0.005, -0.005, 0.0, 0.0, 0.0], 1e-6);
        assert!(von_mises(&st.stress) < 1e-6, "{:?}", st.stress);
    }

    /// Plastic work and heating under a nonlinear law (Johnson–Cook, rising rate-free
    /// curve with heating): (i) W_p = Σ σ̄_{n+1}Δε_p equals Σ σ_{n+1}:Δε^p with Δε^p
    /// recovered independently from the total strain, Δε^p = dε − C⁻¹:Δσ (the elastic
    /// compliance), to round-off; (ii) against the trapezoid ∫σ̄ dε_p on the recorded
    /// curve, the difference is ½ Σ Δσ̄ Δε_p ≥ 0, bounded by ½ max Δε_p (σ̄_end − σ̄_start);
    /// (iii) T − T₀ = χ W_p/(ρ c_p).
    #[test]
    fn plastic_work_and_adiabatic_heating() {
        let mat = copper();
        let j = jc(&mat);
        let (e, nu) = (mat.elastic.youngs_modulus, mat.elastic.poisson_ratio);
        let mut st = mat.initial_state();
        let t0 = st.temperature;
        let mut r = Stream::new(11);
        let mut w_tensor = 0.0;
        let mut curve = vec![(0.0, 0.0)];
        for _ in 0..400 {
            // A mostly deviatoric increment with some volume change and shear, ε̇ ~ 1e3/s.
            let de: [f64; 6] = [
                1e-3,
                -0.5e-3 + 1e-4 * (r.next_uniform() - 0.5),
                -0.5e-3 + 1e-4 * (r.next_uniform() - 0.5),
                2e-4 * (r.next_uniform() - 0.5),
                2e-4 * (r.next_uniform() - 0.5),
                2e-4 * (r.next_uniform() - 0.5),
            ];
            let before = st;
            mat.update(&mut st, &de, 1e-6);
            let ds: [f64; 6] = std::array::from_fn(|k| st.stress[k] - before.stress[k]);
            // C⁻¹: ε_ii = (σ_ii − ν(σ_jj + σ_kk))/E, ε_ij = (1 + ν)σ_ij/E (tensor).
            let tr = ds[0] + ds[1] + ds[2];
            let dep: [f64; 6] = std::array::from_fn(|k| {
                if k < 3 {
                    de[k] - ((1.0 + nu) * ds[k] - nu * tr) / e
                } else {
                    de[k] - (1.0 + nu) * ds[k] / e
                }
            });
            let s = st.stress;
            w_tensor += s[0] * dep[0]
                + s[1] * dep[1]
                + s[2] * dep[2]
                + 2.0 * (s[3] * dep[3] + s[4] * dep[4] + s[5] * dep[5]);
            curve.push((st.plastic_strain, von_mises(&st.stress)));
        }
        // The first increment yields from zero; start the curve at yield (σ̄ = A).
        curve[0].1 = 90e6;
        let wp = st.plastic_work;
        assert!(
            st.plastic_strain > 0.3 && wp > 1e8,
            "{} {wp}",
            st.plastic_strain
        );
        // (i) Backward-Euler consistency: measured equal to the last bit; the bound is the
        // round-off of recovering Δε^p by subtraction (400 steps, ~1e-15 each).
        assert!(
            (wp - w_tensor).abs() < 1e-12 * wp,
            "W_p {wp} vs Σσ:Δε^p {w_tensor}"
        );
        // (ii) Trapezoid.
        let mut trap = 0.0;
        let mut half = 0.0;
        let mut max_dep = 0.0f64;
        for k in 1..curve.len() {
            let (d, s0, s1) = (curve[k].0 - curve[k - 1].0, curve[k - 1].1, curve[k].1);
            trap += 0.5 * (s0 + s1) * d;
            half += 0.5 * (s1 - s0) * d;
            max_dep = max_dep.max(d);
        }
        let bound = 0.5 * max_dep * (curve.last().unwrap().1 - curve[0].1).abs();
        assert!((wp - trap - half).abs() < 1e-12 * wp, "{wp} {trap} {half}");
        assert!(
            (wp - trap).abs() <= bound,
            "W_p − trapezoid = {}, bound {bound}",
            wp - trap
        );
        // Measured (W_p − trapezoid)/W_p = 9.8e-4 against the bound's 1.15e-3.
        assert!((wp - trap).abs() < 2e-3 * wp);
        // (iii) Heating.
        let dt_expect = j.taylor_quinney * wp / (mat.density() * j.specific_heat);
        assert!((st.temperature - t0 - dt_expect).abs() < 1e-14 * dt_expect); // 3.1e-15
        assert!(dt_expect > 20.0, "{dt_expect}");
    }

    /// Each bad constant is refused, and the message names it.
    #[test]
    fn bad_input_is_refused_by_name() {
        let ok = jc(&copper());
        let cases: [(fn(&mut JohnsonCook), &str); 11] = [
            (|j| j.a = 0.0, "A ="),
            (|j| j.b = -1.0, "B ="),
            (|j| j.n = 0.0, "exponent n"),
            (|j| j.n = 1.5, "exponent n"),
            (|j| j.c = -0.1, "constant C"),
            (|j| j.reference_rate = 0.0, "reference strain rate"),
            (|j| j.m = 0.0, "exponent m"),
            (|j| j.melt_temperature = j.room_temperature, "T_melt"),
            (|j| j.specific_heat = 0.0, "specific heat"),
            (|j| j.taylor_quinney = 1.1, "Taylor–Quinney"),
            (|j| j.taylor_quinney = -0.1, "Taylor–Quinney"),
        ];
        for (f, name) in cases {
            let mut j = ok;
            f(&mut j);
            let el = elastic(124e9, 0.34, 8960.0);
            let m = format!(
                "{}",
                Material::new(el, Law::JohnsonCook(j), None).unwrap_err()
            );
            assert!(m.contains(name), "{m} lacks {name}");
        }
        assert!(ok.check_temperature(1000.0).is_ok());
        assert!(format!("{}", ok.check_temperature(1356.0).unwrap_err()).contains("melting"));
    }
}
