//! The projectile objective of the fit stage (`weft-fit --objective projectile`,
//! `--projectile-weight`): P of synthetic series against hand computations (the
//! interpolation and the hold after a run's end included), a planted failure strain of a
//! woven chain patch recovered from the projectile's velocity history, a deformable
//! bullet's velocity as its momentum over its mass, and clear errors for bad input.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use weft::fit::projectile::{at_times, mismatch, read_reference, VelocityHistory};
use weft::fit::respond_with_projectile;
use weft::model::io::read_model;
use weft::table::{batch, write_table, Col, Provenance, Table};

fn history(t: &[f64], v: &[f64]) -> VelocityHistory {
    VelocityHistory {
        t: t.to_vec(),
        v: v.to_vec(),
        striking_speed: v[0],
        source: None,
    }
}

/// P = Σ(v_c − v_r)²/Σ(v_c² + v_r²) over the reference's times, by hand (integers and
/// halves: every operation exact, so the comparison is exact).
#[test]
fn p_of_synthetic_series_is_the_hand_computed_value() {
    let r = history(&[0.0, 1.0, 2.0, 3.0, 4.0], &[100.0, 96.0, 90.0, 88.0, 88.0]);
    // The candidate sampled twice as often, its run ended at its outcome at t = 2.5: its
    // last velocity, 91, holds at t = 3 and 4. At the reference's times: 100, 98, 92, 91,
    // 91; differences 0, 2, 2, 3, 3: Σ = 26; Σ squares 20000 + (98² + 96²) + (92² + 90²)
    // + 2 (91² + 88²) = 20000 + 18820 + 16564 + 32050 = 87434.
    let c = history(
        &[0.0, 0.5, 1.0, 1.5, 2.0, 2.5],
        &[100.0, 99.0, 98.0, 94.0, 92.0, 91.0],
    );
    assert_eq!(at_times(&c, &r.t), vec![100.0, 98.0, 92.0, 91.0, 91.0]);
    assert_eq!(mismatch(&r, &c), 26.0 / 87434.0);
    // Samples between the reference's times: at t = 1, halfway from 99 (t = 0.5) to 95
    // (t = 1.5): 97; at t = 2, halfway from 95 to 91: 93; then 91 held. Differences 0, 1,
    // 3, 3, 3: Σ = 28; Σ squares 20000 + (97² + 96²) + (93² + 90²) + 32050 = 87424.
    let c = history(&[0.0, 0.5, 1.5, 2.5], &[100.0, 99.0, 95.0, 91.0]);
    assert_eq!(at_times(&c, &r.t), vec![100.0, 97.0, 93.0, 91.0, 91.0]);
    assert_eq!(mismatch(&r, &c), 28.0 / 87424.0);
    // Equal histories: 0; a candidate at rest from the start against one in flight: 1.
    assert_eq!(mismatch(&r, &r), 0.0);
    let rest = history(&[0.0, 4.0], &[0.0, 0.0]);
    assert_eq!(mismatch(&r, &rest), 1.0);
}

/// Writes a result `projectile.parquet` of rows (t, id, v).
fn write_projectile_table(path: &Path, rows: &[(f64, i64, [f64; 3])]) {
    let c = |k: usize| rows.iter().map(|r| r.2[k]).collect::<Vec<_>>();
    let zeros = vec![0.0; rows.len()];
    let b = batch(vec![
        Col::F64("t", rows.iter().map(|r| r.0).collect()),
        Col::I64("projectile_id", rows.iter().map(|r| r.1).collect()),
        Col::F64("x", zeros.clone()),
        Col::F64("y", zeros.clone()),
        Col::F64("z", zeros.clone()),
        Col::F64("vx", c(0)),
        Col::F64("vy", c(1)),
        Col::F64("vz", c(2)),
        Col::F64("fx", zeros.clone()),
        Col::F64("fy", zeros.clone()),
        Col::F64("fz", zeros),
    ]);
    write_table(path, &b, &Provenance::new("test", serde_json::json!({}))).unwrap();
}

