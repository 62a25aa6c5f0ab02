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
        .state
        .x
        .iter()
        .zip(&s.x0)
        .map(|(x, x0)| (0..3).map(|d| (x[d] - x0[d]).abs()).fold(0.0, f64::max))
        .fold(0.0, f64::max);
    let f = s.internal_forces();
    let reaction: f64 = far.iter().map(|&n| f[n][0]).sum();
    println!(
        "max displacement {umax:.2e} m; far-end reaction {reaction:.9e} N vs −S₀bt = {:.9e} N",
        -S0 * B * T
    );
    // Measured 6.5e-18 m (round-off of 10 N forces), against the 1.25e-5 m it would
    // shorten if released.
    assert!(umax < 1e-15, "the strip moved {umax} m");
    // Measured 2.1e-12.
    assert!(rel(reaction, -S0 * B * T) < 1e-10, "reaction {reaction}");
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
    // Measured 7.7e-4.
    assert!(stats.max_balance_error_relative < 5e-3);
    // Damped: it comes to rest at λ = √(1 − 2S₀/E).
    let (mut m, _) = strip(false);
    m.analysis.mass_damping = 2e5;
    m.analysis.end_time = 3e-4;
    let (s, _, _) = run_in_memory(&m).unwrap();
    let n = 10;
    let u = s.state.x[n][0] - s.x0[n][0];
    let closed = L * ((1.0 - 2.0 * S0 / E).sqrt() - 1.0);
    println!(
        "released: end displacement {u:.6e} m vs L(√(1 − 2S₀/E) − 1) = {closed:.6e} m ({:.2e})",
        rel(u, closed)
    );
    assert!(rel(u, closed) < 1e-6, "{u} vs {closed}");
}
