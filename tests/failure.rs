//! Element failure and erosion: strips pulled to failure.
//!
//! Reference: the failure criteria of docs/theory.md, "Failure, perforation and the
//! ballistic limit" (after OpenRadioss' /FAIL/FABRIC for membranes: the engineering strain
//! of the fibres √(1 + 2E₁₁) − 1; a truss's axial engineering strain; a link's force or
//! opening), and the energy balance E_kin + E_int + E_eroded = E₀ + W_ext.
//!
//! A strip pulled at a steady rate: every node starts with the velocity v·x/L of a
//! homogeneous stretch at the rate v/L, the far end carries a mass 10⁶ × the strip's (its
//! speed falls by about 2 % by the failure: the bound below takes its speed then), the
//! near end is held. Every element then
//! strains at v/L, and the element next to the far end has a failure strain 20 % lower
//! than the others (`failure_strain_factor` 0.8: a flaw), so it is the one to fail.
//!
//! ```text
//!   held |o---o---o---o---o---o-x-[M]-> v      x: the flawed element
//!        x = 0                  x = L
//! ```
//!
//! Oracles: the failure comes when that element's strain reaches its failure strain,
//! within one step's increment (v_end/L)·Δt; it takes its strain energy (closed form: ½ E A L₀
//! ε² for a truss, A₀ s ½ E₁ E₁₁² for a membrane, ½ k d² for a link) into the eroded
//! energy; the mass, now free, moves on at a constant velocity (the force across the
//! break is zero); the balance closes with the eroded energy.

mod common;
use common::*;
use weft::model::{ElementKind, Model, PartProps};
use weft::solver::failure::Criterion;
use weft::solver::run_in_memory;

const E: f64 = 80e9;
const RHO: f64 = 1440.0;
const EPS_F: f64 = 0.036;
const FLAW: f64 = 0.8;
/// Pull speed [m/s]: the strip (L = 10 mm) strains at 100 s⁻¹.
const V: f64 = 1.0;
const L: f64 = 0.01;

/// The end masses and the steady-stretch start: node velocities v·x/L along x, the far
/// nodes carrying the masses `far` (node, mass).
fn pull(m: &mut Model, far: &[(usize, f64)]) {
    for (k, &(n, mass)) in far.iter().enumerate() {
        let pm = m.add_part(
            100 + k as i64,
            &format!("end_mass_{k}"),
            ElementKind::PointMass,
            PartProps {
                mass: Some(mass),
                ..Default::default()
            },
        );
        m.add_element(1000 + k as i64, pm, &[n]);
    }
    for i in 0..m.num_nodes() {
        let x = m.coords[i][0];
        m.initial_velocities.push((i, [V * x / L, 0.0, 0.0]));
    }
}

/// A chain of `n` trusses along x on [0, L], held at x = 0, y and z held everywhere.
fn truss_strip(n: usize) -> (Model, f64) {
    let area = 6.6e-8;
    let mut m = Model::default();
    for i in 0..=n {
        m.add_node(i as i64 + 1, [L * i as f64 / n as f64, 0.0, 0.0]);
        m.constraints.push((i, [i == 0, true, true]));
    }
    let p = m.add_part(
        1,
        "yarn",
        ElementKind::Truss,
        PartProps {
            youngs_modulus: Some(E),
            density: Some(RHO),
            area: Some(area),
            failure_strain: Some(EPS_F),
            ..Default::default()
        },
    );
    for e in 0..n {
        m.add_element(e as i64 + 1, p, &[e, e + 1]);
    }
    let b = m.elements.get_mut(&ElementKind::Truss).unwrap();
    b.failure_factor = (0..n)
        .map(|e| if e == n - 1 { FLAW } else { 1.0 })
        .collect();
    let strip_mass = RHO * area * L;
    pull(&mut m, &[(n, 1e6 * strip_mass)]);
    (m, area)
}

/// Time to the flawed element's failure at the steady rate, and 1.5 transits of the
/// strip (L/c = 1.34 µs) after it: long enough for the release wave from the break to
/// reach the held end, short enough that the dispersive ringing a brittle release leaves
/// in a discrete chain (after 3.5 transits its strain peaks reach 1.4 × the strain the
/// strip had, measured) breaks nothing else.
fn end_time() -> f64 {
    1.01 * FLAW * EPS_F * L / V + 2e-6
}

