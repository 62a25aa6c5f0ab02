//! Longitudinal waves in a rod of trusses.
//!
//! Reference: K. F. Graff, *Wave Motion in Elastic Solids* (Dover 1991), §2.1: a rod
//! carries longitudinal waves at c = √(E/ρ) without dispersion; a force F(t) at the end
//! of a semi-infinite rod launches particle velocity v = F/(ρAc) and does work
//! W = ∫F²/(ρAc) dt, which for F₀ sin(πt/T_F) on [0, T_F] is F₀² T_F/(2ρAc).
//!
//! Sketch (defaults of `weft-weave rod`: L = 0.1 m, 200 elements, steel):
//!
//! ```text
//!  fixed |o--o--o-- ... --o--o--o| <- F(t) = F0 sin(pi t / T_F)
//!        x=0                    x=L
//! ```
//! The pulse (half-max of the leading edge at t = T_F/6) travels from x = L towards
//! x = 0; its arrival at x = 0.75 L and x = 0.25 L gives c.

mod common;
use common::*;
use weft::generate::rod::{build, RodParams};
use weft::solver::run_in_memory;

#[test]
fn rod_wave_arrival_speed_matches_sqrt_e_over_rho() {
    let p = RodParams {
        output_interval: Some(2e-8),
        ..Default::default()
    };
    let m = build(&p).unwrap();
    let (_s, out, _st) = run_in_memory(&m).unwrap();
    let c = p.wave_speed();
    // v at the front: F0/(ρAc) at the peak; threshold the leading edge at half of that.
    let vpk = p.force / (p.density * p.width * p.thickness * c);
    let node_at = |frac: f64| {
        out.nodes
            .iter()
            .position(|&i| i == (frac * p.elements as f64) as usize)
            .unwrap()
    };
    let (a, b) = (node_at(0.75), node_at(0.25));
    // The pulse pulls along +x, so the particle velocity it carries is +x.
    let ta = crossing(&out.t, &out.velocity_series(a, 0), 0.5 * vpk).unwrap();
    let tb = crossing(&out.t, &out.velocity_series(b, 0), 0.5 * vpk).unwrap();
    let speed = 0.5 * p.length / (tb - ta);
    eprintln!(
        "rod wave speed {speed:.2} m/s, √(E/ρ) = {c:.2} m/s, error {:.3e}",
        rel(speed, c)
    );
    assert!(
        rel(speed, c) < 0.005,
        "wave speed {speed} m/s vs √(E/ρ) = {c} m/s"
    );
    // Arrival time itself: the half-max of the leading edge leaves x = L at T_F/6.
    let t_expect = p.pulse() / 6.0 + 0.25 * p.length / c;
    assert!(
        rel(ta, t_expect) < 0.01,
        "arrival at 0.75 L: {ta} s vs {t_expect} s"
    );
}

#[test]
fn pulse_work_matches_semi_infinite_rod() {
    let p = RodParams::default();
    let m = build(&p).unwrap();
    let (_s, out, _st) = run_in_memory(&m).unwrap();
    let c = p.wave_speed();
    let w_exact = p.force.powi(2) * p.pulse() / (2.0 * p.density * p.width * p.thickness * c);
    // Once the pulse has left the loaded end (t > T_F) and before its reflection returns
    // (t < 2L/c), the work done is final.
    let k = out
        .energy_t
        .iter()
        .position(|&t| t > 1.5 * p.pulse())
        .unwrap();
    let w = out.energy[k].external_work;
    eprintln!(
        "pulse work {w:.6e} J vs {w_exact:.6e} J, error {:.3e}",
        rel(w, w_exact)
    );
    assert!(
        rel(w, w_exact) < 0.005,
        "work {w} J vs F0²T_F/(2ρAc) = {w_exact} J"
    );
}

#[test]
fn undamped_rod_conserves_energy_within_one_percent() {
    let p = RodParams::default();
    let m = build(&p).unwrap();
    let (_s, out, _st) = run_in_memory(&m).unwrap();
    let w_max = out
        .energy
        .iter()
        .map(|e| e.external_work.abs())
        .fold(0.0, f64::max);
    let worst = out
        .energy
        .iter()
        .map(|e| e.balance_error.abs())
        .fold(0.0, f64::max);
    assert!(w_max > 0.0);
    eprintln!(
        "rod energy balance: max |error| / max work = {:.3e}",
        worst / w_max
    );
    assert!(
        worst / w_max < 0.01,
        "energy balance error {worst} J against work {w_max} J"
    );
    // Total energy: equal split kinetic/strain in a travelling wave (Graff §2.1).
    let last = out.energy.last().unwrap();
    assert!(rel(last.kinetic, last.internal) < 0.02, "{last:?}");
}

