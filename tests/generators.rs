//! Model generators: counts, masses and node sets against their formulas, the rod-width
//! warning, stable default runs, and the lattice homogenisation the paper's §4 relies on.
//!
//! References: the square lattice of rods (spacing a, width b, height h) as a membrane
//! (docs/theory.md, "Closed forms used as oracles"; Gibson & Ashby, *Cellular Solids*, §4.3): stretching stiffness E·b·h/a
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
        clamp_rotations: true,
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
            let mass: f64 = s.masses().iter().sum();
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
        let mass: f64 = Solver::new(&m).unwrap().masses().iter().sum();
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

use weft::generate::zones::{
    combined, woven_reduced, Centre, CombinedParams, MembraneProps, WovenParams,
};
use weft::model::{ElementKind, Model};

fn cp(centre: Centre, quarter: bool) -> CombinedParams {
    let (a, b) = (0.02 / 8.0, 0.02 / 80.0);
    CombinedParams {
        centre,
        centre_length: 0.02,
        centre_cells: 8,
        length: 0.06,
        coarsening: 2,
        growth: 1.3,
        quarter,
        youngs_modulus: 1.5e11,
        density: 7800.0,
        rod_width: b,
        membrane: MembraneProps {
            youngs_modulus: 1.5e11,
            poisson_ratio: 0.0,
            shear_modulus: 1.5e11 * (b / a).powi(2) / 2.0,
            thickness: b * b / a,
            density: 7800.0 * (2.0 - b / a),
        },
        force: 10.0,
        pulse: 0.02 * (7800.0f64 / 1.5e11).sqrt(),
        end_time: 2.0 * 0.03 * (7800.0f64 / 1.5e11).sqrt(),
        output_interval: 1e-7,
    }
}

/// Every node strictly inside an edge of a coarse quad is a tie slave.
fn no_hanging_nodes(m: &Model) {
    let slaves: std::collections::HashSet<usize> = m.ties.iter().map(|t| t.slave).collect();
    let b = m.block(ElementKind::Quad).unwrap();
    let coarse: Vec<usize> = (0..b.len())
        .filter(|&e| m.parts[b.part[e]].name == "coarse_membrane")
        .collect();
    for e in coarse {
        let ns = &b.nodes[4 * e..4 * e + 4];
        for k in 0..4 {
            let (p, q) = (m.coords[ns[k]], m.coords[ns[(k + 1) % 4]]);
            for (i, x) in m.coords.iter().enumerate() {
                if ns.contains(&i) {
                    continue;
                }
                let t = ((x[0] - p[0]) * (q[0] - p[0]) + (x[1] - p[1]) * (q[1] - p[1]))
                    / ((q[0] - p[0]).powi(2) + (q[1] - p[1]).powi(2));
                let d = ((p[0] + t * (q[0] - p[0]) - x[0]).powi(2)
                    + (p[1] + t * (q[1] - p[1]) - x[1]).powi(2)
                    + (x[2] - p[2]).powi(2))
                .sqrt();
                if t > 1e-9 && t < 1.0 - 1e-9 && d < 1e-12 {
                    assert!(
                        slaves.contains(&i),
                        "node {} hangs on a coarse edge without a tie",
                        m.node_id[i]
                    );
                }
            }
        }
    }
}

fn sets_on_lines(m: &Model) {
    for name in ["reference", "axis_x", "diagonal", "interface"] {
        assert!(!m.node_sets[name].is_empty(), "set {name} is empty");
    }
    let x = &m.coords;
    for w in m.node_sets["axis_x"].windows(2) {
        assert!(x[w[0]][1].abs() < 1e-12 && x[w[1]][0] > x[w[0]][0]);
    }
    for w in m.node_sets["diagonal"].windows(2) {
        assert!((x[w[1]][0] - x[w[1]][1]).abs() < 1e-12 && x[w[1]][0] > x[w[0]][0]);
    }
    let slaves: std::collections::HashSet<usize> = m.ties.iter().map(|t| t.slave).collect();
    assert!(m.node_sets["interface"].iter().all(|n| slaves.contains(n)));
}

