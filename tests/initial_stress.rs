//! Membranes with an initial stress S₀ (`s0_11`, `s0_22`, `s0_12` of the element tables):
//! a formed, pre-stressed state. S = D E + S₀ (St Venant–Kirchhoff), stored energy
//! ½E·DE + S₀·E.
//!
//! Oracles: a uniformly pre-stressed strip held at both ends is in equilibrium (the patch
//! test: every interior node's forces cancel) and its supports carry S₀·b·t; released at
//! one end it comes to rest where S = 0, E₁₁ = −S₀/E, i.e. λ = √(1 − 2S₀/E) (uniaxial
//! St Venant–Kirchhoff with ν = 0), and without damping its energy is conserved.
//!
//! ```text
//!   |o--o--o--o--o--o--o--o--o--o|   10 × 1 quads, L = 10 mm, b = 1 mm, t = 0.1 mm
//!   |o--o--o--o--o--o--o--o--o--o|   S₀ = 100 MPa along x
//! ```

mod common;
use common::rel;
use weft::model::{Analysis, ElementKind, Model, PartProps};
use weft::solver::run_in_memory;

const E: f64 = 80e9;
const S0: f64 = 1e8;
const L: f64 = 1e-2;
const B: f64 = 1e-3;
const T: f64 = 1e-4;

fn strip(hold_far_end: bool) -> (Model, Vec<usize>) {
    let mut m = Model::default();
    let p = m.add_part(
        1,
        "strip",
        ElementKind::Quad,
        PartProps {
            youngs_modulus_1: Some(E),
            youngs_modulus_2: Some(E),
            shear_modulus_12: Some(E / 2.0),
            density: Some(1440.0),
            thickness: Some(T),
            ..Default::default()
        },
    );
    let n = 10;
    let mut far = vec![];
    for j in 0..2 {
        for i in 0..=n {
            let k = m.add_node(
                (j * (n + 1) + i) as i64 + 1,
                [L * i as f64 / n as f64, B * j as f64, 0.0],
            );
            let end = i == 0 || (hold_far_end && i == n);
            m.constraints.push((k, [end, true, true]));
            if i == n {
                far.push(k);
            }
        }
    }
    for i in 0..n {
        m.add_element(i as i64 + 1, p, &[i, i + 1, n + 1 + i + 1, n + 1 + i]);
    }
    m.elements.get_mut(&ElementKind::Quad).unwrap().stress0 = vec![[S0, 0.0, 0.0]; n];
    m.node_sets.insert("far".into(), far.clone());
    m.analysis = Analysis {
        end_time: 2e-5,
        output_interval: 1e-6,
        history_sets: vec!["far".into()],
        ..Analysis::default()
    };
    (m, far)
}

#[test]
fn a_prestressed_strip_held_at_both_ends_is_in_equilibrium() {
    let (mut m, far) = strip(true);
    // Nothing moves, so every energy is round-off and the balance check has no scale.
    m.analysis.max_energy_error = 1e300;
    let (mut s, out, _) = run_in_memory(&m).unwrap();
    let umax = s
        .state()
        .x
        .iter()
        .zip(s.reference_positions())
        .map(|(x, x0)| (0..3).map(|d| (x[d] - x0[d]).abs()).fold(0.0, f64::max))
        .fold(0.0, f64::max);
    let f = s.internal_forces();
    let reaction: f64 = far.iter().map(|&n| f[n][0]).sum();
    // Round-off bounds. Each node's net force is the sum of its elements' ~S₀bt/2 = 5 N
    // shares, which cancel to within a few ulps; a steady imbalance of 4 ulps of
    // F = S₀bt on a node of mass m = ρtbh/2 (two elements' quarters, h = L/10) moves it
    // ½(4εF/m)t² by the end time t: 2.5e-17 m.
    let h = L / 10.0;
    let m_node = 1440.0 * T * B * h / 2.0;
    let u_roundoff = 0.5 * (4.0 * f64::EPSILON * S0 * B * T / m_node) * m.analysis.end_time.powi(2);
    // The reaction is off by the stress that such a motion makes: a node moved by u_max
    // against its neighbour's −u_max strains an element by 2u_max/h, i.e. a relative
    // stress error of E·2u_max/(h S₀).
    let reaction_roundoff = E * 2.0 * umax / (h * S0);
    println!(
        "max displacement {umax:.2e} m (round-off bound {u_roundoff:.2e}); far-end reaction {reaction:.9e} N vs −S₀bt = {:.9e} N, relative {:.2e} (round-off bound {reaction_roundoff:.2e})",
        -S0 * B * T,
        rel(reaction, -S0 * B * T)
    );
    // Measured 6.5e-18 m, against the 1.25e-5 m it would shorten if released; the
    // bound is 3.8× above.
    assert!(umax < u_roundoff, "the strip moved {umax} m");
    // Measured 2.1e-12; the bound (1.0e-11 at the measured u_max) is 5× above.
    assert!(
        rel(reaction, -S0 * B * T) < reaction_roundoff,
        "reaction {reaction}"
    );
    let _ = out;
}

#[test]
fn a_released_prestressed_strip_shortens_to_zero_stress() {
    // Undamped: energy is conserved while it oscillates about the new length. A sudden
    // release excites every mode, whose discrete kinetic energy (from v^n) differs from
    // the true one by up to (ωΔt)²/4: 1.5 % at dt_safety 0.9, so a smaller step here.
    let (mut m, _) = strip(false);
    m.analysis.dt_safety = 0.2;
    let (_, _, stats) = run_in_memory(&m).unwrap();
    println!(
        "undamped release: energy balance {:.2e}",
        stats.max_balance_error_relative
    );
    // Measured 1.3e-3 (the discrete kinetic energy's (ωΔt)²/4 at dt_safety 0.2);
    // tolerance 5e-3, 3.8×.
    assert!(stats.max_balance_error_relative < 5e-3);
    // Damped: it comes to rest at λ = √(1 − 2S₀/E).
    let (mut m, _) = strip(false);
    m.analysis.mass_damping = 2e5;
    m.analysis.end_time = 3e-4;
    let (s, _, _) = run_in_memory(&m).unwrap();
    let n = 10;
    let u = s.state().x[n][0] - s.reference_positions()[n][0];
    let closed = L * ((1.0 - 2.0 * S0 / E).sqrt() - 1.0);
    println!(
        "released: end displacement {u:.6e} m vs L(√(1 − 2S₀/E) − 1) = {closed:.6e} m ({:.2e})",
        rel(u, closed)
    );
    // Measured 2.5e-13: what is left of the oscillation under mass damping α = 2e5 /s
    // after 3e-4 s, e^(−αt/2) = e^(−30) = 9e-14 of its amplitude (the full shortening);
    // tolerance 1e-12, 4×.
    assert!(rel(u, closed) < 1e-12, "{u} vs {closed}");
}
