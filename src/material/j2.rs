//! J2 (von Mises) plasticity with isotropic hardening, rate- and temperature-independent,
//! no heating: σ_y(ε_p) linear (bilinear stress–strain curve, from the tangent modulus
//! E_t) or tabulated (LS-DYNA *MAT_PIECEWISE_LINEAR_PLASTICITY's curve), by the radial
//! return of [`super::radial_return`]. For linear hardening σ_y = σ_y0 + H ε_p the root
//! is explicit, Δε_p = (σ̄_tr − σ_y(ε_p))/(3μ + H) (Simo & Hughes §3.3); for the table,
//! the safeguarded Newton iteration [`newton_return`].
//!
//! Columns: `yield_stress` σ_y0 (selects the law), `tangent_modulus` E_t (0 when null:
//! perfect plasticity).

use super::law::{Columns, Elastic, MaterialLaw, PointState, Selection};
use super::radial_return::{newton_return, radial_return};
use crate::error::{Result, WeftError};

/// J2 plasticity with isotropic hardening, σ_y(ε_p) = `hardening` from σ_y0 =
/// `yield_stress` [Pa].
#[derive(Debug, Clone, PartialEq)]
pub struct J2 {
    pub yield_stress: f64,
    pub hardening: Hardening,
}

impl MaterialLaw for J2 {
    const NAME: &'static str = "j2";
    const SELECTION: Selection = Selection::ByColumn("yield_stress");
    const COLUMNS: &'static [&'static str] = &["yield_stress", "tangent_modulus"];

    fn from_columns(cols: &dyn Columns, elastic: &Elastic) -> Result<Self> {
        Ok(J2 {
            yield_stress: cols.f64("yield_stress").unwrap_or(f64::NAN),
            hardening: Hardening::from_tangent_modulus(
                elastic.youngs_modulus,
                cols.f64("tangent_modulus").unwrap_or(0.0),
            )?,
        })
    }

    /// σ_y0 > 0, the hardening's shape, and a table that starts at σ_y0.
    fn validate(&self) -> Result<()> {
        let yield_stress = self.yield_stress;
        if !(yield_stress > 0.0 && yield_stress.is_finite()) {
            return Err(
                WeftError::input(format!("yield stress σ_y0 = {yield_stress} Pa"))
                    .expected("σ_y0 > 0"),
            );
        }
        self.hardening.validate_shape()?;
        if let Hardening::Table { stress, .. } = &self.hardening {
            if (stress[0] - yield_stress).abs() > 1e-12 * yield_stress {
                return Err(WeftError::input(format!(
                    "yield stress σ_y0 = {yield_stress} Pa but the hardening table starts at {} Pa",
                    stress[0]
                ))
                .expected("σ_y0 equal to the table's flow stress at ε_p = 0"));
            }
        }
        Ok(())
    }

    #[inline]
    fn update(&self, elastic: &Elastic, st: &mut PointState, deps: &[f64; 6], _dt: f64) {
        let ep = st.plastic_strain;
        let (sy0, _) = self.hardening.flow_stress(self.yield_stress, ep);
        radial_return(elastic, st, deps, |sbar, mu| {
            if sbar <= sy0 {
                0.0
            } else {
                match &self.hardening {
                    Hardening::Linear { plastic_modulus: h } => (sbar - sy0) / (3.0 * mu + h),
                    Hardening::Table { .. } => newton_return(sbar, 3.0 * mu, sbar - sy0, |d| {
                        self.hardening.flow_stress(self.yield_stress, ep + d)
                    }),
                }
            }
        });
    }
}

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

    pub(crate) fn validate_shape(&self) -> Result<()> {
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

#[cfg(test)]
pub(crate) mod tests {
    use super::super::radial_return::von_mises;
    use super::super::tests::{elastic, uniaxial_step};
    use super::super::{Law, Material};
    use super::*;

    /// Steel-like bilinear J2: E = 200 GPa, ν = 0.3, σ_y0 = 250 MPa, E_t = 2 GPa.
    pub(crate) fn bilinear() -> Material {
        let h = Hardening::from_tangent_modulus(200e9, 2e9).unwrap();
        let law = Law::J2(J2 {
            yield_stress: 250e6,
            hardening: h,
        });
        Material::new(elastic(200e9, 0.3, 7850.0), law, None).unwrap()
    }

    fn j2(e: f64, sy: f64, h: Hardening) -> Material {
        let law = Law::J2(J2 {
            yield_stress: sy,
            hardening: h,
        });
        Material::new(elastic(e, 0.3, 7850.0), law, None).unwrap()
    }

    /// Uniaxial stress, bilinear hardening (oracle: the hardening law itself,
    /// σ = σ_y0 + H ε_p with ε = σ/E + ε_p, and the uniaxial tangent E_t = EH/(E + H);
    /// Simo & Hughes §1.4 for the 1-D model the 3-D return must reduce to), then elastic
    /// unloading with slope E.
    #[test]
    fn uniaxial_stress_follows_linear_hardening_and_unloads_elastically() {
        let mat = bilinear();
        let (e, sy0) = (200e9, 250e6);
        let h = match &mat.law {
            Law::J2(J2 {
                hardening: Hardening::Linear { plastic_modulus },
                ..
            }) => *plastic_modulus,
            _ => unreachable!(),
        };
        let mut st = mat.initial_state();
        let de = 2e-5;
        let mut eps = 0.0;
        let mut worst = 0.0f64;
        let mut yielded_at = None;
        for k in 0..1000 {
            uniaxial_step(&mat, &mut st, de, 1e-6);
            eps += de;
            let s = st.stress[0];
            if st.plastic_strain == 0.0 {
                worst = worst.max((s - e * eps).abs() / sy0);
                assert!(s <= sy0 * (1.0 + 1e-12));
            } else {
                yielded_at.get_or_insert(k);
                worst = worst.max((s - (sy0 + h * st.plastic_strain)).abs() / s);
                worst = worst.max((eps - (s / e + st.plastic_strain)).abs() / eps);
            }
            assert!(st.stress[3..].iter().all(|&v| v == 0.0));
        }
        // Yield at ε = σ_y0/E = 1.25e-3: increment 62 (0-based).
        assert_eq!(yielded_at, Some(62));
        assert!(worst < 1e-13, "worst relative error {worst}"); // measured 3.5e-14
        assert!(st.plastic_strain > 0.015);
        // Tangent after yield E_t = E H/(E + H) = 2 GPa.
        let s1 = st.stress[0];
        uniaxial_step(&mat, &mut st, de, 1e-6);
        let et = (st.stress[0] - s1) / de;
        // Δσ/Δε cancels ~4 digits of σ: 1e-12 expected, 1.2e-16 measured.
        assert!((et - 2e9).abs() < 1e-10 * 2e9, "E_t = {et}");
        // Unloading: slope E, no new plastic strain, until σ = −σ_y(ε_p) is reached.
        let (ep, s0) = (st.plastic_strain, st.stress[0]);
        for _ in 0..20 {
            let before = st.stress[0];
            uniaxial_step(&mat, &mut st, -de, 1e-6);
            assert!(((before - st.stress[0]) / de - e).abs() < 1e-6 * e);
            assert_eq!(st.plastic_strain, ep);
        }
        assert!((s0 - st.stress[0] - 20.0 * de * e).abs() < 1e-9 * s0);
    }

    /// Pure shear: τ = 2μ ε_xy until the von Mises yield τ = σ_y/√3, then τ stays there
    /// (perfect plasticity: Hill, *Mathematical Theory of Plasticity*, ch. II; S&H §3.3).
    #[test]
    fn pure_shear_yields_at_sigma_y_over_root_3() {
        let sy = 250e6;
        let mat = j2(
            200e9,
            sy,
            Hardening::Linear {
                plastic_modulus: 0.0,
            },
        );
        let mu = mat.shear_modulus();
        let mut st = mat.initial_state();
        let d = 1e-5; // tensor ε_xy per step
        let mut exy = 0.0;
        for _ in 0..300 {
            mat.update(&mut st, &[0.0, 0.0, 0.0, d, 0.0, 0.0], 1e-6);
            exy += d;
            let tau = st.stress[3];
            let expect = (2.0 * mu * exy).min(sy / 3f64.sqrt());
            assert!((tau - expect).abs() <= 1e-14 * expect, "{tau} vs {expect}"); // 3.0e-15
            assert_eq!(&st.stress[..3], &[0.0; 3]);
        }
        assert!(st.plastic_strain > 0.0);
        // Plastic shear: Δε_p = (2/√3) Δε_xy^p (γ^p = 2ε^p_xy, ε_p = γ^p/√3).
        let ep_expect = 2.0 / 3f64.sqrt() * (exy - sy / 3f64.sqrt() / (2.0 * mu));
        assert!((st.plastic_strain - ep_expect).abs() < 1e-12 * ep_expect);
    }

    /// Tabulated hardening: σ̄ = σ_y(ε_p) by linear interpolation, across break points and
    /// on the flat part beyond the last point.
    #[test]
    fn tabulated_hardening_follows_the_table() {
        let (es, ss) = (vec![0.0, 0.01, 0.05, 0.2], vec![250e6, 300e6, 340e6, 360e6]);
        let table = Hardening::table(es.clone(), ss.clone()).unwrap();
        let mat = j2(200e9, 250e6, table);
        let interp = |ep: f64| {
            if ep >= 0.2 {
                return 360e6;
            }
            let i = (0..3).rev().find(|&i| es[i] <= ep).unwrap();
            ss[i] + (ss[i + 1] - ss[i]) * (ep - es[i]) / (es[i + 1] - es[i])
        };
        let mut st = mat.initial_state();
        let mut segs = [false; 4];
        for _ in 0..300 {
            mat.update(&mut st, &[1e-3, -5e-4, -5e-4, 0.0, 0.0, 0.0], 1e-6);
            if st.plastic_strain > 0.0 {
                let expect = interp(st.plastic_strain);
                assert!((von_mises(&st.stress) - expect).abs() < 2e-15 * expect); // 3.9e-16
                segs[es.iter().filter(|&&e| e <= st.plastic_strain).count() - 1] = true;
            }
        }
        assert_eq!(segs, [true; 4]);
    }

    /// Each bad constant of the law is refused, and the message names it.
    #[test]
    fn bad_input_is_refused_by_name() {
        let msg = |sy: f64, h: Hardening| {
            let law = Law::J2(J2 {
                yield_stress: sy,
                hardening: h,
            });
            format!(
                "{}",
                Material::new(elastic(1e9, 0.3, 1.0), law, None).unwrap_err()
            )
        };
        let lin = Hardening::Linear {
            plastic_modulus: 1e9,
        };
        assert!(msg(0.0, lin.clone()).contains("yield stress"));
        assert!(msg(-1e6, lin).contains("yield stress"));
        assert!(
            format!("{}", Hardening::from_tangent_modulus(1e9, 1e9).unwrap_err())
                .contains("tangent")
        );
        assert!(format!(
            "{}",
            Hardening::from_tangent_modulus(1e9, -1.0).unwrap_err()
        )
        .contains("tangent"));
        assert!(format!(
            "{}",
            Hardening::table(vec![0.0, 0.1, 0.1], vec![1.0, 2.0, 3.0]).unwrap_err()
        )
        .contains("strictly"));
        assert!(format!(
            "{}",
            Hardening::table(vec![0.01, 0.1], vec![1.0, 2.0]).unwrap_err()
        )
        .contains("ε_p = 0"));
        assert!(format!(
            "{}",
            Hardening::table(vec![0.0, 0.1], vec![2.0, 1.0]).unwrap_err()
        )
        .contains("non-decreasing"));
        assert!(format!(
            "{}",
            Hardening::table(vec![0.0], vec![1.0, 2.0]).unwrap_err()
        )
        .contains("as many"));
        let t = Hardening::table(vec![0.0, 0.1], vec![2e8, 3e8]).unwrap();
        assert!(msg(2.5e8, t.clone()).contains("table starts"));
        let law = Law::J2(J2 {
            yield_stress: 2e8,
            hardening: t,
        });
        assert!(Material::new(elastic(1e9, 0.3, 1.0), law, None).is_ok());
    }
}
