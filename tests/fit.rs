//! The fit stage: recovering known parameters, the paper's §4 girder → membrane
//! reduction against the lattice closed forms, determinism, and errors for bad input.

use std::process::Command;

use weft::analysis::Level;
use weft::analysis::Series;
use weft::fit::{fit, parse_param, respond, Case, Method, Objective, Options, Problem};
use weft::generate::square::{girder, membrane, GirderParams, LoadCase, MembraneParams, Square};
use weft::model::Model;

const L: f64 = 0.1;
const E: f64 = 1.5e11;
const RHO_G: f64 = 7800.0;

/// T = L√(ρ_g/E): the time a longitudinal wave needs to cross the girder (the paper's §4).
fn period() -> f64 {
    L * (RHO_G / E).sqrt()
}

fn square(cells: usize, load_case: LoadCase, period: f64) -> Square {
    Square {
        length: L,
        cells,
        load_case,
        force: 100.0,
        period: Some(period),
        end_time: None,
        output_interval: None,
    }
}

fn membrane_model(cells: usize, lc: LoadCase, period: f64, g: f64, s: f64, rho: f64) -> Model {
    membrane(&MembraneParams {
        square: square(cells, lc, period),
        youngs_modulus: E,
        poisson_ratio: 0.0,
        shear_modulus: g,
        thickness: s,
        density: rho,
        girder_zone: None,
    })
    .unwrap()
}

fn girder_model(cells: usize, lc: LoadCase, period: f64) -> Model {
    girder(&GirderParams {
        square: square(cells, lc, period),
        youngs_modulus: E,
        density: RHO_G,
        rod_width: None,
        rod_thickness: None,
        rigid: true,
        full_edge_rods: false,
        // The membrane's clamp holds translations; so does the girder's here.
        clamp_rotations: false,
    })
    .unwrap()
    .0
}

fn case(name: &str, reference: Series, model: Model) -> Case {
    Case {
        name: name.into(),
        reference,
        model,
        set: "reference".into(),
        projectile: None,
    }
}

fn params(m: &Model, specs: &[&str]) -> Vec<weft::fit::Parameter> {
    specs.iter().map(|s| parse_param(s, m).unwrap()).collect()
}

const SPECS: [&str; 3] = [
    "membrane.G12:1e8:1e11:log",
    "membrane.s:1e-5:1e-2:log",
    "membrane.rho:1e3:1e5:log",
];

/// A membrane's own history, fitted from a start far from its parameters, gives the
/// parameters back (to 1e-3 relative), with both local methods.
#[test]
fn fit_recovers_a_models_own_parameters() {
    let (g, s, rho) = (7.5e8, 1e-4, 14820.0);
    let n = 6;
    let p = period();
    let ps = 40.0 * p;
    let tension_ref = membrane_model(n, LoadCase::Tension, p, g, s, rho);
    let shear_ref = membrane_model(n, LoadCase::Shear, ps, g, s, rho);
    let (gs, ss, rs) = (1.6e9, 3e-4, 9000.0);
    let cases = vec![
        case(
            "tension",
            respond(&tension_ref, "reference", false).unwrap(),
            membrane_model(n, LoadCase::Tension, p, gs, ss, rs),
        ),
        case(
            "shear",
            respond(&shear_ref, "reference", false).unwrap(),
            membrane_model(n, LoadCase::Shear, ps, gs, ss, rs),
        ),
    ];
    let problem = Problem {
        params: params(&cases[0].model, &SPECS),
        cases,
        components: vec![0, 1],
        tolerance: 1e-9,
        matching: weft::analysis::Matching::Position,
        static_mode: false,
        objective: Objective::Displacement,
        projectile_weight: 0.0,
    };
    for method in [Method::Cobyla, Method::Gradient] {
        let opts = Options {
            method,
            max_evaluations: 600,
            xtol: 1e-9,
            ftol: 1e-14,
            ..Default::default()
        };
        let r = fit(&problem, &opts, &|_| {}).unwrap();
        let errs: Vec<f64> =
            r.x.iter()
                .zip([g, s, rho])
                .map(|(a, b)| (a - b).abs() / b)
                .collect();
        eprintln!(
            "{method:?}: T {:.3e} -> {:.3e} in {} evaluations; relative errors G {:.2e} s {:.2e} ρ {:.2e}",
            r.t_initial,
            r.t,
            r.evaluations.len(),
            errs[0],
            errs[1],
            errs[2]
        );
        assert!(r.t_initial > 0.1, "the start is far: T {}", r.t_initial);
        for (e, name) in errs.iter().zip(["G", "s", "ρ"]) {
            assert!(*e < 1e-3, "{method:?}: {name} recovered to {e:.3e}");
        }
    }
}

