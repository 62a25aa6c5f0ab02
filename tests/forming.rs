//! Forming the yarn-level weave by contact equilibrium (`weft-form`, `weft::form`).
//!
//! Oracles:
//! - statics of a string over frictionless supports (Irvine, *Cable Structures*, 1981,
//!   §1): a yarn pulled by T at its ends carries T all along, and between the crossings
//!   it runs straight, so that its crimp is √(1 + (2a/p)²) − 1 for crossings at ±a a
//!   spacing p apart;
//! - equilibrium: a model that starts in equilibrium and at rest stays there;
//! - the straight yarn's axial stiffness E·A, which the tangent stiffness of a crimped
//!   yarn approaches as it straightens, while the crossing yarns take up its crimp
//!   (crimp interchange; Kawabata, Niwa & Kawai, J. Textile Inst. 64, 1973);
//! - symmetry: the periodic cell of a plain weave under equal tensions is invariant under
//!   the two-fold rotations about its mid-span axes, which its forming does not impose.
//!
//! Two ways to form: from the periodic cell reflected over the patch (the default,
//! `--start cell`) and by relaxing the generated geometry whole (`--start geometry`);
//! both meet the same checks.

mod common;
use weft::form::{cell, cell_start, form, form_from, run, Config, Params, Report, StartMode};
use weft::generate::woven::{woven, Lenticular, WovenBandParams};
use weft::model::Model;
use weft::solver::run_in_memory;

fn patch(yarns: usize) -> Model {
    woven(&WovenBandParams {
        yarns,
        ..WovenBandParams::default()
    })
    .unwrap()
    .0
}

/// Formed by relaxing the generated geometry whole (`--start geometry`).
fn formed(m: &Model, p: &Params) -> (Model, Report) {
    form(m, p, &mut |_| {}).unwrap()
}

/// Formed from the periodic cell (`--start cell`, the stage's default).
fn formed_by_cell(m: &Model, p: &Params) -> (Model, Report) {
    let start = cell_start(m, p, &mut |_| {}).unwrap();
    form_from(m, p, Some(&start), &mut |_| {}).unwrap()
}

/// The 6 × 6 quarter formed with the defaults (once for the tests that look at it).
fn default_6x6() -> &'static (Model, Model, Report) {
    static F: std::sync::OnceLock<(Model, Model, Report)> = std::sync::OnceLock::new();
    F.get_or_init(|| {
        let m = patch(6);
        let (f, r) = formed_by_cell(&m, &Params::default());
        (m, f, r)
    })
}

#[test]
fn a_formed_weave_is_in_equilibrium_with_its_tension_and_a_string_crimp() {
    let (m, f, r) = default_6x6();
    assert_eq!(r.start, "cell");
    // Measured 1.0 % (the contacts' discretisation: the cell's quarter crossings see
    // one face each, the patch's crossings four, whose penalty masses differ slightly).
    check_formed("6×6 quarter from the periodic cell", m, f, r, 0.05);
}

/// The same checks, relaxing the generated geometry whole (`--start geometry`).
#[test]
fn a_weave_relaxed_from_its_geometry_meets_the_same_checks() {
    let m = patch(6);
    let (f, r) = formed(&m, &Params::default());
    assert_eq!(r.start, "geometry");
    // Measured 4.4 %: a node chattering at a lens flank; the forming's own stop is 5 %
    // (of the larger of the largest contact force and the largest nodal pull).
    check_formed("6×6 quarter relaxed whole", &m, &f, &r, 0.05);
}

fn check_formed(what: &str, m: &Model, f: &Model, r: &Report, residual: f64) {
    let p = Params::default();
    println!(
        "{what} formed at T = {} N: {} steps, K/W {:.2e}, residual {:.3e} N of contact forces up to {:.3e} N ({:.2} %); tension in the bands {:.4} / {:.4} N, at the ends {:.4} / {:.4} N; crimp {:.3} % → {:.3} % / {:.3} % (string {:.3} %); deepest contact {:.2} %",
        p.warp_tension,
        r.steps,
        r.kinetic_over_work,
        r.max_residual_force,
        r.max_contact_force,
        100.0 * r.max_residual_force / r.max_contact_force,
        r.warp_tension,
        r.weft_tension,
        r.warp_end_tension,
        r.weft_end_tension,
        100.0 * r.crimp_warp_before,
        100.0 * r.crimp_warp_after,
        100.0 * r.crimp_weft_after,
        100.0 * r.crimp_target,
        100.0 * r.max_penetration_ratio
    );
    // Equilibrium: the issue's criteria, which forming stops on.
    assert!(r.kinetic_over_work <= 1e-6);
    assert!(r.max_residual_force <= residual * r.max_contact_force);
    // The tension at the ends: what pulls the yarn, to the residual (measured 0.06 %
    // relaxed whole, 0.02 % from the cell).
    for t in [r.warp_end_tension, r.weft_end_tension] {
        assert!(
            (t - p.warp_tension).abs() < 0.01 * p.warp_tension,
            "end tension {t}"
        );
    }
    // In the bands: the volume mean of the stress along the yarn times A, measured
    // −1.0 % relaxed whole, +1.4 % from the cell (the mean over a crimped band is not its
    // end's resultant: frictionless contact across a lenticular envelope has a component
    // along the yarn, and the one-point quads' hourglass forces carry some); 2 %.
    for t in [r.warp_tension, r.weft_tension] {
        assert!(
            (t - p.warp_tension).abs() < 0.02 * p.warp_tension,
            "band tension {t}"
        );
    }
    // Crimp: the generator's cosine (1.60 %) becomes straight runs between the crossings
    // (string 1.371 %); measured 1.371 % / 1.323 % (warp / weft) relaxed whole, 1.386 % /
    // 1.386 % from the cell; asked 5 %.
    for c in [r.crimp_warp_after, r.crimp_weft_after] {
        assert!(
            (c - r.crimp_target).abs() < 0.05 * r.crimp_target,
            "crimp {c} against {}",
            r.crimp_target
        );
    }
    assert!(r.max_penetration_ratio < 0.1);
    // The formed model writes the formed positions as initial displacements.
    assert_eq!(f.initial_displacement.len(), m.num_nodes());
    assert_eq!(f.coords, m.coords);
    // ... as nodes.parquet columns ux0, uy0, uz0, read back unchanged.
    let dir = tempfile::tempdir().unwrap();
    let prov = weft::table::Provenance::new("test", serde_json::json!({}));
    weft::model::io::write_model(&f, dir.path(), &prov).unwrap();
    let back = weft::model::io::read_model(dir.path()).unwrap();
    assert!(back.initial_displacement == f.initial_displacement);
}

