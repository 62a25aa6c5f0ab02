//! Two-node corotational beams.
//!
//! References: cantilever tip deflection δ = PL³/(3EI) (Timoshenko & Gere, *Mechanics of
//! Materials*, table G-1); first natural frequency of a cantilever
//! ω₁ = (β₁L)² √(EI/(ρAL⁴)), β₁L = 1.875104 (Blevins, *Formulas for Natural Frequency
//! and Mode Shape*, table 8-1); a square lattice of rigidly jointed rods (spacing a,
//! in-plane width b, height h) has the membrane shear stiffness per unit width
//! E h b³/(2a³) (Gibson & Ashby, *Cellular Solids*, §4.3, square cells; docs/theory.md, "Closed forms used as oracles").
//!
//! ```text
//!   clamped |==o==o==o== ... ==o  <- P        20 beams, L = 0.1 m, b = 2 mm, h = 1 mm
//! ```

mod common;
use common::*;
use weft::model::{ElementKind, Load, Model, PartProps, TimeLaw};
use weft::solver::{run_in_memory, Solver};

const E: f64 = 1.5e11;
const RHO: f64 = 7800.0;

fn cantilever(n: usize, l: f64, b: f64, h: f64) -> Model {
    let mut m = Model::default();
    for i in 0..=n {
        m.add_node(i as i64 + 1, [l * i as f64 / n as f64, 0.0, 0.0]);
    }
    let p = m.add_part(
        1,
        "rod",
        ElementKind::Beam,
        PartProps {
            youngs_modulus: Some(E),
            density: Some(RHO),
            width: Some(b),
            height: Some(h),
            poisson_ratio: Some(0.3),
            ..Default::default()
        },
    );
    for e in 0..n {
        m.add_element(e as i64 + 1, p, &[e, e + 1]);
    }
    m.constraints.push((0, [true, true, true]));
    m.rot_constraints.push((0, [true, true, true]));
    m
}

#[test]
fn cantilever_tip_deflection_is_pl3_over_3ei() {
    let (n, l, b, h): (usize, f64, f64, f64) = (20, 0.1, 2e-3, 1e-3);
    for (dir, ei) in [
        (1usize, E * h * b.powi(3) / 12.0),
        (2usize, E * b * h.powi(3) / 12.0),
    ] {
        let mut m = cantilever(n, l, b, h);
        let mut f = [0.0; 3];
        f[dir] = 0.5;
        m.loads.push(Load {
            id: 1,
            node: n,
            force: f,
            law: TimeLaw::Step { start: 0.0 },
        });
        let r = Solver::new(&m).unwrap().solve_static(&m).unwrap();
        let exact = 0.5 * l.powi(3) / (3.0 * ei);
        let tip = r.u[n][dir];
        eprintln!(
            "cantilever ({}): {tip:.6e} m vs PL³/3EI = {exact:.6e} m",
            ["x", "y", "z"][dir]
        );
        // Cubic Hermite beams reproduce the cubic deflection exactly: measured < 1e-7
        // (the printout agrees to 7 digits); round-off of the static solve aside.
        assert!(rel(tip, exact) < 1e-6, "{tip} vs {exact}");
    }
}

#[test]
fn cantilever_first_natural_frequency() {
    let (n, l, b, h): (usize, f64, f64, f64) = (40, 0.1, 2e-3, 1e-3);
    let mut m = cantilever(n, l, b, h);
    let ei = E * h * b.powi(3) / 12.0;
    let area = b * h;
    let w1 = 1.875104f64.powi(2) * (ei / (RHO * area * l.powi(4))).sqrt();
    // Start in the first mode shape (velocity), so that the tip swings at ω₁.
    let beta = 1.875104 / l;
    let sigma = 0.734096;
    for i in 1..=n {
        let x = l * i as f64 / n as f64;
        let phi =
            ((beta * x).cosh() - (beta * x).cos()) - sigma * ((beta * x).sinh() - (beta * x).sin());
        m.initial_velocities.push((i, [0.0, 0.01 * phi / 2.0, 0.0]));
    }
    let period = 2.0 * std::f64::consts::PI / w1;
    m.analysis.end_time = 5.2 * period;
    m.analysis.output_interval = period / 400.0;
    m.analysis.history_sets = vec!["tip".into()];
    m.node_sets.insert("tip".into(), vec![n]);
    let (_s, out, _) = run_in_memory(&m).unwrap();
    let y = out.series(0, 1);
    let ups = crossings(&out.t, &y.iter().map(|v| -v).collect::<Vec<_>>(), 0.0);
    let k = ups.len() - 1;
    let measured = 2.0 * std::f64::consts::PI * k as f64 / (ups[k] - ups[0]);
    eprintln!("cantilever ω₁: {measured:.2} rad/s vs {w1:.2} rad/s over {k} periods");
    assert!(k >= 4);
    // Measured 5.1e-4 (40 elements, the period read from 4 zero crossings).
    assert!(rel(measured, w1) < 1e-3, "{measured} vs {w1}");
    let e = out.energy.last().unwrap();
    // Energy balance: measured 1.52·10⁻⁴ of the energy at the end; tolerance 3.3×.
    assert!(
        e.balance_error.abs() < 5e-4 * (e.kinetic + e.internal),
        "{e:?}"
    );
}

