//! Single-degree-of-freedom oracles for the explicit integrator, the link element's
//! spring, dashpot and friction slider, and mass-proportional damping.
//!
//! Reference: the closed-form responses of a mass–spring–dashpot oscillator (e.g.
//! Clough & Penzien, *Dynamics of Structures*, ch. 2–3); the central-difference scheme's
//! second-order accuracy and its period error ω²Δt²/24 (Belytschko, Liu, Moran, *Nonlinear
//! Finite Elements*, §6.2; Hughes, *The Finite Element Method*, §9.3).
//!
//! ```text
//!   fixed o--/\/\/\--[=]--o m      (spring k and dashpot c along x)
//! ```

mod common;
use common::*;
use weft::model::{Load, TimeLaw};
use weft::solver::run_in_memory;

const M: f64 = 2.0;
const K: f64 = 800.0; // ω = 20 rad/s, period 0.314 s

/// Max |x_h(t) − x(t)| over the output grid for an undamped oscillator released with
/// velocity v0 at a fixed step dt: x(t) = (v0/ω) sin ωt.
fn sho_error(dt: f64) -> f64 {
    let w = (K / M).sqrt();
    let v0 = 1.0;
    let mut m = oscillator(M, K, 0.0);
    m.initial_velocities.push((1, [v0, 0.0, 0.0]));
    m.analysis.end_time = 1.0;
    // Output on every 16·dt0 so that samples coincide with steps for dt0, dt0/2, dt0/4.
    m.analysis.output_interval = 1.0 / 50.0;
    m.analysis.time_step = Some(dt);
    let (_s, out, _) = run_in_memory(&m).unwrap();
    out.t
        .iter()
        .zip(out.series(1, 0))
        .map(|(t, x)| (x - v0 / w * (w * t).sin()).abs())
        .fold(0.0, f64::max)
}

#[test]
fn central_difference_is_second_order_on_harmonic_oscillator() {
    let dt0 = 1.0 / 50.0 / 16.0; // ωΔt = 0.025
    let e: Vec<f64> = [dt0, dt0 / 2.0, dt0 / 4.0]
        .iter()
        .map(|&dt| sho_error(dt))
        .collect();
    let p1 = (e[0] / e[1]).log2();
    let p2 = (e[1] / e[2]).log2();
    eprintln!("SHO max errors {e:?}, observed orders {p1:.3}, {p2:.3}");
    assert!(
        (p1 - 2.0).abs() < 0.1 && (p2 - 2.0).abs() < 0.1,
        "orders {p1}, {p2}"
    );
    // The leading error is the period error: amplitude·ω·t·(ωΔt)²/24 at t = 1 s.
    let w = (K / M).sqrt();
    let predicted = (1.0 / w) * w * 1.0 * (w * dt0).powi(2) / 24.0;
    assert!(
        rel(e[0], predicted) < 0.15,
        "error {} vs predicted {predicted}",
        e[0]
    );
}

#[test]
fn spring_mass_static_deflection_and_period() {
    // A step force F on a spring–mass: x(t) = (F/k)(1 − cos ωt), peak 2F/k at t = π/ω.
    let f = 10.0;
    let mut m = oscillator(M, K, 0.0);
    m.loads.push(step_load(1, [f, 0.0, 0.0]));
    m.analysis.end_time = 0.5;
    m.analysis.output_interval = 1e-4;
    // Stable step of a mass on a spring to ground: 2√(m/k) (Belytschko eq. 6.2.11).
    let s = weft::solver::Solver::new(&m).unwrap();
    assert!(rel(s.time_step().dt_stable, 2.0 * (M / K).sqrt()) < 1e-12);
    // Accuracy needs ωΔt ≪ 1: ωΔt = 0.02.
    m.analysis.time_step = Some(1e-3);
    let (_s, out, _) = run_in_memory(&m).unwrap();
    let w = (K / M).sqrt();
    let worst = out
        .t
        .iter()
        .zip(out.series(1, 0))
        .map(|(t, x)| (x - f / K * (1.0 - (w * t).cos())).abs())
        .fold(0.0, f64::max);
    assert!(
        worst / (2.0 * f / K) < 2e-3,
        "max error {worst} m against peak {}",
        2.0 * f / K
    );
}

