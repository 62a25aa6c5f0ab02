//! Malformed contact definitions (`contacts.parquet`) and nodal thicknesses: each gives a
//! clear error naming the file, column, row and value, exits 1 without a panic, and
//! writes no table.

use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::Arc;

use arrow_array::{ArrayRef, Float64Array, RecordBatch, StringArray};
use arrow_schema::{DataType, Field, Schema};
use weft::model::contacts::{ContactDef, Slave};
use weft::model::io::write_model;
use weft::model::{Analysis, ElementKind, Model, PartProps};
use weft::table::{write_table, Provenance, Table};

/// A fixed band of 2 × 2 quads with nodal thickness, a ball (point mass, set `ball`)
/// above it, and one contact of the ball against the band.
fn good_model(dir: &Path) -> PathBuf {
    let mut m = Model::default();
    let band = m.add_part(
        1,
        "band",
        ElementKind::Quad,
        PartProps {
            youngs_modulus_1: Some(8e10),
            youngs_modulus_2: Some(8e10),
            shear_modulus_12: Some(3e10),
            density: Some(1440.0),
            thickness: Some(1e-4),
            ..Default::default()
        },
    );
    for j in 0..3 {
        for i in 0..3 {
            let n = m.add_node(
                (3 * j + i) as i64 + 1,
                [i as f64 * 1e-3, j as f64 * 1e-3, 0.0],
            );
            m.constraints.push((n, [true, true, true]));
        }
    }
    for j in 0..2 {
        for i in 0..2 {
            let a = 3 * j + i;
            m.add_element_with_thickness(
                (2 * j + i) as i64 + 1,
                band,
                &[a, a + 1, a + 4, a + 3],
                &[1e-4, 1.2e-4, 1.2e-4, 1e-4],
            );
        }
    }
    let b = m.add_node(100, [1e-3, 1e-3, 5e-4]);
    let p = m.add_part(
        2,
        "ball",
        ElementKind::PointMass,
        PartProps {
            mass: Some(1e-6),
            ..Default::default()
        },
    );
    m.add_element(100, p, &[b]);
    m.node_sets.insert("ball".into(), vec![b]);
    m.initial_velocities.push((b, [0.0, 0.0, -1.0]));
    let mut c = ContactDef::new(7, Slave::Set("ball".into()), band).with_friction(0.2);
    c.slave_thickness = Some(1e-4);
    m.contacts.push(c);
    m.analysis = Analysis {
        end_time: 1e-6,
        output_interval: 1e-7,
        time_step: Some(1e-8),
        ..Analysis::default()
    };
    let d = dir.join("model");
    write_model(&m, &d, &Provenance::new("test", serde_json::json!({}))).unwrap();
    d
}

