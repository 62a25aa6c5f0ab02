//! The backing clay of the armour test (`weft-weave clay-drop`, `weft-ballistic
//! clay-calibration`): the sphere's impact on an elastic block against Hertz's theory,
//! the calibrated clay against the standard's drop band, and bad input.

mod common;
use common::*;
use weft::table::Table;

const WEAVE: &str = env!("CARGO_BIN_EXE_weft-weave");
const BALLISTIC: &str = env!("CARGO_BIN_EXE_weft-ballistic");

/// Weaves a drop model into `dir/name` with `args` after the defaults, runs the
/// calibration on it into `dir/name-cal`; the calibration's table, the drop's history
/// table and the command's success.
fn drop(dir: &std::path::Path, name: &str, args: &[&str]) -> (Table, Table, bool, String) {
    let m = dir.join(name);
    let mut a = vec!["clay-drop", "--out", m.to_str().unwrap()];
    a.extend_from_slice(args);
    run_ok(WEAVE, &a);
    let out = dir.join(format!("{name}-cal"));
    let o = std::process::Command::new(BALLISTIC)
        .args([
            "clay-calibration",
            "--model",
            m.to_str().unwrap(),
            "--threads",
            "2",
            "--out",
            out.to_str().unwrap(),
        ])
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&o.stderr).to_string();
    let cal =
        Table::read(&out.join("clay_calibration.parquet")).unwrap_or_else(|e| panic!("{e}: {err}"));
    let hist = Table::read(&out.join("clay_drop.parquet")).unwrap();
    (cal, hist, o.status.success(), err)
}

fn one(t: &Table, c: &str) -> f64 {
    t.f64(c, "").unwrap()[0]
}

/// The node id of the one node in node set `set` of the model `dir/m` next to the
/// results folder `r` (`weave_and_simulate`'s).
fn node_id_in_set(r: &std::path::Path, set: &str) -> i64 {
    let t = Table::read(&r.with_file_name("m").join("node_sets.parquet")).unwrap();
    let (names, ids) = (t.str("set", "").unwrap(), t.i64("node_id", "").unwrap());
    let mut found = (0..ids.len()).filter(|&i| names[i] == set).map(|i| ids[i]);
    let id = found.next().unwrap();
    assert!(found.next().is_none(), "`{set}` holds more than one node");
    id
}

/// Weaves `dir/m` (`weave`: the subcommand, then its flags) and runs weft-simulate on it
/// on 2 threads with the flags `simulate` into `dir/r`; returns `dir/r`.
fn weave_and_simulate(
    dir: &std::path::Path,
    weave: &[&str],
    simulate: &[&str],
) -> std::path::PathBuf {
    let (m, r) = (dir.join("m"), dir.join("r"));
    let mut a = vec![weave[0], "--out", m.to_str().unwrap()];
    a.extend_from_slice(&weave[1..]);
    run_ok(WEAVE, &a);
    let mut a = vec![
        "--model",
        m.to_str().unwrap(),
        "--out",
        r.to_str().unwrap(),
        "--threads",
        "2",
        "--quiet",
    ];
    a.extend_from_slice(simulate);
    run_ok(env!("CARGO_BIN_EXE_weft-simulate"), &a);
    r
}