#[test]
fn a_formed_weave_left_alone_stays_where_it_is() {
    let mut f = default_6x6().1.clone();
    f.projectiles.clear();
    f.analysis.end_time = 50e-6;
    f.analysis.output_interval = 5e-6;
    let (s, out, stats) = run_in_memory(&f).unwrap();
    // Displacements in the outputs are from the formed state.
    let size = |u: &[f64; 3]| (u[0] * u[0] + u[1] * u[1] + u[2] * u[2]).sqrt();
    let mut crossing = vec![false; f.num_nodes()];
    for set in ["axis_x", "axis_x_weft", "diagonal", "diagonal_weft"] {
        for &n in &f.node_sets[set] {
            crossing[n] = true;
        }
    }
    let (mut all, mut at_crossings) = (0.0f64, 0.0f64);
    for sample in &out.u {
        for (j, u) in sample.iter().enumerate() {
            let n = s.output_nodes()[j];
            all = all.max(size(u));
            if crossing[n] {
                at_crossings = at_crossings.max(size(u));
            }
        }
    }
    let h = WovenBandParams::default().thickness;
    println!(
        "formed 6×6 quarter at rest for 50 µs: largest displacement at the crossing sets {at_crossings:.3e} m = {:.3} % of h, anywhere {all:.3e} m = {:.3} % of h; energy balance {:.2e}",
        100.0 * at_crossings / h,
        100.0 * all / h,
        stats.max_balance_error_relative
    );
    // The issue asks < 1 % of the yarn thickness over 50 µs, which is also forming's own
    // stop (its rest test, on the pulled model): asserting that could not fail. Measured,
    // relaxed whole: 1.9 % when forming stopped on kinetic energy and residual force
    // alone, 0.14 % with the rest test; from the periodic cell (this model) 1.70e-8 m =
    // 0.014 % of h at the crossings and anywhere: tolerance 5e-4 h = 6.2e-8 m, 3.6×. The
    // tiled cell taken without its rest test, relaxed on until forming's stop, moves
    // 2.4e-7 m = 0.195 % of h here (measured): it passes the 1 % and fails this. Energy
    // balance measured 7.90e-4, tolerance 2.5e-3, 3.2×.
    assert!(
        at_crossings < 5e-4 * h,
        "moved {at_crossings} m at the crossings"
    );
    assert!(all < 5e-4 * h, "moved {all} m");
    assert!(
        stats.max_balance_error_relative < 2.5e-3,
        "energy balance {}",
        stats.max_balance_error_relative
    );
}

/// The chain representation (`weft-weave woven --yarn-model chain`: truss chains along
/// the bands' centre lines, contact thickness t_c) is formed by the same stage and meets
/// the same checks: the string's crimp, the tension at the ends, equilibrium, rest.
#[test]
fn a_chain_weave_is_formed_to_the_same_checks() {
    use weft::generate::woven::YarnModel;
    let m = woven(&WovenBandParams {
        yarns: 6,
        yarn_model: YarnModel::Chain,
        ..WovenBandParams::default()
    })
    .unwrap()
    .0;
    // From the periodic cell (the default) and relaxed whole: measured residual 1.3 % /
    // 0.01 % of the contact forces, end tension 0.5000 N both, tension along the chains
    // 0.5074 / 0.5042 N (the bands': 0.5072 / −1.0 %), crimp 1.402 % / 1.395 % against
    // the string's 1.371 % (+2.3 % / +1.8 %; the bands' +1.1 %).
    let (f, r) = formed_by_cell(&m, &Params::default());
    assert_eq!(r.start, "cell");
    check_formed("6×6 chain quarter from the periodic cell", &m, &f, &r, 0.05);
    let (g, r) = formed(&m, &Params::default());
    check_formed("6×6 chain quarter relaxed whole", &m, &g, &r, 0.05);
    // Left alone for 50 µs: the issue asks < 1 % of the yarn thickness; measured 3.54e-9 m
    // = 0.003 % of h, tolerance 1e-4 h = 1.24e-8 m, 3.5×; energy balance measured 6.26e-4,
    // tolerance 2e-3, 3.2×.
    let mut f = f;
    f.projectiles.clear();
    f.analysis.end_time = 50e-6;
    f.analysis.output_interval = 5e-6;
    let (_, out, stats) = run_in_memory(&f).unwrap();
    let moved = out
        .u
        .iter()
        .flatten()
        .map(|u| (u[0] * u[0] + u[1] * u[1] + u[2] * u[2]).sqrt())
        .fold(0.0, f64::max);
    let h = WovenBandParams::default().thickness;
    println!(
        "formed 6×6 chain quarter at rest for 50 µs: moved ≤ {moved:.3e} m = {:.3} % of h; balance {:.2e}",
        100.0 * moved / h,
        stats.max_balance_error_relative
    );
    assert!(moved < 1e-4 * h, "moved {moved} m");
    assert!(
        stats.max_balance_error_relative < 2e-3,
        "energy balance {}",
        stats.max_balance_error_relative
    );
}

#[test]
fn forming_is_thread_independent() {
    let m = patch(4);
    let p = Params {
        // 3000 relaxation steps, then the free rest test (2157 steps).
        max_steps: 6000,
        min_steps: 3000,
        kinetic_tolerance: 1.0,
        force_tolerance: 1.0,
        creep_tolerance: 1.0,
        ..Params::default()
    };
    let go = |n: usize| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(n)
            .build()
            .unwrap()
            .install(|| {
                (
                    formed(&m, &p).0.initial_displacement,
                    cell_start(&m, &Params::default(), &mut |_| {}).unwrap().u,
                )
            })
    };
    let (one, two) = (go(1), go(2));
    assert!(one.0 == two.0, "relaxed whole: 1 and 2 threads differ");
    assert!(one.1 == two.1, "from the cell: 1 and 2 threads differ");
}

