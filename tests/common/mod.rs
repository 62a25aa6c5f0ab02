//! Helpers shared by the integration tests: small models built in code.
#![allow(dead_code)]

use weft::model::{Analysis, ElementKind, Load, Model, PartProps, TimeLaw};

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
