//! Sliding crossing links (`sliding` link parts, `src/solver/sliding_link.rs`): a link
//! whose ends are points of two yarns that move along them when the link slips, so that
//! yarns slide across each other.
//!
//! Reference: Wriggers, *Computational Contact Mechanics*, §5.2 (Coulomb slip at μ·p_N,
//! return mapping); a block pulled over a rough floor (x = x₁ + v₁τ + ½ (F − μN)/m τ²
//! after a stick phase x = (F/k)(1 − cos ωt) on the tangential spring, ω = √(k/m));
//! the single-degree-of-freedom oscillator x = (v₀/ω) sin ωt; Crisfield, *Non-linear
//! Finite Element Analysis of Solids and Structures* vol. 1, §3.3 (internal force = the
//! energy's gradient).
//!
//! ```text
//!   yarn B:  10 ●━━━━━━━━━━━━━━━━━━━━━━━━━━━━━━━━━━━━ 11 (fixed, 1 m along y)
//!               ┊ link (h above A)
//!   yarn A:  ●──●──●──●──●──●──●──●──●    nodes 1 … 9, fixed, spacing p = 1 mm along x,
//!            1        node 5 (origin) 9   crimped ±c (zigzag) in the crimped cases
//! ```
//!
//! Node 10 (a point mass) is pressed onto yarn A by N and pulled along x by F: it slides
//! along A, across A's nodes and its crimp's crests, while the link's end on A follows.

mod common;

use common::rel;
use weft::model::{ElementKind, Load, Model, PartProps, TimeLaw};
use weft::solver::sliding_link::{self, SlidingState, WIN};
use weft::solver::{run_in_memory, Solver};

const P: f64 = 1e-3;
const H: f64 = 2e-4;
const K_T: f64 = 1e6;
const K_N: f64 = 1e8;

/// The model of the module docs: yarn A (nodes 1…9) with crimp ±`crimp`, node 10 at
/// `h` above A's node 5 on yarn B, whose far end (node 11) is `lb` away along y.
fn node_on_yarn(mass: f64, lb: f64, crimp: f64, props: PartProps) -> Model {
    let mut m = Model::default();
    for k in 0..9 {
        let z = if k % 2 == 0 { crimp } else { -crimp };
        m.add_node(k as i64 + 1, [(k as f64 - 4.0) * P, 0.0, z]);
    }
    m.add_node(10, [0.0, 0.0, crimp + H]);
    m.add_node(11, [0.0, lb, crimp + H]);
    let yarn = m.add_part(
        1,
        "yarn",
        ElementKind::Truss,
        PartProps {
            youngs_modulus: Some(1e9),
            density: Some(0.0),
            area: Some(1e-8),
            ..Default::default()
        },
    );
    let link = m.add_part(
        2,
        "link",
        ElementKind::Link,
        PartProps {
            kx: Some(K_T),
            ky: Some(K_T),
            kz: Some(K_N),
            sliding: Some(true),
            ..props
        },
    );
    let pm = m.add_part(
        3,
        "mass",
        ElementKind::PointMass,
        PartProps {
            mass: Some(mass),
            ..Default::default()
        },
    );
    let mut eid = 1;
    for k in 0..8 {
        m.add_element(eid, yarn, &[k, k + 1]);
        eid += 1;
    }
    m.add_element(eid, yarn, &[9, 10]);
    m.add_element(eid + 1, link, &[4, 9]);
    m.add_element(eid + 2, pm, &[9]);
    for k in (0..9).chain([10]) {
        m.constraints.push((k, [true, true, true]));
    }
    m
}

/// Node 10 pressed by N (starting in equilibrium: the normal spring carries N) and
/// pulled along +x by F from t = 0.
fn pressed_and_pulled(crimp: f64, mass: f64, n_load: f64, mu: f64, f_pull: f64) -> Model {
    let mut m = node_on_yarn(
        mass,
        1.0,
        crimp,
        PartProps {
            friction: Some(mu),
            ..Default::default()
        },
    );
    m.initial_displacement = vec![[0.0; 3]; 11];
    m.initial_displacement[9][2] = -n_load / K_N;
    m.loads.push(Load {
        id: 1,
        node: 9,
        force: [f_pull, 0.0, -n_load],
        law: TimeLaw::Step { start: 0.0 },
    });
    m
}

/// The block on a rough floor with a tangential spring: stick (x = (F/k)(1 − cos ωt))
/// until k x = μN at t₁, then slip at (F − μN)/m with the spring held at μN/k.
fn block_on_floor(t: f64, mass: f64, n_load: f64, mu: f64, f_pull: f64) -> f64 {
    let w = (K_T / mass).sqrt();
    let t1 = (1.0 - mu * n_load / f_pull).acos() / w;
    if t <= t1 {
        return f_pull / K_T * (1.0 - (w * t).cos());
    }
    let (x1, v1) = (mu * n_load / K_T, f_pull / (mass * w) * (w * t1).sin());
    let tau = t - t1;
    x1 + v1 * tau + 0.5 * (f_pull - mu * n_load) / mass * tau * tau
}

