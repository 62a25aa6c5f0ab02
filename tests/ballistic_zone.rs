//! `weft-ballistic zone`: the failed zone of impact runs, measured from the projectile's
//! axis.
//!
//! References: a hand-built model whose failed elements lie at distances chosen by hand
//! (3-4-5 triangles about the axis, a triangle's centroid at (2, 2) mm from it), the
//! nearest-rank percentile counted by hand; real runs of `weft-weave woven` (rigid nose
//! and deformable bullet) against the tables themselves: the generators put the strike
//! axis on x = y = 0, so r = √(x̄² + ȳ²) of each failed truss's two nodes
//! (`nodes.parquet`, `elements_truss.parquet`), and the run's own summary counts the
//! failures and times the first.

mod common;
use common::run_ok;
use std::path::{Path, PathBuf};
use weft::model::{ElementKind, Model, PartProps, ProjectileShape, ProjectileSpec};
use weft::table::{batch, write_table, Col, Provenance, Table};

const WEAVE: &str = env!("CARGO_BIN_EXE_weft-weave");
const SIMULATE: &str = env!("CARGO_BIN_EXE_weft-simulate");
const BALLISTIC: &str = env!("CARGO_BIN_EXE_weft-ballistic");

fn prov() -> Provenance {
    Provenance::new("test", serde_json::json!({}))
}

/// One row of `failure_zone.parquet`.
#[derive(Debug)]
struct Row {
    run: String,
    layer: i64,
    failed: i64,
    radius_max: Option<f64>,
    radius_p90: Option<f64>,
    diameter: Option<f64>,
    first: Option<f64>,
    last: Option<f64>,
}

fn read_zone(out: &Path) -> Vec<Row> {
    let t = Table::read(&out.join("failure_zone.parquet")).unwrap();
    let f = |c: &str| t.f64_opt(c).unwrap().unwrap();
    let (run, layer, failed) = (
        t.str("run", "").unwrap(),
        t.i64("layer", "").unwrap(),
        t.i64("failed_elements", "").unwrap(),
    );
    let (rmax, p90, dia, first, last) = (
        f("radius_max"),
        f("radius_p90"),
        f("diameter"),
        f("first_failure_time"),
        f("last_failure_time"),
    );
    (0..t.num_rows())
        .map(|i| Row {
            run: run[i].clone(),
            layer: layer[i],
            failed: failed[i],
            radius_max: rmax[i],
            radius_p90: p90[i],
            diameter: dia[i],
            first: first[i],
            last: last[i],
        })
        .collect()
}

/// The planted model [mm → m]: the projectile's tip at (1, 2, 1) mm flying along −z, so
/// its axis is the line x = 1, y = 2 mm. Layer 1: trusses k = 1..11 from (1 + 0.3k, 2, 0)
/// to (1 + 0.3k, 2 + 0.8k, 0), centroid (1 + 0.3k, 2 + 0.4k): r = 0.5k mm. Layer 2: truss
/// 12 from (−5, −6 ± 1, −1), centroid offset (−6, −8): r = 10 mm; triangle 100 at (1, 2),
/// (7, 2), (1, 8) mm, z = −1, centroid offset (2, 2): r = 2√2 mm; truss 13 at r = 40 mm.
/// Layer 3: truss 14, far away, which never fails.
fn planted_model() -> Model {
    let mm = |x: f64, y: f64, z: f64| [1e-3 * x, 1e-3 * y, 1e-3 * z];
    let mut m = Model::default();
    let truss = m.add_part(
        1,
        "yarn",
        ElementKind::Truss,
        PartProps {
            youngs_modulus: Some(80e9),
            density: Some(1440.0),
            area: Some(1e-8),
            failure_strain: Some(0.036),
            ..Default::default()
        },
    );
    let mut node = 0;
    let mut add = |m: &mut Model, p: [f64; 3]| {
        node += 1;
        m.add_node(node, p)
    };
    let mut layers = vec![];
    for k in 1..=11 {
        let x = 1.0 + 0.3 * k as f64;
        let a = add(&mut m, mm(x, 2.0, 0.0));
        let b = add(&mut m, mm(x, 2.0 + 0.8 * k as f64, 0.0));
        m.add_element(k, truss, &[a, b]);
        layers.push(Some(1));
    }
    for (id, c, half) in [(12, (-5.0, -6.0), 1.0), (13, (25.0, 34.0), 0.5)] {
        let a = add(&mut m, mm(c.0, c.1 - half, -1.0));
        let b = add(&mut m, mm(c.0, c.1 + half, -1.0));
        m.add_element(id, truss, &[a, b]);
        layers.push(Some(2));
    }
    let (a, b) = (
        add(&mut m, mm(50.0, 0.0, -2.0)),
        add(&mut m, mm(51.0, 0.0, -2.0)),
    );
    m.add_element(14, truss, &[a, b]);
    layers.push(Some(3));
    m.elements.get_mut(&ElementKind::Truss).unwrap().layer = layers;
    let membrane = m.add_part(
        2,
        "sheet",
        ElementKind::Tri,
        PartProps {
            youngs_modulus_1: Some(1e9),
            youngs_modulus_2: Some(1e9),
            poisson_ratio_12: Some(0.3),
            shear_modulus_12: Some(0.4e9),
            thickness: Some(1e-4),
            density: Some(1000.0),
            ..Default::default()
        },
    );
    let tri = [(1.0, 2.0), (7.0, 2.0), (1.0, 8.0)].map(|(x, y)| add(&mut m, mm(x, y, -1.0)));
    m.add_element(100, membrane, &tri);
    m.elements.get_mut(&ElementKind::Tri).unwrap().layer = vec![Some(2)];
    m.projectiles.push(ProjectileSpec {
        id: 1,
        shape: ProjectileShape::Sphere,
        radius: 1e-3,
        length: 0.0,
        mass: 1e-3,
        tip: mm(1.0, 2.0, 1.0),
        axis: [0.0, 0.0, -1.0],
        velocity: [0.0, 0.0, -100.0],
        prescribed_velocity: false,
        contact_stiffness: None,
        friction: 0.0,
        contact_damping: 0.0,
        segment_contact: true,
    });
    m
}

