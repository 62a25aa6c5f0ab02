//! Bit-identical results whatever the thread count.
//!
//! Reference: the "Parith/ON" principle of OpenRadioss and MFEM's assemble-twice check:
//! per-element contributions are summed in a fixed order, and reductions run over fixed
//! chunks summed in chunk order, so the floating-point result cannot depend on how work
//! is split between threads.
//!
//! ```text
//!   o--o--o--o-- ... 6000 trusses ... --o   <- axial pulse
//!   |  |  |  |                          |      links: springs, dashpots, slider
//!   m  m  m  m   ... point masses ...   m   <- transverse step load on one mass
//! ```

use std::path::Path;

use arrow_array::{Array, Float64Array, Int64Array};
use weft::model::io::write_model;
use weft::model::{ElementKind, Load, Model, PartProps, TimeLaw};
use weft::simulate::{run, Config};
use weft::table::{Provenance, Table};

fn model(n: usize) -> Model {
    let mut m = Model::default();
    let h = 1e-3;
    for i in 0..=n {
        m.add_node(i as i64 + 1, [i as f64 * h, 0.0, 0.0]);
    }
    for i in 0..=n {
        m.add_node((n + 2 + i) as i64, [i as f64 * h, 2e-3, 0.0]);
    }
    let rod = m.add_part(
        1,
        "rod",
        ElementKind::Truss,
        PartProps {
            youngs_modulus: Some(8e10),
            density: Some(1440.0),
            area: Some(1e-7),
            ..Default::default()
        },
    );
    let link = m.add_part(
        2,
        "crossing",
        ElementKind::Link,
        PartProps {
            kx: Some(2e4),
            ky: Some(2e4),
            kz: Some(5e5),
            cx: Some(1e-3),
            cy: Some(1e-3),
            cz: Some(1e-2),
            slip_force: Some(0.05),
            ..Default::default()
        },
    );
    let pm = m.add_part(
        3,
        "mass",
        ElementKind::PointMass,
        PartProps {
            mass: Some(1e-6),
            ..Default::default()
        },
    );
    let mut id = 1;
    for i in 0..n {
        m.add_element(id, rod, &[i, i + 1]);
        id += 1;
    }
    for i in 0..=n {
        m.add_element(id, link, &[i, n + 1 + i]);
        m.add_element(id + 1, pm, &[n + 1 + i]);
        id += 2;
    }
    m.constraints.push((0, [true, true, true]));
    m.loads.push(Load {
        id: 1,
        node: n,
        force: [5.0, 0.0, 0.0],
        law: TimeLaw::SinePulse {
            start: 0.0,
            duration: 2e-6,
        },
    });
    m.loads.push(Load {
        id: 2,
        node: n + 1 + n / 2,
        force: [0.3, 0.1, 1.0],
        law: TimeLaw::Step { start: 0.0 },
    });
    m.analysis.end_time = 3e-6;
    m.analysis.output_interval = 1e-7;
    m
}

fn f64_bits(t: &Table, c: &str) -> Vec<u64> {
    let a = t.batch.column_by_name(c).unwrap();
    if let Some(f) = a.as_any().downcast_ref::<Float64Array>() {
        f.values().iter().map(|v| v.to_bits()).collect()
    } else {
        let i = a.as_any().downcast_ref::<Int64Array>().unwrap();
        i.values().iter().map(|v| *v as u64).collect()
    }
}

fn run_with(dir: &Path, threads: usize) -> (Table, Table) {
    let out = dir.join(format!("out{threads}"));
    let cfg = Config {
        model: dir.join("model"),
        out: out.clone(),
        threads: Some(threads),
        ..Default::default()
    };
    let r = run(&cfg, &mut |_| {}).unwrap();
    assert_eq!(r.stats.threads, threads);
    (
        Table::read(&out.join("history.parquet")).unwrap(),
        Table::read(&out.join("energy.parquet")).unwrap(),
    )
}

#[test]
fn one_two_and_three_threads_give_bit_identical_tables() {
    let dir = tempfile::tempdir().unwrap();
    let m = model(6000); // 6000 trusses, 6001 links: several chunks of 2048 per group
    write_model(
        &m,
        &dir.path().join("model"),
        &Provenance::new("test", serde_json::json!({})),
    )
    .unwrap();
    let (h1, e1) = run_with(dir.path(), 1);
    let mut nonzero = 0;
    for threads in [2, 3] {
        let (h, e) = run_with(dir.path(), threads);
        assert_eq!(h.num_rows(), h1.num_rows());
        for c in ["t", "node_id", "ux", "uy", "uz", "vx", "vy", "vz"] {
            assert!(
                f64_bits(&h, c) == f64_bits(&h1, c),
                "history column `{c}` differs with {threads} threads"
            );
        }
        for f in e1.batch.schema().fields() {
            let c = f.name();
            assert!(
                f64_bits(&e, c) == f64_bits(&e1, c),
                "energy column `{c}` differs with {threads} threads"
            );
        }
        nonzero = f64_bits(&h, "uz").iter().filter(|b| **b != 0).count();
    }
    // The comparison is not vacuous: the links and the slider did work.
    assert!(nonzero > 100);
    let fric = e1.batch.column_by_name("friction").unwrap();
    let fric = fric.as_any().downcast_ref::<Float64Array>().unwrap();
    assert!(fric.value(fric.len() - 1) > 0.0, "the slider never slipped");
}