#[test]
fn chain_stable_step_is_element_length_over_wave_speed() {
    // Lumped-mass chain: ω_max = 2c/h, so the critical step is h/c (Belytschko, Liu,
    // Moran, Nonlinear Finite Elements, eq. 6.2.11).
    let p = RodParams::default();
    let m = build(&p).unwrap();
    let s = weft::solver::Solver::new(&m).unwrap();
    let h = p.length / p.elements as f64;
    assert!(
        rel(s.time_step().dt_stable, h / p.wave_speed()) < 1e-9,
        "{} vs {}",
        s.time_step().dt_stable,
        h / p.wave_speed()
    );
    assert!(rel(s.time_step().dt, 0.9 * h / p.wave_speed()) < 1e-9);
    assert_eq!(
        s.time_step().element.unwrap().0,
        weft::model::ElementKind::Truss
    );
}

#[test]
fn pretensioned_string_carries_transverse_waves_at_sqrt_t_over_mu() {
    // A string of trusses pre-strained by ε₀ between fixed ends carries T = E·A·ε₀;
    // transverse waves travel at √(T/μ) = √(E ε₀/ρ) (the string equation; e.g. Graff
    // §1.1). E = 80 GPa, ρ = 1440 kg/m³, ε₀ = 1 %: 745.4 m/s.
    use weft::model::{ElementKind, Load, Model, PartProps, TimeLaw};
    let (e, rho, eps0, l, n) = (80e9, 1440.0, 0.01, 0.2, 400usize);
    let mut m = Model::default();
    for i in 0..=n {
        m.add_node(i as i64 + 1, [l * i as f64 / n as f64, 0.0, 0.0]);
    }
    let p = m.add_part(
        1,
        "yarn",
        ElementKind::Truss,
        PartProps {
            youngs_modulus: Some(e),
            density: Some(rho),
            area: Some(1e-8),
            prestrain: Some(eps0),
            ..Default::default()
        },
    );
    for k in 0..n {
        m.add_element(k as i64 + 1, p, &[k, k + 1]);
    }
    m.constraints.push((0, [true, true, true]));
    m.constraints.push((n, [true, true, true]));
    for i in 1..n {
        m.constraints.push((i, [true, true, false]));
    }
    let c = (e * eps0 / rho).sqrt();
    let t_f = 0.02 / c;
    m.loads.push(Load {
        id: 1,
        node: 1,
        force: [0.0, 0.0, 0.01],
        law: TimeLaw::SinePulse {
            start: 0.0,
            duration: t_f,
        },
    });
    m.analysis.end_time = 0.15 / c;
    m.analysis.output_interval = m.analysis.end_time / 1500.0;
    let (s, out, _) = run_in_memory(&m).unwrap();
    // The initial axial force is E·A·ε₀.
    let n0 = weft::solver::truss::axial_force(
        &s.reference_positions()[0],
        &s.reference_positions()[1],
        s.operator().el.truss.k[0],
        s.operator().el.truss.l0[0],
        false,
    );
    assert!(rel(n0, e * 1e-8 * eps0) < 1e-12, "{n0}");
    let j = |x: f64| {
        out.nodes
            .iter()
            .position(|&i| i == (x / l * n as f64).round() as usize)
            .unwrap()
    };
    let wa = out.velocity_series(j(0.04), 2);
    let wb = out.velocity_series(j(0.12), 2);
    let peak = wa.iter().cloned().fold(0.0, f64::max);
    let (ta, tb) = (
        crossing(&out.t, &wa, 0.5 * peak).unwrap(),
        crossing(&out.t, &wb, 0.5 * peak).unwrap(),
    );
    let v = 0.08 / (tb - ta);
    eprintln!("pretensioned string: {v:.1} m/s vs √(Eε₀/ρ) = {c:.1} m/s");
    assert!(rel(v, c) < 0.01, "{v} vs {c}");
}
