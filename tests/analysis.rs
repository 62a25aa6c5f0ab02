//! Wave speeds and the mismatch T.
//!
//! References: the rod's wave speed √(E/ρ) (Graff §2.1); the paper's eq. 2,
//! T = ∫Σ‖p − q‖² / ∫Σ(‖p‖² + ‖q‖²): 0 for p = q, 1 for orthogonal histories
//! (∫p·q dt = 0), 2 for p = −q; the trapezoidal rule on a periodic grid integrates
//! sin·cos over a period to zero exactly.

mod common;
use common::*;
use std::process::Command;
use weft::analysis::{match_nodes, mismatch, Series};

#[test]
fn wavespeed_stage_measures_the_rod_wave_speed() {
    let dir = tempfile::tempdir().unwrap();
    let (m, o) = (dir.path().join("rod"), dir.path().join("out"));
    assert!(Command::new(env!("CARGO_BIN_EXE_weft-weave"))
        .args(["rod", "--output-interval", "2e-8", "--out"])
        .arg(&m)
        .status()
        .unwrap()
        .success());
    assert!(Command::new(env!("CARGO_BIN_EXE_weft-simulate"))
        .arg("--model")
        .arg(&m)
        .arg("--out")
        .arg(&o)
        .arg("-q")
        .status()
        .unwrap()
        .success());
    let st = Command::new(env!("CARGO_BIN_EXE_weft-wavespeed"))
        .arg("--model")
        .arg(&m)
        .arg("--history")
        .arg(o.join("history.parquet"))
        .args([
            "--set",
            "axis_x",
            "--component",
            "vx",
            "--relative-level",
            "0.5",
            "--out",
        ])
        .arg(o.join("wavespeeds.parquet"))
        .output()
        .unwrap();
    assert!(
        st.status.success(),
        "{}",
        String::from_utf8_lossy(&st.stderr)
    );
    let t = weft::table::Table::read(&o.join("wavespeeds.parquet")).unwrap();
    let pos = t.f64("position", "").unwrap();
    let v = t.f64_opt("node_speed").unwrap().unwrap();
    let mid: Vec<f64> = (0..pos.len())
        .filter(|&j| pos[j] > 0.02 && pos[j] < 0.08)
        .map(|j| v[j].unwrap().abs())
        .collect();
    let mean = mid.iter().sum::<f64>() / mid.len() as f64;
    let c = (1.5e11f64 / 7800.0).sqrt();
    eprintln!(
        "weft-wavespeed on the rod: {mean:.1} m/s vs {c:.1} m/s over {} nodes",
        mid.len()
    );
    assert!(rel(mean, c) < 0.005, "{mean} vs {c}");
    // The wave runs from x = L towards x = 0: against the set's order, so negative.
    assert!(v[100].unwrap() < 0.0);
}

