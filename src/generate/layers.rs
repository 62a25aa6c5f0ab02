//! Two crossing layers of flat bands in contact: the contact benchmark and test model.
//!
//! Layer A: bands along x at z = 0; layer B: bands along y at z = t (the layers touch:
//! the contact distance of two bands of thickness t is t). Each band is w wide with
//! `across` quads across and `per_spacing` quads per spacing p along; both ends of every
//! band are clamped; every free node of layer B is pushed towards A by `load`, so every
//! crossing stays in contact (two-way node-to-surface contact with friction μ between
//! the layers).
//!
//! ```text
//!   y ^   |B|   |B|   |B|
//!     | ==+=====+=====+==  A
//!     |   | |   | |   | |
//!     | ==+=====+=====+==  A      bands w wide at spacing p, nb per layer
//!     +--------------------> x
//! ```

use crate::model::contacts::{ContactDef, Slave};
use crate::model::{Analysis, ElementKind, Load, Model, PartProps, TimeLaw};

/// Parameters of [`crossing_bands`].
#[derive(Debug, Clone, Copy)]
pub struct CrossingBands {
    /// Bands per layer.
    pub bands: usize,
    /// Band spacing p [m].
    pub spacing: f64,
    /// Band width w [m].
    pub width: f64,
    /// Band thickness t [m].
    pub thickness: f64,
    /// Quads per spacing along a band, and across its width.
    pub per_spacing: usize,
    pub across: usize,
    /// Force on each free node of layer B, towards A [N].
    pub load: f64,
    /// Coulomb friction between the layers.
    pub friction: f64,
}

impl Default for CrossingBands {
    fn default() -> Self {
        // Aramid-like bands (docs/theory.md, "Material data and defaults"): 1 mm spacing,
        // 0.6 mm × 0.1 mm.
        CrossingBands {
            bands: 6,
            spacing: 1e-3,
            width: 0.6e-3,
            thickness: 1e-4,
            per_spacing: 4,
            across: 2,
            load: 2e-4,
            friction: 0.2,
        }
    }
}

impl CrossingBands {
    /// The number of bands per layer that gives about `nodes` nodes in all.
    pub fn with_nodes(nodes: usize) -> CrossingBands {
        let d = CrossingBands::default();
        // Nodes ≈ 2 · nb · (per_spacing·nb + 1) · (across + 1).
        let per = (d.per_spacing * (d.across + 1) * 2) as f64;
        let nb = ((nodes as f64 / per).sqrt()).round().max(2.0) as usize;
        CrossingBands { bands: nb, ..d }
    }
}

/// The two-layer model (see the module docs).
pub fn crossing_bands(c: &CrossingBands) -> Model {
    let mut m = Model::default();
    let props = |angle: f64| PartProps {
        youngs_modulus_1: Some(80e9),
        youngs_modulus_2: Some(2e9),
        shear_modulus_12: Some(1e9),
        poisson_ratio_12: Some(0.0),
        density: Some(1440.0),
        thickness: Some(c.thickness),
        material_angle: Some(angle),
        ..Default::default()
    };
    let pa = m.add_part(1, "layer_a", ElementKind::Quad, props(0.0));
    let pb = m.add_part(
        2,
        "layer_b",
        ElementKind::Quad,
        props(std::f64::consts::FRAC_PI_2),
    );
    let length = c.bands as f64 * c.spacing;
    let nl = c.bands * c.per_spacing;
    let (mut nid, mut eid) = (0i64, 0i64);
    for layer in 0..2 {
        for b in 0..c.bands {
            let centre = (b as f64 + 0.5) * c.spacing;
            let mut idx = vec![vec![0usize; c.across + 1]; nl + 1];
            for i in 0..=nl {
                for j in 0..=c.across {
                    let s = i as f64 * length / nl as f64;
                    let r = centre - 0.5 * c.width + j as f64 * c.width / c.across as f64;
                    let x = if layer == 0 {
                        [s, r, 0.0]
                    } else {
                        [r, s, c.thickness]
                    };
                    nid += 1;
                    let n = m.add_node(nid, x);
                    idx[i][j] = n;
                    if i == 0 || i == nl {
                        m.constraints.push((n, [true, true, true]));
                    } else if layer == 1 {
                        let id = m.loads.len() as i64 + 1;
                        m.loads.push(Load {
                            id,
                            node: n,
                            force: [0.0, 0.0, -c.load],
                            law: TimeLaw::Step { start: 0.0 },
                        });
                    }
                }
            }
            for i in 0..nl {
                for j in 0..c.across {
                    eid += 1;
                    // Counter-clockwise seen from +z.
                    let q = if layer == 0 {
                        [idx[i][j], idx[i + 1][j], idx[i + 1][j + 1], idx[i][j + 1]]
                    } else {
                        [idx[i][j], idx[i][j + 1], idx[i + 1][j + 1], idx[i + 1][j]]
                    };
                    m.add_element(eid, if layer == 0 { pa } else { pb }, &q);
                }
            }
        }
    }
    let mut d = ContactDef::new(1, Slave::Part(pb), pa).with_friction(c.friction);
    d.two_way = true;
    m.contacts.push(d);
    m.analysis = Analysis {
        end_time: 2e-6,
        output_interval: 1e-7,
        ..Analysis::default()
    };
    m
}