#[test]
fn a_truss_chain_breaks_at_its_failure_strain() {
    let n = 10;
    let (mut m, area) = truss_strip(n);
    m.analysis.end_time = end_time();
    m.analysis.output_interval = 5e-8;
    let (s, out, stats) = run_in_memory(&m).unwrap();
    let ev = &s.failures.events;
    let dt = s.stable.dt;
    println!(
        "truss strip: {} failures, first {:?}; dt {dt:.3e} s, balance {:.2e}",
        ev.len(),
        ev.first(),
        stats.max_balance_error_relative
    );
    // One failure: the flaw, at its strain (the others unload once it is gone).
    assert_eq!(ev.len(), 1, "{ev:?}");
    let f = ev[0].failure;
    assert_eq!(
        (ev[0].id, f.criterion, f.eroded),
        (n as i64, Criterion::Axial, true)
    );
    let limit = FLAW * EPS_F;
    assert!((f.limit - limit).abs() < 1e-15, "{}", f.limit);
    // Within one step's increment of the strain, (v_end/L) Δt, v_end the pull speed then.
    let tip = out.nodes.iter().position(|&i| i == n).unwrap();
    let vs = out.velocity_series(tip, 0);
    let k = out.t.iter().position(|&t| t >= ev[0].time).unwrap();
    let inc = vs[k - 1] / L * dt;
    assert!(
        f.value >= limit && f.value - limit <= inc,
        "failed at {} against {limit} + {inc:e}",
        f.value
    );
    // What it takes: its strain energy ½ E A L₀ ε², less the half step of work its force
    // N = E A ε would still have done against its ends parting at v_end L₀/L (see
    // `failure::taken_energy`).
    let l0 = L / n as f64;
    let w = 0.5 * E * area / l0 * (f.value * l0).powi(2)
        - 0.5 * dt * (vs[k - 1] * l0 / L) * E * area * f.value;
    println!("taken {:.9e} J, closed form {w:.9e} J", f.energy);
    // Measured: 1·10⁻⁹ (the pull speed at the sample before, against the half step).
    assert!(rel(f.energy, w) < 1e-8, "{} vs {w}", f.energy);
    let last = out.energy.last().unwrap();
    assert!(
        rel(last.eroded, f.energy) < 1e-15,
        "{} vs {}",
        last.eroded,
        f.energy
    );
    // The mass, free, keeps its velocity: no force across the break.
    let after: Vec<f64> = out
        .t
        .iter()
        .zip(&vs)
        .filter(|(t, _)| **t > ev[0].time + 2.0 * dt)
        .map(|(_, v)| *v)
        .collect();
    assert!(after.len() > 10);
    let spread = after
        .iter()
        .fold(0.0f64, |a, v| a.max((v - after[0]).abs()));
    assert!(
        spread == 0.0,
        "free mass velocity changes by {spread:e} m/s"
    );
    // The balance closes to round-off through the failure (measured 1.2·10⁻¹⁴ of the
    // energy scale; the issue asks ≤ 1 %).
    assert!(
        stats.max_balance_error_relative < 1e-13,
        "{}",
        stats.max_balance_error_relative
    );
}

/// A band of quads (or of triangles, two per cell) along x on [0, L], `across` cells
/// across its width w, material axis 1 along x (E₁ along, E₂ across, ν = 0), held at
/// x = 0, y and z held everywhere (a uniaxial stretch); the last column flawed.
fn membrane_strip(n: usize, across: usize, triangles: bool) -> (Model, f64, f64) {
    let (w, s) = (0.8e-3, 0.08e-3);
    let mut m = Model::default();
    let mut idx = vec![vec![0usize; across + 1]; n + 1];
    for i in 0..=n {
        for k in 0..=across {
            let x = [L * i as f64 / n as f64, w * k as f64 / across as f64, 0.0];
            idx[i][k] = m.add_node((i * (across + 1) + k) as i64 + 1, x);
            m.constraints.push((idx[i][k], [i == 0, true, true]));
        }
    }
    let kind = if triangles {
        ElementKind::Tri
    } else {
        ElementKind::Quad
    };
    let p = m.add_part(
        1,
        "band",
        kind,
        PartProps {
            youngs_modulus_1: Some(E),
            youngs_modulus_2: Some(E / 50.0),
            shear_modulus_12: Some(E / 100.0),
            density: Some(RHO),
            thickness: Some(s),
            failure_strain: Some(EPS_F),
            ..Default::default()
        },
    );
    let mut id = 0;
    let mut flaw = Vec::new();
    for i in 0..n {
        for k in 0..across {
            let q = [idx[i][k], idx[i + 1][k], idx[i + 1][k + 1], idx[i][k + 1]];
            let cells: Vec<Vec<usize>> = if triangles {
                vec![vec![q[0], q[1], q[2]], vec![q[0], q[2], q[3]]]
            } else {
                vec![q.to_vec()]
            };
            for c in cells {
                id += 1;
                m.add_element(id, p, &c);
                flaw.push(if i == n - 1 { FLAW } else { 1.0 });
            }
        }
    }
    m.elements.get_mut(&kind).unwrap().failure_factor = flaw;
    // The far masses in proportion to the widths their nodes gather the stress from
    // (½, 1, …, 1, ½ of a cell's): every node of a column then decelerates alike.
    let strip_mass = RHO * s * w * L;
    let far: Vec<(usize, f64)> = (0..=across)
        .map(|k| {
            let share = if k == 0 || k == across { 0.5 } else { 1.0 };
            (idx[n][k], 1e6 * strip_mass * share / across as f64)
        })
        .collect();
    pull(&mut m, &far);
    (
        m,
        w * s / across as f64 * L / n as f64 / if triangles { 2.0 } else { 1.0 },
        s,
    )
}