#[test]
fn dashpot_decays_exponentially() {
    // Mass on a dashpot released with v0: v = v0 e^{−t/τ}, x = v0 τ (1 − e^{−t/τ}), τ = m/c.
    let c = 40.0;
    let tau = M / c;
    let v0 = 3.0;
    let mut m = oscillator(M, 0.0, c);
    m.initial_velocities.push((1, [v0, 0.0, 0.0]));
    m.analysis.end_time = 3.0 * tau;
    m.analysis.output_interval = tau / 100.0;
    m.analysis.time_step = Some(tau / 400.0);
    let (s, out, _) = run_in_memory(&m).unwrap();
    // Pure dashpot: critical step 2m/c.
    assert!(rel(s.time_step().dt_stable, 2.0 * M / c) < 1e-12);
    let worst = out
        .t
        .iter()
        .zip(out.series(1, 0))
        .map(|(t, x)| (x - v0 * tau * (1.0 - (-t / tau).exp())).abs())
        .fold(0.0, f64::max);
    assert!(
        worst / (v0 * tau) < 5e-3,
        "max error {worst} m against v0·τ = {}",
        v0 * tau
    );
    // Dissipated energy equals the kinetic energy lost.
    let e = out.energy.last().unwrap();
    // Measured 3.08·10⁻⁶ of the initial kinetic energy; tolerance 3.2×.
    assert!(e.balance_error.abs() / (0.5 * M * v0 * v0) < 1e-5, "{e:?}");
}

#[test]
fn damped_oscillator_matches_closed_form() {
    // ξ = 0.1: x(t) = e^{−ξωt} (v0/ω_d) sin ω_d t.
    let w = (K / M).sqrt();
    let xi = 0.1;
    let c = 2.0 * xi * M * w;
    let wd = w * (1.0 - xi * xi).sqrt();
    let v0 = 1.0;
    let mut m = oscillator(M, K, c);
    m.initial_velocities.push((1, [v0, 0.0, 0.0]));
    m.analysis.end_time = 1.0;
    m.analysis.output_interval = 1e-3;
    m.analysis.time_step = Some(2e-4);
    let (_s, out, _) = run_in_memory(&m).unwrap();
    let worst = out
        .t
        .iter()
        .zip(out.series(1, 0))
        .map(|(t, x)| (x - (-xi * w * t).exp() * v0 / wd * (wd * t).sin()).abs())
        .fold(0.0, f64::max);
    assert!(
        worst / (v0 / w) < 0.01,
        "max error {worst} m against amplitude {}",
        v0 / w
    );
    let e = out.energy.last().unwrap();
    // Measured 5.14·10⁻⁶ of the initial kinetic energy; tolerance 2.9×.
    assert!(
        e.balance_error.abs() / (0.5 * M * v0 * v0) < 1.5e-5,
        "{e:?}"
    );
}

#[test]
fn mass_proportional_damping_decays_free_mass() {
    // Free mass, f = −α m v: v = v0 e^{−αt}, x = (v0/α)(1 − e^{−αt}).
    let alpha = 5.0;
    let v0 = 2.0;
    let mut m = oscillator(M, 0.0, 0.0);
    m.initial_velocities.push((1, [v0, 0.0, 0.0]));
    m.analysis.mass_damping = alpha;
    m.analysis.end_time = 1.0;
    m.analysis.output_interval = 1e-2;
    m.analysis.time_step = Some(1e-3);
    let (_s, out, _) = run_in_memory(&m).unwrap();
    let worst = out
        .t
        .iter()
        .zip(out.series(1, 0))
        .map(|(t, x)| (x - v0 / alpha * (1.0 - (-alpha * t).exp())).abs())
        .fold(0.0, f64::max);
    assert!(worst / (v0 / alpha) < 1e-4, "max error {worst}");
    let e = out.energy.last().unwrap();
    assert!(
        rel(e.damping, 0.5 * M * v0 * v0 * (1.0 - (-2.0 * alpha).exp())) < 1e-3,
        "{e:?}"
    );
}

