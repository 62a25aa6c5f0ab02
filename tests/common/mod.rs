//! Helpers shared by the integration tests: small models built in code.
#![allow(dead_code)]

use std::path::{Path, PathBuf};

use weft::model::{Analysis, ElementKind, Load, Model, PartProps, TimeLaw};

pub mod solid;
pub mod woven;

/// Node 0 fixed, node 1 a point mass `m` joined to it by a link (k, c along x) and free
/// along x only. Returns the model; initial velocity and loads are added by the caller.
pub fn oscillator(m: f64, k: f64, c: f64) -> Model {
    let mut md = Model::default();
    md.add_node(1, [0.0, 0.0, 0.0]);
    md.add_node(2, [0.0, 0.0, 0.0]);
    let link = md.add_part(
        1,
        "spring",
        ElementKind::Link,
        PartProps {
            kx: Some(k),
            cx: Some(c),
            ..Default::default()
        },
    );
    let pm = md.add_part(
        2,
        "mass",
        ElementKind::PointMass,
        PartProps {
            mass: Some(m),
            ..Default::default()
        },
    );
    md.add_element(1, link, &[0, 1]);
    md.add_element(2, pm, &[1]);
    md.constraints.push((0, [true, true, true]));
    md.constraints.push((1, [false, true, true]));
    md.analysis = Analysis::default();
    md
}

pub fn step_load(node: usize, f: [f64; 3]) -> Load {
    Load {
        id: 1,
        node,
        force: f,
        law: TimeLaw::Step { start: 0.0 },
    }
}

/// Relative error |a − b| / |b|.
pub fn rel(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs()
}

/// First time a series crosses `level` upwards, linearly interpolated.
pub fn crossing(t: &[f64], y: &[f64], level: f64) -> Option<f64> {
    for i in 1..y.len() {
        if y[i - 1] < level && y[i] >= level {
            return Some(t[i - 1] + (level - y[i - 1]) / (y[i] - y[i - 1]) * (t[i] - t[i - 1]));
        }
    }
    None
}

/// All upward crossings of `level`, linearly interpolated.
pub fn crossings(t: &[f64], y: &[f64], level: f64) -> Vec<f64> {
    (1..y.len())
        .filter(|&i| y[i - 1] < level && y[i] >= level)
        .map(|i| t[i - 1] + (level - y[i - 1]) / (y[i] - y[i - 1]) * (t[i] - t[i - 1]))
        .collect()
}

