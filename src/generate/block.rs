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
    let lines = |n: usize| (0..=n).map(|i| i as f64 * h).collect::<Vec<f64>>();
    let p = m.add_part(1, name, ElementKind::Hex, props);
    add_hex_grid(&mut m, p, [&lines(nx), &lines(ny), &lines(nz)], 1, 1);
    m
}

/// Adds the structured grid of hexahedra of `part` on the lines `xs`, `ys`, `zs`
/// (ascending): node (i, j, k) at (xs[i], ys[j], zs[k]) with index n₀ + (k (ny + 1) + j)
/// (nx + 1) + i (n₀ the model's node count before) and id `first_node` + that minus n₀;
/// elements in LS-DYNA's corner order (module docs), i fastest, then j, then k, ids from
/// `first_element`. Returns n₀.
pub fn add_hex_grid(
    m: &mut Model,
    part: usize,
    [xs, ys, zs]: [&[f64]; 3],
    first_node: i64,
    first_element: i64,
) -> usize {
    let (nx, ny, nz) = (xs.len() - 1, ys.len() - 1, zs.len() - 1);
    let n0 = m.num_nodes();
    let id = |i: usize, j: usize, k: usize| n0 + (k * (ny + 1) + j) * (nx + 1) + i;
    for (k, &z) in zs.iter().enumerate() {
        for (j, &y) in ys.iter().enumerate() {
            for (i, &x) in xs.iter().enumerate() {
                m.add_node(first_node + (id(i, j, k) - n0) as i64, [x, y, z]);
            }
        }
    }
    let mut e = first_element;
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
                m.add_element(e, part, &ns);
                e += 1;
            }
        }
    }
    n0
}