/// The reference is the first projectile's (the first row's id) velocity along its
/// direction at t = 0, positive into the target; the other projectile's rows and the
/// lateral components do not count.
#[test]
fn the_reference_is_the_first_projectiles_velocity_along_its_flight() {
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("projectile.parquet");
    write_projectile_table(
        &p,
        &[
            (0.0, 7, [0.0, 0.0, -100.0]),
            (0.0, 3, [5.0, 0.0, -300.0]),
            (1e-6, 7, [2.0, -1.0, -96.0]),
            (1e-6, 3, [5.0, 0.0, -290.0]),
            (2e-6, 7, [3.0, 1.0, -90.0]),
            (2e-6, 3, [5.0, 0.0, -280.0]),
        ],
    );
    let r = read_reference(&p).unwrap();
    assert_eq!(r.t, vec![0.0, 1e-6, 2e-6]);
    assert_eq!(r.v, vec![100.0, 96.0, 90.0]);
    assert_eq!(r.striking_speed, 100.0);
    // Out of order, or not starting at t = 0: refused, naming the file, column and row.
    write_projectile_table(
        &p,
        &[(0.0, 7, [0.0, 0.0, -100.0]), (0.0, 7, [0.0, 0.0, -99.0])],
    );
    let e = read_reference(&p).unwrap_err().to_string();
    assert!(
        e.contains("`t`") && e.contains("row 1") && e.contains("increasing"),
        "{e}"
    );
    write_projectile_table(&p, &[(1e-6, 7, [0.0, 0.0, -100.0])]);
    let e = read_reference(&p).unwrap_err().to_string();
    assert!(e.contains("t = 0"), "{e}");
    write_projectile_table(&p, &[(0.0, 7, [0.0, 0.0, 0.0])]);
    let e = read_reference(&p).unwrap_err().to_string();
    assert!(e.contains("at rest"), "{e}");
}

/// The woven chain patch of the planted-failure-strain tests: 4 yarns a side (quarter),
/// a light 4 mm projectile (0.2 g for the quarter) that the fabric slows by 11 % at
/// 100 m/s before it perforates (measured: residual 89.25 m/s at ε_f = 0.03, 71.7 m/s
/// at 0.045), ending at the outcome. About 0.03 s a run.
const WOVEN: [&str; 10] = [
    "woven",
    "--yarns",
    "4",
    "--yarn-model",
    "chain",
    "--projectile-radius",
    "0.002",
    "--projectile-mass",
    "0.0002",
    "--stop-on-outcome",
];

fn run(exe: &str, args: &[&str]) -> Output {
    Command::new(exe).args(args).output().unwrap()
}

fn ok(o: Output) -> String {
    let e = String::from_utf8_lossy(&o.stderr).to_string();
    assert!(o.status.success(), "{e}");
    e
}

fn s(p: &Path) -> String {
    p.to_string_lossy().to_string()
}

/// Weaves the patch at failure strain `eps` and striking speed `v` into `out`.
fn weave(out: &Path, eps: f64, v: f64, extra: &[&str]) {
    let (eps, v) = (eps.to_string(), v.to_string());
    let mut args: Vec<&str> = WOVEN.to_vec();
    args.extend([
        "--failure-strain",
        &eps,
        "--projectile-velocity",
        &v,
        "--out",
    ]);
    let o = s(out);
    args.push(&o);
    args.extend(extra);
    ok(run(env!("CARGO_BIN_EXE_weft-weave"), &args));
}

/// Simulates `model` into `out`: its summary line.
fn simulate(model: &Path, out: &Path) -> String {
    ok(run(
        env!("CARGO_BIN_EXE_weft-simulate"),
        &["--quiet", "--model", &s(model), "--out", &s(out)],
    ))
}

/// A fit of `cases` (reference folder, reference run, candidate folder) with `extra`.
fn fit(cases: &[(&Path, &Path, &Path)], out: &Path, extra: &[&str]) -> Output {
    let mut args: Vec<String> = vec![];
    for (rm, ro, c) in cases {
        args.extend([
            "--reference-model".into(),
            s(rm),
            "--reference-history".into(),
            s(&ro.join("history.parquet")),
            "--model".into(),
            s(c),
        ]);
    }
    args.extend(["--quiet".into(), "--out".into(), s(out)]);
    args.extend(extra.iter().map(|x| x.to_string()));
    let a: Vec<&str> = args.iter().map(|x| x.as_str()).collect();
    run(env!("CARGO_BIN_EXE_weft-fit"), &a)
}

/// Reference and candidate of one striking speed: (reference model, its run, candidate).
struct Impact {
    reference: PathBuf,
    run: PathBuf,
    candidate: PathBuf,
}

fn impact(d: &Path, v: f64, eps_ref: f64, eps_cand: f64) -> Impact {
    let i = Impact {
        reference: d.join(format!("ref{v}")),
        run: d.join(format!("ref{v}-out")),
        candidate: d.join(format!("cand{v}")),
    };
    weave(&i.reference, eps_ref, v, &[]);
    let line = simulate(&i.reference, &i.run);
    assert!(line.contains("perforated at"), "{line}");
    weave(&i.candidate, eps_cand, v, &[]);
    i
}