#[test]
fn a_node_pressed_on_a_yarn_slides_along_it_at_mu_n_across_its_nodes() {
    // m = 10⁻⁶ kg, N = 2 N, μ = 0.2, F = 1.2 N: slip at (F − μN)/m = 8·10⁵ m/s² after a
    // stick phase of 0.84 µs, to 2.5 spacings (the link's end on A passes nodes 6 and 7).
    // Straight and crimped (±0.1 mm zigzag: the end climbs and descends the crests).
    let (mass, n_load, mu, f_pull) = (1e-6, 2.0, 0.2, 1.2);
    let t_end = (2.0 * 2.5 * P * mass / (f_pull - mu * n_load)).sqrt();
    for crimp in [0.0, 1e-4] {
        let mut m = pressed_and_pulled(crimp, mass, n_load, mu, f_pull);
        m.analysis.end_time = t_end;
        m.analysis.output_interval = t_end / 50.0;
        let (s, out, _) = run_in_memory(&m).unwrap();
        let j = out.nodes.iter().position(|&n| n == 9).unwrap();
        let (x, z) = (out.series(j, 0), out.series(j, 2));
        let want = block_on_floor(t_end, mass, n_load, mu, f_pull);
        let got = *x.last().unwrap();
        let zmax = z.iter().map(|v| (v - z[0]).abs()).fold(0.0, f64::max);
        let e = out.energy.last().unwrap();
        let st = s.operator().el.sliding_link.state[0];
        let slide = (got - mu * n_load / K_T) / P;
        let dissipated = mu * n_load * (got - mu * n_load / K_T);
        eprintln!(
            "crimp {crimp:.0e}: x {got:.6e} m vs {want:.6e} (block on a floor, {:.2e}), end on A at ξ = {:.4} (home 4; {:.2e} off the slide), normal drift {zmax:.2e} m, friction {:.6e} J vs μN·slide {dissipated:.6e} ({:.2e}), balance {:.2e}",
            rel(got, want),
            st.xi[0],
            rel(st.xi[0] - 4.0, slide),
            e.friction,
            rel(e.friction, dissipated),
            e.balance_error_relative
        );
        // Measured 6.8·10⁻⁶ relative, straight and crimped alike; tolerance 2·10⁻⁵, 3×.
        assert!(rel(got, want) < 2e-5, "crimp {crimp}: {got} vs {want}");
        // The end on A followed: ξ − 4 = the slide in spacings, less the spring's μN/k_t
        // (the state is at the last step, x at the output time just before it: measured
        // 2.5·10⁻⁴; tolerance 10⁻³, 4×).
        assert!(
            rel(st.xi[0] - 4.0, slide) < 1e-3,
            "{} vs {slide}",
            st.xi[0] - 4.0
        );
        // Across the crests the normal spring keeps N: node 10 does not move in z
        // (measured 9.0·10⁻¹⁷ m straight, 9.1·10⁻¹⁷ m crimped: 4.5·10⁻⁹ of the static
        // deflection N/k_n; tolerance 4·10⁻¹⁶ m, 4.4×).
        assert!(zmax < 4e-16, "crimp {crimp}: z drift {zmax}");
        // Dissipation μN × the slide (Wriggers §5.2; measured 4.7·10⁻⁸ relative, straight
        // and crimped; tolerance 1.5·10⁻⁷, 3.2×); energy balance 2.9·10⁻⁷ (tolerance
        // 10⁻⁶, 3.5×).
        assert!(
            rel(e.friction, dissipated) < 1.5e-7,
            "crimp {crimp}: friction {} vs μN·slide {dissipated}",
            e.friction
        );
        assert!(e.balance_error_relative.abs() < 1e-6, "{e:?}");
    }
}

