//! Structured meshes of a rectangle [0, lx] × [0, ly] in the plane z = 0.

use crate::model::ElementKind;

/// Nodes (row-major: index j·(nx+1) + i for the node at column i, row j) and
/// counter-clockwise connectivity: quads, or each quad split into two triangles along
/// alternating diagonals (so that the mesh has no preferred direction).
pub fn rectangle(
    nx: usize,
    ny: usize,
    lx: f64,
    ly: f64,
    kind: ElementKind,
) -> (Vec<[f64; 3]>, Vec<Vec<usize>>) {
    let mut nodes = Vec::with_capacity((nx + 1) * (ny + 1));
    for j in 0..=ny {
        for i in 0..=nx {
            nodes.push([lx * i as f64 / nx as f64, ly * j as f64 / ny as f64, 0.0]);
        }
    }
    let id = |i: usize, j: usize| j * (nx + 1) + i;
    let mut elems = Vec::new();
    for j in 0..ny {
        for i in 0..nx {
            let (a, b, c, d) = (id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1));
            match kind {
                ElementKind::Quad => elems.push(vec![a, b, c, d]),
                ElementKind::Tri if (i + j) % 2 == 0 => {
                    elems.push(vec![a, b, c]);
                    elems.push(vec![a, c, d]);
                }
                ElementKind::Tri => {
                    elems.push(vec![a, b, d]);
                    elems.push(vec![b, c, d]);
                }
                k => panic!("rectangle meshes quads or triangles, not {}", k.name()),
            }
        }
    }
    (nodes, elems)
}
