//! Closest-point kernels of the contacts: the point of a segment, a triangle, a quad or a
//! face (2, 3 or 4 nodes) nearest to a point, as weights of their nodes. Pure functions,
//! shared by the projectile contact ([`super::projectile`]) and the surface contact
//! ([`super::surface`]).

use crate::solver::vec3::{dot, sub};

/// Closest point of the triangle (a, b, c) to p, as barycentric weights (w_a, w_b, w_c)
/// (Ericson, *Real-Time Collision Detection*, §5.1.5).
#[inline(always)]
pub fn closest_on_triangle(p: &[f64; 3], a: &[f64; 3], b: &[f64; 3], c: &[f64; 3]) -> [f64; 3] {
    let sub = |x: &[f64; 3], y: &[f64; 3]| [x[0] - y[0], x[1] - y[1], x[2] - y[2]];
    let dot = |x: &[f64; 3], y: &[f64; 3]| x[0] * y[0] + x[1] * y[1] + x[2] * y[2];
    let (ab, ac, ap) = (sub(b, a), sub(c, a), sub(p, a));
    let (d1, d2) = (dot(&ab, &ap), dot(&ac, &ap));
    if d1 <= 0.0 && d2 <= 0.0 {
        return [1.0, 0.0, 0.0];
    }
    let bp = sub(p, b);
    let (d3, d4) = (dot(&ab, &bp), dot(&ac, &bp));
    if d3 >= 0.0 && d4 <= d3 {
        return [0.0, 1.0, 0.0];
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        // d1 − d3 = |ab|² is 0 only for a = b: the triangle is a segment (0/0 otherwise).
        if !(d1 - d3 > 0.0) {
            return closest_on_edges(p, a, b, c);
        }
        let v = d1 / (d1 - d3);
        return [1.0 - v, v, 0.0];
    }
    let cp = sub(p, c);
    let (d5, d6) = (dot(&ab, &cp), dot(&ac, &cp));
    if d6 >= 0.0 && d5 <= d6 {
        return [0.0, 0.0, 1.0];
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        if !(d2 - d6 > 0.0) {
            return closest_on_edges(p, a, b, c);
        }
        let w = d2 / (d2 - d6);
        return [1.0 - w, 0.0, w];
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        if !((d4 - d3) + (d5 - d6) > 0.0) {
            return closest_on_edges(p, a, b, c);
        }
        let w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        return [0.0, 1.0 - w, w];
    }
    // va + vb + vc = |ab × ac|² = |ab|²|ac|² sin²θ. Each carries a round-off of order
    // ε|ab|²|ac|², so the weights of a sliver (sin²θ ≤ 10⁻¹⁰) are noise (measured: a
    // collinear triangle gave a point 0.09 of its length off): its edges' nearest point
    // instead, within its height (≤ 10⁻⁵ of its size) of the true one.
    // (d1 − d3 = |ab|², d2 − d6 = |ac|².)
    let area2 = va + vb + vc;
    if !(area2 > SLIVER * (d1 - d3) * (d2 - d6)) {
        return closest_on_edges(p, a, b, c);
    }
    let denom = 1.0 / area2;
    let (v, w) = (vb * denom, vc * denom);
    [1.0 - v - w, v, w]
}

/// sin²θ below which [`closest_on_triangle`] treats a triangle as a sliver.
const SLIVER: f64 = 1e-10;

/// Closest point of the segment (a, b) to p, as the parameter t ∈ [0, 1] of a + t(b − a)
/// (0 for a segment of no length).
#[inline]
pub fn closest_on_segment(p: &[f64; 3], a: &[f64; 3], b: &[f64; 3]) -> f64 {
    let e = sub(b, a);
    let ee = dot(&e, &e);
    if ee > 0.0 {
        (dot(&sub(p, a), &e) / ee).clamp(0.0, 1.0)
    } else {
        0.0
    }
}

/// Closest point of the three edges of a triangle (a, b, c) to p, as weights: the
/// fallback of [`closest_on_triangle`] for a triangle of no area.
#[cold]
fn closest_on_edges(p: &[f64; 3], a: &[f64; 3], b: &[f64; 3], c: &[f64; 3]) -> [f64; 3] {
    let seg = |x: &[f64; 3], y: &[f64; 3]| -> (f64, f64) {
        let t = closest_on_segment(p, x, y);
        let r: [f64; 3] = std::array::from_fn(|d| p[d] - (x[d] + t * (y[d] - x[d])));
        (t, dot(&r, &r))
    };
    let (tab, dab) = seg(a, b);
    let (tbc, dbc) = seg(b, c);
    let (tca, dca) = seg(c, a);
    if dab <= dbc && dab <= dca {
        [1.0 - tab, tab, 0.0]
    } else if dbc <= dca {
        [0.0, 1.0 - tbc, tbc]
    } else {
        [tca, 0.0, 1.0 - tca]
    }
}

/// Closest point of the mid-surface of a face (`n` = 2, 3 or 4 nodes) to `p`: the weights
/// of its nodes. Quads average the two diagonal splits, so the result has no handedness.
#[inline]
pub fn closest_on_face(p: &[f64; 3], x: &[[f64; 3]; 4], n: usize) -> [f64; 4] {
    match n {
        2 => {
            let t = closest_on_segment(p, &x[0], &x[1]);
            [1.0 - t, t, 0.0, 0.0]
        }
        3 => {
            let w = closest_on_triangle(p, &x[0], &x[1], &x[2]);
            [w[0], w[1], w[2], 0.0]
        }
        _ => closest_on_quad(p, x),
    }
}

