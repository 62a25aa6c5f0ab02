//! Solids in the general contact: a hexahedron part's boundary — the quads that belong to
//! exactly one of its hexahedra — as a master surface, its boundary nodes as slaves, and
//! the one-sided kernel of a solid's face ([`evaluate_solid`]).
//!
//! **The surface.** Each hexahedron has six faces (LS-DYNA's node order: n1–n4 one end,
//! n5–n8 the other); a face whose four nodes no other hexahedron of the part shares is on
//! the boundary. Faces are kept in element order, then the element's face order, with
//! their nodes turned so that the right-hand normal (x₃ − x₁) × (x₄ − x₂) points away from
//! the element's centroid: outward. The contact thickness of a solid's face is t_F = 0 (it
//! is the body's true surface; the slave's own t_s/2 still offsets) or the definition's
//! `master_thickness`.
//!
//! **Sidedness.** A membrane's face is two-sided: a node is pushed away from the
//! mid-surface on whichever side it is. A solid's face must push a node that has passed
//! through it back out, not further in. With n the face's outward unit normal, r = x_s − q
//! (q the closest point of the face), s = n·r and c = (t_s + t_F)/2:
//! - in front (s ≥ 0): as a membrane's face, g = c − |r| along r/|r| (rounded about the
//!   solid's edges and corners);
//! - behind (s < 0) and inside the face's normal prism (the four planes through its edges
//!   along n, within 10⁻⁶ of an edge's length): g = c − s = c + |s| along n, out of the
//!   solid. g is continuous through the face (c − s on both sides of it);
//! - behind but outside the prism: nothing (a node beside the solid, below the plane of a
//!   face whose edge it passed; the neighbouring face sees it).
//! - behind deeper than max(c, R/10) (R below): nothing. A node gets behind a face from
//!   its front only through the penalty, by micrometres; one found deeper came in beside
//!   the prism (a yarn wrapping past the meplat's rim) and would be pushed out with the
//!   energy ½k g² of a spring it never compressed. Measured on a lead bullet through a
//!   60 × 60 chain patch at 400 m/s: catching every depth to R gave an energy balance of
//!   1.5·10⁻² (jumps of 1–5 J near 35 µs), this rule 10⁻⁴ as the rigid projectile's.
//! - behind (g > c) at a node that was open at the last step: it came in beside the face
//!   too (from open, crossing c through the front takes many steps), so its depth is
//!   tracked as an initial penetration is (`narrow`: g₀ = g, the penalty acting on what it
//!   goes deeper, g₀ shrinking as it leaves) instead of pushed out at once. Measured on
//!   4 plies of chains pressed into the backing clay at 150 m/s: a yarn node caught behind
//!   a clay face at 170–180 µs was kicked out with 0.12 J (the balance 5.8·10⁻³ at
//!   220 µs); with the rule, 4.6·10⁻⁴, the runs identical until then.
//!
//! The depth reached behind a face is bounded, so that the thickness boxes stay sound:
//! every hit has |r| < R + t_s/2 with R = max(t_F/2, D), D half the element's depth across
//! the face at the setup (the distance from the face's centroid to the element's). The
//! face's nodes carry t_a = 2R in the side's `face_t` — the thickness boxes, envelope bounds
//! (here along ±n, the thickness being uniform) and every claim of `super` and
//! `staleness` about them hold as for a membrane of thickness 2R, as a hit lies within
//! R + t_s/2 of q — while the penetration uses the true t_F. A node pushed deeper than
//! that (half an element) is lost: the penalty's depth is a few micrometres at ballistic
//! speeds, far less. Behind a concave crease of the surface a node may lie in neither
//! face's prism (a bullet is convex).
//!
//! **Erosion.** An eroded hexahedron's faces leave the surface (as a failed membrane's:
//! what they held is booked into `eroded`). A part whose cells can erode
//! (`erosion_plastic_strain`) keeps its interior faces in the surface too, each twice (once
//! per element, turned outward from it) and dormant; when a cell erodes, its live
//! neighbours' copies of the faces it shared with them wake, and the next step's broad
//! phase builds anew so that they are found (an eroding contact: the crater's floor under
//! an eroded cell is the next cell's face). A slave that finds itself behind a woken face
//! is tracked as above, not kicked out. The part's slaves stay its boundary nodes of the
//! setup: an eroding solid that is also a slave does not gain the nodes erosion uncovers.

use super::kernels::Hit;
use crate::model::{ElementKind, Model};
use crate::shape::hex8::FACES as HEX_FACES;
use crate::solver::contact::closest::closest_on_quad;
use crate::solver::vec3::{cross, dot, sub};

