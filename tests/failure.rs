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
    let ev = &s.failure_log().events;
    let dt = s.time_step().dt;
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

/// The rate law ε_f(ε̇) = ε_f (1 + C ln(ε̇/ε̇₀)) (docs/theory.md, "Rate dependence"),
/// C = 0.146 at ε̇₀ = 30 s⁻¹ (the fit to Kevlar 49 fabric strips there). The strip of
/// `a_truss_chain_breaks_at_its_failure_strain` pulled at 100 and at 1000 s⁻¹: the flaw
/// fails where its strain reaches the law's threshold at the rate it is strained at,
/// 0.8 ε_f (1 + C ln(ε̇/30)) with ε̇ = v/L, v the pull speed just before the failure (the
/// end mass slows by 3 % or less by then). Measured: failed at 0.033733 at 96.8 s⁻¹ and
/// 0.043582 at 999.5 s⁻¹, their limits 1.7·10⁻⁸ and 3.1·10⁻⁹ from the law at v/L (v
/// sampled at the output before: tolerance 5·10⁻⁸), the strain above the limit by less
/// than one step's increment; the quasi-static strip (no law) fails at 0.0288. (After the flaw
/// breaks, the strip's ringing breaks others at 4–8 µs: their strain peaks, 0.038–0.041,
/// come where the rate passes through zero and the threshold is back at ε_f: the law
/// reads the rate at the step, docs/ballistic_convergence.md, "At armour velocity".)
#[test]
fn a_truss_fails_at_the_rate_laws_strain_for_the_rate_it_is_pulled_at() {
    let (c, rate0) = (0.146, 30.0);
    for speed in [1.0, 10.0] {
        let (mut m, _) = truss_strip(10);
        m.parts[0].props.failure_rate_coefficient = Some(c);
        m.parts[0].props.failure_reference_rate = Some(rate0);
        for iv in m.initial_velocities.iter_mut() {
            iv.1[0] *= speed;
        }
        let law = |rate: f64| FLAW * EPS_F * (1.0 + c * (rate / rate0).ln());
        // To the failure at the law's strain for the nominal rate, and 2 µs on.
        m.analysis.end_time = 1.05 * law(speed * V / L) * L / (speed * V) + 2e-6;
        m.analysis.output_interval = 5e-8;
        let (s, out, _) = run_in_memory(&m).unwrap();
        let ev = &s.failure_log().events;
        assert!(!ev.is_empty(), "at {speed} m/s nothing failed");
        // The flaw first.
        let f = ev[0].failure;
        assert_eq!((ev[0].id, f.criterion), (10, Criterion::Axial), "{ev:?}");
        let tip = out.nodes.iter().position(|&i| i == 10).unwrap();
        let vs = out.velocity_series(tip, 0);
        let k = out.t.iter().position(|&t| t >= ev[0].time).unwrap();
        let rate = vs[k - 1] / L;
        let want = law(rate);
        let inc = rate * s.time_step().dt;
        println!(
            "pulled at {rate:.1} 1/s: failed at {:.6} (limit {:.6}, {:.1e} from the law's {want:.6}), a step's increment {inc:.1e}",
            f.value,
            f.limit,
            (f.limit - want).abs()
        );
        assert!(
            (f.limit - want).abs() < 5e-8,
            "limit {} against {want}",
            f.limit
        );
        assert!(f.value >= f.limit && f.value - f.limit <= inc);
    }
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
    let ev = &s.failure_log().events;
    let dt = s.time_step().dt;
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

/// A link between a held node and a mass moving away at v along x (the spring kx): it
/// breaks when its opening, or its spring force k d, reaches the limit, within one
/// step's increment v Δt of the opening; it takes ½ k d², less the half step of work its
/// force would still have done (k d · v · Δt/2).
fn check_link(by_force: bool) {
    let (k, mass) = (1e5, 1.0);
    let d_f = 1e-3;
    let mut m = Model::default();
    m.add_node(1, [0.0; 3]);
    m.add_node(2, [0.0; 3]);
    let p = m.add_part(
        1,
        "link",
        ElementKind::Link,
        PartProps {
            kx: Some(k),
            failure_force: by_force.then_some(k * d_f),
            failure_opening: (!by_force).then_some(d_f),
            ..Default::default()
        },
    );
    m.add_element(1, p, &[0, 1]);
    pull(&mut m, &[(1, mass)]);
    m.initial_velocities = vec![(1, [V, 0.0, 0.0])];
    m.constraints.push((0, [true, true, true]));
    m.constraints.push((1, [false, true, true]));
    // The mass slows as ½ m v² − ½ k d²: it reaches d_f at v² = V² − k d_f²/m.
    m.analysis.end_time = 1.2e-3;
    m.analysis.output_interval = 1e-5;
    // (The oscillator's stable step is 5.7 ms; a step of 1 µs resolves the failure.)
    m.analysis.time_step = Some(1e-6);
    let (s, out, stats) = run_in_memory(&m).unwrap();
    let ev = &s.failure_log().events;
    let dt = s.time_step().dt;
    assert_eq!(ev.len(), 1, "{ev:?}");
    let f = ev[0].failure;
    let v_at = (V * V - k * d_f * d_f / mass).sqrt();
    let (d, expect) = if by_force {
        (f.value / k, (Criterion::Force, k * d_f))
    } else {
        (f.value, (Criterion::Opening, d_f))
    };
    println!(
        "link by {:?}: at {} (limit {}), d = {d:e} m, dt {dt:.3e} s, taken {:e} J, balance {:.2e}",
        f.criterion, f.value, f.limit, f.energy, stats.max_balance_error_relative
    );
    assert_eq!((f.criterion, f.limit), expect);
    assert!(
        d >= d_f && d - d_f <= v_at * dt,
        "{d} vs {d_f} + {:e}",
        v_at * dt
    );
    let w = 0.5 * k * d * d - 0.5 * dt * k * d * v_at;
    // Measured: 3.5·10⁻⁹ (the speed at the half step against v_at at the failure).
    assert!(rel(f.energy, w) < 1e-8, "{} vs {w}", f.energy);
    let v_end = out.velocity_series(1, 0).last().copied().unwrap();
    assert!(rel(v_end, v_at) < 1e-3, "{v_end} vs {v_at}");
    // A linear spring: the balance closes to round-off (measured 7·10⁻¹⁵).
    assert!(
        stats.max_balance_error_relative < 1e-13,
        "{}",
        stats.max_balance_error_relative
    );
}

#[test]
fn a_link_breaks_at_its_opening() {
    check_link(false);
}

#[test]
fn a_link_breaks_at_its_force() {
    check_link(true);
}

// ---------------------------------------------------------------------------------------
// Smith's critical velocity.
//
// Reference: Smith, McCrackin & Schiefer, Textile Res. J. 28 (1958): a yarn struck
// transversely at constant speed V takes at once, at the impact point, the strain ε(V) of
// V = c√(2ε√(ε(1 + ε)) − ε²) (c = √(E/ρ), a linear law; for another law the same
// relations with its wave speeds, below); so it breaks at once when V exceeds the V_c of
// ε(V_c) = ε_f, and not below (until a reflection comes back). The yarn: a straight
// chain (or a band) on ±40 mm, ends pinned, held in y, struck at its middle by a flat
// nose at a prescribed speed; runs of 4 µs, before the longitudinal wave returns from the
// ends (5.4 µs).
//
// The discretisation (docs/theory.md, "Failure, perforation and the ballistic limit"):
// a discrete yarn's first elements overshoot Smith's strain by about 40 % for the first
// ten steps after the nose strikes, whatever the element size, and the nodes under a
// flat nose ring on their penalty springs: the failure strain is compared after a delay
// τ of ten element transits (`failure_delay`, dε̄/dt = (ε − ε̄)/τ), and the nose's
// contact springs have half their critical damping (`contact_damping`, LS-DYNA's VDC).
// Without them the chain breaks at 0.8 V_c (measured).

/// Smith's V(ε) for a linear law (docs/theory.md, "Closed forms used as oracles").
fn smith_v(eps: f64, c: f64) -> f64 {
    c * (2.0 * eps * (eps * (1.0 + eps)).sqrt() - eps * eps).sqrt()
}

/// A straight chain of trusses on ±half along x (element h), ends pinned, every node held
/// in y, struck at its middle by a flat nose of radius r_n at the constant speed v.
fn struck_chain(v: f64, half: f64, h: f64, r_n: f64) -> Model {
    let mut m = Model::default();
    let n = (2.0 * half / h).round() as usize;
    for i in 0..=n {
        m.add_node(i as i64 + 1, [-half + i as f64 * h, 0.0, 0.0]);
    }
    let p = m.add_part(
        1,
        "yarn",
        ElementKind::Truss,
        PartProps {
            youngs_modulus: Some(E),
            density: Some(RHO),
            area: Some(1e-8),
            tension_only: Some(true),
            failure_strain: Some(EPS_F),
            ..Default::default()
        },
    );
    for e in 0..n {
        m.add_element(e as i64 + 1, p, &[e, e + 1]);
    }
    m.constraints.push((0, [true, true, true]));
    m.constraints.push((n, [true, true, true]));
    for i in 1..n {
        m.constraints.push((i, [false, true, false]));
    }
    m.projectiles.push(weft::model::ProjectileSpec {
        id: 1,
        shape: weft::model::ProjectileShape::Flat,
        radius: r_n,
        length: 2e-3,
        mass: 1.0,
        tip: [0.0, 0.0, 0.0],
        axis: [0.0, 0.0, -1.0],
        velocity: [0.0, 0.0, -v],
        prescribed_velocity: true,
        contact_stiffness: None,
        friction: 0.0,
        contact_damping: 0.0,
        segment_contact: true,
    });
    m
}

/// The speeds around V_c that the tests strike at.
const AROUND: [f64; 4] = [0.98, 0.99, 1.01, 1.02];
const AROUND_BAND: [f64; 4] = [0.97, 0.98, 1.02, 1.03];

/// Whether a struck yarn broke near its middle (within `reach` of the nose), and when.
fn broke_near(s: &weft::solver::Solver, m: &Model, reach: f64) -> Option<f64> {
    s.failure_log()
        .events
        .iter()
        .find(|e| {
            let b = m.block(e.failure.kind).unwrap();
            let npe = e.failure.kind.nodes_per_element();
            let x = b.nodes[npe * e.failure.element..npe * e.failure.element + npe]
                .iter()
                .map(|&n| m.coords[n][0].abs())
                .fold(f64::INFINITY, f64::min);
            x < reach
        })
        .map(|e| e.time)
}

#[test]
fn a_chain_breaks_at_smiths_critical_velocity_and_not_below() {
    let c = (E / RHO).sqrt();
    let vc = smith_v(EPS_F, c);
    // 3.6 %: V_c = 837 m/s for c = 7454 m/s.
    assert!((vc - 837.0).abs() < 1.0, "{vc}");
    let h = 1e-4;
    for f in AROUND {
        let mut m = struck_chain(f * vc, 0.04, h, 2.5e-4);
        m.parts[0].props.failure_delay = Some(10.0 * h / c);
        m.projectiles[0].contact_damping = 0.5;
        m.analysis.end_time = 4e-6;
        m.analysis.output_interval = 1e-7;
        let (s, _, stats) = run_in_memory(&m).unwrap();
        let broke = broke_near(&s, &m, 2e-3);
        println!(
            "chain at {f} V_c: broke at the nose {broke:?}, balance {:.2e}",
            stats.max_balance_error_relative
        );
        // Measured: unbroken at 0.99 V_c; broken at 1.01 V_c after 0.60 µs (4 µs
        // without breaking at 0.99).
        assert_eq!(broke.is_some(), f > 1.0, "at {f} V_c: {broke:?}");
        if let Some(t) = broke {
            assert!(t < 1e-6, "broke {t:e} s after the impact");
        }
    }
}

/// A straight band of `across` quads across its width w along x on ±half, ends pinned,
/// every node held in y, fibres along x (E₁ = E, E₂ = E/50, ν = 0: St Venant–Kirchhoff).
fn struck_band(v: f64, half: f64, h: f64, r_n: f64) -> Model {
    let (w, s, across) = (0.8e-3, 0.08e-3, 2);
    let mut m = Model::default();
    let n = (2.0 * half / h).round() as usize;
    let mut idx = vec![[0usize; 3]; n + 1];
    for i in 0..=n {
        for k in 0..=across {
            let x = [
                -half + i as f64 * h,
                -0.5 * w + w * k as f64 / across as f64,
                0.0,
            ];
            idx[i][k] = m.add_node((i * 3 + k) as i64 + 1, x);
            let end = i == 0 || i == n;
            m.constraints.push((idx[i][k], [end, true, end]));
        }
    }
    let p = m.add_part(
        1,
        "band",
        ElementKind::Quad,
        PartProps {
            youngs_modulus_1: Some(E),
            youngs_modulus_2: Some(E / 50.0),
            shear_modulus_12: Some(E / 100.0),
            density: Some(RHO),
            thickness: Some(s),
            no_compression: Some(true),
            failure_strain: Some(EPS_F),
            ..Default::default()
        },
    );
    let mut id = 0;
    for i in 0..n {
        for k in 0..across {
            id += 1;
            m.add_element(
                id,
                p,
                &[idx[i][k], idx[i + 1][k], idx[i + 1][k + 1], idx[i][k + 1]],
            );
        }
    }
    m.projectiles.push(weft::model::ProjectileSpec {
        id: 1,
        shape: weft::model::ProjectileShape::Flat,
        radius: r_n,
        length: 2e-3,
        mass: 1.0,
        tip: [0.0, 0.0, 0.0],
        axis: [0.0, 0.0, -1.0],
        velocity: [0.0, 0.0, -v],
        prescribed_velocity: true,
        contact_stiffness: None,
        friction: 0.0,
        contact_damping: 0.5,
        segment_contact: true,
    });
    m
}

/// Smith's V(ε) for a yarn of nominal stress P(ε) (Smith et al. treat any law): the
/// longitudinal wave leaves the particle speed w = ∫₀^ε √(P′/ρ) ds, the kink runs at
/// U_L = √(P/(ρ(1 + ε))) in the material, and V² = 2 U_L (1 + ε) w − w². For P = Eε
/// this is the closed form above.
fn smith_v_law(p: impl Fn(f64) -> f64, rho: f64, eps: f64) -> f64 {
    let dp = |s: f64| (p(s + 1e-9) - p(s - 1e-9)) / 2e-9;
    let n = 2000;
    // Simpson on [0, ε]: √P′ is smooth (P′(0) = E).
    let w: f64 = (0..=n)
        .map(|i| {
            let s = eps * i as f64 / n as f64;
            let wt = if i == 0 || i == n {
                1.0
            } else if i % 2 == 1 {
                4.0
            } else {
                2.0
            };
            wt * (dp(s.max(1e-12)) / rho).sqrt()
        })
        .sum::<f64>()
        * eps
        / (3.0 * n as f64);
    let ul = (p(eps) / (rho * (1.0 + eps))).sqrt();
    (2.0 * ul * (1.0 + eps) * w - w * w).sqrt()
}

#[test]
fn a_band_breaks_at_smiths_critical_velocity_for_its_law_and_not_below() {
    let c = (E / RHO).sqrt();
    // The general relations give the closed form for the linear law (the oracle's check).
    assert!(rel(smith_v_law(|e| E * e, RHO, EPS_F), smith_v(EPS_F, c)) < 1e-6);
    // St Venant–Kirchhoff along the fibres (ν = 0): S = E(λ² − 1)/2, P = λS.
    let vc = smith_v_law(|e| E * (1.0 + e) * (e + 0.5 * e * e), RHO, EPS_F);
    println!(
        "band V_c {vc:.1} m/s (linear law: {:.1})",
        smith_v(EPS_F, c)
    );
    let h = 2.5e-4;
    for f in AROUND_BAND {
        let mut m = struck_band(f * vc, 0.04, h, 0.6e-3);
        m.parts[0].props.failure_delay = Some(10.0 * h / c);
        m.analysis.end_time = 4e-6;
        m.analysis.output_interval = 1e-7;
        let (s, _, stats) = run_in_memory(&m).unwrap();
        let broke = broke_near(&s, &m, 3e-3);
        println!(
            "band at {f} V_c: broke at the nose {broke:?}, balance {:.2e}",
            stats.max_balance_error_relative
        );
        // Measured: unbroken at 0.98 V_c; broken at 1.02 V_c after 1.0 µs (at 0.99 V_c
        // the band breaks at 2.0 µs: its ringing is slower to die than the chain's, so
        // the bracket is the issue's 2 %).
        assert_eq!(broke.is_some(), f > 1.0, "at {f} V_c: {broke:?}");
        if let Some(t) = broke {
            assert!(t < 2e-6, "broke {t:e} s after the impact");
        }
    }
}