/// The §4 girder (a rigid-jointed square lattice of rods, E = 150 GPa, ρ_g = 7800 kg/m³,
/// b/a = 0.1) clamped at x = 0 and pulsed along x = L: the longitudinal wave runs at the
/// lattice's long-wave speed √(E/(ρ_g(2 − b/a))) = 3181 m/s (lattice homogenisation,
/// docs/theory.md, "Closed forms used as oracles": the membrane of thickness b²/a, density ρ_g(2 − b/a)). One level for all
/// nodes and the incident front only; with each node's own half peak, the nodes by the
/// clamp read −10 000 to −49 000 m/s (a bug found in the §4 figure).
#[test]
fn wavespeed_on_the_lattice_is_its_long_wave_speed() {
    let dir = tempfile::tempdir().unwrap();
    let (m, o) = (dir.path().join("girder"), dir.path().join("out"));
    let run = |exe: &str, args: &[&str]| {
        let out = Command::new(exe).args(args).output().unwrap();
        assert!(
            out.status.success(),
            "{exe}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
    };
    let (ms, os) = (m.to_str().unwrap(), o.to_str().unwrap());
    run(
        env!("CARGO_BIN_EXE_weft-weave"),
        &[
            "girder",
            "--cells",
            "10",
            "--clamp",
            "translations",
            "--load-case",
            "tension",
            "--period",
            "2.280350850198276e-05",
            "--out",
            ms,
        ],
    );
    run(
        env!("CARGO_BIN_EXE_weft-simulate"),
        &["--quiet", "--model", ms, "--out", os],
    );
    let h = o.join("history.parquet");
    let speeds = |extra: &[&str], name: &str| {
        let out = o.join(name);
        let mut a = vec![
            "--model",
            ms,
            "--history",
            h.to_str().unwrap(),
            "--set",
            "axis_x",
            "--component",
            "vx",
            "--out",
            out.to_str().unwrap(),
        ];
        a.extend_from_slice(extra);
        run(env!("CARGO_BIN_EXE_weft-wavespeed"), &a);
        let t = weft::table::Table::read(&out).unwrap();
        let pos = t.f64("position", "").unwrap();
        let v = t.f64_opt("node_speed").unwrap().unwrap();
        pos.into_iter().zip(v).collect::<Vec<_>>()
    };
    let c = (150e9f64 / (7800.0 * (2.0 - 0.1))).sqrt();
    let line = speeds(&[], "line.parquet");
    let reached: Vec<(f64, f64)> = line
        .iter()
        .filter_map(|(x, v)| v.map(|v| (*x, v)))
        .collect();
    eprintln!("one level (0.2 of the line's peak): {reached:?} against −{c:.0} m/s");
    // Over [0, T] the front travels L: nodes down to x = 0.04 m are reached (measured 7).
    assert!(reached.len() >= 6, "{reached:?}");
    // Every reached node within 7 % (measured +0.9 % in the middle to +6.3 % at the
    // loaded edge, where the front of the sine pulse is still forming), running
    // against the set's order, and the middle's mean within 3 % (measured +1.5 %).
    for (x, v) in &reached {
        assert!(*v < 0.0 && rel(-v, c) < 0.07, "{v} m/s at x = {x}");
    }
    let mid: Vec<f64> = reached
        .iter()
        .filter(|(x, _)| *x > 0.035 && *x < 0.085)
        .map(|(_, v)| -v)
        .collect();
    let mean = mid.iter().sum::<f64>() / mid.len() as f64;
    assert!(rel(mean, c) < 0.03, "{mean} vs {c}");
    // The per-node level the §4 figure used: far off by the clamp (what this guards
    // against).
    let own = speeds(&["--relative-level", "0.5"], "own.parquet");
    assert!(own
        .iter()
        .any(|(_, v)| v.is_some_and(|v| v.abs() > 3.0 * c)));
}

/// The incident front only: a ramp running at 10 mm per unit time (exact under linear
/// interpolation), and a bump at x = 8 mm at t = 0.1, before the front gets there (a
/// reflection, or a wave that came another way): nodes 8 and 9 count as not reached,
/// the others keep the front's speed.
#[test]
fn wave_speeds_keep_the_incident_front_only() {
    use weft::analysis::{wave_speeds, Level};
    let ids: Vec<i64> = (0..10).collect();
    let s = series(1000, &ids, |t, x| {
        let ramp = ((t - 100.0 * x) * 10.0).clamp(0.0, 1.0);
        let bump = if (x - 8e-3).abs() < 1e-9 && (t - 0.1).abs() < 0.02 {
            1.0
        } else {
            0.0
        };
        ramp.max(bump)
    });
    let w = wave_speeds(&s, 0, Level::Line(0.5));
    assert!(w.arrival[8].is_none() && w.arrival[9].is_none(), "{w:?}");
    for j in 1..8 {
        let v = w.segment_speed[j].unwrap();
        assert!((v - 0.01).abs() < 1e-9, "segment {j}: {v}");
    }
}

/// Nodes along x at spacing 1 mm, with ux = f(t, x) sampled on `n` points over one period.
fn series(n: usize, ids: &[i64], f: impl Fn(f64, f64) -> f64) -> Series {
    let t: Vec<f64> = (0..=n).map(|k| k as f64 / n as f64).collect();
    let x0: Vec<[f64; 3]> = ids
        .iter()
        .map(|&i| [1e-3 * (i % 100) as f64, 0.0, 0.0])
        .collect();
    let values = t
        .iter()
        .map(|&tt| {
            x0.iter()
                .map(|x| [f(tt, x[0]), 0.0, 0.0, 0.0, 0.0, 0.0])
                .collect()
        })
        .collect();
    Series {
        t,
        node_id: ids.to_vec(),
        x0,
        values,
    }
}

#[test]
fn t_is_zero_one_and_two_for_equal_orthogonal_and_opposite_histories() {
    use std::f64::consts::PI;
    let ids: Vec<i64> = (0..5).collect();
    let q = series(200, &ids, |t, x| (2.0 * PI * t).sin() * (1.0 + x));
    let same = mismatch(&q, &q, &[0], 1e-9, false).unwrap();
    assert_eq!(same.t_value, 0.0);
    assert_eq!(same.max_peak_relative_error, 0.0);
    let orth = series(200, &ids, |t, x| (2.0 * PI * t).cos() * (1.0 + x));
    let r = mismatch(&orth, &q, &[0], 1e-9, false).unwrap();
    assert!((r.t_value - 1.0).abs() < 1e-12, "orthogonal: {}", r.t_value);
    let opp = series(200, &ids, |t, x| -(2.0 * PI * t).sin() * (1.0 + x));
    let r = mismatch(&opp, &q, &[0], 1e-9, false).unwrap();
    assert!((r.t_value - 2.0).abs() < 1e-12, "opposite: {}", r.t_value);
    assert!((r.max_peak_relative_error - 2.0).abs() < 1e-12);
}

#[test]
fn t_does_not_depend_on_a_common_refinement_of_the_time_grid() {
    let ids: Vec<i64> = (0..5).collect();
    let f = |t: f64, x: f64| (3.0 * t).sin() + 0.2 * x * t * t;
    let g = |t: f64, x: f64| (3.0 * t + 0.3).sin() + 0.1 * x * t;
    let coarse = mismatch(
        &series(100, &ids, f),
        &series(100, &ids, g),
        &[0],
        1e-9,
        false,
    )
    .unwrap();
    let fine = mismatch(
        &series(800, &ids, f),
        &series(800, &ids, g),
        &[0],
        1e-9,
        false,
    )
    .unwrap();
    assert!(
        rel(coarse.t_value, fine.t_value) < 1e-4,
        "{} vs {}",
        coarse.t_value,
        fine.t_value
    );
    // A candidate on another grid is resampled onto the reference's.
    let other = mismatch(
        &series(100, &ids, f),
        &series(37, &ids, f),
        &[0],
        1e-9,
        false,
    )
    .unwrap();
    assert!(other.t_value < 1e-3, "{}", other.t_value);
}

#[test]
fn nodes_of_two_meshes_are_matched_by_position() {
    // The candidate numbers the same positions differently (ids 503, 201, 702, 300 at
    // x = 3, 1, 2, 0 mm) and has an extra node elsewhere (99 at 99 mm), which is ignored.
    let q = series(50, &[0, 1, 2, 3], |t, x| t * (1.0 + 10.0 * x));
    let p = series(50, &[503, 201, 702, 300, 99], |t, x| t * (1.0 + 10.0 * x));
    let pairs = match_nodes(&q, &p, 1e-9).unwrap();
    let matched: Vec<i64> = pairs.iter().map(|&k| p.node_id[k]).collect();
    assert_eq!(matched, vec![300, 201, 702, 503]);
    assert_eq!(mismatch(&q, &p, &[0], 1e-9, false).unwrap().t_value, 0.0);
    // A reference node with no candidate at its position is an error naming it.
    let far = series(50, &[0, 1, 2, 7], |t, _| t);
    let err = match_nodes(&far, &p, 1e-9).err().unwrap().to_string();
    assert!(
        err.contains("reference node `7`") && err.contains("hint:"),
        "{err}"
    );
}

#[test]
fn static_mode_compares_the_last_samples() {
    let ids: Vec<i64> = (0..3).collect();
    let q = series(10, &ids, |t, _| t);
    let p = series(10, &ids, |t, _| if t < 1.0 { 5.0 } else { 1.1 });
    let r = mismatch(&q, &p, &[0], 1e-9, true).unwrap();
    let expect = 3.0 * 0.01 / (3.0 * (1.21 + 1.0));
    assert!(rel(r.t_value, expect) < 1e-12, "{} vs {expect}", r.t_value);
    assert_eq!(r.samples, 1);
}

/// T written out here from the tables (the paper's eq. 2 on the last samples, the static
/// mode): the reference set's nodes of `rm` matched by position (1e-9 m) to nodes of `cm`,
/// Σ‖p − q‖² / Σ(‖p‖² + ‖q‖²) over ux, uy. Independent of weft's reading, matching and
/// integration.
fn t_by_hand(dir: &std::path::Path, rm: &str, rh: &str, cm: &str, ch: &str) -> f64 {
    use std::collections::HashMap;
    use weft::table::Table;
    let read = |p: String| Table::read(&dir.join(p)).unwrap();
    let positions = |m: &str| -> HashMap<i64, [f64; 2]> {
        let n = read(format!("{m}/nodes.parquet"));
        let (id, x, y) = (
            n.i64("node_id", "").unwrap(),
            n.f64("x", "").unwrap(),
            n.f64("y", "").unwrap(),
        );
        (0..id.len()).map(|i| (id[i], [x[i], y[i]])).collect()
    };
    let last = |h: &str| -> HashMap<i64, [f64; 2]> {
        let h = read(h.to_string());
        let (t, id, ux, uy) = (
            h.f64("t", "").unwrap(),
            h.i64("node_id", "").unwrap(),
            h.f64("ux", "").unwrap(),
            h.f64("uy", "").unwrap(),
        );
        let t_end = t.iter().cloned().fold(f64::MIN, f64::max);
        (0..t.len())
            .filter(|&r| t[r] == t_end)
            .map(|r| (id[r], [ux[r], uy[r]]))
            .collect()
    };
    let sets = read(format!("{rm}/node_sets.parquet"));
    let (set, sid) = (
        sets.str("set", "").unwrap(),
        sets.i64("node_id", "").unwrap(),
    );
    let (rpos, cpos) = (positions(rm), positions(cm));
    let (q, p) = (last(rh), last(ch));
    let (mut num, mut den) = (0.0, 0.0);
    let mut n = 0;
    for (s, id) in set.iter().zip(&sid) {
        if s != "reference" {
            continue;
        }
        let x = rpos[id];
        let cid = cpos
            .iter()
            .find(|(_, y)| (x[0] - y[0]).hypot(x[1] - y[1]) < 1e-9)
            .map(|(i, _)| *i)
            .unwrap();
        let (a, b) = (q[id], p[&cid]);
        num += (a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2);
        den += a[0] * a[0] + a[1] * a[1] + b[0] * b[0] + b[1] * b[1];
        n += 1;
    }
    assert_eq!(n, 121);
    num / den
}

#[test]
fn error_stage_compares_a_girder_with_its_closed_form_membrane() {
    // Static, N = 10: in tension the closed-form membrane reproduces the girder (T = 0);
    // in clamped shear the lattice's boundary layer leaves a few per cent, T from the
    // tables by hand; a membrane against itself under a 1.25 times larger force has,
    // the static solve being linear, u_c = k·u_r and T = (k − 1)²/(1 + k²) exactly.
    // Mutation tried: T's denominator 2Σ‖q‖² instead of Σ(‖p‖² + ‖q‖²) gives a shear T of
    // 2.514e-3 against 2.350e-3 by hand: fails here (the old range 1e-3 < T < 4e-3 passed).
    let dir = tempfile::tempdir().unwrap();
    let run = |args: &[&str], bin: &str| {
        let o = Command::new(bin)
            .args(args)
            .current_dir(dir.path())
            .output()
            .unwrap();
        assert!(
            o.status.success(),
            "{bin} {args:?}: {}",
            String::from_utf8_lossy(&o.stderr)
        );
    };
    let (weave, sim, err) = (
        env!("CARGO_BIN_EXE_weft-weave"),
        env!("CARGO_BIN_EXE_weft-simulate"),
        env!("CARGO_BIN_EXE_weft-error"),
    );
    let mut t = vec![];
    for lc in ["tension", "shear"] {
        run(
            &["girder", "--load-case", lc, "--out", &format!("g-{lc}")],
            weave,
        );
        run(
            &["membrane", "--load-case", lc, "--out", &format!("m-{lc}")],
            weave,
        );
        run(
            &[
                "--model",
                &format!("g-{lc}"),
                "--out",
                &format!("go-{lc}"),
                "--static",
            ],
            sim,
        );
        run(
            &[
                "--model",
                &format!("m-{lc}"),
                "--out",
                &format!("mo-{lc}"),
                "--static",
            ],
            sim,
        );
        run(
            &[
                "--reference-model",
                &format!("g-{lc}"),
                "--reference-history",
                &format!("go-{lc}/history.parquet"),
                "--model",
                &format!("m-{lc}"),
                "--history",
                &format!("mo-{lc}/history.parquet"),
                "--set",
                "reference",
                "--components",
                "ux,uy",
                "--static",
                "--out-dir",
                &format!("e-{lc}"),
            ],
            err,
        );
        let s = weft::table::Table::read(&dir.path().join(format!("e-{lc}/error_summary.parquet")))
            .unwrap();
        let per =
            weft::table::Table::read(&dir.path().join(format!("e-{lc}/error.parquet"))).unwrap();
        assert_eq!(per.num_rows(), 121);
        t.push((
            s.f64("T", "").unwrap()[0],
            s.f64("max_peak_relative_error", "").unwrap()[0],
        ));
    }
    eprintln!("girder vs membrane: tension T = {:.3e} (max node error {:.2e}), shear T = {:.3e} (max {:.2e})", t[0].0, t[0].1, t[1].0, t[1].1);
    assert!(t[0].0 < 1e-12, "tension T {}", t[0].0);
    // Shear: T of the tables by hand (a relative gap δ ≈ 6 %, the lattice boundary layer
    // at N = 10, gives T ≈ δ²/2 ≈ 1.8e-3). Measured: weft-error's T and the hand
    // computation agree exactly (relative difference 0: both sum the same terms; T = 2.350e-3).
    let hand = t_by_hand(
        dir.path(),
        "g-shear",
        "go-shear/history.parquet",
        "m-shear",
        "mo-shear/history.parquet",
    );
    eprintln!(
        "shear T by hand {hand:.6e}, relative difference {:.1e}",
        rel(t[1].0, hand)
    );
    assert!(
        rel(t[1].0, hand) < 1e-12,
        "shear T {} vs {hand} by hand",
        t[1].0
    );
    // The same membrane under k = 1.25 times the force: closed form.
    let k: f64 = 1.25;
    run(
        &[
            "membrane",
            "--load-case",
            "shear",
            "--force",
            "125",
            "--out",
            "m-k",
        ],
        weave,
    );
    run(&["--model", "m-k", "--out", "mo-k", "--static"], sim);
    run(
        &[
            "--reference-model",
            "m-shear",
            "--reference-history",
            "mo-shear/history.parquet",
            "--model",
            "m-k",
            "--history",
            "mo-k/history.parquet",
            "--set",
            "reference",
            "--components",
            "ux,uy",
            "--static",
            "--out-dir",
            "e-k",
        ],
        err,
    );
    let tk = weft::table::Table::read(&dir.path().join("e-k/error_summary.parquet"))
        .unwrap()
        .f64("T", "")
        .unwrap()[0];
    let expect = (k - 1.0).powi(2) / (1.0 + k * k);
    eprintln!(
        "membrane vs 1.25 × force: T = {tk:.9e}, closed form {expect:.9e}, relative error {:.1e}",
        rel(tk, expect)
    );
    // Measured: relative error 2.0e-15 (the static solve's round-off).
    assert!(
        rel(tk, expect) < 1e-12,
        "T {tk} vs (k − 1)²/(1 + k²) = {expect}"
    );
}

// ---- Comparing models whose meshes differ (issue 14, item 1) ----

use weft::analysis::{interpolation, mismatch_paired, pair, Matching};
use weft::model::{ElementKind, Model, PartProps};

/// A linear field u(x) = A x + c (each of the six components its own row).
fn linear(x: &[f64; 3]) -> [f64; 6] {
    const A: [[f64; 3]; 6] = [
        [1.3, -0.7, 0.2],
        [0.4, 2.1, -1.1],
        [-0.9, 0.3, 0.8],
        [0.5, 0.5, -0.5],
        [2.0, -1.0, 0.1],
        [-0.3, 0.9, 1.7],
    ];
    const C: [f64; 6] = [0.01, -0.02, 0.03, 0.0, 0.1, -0.1];
    std::array::from_fn(|k| C[k] + (0..3).map(|j| A[k][j] * x[j]).sum::<f64>())
}

/// One element of each kind, apart, in 3-D and distorted: a triangle, a non-parallelogram
/// quad in a tilted plane, a truss and a beam along slanted axes.
fn one_of_each() -> (Model, Vec<(ElementKind, Vec<usize>)>) {
    let mut m = Model::default();
    let mut els = vec![];
    let mut id = 0i64;
    let mut add = |m: &mut Model, kind: ElementKind, xs: &[[f64; 3]]| {
        let part = m.add_part(
            m.parts.len() as i64 + 1,
            kind.name(),
            kind,
            PartProps::default(),
        );
        let nodes: Vec<usize> = xs
            .iter()
            .map(|x| {
                id += 1;
                m.add_node(100 + id, *x)
            })
            .collect();
        m.add_element(id, part, &nodes);
        els.push((kind, nodes));
    };
    add(
        &mut m,
        ElementKind::Tri,
        &[[0.0, 0.0, 0.0], [0.03, 0.005, 0.002], [0.01, 0.025, -0.004]],
    );
    // A quad with no parallel sides, its plane tilted about x (z = 0.3 y).
    let q = |x: f64, y: f64| [x, y, 0.3 * y];
    add(
        &mut m,
        ElementKind::Quad,
        &[q(0.1, 0.0), q(0.14, 0.01), q(0.135, 0.05), q(0.095, 0.035)],
    );
    add(
        &mut m,
        ElementKind::Truss,
        &[[0.2, 0.0, 0.0], [0.23, 0.02, 0.01]],
    );
    add(
        &mut m,
        ElementKind::Beam,
        &[[0.3, 0.0, 0.0], [0.31, -0.02, 0.03]],
    );
    (m, els)
}

#[test]
fn interpolation_reproduces_a_linear_field_exactly_on_every_element_kind() {
    // Linear shape functions (triangle, truss and beam axis) and the isoparametric
    // bilinear quad reproduce any linear field exactly (Zienkiewicz & Taylor, The Finite
    // Element Method vol. 1, §9.5, completeness of isoparametric elements): the
    // interpolated value at any interior point equals the field there, to rounding.
    let (m, els) = one_of_each();
    let mut points = vec![];
    let mut kinds = vec![];
    for (kind, nodes) in &els {
        let x: Vec<[f64; 3]> = nodes.iter().map(|&i| m.coords[i]).collect();
        let locals: Vec<Vec<f64>> = match kind {
            ElementKind::Tri => vec![
                vec![0.2, 0.3, 0.5],
                vec![0.6, 0.1, 0.3],
                vec![1.0, 0.0, 0.0],
            ],
            ElementKind::Quad => {
                let n = |xi: f64, eta: f64| {
                    vec![
                        0.25 * (1.0 - xi) * (1.0 - eta),
                        0.25 * (1.0 + xi) * (1.0 - eta),
                        0.25 * (1.0 + xi) * (1.0 + eta),
                        0.25 * (1.0 - xi) * (1.0 + eta),
                    ]
                };
                vec![n(0.3, -0.6), n(-0.8, 0.7), n(0.0, 1.0)]
            }
            _ => vec![vec![0.75, 0.25], vec![0.1, 0.9]],
        };
        for w in locals {
            points.push(std::array::from_fn::<f64, 3, _>(|c| {
                w.iter().zip(&x).map(|(w, x)| w * x[c]).sum()
            }));
            kinds.push(*kind);
        }
    }
    let ids: Vec<i64> = (0..points.len() as i64).collect();
    let (nodes, pairs) = interpolation(&m, None, &points, &ids, 1e-9).unwrap();
    let mut worst = 0.0f64;
    for (j, p) in points.iter().enumerate() {
        let exact = linear(p);
        for k in 0..6 {
            let v: f64 = pairs[j]
                .iter()
                .map(|&(c, w)| w * linear(&m.coords[nodes[c]])[k])
                .sum();
            let e = (v - exact[k]).abs();
            worst = worst.max(e);
            assert!(
                e < 5e-16,
                "{:?} point {j} component {k}: {v} vs {}",
                kinds[j],
                exact[k]
            );
        }
    }
    // Measured: 1.1e-16 (|u| ~ 0.1).
    eprintln!("linear field: worst interpolation error {worst:.1e}");
    // Through T: a reference carrying the field at the points, a candidate carrying it at
    // the element nodes only, give T = 0 to rounding.
    let q = Series {
        t: vec![0.0, 1.0],
        node_id: ids.clone(),
        x0: points.clone(),
        values: vec![points.iter().map(linear).collect(); 2],
    };
    let p = Series {
        t: vec![0.0, 1.0],
        node_id: nodes.iter().map(|&i| m.node_id[i]).collect(),
        x0: nodes.iter().map(|&i| m.coords[i]).collect(),
        values: vec![nodes.iter().map(|&i| linear(&m.coords[i])).collect(); 2],
    };
    let r = mismatch_paired(&q, &p, &pairs, &[0, 1, 2, 3, 4, 5], false).unwrap();
    assert!(r.t_value < 1e-28, "T {}", r.t_value);
    // A point off every element (5 µm out of the quad's plane) is refused, naming it.
    let off = [[0.12, 0.02, 0.3 * 0.02 + 5e-6]];
    let err = interpolation(&m, None, &off, &[7], 1e-9)
        .err()
        .unwrap()
        .to_string();
    assert!(
        err.contains("reference node `7`") && err.contains("no candidate element"),
        "{err}"
    );
}

#[test]
fn coincident_nodes_are_a_tie_that_position_matching_refuses() {
    // A yarn crossing: warp node 10 and weft node 11 at the same point, moving
    // differently. Position cannot tell them apart: the match must be refused with a way
    // out, and matching by id must pair them right (T = 0 exactly).
    let at = |ids: &[i64], vals: &[f64]| Series {
        t: vec![0.0, 1.0],
        node_id: ids.to_vec(),
        x0: vec![[0.001, 0.002, 0.0]; ids.len()],
        values: vec![
            vec![[0.0; 6]; ids.len()],
            vals.iter().map(|&v| [v, 0.0, 0.0, 0.0, 0.0, 0.0]).collect(),
        ],
    };
    let q = at(&[10, 11], &[1.0, 2.0]);
    let p = at(&[11, 10], &[2.0, 1.0]);
    let err = match_nodes(&q, &p, 1e-9).err().unwrap().to_string();
    assert!(
        err.contains("reference node `10`")
            && err.contains("tied between 2 candidate nodes")
            && err.contains("--match id")
            && err.contains("--candidate-set")
            && !err.contains("lower --tolerance"),
        "{err}"
    );
    let pairs = pair(&q, &p, 1e-9, Matching::Id).unwrap();
    assert_eq!(pairs, vec![vec![(1, 1.0)], vec![(0, 1.0)]]);
    assert_eq!(
        mismatch_paired(&q, &p, &pairs, &[0], false)
            .unwrap()
            .t_value,
        0.0
    );
    // A missing id is an error naming the node.
    let r = at(&[10, 12], &[1.0, 2.0]);
    let err = pair(&r, &p, 1e-9, Matching::Id).err().unwrap().to_string();
    assert!(
        err.contains("reference node `12`") && err.contains("hint:"),
        "{err}"
    );
}

#[test]
fn error_stage_interpolates_a_coarser_membrane_and_needs_no_velocities() {
    // Static tension of the equivalent membrane (ν = 0), clamped (translations) at x = 0,
    // the edge x = L loaded uniformly: u_x = F x/(E s L), u_y = 0, a linear field that
    // bilinear quads of any size reproduce. So a 4 × 4 membrane interpolated at the nodes
    // of a 10 × 10 one (none coincide inside) gives T = 0 to the static solver's tolerance,
    // where position matching finds no partner. The candidate's history is rewritten
    // without its velocity columns: a displacement comparison must not need them.
    let dir = tempfile::tempdir().unwrap();
    let d = |s: &str| dir.path().join(s).display().to_string();
    let (weave, sim, err) = (
        env!("CARGO_BIN_EXE_weft-weave"),
        env!("CARGO_BIN_EXE_weft-simulate"),
        env!("CARGO_BIN_EXE_weft-error"),
    );
    for (name, n) in [("fine", "10"), ("coarse", "4")] {
        // The same material in both (the defaults follow the cell size: s = a/100).
        run_ok(
            weave,
            &[
                "membrane",
                "--cells",
                n,
                "--load-case",
                "tension",
                "--thickness",
                "1e-4",
                "--out",
                &d(name),
            ],
        );
        run_ok(
            sim,
            &[
                "--model",
                &d(name),
                "--static",
                "-q",
                "--out",
                &d(&format!("{name}-out")),
            ],
        );
    }
    let h = weft::table::Table::read(&dir.path().join("coarse-out/history.parquet")).unwrap();
    use weft::table::Col;
    weft::table::write_table(
        &dir.path().join("coarse-out/disp.parquet"),
        &weft::table::batch(vec![
            Col::F64("t", h.f64("t", "").unwrap()),
            Col::I64("node_id", h.i64("node_id", "").unwrap()),
            Col::F64("ux", h.f64("ux", "").unwrap()),
            Col::F64("uy", h.f64("uy", "").unwrap()),
            Col::F64("uz", h.f64("uz", "").unwrap()),
        ]),
        &weft::table::Provenance::new("test", serde_json::json!({})),
    )
    .unwrap();
    let args = |how: &str, out: &str| -> Vec<String> {
        [
            "--reference-model",
            &d("fine"),
            "--reference-history",
            &d("fine-out/history.parquet"),
            "--model",
            &d("coarse"),
            "--history",
            &d("coarse-out/disp.parquet"),
            "--components",
            "ux,uy",
            "--static",
            "--match",
            how,
            "--out-dir",
            &d(out),
        ]
        .iter()
        .map(|s| s.to_string())
        .collect()
    };
    let a = args("interpolate", "e");
    run_ok(err, &a.iter().map(|s| s.as_str()).collect::<Vec<_>>());
    let s = weft::table::Table::read(&dir.path().join("e/error_summary.parquet")).unwrap();
    let t = s.f64("T", "").unwrap()[0];
    assert_eq!(s.i64("nodes", "").unwrap()[0], 121);
    // Measured: T = 2.5e-19, the static solves' residual (~1e-10 relative); the nearest
    // coarse node instead of the interpolation would leave T ~ 1e-2.
    eprintln!("coarse membrane interpolated at the fine one's nodes: T = {t:.2e}");
    assert!(t < 1e-18, "T {t}");
    let a = args("position", "e2");
    let o = Command::new(err).args(&a).output().unwrap();
    let msg = String::from_utf8_lossy(&o.stderr);
    assert!(
        !o.status.success() && msg.contains("--match interpolate"),
        "{msg}"
    );
}

/// `weft-wavespeed --slack`: a ramp front at c = 10 mm/s along nodes 1 mm apart,
/// u = max(0, t − x/c), level 2·10⁻³ (two samples past each node's kink, where linear
/// interpolation between samples is exact): arrival x/c + 2·10⁻³. Node 5 is reached
/// 0.1005 early, half a sample before node 4 (what a flat tied interface node beside a
/// crimped crossing does). Without slack the front ends at node 5; with one sample's
/// slack (10⁻³) it goes on, the segment 4→5 that does not advance gets no speed, and
/// every segment that does not touch node 5 keeps the exact speed c.
#[test]
fn slack_lets_a_node_reached_a_little_early_keep_the_front_going() {
    use weft::analysis::{wave_speeds, wave_speeds_with, Level};
    let c = 1e-2;
    let ids: Vec<i64> = (0..10).collect();
    let s = series(1000, &ids, |t, x| {
        let early = if (x - 5e-3).abs() < 1e-12 {
            0.1005
        } else {
            0.0
        };
        (t - x / c + early).max(0.0)
    });
    let strict = wave_speeds(&s, 0, Level::Absolute(2e-3));
    let reached: Vec<bool> = strict.arrival.iter().map(|a| a.is_some()).collect();
    assert_eq!(&reached[..5], &[true; 5]);
    assert_eq!(&reached[5..], &[false; 5]);
    let w = wave_speeds_with(&s, 0, Level::Absolute(2e-3), 1e-3);
    assert!(w.arrival.iter().all(|a| a.is_some()));
    assert!(w.segment_speed[5].is_none(), "{:?}", w.segment_speed[5]);
    for j in [1, 2, 3, 4, 7, 8, 9] {
        let v = w.segment_speed[j].unwrap();
        assert!(rel(v, c) < 1e-9, "segment {j}: {v}");
    }
    // Node 4's speed is its other segment's alone (c), not a mean with a bogus one.
    assert!(rel(w.node_speed[4].unwrap(), c) < 1e-9);
}
