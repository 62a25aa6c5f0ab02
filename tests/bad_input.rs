//! Malformed models and numerical breakdowns: each gives a clear error that names the
//! file, column, row and value, exits non-zero, never panics, and leaves no table that
//! looks complete.

use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::Arc;

use arrow_array::{ArrayRef, Float64Array, Int64Array, RecordBatch, StringArray};
use arrow_schema::{DataType, Field, Schema};
use weft::generate::rod::{build, RodParams};
use weft::model::io::write_model;
use weft::table::{write_table, Provenance, Table};

fn good_model(dir: &Path) -> PathBuf {
    let p = RodParams {
        elements: 20,
        ..Default::default()
    };
    let m = build(&p).unwrap();
    let d = dir.join("model");
    write_model(&m, &d, &Provenance::new("test", serde_json::json!({}))).unwrap();
    d
}

/// Rewrite one table with a column replaced (or removed when `new` is None).
fn replace_col(dir: &Path, file: &str, col: &str, new: Option<(DataType, ArrayRef)>) {
    let path = dir.join(file);
    let t = Table::read(&path).unwrap();
    let schema = t.batch.schema();
    let mut fields = vec![];
    let mut arrays = vec![];
    for (i, f) in schema.fields().iter().enumerate() {
        if f.name() == col {
            if let Some((dt, a)) = &new {
                fields.push(Field::new(col, dt.clone(), true));
                arrays.push(a.clone());
            }
        } else {
            fields.push(f.as_ref().clone());
            arrays.push(t.batch.column(i).clone());
        }
    }
    let b = RecordBatch::try_new(Arc::new(Schema::new(fields)), arrays).unwrap();
    write_table(
        &path,
        &b,
        &Provenance::new("corrupt", serde_json::json!({})),
    )
    .unwrap();
}

fn f64s(dir: &Path, file: &str, col: &str, f: impl Fn(&mut Vec<Option<f64>>)) {
    let t = Table::read(&dir.join(file)).unwrap();
    let mut v = t.f64_opt(col).unwrap().unwrap();
    f(&mut v);
    replace_col(
        dir,
        file,
        col,
        Some((DataType::Float64, Arc::new(Float64Array::from(v)))),
    );
}

fn i64s(dir: &Path, file: &str, col: &str, f: impl Fn(&mut Vec<Option<i64>>)) {
    let t = Table::read(&dir.join(file)).unwrap();
    let mut v: Vec<Option<i64>> = t.i64(col, "").unwrap().into_iter().map(Some).collect();
    f(&mut v);
    replace_col(
        dir,
        file,
        col,
        Some((DataType::Int64, Arc::new(Int64Array::from(v)))),
    );
}

fn strs(dir: &Path, file: &str, col: &str, f: impl Fn(&mut Vec<String>)) {
    let t = Table::read(&dir.join(file)).unwrap();
    let mut v = t.str(col, "").unwrap();
    f(&mut v);
    replace_col(
        dir,
        file,
        col,
        Some((DataType::Utf8, Arc::new(StringArray::from(v)))),
    );
}

/// Run weft-simulate, expect failure with every fragment in stderr, no panic, no tables.
fn expect_failure(model: &Path, extra: &[&str], fragments: &[&str]) {
    let out = model.parent().unwrap().join("out");
    let o = Command::new(env!("CARGO_BIN_EXE_weft-simulate"))
        .arg("--model")
        .arg(model)
        .arg("--out")
        .arg(&out)
        .arg("--quiet")
        .args(extra)
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        !o.status.success(),
        "expected failure, got success; stderr:\n{err}"
    );
    assert_eq!(o.status.code(), Some(1), "exit code; stderr:\n{err}");
    assert!(!err.contains("panicked"), "panic:\n{err}");
    for f in fragments {
        assert!(err.contains(f), "stderr lacks `{f}`:\n{err}");
    }
    if err.contains("the run stopped") {
        // A run that stopped keeps its tables up to the last good sample, and says so.
        let s = Table::read(&out.join("summary.parquet")).unwrap();
        assert_eq!(s.str("status", "").unwrap(), vec!["stopped"], "{err}");
        for t in ["history.parquet", "energy.parquet"] {
            assert!(out.join(t).exists(), "a stopped run without `{t}`:\n{err}");
        }
    } else if out.exists() {
        for e in std::fs::read_dir(&out).unwrap() {
            let name = e.unwrap().file_name().to_string_lossy().to_string();
            panic!("output folder holds `{name}` after a failed run; stderr:\n{err}");
        }
    }
}

