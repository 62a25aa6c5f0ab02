//! Helpers of the woven-patch tests, shared by the bands (`tests/woven.rs`) and the
//! chains (`tests/woven_chain.rs`).

use std::collections::HashMap;

use weft::model::Model;
use weft::solver::contact::ContactReport;
use weft::solver::output::MemorySink;
use weft::solver::{run_in_memory, RunStats};
use weft::table::Table;

/// The run of `m` on `threads` threads: its outputs, contact report and statistics.
pub fn run_on(m: &Model, threads: usize) -> (MemorySink, ContactReport, RunStats) {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap()
        .install(|| {
            let (s, out, stats) = run_in_memory(m).unwrap();
            let rep = s.operator().surfaces.report(&s.node_ids());
            (out, rep, stats)
        })
}

/// One output sample of a transverse front along a yarn.
pub struct FrontSample {
    pub t: f64,
    /// The front's reference x [m].
    pub x: f64,
    /// The rows of `elements.parquet` at this sample whose element lies in the 2 mm
    /// behind the front.
    pub rows: Vec<usize>,
}

/// Simulate `m` (written to a temporary folder, element results of part `warp_1`) and
/// read its transverse front along `line` (nodes in order along x) from 2 µs on: per
/// output sample the outermost node with −u_z > 0.2 mm, and the element results of the
/// elements whose centre x (`centre`, by element id) lies in the 2 mm behind it. Returns
/// `elements.parquet` and the samples.
pub fn front(m: &Model, line: &[usize], centre: &HashMap<i64, f64>) -> (Table, Vec<FrontSample>) {
    let dir = tempfile::tempdir().unwrap();
    let prov = weft::table::Provenance::new("test", serde_json::json!({}));
    weft::model::io::write_model(m, &dir.path().join("model"), &prov).unwrap();
    weft::simulate::run(
        &weft::simulate::Config {
            model: dir.path().join("model"),
            out: dir.path().join("run"),
            history_sets: Some(vec![]),
            element_results: vec!["warp_1".into()],
            ..Default::default()
        },
        &mut |_| {},
    )
    .unwrap();
    let id_of: HashMap<i64, usize> = line
        .iter()
        .enumerate()
        .map(|(j, &n)| (m.node_id[n], j))
        .collect();
    let h = Table::read(&dir.path().join("run/history.parquet")).unwrap();
    let (ht, hid, huz) = (
        h.f64("t", "").unwrap(),
        h.i64("node_id", "").unwrap(),
        h.f64("uz", "").unwrap(),
    );
    let el = Table::read(&dir.path().join("run/elements.parquet")).unwrap();
    let (et, eid) = (el.f64("t", "").unwrap(), el.i64("element_id", "").unwrap());
    let dt = m.analysis.output_interval;
    let sample = |t: f64| (t / dt).round() as usize;
    let ns = sample(m.analysis.end_time) + 1;
    let mut uz = vec![vec![0.0; line.len()]; ns];
    for r in 0..ht.len() {
        if let Some(&j) = id_of.get(&hid[r]) {
            uz[sample(ht[r])][j] = huz[r];
        }
    }
    let mut out = vec![];
    for (k, row) in uz.iter().enumerate() {
        let t = k as f64 * dt;
        if t < 2e-6 - 1e-12 {
            continue;
        }
        let jf = (0..line.len()).rev().find(|&j| -row[j] > 2e-4).unwrap();
        let x = m.coords[line[jf]][0];
        let rows = (0..et.len())
            .filter(|&r| sample(et[r]) == k)
            .filter(|&r| {
                centre
                    .get(&eid[r])
                    .is_some_and(|&xc| xc > x - 2e-3 && xc < x)
            })
            .collect();
        out.push(FrontSample { t, x, rows });
    }
    (el, out)
}

/// The front's speed: the least-squares slope of x against t [m/s].
pub fn front_speed(s: &[FrontSample]) -> f64 {
    let n = s.len() as f64;
    let (mt, mx) = (
        s.iter().map(|f| f.t).sum::<f64>() / n,
        s.iter().map(|f| f.x).sum::<f64>() / n,
    );
    s.iter().map(|f| (f.t - mt) * (f.x - mx)).sum::<f64>()
        / s.iter().map(|f| (f.t - mt).powi(2)).sum::<f64>()
}