/// The reference patch fails at ε_f = 0.03; the candidate, woven at 0.045, is fitted to
/// the projectile's velocity histories at 100 and 150 m/s (both perforate) and gets
/// ε_f back.
#[test]
fn a_planted_failure_strain_is_recovered_from_the_projectiles_history() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let cases = [impact(d, 100.0, 0.03, 0.045), impact(d, 150.0, 0.03, 0.045)];
    let c: Vec<(&Path, &Path, &Path)> = cases
        .iter()
        .map(|i| {
            (
                i.reference.as_path(),
                i.run.as_path(),
                i.candidate.as_path(),
            )
        })
        .collect();
    let param = "warp_1.eps_f,weft_1.eps_f";
    let e = ok(fit(
        &c,
        &d.join("fit"),
        &[
            "--objective",
            "projectile",
            "--param",
            &format!("{param}:0.02:0.06:log"),
            "--max-evaluations",
            "20",
            "--threads",
            "1",
            "--expected",
            &format!("{param}=0.03"),
        ],
    ));
    let r = Table::read(&d.join("fit/fit_result.parquet")).unwrap();
    let v = r.f64("value", "value").unwrap()[0];
    let rel = r.f64_opt("relative_difference").unwrap().unwrap()[0].unwrap();
    // The failure strain is identified only to what the time step resolves: near the
    // planted value P is rugged (0 at 0.03 exactly, 3.1e-8 at 0.02982, 2.4e-7 at 0.02991,
    // 5.6e-8 at 0.03022: a yarn breaks a step earlier or later), and COBYLA settles in
    // one of its local minima. Measured: 0.029820 (relative −6.0e-3), P 3.1e-8, from
    // 0.045 (P 1.05e-3) in 20 evaluations; the same with 40.
    assert!(rel.abs() < 1.5e-2, "fitted ε_f {v} ({rel:+e}): {e}");
    let trace = Table::read(&d.join("fit/fit_trace.parquet")).unwrap();
    let t = trace.f64("T", "T").unwrap();
    let p = trace.f64_opt("projectile_mismatch").unwrap().unwrap();
    // Alone, the objective is P (the mean over the cases): the column repeats T.
    for (t, p) in t.iter().zip(&p) {
        if *t < 4.0 {
            assert_eq!(Some(*t), *p);
        }
    }
    // From 0.045 the histories differ (P 1.05e-3 measured, mean of the two speeds).
    assert!(t[0] > 1e-4, "P at the start {}", t[0]);
}

/// The candidate's in-process recording is weft-simulate's: at the reference's own
/// failure strain P is 0 exactly. A run that ends at its outcome holds its last velocity:
/// against the same patch run on to the end time, free flight after the perforation.
#[test]
fn a_run_that_ends_at_its_outcome_holds_its_last_velocity() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let i = impact(d, 100.0, 0.03, 0.03);
    let reference = read_reference(&i.run.join("projectile.parquet")).unwrap();
    let m = read_model(&i.candidate).unwrap();
    let (_, stopped) = respond_with_projectile(&m, &[]).unwrap();
    assert_eq!((&stopped.t, &stopped.v), (&reference.t, &reference.v));
    assert_eq!(mismatch(&reference, &stopped), 0.0);
    // Run on to the end time (60 µs), the run is the reference; the stopped one (25 µs)
    // holds its last velocity over the 35 µs after.
    let mut full = m.clone();
    full.analysis.stop_on_outcome = false;
    let (_, on) = respond_with_projectile(&full, &[]).unwrap();
    let end = *stopped.t.last().unwrap();
    assert!(end < 0.5 * on.t.last().unwrap(), "stopped at {end}");
    let p = mismatch(&on, &stopped);
    // Held: P 3.8e-9 measured (the free projectile still touches a broken yarn end now
    // and then); at rest after the end instead (no hold), P would be 0.39.
    let dropped = VelocityHistory {
        t: [stopped.t.clone(), vec![end + 1e-6, 1.0]].concat(),
        v: [stopped.v.clone(), vec![0.0, 0.0]].concat(),
        ..stopped.clone()
    };
    let p_dropped = mismatch(&on, &dropped);
    eprintln!("held: P {p:e}; dropped to rest: P {p_dropped:e}");
    assert!(
        p < 2e-8 && p_dropped > 0.2,
        "held {p:e}, dropped {p_dropped:e}"
    );
}