/// A failure: (time, kind, id, eroded).
type Planted = (f64, &'static str, i64, bool);

/// A run folder holding only a `failures.parquet` of the planted failures.
fn plant(dir: &Path, failures: &[Planted]) -> PathBuf {
    std::fs::create_dir_all(dir).unwrap();
    write_table(
        &dir.join("failures.parquet"),
        &batch(vec![
            Col::F64("t", failures.iter().map(|f| f.0).collect()),
            Col::I64(
                "step",
                failures.iter().map(|f| (f.0 * 1e9) as i64).collect(),
            ),
            Col::Str(
                "element_kind",
                failures.iter().map(|f| f.1.to_string()).collect(),
            ),
            Col::I64("element_id", failures.iter().map(|f| f.2).collect()),
            Col::Bool("eroded", failures.iter().map(|f| f.3).collect()),
        ]),
        &prov(),
    )
    .unwrap();
    dir.to_path_buf()
}

fn zone(runs: &[&Path], model: &Path, out: &Path) -> std::process::Output {
    let mut args: Vec<String> = vec!["zone".into()];
    for r in runs {
        args.extend(["--run".into(), r.display().to_string()]);
    }
    args.extend([
        "--model".into(),
        model.display().to_string(),
        "--out".into(),
        out.display().to_string(),
    ]);
    std::process::Command::new(BALLISTIC)
        .args(&args)
        .output()
        .unwrap()
}

fn close(a: Option<f64>, b: f64) -> bool {
    // Measured: 0 here (the same roundings as the hand values); the bound allows a few.
    a.is_some_and(|a| (a - b).abs() <= 1e-14 * b.abs())
}

/// The planted failures come back at the distances chosen by hand: layer 1's radii
/// 0.5, 1, …, 5.5 mm (max 5.5, the 90th percentile's nearest rank ⌈0.9·11⌉ = 10: 5 mm,
/// the diameter 11 mm); layer 2's 2√2 and 10 mm (the triangle's failure that did not
/// erode and the truss at 40 mm that failed without eroding do not count); layer 3
/// failed nothing; a run that failed nothing gives every layer 0 and null radii.
#[test]
fn planted_failures_lie_at_the_distances_chosen_by_hand() {
    let dir = tempfile::tempdir().unwrap();
    let model = dir.path().join("model");
    weft::model::io::write_model(&planted_model(), &model, &prov()).unwrap();
    // Layer 1 in shuffled order, times 1..11 µs.
    let mut failures: Vec<Planted> = [7, 2, 11, 1, 5, 9, 3, 10, 4, 8, 6]
        .iter()
        .enumerate()
        .map(|(i, &k)| (1e-6 * (i + 1) as f64, "truss", k, true))
        .collect();
    failures.extend([
        (2.5e-6, "tri", 100, false),
        (3.5e-6, "truss", 13, false),
        (4.5e-6, "truss", 12, true),
        (12e-6, "tri", 100, true),
    ]);
    let hit = plant(&dir.path().join("hit"), &failures);
    let none = plant(&dir.path().join("none"), &[]);
    let out = dir.path().join("zone");
    let o = zone(&[&hit, &none], &model, &out);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let rows = read_zone(&out);
    for r in &rows {
        println!("{r:?}");
    }
    assert_eq!(rows.len(), 6, "two runs × three layers");
    let (l1, l2, l3) = (&rows[0], &rows[1], &rows[2]);
    assert_eq!((l1.run.as_str(), l1.layer), (hit.to_str().unwrap(), 1));
    assert_eq!(l1.failed, 11);
    assert!(close(l1.radius_max, 5.5e-3), "{l1:?}");
    assert!(close(l1.radius_p90, 5.0e-3), "{l1:?}");
    assert!(close(l1.diameter, 11e-3), "{l1:?}");
    assert_eq!((l1.first, l1.last), (Some(1e-6), Some(11e-6)));
    assert_eq!((l2.layer, l2.failed), (2, 2));
    assert!(close(l2.radius_max, 10e-3), "{l2:?}");
    // ⌈0.9·2⌉ = 2: the larger.
    assert!(close(l2.radius_p90, 10e-3), "{l2:?}");
    assert!(close(l2.diameter, 20e-3), "{l2:?}");
    assert_eq!((l2.first, l2.last), (Some(4.5e-6), Some(12e-6)));
    assert_eq!((l3.layer, l3.failed), (3, 0));
    assert!(l3.radius_max.is_none() && l3.diameter.is_none() && l3.first.is_none());
    for (i, r) in rows[3..].iter().enumerate() {
        assert_eq!((r.layer, r.failed), (i as i64 + 1, 0));
        assert!(r.radius_max.is_none() && r.radius_p90.is_none() && r.last.is_none());
    }
    // The triangle alone, eroded: its centroid (3, 4) mm, 2√2 mm from the axis.
    let tri = plant(&dir.path().join("tri"), &[(1e-6, "tri", 100, true)]);
    let o = zone(&[&tri], &model, &out);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let rows = read_zone(&out);
    assert!(
        close(rows[1].radius_max, 2e-3 * 2f64.sqrt()),
        "{:?}",
        rows[1]
    );
}

/// r of each eroded truss of a run from the tables themselves: the centroid of its two
/// nodes, measured from x = y = 0 (the generators' strike axis). Returns (r, t).
fn radii_from_tables(model: &Path, run: &Path) -> Vec<(f64, f64)> {
    let n = Table::read(&model.join("nodes.parquet")).unwrap();
    let (id, x, y) = (
        n.i64("node_id", "").unwrap(),
        n.f64("x", "").unwrap(),
        n.f64("y", "").unwrap(),
    );
    let at = |node: i64| {
        let i = id.iter().position(|&j| j == node).unwrap();
        (x[i], y[i])
    };
    let e = Table::read(&model.join("elements_truss.parquet")).unwrap();
    let (eid, n1, n2) = (
        e.i64("element_id", "").unwrap(),
        e.i64("n1", "").unwrap(),
        e.i64("n2", "").unwrap(),
    );
    let f = Table::read(&run.join("failures.parquet")).unwrap();
    let (t, kind, fid, eroded) = (
        f.f64("t", "").unwrap(),
        f.str("element_kind", "").unwrap(),
        f.i64("element_id", "").unwrap(),
        f.bool("eroded", "").unwrap(),
    );
    (0..f.num_rows())
        .filter(|&i| eroded[i])
        .map(|i| {
            assert_eq!(kind[i], "truss");
            let k = eid.iter().position(|&j| j == fid[i]).unwrap();
            let (a, b) = (at(n1[k]), at(n2[k]));
            let (cx, cy) = (0.5 * (a.0 + b.0), 0.5 * (a.1 + b.1));
            ((cx * cx + cy * cy).sqrt(), t[i])
        })
        .collect()
}

/// Real runs of a small woven patch, with the rigid nose and with the deformable bullet
/// (its axis from its tip face's centre node): the zone's radius is the largest of the
/// failed trusses' distances from x = y = 0 computed from the tables, its failures and
/// first failure time are the summary's, and the diameter is twice the radius.
#[test]
fn the_zone_of_real_runs_agrees_with_the_tables() {
    let dir = tempfile::tempdir().unwrap();
    for projectile in ["rigid", "deformable"] {
        let model = dir.path().join(format!("m-{projectile}"));
        let run = dir.path().join(format!("r-{projectile}"));
        let out = dir.path().join(format!("z-{projectile}"));
        let (m, r, o) = (
            model.to_str().unwrap(),
            run.to_str().unwrap(),
            out.to_str().unwrap(),
        );
        run_ok(
            WEAVE,
            &[
                "woven",
                "--yarns",
                "4",
                "--yarn-model",
                "chain",
                "--failure-strain",
                "0.036",
                "--stop-on-outcome",
                "--projectile",
                projectile,
                "--out",
                m,
            ],
        );
        run_ok(
            SIMULATE,
            &[
                "--model",
                m,
                "--out",
                r,
                "--projectile-velocity",
                "400",
                "--quiet",
            ],
        );
        run_ok(BALLISTIC, &["zone", "--run", r, "--model", m, "--out", o]);
        let rows = read_zone(&out);
        assert_eq!(rows.len(), 1, "one layer");
        let z = &rows[0];
        let radii = radii_from_tables(&model, &run);
        let rmax = radii.iter().map(|r| r.0).fold(0.0, f64::max);
        let s = Table::read(&run.join("summary.parquet")).unwrap();
        let failed = s.i64("failed_elements", "").unwrap()[0];
        let first = s.f64_opt("first_failure_time").unwrap().unwrap()[0];
        println!(
            "{projectile}: {failed} failed, radius {:?} vs {rmax:e} from the tables, p90 {:?}, first {:?}",
            z.radius_max, z.radius_p90, z.first
        );
        assert!(failed > 0 && z.failed == failed && radii.len() as i64 == failed);
        assert!(close(z.radius_max, rmax), "{z:?} vs {rmax}");
        assert_eq!(z.diameter, z.radius_max.map(|r| 2.0 * r));
        assert!(z.radius_p90.unwrap() <= rmax);
        assert_eq!(z.first, first);
        assert_eq!(z.last, Some(radii.iter().map(|r| r.1).fold(0.0, f64::max)));
    }
}

/// Bad input is named: a run without failures.parquet (its model had no failure law), a
/// failed element that is not in the model (its id, kind and both folders), a run of
/// another model (the nodes of its summary), a model without a projectile.
#[test]
fn bad_zone_input_is_named() {
    let dir = tempfile::tempdir().unwrap();
    let d = |s: &str| dir.path().join(s);
    let (m, r) = (d("plain"), d("plain-run"));
    run_ok(
        WEAVE,
        &[
            "woven",
            "--yarns",
            "4",
            "--yarn-model",
            "chain",
            "--end-time",
            "2e-6",
            "--out",
            m.to_str().unwrap(),
        ],
    );
    run_ok(
        SIMULATE,
        &[
            "--model",
            m.to_str().unwrap(),
            "--out",
            r.to_str().unwrap(),
            "--quiet",
        ],
    );
    let err = |o: std::process::Output| {
        assert!(!o.status.success());
        String::from_utf8_lossy(&o.stderr).to_string()
    };
    let e = err(zone(&[&r], &m, &d("z")));
    assert!(
        e.contains("no failures.parquet")
            && e.contains("no failure law")
            && e.contains("--failure-strain")
            && e.contains("plain-run"),
        "{e}"
    );
    let planted = d("planted");
    weft::model::io::write_model(&planted_model(), &planted, &prov()).unwrap();
    let stray = plant(&d("stray"), &[(1e-6, "truss", 999, true)]);
    let e = err(zone(&[&stray], &planted, &d("z")));
    assert!(
        e.contains("999")
            && e.contains("`truss`")
            && e.contains("stray")
            && e.contains("planted")
            && e.contains("element_id"),
        "{e}"
    );
    let odd = plant(&d("odd"), &[(1e-6, "blob", 1, true)]);
    let e = err(zone(&[&odd], &planted, &d("z")));
    assert!(e.contains("`blob`") && e.contains("odd"), "{e}");
    // The plain model's run (120 nodes) against the planted model (31 nodes): its ids
    // would all be there, so the summary's node count refuses it.
    std::fs::copy(stray.join("failures.parquet"), r.join("failures.parquet")).unwrap();
    let e = err(zone(&[&r], &planted, &d("z")));
    assert!(
        e.contains("120 nodes") && e.contains("has 31") && e.contains("plain-run"),
        "{e}"
    );
    let mut bare = planted_model();
    bare.projectiles.clear();
    weft::model::io::write_model(&bare, &d("bare"), &prov()).unwrap();
    let e = err(zone(&[&stray], &d("bare"), &d("z")));
    assert!(e.contains("no projectile") && e.contains("bare"), "{e}");
    let e = err(zone(&[&d("nowhere")], &planted, &d("z")));
    assert!(e.contains("nowhere"), "{e}");
}