/// Strip tension as a sequence of equilibria (the quasi-static limit of a slow pull): the
/// warp of `m` pulled with T = 0.5 … 100 N, the weft held at 0.5 N; per load (T, the
/// strain from the warp ends' displacement over the half length, warp crimp, weft crimp).
fn pull_strip(m: &Model, p0: &WovenBandParams) -> Vec<(f64, f64, f64, f64)> {
    let half = (p0.yarns as f64 - 0.5) * p0.spacing;
    let end = m
        .coords
        .iter()
        .map(|c| c[0])
        .fold(f64::NEG_INFINITY, f64::max);
    let mut pts = vec![];
    for t in [0.5, 5.0, 25.0, 30.0, 90.0, 100.0] {
        let (f, r) = formed(
            m,
            &Params {
                warp_tension: t,
                kinetic_tolerance: 1e-5,
                // Off: each point is an equilibrium of the strip's stretch, which the
                // ends' mean displacement measures.
                creep_tolerance: 1e3,
                ..Params::default()
            },
        );
        let (mut s, mut n) = (0.0, 0);
        for (c, u) in m.coords.iter().zip(&f.initial_displacement) {
            if (c[0] - end).abs() < 1e-12 {
                s += u[0];
                n += 1;
            }
        }
        pts.push((
            t,
            s / n as f64 / half,
            r.crimp_warp_after,
            r.crimp_weft_after,
        ));
        println!(
            "T = {t} N: {} steps, deepest contact {:.1} % of the centre-line distance",
            r.steps,
            100.0 * r.max_penetration_ratio
        );
    }
    pts
}

/// The same strip of chains (`--yarn-model chain`): the truss's law is linear in the
/// engineering strain, N = E·A(L − L₀)/L₀, so the straight yarn's stiffness is E·A exactly
/// and λ = 1 + T/(E·A).
#[test]
fn pulling_a_chain_warp_straightens_it_and_crimps_the_weft() {
    let p0 = WovenBandParams {
        yarns: 6,
        yarn_model: weft::generate::woven::YarnModel::Chain,
        ..WovenBandParams::default()
    };
    let m = woven(&p0).unwrap().0;
    let ea = p0.modulus * Lenticular::new(p0.width, p0.thickness).area();
    // Measured 0.058 (de-crimping), 0.974 (25–30 N), 0.984 (90–100 N); the warp's crimp
    // 1.39 % → 6·10⁻⁴ % at 30 N while the weft's grows to 6.7 % (7.0 % at 100 N).
    check_strip("chain strip", &pull_strip(&m, &p0), |t| 1.0 + t / ea);
}

#[test]
fn pulling_the_warp_straightens_it_and_crimps_the_weft() {
    let p0 = WovenBandParams {
        yarns: 6,
        ..WovenBandParams::default()
    };
    let m = woven(&p0).unwrap().0;
    let ea = p0.modulus * Lenticular::new(p0.width, p0.thickness).area();
    // The straight yarn: the bands' law is St Venant–Kirchhoff, so a straight yarn
    // pulled by T stretches to λ with T = E·A·λ(λ² − 1)/2 (uniaxial plane stress, the
    // nominal force of S = E·(λ² − 1)/2), a tangent E·A(3λ² − 1)/2.
    let stretch = |t: f64| {
        let mut l = 1.0 + t / ea;
        for _ in 0..20 {
            l -= (ea * l * (l * l - 1.0) / 2.0 - t) / (ea * (3.0 * l * l - 1.0) / 2.0);
        }
        l
    };
    // Measured 0.083 (de-crimping), 0.897 (25–30 N), 0.971 (90–100 N; the warp's strain
    // is 1.9 % there); the weft's crimp 1.37 % → 8.1 %.
    check_strip("strip", &pull_strip(&m, &p0), stretch);
}

/// The strip's checks: `pts` from [`pull_strip`], `stretch(T)` the straight yarn's
/// stretch under T (its law).
fn check_strip(what: &str, pts: &[(f64, f64, f64, f64)], stretch: impl Fn(f64) -> f64) {
    // Secant stiffness between two loads, over the straight yarn's.
    let k = |a: usize, b: usize| {
        (pts[b].1 - pts[a].1).recip() * (stretch(pts[b].0) - stretch(pts[a].0))
    };
    println!(
        "{what}: (T, strain, warp crimp, weft crimp) {pts:?}; stiffness / the straight yarn's: {:.4} (0.5–5 N), {:.4} (25–30 N), {:.4} (90–100 N)",
        k(0, 1),
        k(2, 3),
        k(4, 5)
    );
    // De-crimping first: far softer than the straight yarn.
    assert!(k(0, 1) < 0.1);
    // Then the stiffness tends to the straight yarn's: at 25–30 N the warp's remaining
    // crimp still gives (pulled by T_w over wefts at T_f, its crimp angle is ~θ_f T_f/T_w,
    // its crimp ∝ T_w⁻²); at 90–100 N the issue asks 3 %.
    assert!(k(2, 3) < k(4, 5));
    assert!((k(4, 5) - 1.0).abs() < 0.03, "{}", k(4, 5));
    // Crimp interchange: the warp straightens while the weft crimps.
    assert!(pts[3].2 < 0.01 * pts[0].2);
    assert!(pts[3].3 > 4.0 * pts[0].3);
}

