//! Every model feature survives the tables: a composite model written by the library and
//! read back is the same model, and simulates to bit-identical results.

mod common;
use arrow_array::{Array, Float64Array};
use weft::model::io::{read_model, write_model};
use weft::simulate::{run, Config};
use weft::solver::run_in_memory;
use weft::table::{Provenance, Table};

#[test]
fn a_composite_model_round_trips_through_its_tables() {
    let m = common::composite();
    let dir = tempfile::tempdir().unwrap();
    write_model(
        &m,
        &dir.path().join("model"),
        &Provenance::new("test", serde_json::json!({})),
    )
    .unwrap();
    let back = read_model(&dir.path().join("model")).unwrap();
    assert_eq!(back.node_id, m.node_id);
    assert_eq!(back.coords, m.coords);
    for (a, b) in back.parts.iter().zip(&m.parts) {
        assert_eq!(a, b);
    }
    assert_eq!(back.elements, m.elements);
    assert_eq!(back.ties, m.ties);
    assert_eq!(back.symmetry, m.symmetry);
    assert_eq!(back.projectiles, m.projectiles);
    assert_eq!(back.node_sets, m.node_sets);
    assert_eq!(back.analysis, m.analysis);
    assert_eq!(back.loads.len(), m.loads.len());
    for (a, b) in back.loads.iter().zip(&m.loads) {
        assert_eq!(
            (a.id, a.node, a.force, &a.law),
            (b.id, b.node, b.force, &b.law)
        );
    }
    let sorted = |v: &Vec<(usize, [bool; 3])>| {
        let mut v = v.clone();
        v.sort();
        v
    };
    assert_eq!(sorted(&back.rot_constraints), sorted(&m.rot_constraints));
    // In memory and from the tables: the same numbers, bit for bit.
    let (_s, mem, _) = run_in_memory(&m).unwrap();
    let cfg = Config {
        model: dir.path().join("model"),
        out: dir.path().join("out"),
        threads: Some(2),
        ..Default::default()
    };
    run(&cfg, &mut |_| {}).unwrap();
    let h = Table::read(&dir.path().join("out/history.parquet")).unwrap();
    let uz = h.batch.column_by_name("uz").unwrap();
    let uz = uz.as_any().downcast_ref::<Float64Array>().unwrap();
    let nn = m.num_nodes();
    assert_eq!(uz.len(), mem.t.len() * nn);
    for k in 0..mem.t.len() {
        for j in 0..nn {
            assert_eq!(
                uz.value(k * nn + j).to_bits(),
                mem.u[k][j][2].to_bits(),
                "sample {k}, node {j}"
            );
        }
    }
    // The run did exercise the features.
    let e = mem.energy.last().unwrap();
    assert!(
        e.contact > 0.0 && e.friction > 0.0 && e.damping > 0.0 && e.hourglass > 0.0,
        "{e:?}"
    );
    assert!(
        // Measured 1.06·10⁻³ of the energy scale; tolerance 2.8×.
        e.balance_error.abs() < 3e-3 * e.external_work.abs().max(0.5 * 1e-3 * 2500.0),
        "{e:?}"
    );
    assert!(dir.path().join("out/projectile.parquet").exists());
}