#[test]
fn friction_slider_sticks_then_slips_at_the_slip_force() {
    // Ramp force F(t) = F_max t/t_r on the mass, slider limit F_s = F_max/2, stiff spring
    // (ω t_r = 2000, quasi-static): stick with x = F/k until F = F_s at t_s = t_r/2; then
    // the link force stays F_s and m ẍ = F − F_s, so
    // x(t_r) = F_s/k + F_max (t_r − t_s)³ / (6 m t_r).
    let k = 1e6;
    let w = (k / M).sqrt();
    let t_r = 2000.0 / w;
    let f_max = 100.0;
    let f_s = 50.0;
    let mut m = oscillator(M, k, 0.0);
    m.parts[0].props.ky = Some(k);
    m.parts[0].props.slip_force = Some(f_s);
    m.loads.push(Load {
        id: 1,
        node: 1,
        force: [f_max, 0.0, 0.0],
        law: TimeLaw::Ramp {
            start: 0.0,
            duration: t_r,
        },
    });
    m.analysis.end_time = t_r;
    m.analysis.output_interval = t_r / 400.0;
    let (s, out, _) = run_in_memory(&m).unwrap();
    // Stick: at F = F_s/2 (t = t_r/4) the spring carries the load.
    let k4 = out.t.iter().position(|&t| t >= 0.25 * t_r - 1e-12).unwrap();
    let x4 = out.series(1, 0)[k4];
    assert!(
        rel(x4, 0.25 * f_max / k) < 0.01,
        "stick: x = {x4} vs F/k = {}",
        0.25 * f_max / k
    );
    // Slip: the link force equals F_s.
    let fl = s.link_forces()[0];
    assert!(
        rel(-fl[0], f_s) < 1e-9,
        "link force {fl:?} vs slip force {f_s}"
    );
    let x_end = *out.series(1, 0).last().unwrap();
    let t_s = 0.5 * t_r;
    let x_exact = f_s / k + f_max * (t_r - t_s).powi(3) / (6.0 * M * t_r);
    assert!(
        rel(x_end, x_exact) < 0.01,
        "slip: x(t_r) = {x_end} vs {x_exact}"
    );
    // Friction dissipation = F_s × slip distance.
    let e = out.energy.last().unwrap();
    let slip = x_end - f_s / k;
    assert!(
        rel(e.friction, f_s * slip) < 0.01,
        "friction energy {} vs F_s·slip {}",
        e.friction,
        f_s * slip
    );
    assert!(e.balance_error.abs() / e.external_work < 0.01, "{e:?}");
}

#[test]
fn mass_scaling_reaches_target_step_and_reports_added_mass() {
    // A stiff spring to ground: critical step 2√(m/k). Asking for 4× that step needs
    // 16× the mass (with the safety factor 0.9: (4/0.9)²·m); the scaled oscillator then
    // swings with the period 2π√(m'/k).
    let k = 1e6;
    let dt_crit = 2.0 * (M / K.max(k)).sqrt();
    let mut m = oscillator(M, k, 0.0);
    m.initial_velocities.push((1, [1.0, 0.0, 0.0]));
    let target = 4.0 * dt_crit;
    m.analysis.target_time_step = Some(target);
    m.analysis.end_time = 0.2;
    m.analysis.output_interval = 1e-4;
    let (s, out, _) = run_in_memory(&m).unwrap();
    let sc = s.mass_scaling().clone().unwrap();
    let m_new = M * (4.0f64 / 0.9).powi(2);
    assert!(
        rel(sc.added_mass, m_new - M) < 1e-6,
        "added {} vs {}",
        sc.added_mass,
        m_new - M
    );
    assert_eq!(sc.nodes_scaled, 1);
    assert!(rel(s.time_step().dt, target) < 1e-12);
    // At ωΔt = 1.8 the discrete solution oscillates with ω_h = (2/Δt) asin(ωΔt/2)
    // (Hughes, The Finite Element Method, §9.3): the scaled system is the one simulated.
    let x = out.series(1, 0);
    let ups = crossings(&out.t, &x, 0.0);
    let n = ups.len() - 1;
    let period_h = (ups[n] - ups[0]) / n as f64;
    let w = (k / m_new).sqrt();
    let wh = 2.0 / target * (w * target / 2.0).asin();
    let period = 2.0 * std::f64::consts::PI / wh;
    eprintln!("scaled oscillator: {n} periods, {period_h:.6} s vs {period:.6} s");
    assert!(n >= 4);
    assert!(
        rel(period_h, period) < 0.01,
        "period {period_h} vs 2π/ω_h = {period}"
    );
}