/// `weft-form --start-from`: a patch formed from a smaller formed one laid over it
/// meets the same checks as one formed from the generated geometry (string statics:
/// the tension at the ends, the crimp of straight runs between the crossings).
#[test]
fn a_patch_formed_from_a_smaller_formed_one_meets_the_same_checks() {
    use weft::form::{tile_start, Start};
    let p = Params::default();
    let small = patch(4);
    let (fs, rs) = formed(&small, &p);
    let big = patch(8);
    let quads = |m: &Model| m.elements[&weft::model::ElementKind::Quad].len() as f64;
    let u = tile_start(&big, &fs, "4 × 4").unwrap();
    let start = Start {
        u,
        work: rs.forming_work * quads(&big) / quads(&small),
        cell: None,
    };
    let (fb, rb) = form_from(&big, &p, Some(&start), &mut |_| {}).unwrap();
    println!(
        "8×8 from the formed 4×4: {} steps (the 4×4: {}); ends {:.4} / {:.4} N; crimp {:.3} % / {:.3} % (string {:.3} %); at rest moved {:.2e} m",
        rb.steps,
        rs.steps,
        rb.warp_end_tension,
        rb.weft_end_tension,
        100.0 * rb.crimp_warp_after,
        100.0 * rb.crimp_weft_after,
        100.0 * rb.crimp_target,
        rb.creep
    );
    assert_eq!(rb.start_work, start.work);
    for t in [rb.warp_end_tension, rb.weft_end_tension] {
        assert!((t - p.warp_tension).abs() < 0.01 * p.warp_tension, "{t}");
    }
    for c in [rb.crimp_warp_after, rb.crimp_weft_after] {
        assert!((c - rb.crimp_target).abs() < 0.05 * rb.crimp_target, "{c}");
    }
    assert_eq!(fb.coords, big.coords);
    // What cannot be laid over: sizes that differ by an odd number of yarns (the weave
    // would be out of phase at the ends), an unformed start, another spacing.
    let e = tile_start(&patch(7), &fs, "4 × 4").unwrap_err().to_string();
    assert!(
        e.contains("even number of yarns") && e.contains("4 × 4"),
        "{e}"
    );
    let e = tile_start(&big, &small, "raw").unwrap_err().to_string();
    assert!(e.contains("not formed"), "{e}");
    let other = woven(&WovenBandParams {
        yarns: 8,
        spacing: 1.1e-3,
        ..WovenBandParams::default()
    })
    .unwrap()
    .0;
    let e = tile_start(&other, &fs, "4 × 4").unwrap_err().to_string();
    assert!(e.contains("spacing"), "{e}");
}

#[test]
fn forming_that_does_not_converge_is_an_error_and_writes_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let model = dir.path().join("patch");
    weft::model::io::write_model(
        &patch(4),
        &model,
        &weft::table::Provenance::new("test", serde_json::json!({})),
    )
    .unwrap();
    let out = dir.path().join("formed");
    let e = run(
        &Config {
            model: model.clone(),
            out: out.clone(),
            params: Params {
                max_steps: 50,
                min_steps: 10,
                check_every: 10,
                ..Params::default()
            },
            start_from: None,
            start: StartMode::Cell,
        },
        &mut |_| {},
    )
    .unwrap_err()
    .to_string();
    assert!(e.contains("did not reach equilibrium in 50 steps"), "{e}");
    assert!(e.contains("--max-steps"), "{e}");
    assert!(!out.exists(), "a failed forming wrote {}", out.display());
    // A yarn pressed through another: the limit on the deepest contact after forming.
    let e = run(
        &Config {
            model,
            out: out.clone(),
            params: Params {
                penetration_limit: 1e-9,
                ..Params::default()
            },
            start_from: None,
            start: StartMode::Cell,
        },
        &mut |_| {},
    )
    .unwrap_err()
    .to_string();
    assert!(
        e.contains("after forming, node `") && e.contains("inside the surface of quad `"),
        "{e}"
    );
    assert!(!out.exists());
    // Bad parameters and models that cannot be formed.
    let m = patch(4);
    for (p, want) in [
        (
            Params {
                warp_tension: -1.0,
                ..Params::default()
            },
            "--warp-tension",
        ),
        (
            Params {
                damping: 1.5,
                ..Params::default()
            },
            "--damping",
        ),
    ] {
        let e = form(&m, &p, &mut |_| {}).unwrap_err().to_string();
        assert!(e.contains(want), "{e}");
    }
    let free = woven(&WovenBandParams {
        yarns: 4,
        edge: weft::generate::woven::Edge::Free,
        ..WovenBandParams::default()
    })
    .unwrap()
    .0;
    let e = form(&free, &Params::default(), &mut |_| {})
        .unwrap_err()
        .to_string();
    assert!(e.contains("no yarn end is held"), "{e}");
}

#[test]
fn the_stages_chain_generate_form_and_draw_the_weave() {
    use std::process::Command;
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let go = |bin: &str, args: &[&str]| {
        let o = Command::new(bin).args(args).output().unwrap();
        let e = String::from_utf8_lossy(&o.stderr).to_string();
        assert!(!e.contains("panicked"), "{e}");
        (o.status.success(), e)
    };
    let s = |p: &std::path::Path| p.to_string_lossy().to_string();
    let (patch, formed) = (d.join("patch"), d.join("formed"));
    let (ok, e) = go(
        env!("CARGO_BIN_EXE_weft-weave"),
        &["woven", "--yarns", "4", "--out", &s(&patch)],
    );
    assert!(ok, "{e}");
    let (ok, e) = go(
        env!("CARGO_BIN_EXE_weft-form"),
        &["--model", &s(&patch), "--out", &s(&formed), "--quiet"],
    );
    assert!(ok && e.contains("equilibrium after"), "{e}");
    // form.parquet: one row, the tension at the ends as asked.
    let t = weft::table::Table::read(&formed.join("form.parquet")).unwrap();
    let end = t.f64("warp_end_tension", "").unwrap();
    assert!((end[0] - 0.5).abs() < 0.005, "{end:?}");
    let (ok, e) = go(
        env!("CARGO_BIN_EXE_weft-plot"),
        &[
            "weave",
            "--model",
            &s(&formed),
            "--out",
            &s(&d.join("w.svg")),
        ],
    );
    assert!(ok && d.join("w.svg").exists(), "{e}");
    // A part that is not there, a section that misses the yarns: named, nothing drawn.
    let (ok, e) = go(
        env!("CARGO_BIN_EXE_weft-plot"),
        &[
            "weave",
            "--model",
            &s(&formed),
            "--along-part",
            "warp_9",
            "--out",
            &s(&d.join("x.svg")),
        ],
    );
    assert!(
        !ok && e.contains("no part `warp_9`") && e.contains("parts.parquet"),
        "{e}"
    );
    let (ok, e) = go(
        env!("CARGO_BIN_EXE_weft-plot"),
        &[
            "weave",
            "--model",
            &s(&formed),
            "--y",
            "0.0003",
            "--out",
            &s(&d.join("x.svg")),
        ],
    );
    assert!(!ok && e.contains("has no node on y = 0.0003"), "{e}");
    assert!(!d.join("x.svg").exists());
}

