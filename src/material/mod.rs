//! Material laws of the solid elements, at one integration point: pure functions of the
//! point's state and its strain increment, one file per law behind one trait
//! ([`MaterialLaw`]), listed once in [`laws!`](crate::laws)' invocation below.
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
//! Every law shares the isotropic elasticity of [`Material`] (E, ν, ρ) and the erosion
//! flag; what differs is the law's own update of the stress and the point's state:
//! - [`elastic`]: isotropic hypoelasticity, no yield;
//! - [`j2`]: J2 (von Mises) plasticity with isotropic hardening, bilinear or tabulated;
//! - [`johnson_cook`]: Johnson–Cook (strain hardening, strain rate, thermal softening)
//!   with adiabatic heating from plastic work;
//! - [`plasticine`]: the backing clay: a flow stress rising as a power of the plastic
//!   strain rate;
//! - [`radial_return`]: what the J2-type laws share: the elastic predictor, the radial
//!   return onto a von Mises surface, the plastic work, and the stress measures.
//!
//! Which law a part takes: the one its `material` column names, or else the one whose
//! selecting column the part sets (`yield_stress`: j2, `jc_a`: johnson_cook,
//! `plasticine_a`: plasticine), or else the
//! elastic law ([`Law::of_part`]). A law reads its constants by column name through
//! [`Columns`] (the model's part properties implement it), so the laws sit below the
//! model and the solver, and the model's checks build a part's material exactly as the
//! solver does.
//!
//! Erosion: when ε_p ≥ `erosion_plastic_strain` the point is flagged `eroded` (the family
//! deletes the element); an eroded point carries no stress in later updates.
//!
//! Adding a law is one file implementing [`MaterialLaw`], its `mod` line and its line in
//! the `laws!` invocation below (docs/howto/element_family.md, "Add a material law").

pub mod elastic;
pub mod j2;
pub mod johnson_cook;
mod law;
pub mod plasticine;
pub mod radial_return;

pub use law::{Columns, Elastic, MaterialLaw, PointState, Selection, DEFAULT_TEMPERATURE};
pub use radial_return::{pressure, von_mises};

use crate::error::{Result, WeftError};

/// Lists the material laws once: generates [`Law`] (one variant per law) and its
/// dispatch, in list order (the order in which a part's selecting columns are tried).
#[macro_export]
macro_rules! laws {
    ($($variant:ident: $ty:ty),+ $(,)?) => {
        /// A part's material law, one variant per law of the `laws!` list.
        #[derive(Debug, Clone, PartialEq)]
        pub enum Law {
            $($variant($ty),)+
        }

        impl Law {
            /// Every law's name, selection and columns, in list order.
            pub const ALL: &'static [(&'static str, $crate::material::Selection, &'static [&'static str])] = &[
                $((
                    <$ty as $crate::material::MaterialLaw>::NAME,
                    <$ty as $crate::material::MaterialLaw>::SELECTION,
                    <$ty as $crate::material::MaterialLaw>::COLUMNS,
                ),)+
            ];
            /// The law's name.
            pub fn name(&self) -> &'static str {
                match self {
                    $(Law::$variant(_) => <$ty as $crate::material::MaterialLaw>::NAME,)+
                }
            }
            /// The law called `name`, its constants from `cols`.
            fn named(
                name: &str,
                cols: &dyn $crate::material::Columns,
                elastic: &$crate::material::Elastic,
            ) -> Option<$crate::error::Result<Law>> {
                $(
                    if name == <$ty as $crate::material::MaterialLaw>::NAME {
                        return Some(
                            <$ty as $crate::material::MaterialLaw>::from_columns(cols, elastic)
                                .map(Law::$variant),
                        );
                    }
                )+
                None
            }
            pub fn validate(&self) -> $crate::error::Result<()> {
                match self {
                    $(Law::$variant(l) => $crate::material::MaterialLaw::validate(l),)+
                }
            }
            pub fn initial_temperature(&self) -> f64 {
                match self {
                    $(Law::$variant(l) => $crate::material::MaterialLaw::initial_temperature(l),)+
                }
            }
            #[inline]
            pub fn update(
                &self,
                elastic: &$crate::material::Elastic,
                st: &mut $crate::material::PointState,
                deps: &[f64; 6],
                dt: f64,
            ) {
                match self {
                    $(Law::$variant(l) => $crate::material::MaterialLaw::update(l, elastic, st, deps, dt),)+
                }
            }
        }
    };
}

laws! {
    Elastic: elastic::ElasticLaw,
    J2: j2::J2,
    JohnsonCook: johnson_cook::JohnsonCook,
    Plasticine: plasticine::Plasticine,
}