/// Relative errors of the fitted (G, s, ρ) against the closed forms of a square lattice of
/// rigid-jointed rods (docs/theory.md, "Closed forms used as oracles"; Gibson & Ashby, Cellular Solids, 2nd ed. 1997, §4.3:
/// stretching E·b·h/a, shear E·h·b³/(2a³) per unit width): with E_m = E_g and b = h,
/// s = b²/a, ρ = ρ_g(2 − b/a), G = E(b/a)²/2.
fn section4_errors(cells: usize, static_mode: bool) -> (Vec<f64>, f64, usize) {
    let p = period();
    // The shear pulse is long against the time the shear wave √(G/ρ) needs to cross the
    // square (pulse 20 T ≈ 1.0 crossing; wavelength ≈ 20 cells): the membrane is the
    // lattice's long-wave limit, so a pulse that resolves single cells measures the
    // lattice's dispersion, not its membrane.
    let ps = 40.0 * p;
    let (g0, s0, r0) = (2e9, 1e-3, 5000.0);
    let cases = vec![
        case(
            "tension",
            respond(
                &girder_model(cells, LoadCase::Tension, p),
                "reference",
                static_mode,
            )
            .unwrap(),
            membrane_model(cells, LoadCase::Tension, p, g0, s0, r0),
        ),
        case(
            "shear",
            respond(
                &girder_model(cells, LoadCase::Shear, ps),
                "reference",
                static_mode,
            )
            .unwrap(),
            membrane_model(cells, LoadCase::Shear, ps, g0, s0, r0),
        ),
    ];
    let specs: &[&str] = if static_mode { &SPECS[..2] } else { &SPECS };
    let problem = Problem {
        params: params(&cases[0].model, specs),
        cases,
        components: vec![0, 1],
        tolerance: 1e-9,
        matching: weft::analysis::Matching::Position,
        static_mode,
        objective: Objective::Displacement,
        projectile_weight: 0.0,
    };
    // The dynamic T is multi-extremal in (G, s, ρ) (the paper's §6 warns of it): from
    // (2e9, 1e-3, 5000) COBYLA alone stops at T = 0.48. A multistart finds the basin.
    let opts = Options {
        max_evaluations: 400,
        starts: if static_mode { 1 } else { 4 },
        ..Default::default()
    };
    let r = fit(&problem, &opts, &|_| {}).unwrap();
    for st in &r.starts {
        eprintln!(
            "  start {}: T {:.3e} after {} evaluations ({})",
            st.start, st.t, st.evaluations, st.status
        );
    }
    let a = L / cells as f64;
    let b = a / 10.0;
    let closed = [E * (b / a).powi(2) / 2.0, b * b / a, RHO_G * (2.0 - b / a)];
    let errs: Vec<f64> = r.x.iter().zip(closed).map(|(x, c)| (x - c) / c).collect();
    eprintln!(
        "N = {cells}, {}: T {:.3e} -> {:.3e} in {} evaluations; fitted {:?}; closed forms {:?}; relative errors {:?}",
        if static_mode { "static" } else { "dynamic" },
        r.t_initial,
        r.t,
        r.evaluations.len(),
        r.x,
        &closed[..r.x.len()],
        errs
    );
    (errs, r.t, r.evaluations.len())
}

/// The paper's §4: the membrane fitted to a rigid-jointed girder (N = 10) reproduces the
/// lattice closed forms within 5 %, statically ({G, s}) and dynamically ({G, s, ρ}).
#[test]
fn section4_fitted_membrane_matches_the_lattice_closed_forms() {
    for static_mode in [true, false] {
        let (errs, t, _) = section4_errors(10, static_mode);
        // Per parameter, a small factor above what was measured (static, dynamic): G
        // 2.6 %, 3.2 % (a discretisation effect of the N = 10 girder: 1.3 % at N = 20, see
        // the convergence test); s 0.017 %, 0.039 %; ρ 0.15 %.
        for ((e, name), tol) in errs.iter().zip(["G", "s", "ρ"]).zip([0.045, 1e-3, 5e-3]) {
            assert!(
                e.abs() < tol,
                "N = 10, static {static_mode}: {name} off by {e:.4} (tolerance {tol})"
            );
        }
        assert!(
            t < 1e-3,
            "the fitted membrane matches the girder: T = {t:e}"
        );
    }
}