/// The standard's sphere (63.5 mm, 1043 g) dropped 51 mm (1 m/s) on a block that does
/// not yield (A = 10¹² Pa: the clay's elasticity alone, E = 20 MPa, ν = 0.45) is Hertz's
/// impact of a rigid sphere on an elastic half-space (Hertz 1882; Johnson, *Contact
/// Mechanics*, 1985, §11.4): the largest approach δ = (15 m v²/(16 E* √R))^{2/5} with
/// E* = E/(1 − ν²), the contact lasting t_c = 2.943 δ/v, and the sphere leaving at its
/// striking speed. Here δ = 2.168 mm (a = √(Rδ) = 8.3 mm, 6.6 cells of 1.25 mm), t_c =
/// 6.38 ms. The drop into cells of `formulation`; (δ, t_c, speed out) measured against
/// Hertz's, each relative, and the run's largest balance error.
fn hertz_drop(formulation: &str) -> (f64, f64, f64, f64) {
    let dir = tempfile::tempdir().unwrap();
    let (cal, hist, ok, err) = drop(
        dir.path(),
        "hertz",
        &[
            "--clay-a",
            "1e12",
            "--clay-fine",
            "1.25e-3",
            "--clay-fine-half",
            "12.5e-3",
            "--clay-fine-depth",
            "7.5e-3",
            "--clay-half-width",
            "0.1",
            "--clay-depth",
            "0.06",
            "--clay-growth",
            "1.5",
            "--height",
            "0.050985",
            "--end-time",
            "7.5e-3",
            "--output-interval",
            "1e-5",
            "--clay-formulation",
            formulation,
        ],
    );
    // An elastic crater closes: outside the band, the exit status says so, the tables
    // are written.
    assert!(!ok && err.contains("OUTSIDE the band"), "{err}");
    let (e, nu) = (20e6, 0.45);
    let (r, m, v): (f64, f64, f64) = (0.5 * 63.5e-3, 1.043, one(&cal, "striking_velocity"));
    assert!((v - 1.0).abs() < 1e-4, "{v}");
    let es = e / (1.0 - nu * nu);
    let delta = (15.0 * m * v * v / (16.0 * es * r.sqrt())).powf(0.4);
    let tc = 2.9432 * delta / v;
    let d_max = hist
        .f64("sphere_depth", "")
        .unwrap()
        .into_iter()
        .fold(0.0, f64::max);
    let (ts, vout) = (one(&cal, "separation_time"), one(&cal, "rebound_velocity"));
    eprintln!("{err}{formulation}: Hertz δ {delta:.4e} m, t_c {tc:.4e} s; weft δ {d_max:.4e}, t_c {ts:.4e}, out {vout:.4} m/s");
    (
        d_max / delta - 1.0,
        ts / tc - 1.0,
        vout / v - 1.0,
        one(&cal, "max_balance_error_relative"),
    )
}

/// One-point cells (the default). Measured: δ 2.223 mm (+2.5 %: the penalty's give and
/// the 1.25 mm cells), t_c 6.51 ms (+2.0 %, the first 10 µs sample after the sphere
/// left), 0.997 m/s out, balance 1.7e-5.
#[test]
fn an_elastic_block_meets_the_sphere_as_hertz_says() {
    let (d, t, out, balance) = hertz_drop("one-point");
    // Tolerances about twice the measured differences.
    assert!(d.abs() < 0.05, "δ {d:+e} against Hertz");
    assert!(t.abs() < 0.04, "t_c {t:+e} against Hertz");
    assert!(out.abs() < 0.01, "out at {out:+e} of the speed in");
    assert!(balance < 5e-5);
}

/// The same drop into selective-reduced cells (eight points, no hourglass control: the
/// knob-free element the one-point one is checked against). Measured: δ 2.218 mm
/// (+2.3 %), t_c 6.49 ms (+1.7 %), 0.9993 m/s out (the one-point cells' viscous
/// hourglass control took 0.3 % of the speed, these nothing but the bulk viscosity's
/// 0.07 %), balance 6.6e-6. The run costs 9.3 times the one-point's (90 s against
/// 9.7 s on one thread).
#[test]
fn selective_reduced_cells_meet_the_sphere_as_hertz_says() {
    let (d, t, out, balance) = hertz_drop("selective-reduced");
    assert!(d.abs() < 0.05, "δ {d:+e} against Hertz");
    assert!(t.abs() < 0.035, "t_c {t:+e} against Hertz");
    assert!(out.abs() < 0.002, "out at {out:+e} of the speed in");
    assert!(balance < 2e-5);
}

/// The clay as weft ships it (Roma Plastilina No. 1 calibrated, the default block and
/// cells of 3 mm), struck as NIJ Standard-0101.06 calibrates it: the indentation within
/// the standard's 19 ± 3 mm, and `clay_calibration.parquet` says so with the constants
/// used. Measured: 19.00 mm (18.93 with 2 mm cells, 19.12 with 4 mm: the depth moves by
/// 0.4 % from 3 to 2 mm); the energy balance 2.3e-5.
#[test]
fn the_standard_drop_indents_the_shipped_clay_within_the_band() {
    let dir = tempfile::tempdir().unwrap();
    let (cal, hist, ok, err) = drop(dir.path(), "drop", &[]);
    eprintln!("{err}");
    assert!(ok, "{err}");
    let d = one(&cal, "indentation");
    assert!(
        (one(&cal, "band_low")..=one(&cal, "band_high")).contains(&d),
        "indentation {d} m"
    );
    assert_eq!(
        (one(&cal, "band_low"), one(&cal, "band_high")),
        (0.016, 0.022)
    );
    assert!(cal.bool("in_band", "").unwrap()[0]);
    // The drop as the standard gives it: 1043 g, 63.5 mm, 2.0 m.
    assert!((one(&cal, "sphere_mass") - 1.043).abs() < 1e-12);
    assert!((one(&cal, "sphere_diameter") - 0.0635).abs() < 1e-12);
    assert!((one(&cal, "drop_height") - 2.0).abs() < 1e-9);
    assert!(one(&cal, "plasticine_a") > 0.0 && one(&cal, "cell_size") == 3e-3);
    // The depth at the end is the last sample's of the history, and the sphere left.
    let depth = hist.f64("depth", "").unwrap();
    assert_eq!(*depth.last().unwrap(), d);
    assert!(one(&cal, "rebound_velocity") > 0.0);
    assert!(one(&cal, "max_balance_error_relative") < 1e-4);
}

