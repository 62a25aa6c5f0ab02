//! A membrane that can fail and is crushed flat in its plane leaves the model when its
//! own stable step falls below the run's (the collapse criterion, docs/theory.md,
//! "Failure, perforation and the ballistic limit"; `src/solver/collapse.rs`).
//!
//! Oracles, each independent of the code:
//! - the stable step of a square one-point quad of side a, E₁ = E₂ = E, ν = 0, 2G ≤ E:
//!   K = A₀ s Bᵀ D B has B Bᵀ = diag(1, 1, 2)/a² (the gradients ±1/(2a)), so its largest
//!   eigenvalue is E s (the hourglass's 0.2 E s |γ|² = 0.05 E s lies below it); a node of
//!   mass ρ s a²/4 on it alone has the step 2√(ρ s a²/(4 E s)) = a/c, c = √(E/ρ);
//! - a rhombus of side a at angle θ has area a² sin θ and longest side a: its
//!   characteristic length is a sin θ, its step (a/c) sin θ;
//! - energy conservation: no force of these models dissipates, so every joule the ledger
//!   loses or gains is an error.

mod common;
use common::rel;
use weft::model::{Analysis, ElementKind, Model, PartProps};
use weft::solver::failure::Criterion;
use weft::solver::run_in_memory;

/// The far-field membrane of the combined model: a fabric's soft in-plane shear
/// (G = E/240), the material that was crushed flat.
const E: f64 = 24e9;
const G: f64 = 1e8;
const RHO: f64 = 1171.55;
const S: f64 = 1.33e-4;
const A: f64 = 0.5e-3;

fn membrane_part(m: &mut Model) -> usize {
    m.add_part(
        1,
        "membrane",
        ElementKind::Quad,
        PartProps {
            youngs_modulus_1: Some(E),
            youngs_modulus_2: Some(E),
            shear_modulus_12: Some(G),
            density: Some(RHO),
            thickness: Some(S),
            failure_strain: Some(0.06),
            failure_strain_2: Some(0.06),
            ..Default::default()
        },
    )
}

/// A square quad of side a at x = `x0`, its bottom edge fixed; returns its top nodes
/// (right, left).
fn square(m: &mut Model, p: usize, id: i64, x0: f64) -> (usize, usize) {
    let n0 = 4 * id;
    let b0 = m.add_node(n0 + 1, [x0, 0.0, 0.0]);
    let b1 = m.add_node(n0 + 2, [x0 + A, 0.0, 0.0]);
    let t1 = m.add_node(n0 + 3, [x0 + A, A, 0.0]);
    let t0 = m.add_node(n0 + 4, [x0, A, 0.0]);
    m.add_element(id, p, &[b0, b1, t1, t0]);
    m.constraints.push((b0, [true, true, true]));
    m.constraints.push((b1, [true, true, true]));
    (t1, t0)
}

/// A square quad whose top corners are thrown sideways at 1000 and 400 m/s, faster than
/// its shear can hold (flat, it stores A₀ s G/2 = 1.7·10⁻³ J of the 5.7·10⁻³ J thrown),
/// the difference an hourglass mode, and apart out of the plane at ±1 m/s (so that the
/// quad is barely warped as it flattens and the normal of its diagonals swings round):
/// it is sheared flat and through, as a quad next to eroded ones was in the combined
/// patch-in-membrane model. Run at a step far below its own (Δt = 0.05 a/c, the
/// contact guard's kind of step), it is removed once its step falls below ½Δt, its
/// characteristic length below a/40. No force dissipates, so the ledger must balance
/// throughout.
#[test]
fn a_quad_sheared_flat_leaves_and_the_energy_balances() {
    let mut m = Model::default();
    let p = membrane_part(&mut m);
    let (t1, t0) = square(&mut m, p, 1, 0.0);
    m.initial_velocities.push((t1, [1000.0, 0.0, 1.0]));
    m.initial_velocities.push((t0, [400.0, 0.0, -1.0]));
    let dt = 0.05 * A / (E / RHO).sqrt();
    m.analysis = Analysis {
        end_time: 3e-6,
        output_interval: 1e-8,
        time_step: Some(dt),
        max_energy_error: 1e9,
        ..Analysis::default()
    };
    let (s, _, stats) = run_in_memory(&m).unwrap();
    let ev = &s.failure_log().events;
    assert_eq!(ev.len(), 1, "{ev:?}");
    let f = &ev[0].failure;
    assert_eq!(f.criterion, Criterion::TimeStep);
    assert!(f.eroded);
    let bal = stats.max_balance_error_relative;
    println!(
        "removed at t = {:.4e} s (step {}), its step {:.4e} s against {:.4e} s, energy taken {:.4e} J; balance {bal:.2e}",
        ev[0].time, ev[0].step, f.value, f.limit, f.energy
    );
    // Measured 3.9·10⁻⁵ (the central difference's O(Δt²) error through the crush).
    // Without the criterion the quad passes through zero area, the turning normal of
    // its hourglass warping mode makes energy, and the balance is 2.3·10⁻².
    assert!(bal < 1e-4, "balance {bal:e}");
}

/// The criterion planted: two rhombi formed (initial displacements) at sin θ = 0.2 and
/// 0.3 from squares, run at Δt = a/(2c). The step of a rhombus is (a/c) sin θ (module
/// docs), the limit ½Δt = 0.25 a/c, so the first leaves at the first step that compares
/// (step 1: before it the run has taken no step), with its step as the value and ½Δt
/// as the limit; the second stays.
#[test]
fn a_membrane_leaves_when_its_step_falls_below_half_the_runs() {
    let c = (E / RHO).sqrt();
    let dt = 0.5 * A / c;
    let mut m = Model::default();
    let p = membrane_part(&mut m);
    let mut u0 = vec![[0.0; 3]; 8];
    for (k, sin) in [(1i64, 0.2f64), (2, 0.3)] {
        let x0 = 3.0 * A * (k - 1) as f64;
        let (t1, t0) = square(&mut m, p, k, x0);
        // The top corners at angle θ from the bottom edge, the sides kept at a.
        let cos = (1.0 - sin * sin).sqrt();
        for t in [t1, t0] {
            u0[t] = [A * cos, A * sin - A, 0.0];
        }
    }
    m.initial_displacement = u0;
    m.analysis = Analysis {
        end_time: 20.0 * dt,
        output_interval: dt,
        time_step: Some(dt),
        ..Analysis::default()
    };
    let (s, _, _) = run_in_memory(&m).unwrap();
    let ev = &s.failure_log().events;
    assert_eq!(ev.len(), 1, "{ev:?}");
    let f = &ev[0].failure;
    assert_eq!((ev[0].id, ev[0].step), (1, 1));
    assert_eq!(f.criterion, Criterion::TimeStep);
    assert!(f.eroded);
    let want = 0.2 * A / c;
    println!(
        "value {:.9e} s against (a/c) sin θ {want:.9e} s ({:.1e}); limit {:.4e} s",
        f.value,
        rel(f.value, want),
        f.limit
    );
    // Measured 2.2·10⁻⁵: the rhombus moved in its first step.
    assert!(rel(f.value, want) < 1e-4, "{} against {want}", f.value);
    assert!(rel(f.limit, 0.5 * dt) < 1e-15);
}
