//! Plasticine (oil-based modelling clay, the backing of the body-armour test): von Mises
//! plasticity whose flow stress rises as a power of the plastic strain rate, by the
//! radial return of [`super::radial_return`]:
//!   σ_y = (A + B ε_pⁿ) · max(ε̇_p/ε̇₀, 1)ᵐ,
//! ε̇_p = Δε_p/Δt the step's plastic strain rate. The power law in the rate is the form
//! fitted to oil-based clays (Roma Plastilina No. 1) from drop and penetration tests,
//! where the flow stress grows by one or two orders of magnitude from quasi-static rates
//! to the 10³–10⁴ s⁻¹ under a bullet, which Johnson–Cook's logarithm does not follow; no
//! heating (the clay's temperature is the standard's conditioning, not the shot's).
//! Below the reference rate the factor is 1 (no rate softening, as Johnson–Cook's
//! convention in [`super::johnson_cook`]). Δε_p solves the consistency condition by the
//! safeguarded Newton iteration [`newton_return`].
//!
//! Columns: `plasticine_a` A (selects the law), `plasticine_b` B (0), `plasticine_n` n
//! (1), `plasticine_m` m (0: rate-independent), `plasticine_reference_rate` ε̇₀ (1/s);
//! in brackets what a null means. The constants of the clay the armour test uses, and
//! how they were set, are in docs/theory.md ("The backing clay").

use super::law::{Columns, Elastic, MaterialLaw, PointState, Selection};
use super::radial_return::{newton_return, radial_return};
use crate::error::{Result, WeftError};

/// The plasticine law's constants, SI units.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Plasticine {
    /// A: the flow stress at ε_p = 0 at or below the reference rate [Pa].
    pub a: f64,
    /// B: the hardening modulus [Pa].
    pub b: f64,
    /// n: the hardening exponent, 0 < n ≤ 1.
    pub n: f64,
    /// m: the rate exponent, 0 ≤ m < 1.
    pub m: f64,
    /// ε̇₀: the reference plastic strain rate [1/s].
    pub reference_rate: f64,
}

impl Plasticine {
    /// σ_y = (A + B ε_pⁿ) max(ε̇_p/ε̇₀, 1)ᵐ (module header).
    pub fn flow_stress(&self, ep: f64, rate: f64) -> f64 {
        (self.a + self.b * ep.powf(self.n)) * (rate / self.reference_rate).max(1.0).powf(self.m)
    }

    /// σ_y at ε_p + Δ with the rate Δ/Δt, and ∂σ_y/∂Δ.
    #[inline]
    fn flow_stress_step(&self, ep: f64, d: f64, dt: f64) -> (f64, f64) {
        let e = ep + d;
        let en = e.powf(self.n);
        let strain = self.a + self.b * en;
        let dstrain = if self.b == 0.0 {
            0.0
        } else if e > 0.0 {
            self.n * self.b * en / e
        } else {
            f64::INFINITY
        };
        let x = if dt > 0.0 {
            d / (dt * self.reference_rate)
        } else {
            0.0
        };
        let (rate, drate) = if x > 1.0 && self.m > 0.0 {
            let r = x.powf(self.m);
            (r, self.m * r / d)
        } else {
            (1.0, 0.0)
        };
        (strain * rate, dstrain * rate + strain * drate)
    }

    /// The constants' ranges (each error names the constant and its column).
    fn check_constants(&self) -> Result<()> {
        let bad = |what: String, exp: &str| Err(WeftError::input(what).expected(exp.to_string()));
        let p = self;
        if !(p.a > 0.0 && p.a.is_finite()) {
            return bad(
                format!("plasticine A (`plasticine_a`) = {} Pa", p.a),
                "A > 0 (the flow stress at the reference rate)",
            );
        }
        if !(p.b >= 0.0 && p.b.is_finite()) {
            return bad(
                format!("plasticine B (`plasticine_b`) = {} Pa", p.b),
                "B ≥ 0",
            );
        }
        if !(p.n > 0.0 && p.n <= 1.0) {
            return bad(
                format!("plasticine hardening exponent n (`plasticine_n`) = {}", p.n),
                "0 < n ≤ 1",
            );
        }
        if !(p.m >= 0.0 && p.m < 1.0) {
            return bad(
                format!("plasticine rate exponent m (`plasticine_m`) = {}", p.m),
                "0 ≤ m < 1 (0: rate-independent)",
            );
        }
        if !(p.reference_rate > 0.0 && p.reference_rate.is_finite()) {
            return bad(
                format!(
                    "plasticine reference strain rate ε̇₀ (`plasticine_reference_rate`) = {} 1/s",
                    p.reference_rate
                ),
                "ε̇₀ > 0",
            );
        }
        Ok(())
    }
}