#[test]
fn without_a_slider_the_link_is_a_spring_along_the_yarn() {
    // No slider: the ends never move, and node 10 given v₀ along A oscillates on k_t:
    // x = (v₀/ω) sin ωt, ω = √(k_t/m) = 10⁶ rad/s; energy conserved.
    let (mass, v0) = (1e-6, 0.1);
    let mut m = node_on_yarn(mass, 1.0, 1e-4, PartProps::default());
    m.initial_velocities.push((9, [v0, 0.0, 0.0]));
    let w = (K_T / mass).sqrt();
    m.analysis.end_time = 1.25 * std::f64::consts::TAU / w;
    m.analysis.output_interval = m.analysis.end_time / 100.0;
    let (s, out, _) = run_in_memory(&m).unwrap();
    let j = out.nodes.iter().position(|&n| n == 9).unwrap();
    let x = out.series(j, 0);
    let err = out
        .t
        .iter()
        .zip(&x)
        .map(|(t, x)| (x - v0 / w * (w * t).sin()).abs())
        .fold(0.0, f64::max);
    let e = out.energy.last().unwrap();
    eprintln!(
        "largest |x − (v₀/ω) sin ωt| {err:.3e} m of {:.3e}; balance {:.2e}; ends {:?}",
        v0 / w,
        e.balance_error_relative,
        s.operator().el.sliding_link.state[0].xi
    );
    // Measured: 3.1·10⁻³ of the amplitude (the central difference's phase error over 1.25
    // periods); tolerance 1.6×. The energy balance, at its worst over the samples:
    // 6.4·10⁻¹⁶, round-off (a linear spring's work booked step by step); tolerance 5×.
    assert!(err < 5e-3 * v0 / w);
    let worst = out
        .energy
        .iter()
        .map(|e| e.balance_error_relative.abs())
        .fold(0.0, f64::max);
    assert!(worst < 3e-15, "balance {worst:e}");
    assert_eq!(s.operator().el.sliding_link.state[0].xi, [4.0, 1.0]);
}

/// W at window positions `x` (A's nine nodes, then B's; B padded with its last node).
fn energy_at(s: &Solver, x: &[[f64; 3]; 2 * WIN], st: &SlidingState) -> f64 {
    let g = &s.operator().el.sliding_link;
    let xs = [
        std::array::from_fn(|k| x[k]),
        std::array::from_fn(|k| x[WIN + k]),
    ];
    sliding_link::energy(&xs, &g.geom[0], &g.props[0], &g.law[0], st)
}

#[test]
fn the_sliding_link_force_is_minus_its_energy_gradient_on_every_window_node() {
    // W(x) = ½ Σ k d², d = R(u_A, u_B)(P_B − P_A) − d₀ with P and u interpolated on the
    // yarns at the ends ξ (fixed while the link sticks): the forces on A's and B's
    // window nodes must be −∂W/∂x (central differences of W), sum to zero and have no
    // moment (W is invariant under rigid motion). Crimped A, the ends moved off the
    // nodes (ξ_A = 5.3, on a segment, ξ_B = 0.6), every node displaced at random.
    let m = node_on_yarn(1e-6, 2e-3, 1e-4, PartProps::default());
    let s = Solver::new(&m).unwrap();
    let g = &s.operator().el.sliding_link;
    let st = SlidingState {
        xi: [5.3, 0.6],
        gap: g.geom[0].d0[2] + 1e-5,
        ..Default::default()
    };
    let mut x: [[f64; 3]; 2 * WIN] = std::array::from_fn(|k| m.coords[g.nodes[0][k] as usize]);
    let mut seed = 7u64;
    let mut rnd = || {
        seed = seed
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((seed >> 11) as f64 / (1u64 << 53) as f64 - 0.5) * 4e-5
    };
    for p in x.iter_mut() {
        for c in p.iter_mut() {
            *c += rnd();
        }
    }
    // Padding slots repeat B's last node: keep them equal to it.
    let lb = g.geom[0].win[1].len;
    for k in lb..WIN {
        x[WIN + k] = x[WIN + lb - 1];
    }
    let xs = [
        std::array::from_fn(|k| x[k]),
        std::array::from_fn(|k| x[WIN + k]),
    ];
    let mut f = [[0.0; 3]; 2 * WIN];
    sliding_link::elastic_forces(&xs, &g.geom[0], &g.props[0], &g.law[0], &st, &mut f);
    let h = 1e-9;
    let mut worst: f64 = 0.0;
    let scale = f.iter().flatten().fold(0.0f64, |a, v| a.max(v.abs()));
    for k in 0..(WIN + lb) {
        for c in 0..3 {
            let (mut xp, mut xm) = (x, x);
            xp[k][c] += h;
            xm[k][c] -= h;
            let grad = (energy_at(&s, &xp, &st) - energy_at(&s, &xm, &st)) / (2.0 * h);
            worst = worst.max((f[k][c] + grad).abs());
        }
    }
    let sum: [f64; 3] = std::array::from_fn(|c| f.iter().map(|v| v[c]).sum());
    let moment: [f64; 3] = std::array::from_fn(|c| {
        f.iter()
            .zip(&x)
            .map(|(fv, xv)| {
                let m = [
                    xv[1] * fv[2] - xv[2] * fv[1],
                    xv[2] * fv[0] - xv[0] * fv[2],
                    xv[0] * fv[1] - xv[1] * fv[0],
                ];
                m[c]
            })
            .sum()
    });
    eprintln!(
        "largest |f + ∂W/∂x| {worst:.3e} N of forces up to {scale:.3e} N; Σf {sum:?}; Σ x × f {moment:?}"
    );
    // Measured: 7.5·10⁻¹¹ of the largest force (central differences at h = 1 nm); Σf and
    // Σ x × f at rounding.
    assert!(worst < 1e-9 * scale, "{worst} of {scale}");
    assert!(sum.iter().all(|v| v.abs() < 1e-9 * scale), "{sum:?}");
    assert!(
        moment.iter().all(|v| v.abs() < 1e-9 * scale * 1e-2),
        "{moment:?}"
    );
}