/// Bad input names the flag, the value and what was expected; a model that is not a
/// drop is refused by name.
#[test]
fn bad_clay_input_is_named() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("m");
    for (flag, v, expect) in [
        ("--clay-a", "-1", "--clay-a = `-1`"),
        ("--clay-m", "1.5", "--clay-m = `1.5`"),
        ("--clay-density", "0", "--clay-density = `0`"),
        ("--clay-fine-depth", "0.5", "--clay-fine-depth = `0.5`"),
        ("--clay-growth", "0.9", "--clay-growth = `0.9`"),
        ("--clay-half-width", "0.02", "not smaller than the clay box"),
        ("--mass", "0", "--mass = `0`"),
    ] {
        let o = std::process::Command::new(WEAVE)
            .args(["clay-drop", "--out", out.to_str().unwrap(), flag, v])
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(!o.status.success(), "{flag} {v}");
        assert!(err.contains(expect), "{flag} {v}: {err}");
        assert!(!err.contains("panicked"), "{err}");
    }
    // A woven patch is not a drop.
    let patch = dir.path().join("patch");
    run_ok(
        WEAVE,
        &[
            "woven",
            "--yarns",
            "2",
            "--yarn-model",
            "chain",
            "--out",
            patch.to_str().unwrap(),
        ],
    );
    let o = std::process::Command::new(BALLISTIC)
        .args([
            "clay-calibration",
            "--model",
            patch.to_str().unwrap(),
            "--out",
            dir.path().join("c").to_str().unwrap(),
        ])
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        !o.status.success() && err.contains("clay_axis_top"),
        "{err}"
    );
}

