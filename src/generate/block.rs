//! A block of hexahedra: nx × ny × nz cubes of side h from the origin, the structured
//! mesh the solid tests and `weft-bench --solid` build on.
//!
//! Node (i, j, k) at (i h, j h, k h) has index (k (ny + 1) + j)(nx + 1) + i and id
//! index + 1; element (i, j, k) joins the cube's corners in LS-DYNA's order (n1–n4 the
//! face z = k h counter-clockwise seen from +z, n5–n8 above them), ids from 1 in the
//! order i fastest, then j, then k. One part, id 1, of the name and properties given.

use crate::model::{ElementKind, Model, PartProps};

pub fn hex_block(nx: usize, ny: usize, nz: usize, h: f64, name: &str, props: PartProps) -> Model {
    let mut m = Model::default();
    let id = |i: usize, j: usize, k: usize| (k * (ny + 1) + j) * (nx + 1) + i;
    for k in 0..=nz {
        for j in 0..=ny {
            for i in 0..=nx {
                m.add_node(
                    id(i, j, k) as i64 + 1,
                    [i as f64 * h, j as f64 * h, k as f64 * h],
                );
            }
        }
    }
    let p = m.add_part(1, name, ElementKind::Hex, props);
    let mut e = 1;
    for k in 0..nz {
        for j in 0..ny {
            for i in 0..nx {
                let ns = [
                    id(i, j, k),
                    id(i + 1, j, k),
                    id(i + 1, j + 1, k),
                    id(i, j + 1, k),
                    id(i, j, k + 1),
                    id(i + 1, j, k + 1),
                    id(i + 1, j + 1, k + 1),
                    id(i, j + 1, k + 1),
                ];
                m.add_element(e, p, &ns);
                e += 1;
            }
        }
    }
    m
}