#[test]
fn bad_initial_displacement_columns_are_named() {
    use weft::table::{batch, write_table, Col, Provenance};
    let dir = tempfile::tempdir().unwrap();
    let model = dir.path().join("m");
    let prov = Provenance::new("test", serde_json::json!({}));
    let m = patch(4);
    weft::model::io::write_model(&m, &model, &prov).unwrap();
    let nodes = |extra: Vec<Col>| {
        let mut cols = vec![
            Col::I64("node_id", m.node_id.clone()),
            Col::F64("x", m.coords.iter().map(|c| c[0]).collect()),
            Col::F64("y", m.coords.iter().map(|c| c[1]).collect()),
            Col::F64("z", m.coords.iter().map(|c| c[2]).collect()),
        ];
        cols.extend(extra);
        write_table(&model.join("nodes.parquet"), &batch(cols), &prov).unwrap();
        weft::model::io::read_model(&model)
            .err()
            .map(|e| e.to_string())
            .unwrap_or_default()
    };
    let nn = m.num_nodes();
    // Only one of the three columns.
    let e = nodes(vec![Col::F64("ux0", vec![0.0; nn])]);
    assert!(
        e.contains("1 of the initial displacement columns") && e.contains("nodes.parquet"),
        "{e}"
    );
    // A non-finite value.
    let mut bad = vec![0.0; nn];
    bad[7] = f64::NAN;
    let e = nodes(vec![
        Col::F64("ux0", vec![0.0; nn]),
        Col::F64("uy0", bad),
        Col::F64("uz0", vec![0.0; nn]),
    ]);
    // The table reader names the column, the row and the file.
    assert!(
        e.contains("`uy0`") && e.contains("row 7") && e.contains("nodes.parquet"),
        "{e}"
    );
    // A formed model cannot be formed again.
    let e = nodes(vec![
        Col::F64("ux0", vec![0.0; nn]),
        Col::F64("uy0", vec![0.0; nn]),
        Col::F64("uz0", vec![1e-9; nn]),
    ]);
    assert!(e.is_empty(), "{e}");
    let formed = weft::model::io::read_model(&model).unwrap();
    let e = form(&formed, &Params::default(), &mut |_| {})
        .unwrap_err()
        .to_string();
    assert!(e.contains("already formed"), "{e}");
}

/// `Solver::relax` alone, on the statics forming relies on: a string of trusses fixed at
/// one end, pulled along its axis at the other by T₀ (free to slide), loaded by P across
/// at its middle. Equilibrium of the string: the horizontal force is T₀ all along, each
/// half carries P/2 across and is straight, so the middle sits at δ = x_c P/(2T₀) below
/// the axis, x_c its distance from the fixed end, whatever the yarn's E·A (statics of a
/// string; Irvine, *Cable Structures*, §1).
#[test]
fn relaxation_finds_the_statics_of_a_pulled_string() {
    use weft::model::{ElementKind, Load, PartProps, TimeLaw};
    use weft::solver::relax::RelaxOptions;
    use weft::solver::Solver;
    let (n, l, t0, p) = (20usize, 10e-3, 0.5, 0.05);
    let mut m = Model::default();
    for i in 0..=n {
        m.add_node(i as i64 + 1, [i as f64 * l / n as f64, 0.0, 0.0]);
    }
    let rod = m.add_part(
        1,
        "yarn",
        ElementKind::Truss,
        PartProps {
            youngs_modulus: Some(80e9),
            density: Some(1440.0),
            area: Some(6.6e-8),
            ..Default::default()
        },
    );
    for i in 0..n {
        m.add_element(i as i64 + 1, rod, &[i, i + 1]);
    }
    m.constraints.push((0, [true; 3]));
    m.constraints.push((n, [false, true, true]));
    for i in 1..n {
        m.constraints.push((i, [false, true, false]));
    }
    let step = TimeLaw::Step { start: 0.0 };
    m.loads.push(Load {
        id: 1,
        node: n,
        force: [t0, 0.0, 0.0],
        law: step.clone(),
    });
    m.loads.push(Load {
        id: 2,
        node: n / 2,
        force: [0.0, 0.0, -p],
        law: step,
    });
    let mut s = Solver::new(&m).unwrap();
    let st = s
        .relax(
            &RelaxOptions {
                max_steps: 2_000_000,
                min_steps: 1000,
                check_every: 100,
                alpha: 0.5,
                kinetic_tolerance: 1e-12,
                force_tolerance: 1e-8,
                force_scale: t0,
                creep_window: 1000,
                creep_tolerance: 1e-12,
                work_offset: 0.0,
                contact_damping: 0.0,
                hold_in_rest_test: vec![],
                probe_first: false,
            },
            &mut |_| {},
        )
        .unwrap();
    let c = s.state().x[n / 2];
    let expect = c[0] * p / (2.0 * t0);
    let err = (-c[2] - expect).abs() / expect;
    println!(
        "pulled string: {} steps, residual {:.2e} N; δ = {:.6e} m against x_c P/(2T₀) = {expect:.6e} m ({err:.1e})",
        st.steps, st.residual, -c[2]
    );
    assert!(st.converged);
    // Measured 1.6e-9: what the stop allows (the residual 1.5e-10 N against P = 0.05 N,
    // 3e-9); tolerance 5e-9, 3×.
    assert!(err < 5e-9, "{err}");
}

