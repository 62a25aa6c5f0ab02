//! Transverse impact of a rigid sphere on a square membrane (one-point quads), full model
//! and quarter model with symmetry planes.
//!
//! References: the symmetric problem's solution is symmetric, so a quarter model with
//! the normal displacement held on x = 0 and y = 0 and a quarter of the projectile mass
//! must reproduce the full model (any FE text on symmetry, e.g. Cook et al., *Concepts
//! and Applications of FEA*, §2.11); the hourglass energy of one-point quads must stay a
//! small fraction of the internal energy (below 10 %, the usual acceptance criterion;
//! Belytschko, Liu, Moran §8.7; docs/theory.md, "Closed forms used as oracles").
//!
//! ```text
//!        y                      quarter:  y
//!   +----+----+                        +----+
//!   |    |    |   40 mm × 40 mm        |    |   symmetry x = 0, y = 0
//!   +----o----+-- x  pinned edges      o----+-- x
//!   |    |    |   sphere R 3 mm, 100 m/s
//!   +----+----+
//! ```

mod common;
use weft::generate::grid::rectangle;
use weft::model::{ElementKind, Model, PartProps, ProjectileShape, ProjectileSpec, SymmetryPlane};
use weft::solver::run_in_memory;

fn sheet(x0: f64, y0: f64, l: f64, n: usize, mass: f64, quarter: bool) -> Model {
    let (nodes, elems) = rectangle(n, n, l, l, ElementKind::Quad);
    let mut m = Model::default();
    for (i, x) in nodes.iter().enumerate() {
        m.add_node(i as i64 + 1, [x[0] + x0, x[1] + y0, 0.0]);
    }
    let p = m.add_part(
        1,
        "fabric",
        ElementKind::Quad,
        PartProps {
            youngs_modulus_1: Some(30e9),
            youngs_modulus_2: Some(30e9),
            poisson_ratio_12: Some(0.0),
            shear_modulus_12: Some(1e9),
            thickness: Some(2e-4),
            density: Some(1440.0),
            ..Default::default()
        },
    );
    for (e, ns) in elems.iter().enumerate() {
        m.add_element(e as i64 + 1, p, ns);
    }
    let edge = 0.02 - 1e-9;
    for (i, x) in m.coords.clone().iter().enumerate() {
        if x[0].abs() >= edge || x[1].abs() >= edge {
            m.constraints.push((i, [true, true, true]));
        }
    }
    if quarter {
        m.symmetry.push(SymmetryPlane {
            normal: 0,
            position: 0.0,
            tolerance: 1e-9,
        });
        m.symmetry.push(SymmetryPlane {
            normal: 1,
            position: 0.0,
            tolerance: 1e-9,
        });
    }
    m.projectiles.push(ProjectileSpec {
        id: 1,
        shape: ProjectileShape::Sphere,
        radius: 3e-3,
        length: 0.0,
        mass,
        tip: [0.0, 0.0, 0.0],
        axis: [0.0, 0.0, -1.0],
        velocity: [0.0, 0.0, -100.0],
        prescribed_velocity: false,
        contact_stiffness: None,
        friction: 0.0,
        contact_damping: 0.0,
        segment_contact: true,
    });
    m.analysis.end_time = 40e-6;
    m.analysis.output_interval = 1e-6;
    m
}

#[test]
fn quarter_model_with_symmetry_planes_matches_the_full_model() {
    let mass = 1e-3;
    let full = sheet(-0.02, -0.02, 0.04, 40, mass, false);
    let quarter = sheet(0.0, 0.0, 0.02, 20, mass / 4.0, true);
    let (sf, of, _) = run_in_memory(&full).unwrap();
    let (sq, oq, _) = run_in_memory(&quarter).unwrap();
    let find = |s: &weft::solver::Solver, x: f64, y: f64| {
        s.reference_positions()
            .iter()
            .position(|p| (p[0] - x).abs() < 1e-9 && (p[1] - y).abs() < 1e-9)
            .unwrap()
    };
    let mut worst: f64 = 0.0;
    let mut peak: f64 = 0.0;
    for (x, y) in [
        (0.0, 0.0),
        (0.005, 0.002),
        (0.01, 0.0),
        (0.0, 0.012),
        (0.007, 0.007),
    ] {
        let (jf, jq) = (find(&sf, x, y), find(&sq, x, y));
        for k in 0..of.t.len() {
            for d in 0..3 {
                worst = worst.max((of.u[k][jf][d] - oq.u[k][jq][d]).abs());
                peak = peak.max(of.u[k][jf][d].abs());
            }
        }
    }
    eprintln!("quarter vs full: max |Δu| {worst:.3e} m against peak {peak:.3e} m");
    assert!(peak > 1e-4, "the membrane deflected");
    assert!(
        worst < 1e-6 * peak,
        "quarter and full models differ by {worst} m (peak {peak} m)"
    );
    let (pf, pq) = (
        of.projectile.last().unwrap().2[5],
        oq.projectile.last().unwrap().2[5],
    );
    assert!(
        (pf - pq).abs() < 1e-6 * pf.abs(),
        "projectile velocity {pf} vs {pq}"
    );
}

#[test]
fn hourglass_energy_stays_below_ten_percent_of_internal_energy_in_an_impact() {
    let m = sheet(0.0, 0.0, 0.02, 20, 2.5e-4, true);
    let (_s, out, _) = run_in_memory(&m).unwrap();
    let e = out.energy.last().unwrap();
    // Judged once the internal energy is meaningful (5 % of its peak): before that the
    // ratio of two vanishing energies says nothing.
    let peak = out.energy.iter().map(|e| e.internal).fold(0.0, f64::max);
    let worst = out
        .energy
        .iter()
        .filter(|e| e.internal > 0.05 * peak)
        .map(|e| e.hourglass / e.internal)
        .fold(0.0, f64::max);
    eprintln!("impact: hourglass/internal max {worst:.3e}, at the end {:.3e}; energy error {:.2e} of {:.3e} J", e.hourglass / e.internal, e.balance_error, 0.5 * 2.5e-4 * 100.0f64.powi(2));
    assert!(e.internal > 0.0);
    assert!(
        worst < 0.1,
        "hourglass energy reached {:.1} % of the internal energy",
        100.0 * worst
    );
    // Energy balance: measured 2.03·10⁻⁴ of the striking energy; tolerance 3×.
    assert!(e.balance_error.abs() < 6e-4 * 0.5 * 2.5e-4 * 1e4, "{e:?}");
}