#[test]
fn combined_models_are_tied_without_hanging_nodes_and_weigh_what_they_should() {
    for centre in [Centre::Girder, Centre::Membrane] {
        for quarter in [true, false] {
            let p = cp(centre, quarter);
            let m = combined(&p).unwrap();
            no_hanging_nodes(&m);
            sets_on_lines(&m);
            let mass: f64 = weft::solver::Solver::new(&m).unwrap().physical_mass();
            let (c, half) = (0.01, 0.03);
            let area_out = if quarter {
                half * half - c * c
            } else {
                4.0 * (half * half - c * c)
            };
            let area_in = if quarter { c * c } else { 4.0 * c * c };
            let a = 0.02 / 8.0;
            let b = p.rod_width;
            let areal_in = match centre {
                Centre::Girder => 7800.0 * b * b * (2.0 - b / a) / a,
                Centre::Membrane => p.membrane.density * p.membrane.thickness,
            };
            let exact = p.membrane.density * p.membrane.thickness * area_out + areal_in * area_in;
            assert!(
                rel(mass, exact) < 1e-9,
                "{centre:?} quarter={quarter}: {mass} vs {exact}"
            );
        }
    }
}

#[test]
fn a_quarter_combined_model_matches_the_full_one() {
    let (q, f) = (
        combined(&cp(Centre::Girder, true)).unwrap(),
        combined(&cp(Centre::Girder, false)).unwrap(),
    );
    let (sq_, oq, _) = run_in_memory(&q).unwrap();
    let (sf, of, _) = run_in_memory(&f).unwrap();
    let find = |s: &Solver, x: f64, y: f64| {
        s.reference_positions()
            .iter()
            .position(|p| (p[0] - x).abs() < 1e-12 && (p[1] - y).abs() < 1e-12)
            .unwrap()
    };
    let (mut worst, mut peak) = (0.0f64, 0.0f64);
    for (x, y) in [(0.0, 0.0), (0.005, 0.0025), (0.0075, 0.0075), (0.01, 0.005)] {
        let (jq, jf) = (find(&sq_, x, y), find(&sf, x, y));
        for k in 0..oq.t.len() {
            worst = worst.max((oq.u[k][jq][2] - of.u[k][jf][2]).abs());
            peak = peak.max(of.u[k][jf][2].abs());
        }
    }
    eprintln!("combined quarter vs full: {worst:.3e} m of {peak:.3e} m");
    assert!(peak > 0.0 && worst < 1e-9 * peak, "{worst} of {peak}");
}

#[test]
fn the_reduced_woven_model() {
    let p = WovenParams::paper();
    let m = woven_reduced(&p).unwrap();
    no_hanging_nodes(&m);
    sets_on_lines(&m);
    let n = p.yarns / 2;
    assert_eq!(m.block(ElementKind::Link).unwrap().len(), (n + 1) * (n + 1));
    assert_eq!(m.block(ElementKind::Truss).unwrap().len(), 2 * n * (n + 1));
    // Mass: yarns ρA × length (the yarns on the symmetry planes and on the interface
    // with half the area: n + 1 lines of length c per family, two of them half) and the
    // membrane ρ s × its area.
    let c = n as f64 * p.spacing;
    let yarn = p.yarn_density * p.yarn_area * 2.0 * c * n as f64;
    let mp = p.membrane();
    let mem = mp.density * mp.thickness * (0.05f64.powi(2) - c * c);
    let s = Solver::new(&m).unwrap();
    assert!(
        rel(s.physical_mass(), yarn + mem) < 1e-9,
        "{} vs {}",
        s.physical_mass(),
        yarn + mem
    );
    // It runs stably, in seconds, and the patch takes up the projectile.
    let t = std::time::Instant::now();
    let (_s, out, st) = run_in_memory(&m).unwrap();
    let e = out.energy.last().unwrap();
    let v = out.projectile.last().unwrap().2[5];
    let ke0 = 0.5 * 0.25 * p.projectile_mass * p.projectile_velocity.powi(2);
    eprintln!("woven-reduced: {} steps in {:.2} s, projectile {v:.1} m/s, energy error {:.2e} of {ke0:.1} J", st.steps, t.elapsed().as_secs_f64(), e.balance_error);
    assert!(
        v > -0.999 * p.projectile_velocity,
        "the patch did not slow the projectile"
    );
    // Energy balance: measured 1.57·10⁻⁶ of the striking energy; tolerance 3.2×.
    assert!(e.balance_error.abs() < 5e-6 * ke0, "{e:?}");
}

