//! Comparing models whose meshes differ: how a reference node's value is read from a
//! candidate, by position (the nearest node), by node id, or interpolated at the
//! reference node's position with the candidate's own element shape functions.

use std::collections::HashMap;

use serde::Serialize;

use super::series::Series;
use crate::error::{Result, WeftError};
use crate::model::{ElementKind, Model};

/// How reference nodes find their candidate values (`--match`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, clap::ValueEnum)]
#[serde(rename_all = "lowercase")]
pub enum Matching {
    // No doc comments here: clap would print them in the value list.
    // The candidate node at the reference node's position (within the tolerance).
    #[default]
    Position,
    // The candidate node with the reference node's id.
    Id,
    // The candidate's displacement interpolated at the reference node's position with
    // the shape functions of the candidate element that contains it.
    Interpolate,
}

/// Per reference node, the candidate series entries and weights whose weighted sum is
/// its candidate value (one entry of weight 1 when matched by position or id).
pub type Pairing = Vec<Vec<(usize, f64)>>;

fn dist(a: &[f64; 3], b: &[f64; 3]) -> f64 {
    ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt()
}

/// For each reference node, the candidate node with the same id.
pub fn match_ids(reference: &Series, candidate: &Series) -> Result<Vec<usize>> {
    let by_id: HashMap<i64, usize> = candidate
        .node_id
        .iter()
        .enumerate()
        .map(|(k, &id)| (id, k))
        .collect();
    reference
        .node_id
        .iter()
        .map(|id| {
            by_id.get(id).copied().ok_or_else(|| {
                WeftError::input(format!(
                    "reference node `{id}` has no candidate node with the same id"
                ))
                .expected("the reference's node ids among the candidate's compared nodes")
                .hint("match by position (--match position) or interpolate (--match interpolate) when the meshes are numbered differently")
            })
        })
        .collect()
}

/// The candidate's elements that interpolation may use, and the model node indices
/// whose values it needs, for reference points `points` (ids `ids`, for errors).
/// `restrict`: only elements all of whose nodes are in this list (a candidate node set).
/// Returns the candidate nodes to read (model indices, sorted) and the pairing onto them.
pub fn interpolation(
    m: &Model,
    restrict: Option<&[usize]>,
    points: &[[f64; 3]],
    ids: &[i64],
    tol: f64,
) -> Result<(Vec<usize>, Pairing)> {
    let allowed: Option<std::collections::HashSet<usize>> =
        restrict.map(|r| r.iter().copied().collect());
    // Candidate elements: (kind, node indices, bounding box).
    let mut elems: Vec<(ElementKind, Vec<usize>, [[f64; 3]; 2])> = vec![];
    for (&kind, block) in &m.elements {
        if !matches!(
            kind,
            ElementKind::Tri | ElementKind::Quad | ElementKind::Truss | ElementKind::Beam
        ) {
            continue;
        }
        let npe = kind.nodes_per_element();
        for nodes in block.nodes.chunks(npe) {
            if let Some(a) = &allowed {
                if !nodes.iter().all(|i| a.contains(i)) {
                    continue;
                }
            }
            let mut bb = [[f64::INFINITY; 3], [f64::NEG_INFINITY; 3]];
            for &i in nodes {
                for (c, &x) in m.coords[i].iter().enumerate() {
                    bb[0][c] = bb[0][c].min(x - tol);
                    bb[1][c] = bb[1][c].max(x + tol);
                }
            }
            elems.push((kind, nodes.to_vec(), bb));
        }
    }
    if elems.is_empty() {
        return Err(WeftError::input(
            "the candidate has no membrane (tri, quad), truss or beam element to interpolate in",
        )
        .expected("a candidate mesh of membranes, trusses or beams")
        .hint("without --candidate-set every element of the candidate counts; a set restricts to the elements all of whose nodes it holds"));
    }
    let mut per_point: Vec<Vec<(usize, f64)>> = Vec::with_capacity(points.len());
    for (j, p) in points.iter().enumerate() {
        let mut best: Option<(f64, Vec<(usize, f64)>)> = None;
        for (kind, nodes, bb) in &elems {
            if (0..3).any(|c| p[c] < bb[0][c] || p[c] > bb[1][c]) {
                continue;
            }
            let x: Vec<[f64; 3]> = nodes.iter().map(|&i| m.coords[i]).collect();
            let found = match kind {
                ElementKind::Tri => tri_weights(&x, p, tol),
                ElementKind::Quad => quad_weights(&x, p, tol),
                _ => line_weights(&x, p, tol),
            };
            if let Some((score, w)) = found {
                if best.as_ref().is_none_or(|b| score > b.0) {
                    best = Some((score, nodes.iter().copied().zip(w).collect()));
                }
            }
        }
        let Some((_, w)) = best else {
            return Err(WeftError::input(format!(
                "reference node `{}` at {:?} lies in no candidate element within {tol:e} m",
                ids[j], p
            ))
            .expected("every reference node inside the candidate's mesh (membrane triangles and quads, trusses, beams)")
            .hint("compare the reference nodes the candidate covers (a node set), or raise --tolerance for a point just off the mesh"));
        };
        per_point.push(w);
    }
    let mut nodes: Vec<usize> = per_point.iter().flatten().map(|w| w.0).collect();
    nodes.sort_unstable();
    nodes.dedup();
    let at: HashMap<usize, usize> = nodes.iter().enumerate().map(|(k, &i)| (i, k)).collect();
    let pairing = per_point
        .into_iter()
        .map(|w| w.into_iter().map(|(i, wt)| (at[&i], wt)).collect())
        .collect();
    Ok((nodes, pairing))
}