/// The depth behind a face that is still caught, as a fraction of R (when above the
/// contact distance c): see the module doc.
const BEHIND_FRACTION: f64 = 0.1;

/// Lateral tolerance of the prism test, relative to the edge's length.
const PRISM_TOL: f64 = 1e-6;

/// A boundary face of a hexahedron part.
pub(super) struct BoundaryFace {
    /// Its nodes, counter-clockwise seen from outside.
    pub nodes: [u32; 4],
    /// Its element (index in the model's hex block).
    pub elem: u32,
    /// Half the element's depth across it at the setup [m] (D of the module doc).
    pub depth: f64,
    /// The element on its other side (index in the hex block; `u32::MAX`: none, the
    /// face is on the part's boundary).
    pub other: u32,
}

/// The boundary faces of hexahedron part `part` (see the module doc), in element order.
pub(super) fn boundary_faces(m: &Model, part: usize) -> Vec<BoundaryFace> {
    solid_faces(m, part, false)
}

/// The faces of hexahedron part `part` in element order, then each element's face
/// order: its boundary faces and, with `interior`, every face it shares with another
/// element of the part too (each such face twice, once per element, turned outward from
/// it: the face its neighbour's erosion uncovers).
pub(super) fn solid_faces(m: &Model, part: usize, interior: bool) -> Vec<BoundaryFace> {
    let Some(b) = m.elements.get(&ElementKind::Hex) else {
        return vec![];
    };
    let key = |e: usize, f: &[usize; 4]| {
        let mut k: [usize; 4] = std::array::from_fn(|a| b.nodes[8 * e + f[a]]);
        k.sort_unstable();
        k
    };
    let mine = |e: usize| b.part[e] == part;
    // Per face, the elements that have it (two at most in a conforming mesh).
    let mut owners: std::collections::HashMap<[usize; 4], Vec<u32>> = Default::default();
    for e in (0..b.len()).filter(|&e| mine(e)) {
        for f in &HEX_FACES {
            owners.entry(key(e, f)).or_default().push(e as u32);
        }
    }
    let x = &m.coords;
    let mut out = vec![];
    for e in (0..b.len()).filter(|&e| mine(e)) {
        let ns = &b.nodes[8 * e..8 * e + 8];
        let ch: [f64; 3] = std::array::from_fn(|d| ns.iter().map(|&n| x[n][d]).sum::<f64>() / 8.0);
        for f in &HEX_FACES {
            let o = &owners[&key(e, f)];
            let other = match o.len() {
                1 => u32::MAX,
                2 if interior => o[(o[0] == e as u32) as usize],
                _ => continue,
            };
            let mut nodes: [u32; 4] = std::array::from_fn(|a| ns[f[a]] as u32);
            let xf: [[f64; 3]; 4] = std::array::from_fn(|a| x[nodes[a] as usize]);
            let cf: [f64; 3] = std::array::from_fn(|d| xf.iter().map(|p| p[d]).sum::<f64>() / 4.0);
            let n = cross(&sub(&xf[2], &xf[0]), &sub(&xf[3], &xf[1]));
            let ln = dot(&n, &n).sqrt();
            let h = dot(&n, &sub(&cf, &ch));
            if h < 0.0 {
                nodes.swap(1, 3);
            }
            let depth = if ln > 0.0 { h.abs() / ln } else { 0.0 };
            out.push(BoundaryFace {
                nodes,
                elem: e as u32,
                depth,
                other,
            });
        }
    }
    out
}

/// The nodes of hexahedron part `part`'s boundary faces, sorted, each once (the interior
/// nodes cannot touch anything).
pub(super) fn boundary_nodes(m: &Model, part: usize) -> Vec<u32> {
    let mut v: Vec<u32> = boundary_faces(m, part)
        .iter()
        .flat_map(|f| f.nodes)
        .collect();
    v.sort_unstable();
    v.dedup();
    v
}