/// The striking speed is checked in one place (`model::striker::check_striking_speed`): both woven
/// generators refuse a negative or non-finite `--projectile-velocity` in the same words,
/// the flag, the value, what is expected and a hint.
#[test]
fn both_woven_generators_refuse_a_bad_striking_speed_in_one_wording() {
    use weft::generate::woven::{woven, WovenBandParams};
    for v in [-1.0, f64::NAN, f64::NEG_INFINITY] {
        let band = woven(&WovenBandParams {
            projectile_velocity: v,
            ..WovenBandParams::default()
        })
        .expect_err("the yarn-level patch refuses it")
        .to_string();
        let reduced = woven_reduced(&WovenParams {
            projectile_velocity: v,
            ..WovenParams::paper()
        })
        .expect_err("the reduced model refuses it")
        .to_string();
        assert_eq!(band, reduced);
        for part in [
            format!("--projectile-velocity = `{v}`"),
            "expected a finite striking speed ≥ 0 in m/s".to_string(),
            "hint: give the speed without a sign".to_string(),
        ] {
            assert!(band.contains(&part), "{band} lacks {part}");
        }
    }
}

#[test]
fn combined_models_run_stably_at_their_defaults() {
    for centre in [Centre::Girder, Centre::Membrane] {
        let m = combined(&cp(centre, true)).unwrap();
        let (_s, out, _) = run_in_memory(&m).unwrap();
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
        eprintln!("combined {centre:?}: energy balance {:.2e}", worst / wmax);
        assert!(worst < 0.01 * wmax, "{centre:?}: {worst} of {wmax}");
    }
}

#[test]
fn every_generator_at_its_cli_defaults_simulates_stably_through_the_binaries() {
    use std::process::Command;
    let dir = tempfile::tempdir().unwrap();
    for model in ["rod", "girder", "membrane", "combined", "woven-reduced"] {
        let (m, o) = (
            dir.path().join(model),
            dir.path().join(format!("{model}-out")),
        );
        let st = Command::new(env!("CARGO_BIN_EXE_weft-weave"))
            .arg(model)
            .arg("--out")
            .arg(&m)
            .output()
            .unwrap();
        assert!(
            st.status.success(),
            "{model}: {}",
            String::from_utf8_lossy(&st.stderr)
        );
        let t = std::time::Instant::now();
        let st = Command::new(env!("CARGO_BIN_EXE_weft-simulate"))
            .arg("--model")
            .arg(&m)
            .arg("--out")
            .arg(&o)
            .arg("-q")
            .output()
            .unwrap();
        assert!(
            st.status.success(),
            "{model}: {}",
            String::from_utf8_lossy(&st.stderr)
        );
        let secs = t.elapsed().as_secs_f64();
        let e = weft::table::Table::read(&o.join("energy.parquet")).unwrap();
        let err = e.f64("balance_error", "").unwrap();
        let (ke, ie, w) = (
            e.f64("kinetic", "").unwrap(),
            e.f64("internal", "").unwrap(),
            e.f64("external_work", "").unwrap(),
        );
        let scale = (0..ke.len())
            .map(|k| w[k].abs().max(ke[0] + ie[0]).max(ke[k] + ie[k]))
            .fold(0.0, f64::max);
        let worst = err.iter().map(|x| x.abs()).fold(0.0, f64::max);
        eprintln!("{model}: {secs:.2} s, energy balance {:.2e}", worst / scale);
        assert!(
            scale > 0.0 && worst < 0.01 * scale,
            "{model}: {worst} of {scale}"
        );
        // The written relative column says the same at every sample, the first ones
        // included (it once read 0.90 at the rod's first sample, against the tiny energy
        // of the first 0.1 µs, for a run whose balance is 2e-4).
        let rel = e.f64("balance_error_relative", "").unwrap();
        let first = rel.iter().cloned().fold(0.0, f64::max);
        assert!(
            first < 0.01,
            "{model}: balance_error_relative up to {first}"
        );
        // No wall-time assertion (a shared machine); the time is printed above.
    }
}