fn case(f: impl Fn(&Path), extra: &[&str], fragments: &[&str]) {
    let dir = tempfile::tempdir().unwrap();
    let m = good_model(dir.path());
    f(&m);
    expect_failure(&m, extra, fragments);
}

#[test]
fn missing_column() {
    case(
        |m| replace_col(m, "nodes.parquet", "z", None),
        &[],
        &[
            "nodes.parquet",
            "missing column `z`",
            "hint:",
            "node_id, x, y, z",
        ],
    );
}

#[test]
fn wrong_type() {
    case(
        |m| {
            let v: Vec<String> = (0..21).map(|i| format!("{i}")).collect();
            replace_col(
                m,
                "nodes.parquet",
                "x",
                Some((DataType::Utf8, Arc::new(StringArray::from(v)))),
            );
        },
        &[],
        &[
            "nodes.parquet",
            "column `x` has type Utf8",
            "expected a floating-point column",
        ],
    );
}

#[test]
fn dangling_node_id() {
    case(
        |m| i64s(m, "elements_truss.parquet", "n2", |v| v[5] = Some(9999)),
        &[],
        &[
            "elements_truss.parquet",
            "column `n2`",
            "row 5",
            "node id `9999` does not exist",
        ],
    );
}

#[test]
fn negative_area() {
    case(
        |m| f64s(m, "parts.parquet", "area", |v| v[0] = Some(-1e-6)),
        &[],
        &[
            "parts.parquet",
            "column `area`",
            "row 0",
            "area = `-0.000001`",
            "expected a value > 0",
        ],
    );
}

#[test]
fn zero_modulus() {
    case(
        |m| f64s(m, "parts.parquet", "youngs_modulus", |v| v[0] = Some(0.0)),
        &[],
        &["parts.parquet", "youngs_modulus = `0`", "row 0"],
    );
}

/// A modulus of 10³⁰⁸ makes the stable step ~10⁻¹⁵⁴ s: the run would set out to take
/// ~10¹⁵⁰ steps (found by mutating model tables: 7 of 1832 variants never ended). Refused
/// before it starts, naming the element that sets the step, like LS-DYNA's DTMIN stop.
#[test]
fn a_step_too_small_for_the_step_budget() {
    case(
        |m| f64s(m, "parts.parquet", "youngs_modulus", |v| v[0] = Some(1e308)),
        &[],
        &[
            "steps of",
            "more than the budget of 1000000000 steps",
            "the step is set by truss",
            "--max-steps",
        ],
    );
    // The budget is the user's: a normal rod (≈ 500 steps) refused at 10.
    case(|_| {}, &["--max-steps", "10"], &["budget of 10 steps"]);
}

#[test]
fn missing_property() {
    case(
        |m| f64s(m, "parts.parquet", "density", |v| v[0] = None),
        &[],
        &["parts.parquet", "has no density", "hint:"],
    );
}

#[test]
fn duplicate_node_id() {
    case(
        |m| i64s(m, "nodes.parquet", "node_id", |v| v[7] = Some(3)),
        &[],
        &["nodes.parquet", "duplicate node id `3`", "row 7"],
    );
}

#[test]
fn duplicate_element_id() {
    case(
        |m| {
            i64s(m, "elements_truss.parquet", "element_id", |v| {
                v[4] = Some(1)
            })
        },
        &[],
        &[
            "elements_truss.parquet",
            "duplicate element id `1`",
            "row 4",
        ],
    );
}

#[test]
fn nan_coordinate() {
    case(
        |m| f64s(m, "nodes.parquet", "x", |v| v[3] = Some(f64::NAN)),
        &[],
        &[
            "nodes.parquet",
            "column `x`",
            "row 3",
            "non-finite value `NaN`",
        ],
    );
}