fn sub(a: &[f64; 3], b: &[f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}
fn dot(a: &[f64; 3], b: &[f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}
fn longest_edge(x: &[[f64; 3]]) -> f64 {
    let n = x.len();
    (0..n)
        .map(|i| dist(&x[i], &x[(i + 1) % n]))
        .fold(0.0, f64::max)
}

/// Linear shape functions along a truss or beam axis: (score, weights) when `p` lies on
/// the segment within `tol`; the score is how far inside it is (0 at an end).
fn line_weights(x: &[[f64; 3]], p: &[f64; 3], tol: f64) -> Option<(f64, Vec<f64>)> {
    let e = sub(&x[1], &x[0]);
    let d = sub(p, &x[0]);
    let l2 = dot(&e, &e);
    if l2 <= 0.0 {
        return None;
    }
    let t = dot(&d, &e) / l2;
    let slack = tol / l2.sqrt() + 1e-12;
    let r = [d[0] - t * e[0], d[1] - t * e[1], d[2] - t * e[2]];
    if t < -slack || t > 1.0 + slack || dot(&r, &r).sqrt() > tol {
        return None;
    }
    Some((t.min(1.0 - t), vec![1.0 - t, t]))
}

/// Barycentric (linear) shape functions of a triangle.
fn tri_weights(x: &[[f64; 3]], p: &[f64; 3], tol: f64) -> Option<(f64, Vec<f64>)> {
    let (e1, e2, d) = (sub(&x[1], &x[0]), sub(&x[2], &x[0]), sub(p, &x[0]));
    let (a11, a12, a22) = (dot(&e1, &e1), dot(&e1, &e2), dot(&e2, &e2));
    let det = a11 * a22 - a12 * a12;
    if det <= 0.0 {
        return None;
    }
    let (b1, b2) = (dot(&d, &e1), dot(&d, &e2));
    let l1 = (a22 * b1 - a12 * b2) / det;
    let l2 = (a11 * b2 - a12 * b1) / det;
    let l = [1.0 - l1 - l2, l1, l2];
    let r: [f64; 3] = std::array::from_fn(|c| d[c] - l1 * e1[c] - l2 * e2[c]);
    let slack = tol / longest_edge(x) + 1e-12;
    let min = l.iter().copied().fold(f64::INFINITY, f64::min);
    if min < -slack || dot(&r, &r).sqrt() > tol {
        return None;
    }
    Some((min, l.to_vec()))
}

/// Bilinear shape functions of a quadrilateral (nodes in order, ξ, η ∈ [−1, 1]),
/// inverted by Newton's method in the quad's mean plane.
fn quad_weights(x: &[[f64; 3]], p: &[f64; 3], tol: f64) -> Option<(f64, Vec<f64>)> {
    let shape = |xi: f64, eta: f64| -> [f64; 4] {
        [
            0.25 * (1.0 - xi) * (1.0 - eta),
            0.25 * (1.0 + xi) * (1.0 - eta),
            0.25 * (1.0 + xi) * (1.0 + eta),
            0.25 * (1.0 - xi) * (1.0 + eta),
        ]
    };
    let at = |n: &[f64; 4]| -> [f64; 3] {
        std::array::from_fn(|c| (0..4).map(|a| n[a] * x[a][c]).sum())
    };
    let (mut xi, mut eta) = (0.0f64, 0.0f64);
    for _ in 0..30 {
        let r = sub(p, &at(&shape(xi, eta)));
        // ∂x/∂ξ and ∂x/∂η.
        let dxi: [f64; 3] = std::array::from_fn(|c| {
            0.25 * (-(1.0 - eta) * x[0][c] + (1.0 - eta) * x[1][c] + (1.0 + eta) * x[2][c]
                - (1.0 + eta) * x[3][c])
        });
        let deta: [f64; 3] = std::array::from_fn(|c| {
            0.25 * (-(1.0 - xi) * x[0][c] - (1.0 + xi) * x[1][c]
                + (1.0 + xi) * x[2][c]
                + (1.0 - xi) * x[3][c])
        });
        // Least-squares step (Gauss–Newton in 3-D: the normal equations of the 3×2 system).
        let (a11, a12, a22) = (dot(&dxi, &dxi), dot(&dxi, &deta), dot(&deta, &deta));
        let det = a11 * a22 - a12 * a12;
        if det <= 0.0 {
            return None;
        }
        let (b1, b2) = (dot(&r, &dxi), dot(&r, &deta));
        let (dx, de) = ((a22 * b1 - a12 * b2) / det, (a11 * b2 - a12 * b1) / det);
        xi += dx;
        eta += de;
        if !xi.is_finite() || !eta.is_finite() || xi.abs() > 10.0 || eta.abs() > 10.0 {
            return None;
        }
        if dx.abs() < 1e-15 && de.abs() < 1e-15 {
            break;
        }
    }
    let n = shape(xi, eta);
    let r = sub(p, &at(&n));
    let slack = 2.0 * tol / longest_edge(x) + 1e-12;
    if xi.abs() > 1.0 + slack || eta.abs() > 1.0 + slack || dot(&r, &r).sqrt() > tol {
        return None;
    }
    Some((0.5 * (1.0 - xi.abs()).min(1.0 - eta.abs()), n.to_vec()))
}
