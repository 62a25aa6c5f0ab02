//! Named metals for the solid generators (`weft-weave taylor --material`, the deformable
//! bullet's `--bullet-material`): their part columns, each constant with its source in
//! `docs/theory.md`, "Solid elements", the metals' table.
//!
//! Johnson–Cook constants σ_y = (A + B ε_p^n)(1 + C ln(ε̇_p/ε̇₀))(1 − T*^m) with ε̇₀ = 1/s,
//! T_room = 293 K, from Johnson & Cook (1983), *A constitutive model and data for metals
//! subjected to large strains, high strain rates and high temperatures*, 7th Int. Symp.
//! on Ballistics, The Hague, Table 1 (OFHC copper, 2024-T351 aluminium, cartridge brass);
//! lead from Steinberg's compendium (UCRL-MA-106439), its Steinberg–Guinan curve
//! Y = Y₀(1 + β ε_p)ⁿ ≤ Y_max (Y₀ = 8 MPa, β = 110, n = 0.52, Y_max = 100 MPa) written in
//! the Johnson–Cook form A + B ε_p^n (A = Y₀, B and n fitted through ε_p = 0.5 and 1:
//! within 6 % of the curve for 0.05 ≤ ε_p ≤ 1.2; Steinberg–Guinan has no rate term).

use crate::model::PartProps;

/// A named metal.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, clap::ValueEnum)]
#[serde(rename_all = "kebab-case")]
pub enum Metal {
    /// OFHC copper (Johnson & Cook 1983): ρ 8960 kg/m³, E 124 GPa, ν 0.34.
    Copper,
    /// 2024-T351 aluminium (Johnson & Cook 1983): ρ 2770 kg/m³, E 73 GPa, ν 0.33.
    Aluminium,
    /// Cartridge brass, 70/30 (Johnson & Cook 1983): the FMJ jacket's stand-in for
    /// gilding metal (CuZn10), whose Johnson–Cook constants are not in that table.
    Brass,
    /// Soft lead (Steinberg–Guinan, as above): ρ 11 340 kg/m³, E 24.4 GPa, ν 0.42,
    /// melting at 600 K.
    Lead,
}

/// A metal's constants [SI].
#[derive(Debug, Clone, Copy)]
pub struct MetalConstants {
    pub density: f64,
    pub youngs_modulus: f64,
    pub poisson_ratio: f64,
    pub a: f64,
    pub b: f64,
    pub n: f64,
    pub c: f64,
    pub m: f64,
    pub melt_temperature: f64,
    pub specific_heat: f64,
}

impl Metal {
    pub fn name(self) -> &'static str {
        match self {
            Metal::Copper => "copper",
            Metal::Aluminium => "aluminium",
            Metal::Brass => "brass",
            Metal::Lead => "lead",
        }
    }

    pub fn constants(self) -> MetalConstants {
        match self {
            Metal::Copper => MetalConstants {
                density: 8960.0,
                youngs_modulus: 124e9,
                poisson_ratio: 0.34,
                a: 90e6,
                b: 292e6,
                n: 0.31,
                c: 0.025,
                m: 1.09,
                melt_temperature: 1356.0,
                specific_heat: 383.0,
            },
            Metal::Aluminium => MetalConstants {
                density: 2770.0,
                youngs_modulus: 73e9,
                poisson_ratio: 0.33,
                a: 265e6,
                b: 426e6,
                n: 0.34,
                c: 0.015,
                m: 1.0,
                melt_temperature: 775.0,
                specific_heat: 875.0,
            },
            Metal::Brass => MetalConstants {
                density: 8520.0,
                youngs_modulus: 115e9,
                poisson_ratio: 0.31,
                a: 112e6,
                b: 505e6,
                n: 0.42,
                c: 0.009,
                m: 1.68,
                melt_temperature: 1189.0,
                specific_heat: 385.0,
            },
            Metal::Lead => MetalConstants {
                density: 11340.0,
                youngs_modulus: 24.4e9,
                poisson_ratio: 0.42,
                a: 8e6,
                b: 84.8e6,
                n: 0.58,
                c: 0.0,
                m: 1.0,
                melt_temperature: 600.0,
                specific_heat: 129.0,
            },
        }
    }

    /// The part columns of a hexahedron part of this metal (Johnson–Cook, adiabatic
    /// heating with Taylor–Quinney 0.9, the room temperature 293 K), with the given
    /// hourglass coefficient and optional erosion strain.
    pub fn part_props(self, hourglass: f64, erosion_plastic_strain: Option<f64>) -> PartProps {
        let k = self.constants();
        PartProps {
            density: Some(k.density),
            youngs_modulus: Some(k.youngs_modulus),
            poisson_ratio: Some(k.poisson_ratio),
            hourglass: Some(hourglass),
            jc_a: Some(k.a),
            jc_b: Some(k.b),
            jc_n: Some(k.n),
            jc_c: Some(k.c),
            jc_reference_rate: Some(1.0),
            jc_m: Some(k.m),
            room_temperature: Some(293.0),
            melt_temperature: Some(k.melt_temperature),
            specific_heat: Some(k.specific_heat),
            taylor_quinney: Some(0.9),
            erosion_plastic_strain,
            ..Default::default()
        }
    }
}