/// A clay cell that erodes (`--clay-erosion-strain`) is a failure like any other
/// element's: failures.parquet lists it (`hex`, criterion `plastic_strain`, its ε_p at or
/// above the limit), the summary counts it, and the element results say the same
/// independently: at the end, the cells of plastic strain ≥ the limit are exactly the
/// eroded ones, their stress zero. Before, a hexahedron's erosion went unreported. The
/// standard's sphere's size, 9 mm and 8 g, at 60 m/s into 1 mm cells, eroded at ε_p = 1.5
/// (without erosion those cells invert at 130 µs). Measured: 25 cells eroded by 150 µs,
/// the balance 4.7e-5 (tolerance 3e-4: the erosion's abrupt loss of a cell's elastic
/// energy is bounded by the balance check, not booked). The crater's floor on the axis
/// (`bfs.parquet`) is then the clay left under the eroded cells, not their orphaned node.
#[test]
fn an_eroded_clay_cell_is_a_reported_failure() {
    let dir = tempfile::tempdir().unwrap();
    let r = weave_and_simulate(
        dir.path(),
        &eroding_drop("20e-3", "0.06"),
        &["--element-results", "clay"],
    );
    let f = Table::read(&r.join("failures.parquet")).unwrap();
    let kind = f.str("element_kind", "").unwrap();
    let crit = f.str("criterion", "").unwrap();
    let (value, limit) = (f.f64("value", "").unwrap(), f.f64("limit", "").unwrap());
    let ids = f.i64("element_id", "").unwrap();
    assert!(!ids.is_empty(), "no cell eroded");
    for i in 0..ids.len() {
        assert_eq!(
            (kind[i].as_str(), crit[i].as_str()),
            ("hex", "plastic_strain")
        );
        assert!(
            value[i] >= limit[i] && limit[i] == 1.5,
            "{} {}",
            value[i],
            limit[i]
        );
    }
    let s = Table::read(&r.join("summary.parquet")).unwrap();
    assert_eq!(s.i64("failed_elements", "").unwrap()[0], ids.len() as i64);
    // The element results at the last output time.
    let el = Table::read(&r.join("elements.parquet")).unwrap();
    let t = el.f64("t", "").unwrap();
    let last = t.iter().cloned().fold(f64::NEG_INFINITY, f64::max);
    let (eid, ep, vm) = (
        el.i64("element_id", "").unwrap(),
        el.f64_opt("plastic_strain").unwrap().unwrap(),
        el.f64_opt("von_mises_stress").unwrap().unwrap(),
    );
    let mut over: Vec<i64> = (0..t.len())
        .filter(|&i| t[i] == last && ep[i].unwrap() >= 1.5)
        .map(|i| eid[i])
        .collect();
    over.sort();
    let mut eroded = ids.clone();
    eroded.sort();
    eprintln!("{} cells eroded by {last:e} s", eroded.len());
    assert_eq!(over, eroded, "the cells at ε_p ≥ 1.5 are the eroded ones");
    for i in (0..t.len()).filter(|&i| t[i] == last && ep[i].unwrap() >= 1.5) {
        assert_eq!(vm[i], Some(0.0), "an eroded cell carries no stress");
    }
    let bal = s.f64("max_balance_error_relative", "").unwrap()[0];
    eprintln!("balance {bal:.2e}");
    assert!(bal < 3e-4, "balance {bal}");
    // The crater is read from the clay that is left. The axis's top node belongs to one
    // cell (a quarter model's corner); once that cell erodes the node is a free mass that
    // the sphere kicks ahead of itself (history.parquet: faster than the sphere, deeper
    // than its tip). The crater's floor there is the node below it, which a rigid sphere
    // cannot have passed: no deeper than the sphere's tip, and behind it by at most a cell
    // (1 mm; the contact lets the sphere travel v·Δt ≈ 0.2 mm a step of the clay's 4 µs
    // into it before the penalty answers).
    let last_of = |table: &Table| {
        let t = table.f64("t", "").unwrap();
        let end = t.iter().cloned().fold(f64::NEG_INFINITY, f64::max);
        (t, end)
    };
    let p = Table::read(&r.join("projectile.parquet")).unwrap();
    let (pt, end) = last_of(&p);
    let tip = -p.f64("z", "").unwrap()[pt.iter().position(|&x| x == end).unwrap()];
    let h = Table::read(&r.join("history.parquet")).unwrap();
    let (ht, _) = last_of(&h);
    let hid = h.i64("node_id", "").unwrap();
    let huz = h.f64("uz", "").unwrap();
    let axis_node = node_id_in_set(&r, "clay_axis_top");
    let orphan = (0..ht.len())
        .find(|&i| ht[i] == end && hid[i] == axis_node)
        .map(|i| -huz[i])
        .unwrap();
    let b = Table::read(&r.join("bfs.parquet")).unwrap();
    let (bt, _) = last_of(&b);
    let (r0, depth) = (b.f64("r0", "").unwrap(), b.f64("depth", "").unwrap());
    let floor = depth[(0..bt.len())
        .find(|&i| bt[i] == end && r0[i] == 0.0)
        .unwrap()];
    eprintln!(
        "at {end:e} s: sphere's tip {tip:.4e} m deep, the axis's orphaned top node {orphan:.4e} m, the crater's floor {floor:.4e} m"
    );
    // Measured: tip 8.803 mm, orphan 12.03 mm, floor 8.424 mm.
    assert!(
        orphan > tip,
        "the axis's top node did not fly ahead ({orphan} m, tip {tip} m)"
    );
    assert!(
        floor <= tip + 1e-5 && floor > tip - 1e-3,
        "the crater's floor {floor} m against the tip at {tip} m"
    );
    let summary_bfs = s.f64_opt("bfs").unwrap().unwrap()[0].unwrap();
    assert!(
        summary_bfs < tip + 1e-5,
        "summary bfs {summary_bfs} m, tip {tip} m"
    );
}

/// `weft-weave clay-drop`'s flags for the standard's sphere's size, 9 mm and 8 g, at
/// 60 m/s (dropped 183.5 m) into 1 mm cells eroded at ε_p = 1.5, in a block
/// `depth` deep whose fine cells reach `fine_depth` [m], to 150 µs.
fn eroding_drop(fine_depth: &'static str, depth: &'static str) -> Vec<&'static str> {
    vec![
        "clay-drop",
        "--clay-fine",
        "1e-3",
        "--clay-fine-half",
        "15e-3",
        "--clay-fine-depth",
        fine_depth,
        "--clay-half-width",
        "0.1",
        "--clay-depth",
        depth,
        "--clay-erosion-strain",
        "1.5",
        "--diameter",
        "9e-3",
        "--mass",
        "8e-3",
        "--height",
        "183.5",
        "--end-time",
        "1.5e-4",
        "--output-interval",
        "5e-6",
    ]
}