/// The §3 combined model formed the same way as the reference patch: the 4 × 4 quarter
/// tied into a membrane out to 8 mm. The patch is formed with its ends pulled (as a
/// patch alone), then the ties and the membrane's pre-stress come back and the whole
/// model settles. Oracles: the yarns' tension, taken in the test from the forces their
/// tied ends exert (Irvine's string statics: the yarn's tension is the pull at its end),
/// is the requested T; the membrane's pre-stress S₀ is what a clamped 1-D bar (ν = 0)
/// whose edge moved out by ū needs to pull with that tension, N/s + E ū/(L − c), hence
/// above N/s; left alone 50 µs, the model stays (the issue's < 1 % of the yarn
/// thickness) with the energy balanced. (The bands' 1 % and K ≤ 10⁻⁶ W are forming's own
/// stop: it errors otherwise.)
#[test]
fn a_patch_tied_into_a_membrane_is_formed_with_the_requested_tension() {
    use weft::generate::woven::Surround;
    let m = woven(&WovenBandParams {
        yarns: 4,
        surround: Some(Surround::paper(8e-3)),
        ..WovenBandParams::default()
    })
    .unwrap()
    .0;
    let p = Params::default();
    let (f, r) = formed_by_cell(&m, &p);
    println!(
        "4×4 quarter in an 8 mm membrane formed at T = {} N: {} steps, K/W {:.2e}, residual {:.2} % of the contact forces; bands {:.4} / {:.4} N, ends {:.4} / {:.4} N; crimp {:.3} / {:.3} %",
        p.warp_tension,
        r.steps,
        r.kinetic_over_work,
        100.0 * r.max_residual_force / r.max_contact_force,
        r.warp_tension,
        r.weft_tension,
        r.warp_end_tension,
        r.weft_end_tension,
        100.0 * r.crimp_warp_after,
        100.0 * r.crimp_weft_after
    );
    assert!(r.kinetic_over_work <= 1e-6);
    // Measured: bands 0.5008 / 0.4995 N (the correction stops at 0.3 %), ends 0.4991 /
    // 0.4989 N; 44 985 steps, K/W 4.2e-7.
    for t in [r.warp_tension, r.weft_tension] {
        assert!(
            (t - p.warp_tension).abs() < 0.01 * p.warp_tension,
            "band tension {t}"
        );
    }
    // The membrane's pre-stress, uniform (measured 1.2757e7 / 1.2759e7 Pa against N₀/s =
    // 3.76e6 Pa: its edge moved out ~1.7 µm as the band ends followed its ripple).
    let q = &f.elements[&weft::model::ElementKind::Quad];
    let s = f
        .parts
        .iter()
        .find(|pt| pt.name == "coarse_membrane")
        .and_then(|pt| pt.props.thickness)
        .unwrap();
    let closed = p.warp_tension / (1e-3 * s);
    let mem: Vec<[f64; 3]> = (0..q.len())
        .filter(|&e| f.parts[q.part[e]].name == "coarse_membrane")
        .map(|e| q.stress0[e])
        .collect();
    assert!(!mem.is_empty());
    println!(
        "membrane S₀ {:.4e} / {:.4e} Pa against N₀/s = {closed:.4e} Pa",
        mem[0][0], mem[0][1]
    );
    for s0 in &mem {
        assert!(s0 == &mem[0] && s0[2] == 0.0, "{s0:?}");
    }
    // The tension from the reactions (not the bands' stress, on which forming corrects
    // S₀): at the formed state, −Σ f_int·ê over a yarn's tied end nodes is the pull the
    // tie takes from it, which a string carries all along (Irvine §1). Per yarn j (at
    // y = j·p; the one on the symmetry plane y = 0 is half a yarn), and per unit length of
    // the tied edge x = c (y = c for the weft), N = Σ_j T_j / c.
    let pitch = WovenBandParams::default().spacing;
    let c = 3.5 * pitch;
    let mpart = f
        .parts
        .iter()
        .position(|pt| pt.name == "coarse_membrane")
        .unwrap();
    let props = &f.parts[mpart].props;
    let e_m = props.youngs_modulus_1.unwrap();
    // The membrane is a set of independent strips (ν₁₂ = 0, G₁₂ = 0.0042 E): 1-D bars.
    assert_eq!(props.poisson_ratio_12, Some(0.0));
    assert!(props.shear_modulus_12.unwrap() < 0.01 * e_m);
    let mut on_membrane = vec![false; f.num_nodes()];
    for e in (0..q.len()).filter(|&e| q.part[e] == mpart) {
        for &n in &q.nodes[4 * e..4 * e + 4] {
            on_membrane[n] = true;
        }
    }
    let outer = f.coords.iter().map(|x| x[0]).fold(0.0, f64::max);
    let fi = weft::solver::Solver::new(&f).unwrap().internal_forces();
    let u0 = &f.initial_displacement;
    for d in 0..2 {
        let mut t = [0.0f64; 4];
        for tie in &f.ties {
            let x = f.coords[tie.slave];
            if (x[d] - c).abs() < 1e-9 * c {
                t[(x[1 - d] / pitch).round() as usize] -= fi[tie.slave][d];
            }
        }
        let share = [0.5, 1.0, 1.0, 1.0];
        let mean = t.iter().sum::<f64>() / share.iter().sum::<f64>();
        let spread = (0..4)
            .map(|j| (t[j] / (share[j] * p.warp_tension) - 1.0).abs())
            .fold(0.0, f64::max);
        // The 1-D bar from the tied edge x = c to the clamped x = L (the membrane's
        // outer edge), pre-stressed by S₀, its edge moved out by ū (the mean of u₀ along
        // the edge): S = S₀ − E ū/(L − c), which must carry N: S₀ = N/s + E ū/(L − c).
        let mut edge: Vec<usize> = (0..f.num_nodes())
            .filter(|&n| {
                on_membrane[n]
                    && (f.coords[n][d] - c).abs() < 1e-9 * c
                    && f.coords[n][1 - d] <= c * (1.0 + 1e-9)
            })
            .collect();
        edge.sort_by(|&a, &b| f.coords[a][1 - d].total_cmp(&f.coords[b][1 - d]));
        let (mut ws, mut us) = (0.0, 0.0);
        for k in 1..edge.len() {
            let (a, b) = (edge[k - 1], edge[k]);
            let w = f.coords[b][1 - d] - f.coords[a][1 - d];
            us += 0.5 * w * (u0[a][d] + u0[b][d]);
            ws += w;
        }
        let ubar = us / ws;
        let n_edge = t.iter().sum::<f64>() / c;
        let bar = n_edge / s + e_m * ubar / (outer - c);
        let s0 = mem[0][d];
        println!(
            "{}: from the ties' reactions T_j {:.4} (half) / {:.4} / {:.4} / {:.4} N, mean per yarn {mean:.5} N ({:+.2e}), largest departure {spread:.3e}; edge moved out ū = {ubar:.4e} m; S₀ {s0:.5e} Pa against N/s = {:.5e} Pa and the bar's N/s + E ū/(L − c) = {bar:.5e} Pa ({:+.2e})",
            ["warp", "weft"][d],
            t[0],
            t[1],
            t[2],
            t[3],
            mean / p.warp_tension - 1.0,
            n_edge / s,
            s0 / bar - 1.0
        );
        // Measured −7.1e-3 (both families): the reactions include the hourglass forces
        // and the lenticular contact's component along the yarn, the bands' stress not;
        // tolerance 2e-2, 2.8×.
        assert!(
            (mean / p.warp_tension - 1.0).abs() < 2e-2,
            "mean tension {mean} from the reactions"
        );
        // Per yarn: the ends follow the membrane edge's ripple; measured 6.2e-2 (the
        // first full yarn), tolerance 0.15, 2.4×.
        assert!(spread < 0.15, "tensions {t:?}");
        // S₀ on both sides: at least N/s (the edge moved out, ū > 0, relieves the
        // membrane), and the bar's value: measured +1.18e-2 (the shear coupling of the
        // strips and the ripple's stretch), tolerance 4e-2, 3.4×.
        assert!(
            ubar > 0.0 && s0 > n_edge / s,
            "S₀ {s0} against N/s {}",
            n_edge / s
        );
        assert!((s0 / bar - 1.0).abs() < 4e-2, "S₀ {s0} against {bar}");
    }
    // Left alone: the ties keep the formed ends' offsets, nothing jumps.
    let mut g = f.clone();
    g.projectiles.clear();
    g.analysis.end_time = 50e-6;
    g.analysis.output_interval = 5e-6;
    let (_, out, stats) = run_in_memory(&g).unwrap();
    let moved = out
        .u
        .iter()
        .flat_map(|sample| sample.iter())
        .map(|u| (u[0] * u[0] + u[1] * u[1] + u[2] * u[2]).sqrt())
        .fold(0.0, f64::max);
    let h = WovenBandParams::default().thickness;
    println!(
        "at rest 50 µs: moved {moved:.3e} m = {:.3} % of h; energy balance {:.2e}",
        100.0 * moved / h,
        stats.max_balance_error_relative
    );
    // The issue asks < 1 % of h; measured 2.47e-7 m = 0.199 % of h, tolerance 6e-3 h =
    // 7.4e-7 m, 3×; energy balance measured 4.93e-4, tolerance 1.5e-3, 3×.
    assert!(moved < 6e-3 * h, "moved {moved} m");
    assert!(
        stats.max_balance_error_relative < 1.5e-3,
        "energy balance {}",
        stats.max_balance_error_relative
    );
}