#[test]
fn null_in_required_column() {
    case(
        |m| i64s(m, "nodes.parquet", "node_id", |v| v[2] = None),
        &[],
        &[
            "nodes.parquet",
            "null value in required column `node_id`",
            "row 2",
        ],
    );
}

#[test]
fn unknown_element_kind() {
    case(
        |m| strs(m, "parts.parquet", "kind", |v| v[0] = "shell".into()),
        &[],
        &["parts.parquet", "unknown element kind `shell`", "`truss`"],
    );
}

#[test]
fn unknown_element_table() {
    case(
        |m| {
            std::fs::copy(
                m.join("elements_truss.parquet"),
                m.join("elements_shell.parquet"),
            )
            .map(|_| ())
            .unwrap()
        },
        &[],
        &["elements_shell.parquet", "unknown element table"],
    );
}

#[test]
fn truncated_table() {
    case(
        |m| {
            let p = m.join("nodes.parquet");
            let b = std::fs::read(&p).unwrap();
            std::fs::write(&p, &b[..b.len() / 2]).unwrap();
        },
        &[],
        &["nodes.parquet", "cannot read the file as Parquet", "hint:"],
    );
}

#[test]
fn not_a_model_folder() {
    let dir = tempfile::tempdir().unwrap();
    let m = dir.path().join("nothing");
    std::fs::create_dir_all(&m).unwrap();
    expect_failure(&m, &[], &["is not a model folder", "weft-weave rod"]);
}

#[test]
fn unknown_time_law_and_missing_duration() {
    case(
        |m| strs(m, "loads.parquet", "law", |v| v[0] = "sawtooth".into()),
        &[],
        &["loads.parquet", "unknown time law `sawtooth`", "row 0"],
    );
    case(
        |m| f64s(m, "loads.parquet", "duration", |v| v[0] = None),
        &[],
        &["loads.parquet", "duration", "row 0"],
    );
}

#[test]
fn bad_analysis_setting() {
    case(
        |m| {
            f64s(m, "analysis.parquet", "output_interval", |v| {
                v[0] = Some(-1.0)
            })
        },
        &[],
        &["analysis.parquet", "output_interval", "`-1`"],
    );
}

#[test]
fn unknown_history_set() {
    case(
        |_| {},
        &["--history-set", "nope"],
        &["history node set `nope` does not exist", "`axis_x`"],
    );
}

#[test]
fn time_step_above_stable_step() {
    case(
        |_| {},
        &["--time-step", "2e-6"],
        &["exceeds the stable step", "truss", "hint:"],
    );
}

#[test]
fn fixed_direction_with_initial_velocity() {
    case(
        |m| {
            let mut md = weft::model::io::read_model(m).unwrap();
            md.initial_velocities.push((0, [1.0, 0.0, 0.0]));
            // Write the table directly: the model writer itself refuses invalid models.
            let b = weft::table::batch(vec![
                weft::table::Col::I64("node_id", vec![1]),
                weft::table::Col::F64("vx", vec![1.0]),
                weft::table::Col::F64("vy", vec![0.0]),
                weft::table::Col::F64("vz", vec![0.0]),
            ]);
            write_table(
                &m.join("initial_velocities.parquet"),
                &b,
                &Provenance::new("t", serde_json::json!({})),
            )
            .unwrap();
        },
        &[],
        &[
            "initial_velocities.parquet",
            "node `1` has fixed x but initial velocity vx = 1",
        ],
    );
}

#[test]
fn nan_during_the_run_names_node_step_and_element() {
    // A load of 1e308 N overflows the velocity to infinity within a step.
    case(
        |m| f64s(m, "loads.parquet", "fx", |v| v[0] = Some(1e308)),
        &[],
        &[
            "became NaN or infinite",
            "node `",
            "at step",
            "the run stopped; the tables up to t = 0.000000e0 s",
        ],
    );
}

#[test]
fn energy_runaway_stops_the_run() {
    // With a limit far below the O(Δt²) drift of this run the stop must trigger.
    case(
        |_| {},
        &["--max-energy-error", "1e-12", "--end-time", "4e-4"],
        &["energy balance error", "at step", "hint:"],
    );
}