/// A ply on the clay (`weft-weave woven --backing clay`), struck at 100 m/s by the rigid
/// 9 mm nose: the clay's top under the shot follows the pack's back face, as contact
/// without interpenetration or lift-off requires: the crater's depth on the axis
/// (`bfs.parquet`) equals the back ply's deflection (`ballistic.parquet`) to within the
/// initial separation of the two surfaces (half the chains' contact thickness and the
/// layer gap, 93 µm: it can at most close; a lift-off opens it), measured 19 µm. The
/// crater is a crater: its depth falls from the axis outwards to its rim, not rising by
/// more than 3 % of the axis depth between neighbouring points (measured 0.9 %, at
/// 15 µs; a surface that corrugates cell by cell under the yarns, as the drop's
/// Q_hg = 0.1 lets it under 4 plies, rises by 17 %). The energy balance 7.8e-5 (tolerance
/// 1.5e-4: 2.0e-4 under the per-face contact law, an experiment not kept);
/// `bfs` in the summary is the crater's deepest point at the end. All this with the clay
/// kept whole (`--clay-erosion-strain 0`); under the default erosion (1.5) the cells
/// under the nose erode from 39 µs on, the axis's at 51–57 µs, and the crater (the clay
/// left) then leads the back face by the void of the eroded cell until the ply closes it:
/// by at most one cell (1 mm; measured 0.55 mm at 55 µs, 0.34 mm at 60 µs), never
/// behind it by more than the surfaces' separation; balance 2.1e-4 (tolerance 4e-4).
#[test]
fn a_ply_on_the_clay_presses_a_crater_that_follows_its_back_face() {
    let dir = tempfile::tempdir().unwrap();
    // The shot: one ply of the 8 × 8 chain patch in a 50 mm membrane at 100 m/s.
    let shot = [
        "woven",
        "--yarns",
        "8",
        "--yarn-model",
        "chain",
        "--membrane-length",
        "0.05",
        "--failure-strain",
        "0.036",
        "--projectile-velocity",
        "100",
        "--end-time",
        "6e-5",
        "--output-interval",
        "5e-6",
        "--backing",
        "clay",
        "--projectile",
        "rigid",
        "--clay-fine-half",
        "0.012",
        "--clay-fine-depth",
        "0.012",
        "--clay-half-width",
        "0.1",
        "--clay-depth",
        "0.06",
    ];
    let whole = [&shot[..], &["--clay-erosion-strain", "0"]].concat();
    let r = weave_and_simulate(dir.path(), &whole, &[]);
    let s = Table::read(&r.join("summary.parquet")).unwrap();
    let balance = one(&s, "max_balance_error_relative");
    assert!(balance < 1.5e-4, "energy balance {balance}");
    // Pressed, not perforated (no yarn breaks at 100 m/s on the clay by 60 µs).
    assert_eq!(s.i64_opt("plies_perforated").unwrap().unwrap()[0], Some(0));
    let b = Table::read(&r.join("bfs.parquet")).unwrap();
    let (t, r0, depth) = (
        b.f64("t", "").unwrap(),
        b.f64("r0", "").unwrap(),
        b.f64("depth", "").unwrap(),
    );
    let l = Table::read(&r.join("ballistic.parquet")).unwrap();
    let deflection = l.f64("deflection", "").unwrap();
    let lt = l.f64("t", "").unwrap();
    // One row per output time and profile point, the axis first.
    let points = r0.iter().filter(|&&x| x == r0[0]).count();
    assert_eq!(points, lt.len(), "one axis point per output time");
    let per = t.len() / lt.len();
    assert_eq!(per * lt.len(), t.len());
    let mut deepest_now = 0.0;
    for (k, (&tk, &d)) in lt.iter().zip(&deflection).enumerate() {
        let row = &depth[k * per..(k + 1) * per];
        assert_eq!(t[k * per], tk);
        assert_eq!(r0[k * per], 0.0, "the profile starts on the axis");
        assert!(
            (row[0] - d).abs() < 93e-6,
            "t = {tk:e}: crater {} m against the back face's {d} m",
            row[0]
        );
        for w in row.windows(2).take_while(|w| w[1] > 0.0) {
            assert!(
                w[1] - w[0] < 0.03 * row[0],
                "t = {tk:e}: the crater rises outwards by {} m at {} m deep on the axis",
                w[1] - w[0],
                row[0]
            );
        }
        deepest_now = row.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    }
    assert!(deflection.last().unwrap() > &4e-3, "the pack went in");
    // The summary's is the run's last step's, the table's the output sample at or before it.
    let bfs = one(&s, "bfs");
    assert!(
        (bfs - deepest_now).abs() < 1e-3 * bfs,
        "bfs {bfs} against {deepest_now}"
    );
    // `weft-plot crater` draws both figures from the table, and names a bad flag.
    let plot = env!("CARGO_BIN_EXE_weft-plot");
    let table = r.join("bfs.parquet");
    for (kind, out) in [("depth", "depth.svg"), ("profile", "profile.svg")] {
        let out = dir.path().join(out);
        let mut a = vec![
            "crater",
            "--bfs",
            table.to_str().unwrap(),
            "--kind",
            kind,
            "--limit",
            "0.044",
            "--out",
            out.to_str().unwrap(),
        ];
        if kind == "profile" {
            a.extend(["--time", "3e-5", "--max-radius", "0.03"]);
        }
        run_ok(plot, &a);
        let svg = std::fs::read_to_string(&out).unwrap();
        assert!(
            svg.contains("<polyline") || svg.contains("<path"),
            "{kind}: nothing drawn"
        );
    }
    let o = std::process::Command::new(plot)
        .args([
            "crater",
            "--bfs",
            table.to_str().unwrap(),
            "--max-radius",
            "-1",
        ])
        .args(["--out", dir.path().join("x.svg").to_str().unwrap()])
        .output()
        .unwrap();
    let e = String::from_utf8_lossy(&o.stderr);
    assert!(
        !o.status.success() && e.contains("--max-radius = -1"),
        "{e}"
    );
    // The default: the clay erodes under the nose.
    let dir = tempfile::tempdir().unwrap();
    let r = weave_and_simulate(dir.path(), &shot, &[]);
    let balance = one(
        &Table::read(&r.join("summary.parquet")).unwrap(),
        "max_balance_error_relative",
    );
    let eroded = Table::read(&r.join("failures.parquet"))
        .unwrap()
        .f64("t", "")
        .unwrap()
        .len();
    let b = Table::read(&r.join("bfs.parquet")).unwrap();
    let (r0, depth) = (b.f64("r0", "").unwrap(), b.f64("depth", "").unwrap());
    let axis: Vec<f64> = (0..r0.len())
        .filter(|&i| r0[i] == 0.0)
        .map(|i| depth[i])
        .collect();
    let deflection = Table::read(&r.join("ballistic.parquet"))
        .unwrap()
        .f64("deflection", "")
        .unwrap();
    let lead = axis
        .iter()
        .zip(&deflection)
        .map(|(c, d)| c - d)
        .fold(f64::NEG_INFINITY, f64::max);
    let lag = axis
        .iter()
        .zip(&deflection)
        .map(|(c, d)| d - c)
        .fold(f64::NEG_INFINITY, f64::max);
    eprintln!("eroding clay: {eroded} cells eroded; the crater leads the back face by {lead:.3e} m at most, lags it by {lag:.3e} m; balance {balance:.2e}");
    assert!(eroded > 0, "no clay cell eroded under the default");
    assert!(lead < 1e-3 && lag < 93e-6, "lead {lead} m, lag {lag} m");
    assert!(balance < 4e-4, "energy balance {balance}");
}

