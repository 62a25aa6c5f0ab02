//! Model generators: counts, masses and node sets against their formulas, the rod-width
//! warning, stable default runs, and the lattice homogenisation the paper's §4 relies on.
//!
//! References: the square lattice of rods (spacing a, width b, height h) as a membrane
//! (DESIGN.md §8; Gibson & Ashby, *Cellular Solids*, §4.3): stretching stiffness E·b·h/a
//! per unit width, shear stiffness E·h·b³/(2a³) with rigid joints, areal density
//! ρ·b·h·(2 − b/a)/a; with b = h the equivalent membrane has s = b²/a, ρ_m = ρ(2 − b/a),
//! G = E(b/a)²/2. The paper's rod range L/(20N) ≤ b ≤ L/(8N) is its eq. (3).

mod common;
use common::*;
use weft::generate::square::{girder, membrane, GirderParams, LoadCase, MembraneParams, Square};
use weft::solver::{run_in_memory, Solver};

fn sq(cells: usize, load_case: LoadCase) -> Square {
    Square {
        length: 0.1,
        cells,
        load_case,
        force: 100.0,
        period: None,
        end_time: None,
        output_interval: None,
    }
}

fn gp(cells: usize, load_case: LoadCase, rigid: bool) -> GirderParams {
    GirderParams {
        square: sq(cells, load_case),
        youngs_modulus: 1.5e11,
        density: 7800.0,
        rod_width: None,
        rod_thickness: None,
        rigid,
        full_edge_rods: false,
    }
}

#[test]
fn girder_and_membrane_counts_masses_and_sets() {
    for n in [1usize, 3, 10] {
        for rigid in [true, false] {
            let p = gp(n, LoadCase::Tension, rigid);
            let (m, _) = girder(&p).unwrap();
            assert_eq!(m.num_nodes(), (n + 1) * (n + 1));
            assert_eq!(m.num_elements(), 2 * n * (n + 1));
            let a = 0.1 / n as f64;
            let (b, h) = (p.b(), p.h());
            let s = Solver::new(&m).unwrap();
            let mass: f64 = s.mass.iter().sum();
            // ρ × volume, each b × b crossing counted once (per rod b·h·(a − b/2)), the
            // 4N boundary rods with half the height: the lattice's areal density
            // ρ·b·h·(2 − b/a)/a over L².
            let exact = 7800.0 * b * h * (a - b / 2.0) * (2 * n * (n + 1) - 2 * n) as f64;
            assert!(rel(exact, 7800.0 * b * h * (2.0 - b / a) / a * 0.01) < 1e-12);
            assert!(rel(mass, exact) < 1e-12, "N = {n}: {mass} vs {exact}");
        }
        let mp = MembraneParams::paper_default(sq(n, LoadCase::Tension));
        let m = membrane(&mp).unwrap();
        assert_eq!(m.num_nodes(), (n + 1) * (n + 1));
        assert_eq!(m.num_elements(), n * n);
        let mass: f64 = Solver::new(&m).unwrap().mass.iter().sum();
        assert!(rel(mass, mp.density * mp.thickness * 0.01) < 1e-12);
        for model in [&m, &girder(&gp(n, LoadCase::Shear, true)).unwrap().0] {
            let x = &model.coords;
            let axis = &model.node_sets["axis_x"];
            let diag = &model.node_sets["diagonal"];
            assert_eq!(axis.len(), n + 1);
            assert_eq!(diag.len(), n + 1);
            assert_eq!(model.node_sets["reference"].len(), (n + 1) * (n + 1));
            for w in axis.windows(2) {
                assert!(x[w[0]][1] == 0.0 && x[w[1]][1] == 0.0 && x[w[1]][0] > x[w[0]][0]);
            }
            for w in diag.windows(2) {
                assert!((x[w[1]][0] - x[w[1]][1]).abs() < 1e-15 && x[w[1]][0] > x[w[0]][0]);
            }
            for &i in &model.node_sets["loaded_edge"] {
                assert!((x[i][0] - 0.1).abs() < 1e-12);
            }
        }
    }
}