impl MaterialLaw for Plasticine {
    const NAME: &'static str = "plasticine";
    const SELECTION: Selection = Selection::ByColumn("plasticine_a");
    const COLUMNS: &'static [&'static str] = &[
        "plasticine_a",
        "plasticine_b",
        "plasticine_n",
        "plasticine_m",
        "plasticine_reference_rate",
    ];

    fn from_columns(cols: &dyn Columns, _elastic: &Elastic) -> Result<Self> {
        Ok(Plasticine {
            a: cols.f64("plasticine_a").unwrap_or(f64::NAN),
            b: cols.f64("plasticine_b").unwrap_or(0.0),
            n: cols.f64("plasticine_n").unwrap_or(1.0),
            m: cols.f64("plasticine_m").unwrap_or(0.0),
            reference_rate: cols.f64("plasticine_reference_rate").unwrap_or(1.0),
        })
    }
    fn validate(&self) -> Result<()> {
        self.check_constants()
    }
    #[inline]
    fn update(&self, elastic: &Elastic, st: &mut PointState, deps: &[f64; 6], dt: f64) {
        let ep = st.plastic_strain;
        // σ_y at the start (Δ = 0: no rate effect), then the return.
        let sy0 = self.flow_stress(ep, 0.0);
        radial_return(elastic, st, deps, |sbar, mu| {
            if sbar <= sy0 {
                0.0
            } else {
                newton_return(sbar, 3.0 * mu, sbar - sy0, |d| {
                    self.flow_stress_step(ep, d, dt)
                })
            }
        });
    }
}

#[cfg(test)]
mod tests {
    use super::super::radial_return::{von_mises, RETURN_TOLERANCE};
    use super::super::{Law, Material};
    use super::*;

    fn clay(m: f64, b: f64) -> (Elastic, Plasticine) {
        (
            Elastic {
                youngs_modulus: 20e6,
                poisson_ratio: 0.45,
                density: 1500.0,
            },
            Plasticine {
                a: 50e3,
                b,
                n: 0.5,
                m,
                reference_rate: 1.0,
            },
        )
    }

    /// Uniaxial-strain-free shear at a constant rate: once flowing, the von Mises stress
    /// sits on σ_y = (A + B ε_pⁿ)(ε̇_p/ε̇₀)ᵐ with ε̇_p the step's plastic strain rate, to
    /// the return's tolerance, and rises by 10ᵐ per decade of rate (the power law itself,
    /// computed here from the constants).
    #[test]
    fn the_flow_stress_follows_the_power_law_in_rate() {
        for &(m, b) in &[(0.0, 0.0), (0.2, 0.0), (0.15, 30e3)] {
            let (el, p) = clay(m, b);
            let mut sbar_at = vec![];
            for &rate in &[10.0, 100.0] {
                let mut st = PointState::default();
                let dt = 1e-5;
                // Pure shear γ̇ = 2 ε̇_xy: ε̄̇ = 2 ε̇_xy/√3 in the plastic flow.
                let dexy = rate * dt * 3f64.sqrt() / 2.0;
                let (mut ep_prev, mut last) = (0.0, (0.0, 0.0, 0.0));
                for _ in 0..4000 {
                    p.update(&el, &mut st, &[0.0, 0.0, 0.0, dexy, 0.0, 0.0], dt);
                    let dep = st.plastic_strain - ep_prev;
                    ep_prev = st.plastic_strain;
                    last = (von_mises(&st.stress), st.plastic_strain, dep / dt);
                }
                let (sbar, ep, ep_rate) = last;
                let expect = p.flow_stress(ep, ep_rate);
                assert!(
                    (sbar - expect).abs() <= 1e3 * RETURN_TOLERANCE * expect,
                    "m {m}, B {b}, rate {rate}: σ̄ {sbar} against σ_y {expect}"
                );
                // Flowing at the imposed rate, to 1 % (the elastic part of the rate is
                // the stress's slow rise with hardening).
                assert!(
                    (ep_rate / rate - 1.0).abs() < 1e-2,
                    "ε̇_p {ep_rate} against {rate}"
                );
                sbar_at.push((sbar, ep));
            }
            if b == 0.0 {
                let ratio = sbar_at[1].0 / sbar_at[0].0;
                assert!(
                    (ratio - 10f64.powf(m)).abs() < 1e-2 * 10f64.powf(m),
                    "m {m}: a decade of rate raised σ̄ by {ratio}, expected {}",
                    10f64.powf(m)
                );
            }
        }
    }

    /// A part with `plasticine_a` takes the law; bad constants are refused naming the
    /// column.
    #[test]
    fn the_part_selects_the_law_and_bad_constants_are_named() {
        struct Cols(Vec<(&'static str, f64)>);
        impl Columns for Cols {
            fn f64(&self, name: &str) -> Option<f64> {
                self.0.iter().find(|c| c.0 == name).map(|c| c.1)
            }
        }
        let (el, _) = clay(0.2, 0.0);
        let law = Law::of_part(None, &Cols(vec![("plasticine_a", 5e4)]), &el).unwrap();
        assert_eq!(law.name(), "plasticine");
        for (col, v) in [
            ("plasticine_a", -1.0),
            ("plasticine_m", 1.5),
            ("plasticine_n", 0.0),
            ("plasticine_reference_rate", 0.0),
        ] {
            let mut c = vec![("plasticine_a", 5e4)];
            if col == "plasticine_a" {
                c[0].1 = v;
            } else {
                c.push((col, v));
            }
            let law = Law::of_part(None, &Cols(c), &el).unwrap();
            let err = Material::new(el, law, None).unwrap_err().to_string();
            assert!(err.contains(col), "{col} = {v}: {err}");
        }
    }
}