/// The periodic cell of the default weave (four half yarns between neighbouring
/// crossings, symmetry planes on its four sides), formed alone at T = 0.5 N per yarn.
///
/// ```text
///   y = p ┌──────────────┐   warp 1 (lower half) along y = p, weft 1 (lower half)
///         │ ╲          ╱ │   along x = p; warp 0 and weft 0 (upper halves) along the
///         │   quarter    │   fixed planes y = 0 and x = 0; the planes x = p, y = p
///         │   crossings  │   moved by δ until the force across them is T
///   y = 0 └──────────────┘
///        x = 0         x = p
/// ```
///
/// Oracles: Newton's Σ F = 0 over the cell — the reactions of the fixed planes balance
/// the force across the moved ones; symmetry — the relaxed state is invariant under the
/// two-fold rotation about the mid-span axis (x = p/2 + δ_x/2, z = 0) along y, and
/// likewise about (y = p/2 + δ_y/2, z = 0) along x (each maps the cell's yarns onto
/// themselves or each other), so the node held in z on that axis needs no force; neither
/// is imposed by the relaxation, which only moves the planes.
#[test]
fn the_periodic_cell_balances_its_planes_and_keeps_its_two_fold_symmetry() {
    let m = patch(4);
    let p = Params::default();
    let c = cell::extract(&m, 1e-3).unwrap();
    // 4 half bands × 5 nodes along × 2 across, 4 quads each.
    assert_eq!(c.model.num_nodes(), 40);
    assert_eq!(c.model.elements[&weft::model::ElementKind::Quad].len(), 16);
    let f = cell::form(&c, &p, 1e-3, &mut |_| {}).unwrap();
    println!(
        "cell: {} relaxations, {} steps; planes moved {:.4e} / {:.4e} m; force across the moved planes {:.5} / {:.5} N, the fixed {:.5} / {:.5} N; z force on the axis {:.2e} N",
        f.rounds, f.steps, f.stretch[0], f.stretch[1], f.tension[0], f.tension[1],
        f.fixed_tension[0], f.fixed_tension[1], f.axis_reaction
    );
    for d in 0..2 {
        // The stop: the tension to 1e-3.
        assert!((f.tension[d] / 0.5 - 1.0).abs() <= 1e-3, "{:?}", f.tension);
        let balance = (f.fixed_tension[d] / f.tension[d] - 1.0).abs();
        println!(
            "Σ F across the planes {}: {balance:.2e} of the tension",
            ["x", "y"][d]
        );
        // Balance: the relaxation's residual; measured 3.4e-8 / 2.6e-7 (x / y) of the
        // tension; tolerance 1e-6, 3.8×.
        assert!(balance < 1e-6, "{:?} {:?}", f.fixed_tension, f.tension);
        // The planes moved by the de-crimping and the stretch: positive, a few µm.
        assert!(f.stretch[d] > 0.0 && f.stretch[d] < 1e-5, "{:?}", f.stretch);
    }
    // Measured 7.62e-9 N against contact forces of 0.04 N at the quarter crossings (the
    // relaxation's residual); tolerance 3e-8 N, 3.9×.
    assert!(f.axis_reaction < 3e-8, "{}", f.axis_reaction);
    // The two-fold rotations: node at (x, y, z) ↔ partner at (p − x, y, −z) with
    // u' = (δ_x − u_x, u_y, −u_z), and (x, y, z) ↔ (x, p − y, −z) with
    // u' = (u_x, δ_y − u_y, −u_z).
    let cm = &c.model;
    let find = |x: [f64; 3]| {
        (0..cm.num_nodes())
            .find(|&n| (0..3).all(|d| (cm.coords[n][d] - x[d]).abs() < 1e-9))
            .unwrap_or_else(|| panic!("no partner at {x:?}"))
    };
    let amp = cm.coords.iter().map(|x| x[2].abs()).fold(0.0, f64::max);
    let mut worst = 0.0f64;
    for n in 0..cm.num_nodes() {
        let (x, u) = (cm.coords[n], f.u[n]);
        for (d, other) in [(0usize, 1usize), (1, 0)] {
            let mut xp = x;
            xp[d] = 1e-3 - x[d];
            xp[2] = -x[2];
            let k = find(xp);
            let mut want = [0.0; 3];
            want[d] = f.stretch[d] - u[d];
            want[other] = u[other];
            want[2] = -u[2];
            for j in 0..3 {
                worst = worst.max((f.u[k][j] - want[j]).abs());
            }
        }
    }
    println!("two-fold symmetry: largest departure {worst:.2e} m (crimp amplitude {amp:.3e} m)");
    // Measured 1.42e-10 m = 1.7e-6 of the amplitude (8.31e-5 m): the relaxation's
    // residual; tolerance 5e-6 of the amplitude, 2.9×.
    assert!(worst < 5e-6 * amp, "{worst}");
}