#[test]
fn rod_width_outside_the_papers_range_is_warned_about() {
    let mut p = gp(10, LoadCase::Tension, true);
    assert!(
        girder(&p).unwrap().1.is_empty(),
        "b = L/(10N) is inside the range"
    );
    p.rod_width = Some(0.1 / (25.0 * 10.0));
    let w = girder(&p).unwrap().1;
    assert!(w.len() == 1 && w[0].contains("L/(20N) … L/(8N)"), "{w:?}");
    p.rod_width = Some(0.1 / (6.0 * 10.0));
    assert_eq!(girder(&p).unwrap().1.len(), 1);
    p.rod_width = Some(0.02);
    assert!(girder(&p).is_err(), "b ≥ a must be refused");
}

#[test]
fn every_model_runs_stably_at_its_defaults() {
    for lc in [LoadCase::Tension, LoadCase::Shear, LoadCase::Transverse] {
        let models = [
            ("girder rigid", girder(&gp(10, lc, true)).unwrap().0),
            ("girder pinned", girder(&gp(10, lc, false)).unwrap().0),
            (
                "membrane",
                membrane(&MembraneParams::paper_default(sq(10, lc))).unwrap(),
            ),
        ];
        for (name, mut m) in models {
            // Twice the default time, so that the pulse has passed and reflected.
            m.analysis.end_time *= 2.0;
            let t = std::time::Instant::now();
            let (_s, out, st) = run_in_memory(&m).unwrap();
            let wmax = out
                .energy
                .iter()
                .map(|e| e.external_work.abs())
                .fold(0.0, f64::max);
            let worst = out
                .energy
                .iter()
                .map(|e| e.balance_error.abs())
                .fold(0.0, f64::max);
            eprintln!(
                "{name} {lc:?}: {} steps in {:.3} s, energy balance {:.2e}",
                st.steps,
                t.elapsed().as_secs_f64(),
                worst / wmax
            );
            assert!(wmax > 0.0, "{name} {lc:?}: no work done");
            assert!(
                worst < 0.01 * wmax,
                "{name} {lc:?}: energy balance error {worst} of {wmax}"
            );
            assert!(t.elapsed().as_secs_f64() < 10.0);
        }
    }
}

#[test]
fn a_girder_converges_to_its_closed_form_membrane() {
    // Static, b = h = a/10: the membrane with s = b²/a, ρ = ρ_g(2 − b/a), G = E(b/a)²/2
    // carries the same edge loads. In tension the two agree exactly (half-height edge
    // rods make the finite girder the lattice). In shear with a clamped edge, the clamped
    // joint rotations of a rigid-jointed lattice form a boundary layer one cell deep that
    // a continuum cannot have: the difference is O(1/N) and halves as N doubles.
    let edge_mean = |n: usize, lc: LoadCase, d: usize| -> (f64, f64) {
        let (g, _) = girder(&gp(n, lc, true)).unwrap();
        let mem = membrane(&MembraneParams::paper_default(sq(n, lc))).unwrap();
        let ug = Solver::new(&g).unwrap().solve_static(&g).unwrap().u;
        let um = Solver::new(&mem).unwrap().solve_static(&mem).unwrap().u;
        let edge = &g.node_sets["loaded_edge"];
        let mean =
            |u: &Vec<[f64; 3]>| edge.iter().map(|&i| u[i][d]).sum::<f64>() / edge.len() as f64;
        (mean(&ug), mean(&um))
    };
    let (g, m) = edge_mean(10, LoadCase::Tension, 0);
    eprintln!("tension, N = 10: girder {g:.6e} m, membrane {m:.6e} m");
    assert!(rel(m, g) < 1e-6, "tension: {m} vs {g}");
    let errs: Vec<f64> = [10usize, 20, 40]
        .iter()
        .map(|&n| {
            let (g, m) = edge_mean(n, LoadCase::Shear, 1);
            eprintln!(
                "shear, N = {n}: girder {g:.4e} m, membrane {m:.4e} m ({:.2e})",
                rel(m, g)
            );
            rel(m, g)
        })
        .collect();
    assert!(errs[0] < 0.06, "N = 10: {}", errs[0]);
    assert!(
        errs[1] < 0.6 * errs[0] && errs[2] < 0.6 * errs[1],
        "not O(1/N): {errs:?}"
    );
    assert!(errs[2] < 0.015, "N = 40: {}", errs[2]);
}