fn replace_col(dir: &Path, file: &str, col: &str, dt: DataType, a: ArrayRef) {
    let path = dir.join(file);
    let t = Table::read(&path).unwrap();
    let schema = t.batch.schema();
    let (mut fields, mut arrays) = (vec![], vec![]);
    for (i, f) in schema.fields().iter().enumerate() {
        if f.name() == col {
            fields.push(Field::new(col, dt.clone(), true));
            arrays.push(a.clone());
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

fn set_str(dir: &Path, file: &str, col: &str, v: Option<&str>) {
    replace_col(
        dir,
        file,
        col,
        DataType::Utf8,
        Arc::new(StringArray::from(vec![v])),
    );
}

fn set_f64(dir: &Path, file: &str, col: &str, v: Vec<Option<f64>>) {
    replace_col(
        dir,
        file,
        col,
        DataType::Float64,
        Arc::new(Float64Array::from(v)),
    );
}

/// weft-simulate fails with exit code 1, every fragment in stderr, no panic, no tables.
fn case(f: impl Fn(&Path), fragments: &[&str]) {
    let dir = tempfile::tempdir().unwrap();
    let model = good_model(dir.path());
    f(&model);
    let out = dir.path().join("out");
    let o = Command::new(env!("CARGO_BIN_EXE_weft-simulate"))
        .args(["--quiet", "--model"])
        .arg(&model)
        .arg("--out")
        .arg(&out)
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "exit code; stderr:\n{err}");
    assert!(!err.contains("panicked"), "panic:\n{err}");
    for fr in fragments {
        assert!(err.contains(fr), "stderr lacks `{fr}`:\n{err}");
    }
    assert!(
        !out.exists() || std::fs::read_dir(&out).unwrap().next().is_none(),
        "tables written after a failure"
    );
}

#[test]
fn the_good_model_runs() {
    let dir = tempfile::tempdir().unwrap();
    let model = good_model(dir.path());
    let o = Command::new(env!("CARGO_BIN_EXE_weft-simulate"))
        .args(["--quiet", "--model"])
        .arg(&model)
        .arg("--out")
        .arg(dir.path().join("out"))
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    // The nodal thickness survives the round trip.
    let m = weft::model::io::read_model(&model).unwrap();
    assert_eq!(
        m.elements[&ElementKind::Quad].thickness[..4],
        [1e-4, 1.2e-4, 1.2e-4, 1e-4]
    );
    assert_eq!(m.contacts.len(), 1);
}

#[test]
fn unknown_master_part() {
    case(
        |m| set_str(m, "contacts.parquet", "master_part", Some("sail")),
        &[
            "contacts.parquet",
            "master_part",
            "row 0",
            "part `sail` does not exist",
            "`band`",
        ],
    );
}

#[test]
fn unknown_slave_set() {
    case(
        |m| set_str(m, "contacts.parquet", "slave_set", Some("moon")),
        &[
            "contacts.parquet",
            "slave_set",
            "row 0",
            "node set `moon` does not exist",
            "`ball`",
        ],
    );
}

#[test]
fn neither_slave_part_nor_set() {
    case(
        |m| set_str(m, "contacts.parquet", "slave_set", None),
        &[
            "contacts.parquet",
            "row 0",
            "exactly one of slave_part and slave_set",
        ],
    );
}

#[test]
fn negative_friction() {
    case(
        |m| set_f64(m, "contacts.parquet", "static_friction", vec![Some(-0.3)]),
        &[
            "contacts.parquet",
            "static_friction",
            "row 0",
            "`-0.3`",
            "≥ 0",
        ],
    );
}

#[test]
fn dynamic_above_static_friction() {
    case(
        |m| set_f64(m, "contacts.parquet", "dynamic_friction", vec![Some(0.5)]),
        &[
            "contacts.parquet",
            "dynamic_friction",
            "0.5 exceeds static_friction 0.2",
        ],
    );
}

#[test]
fn negative_thickness() {
    case(
        |m| set_f64(m, "contacts.parquet", "slave_thickness", vec![Some(-1e-4)]),
        &[
            "contacts.parquet",
            "slave_thickness",
            "row 0",
            "`-0.0001`",
            "thickness ≥ 0",
        ],
    );
}

#[test]
fn surface_without_faces() {
    case(
        |m| set_str(m, "contacts.parquet", "master_part", Some("ball")),
        &[
            "contacts.parquet",
            "master_part",
            "row 0",
            "`ball` is a point_mass part and has no faces or segments",
        ],
    );
}

#[test]
fn bad_penalty_scale() {
    case(
        |m| set_f64(m, "contacts.parquet", "penalty_scale", vec![Some(0.0)]),
        &["contacts.parquet", "penalty_scale", "`0`", "> 0"],
    );
}

#[test]
fn unknown_initial_penetration_mode() {
    case(
        |m| set_str(m, "contacts.parquet", "initial_penetration", Some("launch")),
        &[
            "contacts.parquet",
            "initial_penetration",
            "`launch`",
            "`track` (default), `error` or `keep`",
        ],
    );
}

#[test]
fn initial_penetration_as_an_error() {
    // The ball starts 0.05 mm deep (contact distance 0.11 mm at the face centre).
    case(
        |m| {
            set_str(m, "contacts.parquet", "initial_penetration", Some("error"));
            let t = Table::read(&m.join("nodes.parquet")).unwrap();
            let mut z = t.f64_opt("z").unwrap().unwrap();
            *z.last_mut().unwrap() = Some(6e-5);
            set_f64(m, "nodes.parquet", "z", z);
        },
        &[
            "contacts.parquet",
            "initial_penetration",
            "node `100` starts",
            "inside the surface of quad",
            "hint:",
        ],
    );
}

#[test]
fn negative_nodal_thickness() {
    case(
        |m| {
            let t = Table::read(&m.join("elements_quad.parquet")).unwrap();
            let mut v = t.f64_opt("t3").unwrap().unwrap();
            v[1] = Some(-2e-4);
            set_f64(m, "elements_quad.parquet", "t3", v);
        },
        &["elements_quad.parquet", "t3", "row 1", "`-0.0002`", "≥ 0"],
    );
}