/// A model with nothing to drive it (the combined model without its loads) has only
/// round-off energies (~1e-27 J): its balance must not be judged against them (it once
/// stopped with "energy balance error 1.1e-27 J is 86.6 % of the reference energy").
/// Oracle: energy conservation of an unloaded model at rest, with the round-off floor of
/// the energy scale (½ M (10⁻¹² L/Δt)², see `Energies::scale`).
#[test]
fn an_unloaded_model_at_rest_runs_with_no_energy_error() {
    let mut m = combined(&cp(Centre::Girder, false)).unwrap();
    m.loads.clear();
    let (s, out, st) = run_in_memory(&m).unwrap();
    let ke = out.energy.iter().map(|e| e.kinetic).fold(0.0, f64::max);
    let scale = out.energy.last().unwrap().scale;
    let mass: f64 = s.masses().iter().sum();
    eprintln!(
        "unloaded combined: kinetic ≤ {ke:.2e} J, scale {scale:.2e} J, balance {:.2e}",
        st.max_balance_error_relative
    );
    // A round-off bound: a node's position is off by at most half an ulp of the model's
    // size L, εL/2; the whole mass moving that much per step carries ½M(εL/(2Δt))², i.e.
    // (ε/2/10⁻¹²)² = 1.2e-8 of the floor ½M(10⁻¹² L/Δt)² (`Energies::scale`), and the
    // balance error of a model at rest is its round-off energies. Measured: kinetic
    // 1.5e-26 J, balance 4.2e-11 of the floor 3.7e-16 J (290× below the bound; it was
    // 1e-6, 24 000× above).
    let roundoff = (0.5 * f64::EPSILON / 1e-12).powi(2);
    assert!(
        st.max_balance_error_relative < roundoff,
        "balance {} of the floor, above round-off {roundoff:.2e}",
        st.max_balance_error_relative
    );
    // The floor is far below any energy a load would give this model: a velocity of
    // 1 µm/s over its whole mass.
    assert!(scale < 0.5 * mass * 1e-12, "{scale} vs {mass} kg");
}

/// The paper's Fig. 5b: the membrane of N_m cells per side with a girder zone L/2 × L/2
/// at its centre (rods of the girder of N_g cells per side), its closed-form equivalent
/// membrane around it (s = b²/a, ρ = ρ_g(2 − b/a), a = L/N_g; Gibson & Ashby §4.3,
/// docs/theory.md, "Closed forms used as oracles").
fn zone_membrane(nm: usize, ng: usize, lc: LoadCase) -> (MembraneParams, Model) {
    use weft::generate::square::GirderZone;
    let z = GirderZone {
        length: 0.05,
        cells: ng,
        youngs_modulus: 1.5e11,
        density: 7800.0,
        rod_width: 0.1 / (10.0 * ng as f64),
        rigid: true,
    };
    let (s, rho, g) = z.equivalent(0.1);
    let p = MembraneParams {
        square: sq(nm, lc),
        youngs_modulus: 1.5e11,
        poisson_ratio: 0.0,
        shear_modulus: g,
        thickness: s,
        density: rho,
        girder_zone: Some(z),
    };
    let m = membrane(&p).unwrap();
    (p, m)
}

