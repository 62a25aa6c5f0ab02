//! Solids shared by the tests of the hexahedron, its results and its contact: steel and
//! copper parts, the struck copper block, and a run on a given number of threads.

use weft::generate::block::hex_block;
use weft::model::{Model, PartProps};

/// Steel: E [Pa] and ρ [kg/m³].
pub const STEEL_E: f64 = 200e9;
pub const STEEL_RHO: f64 = 7850.0;

/// Elastic steel of Poisson's ratio `nu`.
pub fn steel(nu: f64) -> PartProps {
    PartProps {
        youngs_modulus: Some(STEEL_E),
        density: Some(STEEL_RHO),
        poisson_ratio: Some(nu),
        ..Default::default()
    }
}

/// OFHC copper, Johnson & Cook (1983), Table 1: A = 90 MPa, B = 292 MPa, n = 0.31,
/// C = 0.025, m = 1.09, T_melt = 1356 K; ρ = 8960 kg/m³, c_p = 383 J/(kg K),
/// E = 124 GPa, ν = 0.34 (handbook values).
pub fn copper() -> PartProps {
    PartProps {
        youngs_modulus: Some(124e9),
        poisson_ratio: Some(0.34),
        density: Some(8960.0),
        jc_a: Some(90e6),
        jc_b: Some(292e6),
        jc_n: Some(0.31),
        jc_c: Some(0.025),
        jc_m: Some(1.09),
        room_temperature: Some(293.15),
        melt_temperature: Some(1356.0),
        specific_heat: Some(383.0),
        ..Default::default()
    }
}

/// An 11 × 11 × 10 block of 1 mm copper cubes (1210 hexahedra: two chunks of 1024),
/// its base held, its top struck around the vertical edge x = y = 0 by a smooth velocity
/// field v_z = −150 m/s (1 − r/6 mm)₊ z/H, to 3 µs. Not symmetric about any element: a
/// field that jumps across one layer of one-point elements, a struck face alone, puts
/// half its energy into hourglass modes (measured 46 %).
pub fn struck_block() -> Model {
    let (n, nz, h) = (11, 10, 1e-3);
    let mut m = hex_block(n, n, nz, h, "block", copper());
    for (i, x) in m.coords.clone().iter().enumerate() {
        if x[2] == 0.0 {
            m.constraints.push((i, [true, true, true]));
        }
        let r = x[0].hypot(x[1]);
        if x[2] > 0.0 && r < 6.0 * h {
            let vz = -150.0 * (1.0 - r / (6.0 * h)) * x[2] / (nz as f64 * h);
            m.initial_velocities.push((i, [0.0, 0.0, vz]));
        }
    }
    m.analysis.end_time = 3e-6;
    m.analysis.output_interval = 1e-7;
    m
}

/// `f` run in a pool of `threads` threads (for the 1- against 2-thread comparisons).
pub fn on_threads<T: Send>(threads: usize, f: impl FnOnce() -> T + Send) -> T {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap()
        .install(f)
}