/// The strip of `membrane_strip` pulled to failure: the flawed column fails along the
/// yarn at its strain, takes its energy (closed form below), frees the masses.
fn check_membrane_strip(triangles: bool) {
    let (n, across) = (10, 2);
    let (mut m, volume, _) = membrane_strip(n, across, triangles);
    m.analysis.end_time = end_time();
    m.analysis.output_interval = 5e-8;
    let (s, out, stats) = run_in_memory(&m).unwrap();
    let ev = &s.failures.events;
    let dt = s.stable.dt;
    let per_cell = if triangles { 2 } else { 1 };
    println!(
        "{} strip: {} failures, first {:?}; dt {dt:.3e} s, balance {:.2e}",
        if triangles { "triangle" } else { "quad" },
        ev.len(),
        ev.first(),
        stats.max_balance_error_relative
    );
    // The flawed column, all of it in the same step, and nothing else.
    assert_eq!(ev.len(), across * per_cell, "{ev:?}");
    let first_flawed = ((n - 1) * across * per_cell) as i64 + 1;
    for e in ev {
        assert!(e.id >= first_flawed && e.step == ev[0].step, "{e:?}");
        assert_eq!(
            (e.failure.criterion, e.failure.eroded),
            (Criterion::Direction1, true)
        );
    }
    let tip = out
        .nodes
        .iter()
        .position(|&i| i == m.num_nodes() - 1)
        .unwrap();
    let vs = out.velocity_series(tip, 0);
    let k = out.t.iter().position(|&t| t >= ev[0].time).unwrap();
    let (v_end, limit) = (vs[k - 1], FLAW * EPS_F);
    let f = ev[0].failure;
    assert!(
        f.value >= limit && f.value - limit <= v_end / L * dt,
        "failed at {} against {limit} + {:e}",
        f.value,
        v_end / L * dt
    );
    // Its energy: a uniaxial stretch λ = 1 + ε along axis 1 (E₂₂ = E₁₂ = 0, ν = 0) stores
    // V ½ E₁ E₁₁², E₁₁ = (λ² − 1)/2, and its stress S₁₁ = E₁ E₁₁ would still have worked
    // over half a step at the stretch rate λ̇ = v_end/L: V S₁₁ λ λ̇.
    let lam = 1.0 + f.value;
    let e11 = 0.5 * (lam * lam - 1.0);
    let w = volume * 0.5 * E * e11 * e11 - 0.5 * dt * volume * E * e11 * lam * v_end / L;
    println!("taken {:.9e} J, closed form {w:.9e} J", f.energy);
    // Measured: 4·10⁻¹⁰ (quads), 2·10⁻⁹ (triangles).
    assert!(rel(f.energy, w) < 1e-8, "{} vs {w}", f.energy);
    // The far nodes, free, keep their velocity.
    let spread = vs[k + 2..]
        .iter()
        .fold(0.0f64, |a, v| a.max((v - vs[k + 2]).abs()));
    assert!(
        spread == 0.0,
        "free mass velocity changes by {spread:e} m/s"
    );
    // The balance: exact at the failure (the taken energy above), then the ringing that
    // a brittle release leaves in the strip is integrated with the O(Δt²) energy error of
    // the central difference on this stiffening (St Venant–Kirchhoff) law: 3.5·10⁻⁴ of the
    // energy scale 2.6 µs after (quads; 8·10⁻⁵ J at 1 µs, 1.1·10⁻⁵ J at half the step,
    // 2.5·10⁻⁶ J at a quarter; triangles 1.6·10⁻⁴: measured). The issue asks ≤ 1 %.
    let tol = if triangles { 5e-4 } else { 1e-3 };
    assert!(
        stats.max_balance_error_relative < tol,
        "{}",
        stats.max_balance_error_relative
    );
}

#[test]
fn a_band_of_quads_breaks_along_its_yarn_at_its_failure_strain() {
    check_membrane_strip(false);
}

#[test]
fn a_band_of_triangles_breaks_along_its_yarn_at_its_failure_strain() {
    check_membrane_strip(true);
}
