//! The tables open in pandas and polars with the documented columns and dtypes, carry
//! provenance in `df.attrs`, and tables written back by pandas and polars are read.
//!
//! Runs `tests/read_tables.py`. Where pandas or polars are not installed the tests are
//! reported as ignored (tests/common/optional.rs), unless `WEFT_REQUIRE_PYTHON=1` (set by
//! `.ci/run`, which installs them): then they fail.

mod common;
use common::run_ok;
use std::process::Command;

/// Whether python3 with pandas, polars and pyarrow is here; required when
/// `WEFT_REQUIRE_PYTHON=1` (set by `.ci/run`, which installs them).
fn python_ok() -> bool {
    let probe = Command::new("python3")
        .args(["-c", "import pandas, polars, pyarrow"])
        .output();
    probe.map(|o| o.status.success()).unwrap_or(false)
}

/// Runs `tests/read_tables.py` on a model folder and its results (`open_only`: check
/// the tables only, skip the rod's write-back check); it must pass, and what it prints
/// is shown.
fn read_tables(
    model: &std::path::Path,
    out: &std::path::Path,
    scratch: &std::path::Path,
    open_only: bool,
) {
    let mut c = Command::new("python3");
    c.arg(concat!(env!("CARGO_MANIFEST_DIR"), "/tests/read_tables.py"))
        .arg(env!("CARGO_BIN_EXE_weft-simulate"))
        .arg(model)
        .arg(out)
        .arg(scratch);
    if open_only {
        c.arg("open-only");
    }
    let o = c.output().unwrap();
    let so = String::from_utf8_lossy(&o.stdout);
    let se = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "read_tables.py failed:\n{so}\n{se}");
    eprintln!("{so}");
}

/// Runs a weft binary, which must succeed.
fn tables_open_in_pandas_and_polars() {
    let dir = tempfile::tempdir().unwrap();
    let model = dir.path().join("rod");
    let out = dir.path().join("out");
    let st = Command::new(env!("CARGO_BIN_EXE_weft-weave"))
        .args(["rod", "--out"])
        .arg(&model)
        .status()
        .unwrap();
    assert!(st.success());
    let st = Command::new(env!("CARGO_BIN_EXE_weft-simulate"))
        .arg("--model")
        .arg(&model)
        .arg("--out")
        .arg(&out)
        .arg("--quiet")
        .status()
        .unwrap();
    assert!(st.success());
    read_tables(&model, &out, &dir.path(), false);
}

fn a_model_with_every_feature_opens_in_pandas_and_polars() {
    let dir = tempfile::tempdir().unwrap();
    let model = dir.path().join("composite");
    let out = dir.path().join("out");
    let prov = weft::table::Provenance::new("test composite", serde_json::json!({}));
    weft::model::io::write_model(&common::composite(), &model, &prov).unwrap();
    let st = Command::new(env!("CARGO_BIN_EXE_weft-simulate"))
        .arg("--model")
        .arg(&model)
        .arg("--out")
        .arg(&out)
        .arg("--quiet")
        .status()
        .unwrap();
    assert!(st.success());
    for t in [
        "elements_quad.parquet",
        "elements_tri.parquet",
        "elements_beam.parquet",
        "ties.parquet",
        "symmetry.parquet",
        "projectile.parquet",
        "contacts.parquet",
    ] {
        assert!(model.join(t).exists(), "{t}");
    }
    assert!(out.join("projectile.parquet").exists());
    read_tables(&model, &out, &dir.path(), true);
}

fn a_generated_woven_model_opens_in_pandas_and_polars() {
    let dir = tempfile::tempdir().unwrap();
    let (model, out) = (dir.path().join("woven"), dir.path().join("out"));
    let st = Command::new(env!("CARGO_BIN_EXE_weft-weave"))
        .args(["woven-reduced", "--end-time", "5e-6", "--out"])
        .arg(&model)
        .status()
        .unwrap();
    assert!(st.success());
    let st = Command::new(env!("CARGO_BIN_EXE_weft-simulate"))
        .arg("--model")
        .arg(&model)
        .arg("--out")
        .arg(&out)
        .arg("--quiet")
        .status()
        .unwrap();
    assert!(st.success());
    read_tables(&model, &out, &dir.path(), true);
}

