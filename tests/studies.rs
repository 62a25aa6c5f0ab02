//! The study pipelines shipped in `pipelines/` run end to end through `weft run` in a
//! fresh project, give the physics they are about, and a second run finds them fresh.

mod common;
use common::{project_with, weft_run};
use std::process::Command;

use weft::table::Table;

/// The paper's §4 study: the fitted membrane matches the closed forms of a rigid-jointed
/// square lattice (docs/theory.md, "Closed forms used as oracles"; Gibson & Ashby, Cellular Solids, §4.3) within 5 % at
/// N = 10, statically and dynamically, with T far below its start; figures are written.
#[test]
fn girder_membrane_study_recovers_the_lattice_closed_forms() {
    let dir = project_with("girder_membrane.toml");
    let root = dir.path();
    weft_run(root, "girder_membrane.toml");
    let out = root.join("runs/girder_membrane");
    for mode in ["static", "dynamic"] {
        let r = Table::read(&out.join(format!("fit/{mode}/fit_result.parquet"))).unwrap();
        let names = r.str("name", "").unwrap();
        let diff = r.f64_opt("relative_difference").unwrap().unwrap();
        let (t0, t) = (
            r.f64("T_initial", "").unwrap()[0],
            r.f64("T", "").unwrap()[0],
        );
        assert_eq!(names.len(), if mode == "static" { 2 } else { 3 });
        for (n, d) in names.iter().zip(&diff) {
            let d = d.expect("every parameter has a closed form");
            eprintln!("{mode}: {n} {:+.3} % (T {t0:.3e} -> {t:.3e})", 100.0 * d);
            // As tests/fit.rs (the same fit at N = 10): G measured 2.6–3.2 %, s and ρ
            // ≤ 0.15 %.
            let tol = if n.contains("G12") { 0.045 } else { 5e-3 };
            assert!(
                d.abs() < tol,
                "{mode}: {n} differs by {d} (tolerance {tol})"
            );
        }
        assert!(t0 > 0.5 && t < 1e-3, "{mode}: T {t0} -> {t}");
    }
    for (case, bound) in [("tension", 1e-4), ("shear", 1e-3)] {
        let e = Table::read(&out.join(format!("error/{case}/error_summary.parquet"))).unwrap();
        let t = e.f64("T", "").unwrap()[0];
        assert!(
            t < bound,
            "{case}: fitted membrane against the girder T = {t}"
        );
    }
    for f in [
        "time_laws_tension.png",
        "time_laws_shear.png",
        "wavespeed_tension.png",
        "error.png",
        "fit_convergence.png",
        "field_shear.png",
    ] {
        let b = std::fs::read(out.join("figures").join(f)).unwrap();
        assert!(
            b.starts_with(b"\x89PNG\r\n\x1a\n") && b.len() > 10_000,
            "{f}"
        );
    }
    let svg = std::fs::read_to_string(out.join("figures/fit_convergence.svg")).unwrap();
    assert!(svg.contains("<svg") && svg.contains("best T"), "svg");
    // Nothing changed: nothing reruns.
    let err = weft_run(root, "girder_membrane.toml");
    assert!(err.contains("0 ran, 17 fresh"), "{err}");
}