#[test]
fn rigid_jointed_grid_has_the_lattice_shear_stiffness() {
    // Pure shear by edge tractions τ (N/m) on a grid of n × n cells; γ from the edge
    // displacements; G·s = τ/γ against E h b³/(2a³).
    let (n, a) = (30usize, 1e-3);
    let (b, h) = (a / 10.0, a / 10.0);
    let mut m = Model::default();
    let id = |i: usize, j: usize| j * (n + 1) + i;
    for j in 0..=n {
        for i in 0..=n {
            m.add_node(id(i, j) as i64 + 1, [i as f64 * a, j as f64 * a, 0.0]);
        }
    }
    let p = m.add_part(
        1,
        "rods",
        ElementKind::Beam,
        PartProps {
            youngs_modulus: Some(E),
            density: Some(RHO),
            width: Some(b),
            height: Some(h),
            poisson_ratio: Some(0.0),
            ..Default::default()
        },
    );
    let mut eid = 1;
    for j in 0..=n {
        for i in 0..=n {
            if i < n {
                m.add_element(eid, p, &[id(i, j), id(i + 1, j)]);
                eid += 1;
            }
            if j < n {
                m.add_element(eid, p, &[id(i, j), id(i, j + 1)]);
                eid += 1;
            }
        }
    }
    for k in 0..m.num_nodes() {
        m.constraints.push((k, [false, false, true]));
        m.rot_constraints.push((k, [true, true, false]));
    }
    m.constraints.push((id(0, 0), [true, true, true]));
    m.constraints.push((id(n, 0), [false, true, true]));
    let tau = 10.0; // N/m along every edge
    let mut lid = 1;
    let mut push = |node: usize, f: [f64; 3]| {
        m.loads.push(Load {
            id: lid,
            node,
            force: f,
            law: TimeLaw::Step { start: 0.0 },
        });
        lid += 1;
    };
    for k in 0..=n {
        let w = if k == 0 || k == n { 0.5 } else { 1.0 } * tau * a;
        push(id(n, k), [0.0, w, 0.0]);
        push(id(0, k), [0.0, -w, 0.0]);
        push(id(k, n), [w, 0.0, 0.0]);
        push(id(k, 0), [-w, 0.0, 0.0]);
    }
    let r = Solver::new(&m).unwrap().solve_static(&m).unwrap();
    let mean = |f: &dyn Fn(usize) -> f64| (0..=n).map(f).sum::<f64>() / (n + 1) as f64;
    let l = n as f64 * a;
    let gamma = (mean(&|k| r.u[id(n, k)][1]) - mean(&|k| r.u[id(0, k)][1])) / l
        + (mean(&|k| r.u[id(k, n)][0]) - mean(&|k| r.u[id(k, 0)][0])) / l;
    let gs = tau / gamma;
    let expect = E * h * b.powi(3) / (2.0 * a.powi(3));
    eprintln!(
        "grid shear stiffness {gs:.1} N/m vs E h b³/(2a³) = {expect:.1} N/m ({:.2e})",
        rel(gs, expect)
    );
    // Measured 1.82e-2: the closed form is the infinite lattice's, the grid is finite
    // (its boundary rows shear differently).
    assert!(rel(gs, expect) < 0.03, "{gs} vs {expect}");
}

#[test]
fn a_rigidly_rotated_beam_carries_no_force() {
    use weft::solver::beam::{forces, reference_frame, rotate, BeamProps};
    let (x1, x2) = ([0.1, 0.2, 0.3], [0.15, 0.21, 0.28]);
    let e0 = reference_frame(&x1, &x2).unwrap();
    let d = [x2[0] - x1[0], x2[1] - x1[1], x2[2] - x1[2]];
    let l0 = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
    let p = BeamProps {
        l0,
        ea: 1e5,
        gj: 0.5,
        eiy: 0.2,
        eiz: 0.8,
        e0,
    };
    let eye = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    let r = rotate(&eye, &[0.7, -1.1, 0.4]);
    let rx = |v: &[f64; 3]| -> [f64; 3] {
        std::array::from_fn(|i| r[i][0] * v[0] + r[i][1] * v[1] + r[i][2] * v[2] + 0.05)
    };
    let f = forces(&rx(&x1), &rx(&x2), &r, &r, &p);
    for v in f {
        assert!(v.iter().all(|c| c.abs() < 1e-9), "{f:?}");
    }
    // A small relative twist gives the torque GJ φ/L about the (rotated) axis.
    let r2 = rotate(&r, &{
        let ax = std::array::from_fn::<f64, 3, _>(|i| {
            r[i][0] * e0[0][0] + r[i][1] * e0[0][1] + r[i][2] * e0[0][2]
        });
        [1e-4 * ax[0], 1e-4 * ax[1], 1e-4 * ax[2]]
    });
    let f = forces(&rx(&x1), &rx(&x2), &r, &r2, &p);
    let t = (f[3][0].powi(2) + f[3][1].powi(2) + f[3][2].powi(2)).sqrt();
    assert!(
        rel(t, 0.5 * 1e-4 / l0) < 1e-3,
        "torque {t} vs {}",
        0.5 * 1e-4 / l0
    );
}