/// A block thinner than the crater cannot measure it: the run stops once the crater
/// reaches 90 % of the clay's depth under a point (its held floor would be shaping it),
/// names the flag, and keeps its tables (`status = stopped`, bfs.parquet to the last
/// sample). The 9 mm sphere at 60 m/s of the eroding drop into an 8 mm block: stopped at
/// 135 µs with the crater 7.37 mm deep on the axis (92 %); in a 10 mm block it completes
/// at 8.34 mm (83 %).
#[test]
fn a_crater_deeper_than_its_block_stops_the_run_naming_the_flag() {
    let dir = tempfile::tempdir().unwrap();
    let (m, r) = (dir.path().join("m"), dir.path().join("r"));
    let mut weave: Vec<&str> = eroding_drop("6e-3", "0.008");
    weave.extend(["--out", m.to_str().unwrap()]);
    run_ok(WEAVE, &weave);
    let o = std::process::Command::new(env!("CARGO_BIN_EXE_weft-simulate"))
        .args([
            "--model",
            m.to_str().unwrap(),
            "--out",
            r.to_str().unwrap(),
            "--quiet",
        ])
        .output()
        .unwrap();
    let e = String::from_utf8_lossy(&o.stderr);
    eprintln!("{e}");
    assert!(!o.status.success());
    for w in [
        "thinner than the crater",
        "--clay-depth",
        "from the shot's axis",
    ] {
        assert!(e.contains(w), "`{w}` missing from: {e}");
    }
    let s = Table::read(&r.join("summary.parquet")).unwrap();
    assert_eq!(s.str("status", "").unwrap()[0], "stopped");
    let bfs = one(&s, "bfs");
    assert!(bfs >= 0.9 * 0.008 && bfs < 0.008, "bfs {bfs}");
    let t = Table::read(&r.join("bfs.parquet"))
        .unwrap()
        .f64("t", "")
        .unwrap();
    let end = one(&s, "end_time");
    assert_eq!(
        t.iter().cloned().fold(0.0, f64::max),
        end,
        "bfs.parquet ends at the last sample"
    );
}