/// A deformable bullet's velocity is its momentum over its mass along its direction of
/// flight: constant in free flight, even when its nodes start at different speeds and
/// the bullet rings (its internal forces sum to zero: momentum is conserved).
#[test]
fn a_deformable_bullets_velocity_is_its_momentum_over_its_mass() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path().join("bullet");
    ok(run(
        env!("CARGO_BIN_EXE_weft-weave"),
        &[
            "woven",
            "--yarns",
            "4",
            "--yarn-model",
            "chain",
            "--projectile",
            "deformable",
            "--projectile-velocity",
            "400",
            "--end-time",
            "2e-6",
            "--output-interval",
            "1e-7",
            "--out",
            &s(&d),
        ],
    ));
    let mut m = read_model(&d).unwrap();
    let nodes = m.node_sets["bullet"].clone();
    // 5 mm above the fabric: free for the 0.8 mm it flies in 2 µs.
    for &i in &nodes {
        m.coords[i][2] += 5e-3;
    }
    let (_, h) = respond_with_projectile(&m, &[]).unwrap();
    eprintln!(
        "uniform: largest |v − 400| {:e} m/s",
        h.v.iter().map(|v| (v - 400.0).abs()).fold(0.0, f64::max)
    );
    assert_eq!(h.t.len(), 21);
    assert_eq!(h.striking_speed, 400.0);
    for v in &h.v {
        // Measured: |v − 400| ≤ 2.8e-13 m/s (uniform motion, no stress; round-off).
        assert!((v - 400.0).abs() < 1e-12, "{v}");
    }
    // Every other node 10 % faster: the bullet rings, each node's velocity swings, the
    // mean of its nodes' velocities (unweighted) with them; momentum/mass stays.
    for (i, v) in m.initial_velocities.iter_mut() {
        if *i % 2 == 0 {
            v[2] *= 1.1;
        }
    }
    let (series, h) = respond_with_projectile(&m, &nodes).unwrap();
    let drift = h.v.iter().map(|v| (v - h.v[0]).abs()).fold(0.0, f64::max);
    let mean = |k: usize| -> f64 {
        -series.values[k].iter().map(|q| q[5]).sum::<f64>() / nodes.len() as f64
    };
    let swing = (0..h.t.len())
        .map(|k| (mean(k) - mean(0)).abs())
        .fold(0.0, f64::max);
    eprintln!("ringing: drift {drift:e} m/s, swing of the unweighted mean {swing:e} m/s");
    // Measured: drift 4.0e-13 m/s (round-off) against a swing of the unweighted mean of
    // 0.19 m/s.
    assert!(
        drift < 2e-12 && swing > 0.05,
        "drift {drift:e}, swing {swing:e}"
    );
}

/// Weighted beside T: the objective is T + W·P, T as without the weight (the same
/// arithmetic), P in the trace; without a weight the column is null.
#[test]
fn the_projectile_weight_adds_w_times_p_to_t() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    // Run to the end time (T compares the nodes over the reference's times: a candidate
    // that stopped earlier at its outcome would not cover them).
    let (r, ro, c) = (d.join("ref"), d.join("ref-out"), d.join("cand"));
    let mut args: Vec<&str> = WOVEN[..9].to_vec();
    let (ra, ca) = (s(&r), s(&c));
    args.extend(["--failure-strain", "0.03", "--projectile-velocity", "100"]);
    ok(run(
        env!("CARGO_BIN_EXE_weft-weave"),
        &[args.clone(), vec!["--out", &ra]].concat(),
    ));
    args[10] = "0.045";
    ok(run(
        env!("CARGO_BIN_EXE_weft-weave"),
        &[args, vec!["--out", &ca]].concat(),
    ));
    simulate(&r, &ro);
    let traces: Vec<Table> = ["0", "2.5"]
        .iter()
        .map(|w| {
            let out = d.join(format!("fit{w}"));
            ok(fit(
                &[(&r, &ro, &c)],
                &out,
                &[
                    "--set",
                    "axis_x",
                    "--param",
                    "warp_1.eps_f,weft_1.eps_f:0.02:0.06",
                    "--max-evaluations",
                    "3",
                    "--projectile-weight",
                    w,
                ],
            ));
            Table::read(&out.join("fit_trace.parquet")).unwrap()
        })
        .collect();
    let t0 = traces[0].f64("T", "T").unwrap();
    let p0 = traces[0].f64_opt("projectile_mismatch").unwrap().unwrap();
    assert!(p0.iter().all(|p| p.is_none()));
    let t = traces[1].f64("T", "T").unwrap();
    let p = traces[1].f64_opt("projectile_mismatch").unwrap().unwrap();
    // The first evaluation, at the same start: T + 2.5 P exactly (measured: T 0.509,
    // P 1.01e-2).
    let p = p[0].unwrap();
    eprintln!("T {:e}, P {p:e}, T + 2.5 P {:e}", t0[0], t[0]);
    assert!(p > 1e-4, "P {p}");
    assert_eq!(t[0], t0[0] + 2.5 * p);
}