#[test]
fn a_frictionless_slide_keeps_its_speed_across_the_crests() {
    // μ = 0: the link carries no tangential force at all (its ends follow the crossing),
    // so node 10 given v₀ along A keeps it: x = v₀ t, kinetic energy constant, nothing
    // dissipated, across 2.5 spacings of a crimped yarn (the normal spring unloaded: h
    // is the rest gap, and it is carried along the crests).
    let (mass, v0) = (1e-6, 50.0);
    let mut m = node_on_yarn(
        mass,
        1.0,
        1e-4,
        PartProps {
            friction: Some(0.0),
            ..Default::default()
        },
    );
    m.initial_velocities.push((9, [v0, 0.0, 0.0]));
    m.analysis.end_time = 2.5 * P / v0;
    m.analysis.output_interval = m.analysis.end_time / 20.0;
    let (s, out, _) = run_in_memory(&m).unwrap();
    let j = out.nodes.iter().position(|&n| n == 9).unwrap();
    let x = *out.series(j, 0).last().unwrap();
    let e = out.energy.last().unwrap();
    let k0 = 0.5 * mass * v0 * v0;
    eprintln!(
        "x {x:.6e} m vs v₀t {:.6e}; kinetic {:.6e} J vs {k0:.6e}; friction {:.2e} J; end on A at ξ = {:.4}",
        v0 * m.analysis.end_time,
        e.kinetic,
        e.friction,
        s.operator().el.sliding_link.state[0].xi[0]
    );
    // Measured: x and the kinetic energy to rounding, friction −4.9·10⁻¹¹ J (3.9·10⁻⁸ of
    // it).
    assert!(rel(x, v0 * m.analysis.end_time) < 1e-9);
    assert!(rel(e.kinetic, k0) < 1e-9);
    assert!(e.friction.abs() < 1e-7 * k0);
    assert!((s.operator().el.sliding_link.state[0].xi[0] - 6.5).abs() < 0.01);
}

#[test]
fn linear_statics_takes_the_sliding_link_as_stuck() {
    // A static force F along A on node 10: x = F/k_t (the link stuck at its reference
    // ends, assembled by finite differences); across (along B, 1 m long) the same.
    let f = 0.3;
    let mut m = node_on_yarn(
        1e-6,
        1.0,
        1e-4,
        PartProps {
            friction: Some(0.2),
            ..Default::default()
        },
    );
    m.loads.push(Load {
        id: 1,
        node: 9,
        force: [f, f, 0.0],
        law: TimeLaw::Step { start: 0.0 },
    });
    let r = Solver::new(&m).unwrap().solve_static(&m).unwrap();
    eprintln!("u {:?} vs F/k_t = {:.6e}", r.u[9], f / K_T);
    // Measured: F/k_t to rounding; across, 4·10⁻¹⁰ relative.
    assert!(rel(r.u[9][0], f / K_T) < 1e-8, "{:?}", r.u[9]);
    // Along y node 10 also pulls yarn B (1 m, E A/L = 10 N/m: in parallel with k_t).
    assert!(rel(r.u[9][1], f / (K_T + 10.0)) < 1e-8, "{:?}", r.u[9]);
}

#[test]
fn bad_sliding_links_are_refused_with_the_link_and_the_reason() {
    let base = || node_on_yarn(1e-6, 1.0, 0.0, PartProps::default());
    // With local_frame as well.
    let mut m = base();
    m.parts[1].props.local_frame = Some(true);
    let e = m.validate().unwrap_err().to_string();
    eprintln!("{e}");
    assert!(e.contains("sliding") && e.contains("local_frame") && e.contains("expected"));
    // An end on no yarn: node 10's truss to node 11 removed.
    let mut m = base();
    let b = m.elements.get_mut(&ElementKind::Truss).unwrap();
    b.id.pop();
    b.part.pop();
    b.nodes.truncate(b.nodes.len() - 2);
    let e = m.validate().unwrap_err().to_string();
    eprintln!("{e}");
    assert!(e.contains("sliding link `10`") && e.contains("on no truss") && e.contains("n2"));
    // Both ends on one yarn.
    let mut m = base();
    let b = m.elements.get_mut(&ElementKind::Link).unwrap();
    b.nodes[1] = 5;
    let e = m.validate().unwrap_err().to_string();
    eprintln!("{e}");
    assert!(e.contains("same yarn"), "{e}");
}