/// The armour test's verdict follows NIJ Standard-0101.06's rules (as the NRC's review of
/// 2012 restates them): a fair hit (the level's velocity ± 9.1 m/s) passes when the bullet
/// is arrested and the back-face signature is at most 44 mm; a perforation or a deeper
/// crater fails; a run that stopped, a shot off the level's velocity or a bullet not yet
/// arrested (the crater may still deepen) gets no verdict. Summaries written here, one
/// per case; the verdicts, margins and exit code checked against those rules.
#[test]
fn the_nij_verdict_follows_the_standards_rules() {
    use weft::table::{batch, write_table, Col, Provenance};
    let dir = tempfile::tempdir().unwrap();
    let prov = Provenance::new("test", serde_json::json!({}));
    // (name, status, outcome, striking velocity, bfs, expected pass)
    let cases: [(&str, &str, &str, f64, f64, Option<bool>); 6] = [
        ("pass", "completed", "arrested", 373.0, 0.030, Some(true)),
        ("deep", "completed", "arrested", 370.0, 0.0445, Some(false)),
        (
            "through",
            "completed",
            "perforated",
            380.0,
            0.020,
            Some(false),
        ),
        ("going", "completed", "undecided", 373.0, 0.030, None),
        ("slow", "completed", "arrested", 363.0, 0.030, None),
        ("broke", "stopped", "undecided", 373.0, 0.030, None),
    ];
    let mut args = vec!["nij".to_string(), "--level".into(), "IIA".into()];
    for (name, status, outcome, v, bfs, _) in cases {
        let run = dir.path().join(name);
        std::fs::create_dir_all(&run).unwrap();
        let b = batch(vec![
            Col::Str("status", vec![status.into()]),
            Col::OptStr("outcome", vec![Some(outcome.into())]),
            Col::OptF64("striking_velocity", vec![Some(v)]),
            Col::OptF64("bfs", vec![Some(bfs)]),
        ]);
        write_table(&run.join("summary.parquet"), &b, &prov).unwrap();
        args.extend(["--run".into(), run.display().to_string()]);
    }
    let out = dir.path().join("verdict");
    args.extend(["--out".into(), out.display().to_string()]);
    let o = std::process::Command::new(env!("CARGO_BIN_EXE_weft-ballistic"))
        .args(&args)
        .output()
        .unwrap();
    eprintln!("{}", String::from_utf8_lossy(&o.stderr));
    assert_eq!(o.status.code(), Some(1), "not every shot passes: exit 1");
    let t = Table::read(&out.join("nij.parquet")).unwrap();
    let pass = t.bool_opt("pass").unwrap().unwrap();
    let margin = t.f64("bfs_margin", "").unwrap();
    for (k, case) in cases.iter().enumerate() {
        assert_eq!(pass[k], case.5, "{}", case.0);
        assert!((margin[k] - (0.044 - case.4)).abs() < 1e-12, "{}", case.0);
    }
    // Only the passing shot: exit 0.
    let o = std::process::Command::new(env!("CARGO_BIN_EXE_weft-ballistic"))
        .args(["nij", "--level", "IIA", "--run"])
        .arg(dir.path().join("pass"))
        .arg("--out")
        .arg(&out)
        .output()
        .unwrap();
    assert!(o.status.success());
    // A shot without clay: named.
    let bare = dir.path().join("bare");
    std::fs::create_dir_all(&bare).unwrap();
    let b = batch(vec![
        Col::Str("status", vec!["completed".into()]),
        Col::OptF64("striking_velocity", vec![Some(398.0)]),
        Col::OptF64("bfs", vec![None]),
    ]);
    write_table(&bare.join("summary.parquet"), &b, &prov).unwrap();
    let o = std::process::Command::new(env!("CARGO_BIN_EXE_weft-ballistic"))
        .args(["nij", "--level", "II", "--run"])
        .arg(&bare)
        .arg("--out")
        .arg(&out)
        .output()
        .unwrap();
    let e = String::from_utf8_lossy(&o.stderr);
    assert!(
        !o.status.success() && e.contains("bfs") && e.contains("--backing clay"),
        "{e}"
    );
}