/// A truss of density 0 is a massless spring k = EA/L₀ (what other codes call SPRINGA with
/// MASS elements): two point masses m on it, released with velocities ±v₀ along its axis,
/// oscillate about the centre with ω = √(2k/m) (two-mass oscillator, Clough & Penzien
/// ch. 2: each half-spring of stiffness 2k holds one mass). And a free node with no mass at
/// all is still refused.
#[test]
fn a_massless_truss_between_point_masses_is_a_spring() {
    use weft::model::{ElementKind, Model, PartProps};
    let (e, a, l0, mass, v0) = (2e9, 1e-6, 0.5, 0.1, 0.01);
    let k = e * a / l0;
    let build = |with_masses: bool| {
        let mut m = Model::default();
        m.add_node(1, [0.0, 0.0, 0.0]);
        m.add_node(2, [l0, 0.0, 0.0]);
        let truss = m.add_part(
            1,
            "spring",
            ElementKind::Truss,
            PartProps {
                youngs_modulus: Some(e),
                area: Some(a),
                density: Some(0.0),
                ..Default::default()
            },
        );
        m.add_element(1, truss, &[0, 1]);
        if with_masses {
            let pm = m.add_part(
                2,
                "masses",
                ElementKind::PointMass,
                PartProps {
                    mass: Some(mass),
                    ..Default::default()
                },
            );
            m.add_element(2, pm, &[0]);
            m.add_element(3, pm, &[1]);
        }
        for n in 0..2 {
            m.constraints.push((n, [false, true, true]));
        }
        m.initial_velocities.push((0, [-v0, 0.0, 0.0]));
        m.initial_velocities.push((1, [v0, 0.0, 0.0]));
        let w = (2.0 * k / mass).sqrt();
        m.analysis.end_time = 4.0 * std::f64::consts::TAU / w;
        m.analysis.output_interval = m.analysis.end_time / 400.0;
        m.analysis.time_step = Some(0.01 / w);
        (m, w)
    };
    let (m, w) = build(true);
    let (_s, out, _) = run_in_memory(&m).unwrap();
    // Node 2 moves by (v₀/ω) sin ωt; the error of central difference at ωΔt = 0.01 over
    // 4 periods is ~ω t (ωΔt)²/24 ≈ 1e-4 of the amplitude.
    let amp = v0 / w;
    let worst = out
        .t
        .iter()
        .zip(out.series(1, 0))
        .map(|(t, x)| (x - amp * (w * t).sin()).abs())
        .fold(0.0, f64::max);
    eprintln!(
        "massless truss spring: max error {:.2e} of the amplitude",
        worst / amp
    );
    // Measured 1.05e-4, the predicted period error 8π(ωΔt)²/24 = 1.05e-4.
    assert!(worst < 5e-4 * amp, "{worst} vs amplitude {amp}");
    // Without the point masses nothing carries mass: refused, naming the node.
    let (bare, _) = build(false);
    let err = run_in_memory(&bare)
        .err()
        .expect("a massless model must be refused");
    let msg = err.to_string();
    assert!(msg.contains("has no mass") && msg.contains('1'), "{msg}");
}