/// The one-sided penetration of a slave at (px, py, pz) of thickness `ts` into the solid's
/// face `f` (outward node order), of contact thickness `tf`, whose nodes carry the box
/// thickness 2R in `fbox` (see the module doc). The hit's r/dist is the direction of the
/// force on the slave (out of the solid behind the face).
#[inline(never)]
#[allow(clippy::too_many_arguments)]
pub(super) fn evaluate_solid(
    px: f64,
    py: f64,
    pz: f64,
    ts: f64,
    tf: f64,
    f: &[u32; 4],
    fbox: &[f64; 4],
    x: &[[f64; 3]],
) -> Option<Hit> {
    let p = [px, py, pz];
    let xf: [[f64; 3]; 4] = std::array::from_fn(|a| x[f[a] as usize]);
    let w = closest_on_quad(&p, &xf);
    let q: [f64; 3] = std::array::from_fn(|d| (0..4).map(|a| w[a] * xf[a][d]).sum());
    let r = sub(&p, &q);
    let d2 = dot(&r, &r);
    // The zone the thickness boxes hold: |r| < R + t_s/2.
    let zone = 0.5 * (ts + fbox[0]);
    if !(d2 < zone * zone) {
        return None;
    }
    let nv = cross(&sub(&xf[2], &xf[0]), &sub(&xf[3], &xf[1]));
    let ln = dot(&nv, &nv).sqrt();
    if !(ln > 0.0) {
        return None;
    }
    let n = [nv[0] / ln, nv[1] / ln, nv[2] / ln];
    let c = 0.5 * (ts + tf);
    let s = dot(&r, &n);
    if s >= 0.0 {
        if d2 >= c * c {
            return None;
        }
        let dist = d2.sqrt();
        return Some(Hit {
            w,
            g: c - dist,
            dist,
            r,
            tg: [0.0; 3],
            flat: n,
        });
    }
    // Behind: no deeper than a node can have gone in from the front (see the module
    // doc), and only inside the face's normal prism.
    if -s > c.max(BEHIND_FRACTION * 0.5 * fbox[0]) {
        return None;
    }
    for a in 0..4 {
        let e = sub(&xf[(a + 1) % 4], &xf[a]);
        if dot(&sub(&p, &xf[a]), &cross(&e, &n)) > PRISM_TOL * dot(&e, &e) {
            return None;
        }
    }
    Some(Hit {
        w,
        g: c - s,
        dist: -s,
        r: [-s * n[0], -s * n[1], -s * n[2]],
        tg: [0.0; 3],
        flat: n,
    })
}

#[cfg(test)]
mod tests {
    use super::evaluate_solid;

    /// The one-sided kernel against the geometry of the top face z = 0 of a unit cube
    /// below it (outward normal +z), contact distance c = t_s/2 = 0.1, zone R = 0.5: in
    /// front within c, pushed up by c − z; behind the face inside its prism, pushed up
    /// (out of the solid) by c − z = c + depth, continuous through z = 0, to a depth of
    /// max(c, R/10) = 0.1 and not beyond; behind but
    /// beside the face (outside the prism: below its edge, out of the cube), nothing;
    /// beyond the zone, nothing.
    #[test]
    fn a_node_behind_a_solid_face_is_pushed_out_and_one_beside_it_is_left() {
        let x = vec![
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [1.0, 1.0, 0.0],
            [0.0, 1.0, 0.0],
        ];
        let f = [0u32, 1, 2, 3];
        let (ts, tf, fbox) = (0.2, 0.0, [1.0; 4]);
        let hit = |p: [f64; 3]| evaluate_solid(p[0], p[1], p[2], ts, tf, &f, &fbox, &x);
        for z in [0.05, 1e-9, 0.0, -1e-9, -0.05, -0.1] {
            let h = hit([0.3, 0.6, z]).expect("a hit");
            let n: Vec<f64> = (0..3).map(|d| h.r[d] / h.dist.max(1e-300)).collect();
            assert!((h.g - (0.1 - z)).abs() < 1e-15, "z {z}: g {}", h.g);
            if z != 0.0 {
                // (At |z| = 1e-9 the foot's round-off, 1e-16, tilts r by 1e-7.)
                assert!((n[2] - 1.0).abs() < 1e-12, "z {z}: normal {n:?}");
            } else {
                assert_eq!(h.flat, [0.0, 0.0, 1.0]);
            }
        }
        assert!(hit([0.3, 0.6, 0.1]).is_none(), "at the contact distance");
        assert!(
            hit([0.3, 0.6, -0.61]).is_none(),
            "beyond the zone R + t_s/2"
        );
        // Deeper behind the face than max(c, R/10) = 0.1: not caught.
        assert!(
            hit([0.3, 0.6, -0.1 - 1e-9]).is_none(),
            "deep behind the face"
        );
        assert!(hit([0.3, 0.6, -0.3]).is_none(), "deep behind the face");
        // Under the edge x = 1, just outside the cube: beside the face.
        assert!(hit([1.0 + 1e-3, 0.5, -0.05]).is_none(), "beside the face");
        // On the edge's plane (a matched mesh's node under a vertex): inside.
        assert!(hit([1.0, 1.0, -0.05]).is_some(), "under the vertex");
        // In front of the edge, rounded: g = c − distance.
        let h = hit([1.05, 0.5, 0.0]).expect("rounded edge");
        assert!((h.g - 0.05).abs() < 1e-15 && h.r[0] > 0.0, "{}", h.g);
    }
}
