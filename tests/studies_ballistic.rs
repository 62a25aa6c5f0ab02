//! The paper's reductions judged by the ballistic limit, made small enough for CI: the
//! §5 girder's V50 with a fitted failure strain (`pipelines/woven_reduced_ballistic.toml`),
//! run end to end through `weft run` in a fresh project.

mod common;
use common::{project_with, weft_run};
use std::collections::BTreeMap;
use std::path::Path;

use weft::table::Table;

/// Rewrites the pipeline's text by (from, to) pairs, each of which must occur.
fn shrink(root: &Path, pipeline: &str, edits: &[(&str, &str)]) {
    let p = root.join("pipelines").join(pipeline);
    let mut s = std::fs::read_to_string(&p).unwrap();
    for (from, to) in edits {
        assert!(s.contains(from), "{pipeline} has no `{from}`");
        s = s.replace(from, to);
    }
    std::fs::write(&p, s).unwrap();
}

/// Every value of a float column that has no nulls.
fn f64s(t: &Table, c: &str) -> Vec<f64> {
    t.f64_opt(c)
        .unwrap()
        .unwrap_or_else(|| panic!("no column {c}"))
        .into_iter()
        .map(|x| x.unwrap())
        .collect()
}

/// Per group (a string column) of a ballistic_limit.parquet: (V50, fastest stop, slowest
/// perforation).
fn limits(path: &Path, by: &str) -> BTreeMap<String, (f64, f64, f64)> {
    let t = Table::read(path).unwrap();
    let groups: Vec<String> = t
        .str_opt(by)
        .unwrap()
        .unwrap()
        .into_iter()
        .map(|x| x.unwrap())
        .collect();
    let (v50, lo, hi) = (
        f64s(&t, "v50"),
        f64s(&t, "fastest_stop"),
        f64s(&t, "slowest_perforation"),
    );
    groups
        .into_iter()
        .enumerate()
        .map(|(i, g)| (g, (v50[i], lo[i], hi[i])))
        .collect()
}

/// §5 small: the reference a quarter 5 × 5-yarn patch in the membrane out to 20 mm, the
/// girder at its crossings. The girder's failure strain fitted to the reference's
/// projectile velocity histories lowers that mismatch (the fit's last evaluation against
/// its start), and the fitted girder's V50 lies nearer the reference's than the trial
/// girder's, whose rods fail at the yarn's strain (a rod of a whole spacing, straight, is
/// strained unlike the bands it stands for, so the yarn's strain is no more than a start),
/// and equals the reference's within what the searches resolve (1 m/s).
#[test]
fn fitted_girder_v50_is_nearer_the_reference_than_the_trial_girder() {
    let dir = project_with("woven_reduced_ballistic.toml");
    let root = dir.path();
    shrink(
        root,
        "woven_reduced_ballistic.toml",
        &[
            ("yarns = 11", "yarns = 5"),
            ("half_size = 0.05", "half_size = 0.02"),
            ("girder = 20", "girder = 8"),
            ("side = 0.1", "side = 0.04"),
            ("tolerance = 2", "tolerance = 1"),
            ("--max-evaluations 20", "--max-evaluations 12"),
            // No V50 of the combined models (6 and 8 crossings, woven but larger than
            // this reference of 5): the §3 test below judges that reduction.
            (
                "  { variant = \"combined_6\", path = \"models/combined/6\" },\n  { variant = \"combined_8\", path = \"models/combined/8\" },\n",
                "",
            ),
        ],
    );
    weft_run(root, "woven_reduced_ballistic.toml");
    let out = root.join("runs/woven_reduced_ballistic");
    let l = limits(&out.join("limit/ballistic_limit.parquet"), "variant");
    let (r, t, f) = (l["reference"].0, l["trial"].0, l["fitted"].0);
    eprintln!("V50: reference {r:.1}, trial girder {t:.1}, fitted girder {f:.1} m/s");
    assert!(
        (f - r).abs() < (t - r).abs(),
        "fitted {f} is not nearer the reference {r} than the trial {t}"
    );
    // The independent expectation: the fit matched the projectile's velocity history,
    // not its limit, so a girder that stands for the reference (the paper's §5) has the
    // reference's V50 to what the searches resolve: each is the middle of a bracket
    // 1 m/s wide around its limit, so two equal limits give V50s within 1 m/s. Measured
    // 2026-11-29: reference 20.1, fitted 20.4 (0.3 apart), the trial 22.2 (2.1 apart:
    // this check alone tells it from the fitted girder).
    assert!(
        (f - r).abs() <= 1.0,
        "the fitted girder's V50 {f:.2} m/s is not the reference's {r:.2} within the searches' 1 m/s"
    );
    let trace = Table::read(&out.join("fit/fit_trace.parquet")).unwrap();
    let obj = f64s(&trace, "T");
    let best = obj.iter().cloned().fold(f64::INFINITY, f64::min);
    eprintln!("projectile mismatch: start {:.3e}, best {best:.3e}", obj[0]);
    assert!(best < obj[0]);
    assert!(out.join("figures/residual.png").exists());
}

