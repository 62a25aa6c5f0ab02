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

/// Every element family, ties and contact above their parallel chunk sizes (1024
/// elements per family chunk, 256 slaves per contact chunk), so that their parallel paths
/// run, on 1, 2 and 3 threads: bit-identical histories and energies. Models: the
/// combined girder (beams) and membrane-centre (quads) models tied into a graded membrane,
/// and the quarter 12 × 12 yarn-level woven patch (band quads, yarn–yarn contact with
/// friction, the projectile).
#[test]
fn every_family_ties_and_contact_are_thread_independent_above_their_chunks() {
    use weft::generate::woven::{woven, WovenBandParams};
    use weft::generate::zones::{combined, Centre, CombinedParams, MembraneProps};
    use weft::solver::{run_in_memory, CHUNK};
    let combined_model = |centre: Centre| {
        let (a, b) = (0.02 / 48.0, 0.02 / 480.0);
        let c = (7800.0f64 / 1.5e11).sqrt();
        combined(&CombinedParams {
            centre,
            centre_length: 0.02,
            centre_cells: 48,
            length: 0.06,
            coarsening: 4,
            growth: 1.2,
            quarter: false,
            youngs_modulus: 1.5e11,
            density: 7800.0,
            rod_width: b,
            membrane: MembraneProps {
                youngs_modulus: 1.5e11,
                poisson_ratio: 0.3,
                shear_modulus: 1.5e11 * (b / a).powi(2) / 2.0,
                thickness: b * b / a,
                density: 7800.0 * (2.0 - b / a),
            },
            force: 10.0,
            pulse: 0.005 * c,
            end_time: 0.02 * c,
            output_interval: 0.002 * c,
        })
        .unwrap()
    };
    let (woven_model, _) = woven(&WovenBandParams {
        yarns: 12,
        end_time: 3e-6,
        output_interval: 3e-7,
        ..WovenBandParams::default()
    })
    .unwrap();
    let models = [
        ("combined girder", combined_model(Centre::Girder)),
        ("combined membrane", combined_model(Centre::Membrane)),
        ("woven 12 × 12", woven_model),
    ];
    let count = |m: &weft::model::Model, k: ElementKind| m.elements.get(&k).map_or(0, |b| b.len());
    let beams = count(&models[0].1, ElementKind::Beam);
    let quads = count(&models[1].1, ElementKind::Quad);
    let ties = models[0].1.ties.len();
    let slaves = models[2].1.num_nodes();
    eprintln!("beams {beams}, quads {quads}, ties {ties}, contact slaves {slaves}");
    assert!(
        beams > 2 * CHUNK && quads > 2 * CHUNK && slaves > 4 * 256,
        "models too small"
    );
    assert!(ties > 0 && !models[2].1.contacts.is_empty());
    for (name, m) in &models {
        let run = |threads: usize| {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            pool.install(|| {
                let (_s, out, _) = run_in_memory(m).unwrap();
                (out.u, out.v, out.energy, out.projectile)
            })
        };
        let one = run(1);
        let moved = one
            .0
            .iter()
            .flatten()
            .filter(|u| u[2] != 0.0 || u[0] != 0.0)
            .count();
        assert!(moved > 10, "{name}: nothing moved");
        for threads in [2, 3] {
            let r = run(threads);
            // Bit for bit (f64 == is exact; no NaN can occur in a finished run).
            assert!(
                r.0 == one.0,
                "{name}: displacements differ with {threads} threads"
            );
            assert!(
                r.1 == one.1,
                "{name}: velocities differ with {threads} threads"
            );
            assert!(
                r.2 == one.2,
                "{name}: energies differ with {threads} threads"
            );
            assert!(
                r.3 == one.3,
                "{name}: projectile differs with {threads} threads"
            );
        }
    }
}