#[test]
fn the_armour_test_judges_each_shot_at_its_level_and_names_the_lightest_pass() {
    use weft::table::{batch, write_table, Col, Provenance};
    let dir = tempfile::tempdir().unwrap();
    let prov = Provenance::new("test", serde_json::json!({}));
    // (plies, velocity, outcome, plies perforated, bfs, expected level, expected pass):
    // NIJ Standard-0101.06's rules (IIA 373, II 398 ± 9.1 m/s; no perforation, BFS ≤ 44 mm).
    type Case = (
        i64,
        f64,
        &'static str,
        i64,
        f64,
        Option<&'static str>,
        Option<bool>,
    );
    let cases: [Case; 6] = [
        (4, 373.0, "perforated", 4, 0.070, Some("IIA"), Some(false)),
        (4, 398.0, "perforated", 4, 0.080, Some("II"), Some(false)),
        (8, 373.0, "arrested", 5, 0.041, Some("IIA"), Some(true)),
        (8, 398.0, "arrested", 6, 0.046, Some("II"), Some(false)),
        (16, 398.0, "arrested", 3, 0.030, Some("II"), Some(true)),
        (16, 385.0, "arrested", 3, 0.030, None, None),
    ];
    let shots = dir.path().join("shots");
    for (plies, v, outcome, perf, bfs, _, _) in cases {
        let run = shots.join(plies.to_string()).join(format!("{v}"));
        std::fs::create_dir_all(&run).unwrap();
        let b = batch(vec![
            Col::Str("status", vec!["completed".into()]),
            Col::OptStr("outcome", vec![Some(outcome.into())]),
            Col::OptF64("striking_velocity", vec![Some(v)]),
            Col::OptF64("bfs", vec![Some(bfs)]),
            Col::I64("layers", vec![plies]),
            Col::OptI64("plies_perforated", vec![Some(perf)]),
            Col::OptF64("areal_density", vec![Some(0.2 * plies as f64)]),
        ]);
        write_table(&run.join("summary.parquet"), &b, &prov).unwrap();
    }
    let out = dir.path().join("verdict");
    let o = std::process::Command::new(BALLISTIC)
        .args(["armour-test", "--run"])
        .arg(&shots)
        .arg("--out")
        .arg(&out)
        .output()
        .unwrap();
    let e = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{e}");
    assert!(
        e.contains("level IIA: the lightest pack that passes has 8 plies"),
        "{e}"
    );
    assert!(
        e.contains("level II: the lightest pack that passes has 16 plies"),
        "{e}"
    );
    let t = Table::read(&out.join("armour_test.parquet")).unwrap();
    let (plies, v) = (t.i64("plies", "").unwrap(), t.f64("velocity", "").unwrap());
    let level = t.str_opt("level").unwrap().unwrap();
    let pass = t.bool_opt("pass").unwrap().unwrap();
    let perf = t.i64_opt("plies_perforated").unwrap().unwrap();
    let mut want = cases.to_vec();
    want.sort_by(|a, b| a.0.cmp(&b.0).then(a.1.total_cmp(&b.1)));
    for (k, c) in want.iter().enumerate() {
        assert_eq!((plies[k], v[k]), (c.0, c.1));
        assert_eq!(level[k].as_deref(), c.5, "{c:?}");
        assert_eq!(pass[k], c.6, "{c:?}");
        assert_eq!(perf[k], Some(c.3));
    }
    // The figure draws from the table.
    let png = dir.path().join("bfs.png");
    run_ok(
        env!("CARGO_BIN_EXE_weft-plot"),
        &[
            "armour",
            "--table",
            out.join("armour_test.parquet").to_str().unwrap(),
            "--out",
            png.to_str().unwrap(),
        ],
    );
    assert!(std::fs::metadata(&png).unwrap().len() > 1000);
    // A folder with no shot in it: named.
    let empty = dir.path().join("empty");
    std::fs::create_dir_all(&empty).unwrap();
    let o = std::process::Command::new(BALLISTIC)
        .args(["armour-test", "--run"])
        .arg(&empty)
        .arg("--out")
        .arg(&out)
        .output()
        .unwrap();
    let e = String::from_utf8_lossy(&o.stderr);
    assert!(
        !o.status.success() && e.contains("--run") && e.contains("summary.parquet"),
        "{e}"
    );
}