impl Law {
    /// The law a part takes (module docs): the one `named` (its `material` column), or
    /// else the one whose selecting column it sets (two such columns are refused), or
    /// else the default law; its constants from `cols`.
    pub fn of_part(named: Option<&str>, cols: &dyn Columns, elastic: &Elastic) -> Result<Law> {
        if let Some(name) = named {
            return Law::named(name, cols, elastic).unwrap_or_else(|| {
                Err(
                    WeftError::input(format!("material law `{name}`")).expected(format!(
                        "one of {}",
                        Law::ALL
                            .iter()
                            .map(|l| format!("`{}`", l.0))
                            .collect::<Vec<_>>()
                            .join(", ")
                    )),
                )
            });
        }
        let set: Vec<(&str, &str)> = Law::ALL
            .iter()
            .filter_map(|(name, sel, _)| match sel {
                Selection::ByColumn(c) if cols.f64(c).is_some() => Some((*name, *c)),
                _ => None,
            })
            .collect();
        let name = match set.as_slice() {
            [] => Law::ALL
                .iter()
                .find(|l| l.1 == Selection::Default)
                .map(|l| l.0)
                .expect("one default law"),
            [(name, _)] => name,
            [(_, a), (_, b), ..] => {
                return Err(
                    WeftError::input(format!("has both `{a}` and `{b}`")).expected(format!(
                        "one material law: {}",
                        Law::ALL
                            .iter()
                            .filter_map(|(name, sel, _)| match sel {
                                Selection::ByColumn(c) => Some(format!("{name} (`{c}`)")),
                                _ => None,
                            })
                            .collect::<Vec<_>>()
                            .join(" or ")
                    )),
                )
            }
        };
        Law::named(name, cols, elastic).expect("a listed law")
    }
}

/// A solid material: isotropic elasticity, a law, and optional erosion.
#[derive(Debug, Clone, PartialEq)]
pub struct Material {
    pub elastic: Elastic,
    pub law: Law,
    /// Flag the point eroded when ε_p reaches this value (None: never).
    pub erosion_plastic_strain: Option<f64>,
}

impl Material {
    /// A validated material.
    pub fn new(
        elastic: Elastic,
        law: Law,
        erosion_plastic_strain: Option<f64>,
    ) -> Result<Material> {
        let m = Material {
            elastic,
            law,
            erosion_plastic_strain,
        };
        m.validate()?;
        Ok(m)
    }

    /// The material of a part from its columns (`docs/tables.md`, parts.parquet): E,
    /// ν (0.3 when null), ρ, the law ([`Law::of_part`]) and `erosion_plastic_strain`;
    /// an error names the part.
    pub fn of_part(part: &str, named: Option<&str>, cols: &dyn Columns) -> Result<Material> {
        let elastic = Elastic {
            youngs_modulus: cols.f64("youngs_modulus").unwrap_or(f64::NAN),
            poisson_ratio: cols.f64("poisson_ratio").unwrap_or(0.3),
            density: cols.f64("density").unwrap_or(f64::NAN),
        };
        let in_part = |err: WeftError| {
            WeftError::input(format!("part `{part}` (hex): {err}"))
                .in_file("parts.parquet")
                .hint("see docs/tables.md, parts.parquet: the solid's material columns")
        };
        let law = Law::of_part(named, cols, &elastic).map_err(in_part)?;
        Material::new(elastic, law, cols.f64("erosion_plastic_strain")).map_err(in_part)
    }

    /// E > 0, −1 < ν < ½, ρ > 0, erosion strain > 0, and the law's own ranges.
    pub fn validate(&self) -> Result<()> {
        let Elastic {
            youngs_modulus: e,
            poisson_ratio: nu,
            density: rho,
        } = self.elastic;
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
        self.law.validate()
    }

    /// ρ (reference) [kg/m³].
    #[inline]
    pub fn density(&self) -> f64 {
        self.elastic.density
    }

    /// (λ, μ), [`Elastic::lame`].
    #[inline]
    pub fn lame(&self) -> (f64, f64) {
        self.elastic.lame()
    }

    /// μ = G.
    pub fn shear_modulus(&self) -> f64 {
        self.lame().1
    }

    /// K = E/(3(1 − 2ν)).
    pub fn bulk_modulus(&self) -> f64 {
        self.elastic.youngs_modulus / (3.0 * (1.0 - 2.0 * self.elastic.poisson_ratio))
    }

    /// c = √((λ + 2μ)/ρ), the dilatational (P-wave) speed, for the stable step, the bulk
    /// viscosity and the hourglass coefficient.
    pub fn dilatational_wave_speed(&self) -> f64 {
        let (l, m) = self.lame();
        ((l + 2.0 * m) / self.elastic.density).sqrt()
    }

    /// The unstressed virgin state, at the law's initial temperature.
    pub fn initial_state(&self) -> PointState {
        PointState {
            temperature: self.law.initial_temperature(),
            ..PointState::default()
        }
    }