/// The remaining difference in G is the lattice's O(a/L) boundary layer: it shrinks
/// when the cells are halved.
#[test]
fn section4_shear_modulus_converges_with_the_cells() {
    let (e10, _, _) = section4_errors(10, true);
    let (e20, _, _) = section4_errors(20, true);
    eprintln!("G error: N = 10 {:.4}, N = 20 {:.4}", e10[0], e20[0]);
    assert!(
        e20[0].abs() < 0.7 * e10[0].abs(),
        "G error N = 10 {:.4}, N = 20 {:.4}",
        e10[0],
        e20[0]
    );
}

/// The same fit with a multistart gives bit-identical evaluations on 1 and 2 threads.
#[test]
fn multistart_is_reproducible_across_thread_counts() {
    let p = period();
    let reference = membrane_model(4, LoadCase::Shear, 40.0 * p, 7.5e8, 1e-4, 14820.0);
    let cand = membrane_model(4, LoadCase::Shear, 40.0 * p, 1e9, 2e-4, 9000.0);
    let problem = Problem {
        params: params(&cand, &SPECS),
        cases: vec![case(
            "shear",
            respond(&reference, "reference", false).unwrap(),
            cand,
        )],
        components: vec![0, 1],
        tolerance: 1e-9,
        matching: weft::analysis::Matching::Position,
        static_mode: false,
        objective: Objective::Displacement,
        projectile_weight: 0.0,
    };
    let opts = Options {
        starts: 3,
        max_evaluations: 40,
        method: Method::Gradient,
        ..Default::default()
    };
    let run = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| fit(&problem, &opts, &|_| {}).unwrap())
    };
    let (a, b) = (run(1), run(2));
    assert_eq!(a.evaluations.len(), b.evaluations.len());
    for (x, y) in a.evaluations.iter().zip(&b.evaluations) {
        assert_eq!((x.start, x.index), (y.start, y.index));
        assert_eq!(x.t.to_bits(), y.t.to_bits());
        assert!(x
            .x
            .iter()
            .zip(&y.x)
            .all(|(u, v)| u.to_bits() == v.to_bits()));
    }
    assert_eq!(a.x, b.x);
    assert_eq!(a.starts.len(), 3);
}

#[test]
fn bad_parameters_say_what_was_expected() {
    let m = membrane_model(2, LoadCase::Tension, period(), 7.5e8, 1e-4, 14820.0);
    let cases: &[(&str, &[&str])] = &[
        (
            "girder.G12:1:2",
            &["no part named `girder`", "`membrane` (quad)"],
        ),
        (
            "membrane.kx:1:2",
            &["has no property `kx`", "shear_modulus_12", "thickness"],
        ),
        ("membrane.G12:2:1", &["not below the upper bound"]),
        ("membrane.G12:0:1:log", &["log scale needs bounds > 0"]),
        (
            "membrane.G12:a:1",
            &["lower bound `a` is not a finite number"],
        ),
        ("membrane.G12:1", &["2 `:`-separated fields", "LOWER:UPPER"]),
        ("membrane.G12:1:2:5", &["initial value 5e0 lies outside"]),
        ("membraneG12:1:2", &["not of the form PART.PROPERTY"]),
    ];
    for (spec, want) in cases {
        let e = parse_param(spec, &m).unwrap_err().to_string();
        for w in *want {
            assert!(e.contains(w), "`{spec}`: `{e}` lacks `{w}`");
        }
        assert!(e.contains("expected"), "{e}");
    }
    // A tie with a factor sets both properties.
    let p = parse_param("membrane.E1,membrane.E2*0.5:1e9:1e12:log:2e11", &m).unwrap();
    let mut m2 = m.clone();
    weft::fit::apply(&mut m2, &[p], &[2e11]);
    assert_eq!(m2.parts[0].props.youngs_modulus_1, Some(2e11));
    assert_eq!(m2.parts[0].props.youngs_modulus_2, Some(1e11));
}