/// A small model with every feature the tables carry: trusses, links (slider and
/// dashpots), point masses, quads and triangles tied together, beams with rotation
/// constraints, a symmetry plane, a projectile, a tabulated and a pulse load.
pub fn composite() -> weft::model::Model {
    use weft::model::*;
    let mut m = Model::default();
    let mut id = 0i64;
    let mut node = |m: &mut Model, x: [f64; 3]| {
        id += 1;
        m.add_node(id, x)
    };
    // Quad patch 4 × 4 on [0, 0.02]², triangle patch 2 × 2 on [0.02, 0.04] × [0, 0.02].
    let mut q = vec![];
    for j in 0..=4 {
        for i in 0..=4 {
            q.push(node(&mut m, [0.005 * i as f64, 0.005 * j as f64, 0.0]));
        }
    }
    let mut t = vec![];
    for j in 0..=2 {
        for i in 0..=2 {
            t.push(node(&mut m, [0.02 + 0.01 * i as f64, 0.01 * j as f64, 0.0]));
        }
    }
    let mem = |e1: f64| PartProps {
        youngs_modulus_1: Some(e1),
        youngs_modulus_2: Some(0.5 * e1),
        poisson_ratio_12: Some(0.2),
        shear_modulus_12: Some(0.1 * e1),
        thickness: Some(2e-4),
        density: Some(1440.0),
        material_angle: Some(0.2),
        ..Default::default()
    };
    let pq = m.add_part(
        1,
        "fine",
        ElementKind::Quad,
        PartProps {
            hourglass: Some(0.05),
            ..mem(3e10)
        },
    );
    let pt = m.add_part(
        2,
        "coarse",
        ElementKind::Tri,
        PartProps {
            no_compression: Some(true),
            ..mem(2e10)
        },
    );
    let mut eid = 0i64;
    for j in 0..4 {
        for i in 0..4 {
            eid += 1;
            let ns = [
                q[j * 5 + i],
                q[j * 5 + i + 1],
                q[(j + 1) * 5 + i + 1],
                q[(j + 1) * 5 + i],
            ];
            if j == 3 {
                // The last row has a nodal thickness growing along y (band-like).
                m.add_element_with_thickness(eid, pq, &ns, &[1e-4, 1e-4, 1.4e-4, 1.4e-4]);
            } else {
                m.add_element(eid, pq, &ns);
            }
        }
    }
    for j in 0..2 {
        for i in 0..2 {
            let (a, b, c, d) = (
                t[j * 3 + i],
                t[j * 3 + i + 1],
                t[(j + 1) * 3 + i + 1],
                t[(j + 1) * 3 + i],
            );
            eid += 1;
            m.add_element(eid, pt, &[a, b, c]);
            eid += 1;
            m.add_element(eid, pt, &[a, c, d]);
        }
    }
    // The quad patch's right edge (x = 0.02) is tied to the triangle patch's left edge.
    for j in 0..=4 {
        let k = (j / 2).min(1);
        m.ties.push(Tie {
            slave: q[j * 5 + 4],
            masters: vec![t[k * 3], t[(k + 1) * 3]],
        });
    }
    // Beams along x from the triangle patch's right edge, with a point mass at the end,
    // a truss and a link with slider and dashpots to a fixed anchor.
    let pb = m.add_part(
        3,
        "rods",
        ElementKind::Beam,
        PartProps {
            youngs_modulus: Some(1.5e11),
            density: Some(7800.0),
            width: Some(5e-4),
            height: Some(3e-4),
            poisson_ratio: Some(0.0),
            ..Default::default()
        },
    );
    let mut prev = t[2];
    let mut b_nodes = vec![];
    for k in 1..=4 {
        let n = node(&mut m, [0.04 + 0.005 * k as f64, 0.0, 0.0]);
        eid += 1;
        m.add_element(eid, pb, &[prev, n]);
        b_nodes.push(n);
        prev = n;
    }
    let tip = prev;
    let ptr = m.add_part(
        4,
        "yarn",
        ElementKind::Truss,
        PartProps {
            youngs_modulus: Some(8e10),
            density: Some(1440.0),
            area: Some(1e-7),
            tension_only: Some(true),
            ..Default::default()
        },
    );
    let far = node(&mut m, [0.07, 0.0, 0.0]);
    eid += 1;
    m.add_element(eid, ptr, &[tip, far]);
    let pm = m.add_part(
        5,
        "bead",
        ElementKind::PointMass,
        PartProps {
            mass: Some(1e-4),
            ..Default::default()
        },
    );
    eid += 1;
    m.add_element(eid, pm, &[far]);
    let anchor = node(&mut m, [0.07, 0.0, 0.0]);
    let pl = m.add_part(
        6,
        "crossing",
        ElementKind::Link,
        PartProps {
            kx: Some(1e4),
            ky: Some(1e4),
            kz: Some(5e4),
            cx: Some(0.01),
            cy: Some(0.01),
            cz: Some(0.02),
            slip_force: Some(0.01),
            ..Default::default()
        },
    );
    eid += 1;
    m.add_element(eid, pl, &[far, anchor]);
    m.constraints.push((anchor, [true, true, true]));
    for j in 0..=4 {
        m.constraints.push((q[j * 5], [true, true, true]));
    }
    m.rot_constraints.push((b_nodes[1], [true, false, false]));
    m.symmetry.push(SymmetryPlane {
        normal: 1,
        position: 0.0,
        tolerance: 1e-9,
    });
    m.projectiles.push(ProjectileSpec {
        id: 1,
        shape: ProjectileShape::Round,
        radius: 2e-3,
        length: 8e-3,
        mass: 1e-3,
        tip: [0.01, 0.01, 1e-4],
        axis: [0.0, 0.0, -1.0],
        velocity: [0.0, 0.0, -50.0],
        prescribed_velocity: false,
        contact_stiffness: None,
        friction: 0.1,
        contact_damping: 0.0,
        segment_contact: true,
    });
    let curve = std::sync::Arc::new(Curve {
        t: vec![0.0, 5e-6, 2e-5],
        value: vec![0.0, 1.0, 0.3],
    });
    m.curves.insert("ramp_hold".into(), curve.clone());
    m.loads.push(Load {
        id: 1,
        node: far,
        force: [2.0, 0.0, 0.5],
        law: TimeLaw::Tabulated {
            name: "ramp_hold".into(),
            curve,
        },
    });
    m.loads.push(Load {
        id: 2,
        node: t[8],
        force: [0.0, 0.0, -1.0],
        law: TimeLaw::SinePulse {
            start: 1e-6,
            duration: 5e-6,
        },
    });
    m.node_sets.insert("beam".into(), b_nodes);
    // Contact: the yarn's nodes against the quad patch's faces, with friction.
    let mut c =
        weft::model::contacts::ContactDef::new(1, weft::model::contacts::Slave::Part(ptr), pq)
            .with_friction(0.15);
    c.dynamic_friction = 0.1;
    c.friction_decay = 10.0;
    m.contacts.push(c);
    m.analysis.end_time = 3e-5;
    m.analysis.output_interval = 1e-6;
    m
}