/// [`closest_on_face`] for a quad.
#[inline]
pub fn closest_on_quad(p: &[f64; 3], x: &[[f64; 3]; 4]) -> [f64; 4] {
    let a = closest_on_triangle(p, &x[0], &x[1], &x[2]);
    let b = closest_on_triangle(p, &x[0], &x[2], &x[3]);
    let c = closest_on_triangle(p, &x[1], &x[2], &x[3]);
    let d = closest_on_triangle(p, &x[1], &x[3], &x[0]);
    // Split 0-2: triangles (0,1,2), (0,2,3); split 1-3: (1,2,3), (1,3,0). Each split
    // takes its nearer triangle; the two splits are averaged.
    // Each triangle's weights on the quad's nodes and the squared distance to its foot.
    // The foot is summed over the triangle's three nodes in node order: the four-term
    // sum less its zero term (the node `skip` not in the triangle), so the same bits.
    let q = |w: [f64; 3], i: [usize; 3]| -> ([f64; 4], f64) {
        let mut ww = [0.0; 4];
        for k in 0..3 {
            ww[i[k]] = w[k];
        }
        let skip = 6 - i[0] - i[1] - i[2];
        let qp: [f64; 3] = std::array::from_fn(|dd| {
            (0..4)
                .filter(|&k| k != skip)
                .fold(-0.0, |s, k| s + ww[k] * x[k][dd])
        });
        let r = sub(p, &qp);
        (ww, dot(&r, &r))
    };
    let (wa, da) = q(a, [0, 1, 2]);
    let (wb, db) = q(b, [0, 2, 3]);
    let (wc, dc) = q(c, [1, 2, 3]);
    let (wd, dd) = q(d, [1, 3, 0]);
    let s1 = if da <= db { wa } else { wb };
    let s2 = if dc <= dd { wc } else { wd };
    std::array::from_fn(|k| 0.5 * (s1[k] + s2[k]))
}

#[cfg(test)]
mod tests {
    use super::closest_on_triangle;
    use crate::solver::contact::{jittered_rectangle, uniform};

    /// The triangle kernel's closest point is the projection onto the triangle: by the
    /// projection theorem for a convex set, q is the closest point of the triangle to p iff
    /// (p − q)·(y − q) ≤ 0 for each of its vertices y (the oracle, independent of the
    /// kernel's Voronoi regions), and its weights are barycentric (≥ 0, summing to 1).
    /// The four triangles of random quads' two splits, warped and flat, with points near
    /// and far; degenerate ones (coincident, collinear nodes) must give finite weights and
    /// a point no farther than any vertex.
    #[test]
    fn triangle_projection_satisfies_the_projection_theorem() {
        let mut st = 11u64;
        let tris = [[0, 1, 2], [0, 2, 3], [1, 2, 3], [1, 3, 0]];
        let (mut n_checked, mut worst) = (0usize, 0.0f64);
        for case in 0..40_000 {
            let mut x = jittered_rectangle(1.0, 0.4, &mut st);
            match case % 8 {
                // Coincident nodes, a collinear quad, a flat one.
                5 => x[2] = x[1],
                6 => {
                    for a in 0..4 {
                        x[a] = [a as f64 * 0.3, 0.0, 0.0];
                    }
                }
                7 => x.iter_mut().for_each(|a| a[2] = 0.0),
                _ => {}
            }
            let mut p: [f64; 3] = std::array::from_fn(|_| 3.0 * (uniform(&mut st) - 0.5) + 0.5);
            match case % 11 {
                // On a vertex, on an edge.
                9 => p = x[(case / 11) % 4],
                10 => p = std::array::from_fn(|d| 0.5 * (x[0][d] + x[1][d])),
                _ => {}
            }
            for t in &tris {
                let w = closest_on_triangle(&p, &x[t[0]], &x[t[1]], &x[t[2]]);
                assert!(
                    w.iter().all(|c| c.is_finite() && *c >= 0.0),
                    "case {case}: {w:?}"
                );
                assert!(
                    (w[0] + w[1] + w[2] - 1.0).abs() < 1e-15,
                    "case {case}: {w:?}"
                );
                let q: [f64; 3] = std::array::from_fn(|d| (0..3).map(|k| w[k] * x[t[k]][d]).sum());
                let r: [f64; 3] = std::array::from_fn(|d| p[d] - q[d]);
                let rr: f64 = r.iter().map(|c| c * c).sum();
                for &y in t {
                    let py: f64 = (0..3).map(|d| (p[d] - x[y][d]).powi(2)).sum();
                    assert!(
                        rr <= py * (1.0 + 1e-14),
                        "case {case}: farther than vertex {y}: {w:?}"
                    );
                }
                if case % 8 == 5 || case % 8 == 6 {
                    continue; // degenerate: the projection theorem needs a true triangle
                }
                for &y in t {
                    let e: f64 = (0..3).map(|d| r[d] * (x[y][d] - q[d])).sum();
                    worst = worst.max(e);
                }
                n_checked += 1;
            }
        }
        // Measured: worst (p − q)·(y − q) 7.6e-16 (round-off on unit-size triangles).
        assert!(n_checked >= 120_000, "{n_checked}");
        assert!(worst < 4e-15, "projection theorem violated by {worst}");
    }
}