/// Bad input: clear errors naming what is wrong and what was expected.
#[test]
fn bad_projectile_input_is_refused_clearly() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let i = impact(d, 100.0, 0.03, 0.045);
    let param = ["--param", "warp_1.eps_f,weft_1.eps_f:0.02:0.06"];
    let proj = [&["--objective", "projectile"][..], &param[..]].concat();
    let refused = |o: Output, says: &[&str]| {
        let e = String::from_utf8_lossy(&o.stderr).to_string();
        assert!(!o.status.success(), "ran: {says:?}");
        assert!(!e.contains("panicked"), "{e}");
        for w in says {
            assert!(e.contains(w), "`{w}` not in: {e}");
        }
    };
    let case = [(
        i.reference.as_path(),
        i.run.as_path(),
        i.candidate.as_path(),
    )];
    let out = d.join("fit");
    // A reference run folder without projectile.parquet.
    let bare = d.join("bare");
    std::fs::create_dir_all(&bare).unwrap();
    std::fs::copy(i.run.join("history.parquet"), bare.join("history.parquet")).unwrap();
    let bare_case = [(i.reference.as_path(), bare.as_path(), i.candidate.as_path())];
    refused(
        fit(&bare_case, &out, &proj),
        &[
            "no reference projectile table",
            "bare/projectile.parquet",
            "--reference-projectile",
        ],
    );
    // ... found with --reference-projectile.
    let given = s(&i.run.join("projectile.parquet"));
    let with_given = [
        &proj[..],
        &["--reference-projectile", &given, "--max-evaluations", "2"],
    ]
    .concat();
    ok(fit(&bare_case, &out, &with_given));
    // One --reference-projectile per case, and only with a projectile objective.
    refused(
        fit(
            &case,
            &out,
            &[&with_given[..], &["--reference-projectile", &given]].concat(),
        ),
        &["2 --reference-projectile for 1 cases"],
    );
    refused(
        fit(
            &case,
            &out,
            &[&param[..], &["--reference-projectile", &given]].concat(),
        ),
        &["without a projectile objective", "--projectile-weight > 0"],
    );
    // A candidate striking at another speed.
    let fast = d.join("fast");
    weave(&fast, 0.045, 120.0, &[]);
    let fast_case = [(i.reference.as_path(), i.run.as_path(), fast.as_path())];
    refused(
        fit(&fast_case, &out, &proj),
        &[
            "case `fast`",
            "strikes at 120 m/s",
            "the reference at 100 m/s",
            "--projectile-velocity 100",
        ],
    );
    // A candidate whose run ends before the reference's does.
    let short = d.join("short");
    weave(&short, 0.045, 100.0, &["--end-time", "1e-5"]);
    let short_case = [(i.reference.as_path(), i.run.as_path(), short.as_path())];
    refused(
        fit(&short_case, &out, &proj),
        &["before the reference's last output time", "--end-time"],
    );
    // Weights: negative, NaN, or beside --objective projectile.
    // (NaN: refused by the flag's parser as not a finite number.)
    for (w, says) in [
        ("-1", ["--projectile-weight -1", "≥ 0"]),
        ("NaN", ["--projectile-weight `NaN`", "finite"]),
    ] {
        refused(
            fit(
                &case,
                &out,
                &[&param[..], &["--projectile-weight", w]].concat(),
            ),
            &says,
        );
    }
    refused(
        fit(
            &case,
            &out,
            &[&proj[..], &["--projectile-weight", "1"]].concat(),
        ),
        &["with --objective projectile"],
    );
    // A static fit has no projectile history.
    refused(
        fit(&case, &out, &[&proj[..], &["--static"]].concat()),
        &["--static"],
    );
    // A candidate without a projectile.
    let square = d.join("square");
    ok(run(
        env!("CARGO_BIN_EXE_weft-weave"),
        &["membrane", "--cells", "3", "--out", &s(&square)],
    ));
    let square_case = [(i.reference.as_path(), i.run.as_path(), square.as_path())];
    refused(
        fit(
            &square_case,
            &out,
            &[
                "--objective",
                "projectile",
                "--param",
                "membrane.G12:1e8:1e10:log",
            ],
        ),
        &["case `square`", "has no projectile"],
    );
}