/// Per patch size (an integer column) of a ballistic_limit.parquet: V50.
fn v50_by_patch(path: &Path) -> BTreeMap<i64, f64> {
    let t = Table::read(path).unwrap();
    let n = t.i64_opt("patch").unwrap().unwrap();
    n.into_iter()
        .map(|n| n.unwrap())
        .zip(f64s(&t, "v50"))
        .collect()
}

/// §3 small: the reference a clamped quarter 12 × 12-yarn patch of truss chains, the
/// combined models the quarter 6 × 6 and 9 × 9 patches in the paper's membrane out to the
/// same 11.5 mm. At N = 12 the combined model is the reference itself, and the membrane
/// replaces the yarns beyond N: the larger patch keeps more of the yarns that take the
/// load, so its V50 lies nearer the reference's; and a patch the paper's sizing rule
/// admits (twice the failed zone's diameter) has the reference's V50. Measured
/// (2026-11-29): V50 16.0 m/s (N = 6, bracket 15.4–16.7), 17.3 (N = 9, 16.7–18.0), 17.3
/// (reference, 16.7–18.0); the reference's failed zone 7.52 mm across.
/// (In the full study, reference 24, the combined models' V50s lie above the
/// reference's and fall towards it: docs/studies/woven_membrane_ballistic.md.)
#[test]
fn combined_model_v50_approaches_the_reference_as_the_patch_grows() {
    let dir = project_with("woven_membrane_ballistic.toml");
    let root = dir.path();
    shrink(
        root,
        "woven_membrane_ballistic.toml",
        &[
            ("reference = 24", "reference = 12"),
            ("length = 0.0235", "length = 0.0115"),
            ("tolerance = 2", "tolerance = 1.5"),
            ("hi = 150", "hi = 40"),
            ("[6, 8, 12, 16, 24]", "[6, 9, 12]"),
            ("[6, 8, 12, 16]", "[6, 9]"),
        ],
    );
    weft_run(root, "woven_membrane_ballistic.toml");
    let out = root.join("runs/woven_membrane_ballistic");
    let v = v50_by_patch(&out.join("limit/ballistic_limit.parquet"));
    eprintln!("V50 by patch size: {v:?}");
    let e = |n: i64| (v[&n] - v[&12]).abs();
    assert!(
        e(9) < e(6),
        "V50 error of N = 9 ({:.2} m/s) is not below that of N = 6 ({:.2} m/s)",
        e(9),
        e(6)
    );
    let zones = Table::read(&out.join("failure_zones.parquet")).unwrap();
    assert_eq!(zones.num_rows(), 3, "one failed zone per model");
    // The paper's sizing rule as the independent expectation: a patch "at least twice
    // greater than the diameter of the zone at which the failure of yarns may take place"
    // stands for the reference. Its full width 2Np (p = 1 mm, weft-weave's default
    // spacing) against twice the reference's failed zone (measured: 7.52 mm, so N ≥ 7.5):
    // every N the rule admits has the reference's V50 within the search's tolerance
    // (measured: N = 9, 17.31 m/s, the reference's bracket), and the rule admits N = 9.
    let zp: Vec<i64> = zones
        .i64_opt("patch")
        .unwrap()
        .unwrap()
        .into_iter()
        .map(|x| x.unwrap())
        .collect();
    let zd = f64s(&zones, "diameter");
    let d_ref = zd[zp
        .iter()
        .position(|&n| n == 12)
        .expect("the reference's zone")];
    eprintln!(
        "failed zones' diameters: {:?}",
        zp.iter().zip(&zd).collect::<Vec<_>>()
    );
    let admitted: Vec<i64> = [6, 9]
        .into_iter()
        .filter(|&n| 2.0 * n as f64 * 1e-3 >= 2.0 * d_ref)
        .collect();
    assert!(
        admitted.contains(&9),
        "the rule admits {admitted:?} (zone {d_ref} m)"
    );
    for n in admitted {
        assert!(
            (v[&n] - v[&12]).abs() <= 1.5,
            "N = {n} meets the sizing rule (2Np ≥ 2 × {d_ref:.4} m) but its V50 {:.2} m/s is not the reference's {:.2} within the search's 1.5 m/s",
            v[&n],
            v[&12]
        );
    }
    assert!(out.join("figures/v50_patch.png").exists());
    assert!(out.join("figures/residual.png").exists());
}
