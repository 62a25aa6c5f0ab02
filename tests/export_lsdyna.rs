//! `weft-export --format lsdyna` writes a structurally sound LS-DYNA keyword deck.
//!
//! LS-DYNA is not available here, so the deck is checked for structure against the
//! model (reference: LS-DYNA Keyword User's Manual, R13, for the card layouts): it opens
//! with `*KEYWORD` and ends with `*END`, states its units, has one `*NODE` line per node,
//! one element per weft element (shells with their nodal thicknesses, a triangle as a
//! quad with n4 = n3), one discrete element per link axis with a spring or dashpot, every
//! element's part defined with a section and a material that exist, every node an
//! element or boundary names defined, every load's curve defined, unique element ids, the
//! end time and output interval of the model.
//!
//! Case: the composite model of `tests/common` without what the LS-DYNA writer refuses
//! (beams, the link's slider, the tension field, the tension-only law, ties, contact,
//! projectile): quads with a row of nodal thicknesses, triangles, a truss, a point mass, a
//! link with springs and dashpots, a symmetry plane, a tabulated and a sine-pulse load.

mod common;
use std::collections::{BTreeMap, HashMap, HashSet};
use std::process::Command;

use weft::model::{ElementKind, Model};

fn supported() -> Model {
    let mut m = common::composite();
    m.elements.remove(&ElementKind::Beam);
    m.rot_constraints.clear();
    m.ties.clear();
    m.contacts.clear();
    m.projectiles.clear();
    for p in &mut m.parts {
        p.props.slip_force = None;
        p.props.no_compression = None;
        p.props.tension_only = None;
    }
    m.initial_velocities.push((0, [0.0, 0.0, 0.0]));
    m.initial_velocities.push((3, [0.0, 0.0, -2.0]));
    m
}

/// Data lines (comments dropped) of every keyword, in order of appearance.
fn cards(deck: &str) -> Vec<(String, Vec<Vec<String>>)> {
    let mut out: Vec<(String, Vec<Vec<String>>)> = vec![];
    for line in deck.lines() {
        if line.starts_with('$') {
            continue;
        }
        if let Some(k) = line.strip_prefix('*') {
            out.push((k.trim().to_string(), vec![]));
        } else if let Some(last) = out.last_mut() {
            last.1
                .push(line.split(',').map(|f| f.trim().to_string()).collect());
        }
    }
    out
}