#[test]
fn a_membrane_with_a_girder_zone_weighs_and_stretches_as_the_lattice() {
    for (nm, ng) in [(4usize, 12usize), (8, 8), (4, 20)] {
        let (p, m) = zone_membrane(nm, ng, LoadCase::Tension);
        let z = p.girder_zone.as_ref().unwrap();
        let (a, b) = (0.1 / ng as f64, z.rod_width);
        let nz = ng / 2;
        // Every boundary node of the zone tied once, to the hole's edge it lies on.
        assert_eq!(m.ties.len(), 4 * nz, "N_m = {nm}, N_g = {ng}");
        let centre = &m.node_sets["centre"];
        assert_eq!(centre.len(), (nz + 1) * (nz + 1));
        let (lo, hi) = (0.025 - 1e-12, 0.075 + 1e-12);
        assert!(centre.iter().all(|&n| {
            let x = m.coords[n];
            (lo..=hi).contains(&x[0]) && (lo..=hi).contains(&x[1])
        }));
        // The zone's nodes sit where the full girder's `centre` nodes do, so that
        // position matching pairs them (the paper's reference nodes).
        let (g, _) = girder(&gp(ng, LoadCase::Tension, true)).unwrap();
        let key = |m: &Model, n: usize| {
            let x = m.coords[n];
            ((x[0] * 1e9).round() as i64, (x[1] * 1e9).round() as i64)
        };
        let mut mine: Vec<_> = centre.iter().map(|&n| key(&m, n)).collect();
        let mut theirs: Vec<_> = g.node_sets["centre"].iter().map(|&n| key(&g, n)).collect();
        mine.sort();
        theirs.sort();
        assert_eq!(mine, theirs);
        // Mass: the lattice's areal density ρ_g·b²(2 − b/a)/a over all of L², the zone
        // as rods (its boundary rods half) and the rest as the equivalent membrane.
        let mass = Solver::new(&m).unwrap().physical_mass();
        let exact = 7800.0 * b * b * (2.0 - b / a) / a * 0.01;
        assert!(rel(mass, exact) < 1e-12, "{mass} vs {exact}");
        // Static tension (ν = 0): uniform strain ε = F/(E·s·L) = F/(E·b²·N_g) in the
        // membrane and in the zone's rods alike, so u_x = ε·x at every node, the tied
        // boundary included (a linear field is exact on the hole's edges).
        let u = Solver::new(&m).unwrap().solve_static(&m).unwrap().u;
        let eps = 100.0 / (1.5e11 * b * b * ng as f64);
        let worst = (0..m.num_nodes())
            .map(|n| (u[n][0] - eps * m.coords[n][0]).abs().max(u[n][1].abs()))
            .fold(0.0, f64::max);
        eprintln!("N_m = {nm}, N_g = {ng}: {:.2e} of ε·L", worst / (eps * 0.1));
        // Measured: 4.7e-10, 2.6e-10, 1.1e-9 of ε·L (the sparse solve's round-off).
        assert!(
            worst < 1e-8 * eps * 0.1,
            "N_m = {nm}, N_g = {ng}: {worst:e} m"
        );
    }
}

#[test]
fn a_girder_zone_that_misses_the_grid_is_refused_with_a_hint() {
    use weft::generate::square::GirderZone;
    let mk = |nm: usize, ng: usize, length: f64| {
        membrane(&MembraneParams {
            girder_zone: Some(GirderZone {
                length,
                cells: ng,
                youngs_modulus: 1.5e11,
                density: 7800.0,
                rod_width: 1e-3,
                rigid: true,
            }),
            ..MembraneParams::paper_default(sq(nm, LoadCase::Tension))
        })
        .err()
        .expect("an error")
        .to_string()
    };
    let e = mk(6, 12, 0.05);
    assert!(
        e.contains("membrane's grid lines") && e.contains("multiple of 4"),
        "{e}"
    );
    let e = mk(4, 10, 0.05);
    assert!(
        e.contains("girder's grid lines") && e.contains("--girder-cells"),
        "{e}"
    );
    let e = mk(4, 12, 0.1);
    assert!(e.contains("--zone-length"), "{e}");
    let e = mk(4, 100, 0.05);
    assert!(e.contains("--rod-width") && e.contains("L/N_g"), "{e}");
}