/// The binary: outputs, and clear errors for a bad node set and mismatched cases.
#[test]
fn weft_fit_binary_writes_its_tables_and_refuses_bad_input() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let run = |args: &[&str]| {
        let o = Command::new(env!("CARGO_BIN_EXE_weft-weave"))
            .args(args)
            .output()
            .unwrap();
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    };
    let s = |p: &str| d.join(p).to_string_lossy().to_string();
    run(&[
        "membrane",
        "--cells",
        "3",
        "--load-case",
        "shear",
        "--out",
        &s("ref"),
    ]);
    run(&[
        "membrane",
        "--cells",
        "3",
        "--load-case",
        "shear",
        "--shear-modulus",
        "1e9",
        "--out",
        &s("cand"),
    ]);
    let o = Command::new(env!("CARGO_BIN_EXE_weft-simulate"))
        .args([
            "--static",
            "--quiet",
            "--model",
            &s("ref"),
            "--out",
            &s("refout"),
        ])
        .output()
        .unwrap();
    assert!(o.status.success());
    let fit_cmd = |extra: &[&str]| {
        Command::new(env!("CARGO_BIN_EXE_weft-fit"))
            .args([
                "--reference-model",
                &s("ref"),
                "--reference-history",
                &s("refout/history.parquet"),
                "--model",
                &s("cand"),
                "--static",
                "--components",
                "ux,uy",
                "--quiet",
                "--out",
                &s("fit"),
            ])
            .args(extra)
            .output()
            .unwrap()
    };
    let o = fit_cmd(&["--param", "membrane.G12:1e8:1e10:log"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    for t in [
        "fit_trace.parquet",
        "fit_result.parquet",
        "models/cand/parts.parquet",
    ] {
        assert!(d.join("fit").join(t).exists(), "{t}");
    }
    let r = weft::table::Table::read(&d.join("fit/fit_result.parquet")).unwrap();
    let v = r.f64("value", "value").unwrap()[0];
    assert!((v - 7.5e8).abs() / 7.5e8 < 1e-3, "fitted G {v}");
    let fitted = weft::model::io::read_model(&d.join("fit/models/cand")).unwrap();
    assert_eq!(fitted.parts[0].props.shear_modulus_12, Some(v));

    let o = fit_cmd(&["--param", "membrane.G12:1e8:1e10:log", "--set", "nowhere"]);
    let e = String::from_utf8_lossy(&o.stderr);
    assert!(
        !o.status.success() && e.contains("no node set `nowhere`") && e.contains("reference"),
        "{e}"
    );
    let o = fit_cmd(&["--param", "membrane.G12:1e8:1e10", "--model", &s("cand")]);
    let e = String::from_utf8_lossy(&o.stderr);
    assert!(
        !o.status.success() && e.contains("expected as many of each"),
        "{e}"
    );
    let o = fit_cmd(&["--param", "web.G12:1e8:1e10"]);
    let e = String::from_utf8_lossy(&o.stderr);
    assert!(
        !o.status.success() && e.contains("no part named `web`"),
        "{e}"
    );
    assert!(!e.contains("panicked"), "{e}");
    // Arrival terms: malformed, at a level ≤ 0, or given to a displacement fit.
    for (bad, says) in [
        ("ux", "no `:`"),
        ("ux:-1", "finite number > 0"),
        ("wx:1e-5", "unknown component"),
    ] {
        let o = fit_cmd(&[
            "--param",
            "membrane.G12:1e8:1e10",
            "--objective",
            "both",
            "--arrival",
            bad,
        ]);
        let e = String::from_utf8_lossy(&o.stderr);
        assert!(
            !o.status.success() && e.contains(says) && e.contains("COMPONENT:LEVEL"),
            "{bad}: {e}"
        );
    }
    let o = fit_cmd(&["--param", "membrane.G12:1e8:1e10", "--arrival", "ux:1e-5"]);
    let e = String::from_utf8_lossy(&o.stderr);
    assert!(
        !o.status.success() && e.contains("--objective displacement"),
        "{e}"
    );
}

/// The wave-speed objective: a membrane's density is recovered from the arrival times of
/// its own longitudinal wave along y = 0 (c = √(E/ρ), docs/theory.md, "Closed forms used as oracles").
#[test]
fn arrival_time_objective_recovers_the_wave_speed() {
    let p = period();
    let (g, s, rho) = (7.5e8, 1e-4, 14820.0);
    let reference = membrane_model(10, LoadCase::Tension, p, g, s, rho);
    let cand = membrane_model(10, LoadCase::Tension, p, g, s, 6000.0);
    let r = respond(&reference, "axis_x", false).unwrap();
    let problem = Problem {
        params: params(&cand, &["membrane.rho:1e3:1e5:log"]),
        cases: vec![case("tension", r.clone(), cand.clone())],
        components: vec![0],
        tolerance: 1e-9,
        matching: weft::analysis::Matching::Position,
        static_mode: false,
        objective: Objective::Arrival {
            terms: vec![weft::fit::ArrivalTerm {
                component: 3,
                level: Level::Relative(0.5),
            }],
            slack: 0.0,
        },
        projectile_weight: 0.0,
    };
    let mut problem = problem;
    problem.cases[0].set = "axis_x".into();
    let fit_r = fit(
        &problem,
        &Options {
            max_evaluations: 200,
            ..Default::default()
        },
        &|_| {},
    )
    .unwrap();
    let err = (fit_r.x[0] - rho).abs() / rho;
    eprintln!(
        "arrival objective: ρ {:.2} (true {rho}), W {:.3e} -> {:.3e}, {} evaluations",
        fit_r.x[0],
        fit_r.t_initial,
        fit_r.t,
        fit_r.evaluations.len()
    );
    assert!(err < 1e-3, "ρ recovered to {err:.2e}");
    assert!(
        fit_r.t_initial > 1e-2,
        "a 1.57× faster wave is far off: W {}",
        fit_r.t_initial
    );
}

/// The N_g = 12 girder's central zone in static tension, against which a candidate
/// membrane's thickness alone is fitted (its node set `set`, matched by `matching`).
fn thickness_problem(cand: Model, set: &str, matching: weft::analysis::Matching) -> Problem {
    let g = girder_model(12, LoadCase::Tension, period());
    let reference = respond(&g, "centre", true).unwrap();
    assert_eq!(reference.node_id.len(), 7 * 7);
    Problem {
        params: params(&cand, &["membrane.s:1e-6:1e-2:log"]),
        cases: vec![Case {
            name: "tension".into(),
            reference,
            model: cand,
            set: set.into(),
            projectile: None,
        }],
        components: vec![0, 1],
        tolerance: 1e-9,
        matching,
        static_mode: true,
        objective: Objective::Displacement,
        projectile_weight: 0.0,
    }
}

/// Fit [`thickness_problem`]: the fitted s relative to the closed form s = b²/a of the
/// girder's cell a = L/12 with b = a/10 (Gibson & Ashby §4.3; docs/theory.md, "Closed forms used as oracles"), T and the
/// start's T.
fn fit_thickness(problem: &Problem) -> (f64, f64, f64) {
    let opts = Options {
        max_evaluations: 200,
        xtol: 1e-10,
        ftol: 1e-16,
        ..Default::default()
    };
    let r = fit(problem, &opts, &|_| {}).unwrap();
    let a = L / 12.0;
    let expected = (a / 10.0).powi(2) / a;
    ((r.x[0] - expected).abs() / expected, r.t, r.t_initial)
}

/// The paper's combined approach (Fig. 5b): the membrane's mesh differs from the
/// girder's (N_m = 5 against N_g = 12), its response interpolated at the girder's nodes
/// of the central zone. In static tension (ν = 0) the lattice strains uniformly and a
/// membrane of any mesh reproduces it, so the fitted thickness is the closed form
/// s = b²/a of the girder's cell a = L/N_g (Gibson & Ashby §4.3; docs/theory.md, "Closed forms used as oracles"), where
/// position matching finds no membrane node at most reference nodes.
#[test]
fn fit_across_meshes_recovers_the_closed_form_thickness() {
    let cand = membrane_model(5, LoadCase::Tension, period(), 7.5e8, 1e-3, 14820.0);
    let mut problem = thickness_problem(cand, "reference", weft::analysis::Matching::Position);
    let err = problem.check().err().unwrap().to_string();
    assert!(err.contains("--match interpolate"), "{err}");
    problem.matching = weft::analysis::Matching::Interpolate;
    problem.check().unwrap();
    let (e, t, _) = fit_thickness(&problem);
    eprintln!("N_m = 5 against N_g = 12: s off the closed form by {e:.2e}, T = {t:.2e}");
    // Measured: 9.5e-10, T = 8.4e-20: the optimiser's resolution, its xtol 1e-10 on the
    // unit box of ln s over [1e-6, 1e-2], i.e. 1e-10·ln(1e4) = 9.2e-10 in s; tolerance
    // 3e-9, 3.2×.
    assert!(e < 3e-9, "s off by {e}");
}

/// The paper's combined model itself (Fig. 5b): a membrane of N_m = 4 cells around a
/// girder zone L/2 × L/2 of the N_g = 12 girder's rods (`weft-weave membrane
/// --girder-cells`), fitted so that the zone's nodes (its `centre` set, matched by
/// position to the full girder's) move as the girder's do. In static tension (ν = 0) the
/// lattice strains uniformly, so the membrane around the zone must have the closed-form
/// thickness s = b²/a (Gibson & Ashby §4.3; docs/theory.md, "Closed forms used as oracles"), from a start 2.4 × off.
#[test]
fn the_combined_models_fit_recovers_the_closed_form_thickness() {
    use weft::generate::square::GirderZone;
    let a = L / 12.0;
    let cand = membrane(&MembraneParams {
        square: square(4, LoadCase::Tension, period()),
        youngs_modulus: E,
        poisson_ratio: 0.0,
        shear_modulus: 7.5e8,
        thickness: 2e-4,
        density: 14820.0,
        girder_zone: Some(GirderZone {
            length: L / 2.0,
            cells: 12,
            youngs_modulus: E,
            density: RHO_G,
            rod_width: a / 10.0,
            rigid: true,
        }),
    })
    .unwrap();
    let problem = thickness_problem(cand, "centre", weft::analysis::Matching::Position);
    problem.check().unwrap();
    let (e, t, t0) = fit_thickness(&problem);
    eprintln!(
        "combined N_m = 4, N_g = 12: s off the closed form by {e:.2e}, T = {t:.2e} from {t0:.2e}"
    );
    // Measured: 3.9e-10, T = 7.3e-20 from 8.2e-2: within the optimiser's resolution, its
    // xtol 1e-10 on the unit box of ln s over [1e-6, 1e-2], i.e. 9.2e-10 in s; tolerance
    // 1.5e-9, 3.9×.
    assert!(e < 1.5e-9, "s off by {e}");
    assert!(t0 > 1e-2, "the start is not far off: T {t0}");
}

/// `--objective both`: T plus the arrival-time mismatch of a wave at one absolute level
/// for all nodes (the paper's "pre-selected level", §3). A membrane's own density and
/// thickness are recovered from a far start (its in-plane speed c = √(E/ρ) and its
/// stiffness E·s set the arrivals and the displacements; docs/theory.md, "Closed forms used as oracles"), and the
/// objective is 0 at the truth (both terms vanish).
#[test]
fn displacement_and_arrival_objective_recovers_density_and_thickness() {
    let p = period();
    let (g, s, rho) = (7.5e8, 1e-4, 14820.0);
    let reference = membrane_model(10, LoadCase::Tension, p, g, s, rho);
    let cand = membrane_model(10, LoadCase::Tension, p, g, 3e-4, 6000.0);
    let r = respond(&reference, "axis_x", false).unwrap();
    let peak = r
        .values
        .iter()
        .flat_map(|v| v.iter().map(|u| u[0].abs()))
        .fold(0.0, f64::max);
    let mut problem = Problem {
        params: params(
            &cand,
            &["membrane.rho:1e3:1e5:log", "membrane.s:1e-5:1e-3:log"],
        ),
        cases: vec![case("tension", r, cand)],
        components: vec![0],
        tolerance: 1e-9,
        matching: weft::analysis::Matching::Position,
        static_mode: false,
        objective: Objective::Both {
            terms: vec![weft::fit::ArrivalTerm {
                component: 0,
                level: Level::Absolute(0.2 * peak),
            }],
            slack: 0.0,
            weight: 1.0,
        },
        projectile_weight: 0.0,
    };
    problem.cases[0].set = "axis_x".into();
    assert!(problem.objective(&[rho, s]).unwrap() < 1e-20);
    let fit_r = fit(
        &problem,
        &Options {
            max_evaluations: 300,
            ..Default::default()
        },
        &|_| {},
    )
    .unwrap();
    let (e_rho, e_s) = ((fit_r.x[0] - rho).abs() / rho, (fit_r.x[1] - s).abs() / s);
    eprintln!(
        "both: ρ {:.2} ({e_rho:.1e}), s {:.4e} ({e_s:.1e}), J {:.3e} -> {:.3e}, {} evaluations",
        fit_r.x[0],
        fit_r.x[1],
        fit_r.t_initial,
        fit_r.t,
        fit_r.evaluations.len()
    );
    // Measured: ρ to 1.5e-5, s to 1.7e-5 (COBYLA's xtol), J 0.20 → 6.7e-11, 78 evaluations.
    assert!(
        e_rho < 1e-4 && e_s < 1e-4,
        "ρ to {e_rho:.1e}, s to {e_s:.1e}"
    );
}