/// Runs a binary, asserting success (its stderr in the failure message); returns its
/// stderr.
pub fn run_ok(exe: &str, args: &[&str]) -> String {
    let o = std::process::Command::new(exe).args(args).output().unwrap();
    assert!(
        o.status.success(),
        "{exe} {args:?}: {}",
        String::from_utf8_lossy(&o.stderr)
    );
    String::from_utf8_lossy(&o.stderr).to_string()
}

/// Every file under `root/runs`, relative to `root`, sorted.
pub fn tables(root: &Path) -> Vec<PathBuf> {
    fn walk(d: &Path, out: &mut Vec<PathBuf>) {
        for e in std::fs::read_dir(d).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                walk(&p, out);
            } else {
                out.push(p);
            }
        }
    }
    let mut v = vec![];
    walk(&root.join("runs"), &mut v);
    v.iter_mut()
        .for_each(|p| *p = p.strip_prefix(root).unwrap().to_path_buf());
    v.sort();
    v
}

/// Timing columns of the weft tables: wall times and the throughput derived from them.
pub fn timing(column: &str) -> bool {
    column.starts_with("wall_time")
        || column == "impacts_wall_time"
        || column == "element_updates_per_second"
}

/// Whether two projects' `runs/` hold the same files: tables equal column by column,
/// the timing columns aside (Parquet metadata names paths and is not compared), other
/// files byte for byte. Returns the number of files.
pub fn same_outputs(a: &Path, b: &Path) -> Result<usize, String> {
    let (ta, tb) = (tables(a), tables(b));
    if ta != tb {
        return Err(format!("different files:\n{ta:?}\n{tb:?}"));
    }
    for rel in &ta {
        if rel.extension().is_some_and(|e| e == "parquet") {
            let (x, y) = (
                weft::table::Table::read(&a.join(rel)).unwrap(),
                weft::table::Table::read(&b.join(rel)).unwrap(),
            );
            let (sx, sy) = (x.batch.schema(), y.batch.schema());
            let names: Vec<&String> = sx.fields().iter().map(|f| f.name()).collect();
            let names_y: Vec<&String> = sy.fields().iter().map(|f| f.name()).collect();
            if names != names_y || x.num_rows() != y.num_rows() {
                return Err(format!("{}: columns or rows differ", rel.display()));
            }
            for n in names.iter().filter(|n| !timing(n)) {
                if x.batch.column_by_name(n) != y.batch.column_by_name(n) {
                    return Err(format!("{}: column `{n}` differs", rel.display()));
                }
            }
        } else if std::fs::read(a.join(rel)).unwrap() != std::fs::read(b.join(rel)).unwrap() {
            return Err(format!("{} differs", rel.display()));
        }
    }
    Ok(ta.len())
}
pub mod optional;

/// A fresh project (a temporary folder) holding a copy of `pipelines/<pipeline>`.
pub fn project_with(pipeline: &str) -> tempfile::TempDir {
    let dir = tempfile::tempdir().unwrap();
    std::fs::create_dir_all(dir.path().join("pipelines")).unwrap();
    std::fs::copy(
        Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("pipelines")
            .join(pipeline),
        dir.path().join("pipelines").join(pipeline),
    )
    .unwrap();
    dir
}

/// `weft run pipelines/<pipeline>` in `root`; its stderr (it must succeed).
pub fn weft_run(root: &Path, pipeline: &str) -> String {
    let o = std::process::Command::new(env!("CARGO_BIN_EXE_weft"))
        .args(["run", &format!("pipelines/{pipeline}")])
        .current_dir(root)
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&o.stderr).to_string();
    assert!(o.status.success(), "weft run {pipeline} failed:\n{err}");
    err
}

/// The energies of the named regions in an in-memory run's samples, and the fraction of
/// the first region's launched energy (at t = 0) that is back in it over `window` [s]:
/// a pulse's reflection at an interface (`weft-energy`'s reflection, measured as the
/// stage measures it).
pub fn reflected_fraction(
    m: &Model,
    out: &weft::solver::output::MemorySink,
    regions: &[&str],
    window: (f64, f64),
) -> (weft::analysis::energy::RegionEnergies, f64) {
    use weft::analysis::energy::{reflection, region_energies, Region};
    let regions: Vec<Region> = regions.iter().map(|r| Region::parse(r).unwrap()).collect();
    let en = region_energies(m, &regions, &out.t, &out.u, &out.v, Path::new("(memory)")).unwrap();
    let r = reflection(
        &regions[0].name,
        &en.t,
        &en.total(0),
        Some(0.0),
        Some(window),
    )
    .unwrap();
    assert!(
        r.window_samples > 50,
        "{} samples in the window",
        r.window_samples
    );
    (en, r.reflection)
}
