//! Linear statics.
//!
//! References: a bar under an end force stretches by FL/(EA); a membrane strip with ν = 0
//! under a uniform edge traction by FL/(EsW) (Timoshenko & Goodier, *Theory of
//! Elasticity*, §1); the static solution is the steady state that a damped dynamic run
//! converges to (dynamic relaxation: Underwood, "Dynamic relaxation", in *Computational
//! Methods for Transient Analysis*, 1983); a pin-jointed square grid has no shear
//! stiffness (a mechanism; Maxwell's rule), so the stiffness matrix is singular.

mod common;
use common::*;
use weft::generate::grid::rectangle;
use weft::generate::rod::{build, RodParams};
use weft::model::{ElementKind, Load, Model, PartProps, TimeLaw};
use weft::solver::{run_in_memory, Solver};

/// Mutation tried (2026-11-23): the assembled stiffness scaled by 1.01 in
/// `solver/statics.rs`: this test and the membrane strip's fail (the consistency check
/// against the damped dynamic run below does not: it is no oracle).
#[test]
fn static_rod_stretches_by_fl_over_ea() {
    let p = RodParams::default();
    let m = build(&p).unwrap();
    let s = Solver::new(&m).unwrap();
    let r = s.solve_static(&m).unwrap();
    let exact = p.force * p.length / (p.youngs_modulus * p.width * p.thickness);
    let tip = r.u[p.elements][0];
    assert!(rel(tip, exact) < 1e-8, "{tip} vs {exact}");
}

fn plate(nx: usize, ny: usize, nu: f64) -> Model {
    let (l, w) = (0.02, 0.01);
    let (nodes, elems) = rectangle(nx, ny, l, w, ElementKind::Quad);
    let mut m = Model::default();
    for (i, x) in nodes.iter().enumerate() {
        m.add_node(i as i64 + 1, *x);
    }
    let p = m.add_part(
        1,
        "sheet",
        ElementKind::Quad,
        PartProps {
            youngs_modulus_1: Some(70e9),
            youngs_modulus_2: Some(70e9),
            poisson_ratio_12: Some(nu),
            shear_modulus_12: Some(70e9 / (2.0 * (1.0 + nu))),
            thickness: Some(1e-3),
            density: Some(2700.0),
            ..Default::default()
        },
    );
    for (e, ns) in elems.iter().enumerate() {
        m.add_element(e as i64 + 1, p, ns);
    }
    for j in 0..=ny {
        m.constraints.push((j * (nx + 1), [true, true, true]));
    }
    m
}

fn edge_load(m: &mut Model, nx: usize, ny: usize, f: [f64; 3]) {
    for j in 0..=ny {
        let w = if j == 0 || j == ny { 0.5 } else { 1.0 } / ny as f64;
        m.loads.push(Load {
            id: j as i64 + 1,
            node: j * (nx + 1) + nx,
            force: [f[0] * w, f[1] * w, f[2] * w],
            law: TimeLaw::Step { start: 0.0 },
        });
    }
}

#[test]
fn static_membrane_strip_in_tension() {
    let (nx, ny) = (8, 4);
    let mut m = plate(nx, ny, 0.0);
    edge_load(&mut m, nx, ny, [1000.0, 0.0, 0.0]);
    let s = Solver::new(&m).unwrap();
    let r = s.solve_static(&m).unwrap();
    let exact = 1000.0 * 0.02 / (70e9 * 1e-3 * 0.01);
    for j in 0..=ny {
        let u = r.u[j * (nx + 1) + nx][0];
        assert!(rel(u, exact) < 1e-8, "edge node {j}: {u} vs {exact}");
    }
    // The out-of-plane directions of the flat sheet have no stiffness: held, not solved.
    assert_eq!(r.held, (nx) * (ny + 1));
}

/// A consistency check, not an oracle (the code against itself: two of its solvers must
/// agree); the closed forms are in the tests above.
#[test]
fn static_solution_is_the_steady_state_of_a_damped_dynamic_run() {
    let (nx, ny) = (10, 5);
    let mut m = plate(nx, ny, 0.3);
    // Small enough that the dynamic run stays linear (u_y²/L ≪ u_x).
    edge_load(&mut m, nx, ny, [3.0, 8.0, 0.0]);
    for i in 0..m.num_nodes() {
        m.constraints.push((i, [false, false, true]));
    }
    let s = Solver::new(&m).unwrap();
    let st = s.solve_static(&m).unwrap();
    // Dynamic relaxation: mass damping near critical for the first (bending-like) mode.
    let c = (70e9f64 / 2700.0).sqrt();
    let f1 = c / (4.0 * 0.02) * 0.3;
    m.analysis.mass_damping = 2.0 * 2.0 * std::f64::consts::PI * f1;
    m.analysis.end_time = 60.0 / f1;
    m.analysis.output_interval = m.analysis.end_time / 20.0;
    m.analysis.history_sets = vec!["tip".into()];
    let tip = (ny / 2) * (nx + 1) + nx;
    m.node_sets.insert("tip".into(), vec![tip]);
    let (_s, out, _) = run_in_memory(&m).unwrap();
    let k = out.t.len() - 1;
    let (ud, us) = (out.u[k][0], st.u[tip]);
    eprintln!("static {us:?} vs dynamic relaxation {ud:?}");
    for d in 0..2 {
        assert!(
            (ud[d] - us[d]).abs() < 0.01 * us[d].abs().max(us[1].abs()),
            "direction {d}: {} vs {}",
            ud[d],
            us[d]
        );
    }
    // Converged: the last two samples agree.
    assert!((out.u[k][0][1] - out.u[k - 1][0][1]).abs() < 1e-3 * us[1].abs());
}

#[test]
fn a_pin_jointed_grid_in_shear_is_a_mechanism() {
    // 4 × 4 cells of trusses, clamped at x = 0, sheared at x = L: no shear stiffness.
    let (n, a) = (4, 0.01);
    let mut m = Model::default();
    for j in 0..=n {
        for i in 0..=n {
            m.add_node(
                (j * (n + 1) + i) as i64 + 1,
                [i as f64 * a, j as f64 * a, 0.0],
            );
        }
    }
    let p = m.add_part(
        1,
        "rods",
        ElementKind::Truss,
        PartProps {
            youngs_modulus: Some(1.5e11),
            density: Some(7800.0),
            area: Some(1e-6),
            ..Default::default()
        },
    );
    let mut id = 1;
    for j in 0..=n {
        for i in 0..=n {
            let k = j * (n + 1) + i;
            if i < n {
                m.add_element(id, p, &[k, k + 1]);
                id += 1;
            }
            if j < n {
                m.add_element(id, p, &[k, k + n + 1]);
                id += 1;
            }
        }
    }
    for j in 0..=n {
        m.constraints.push((j * (n + 1), [true, true, true]));
    }
    for i in 0..m.num_nodes() {
        m.constraints.push((i, [false, false, true]));
    }
    for j in 0..=n {
        m.loads.push(Load {
            id: j as i64 + 1,
            node: j * (n + 1) + n,
            force: [0.0, 10.0, 0.0],
            law: TimeLaw::Step { start: 0.0 },
        });
    }
    let err = Solver::new(&m)
        .unwrap()
        .solve_static(&m)
        .err()
        .expect("a mechanism")
        .to_string();
    assert!(
        err.contains("not positive definite") && err.contains("mechanism") && err.contains("hint:"),
        "{err}"
    );
}