/// Outputs of the fit and plot stages with bad input: clear errors, no panic, no file.
#[test]
fn weft_plot_refuses_bad_input_clearly() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let trace = d.join("t.parquet");
    weft::table::write_table(
        &trace,
        &weft::table::batch(vec![weft::table::Col::F64("x", vec![1.0])]),
        &weft::table::Provenance::new("test", serde_json::json!({})),
    )
    .unwrap();
    let plot = |args: &[&str]| {
        Command::new(env!("CARGO_BIN_EXE_weft-plot"))
            .args(args)
            .output()
            .unwrap()
    };
    let t = trace.to_string_lossy().to_string();
    let o = plot(&[
        "fit",
        "--trace",
        &t,
        "--out",
        &d.join("f.png").to_string_lossy(),
    ]);
    let e = String::from_utf8_lossy(&o.stderr);
    assert!(
        !o.status.success() && e.contains("evaluation") && e.contains("t.parquet"),
        "{e}"
    );
    let good = d.join("good.parquet");
    weft::table::write_table(
        &good,
        &weft::table::batch(vec![
            weft::table::Col::I64("evaluation", vec![0, 1]),
            weft::table::Col::F64("T", vec![0.5, 0.1]),
            weft::table::Col::F64("best_T", vec![0.5, 0.1]),
        ]),
        &weft::table::Provenance::new("test", serde_json::json!({})),
    )
    .unwrap();
    let g = good.to_string_lossy().to_string();
    let o = plot(&[
        "fit",
        "--trace",
        &g,
        "--out",
        &d.join("f.pdf").to_string_lossy(),
    ]);
    let e = String::from_utf8_lossy(&o.stderr);
    assert!(
        !o.status.success()
            && e.contains("unknown figure format `pdf`")
            && e.contains(".png or .svg"),
        "{e}"
    );
    let o = plot(&[
        "fit",
        "--trace",
        &g,
        "--out",
        &d.join("ok.svg").to_string_lossy(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    std::fs::remove_file(d.join("ok.svg")).unwrap();
    let o = plot(&[
        "wavespeed",
        "--table",
        &d.join("none.parquet").to_string_lossy(),
        "--out",
        &d.join("w.svg").to_string_lossy(),
    ]);
    let e = String::from_utf8_lossy(&o.stderr);
    assert!(!o.status.success() && e.contains("none.parquet"), "{e}");
    for o in [&o] {
        assert!(!String::from_utf8_lossy(&o.stderr).contains("panicked"));
    }
    let left: Vec<_> = std::fs::read_dir(d)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().to_string())
        .filter(|n| n.ends_with(".png") || n.ends_with(".svg") || n.contains("tmp"))
        .collect();
    assert!(left.is_empty(), "{left:?}");
}

/// The woven patch pipeline (generate, form, impact, figures) at 6 × 6 and 4 µs (the
/// shipped 10 × 10 forms in minutes): the formed patch carries the asked tension at its
/// ends (the pull, to the relaxation's residual), the bullet's z momentum lost is the
/// fabric's gained (momentum balance, below), the figures are written, and a second run
/// is all fresh.
#[test]
fn woven_patch_pipeline_forms_and_hits_the_patch() {
    let dir = project_with("woven_patch.toml");
    let root = dir.path();
    let p = root.join("pipelines/woven_patch.toml");
    let s = std::fs::read_to_string(&p)
        .unwrap()
        .replace("yarns = 10", "yarns = 6")
        .replace("end_time = 1e-5", "end_time = 4e-6");
    std::fs::write(&p, s).unwrap();
    weft_run(root, "woven_patch.toml");
    let out = root.join("runs/woven_patch");
    let f = Table::read(&out.join("formed/form.parquet")).unwrap();
    for c in ["warp_end_tension", "weft_end_tension"] {
        let t = f.f64(c, "").unwrap()[0];
        eprintln!("{c} = {t} N (asked 0.5 N)");
        // The formed ends' tension as forming reports it, against the pull asked: measured
        // off by 1.7e-4 N; tolerance 6e-4 N, 3.5×. (The tension derived independently from
        // the reactions is tests/forming.rs's.)
        assert!((t - 0.5).abs() < 6e-4, "{c} = {t}");
    }
    // Momentum balance along z (the impact direction; the symmetry planes x = 0 and y = 0
    // take no z force). The bullet flies along −z; the z momentum it gives up,
    // Δp = m_p(v(t) − v₀) > 0, is what the fabric takes, −Σ mᵢ v_zᵢ(t), plus the impulse
    // of the clamped yarn ends' reactions. The central-difference scheme conserves
    // momentum exactly (each element's and each contact's forces sum to zero; the bullet's
    // and the nodes' velocities are both written at tₙ), so:
    // - until a signal from the contact can reach a clamp, the balance is exact but for
    //   the formed state's own unbalanced residual (the relaxation stops at a residual,
    //   here a net 5e-7 N along z, 1e-13 N s per sample). The fastest signal is the
    //   in-plane wave c = √(E₁/ρ) (ν = 0), leaving from the edge of the nose's footprint,
    //   whose radius after the tip has moved v₀t is at most √(2Rv₀t) (a hemisphere of
    //   radius R pressed v₀t into a sheet held still), so no clamp stirs while
    //   √(2Rv₀t) + ct < d (d the clamps' least distance from the axis): here 0.45 µs;
    // - afterwards the clamps' reactions enter (at 1.0 µs, when the wave arrives): the
    //   balance then holds only to their impulse, measured beside its tolerance.
    // The bullet's own loss is also checked against the impulse of its written contact
    // force, ∫f_z dt (trapezoid over 0.2 µs samples of a force that rings at the
    // contact's period, so only to about a per cent).
    let pr = Table::read(&out.join("impact/projectile.parquet")).unwrap();
    let (t, vz, fz) = (
        pr.f64("t", "").unwrap(),
        pr.f64("vz", "").unwrap(),
        pr.f64("fz", "").unwrap(),
    );
    let model = weft::model::io::read_model(&out.join("formed")).unwrap();
    let bullet = &model.projectiles[0];
    let m_p = bullet.mass;
    let mass = weft::solver::Solver::new(&model).unwrap().masses().to_vec();
    let index: std::collections::HashMap<i64, usize> = model
        .node_id
        .iter()
        .enumerate()
        .map(|(k, &id)| (id, k))
        .collect();
    let d = model
        .constraints
        .iter()
        .filter(|c| c.1[2])
        .map(|&(n, _)| {
            let x: [f64; 3] = std::array::from_fn(|a| {
                model.coords[n][a] + model.initial_displacement.get(n).map_or(0.0, |u| u[a])
            });
            x[0].hypot(x[1])
        })
        .fold(f64::INFINITY, f64::min);
    let props = &model.parts[0].props;
    let c = (props.youngs_modulus_1.unwrap() / props.density.unwrap()).sqrt();
    let v0 = -vz[0];
    let quiet = |t: f64| (2.0 * bullet.radius * v0 * t).sqrt() + c * t < d;
    let h = Table::read(&out.join("impact/history.parquet")).unwrap();
    let (ht, hid, hvz) = (
        h.f64("t", "").unwrap(),
        h.i64("node_id", "").unwrap(),
        h.f64("vz", "").unwrap(),
    );
    assert_eq!(ht.len(), t.len() * model.node_id.len(), "--all-nodes");
    let (mut early, mut early_dp, mut worst) = (0.0f64, 0.0f64, 0.0f64);
    for (k, &tk) in t.iter().enumerate() {
        let fabric: f64 = (0..ht.len())
            .filter(|&r| ht[r] == tk)
            .map(|r| mass[index[&hid[r]]] * hvz[r])
            .sum();
        let dp = m_p * (vz[k] - vz[0]);
        let off = (dp + fabric).abs();
        if quiet(tk) {
            early = early.max(off);
            early_dp = dp;
        }
        worst = worst.max(off);
    }
    let lost = m_p * (*vz.last().unwrap() - vz[0]);
    let impulse: f64 = (1..t.len())
        .map(|k| 0.5 * (fz[k] + fz[k - 1]) * (t[k] - t[k - 1]))
        .sum();
    eprintln!(
        "momentum: clamps {:.2} mm away, quiet to {:.2} µs: balance off by {early:.2e} N s of {early_dp:.3e} ({:.2e}); \
         to 4 µs the bullet gave up {lost:.4e} N s (Δv {:.4} m/s), balance off by {worst:.2e} ({:.2e}); ∫f_z dt {impulse:.4e} N s ({:+.2e})",
        1e3 * d,
        1e6 * t.iter().filter(|&&x| quiet(x)).last().unwrap(),
        early / early_dp,
        *vz.last().unwrap() - vz[0],
        worst / lost,
        (impulse - lost) / lost
    );
    // Measured: quiet to 0.40 µs, 2.3e-13 N s of 6.9e-6 (3.3e-8); tolerance 1e-7, 3×.
    assert!(
        early_dp > 0.0 && early < 1e-7 * early_dp,
        "momentum before the clamps stir: {early} of {early_dp}"
    );
    // Measured: 4.3e-3 of 9.0e-4 N s (the clamps' impulse); tolerance 1e-2, 2.3×.
    assert!(
        lost > 0.0 && worst < 1e-2 * lost,
        "momentum off by {worst} of {lost}"
    );
    // Measured: +1.02e-2; tolerance 3e-2, 3×.
    assert!(
        (impulse - lost).abs() < 3e-2 * lost,
        "∫f dt {impulse} vs {lost}"
    );
    for fig in ["weave.png", "impact.png", "uz_field.png"] {
        assert!(out.join("figures").join(fig).exists(), "{fig}");
    }
    let again = weft_run(root, "woven_patch.toml");
    assert!(again.contains("4 fresh"), "{again}");
}

/// The paper's §5 study (`pipelines/woven_reduced.toml`), made small: a 5-yarn quarter
/// yarn-level patch in a 20 mm membrane, formed, against the 5 × 5 girder with the same
/// crossings and the same membrane, 20 µs. Expectations that do not come from the code:
/// - every run keeps its energy balance (issue 13; the explicit scheme conserves energy
///   to round-off plus contact work, which the balance counts), held near today's;
/// - the extended fit and the sliding links' fit lower T and the largest nodal error of
///   the trial values, and end below the paper's own fitted model's largest nodal error,
///   14 % (its §5, Fig. 11b);
/// - the reduced model is smaller than the reference (the point of the reduction):
///   counted in elements, not timed.
#[test]
fn woven_reduced_study_fits_the_girder_to_the_yarn_level_patch() {
    let dir = project_with("woven_reduced.toml");
    let root = dir.path();
    let p = root.join("pipelines/woven_reduced.toml");
    let s = std::fs::read_to_string(&p)
        .unwrap()
        .replace("yarns = 11", "yarns = 5")
        .replace("girder = 20", "girder = 8")
        .replace("half_size = 0.05", "half_size = 0.02")
        .replace("side = 0.1", "side = 0.04")
        .replace("end_time = 5e-5", "end_time = 2e-5")
        // The 5-yarn reference's diagonal: ids 1, 52, 121, 190, 259 (0 … 4 mm).
        .replace("nodes = \"241,523,805,1087\"", "nodes = \"52,121,190\"")
        .replace(
            "--starts 4 --max-evaluations 40",
            "--starts 2 --max-evaluations 12",
        )
        .replace(
            "--starts 4 --max-evaluations 50",
            "--starts 2 --max-evaluations 16",
        );
    std::fs::write(&p, s).unwrap();
    weft_run(root, "woven_reduced.toml");
    let out = root.join("runs/woven_reduced");
    // Energy conservation (the explicit scheme's, contact and friction work counted):
    // each run's worst relative balance error held near what it measures today (the
    // users' promise is 1 %, issue 13). Measured: formed 1.23e-4, trial 3.4e-6, soft
    // (the paper fit with k_z/100) 2.1e-6, paper 4.5e-6, extended 1.48e-4, sliding
    // 2.24e-5; tolerances 2.7–3.4× above.
    for (run, tol) in [
        ("formed", 4e-4),
        ("trial", 1e-5),
        ("soft", 6e-6),
        ("paper", 1.5e-5),
        ("extended", 5e-4),
        ("sliding", 6e-5),
    ] {
        let e = Table::read(&out.join(format!("impact/{run}/energy.parquet"))).unwrap();
        let worst = e
            .f64("balance_error_relative", "")
            .unwrap()
            .into_iter()
            .fold(0.0, f64::max);
        eprintln!("{run}: worst energy balance error {worst:.3e} (tolerance {tol:.1e})");
        assert!(worst <= tol, "{run}: energy balance error {worst}");
    }
    let summary = |m: &str| {
        let t = Table::read(&out.join(format!("error/{m}/error_summary.parquet"))).unwrap();
        (
            t.f64("T", "").unwrap()[0],
            t.f64("max_peak_relative_error", "").unwrap()[0],
        )
    };
    let (trial, paper, ext, sl) = (
        summary("trial"),
        summary("paper"),
        summary("extended"),
        summary("sliding"),
    );
    eprintln!(
        "T, max node error: trial {trial:?}, paper fit {paper:?}, extended fit {ext:?}, sliding links {sl:?}"
    );
    // The paper's own reduced model, after its fit, still erred by 14 % at its worst
    // reference node (§5, Fig. 11b: "Maximum error between reference nodes of the
    // reference and reduced FE models was 14% after the adjustment"; the same measure,
    // peak‖p − q‖/peak‖q‖ over the diagonal crossings). weft's extended fit and its
    // sliding links, which add what the paper's links lack (slip at the crossings, the
    // rods' effective modulus), must do better than that here too. Measured at this size:
    // extended 5.5 %, sliding links 4.6 % (the paper's fit 14.0 %, the trial 13.9 %); the
    // bound is 2.5× and 3× above them.
    for (name, e) in [("extended fit", ext.1), ("sliding links", sl.1)] {
        assert!(
            e < 0.14,
            "{name}: max nodal error {e} not below the paper's fitted 14 %"
        );
    }
    assert!(ext.0 < trial.0, "extended T {} vs trial {}", ext.0, trial.0);
    assert!(
        ext.1 < trial.1,
        "extended max error {} vs trial {}",
        ext.1,
        trial.1
    );
    assert!(sl.0 < trial.0, "sliding T {} vs trial {}", sl.0, trial.0);
    assert!(
        sl.1 < trial.1,
        "sliding max error {} vs trial {}",
        sl.1,
        trial.1
    );
    let count = |m: &str| {
        let s = Table::read(&out.join(format!("impact/{m}/summary.parquet"))).unwrap();
        s.i64("elements", "").unwrap()[0]
    };
    assert!(count("trial") < count("formed"));
    for fig in [
        "uz_trial.png",
        "uz_fitted.png",
        "error.png",
        "fit_convergence.png",
        "uz_field.png",
    ] {
        assert!(out.join("figures").join(fig).exists(), "{fig}");
    }
    let again = weft_run(root, "woven_reduced.toml");
    assert!(
        again.contains("fresh") && !again.contains("run "),
        "{again}"
    );
}

/// The §3 pipeline (`pipelines/woven_membrane.toml`) made small: a 4-yarn patch in a
/// membrane against the 10-yarn patch of the same size, 5 µs. Expectations that do not
/// come from the code: the membrane's fit starts from ratios 2–3 × off the paper's and
/// COBYLA keeps its best point, so the fitted T is below the start's; the in-plane fronts
/// of the fitted membrane and of the reference run at the speeds lattice homogenisation
/// gives (below); the combined model
/// has fewer nodes than the reference (the point of the reduction, counted, not timed);
/// the fitted membrane reflects less of a pulse than the start (below); every run's
/// energy balance within 1 %; a second run does nothing.
#[test]
fn woven_membrane_study_runs_small_and_the_fit_lowers_t() {
    let dir = project_with("woven_membrane.toml");
    let root = dir.path();
    let p = root.join("pipelines/woven_membrane.toml");
    let s = std::fs::read_to_string(&p)
        .unwrap()
        .replace("patch = 10", "patch = 4")
        .replace("reference = 60", "reference = 10")
        .replace("length = 0.0595", "length = 0.0095")
        .replace("end_time = 6e-5", "end_time = 5e-6")
        .replace("interval = 5e-7", "interval = 5e-8")
        .replace("field_interval = 1e-5", "field_interval = 2.5e-6")
        // Crossings at 1, 2 | 4, 5 mm (id 8k + 1; the interface at 3.5 mm).
        .replace("nodes = \"57,73,89,105\"", "nodes = \"9,17,33,41\"")
        .replace(
            "--starts 4 --max-evaluations 30",
            "--starts 2 --max-evaluations 30",
        )
        // The pulse from a 1 mm strip; its tail has passed the interface at 3.5 mm by
        // (3.5 + 1) mm / 6.8 km/s = 0.66 µs, the part reflected there is back at it from
        // the symmetry plane at (2.5 + 7) mm / 7.5 km/s = 1.3 µs.
        .replace("pulse_to = 2e-3", "pulse_to = 1e-3")
        .replace("pulse_end = 4e-6", "pulse_end = 1.5e-6")
        .replace("window_start = 1.8e-6", "window_start = 0.8e-6")
        .replace("window_end = 2.2e-6", "window_end = 1.0e-6")
        .replace("patch_box = 9.51e-3", "patch_box = 3.51e-3");
    std::fs::write(&p, s).unwrap();
    weft_run(root, "woven_membrane.toml");
    let out = root.join("runs/woven_membrane");
    // Reflection at the interface (issue 12, item 5). The start membrane's impedance per
    // unit width, √(E t · ρ t) ∝ √(0.1 × 0.4), is 2.4 × below the paper's √(0.3 × 0.8),
    // which matches the warp's (E A/p · ρ A/p); the fit moves E and ρ towards the paper's
    // (it lowers T), so the mismatch, hence the reflected energy ((Z₁ − Z₂)/(Z₁ + Z₂))²
    // (Graff §1.5), falls. The reference has no interface at all: the least left in the
    // patch. Measured: R 0.906 (start), 0.816 (paper), 0.739 (fitted), 0.094 (reference).
    let r = |m: &str| {
        Table::read(&out.join(format!("reflection/{m}/reflection.parquet")))
            .unwrap()
            .f64("reflection", "")
            .unwrap()[0]
    };
    let (r0, rp, rf, rr) = (r("start"), r("paper"), r("fitted"), r("reference"));
    eprintln!("reflection: start {r0:.3}, paper {rp:.3}, fitted {rf:.3}, reference {rr:.3}");
    assert!(rf < r0, "the fitted membrane reflects {rf}, the start {r0}");
    assert!(rr < rf.min(rp), "reference {rr}, paper {rp}, fitted {rf}");
    let fit = Table::read(&out.join("fit/fit_result.parquet")).unwrap();
    let (t0, t) = (
        fit.f64("T_initial", "").unwrap()[0],
        fit.f64("T", "").unwrap()[0],
    );
    eprintln!("membrane fit: T {t0:.3e} -> {t:.3e}");
    assert!(t < t0, "fit T {t} vs start {t0}");
    for run in ["impact/reference", "impact/combined", "impact_all/fitted"] {
        let e = Table::read(&out.join(run).join("energy.parquet")).unwrap();
        let worst = e
            .f64("balance_error_relative", "")
            .unwrap()
            .into_iter()
            .fold(0.0, f64::max);
        assert!(worst <= 0.01, "{run}: energy balance error {worst}");
    }
    let nodes = |m: &str| {
        Table::read(&out.join(format!("impact/{m}/summary.parquet")))
            .unwrap()
            .i64("nodes", "")
            .unwrap()[0]
    };
    assert!(nodes("combined") < nodes("reference"));
    // The cost table gathers both impacts' summaries (one row each).
    let cost = Table::read(&out.join("cost.parquet")).unwrap();
    assert_eq!(cost.i64("nodes", "").unwrap().len(), 2);
    // The in-plane front beyond the interface (c = 3.5 mm) in the fitted membrane against
    // the reference's at the same positions: the front's mean speed between the first and
    // the last membrane node of 3.6–7.5 mm, Δx over the difference of the level's arrival
    // times (the reference's arrival interpolated linearly along the line). Left out: the
    // last 2 mm before the clamped outer edge at 9.5 mm, which its reflection reaches
    // first. (Node by node the speeds scatter: the first membrane nodes take the patch
    // ends' jolt. The transverse front does not get past the interface within 5 µs.)
    //
    // Oracles, from lattice homogenisation of the plain weave along a yarn direction: a
    // long in-plane wave is carried by one family's stiffness E A/p per width and both
    // families' mass 2ρA/p per area, c_L = c_y/√2 with c_y = √(E/ρ) of the yarn. A
    // membrane that stands for the fabric runs at c_L (crimp lowers it: the straightening
    // yarns are softer). Near the impact the reference's front runs faster, between c_L
    // and c_y: the loaded yarns lead before their crossings' mass is dragged along. So:
    // the reference's front within [c_L, c_y] (measured 6654 m/s = 0.89 c_y); the fitted
    // membrane's within 15 % of c_L (measured 4799 m/s, −9 %; the full study's fit runs at
    // √(E/ρ) = 4642 m/s, −12 %); their difference then at most 1 − 0.85/√2 = 40 %
    // (measured −28 %; the paper's "up to about 20 %" is across its larger patch, where
    // the full study measures ±14 % beyond 2 mm past the interface).
    let read = |m: &str| {
        let t = Table::read(&out.join(format!("wavespeed/{m}-ux.parquet"))).unwrap();
        let x = t.f64("position", "").unwrap();
        let a = t.f64_opt("arrival_time").unwrap().unwrap();
        x.into_iter()
            .zip(a)
            .filter_map(|(x, a)| a.map(|a| (x, a)))
            .collect::<Vec<_>>()
    };
    let (r, f) = (read("reference"), read("fitted"));
    let at = |x: f64| {
        r.windows(2)
            .find(|w| w[0].0 <= x && x <= w[1].0)
            .map(|w| w[0].1 + (w[1].1 - w[0].1) * (x - w[0].0) / (w[1].0 - w[0].0))
            .expect("the reference's front reaches the membrane's positions")
    };
    let span: Vec<(f64, f64)> = f
        .iter()
        .copied()
        .filter(|(x, _)| *x > 3.6e-3 && *x < 7.5e-3)
        .collect();
    assert!(
        span.len() >= 3,
        "the in-plane front reaches too few membrane nodes: {span:?}"
    );
    let ((xa, ta), (xb, tb)) = (span[0], span[span.len() - 1]);
    let (vf, vr) = ((xb - xa) / (tb - ta), (xb - xa) / (at(xb) - at(xa)));
    let yarn = weft::generate::woven::WovenBandParams::default();
    let c_y = (yarn.modulus / yarn.density).sqrt();
    let c_l = c_y / 2f64.sqrt();
    eprintln!(
        "in-plane front over {:.2}–{:.2} mm: fitted {vf:.0} m/s, reference {vr:.0} m/s; c_L {c_l:.0}, c_y {c_y:.0}",
        xa * 1e3,
        xb * 1e3
    );
    assert!(
        vr > c_l && vr < c_y,
        "reference front {vr:.0} m/s outside [c_L, c_y] = [{c_l:.0}, {c_y:.0}]"
    );
    assert!(
        (vf / c_l - 1.0).abs() < 0.15,
        "fitted membrane's front {vf:.0} m/s vs the lattice's c_L = {c_l:.0} m/s"
    );
    for fig in [
        "uz_crossings.png",
        "uz_field.png",
        "error_fit.png",
        "fit_convergence.png",
    ] {
        assert!(out.join("figures").join(fig).exists(), "{fig}");
    }
    let again = weft_run(root, "woven_membrane.toml");
    assert!(
        again.contains("fresh") && !again.contains("run "),
        "{again}"
    );
}

/// The ballistic-limit study (`pipelines/ballistic_limit.toml`) made small: one layer,
/// five striking velocities around its limit. Each impact's projectile loses the kinetic
/// energy ½M(V_s² − V_r²) (its mass and two speeds: independent of the fabric's ledger)
/// that the layer's watch says the fabric absorbed, within the run's own energy-balance
/// error (measured: the fabric 0.4–1.1 % above, balance errors 0.8–2.1 %); the slower impacts stop
/// and the faster perforate, with V_r < V_s; V50 lies between the fastest stop and the
/// slowest perforation; the figures are written, and a second run is all fresh.
#[test]
fn ballistic_limit_study_runs_small_and_the_energies_agree() {
    let dir = project_with("ballistic_limit.toml");
    let root = dir.path();
    let p = root.join("pipelines/ballistic_limit.toml");
    // Of the foreach rows (one per line), one layer's five; TOML allows the trailing comma.
    let keep = [35, 48, 57, 70, 90].map(|v| format!("{{ layers = 1, velocity = {v} }}"));
    let s: String = std::fs::read_to_string(&p)
        .unwrap()
        .replace(
            "matrix = { layers = [1, 2, 4, 8] }",
            "matrix = { layers = [1] }",
        )
        .lines()
        .filter_map(|l| {
            let row = l.trim().trim_end_matches(',');
            if !row.starts_with("{ layers = ") {
                Some(format!("{l}\n"))
            } else {
                keep.contains(&row.to_string())
                    .then(|| format!("  {row},\n"))
            }
        })
        .collect();
    std::fs::write(&p, &s).unwrap();
    weft_run(root, "ballistic_limit.toml");
    let out = root.join("runs/ballistic_limit");
    let t = Table::read(&out.join("impacts.parquet")).unwrap();
    let col = |c: &str| -> Vec<f64> {
        t.f64_opt(c)
            .unwrap()
            .unwrap_or_else(|| panic!("no {c}"))
            .into_iter()
            .map(|x| x.unwrap_or(0.0))
            .collect()
    };
    let (vs, vr, m) = (
        col("striking_velocity"),
        col("residual_velocity"),
        col("projectile_mass"),
    );
    let (absorbed, bal) = (col("energy_absorbed"), col("max_balance_error_relative"));
    let perf: Vec<bool> = t
        .bool_opt("perforated")
        .unwrap()
        .unwrap()
        .into_iter()
        .map(|x| x.unwrap())
        .collect();
    assert_eq!(vs.len(), 5);
    for i in 0..vs.len() {
        let ke0 = 0.5 * m[i] * vs[i] * vs[i];
        let lost = ke0 - 0.5 * m[i] * vr[i] * vr[i];
        eprintln!(
            "V_s {:.0} m/s: V_r {:.2}, lost {lost:.4} J, absorbed {:.4} J ({:+.2} %), balance {:.2} %",
            vs[i], vr[i], absorbed[i], 100.0 * (absorbed[i] - lost) / ke0, 100.0 * bal[i]
        );
        // An arrested run stops as the nose turns back, pressed into the fabric: the
        // contact springs then hold energy the layers' `absorbed` leaves out (measured
        // 0.29 % and 0.35 % of the impact energy at 35 and 48 m/s, the balance below
        // 0.005 %); a perforated run ends with the nose free.
        let held = if perf[i] { 0.0 } else { 0.005 * ke0 };
        assert!(
            (absorbed[i] - lost).abs() <= bal[i] * ke0 + held + 1e-9,
            "impact at {} m/s",
            vs[i]
        );
        assert!(
            vr[i] < vs[i] && (vr[i] > 0.0) == perf[i],
            "impact at {} m/s",
            vs[i]
        );
    }
    let fastest_stop = (0..5)
        .filter(|&i| !perf[i])
        .map(|i| vs[i])
        .fold(f64::NAN, f64::max);
    let slowest_perf = (0..5)
        .filter(|&i| perf[i])
        .map(|i| vs[i])
        .fold(f64::NAN, f64::min);
    assert!(
        fastest_stop < slowest_perf,
        "stops up to {fastest_stop}, perforations from {slowest_perf}"
    );
    let l = Table::read(&out.join("limit/ballistic_limit.parquet")).unwrap();
    let v50 = l.f64_opt("v50").unwrap().unwrap()[0].unwrap();
    assert!(v50 > fastest_stop && v50 < slowest_perf, "V50 {v50}");
    for fig in ["residual.png", "energy.png", "probability.png", "limit.png"] {
        assert!(out.join("figures").join(fig).exists(), "{fig}");
    }
    let again = weft_run(root, "ballistic_limit.toml");
    assert!(
        again.contains("fresh") && !again.contains("run "),
        "{again}"
    );
}
