//! `weft-vtk` writes a time series that VTK's own reader (the one ParaView uses) opens
//! with the right cells, times and values.
//!
//! Reference: the VTK XML file formats (Kitware, "VTK File Formats", UnstructuredGrid
//! and Collection), read back by the Python `vtk` package's
//! `vtkXMLUnstructuredGridReader` in `tests/read_vtk.py`, and compared with the model
//! and run tables read by pandas: cell counts and VTK types per element kind, each
//! cell's nodes, the output times, displacements and velocities (exactly: binary
//! Float64), points = X + u₀ + u, the membranes' nodal thickness, the element results
//! of `elements.parquet` as cell data, the projectile's tip and radius. Where Python's `vtk` is missing the test is reported
//! as ignored (tests/common/optional.rs), unless `WEFT_REQUIRE_PYTHON=1` (set by `.ci/run`,
//! which installs it): then it fails.
//!
//! Case: the composite model of `tests/common` (every element kind: quads with a row of
//! nodal thicknesses tied to triangles, beams, a tension-only truss, a point mass, a link
//! with slider and dashpots, a round-nosed projectile, contact), 10 µs.

mod common;
use common::run_ok;
use std::path::Path;
use std::process::Command;

fn python_vtk_ok() -> bool {
    let probe = Command::new("python3")
        .args(["-c", "import vtkmodules.vtkIOXML, pandas, numpy"])
        .output();
    probe.map(|o| o.status.success()).unwrap_or(false)
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// The composite model, run for 10 µs with every node in the history.
fn composite_run(dir: &Path, extra: &[&str]) -> (std::path::PathBuf, std::path::PathBuf) {
    let model = dir.join("composite");
    let out = dir.join("out");
    let prov = weft::table::Provenance::new("test composite", serde_json::json!({}));
    weft::model::io::write_model(&common::composite(), &model, &prov).unwrap();
    let mut args = vec![
        "--model",
        s(&model),
        "--out",
        s(&out),
        "--quiet",
        "--end-time",
        "1e-5",
    ];
    args.extend(extra);
    run_ok(env!("CARGO_BIN_EXE_weft-simulate"), &args);
    (model, out)
}

fn vtk_reads_every_element_kind_the_times_and_the_history_values() {
    let dir = tempfile::tempdir().unwrap();
    let (model, out) = composite_run(dir.path(), &["--all-nodes", "--element-results", "all"]);
    let vtk = dir.path().join("vtk");
    let msg = run_ok(
        env!("CARGO_BIN_EXE_weft-vtk"),
        &[
            "--model",
            s(&model),
            "--history",
            s(&out.join("history.parquet")),
            "--out",
            s(&vtk),
        ],
    );
    eprintln!("{msg}");
    let o = Command::new("python3")
        .arg(concat!(env!("CARGO_MANIFEST_DIR"), "/tests/read_vtk.py"))
        .args([&model, &out, &vtk])
        .output()
        .unwrap();
    let so = String::from_utf8_lossy(&o.stdout);
    assert!(
        o.status.success(),
        "read_vtk.py failed:\n{so}\n{}",
        String::from_utf8_lossy(&o.stderr)
    );
    eprintln!("{so}");
}

fn a_history_without_every_node_is_refused_and_nothing_is_written() {
    let dir = tempfile::tempdir().unwrap();
    let (model, out) = composite_run(dir.path(), &["--history-set", "beam"]);
    let vtk = dir.path().join("vtk");
    let o = Command::new(env!("CARGO_BIN_EXE_weft-vtk"))
        .args(["--model", s(&model), "--history"])
        .arg(out.join("history.parquet"))
        .args(["--out", s(&vtk)])
        .output()
        .unwrap();
    let e = String::from_utf8_lossy(&o.stderr);
    assert!(!o.status.success());
    assert!(
        e.contains("has no value at t = 0e0 s")
            && e.contains("history.parquet")
            && e.contains("--all-nodes"),
        "{e}"
    );
    assert!(!vtk.exists(), "nothing written");
    // Nor is a leftover temporary folder.
    let left: Vec<_> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().to_string())
        .filter(|n| n.contains("tmp"))
        .collect();
    assert!(left.is_empty(), "{left:?}");
    let o = Command::new(env!("CARGO_BIN_EXE_weft-vtk"))
        .args(["--model", s(&model), "--history"])
        .arg(out.join("history.parquet"))
        .args(["--out", s(&vtk), "--every", "0"])
        .output()
        .unwrap();
    let e = String::from_utf8_lossy(&o.stderr);
    assert!(!o.status.success() && e.contains("--every 0"), "{e}");
}

/// python3 with vtk, pandas and numpy: its tests are ignored where it is missing, unless `WEFT_REQUIRE_PYTHON=1`.
const PYTHON_VTK: common::optional::Tool = common::optional::Tool {
    what: "python3 with vtk, pandas and numpy",
    install: "pip install vtk pandas pyarrow",
    require: "WEFT_REQUIRE_PYTHON",
    here: python_vtk_ok,
};

fn main() -> std::process::ExitCode {
    common::optional::run(
        &PYTHON_VTK,
        vec![
            (
                "vtk_reads_every_element_kind_the_times_and_the_history_values",
                true,
                vtk_reads_every_element_kind_the_times_and_the_history_values,
            ),
            (
                "a_history_without_every_node_is_refused_and_nothing_is_written",
                false,
                a_history_without_every_node_is_refused_and_nothing_is_written,
            ),
        ],
    )
}