/// What the periodic cell cannot form, named: a weave without tension (the planes are
/// moved until the yarns carry it) and a patch too small to hold a cell.
#[test]
fn the_periodic_cell_refuses_what_it_cannot_form() {
    let p = Params {
        warp_tension: 0.0,
        ..Params::default()
    };
    let e = cell_start(&patch(4), &p, &mut |_| {})
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("tensions > 0") && e.contains("--start geometry"),
        "{e}"
    );
    let e = cell_start(&patch(1), &Params::default(), &mut |_| {})
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("periodic cell") && e.contains("--start geometry"),
        "{e}"
    );
}

/// A full patch (`--full`, no yarn on x = 0) formed from its periodic cell, whose planes
/// lie on its yarns' centre lines (j + ½)p: the same checks, and its centre stays put —
/// the formed state is symmetric under the patch's two-fold rotation about the z axis
/// (x, y) → (−x, −y), which maps the weave onto itself (u_x(−x, −y) = −u_x(x, y), u_z
/// equal).
#[test]
fn a_full_patch_formed_from_its_cell_keeps_its_centre() {
    let m = woven(&WovenBandParams {
        yarns: 6,
        quarter: false,
        ..WovenBandParams::default()
    })
    .unwrap()
    .0;
    let p = Params::default();
    let (f, r) = formed_by_cell(&m, &p);
    println!(
        "full 6 × 6 from the cell: ends {:.4} / {:.4} N, crimp {:.3} / {:.3} % (string {:.3} %), amplitude {:.4e} / {:.4e} m, at rest moved {:.2e} m",
        r.warp_end_tension, r.weft_end_tension, 100.0 * r.crimp_warp_after,
        100.0 * r.crimp_weft_after, 100.0 * r.crimp_target, r.amplitude_warp_after, r.amplitude_weft_after, r.creep
    );
    for t in [r.warp_end_tension, r.weft_end_tension] {
        assert!((t - p.warp_tension).abs() < 0.01 * p.warp_tension, "{t}");
    }
    for c in [r.crimp_warp_after, r.crimp_weft_after] {
        assert!((c - r.crimp_target).abs() < 0.05 * r.crimp_target, "{c}");
    }
    assert!(r.amplitude_warp_after.is_finite() && r.amplitude_weft_after.is_finite());
    let u = &f.initial_displacement;
    let mut worst = 0.0f64;
    let b = &m.elements[&weft::model::ElementKind::Quad];
    let part_of = |n: usize| {
        (0..b.len())
            .find(|&e| b.nodes[4 * e..4 * e + 4].contains(&n))
            .map(|e| b.part[e])
    };
    for n in 0..m.num_nodes() {
        let c = m.coords[n];
        let k = (0..m.num_nodes())
            .find(|&k| {
                (m.coords[k][0] + c[0]).abs() < 1e-12
                    && (m.coords[k][1] + c[1]).abs() < 1e-12
                    && (m.coords[k][2] - c[2]).abs() < 1e-12
                    && part_of(k) == part_of(n)
            })
            .unwrap_or_else(|| panic!("no partner of node {n} at {c:?}"));
        worst = worst
            .max((u[k][0] + u[n][0]).abs())
            .max((u[k][1] + u[n][1]).abs())
            .max((u[k][2] - u[n][2]).abs());
    }
    println!("two-fold symmetry about the centre: largest departure {worst:.2e} m");
    // The tiling is exact up to the cell's own symmetry (1.4e-10 m, above) and the
    // patch's relaxation: measured 4.66e-10 m; tolerance 2e-9 m, 4.3×.
    assert!(worst < 2e-9, "{worst}");
}