/// A formed woven model (initial displacements ux0, uy0, uz0 in nodes.parquet, and
/// form.parquet) and its impact's tables open in pandas and polars.
fn a_formed_woven_model_opens_in_pandas_and_polars() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let s = |p: &str| d.join(p).to_string_lossy().to_string();
    run_ok(
        env!("CARGO_BIN_EXE_weft-weave"),
        &["woven", "--yarns", "4", "--out", &s("patch")],
    );
    run_ok(
        env!("CARGO_BIN_EXE_weft-form"),
        &["--quiet", "--model", &s("patch"), "--out", &s("formed")],
    );
    run_ok(
        env!("CARGO_BIN_EXE_weft-simulate"),
        &[
            "--quiet",
            "--model",
            &s("formed"),
            "--end-time",
            "2e-6",
            "--out",
            &s("out"),
        ],
    );
    read_tables(&d.join("formed"), &d.join("out"), &d, true);
    let cols = Command::new("python3")
        .args([
            "-c",
            "import sys, pandas as pd; print(list(pd.read_parquet(sys.argv[1]).columns))",
        ])
        .arg(d.join("formed/nodes.parquet"))
        .output()
        .unwrap();
    assert!(String::from_utf8_lossy(&cols.stdout).contains("'uz0'"));
}

/// The fit and error stages' tables open in pandas and polars, with a parameter's name
/// (`membrane.G12`) as a column and nulls where documented.
fn fit_and_error_tables_open_in_pandas_and_polars() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let s = |p: &str| d.join(p).to_string_lossy().to_string();
    run_ok(
        env!("CARGO_BIN_EXE_weft-weave"),
        &[
            "membrane",
            "--cells",
            "3",
            "--load-case",
            "shear",
            "--out",
            &s("ref"),
        ],
    );
    run_ok(
        env!("CARGO_BIN_EXE_weft-weave"),
        &[
            "membrane",
            "--cells",
            "3",
            "--load-case",
            "shear",
            "--shear-modulus",
            "1e9",
            "--out",
            &s("cand"),
        ],
    );
    run_ok(
        env!("CARGO_BIN_EXE_weft-simulate"),
        &[
            "--static",
            "--quiet",
            "--model",
            &s("ref"),
            "--out",
            &s("refout"),
        ],
    );
    run_ok(
        env!("CARGO_BIN_EXE_weft-fit"),
        &[
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
            "--param",
            "membrane.G12:1e8:1e10:log",
            "--expected",
            "membrane.G12=7.5e8",
            "--out",
            &s("fit"),
        ],
    );
    run_ok(
        env!("CARGO_BIN_EXE_weft-error"),
        &[
            "--reference-model",
            &s("ref"),
            "--reference-history",
            &s("refout/history.parquet"),
            "--model",
            &s("ref"),
            "--history",
            &s("refout/history.parquet"),
            "--static",
            "--out-dir",
            &s("fit"),
        ],
    );
    read_tables(&d.join("fit/models/cand"), &d.join("fit"), &d, true);
}

/// An impact in which yarns fail: its failures.parquet and ballistic.parquet (and the
/// summary's outcome columns) open in pandas and polars with the documented types.
fn a_failing_impact_opens_in_pandas_and_polars() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let s = |p: &str| d.join(p).to_string_lossy().to_string();
    run_ok(
        env!("CARGO_BIN_EXE_weft-weave"),
        &[
            "woven",
            "--yarns",
            "6",
            "--yarn-model",
            "chain",
            "--layers",
            "2",
            "--failure-strain",
            "0.036",
            "--projectile-velocity",
            "400",
            "--end-time",
            "3e-5",
            "--out",
            &s("model"),
        ],
    );
    run_ok(
        env!("CARGO_BIN_EXE_weft-simulate"),
        &["--quiet", "--model", &s("model"), "--out", &s("out")],
    );
    for t in ["failures.parquet", "ballistic.parquet"] {
        assert!(d.join("out").join(t).exists(), "{t}");
    }
    read_tables(&d.join("model"), &d.join("out"), d, true);
}

/// python3 with pandas, polars and pyarrow: its tests are ignored where it is missing, unless `WEFT_REQUIRE_PYTHON=1`.
const PYTHON: common::optional::Tool = common::optional::Tool {
    what: "python3 with pandas, polars and pyarrow",
    install: "pip install pandas polars pyarrow",
    require: "WEFT_REQUIRE_PYTHON",
    here: python_ok,
};

fn main() -> std::process::ExitCode {
    common::optional::run(
        &PYTHON,
        vec![
            (
                "tables_open_in_pandas_and_polars",
                true,
                tables_open_in_pandas_and_polars,
            ),
            (
                "a_model_with_every_feature_opens_in_pandas_and_polars",
                true,
                a_model_with_every_feature_opens_in_pandas_and_polars,
            ),
            (
                "a_generated_woven_model_opens_in_pandas_and_polars",
                true,
                a_generated_woven_model_opens_in_pandas_and_polars,
            ),
            (
                "a_formed_woven_model_opens_in_pandas_and_polars",
                true,
                a_formed_woven_model_opens_in_pandas_and_polars,
            ),
            (
                "fit_and_error_tables_open_in_pandas_and_polars",
                true,
                fit_and_error_tables_open_in_pandas_and_polars,
            ),
            (
                "a_failing_impact_opens_in_pandas_and_polars",
                true,
                a_failing_impact_opens_in_pandas_and_polars,
            ),
        ],
    )
}