    /// Advance one integration point by the strain increment `deps` = D Δt (tensor
    /// components, Voigt order) over the step `dt`: the law's update, then the erosion
    /// flag; an eroded point carries no stress.
    #[inline]
    pub fn update(&self, st: &mut PointState, deps: &[f64; 6], dt: f64) {
        if st.eroded {
            st.stress = [0.0; 6];
            return;
        }
        self.law.update(&self.elastic, st, deps, dt);
        // ε_p starts at 0 < ef and is checked after every update, so a point is eroded
        // exactly when its plastic strain first reaches ef.
        if let Some(ef) = self.erosion_plastic_strain {
            if st.plastic_strain >= ef {
                st.eroded = true;
            }
        }
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    /// Columns from (name, value) pairs.
    pub(crate) struct Cols(pub Vec<(&'static str, f64)>);
    impl Columns for Cols {
        fn f64(&self, name: &str) -> Option<f64> {
            self.0.iter().find(|c| c.0 == name).map(|c| c.1)
        }
    }

    pub(crate) fn elastic(e: f64, nu: f64, rho: f64) -> Elastic {
        Elastic {
            youngs_modulus: e,
            poisson_ratio: nu,
            density: rho,
        }
    }

    /// One increment of uniaxial stress: the axial increment `de`, the lateral
    /// increments found by a secant iteration so that σ_yy = σ_zz = 0 after the update
    /// (by symmetry one unknown). Returns the lateral increment.
    pub(crate) fn uniaxial_step(mat: &Material, st: &mut PointState, de: f64, dt: f64) -> f64 {
        let g = |dl: f64| {
            let mut s = *st;
            mat.update(&mut s, &[de, dl, dl, 0.0, 0.0, 0.0], dt);
            (s.stress[1], s)
        };
        let nu = mat.elastic.poisson_ratio;
        let (mut a, mut b) = (-nu * de, -0.5 * de);
        let (mut ga, mut gb) = (g(a).0, g(b).0);
        for _ in 0..60 {
            if gb.abs() <= 1e-7 || gb == ga {
                break;
            }
            let c = b - gb * (b - a) / (gb - ga);
            (a, ga) = (b, gb);
            b = c;
            gb = g(b).0;
        }
        let (r, s) = g(b);
        assert!(
            r.abs() <= 1e-6 && s.stress[2].abs() <= 1e-6,
            "lateral stress {r}"
        );
        *st = s;
        b
    }

    #[test]
    fn erosion_flag() {
        let mut mat = super::j2::tests::bilinear();
        mat.erosion_plastic_strain = Some(0.01);
        let mut st = mat.initial_state();
        let mut n = 0;
        while !st.eroded {
            mat.update(&mut st, &[1e-3, -5e-4, -5e-4, 0.0, 0.0, 0.0], 1e-6);
            n += 1;
            assert!(n < 100);
        }
        assert!(st.plastic_strain >= 0.01 && st.plastic_strain < 0.0111);
        mat.update(&mut st, &[1e-3, 0.0, 0.0, 0.0, 0.0, 0.0], 1e-6);
        assert_eq!(st.stress, [0.0; 6]);
    }

    /// Each bad elastic constant is refused, and the message names it.
    #[test]
    fn bad_elastic_constants_are_refused_by_name() {
        let msg = |el: Elastic, ef: Option<f64>| {
            let law = Law::Elastic(elastic::ElasticLaw);
            format!("{}", Material::new(el, law, ef).unwrap_err())
        };
        assert!(msg(elastic(0.0, 0.3, 1.0), None).contains("Young"));
        assert!(msg(elastic(1e9, 0.5, 1.0), None).contains("Poisson"));
        assert!(msg(elastic(1e9, -1.0, 1.0), None).contains("Poisson"));
        assert!(msg(elastic(1e9, 0.3, 0.0), None).contains("density"));
        assert!(msg(elastic(1e9, 0.3, 1.0), Some(0.0)).contains("erosion"));
    }

    /// The law a part takes: named, selected by its column, or the default; two
    /// selecting columns, or an unknown name, refused with the names.
    #[test]
    fn a_part_selects_its_law() {
        let el = elastic(200e9, 0.3, 7850.0);
        let of = |named: Option<&str>, c: Vec<(&'static str, f64)>| {
            Law::of_part(named, &Cols(c), &el).map(|l| l.name())
        };
        assert_eq!(of(None, vec![]).unwrap(), "elastic");
        assert_eq!(of(None, vec![("yield_stress", 250e6)]).unwrap(), "j2");
        assert_eq!(of(None, vec![("jc_a", 90e6)]).unwrap(), "johnson_cook");
        assert_eq!(of(Some("elastic"), vec![]).unwrap(), "elastic");
        let both = of(None, vec![("yield_stress", 250e6), ("jc_a", 90e6)]).unwrap_err();
        assert!(
            format!("{both}").contains("has both `yield_stress` and `jc_a`"),
            "{both}"
        );
        let unknown = of(Some("clay"), vec![]).unwrap_err();
        assert!(format!("{unknown}").contains("`clay`"), "{unknown}");
        assert!(format!("{unknown}").contains("`johnson_cook`"), "{unknown}");
    }
}