#[test]
fn the_lsdyna_deck_has_every_node_element_part_and_curve_it_refers_to() {
    let dir = tempfile::tempdir().unwrap();
    let model = dir.path().join("m");
    let prov = weft::table::Provenance::new("test", serde_json::json!({}));
    let m = supported();
    weft::model::io::write_model(&m, &model, &prov).unwrap();
    let deck = dir.path().join("m.k");
    let o = Command::new(env!("CARGO_BIN_EXE_weft-export"))
        .args([
            "--model",
            model.to_str().unwrap(),
            "--format",
            "lsdyna",
            "--out",
        ])
        .arg(&deck)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    eprintln!("{}", String::from_utf8_lossy(&o.stderr));
    let text = std::fs::read_to_string(&deck).unwrap();
    assert!(text.starts_with("*KEYWORD\n") && text.ends_with("*END\n"));
    assert!(text.contains("Units: SI (m, kg, s, N, Pa)"));
    let c = cards(&text);
    let all = |k: &str| -> Vec<Vec<String>> {
        c.iter()
            .filter(|(n, _)| n == k)
            .flat_map(|(_, l)| l.clone())
            .collect()
    };
    let int = |s: &String| s.parse::<i64>().unwrap();
    let float = |s: &String| s.parse::<f64>().unwrap();
    // Nodes.
    let nodes: HashSet<i64> = all("NODE").iter().map(|l| int(&l[0])).collect();
    assert_eq!(all("NODE").len(), m.num_nodes());
    assert_eq!(nodes, m.node_id.iter().copied().collect());
    // Parts with their sections and materials.
    let mut secs = HashSet::new();
    for k in ["SECTION_BEAM", "SECTION_SHELL", "SECTION_DISCRETE"] {
        for (n, l) in &c {
            if n == k {
                secs.insert(int(&l[0][0]));
            }
        }
    }
    let mut mats = HashSet::new();
    for (n, l) in &c {
        if n.starts_with("MAT_") {
            mats.insert(int(&l[0][0]));
        }
    }
    let mut parts = HashSet::new();
    for (n, l) in &c {
        if n == "PART" {
            let (pid, sec, mat) = (int(&l[1][0]), int(&l[1][1]), int(&l[1][2]));
            assert!(secs.contains(&sec) && mats.contains(&mat), "part {pid}");
            parts.insert(pid);
        }
    }
    // Elements: counts, nodes, parts, unique ids.
    let count = |k: ElementKind| m.block(k).map_or(0, |b| b.len());
    let beams = all("ELEMENT_BEAM");
    assert_eq!(beams.len(), count(ElementKind::Truss));
    let shells = all("ELEMENT_SHELL_THICKNESS");
    assert_eq!(
        shells.len(),
        2 * (count(ElementKind::Quad) + count(ElementKind::Tri))
    );
    let discrete = all("ELEMENT_DISCRETE");
    let link = m
        .parts
        .iter()
        .find(|p| p.kind == ElementKind::Link)
        .unwrap();
    let axes = [
        link.props.kx,
        link.props.ky,
        link.props.kz,
        link.props.cx,
        link.props.cy,
        link.props.cz,
    ]
    .iter()
    .filter(|v| v.is_some_and(|v| v > 0.0))
    .count();
    assert_eq!(discrete.len(), axes * count(ElementKind::Link));
    let orient: HashSet<i64> = all("DEFINE_SD_ORIENTATION")
        .iter()
        .map(|l| int(&l[0]))
        .collect();
    assert_eq!(all("ELEMENT_MASS").len(), count(ElementKind::PointMass));
    let mut ids = HashSet::new();
    for l in &beams {
        assert!(ids.insert(int(&l[0])) && parts.contains(&int(&l[1])));
        assert!(nodes.contains(&int(&l[2])) && nodes.contains(&int(&l[3])));
    }
    let thickness: BTreeMap<i64, Vec<f64>> = {
        let q = m.block(ElementKind::Quad).unwrap();
        (0..q.len())
            .filter(|_| !q.thickness.is_empty())
            .map(|e| (q.id[e], q.thickness[4 * e..4 * e + 4].to_vec()))
            .collect()
    };
    for pair in shells.chunks(2) {
        let l = &pair[0];
        let id = int(&l[0]);
        assert!(ids.insert(id) && parts.contains(&int(&l[1])));
        assert!(l[2..6].iter().all(|n| nodes.contains(&int(n))));
        if let Some(t) = thickness.get(&id) {
            let got: Vec<f64> = pair[1][..4].iter().map(float).collect();
            assert_eq!(&got, t, "nodal thickness of element {id}");
        }
    }
    for l in &discrete {
        assert!(ids.insert(int(&l[0])) && parts.contains(&int(&l[1])));
        assert!(nodes.contains(&int(&l[2])) && nodes.contains(&int(&l[3])));
        assert!(orient.contains(&int(&l[4])), "orientation {}", l[4]);
    }
    for l in &all("ELEMENT_MASS") {
        assert!(ids.insert(int(&l[0])) && nodes.contains(&int(&l[1])));
    }
    // Boundaries, loads with their curves, initial velocities.
    for l in &all("BOUNDARY_SPC_NODE") {
        assert!(nodes.contains(&int(&l[0])));
    }
    let curves: HashSet<i64> = c
        .iter()
        .filter(|(n, _)| n == "DEFINE_CURVE")
        .map(|(_, l)| int(&l[0][0]))
        .collect();
    let loads = all("LOAD_NODE_POINT");
    let components: usize = m
        .loads
        .iter()
        .map(|l| l.force.iter().filter(|f| **f != 0.0).count())
        .sum();
    assert_eq!(loads.len(), components);
    for l in &loads {
        assert!(nodes.contains(&int(&l[0])) && curves.contains(&int(&l[2])));
    }
    assert_eq!(
        all("INITIAL_VELOCITY_NODE").len(),
        m.initial_velocities.len()
    );
    // Termination and output.
    assert_eq!(
        float(&all("CONTROL_TERMINATION")[0][0]),
        m.analysis.end_time
    );
    assert_eq!(
        float(&all("DATABASE_NODOUT")[0][0]),
        m.analysis.output_interval
    );
    let hist: Vec<i64> = all("SET_NODE_LIST")[1..]
        .iter()
        .flatten()
        .map(int)
        .collect();
    assert_eq!(hist.len(), m.num_nodes(), "history of every node");
    let by_kind: HashMap<&str, usize> = [
        ("beams", beams.len()),
        ("shells", shells.len() / 2),
        ("discrete", discrete.len()),
    ]
    .into_iter()
    .collect();
    eprintln!(
        "deck: {} nodes, {by_kind:?}, {} curves",
        nodes.len(),
        curves.len()
    );
}

#[test]
fn what_the_lsdyna_writer_does_not_map_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let prov = weft::table::Provenance::new("test", serde_json::json!({}));
    let mut slider = supported();
    for p in &mut slider.parts {
        if p.kind == ElementKind::Link {
            p.props.slip_force = Some(0.01);
        }
    }
    for (name, m, want) in [
        ("beams", common::composite(), "beam elements to LS-DYNA"),
        ("slider", slider, "friction slider of link part `crossing`"),
    ] {
        let model = dir.path().join(name);
        weft::model::io::write_model(&m, &model, &prov).unwrap();
        let deck = dir.path().join(format!("{name}.k"));
        let o = Command::new(env!("CARGO_BIN_EXE_weft-export"))
            .args([
                "--model",
                model.to_str().unwrap(),
                "--format",
                "lsdyna",
                "--out",
            ])
            .arg(&deck)
            .output()
            .unwrap();
        let e = String::from_utf8_lossy(&o.stderr);
        assert!(!o.status.success() && e.contains(want), "{name}: {e}");
        assert!(!deck.exists());
    }
}
