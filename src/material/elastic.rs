//! Isotropic hypoelasticity: σ ← σ + λ tr(dε) I + 2μ dε, no yield, no heating
//! ([`super::radial_return::elastic_trial`]). The law of a solid part that selects no
//! other.

use super::law::{Columns, Elastic, MaterialLaw, PointState, Selection};
use super::radial_return::elastic_trial;
use crate::error::Result;

/// The elastic law: no constants of its own (E, ν, ρ are every law's).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ElasticLaw;

impl MaterialLaw for ElasticLaw {
    const NAME: &'static str = "elastic";
    const SELECTION: Selection = Selection::Default;
    const COLUMNS: &'static [&'static str] = &[];

    fn from_columns(_cols: &dyn Columns, _elastic: &Elastic) -> Result<Self> {
        Ok(ElasticLaw)
    }
    fn validate(&self) -> Result<()> {
        Ok(())
    }
    #[inline]
    fn update(&self, elastic: &Elastic, st: &mut PointState, deps: &[f64; 6], _dt: f64) {
        st.stress = elastic_trial(&st.stress, deps, elastic.lame());
    }
}

#[cfg(test)]
mod tests {
    use super::super::tests::elastic;
    use super::super::{Law, Material};
    use super::*;

    /// Lamé constants, bulk modulus and P-wave speed from E, ν (E = 200 GPa, ν = 1/4:
    /// λ = μ = 80 GPa), and the stress of a confined compression with tensor shear:
    /// σ_xx = (λ + 2μ)ε, σ_yy = λε, σ_xy = 2με_xy (any elasticity text).
    #[test]
    fn elastic_law_and_moduli() {
        let mat =
            Material::new(elastic(200e9, 0.25, 7800.0), Law::Elastic(ElasticLaw), None).unwrap();
        let (l, m) = mat.lame();
        assert!((l - 80e9).abs() < 1e-3 && (m - 80e9).abs() < 1e-3);
        assert!((mat.bulk_modulus() - (l + 2.0 * m / 3.0)).abs() < 1e-3);
        assert!((mat.dilatational_wave_speed() - (240e9f64 / 7800.0).sqrt()).abs() < 1e-9);
        let mut st = mat.initial_state();
        mat.update(&mut st, &[1e-3, 0.0, 0.0, 2e-3, 0.0, 0.0], 1e-6);
        assert_eq!(
            st.stress,
            [
                (l + 2.0 * m) * 1e-3,
                l * 1e-3,
                l * 1e-3,
                2.0 * m * 2e-3,
                0.0,
                0.0
            ]
        );
        assert_eq!(st.plastic_strain, 0.0);
    }
}
