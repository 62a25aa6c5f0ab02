//! The eight-node trilinear hexahedron: node order, faces, and exact geometry (volume,
//! mean gradient operator, corner Jacobians, characteristic length). Pure functions of
//! the eight node positions, used by the model's checks, the solid element family and
//! the contact's solid faces.
//!
//! Glossary: x_a node positions [m], a = 1..8 (0..7 in code); (ξ, η, ζ) ∈ [−1, 1]³ natural coordinates, node a at (ξ_a, η_a, ζ_a);
//! N_a = ⅛(1 + ξ_aξ)(1 + η_aη)(1 + ζ_aζ) the trilinear shape functions; J = ∂x/∂(ξ, η, ζ);
//! V the element volume; b_a the mean gradient of N_a [1/m]; h_α (α = 1..4) the
//! hourglass base vectors.
//!
//! Node order (LS-DYNA's): nodes 1–4 the face ζ = −1 counter-clockwise seen from +ζ,
//! 5–8 the face ζ = +1 in the same order:
//!   ξ_a = (−1, 1, 1, −1, −1, 1, 1, −1), η_a = (−1, −1, 1, 1, −1, −1, 1, 1),
//!   ζ_a = (−1, −1, −1, −1, 1, 1, 1, 1).
//! The base vectors {1, ξ, η, ζ, ηζ, ζξ, ξη, ξηζ} (their nodal values) are mutually
//! orthogonal in ℝ⁸; the last four are the hourglass vectors h₁ = ηζ, h₂ = ζξ, h₃ = ξη,
//! h₄ = ξηζ (Flanagan & Belytschko's Γ, LS-DYNA Theory Manual's hourglass table).
//!
//! Geometry. Write x(ξ, η, ζ) = Σ_a N_a x_a in that basis:
//!   x = e₀ + e₁ξ + e₂η + e₃ζ + e₄ηζ + e₅ζξ + e₆ξη + e₇ξηζ,   e_k = ⅛ Σ_a φ_k(a) x_a
//! (φ_k the k-th base vector; exact because the base vectors are orthogonal with
//! |φ_k|² = 8). Then x_ξ = e₁ + e₅ζ + e₆η + e₇ηζ, x_η = e₂ + e₄ζ + e₆ξ + e₇ξζ,
//! x_ζ = e₃ + e₄η + e₅ξ + e₇ξη, and V = ∫ det[x_ξ, x_η, x_ζ] dξdηdζ integrates term by
//! term (only even monomials survive; ∫1 = 8, ∫ξ² = 8/3; the ξ²η²-type terms cancel):
//!   V = 8 [e₁, e₂, e₃] + (8/3) ( [e₂, e₄, e₆] − [e₁, e₅, e₆] − [e₃, e₄, e₅] ),
//! [p, q, r] = p·(q × r) (e₇, the twist mode, does not change the volume). V is a cubic
//! polynomial of the coordinates, linear in each coordinate direction separately:
//! Flanagan & Belytschko's eq. (79) (IJNME 17 (1981) 679–706) gives it and its
//! gradient B_a = ∂V/∂x_a node by node; the form above is the same polynomial in the base
//! vectors' coefficients, and its gradient follows by the chain rule,
//!   ∂V/∂x_a = Σ_k (φ_k(a)/8) ∂V/∂e_k,
//! ∂V/∂e_k from ∂[p, q, r]/∂p = q × r (cyclically). The mean gradient operator is
//!   b_a = (1/V) ∫_V ∇N_a dV = (1/V) ∂V/∂x_a            (FB eq. (79); BLM ch. 8).
//! det J is at most quadratic in each natural coordinate, so the 2×2×2 Gauss rule gives
//! V and ∫∇N_a dV exactly: the unit tests check the closed form against it.
//! Σ_a b_a = 0 and Σ_a x_a ⊗ b_a = I exactly (∫∇(Σ_a N_a x_a) dV = V I), so a linear
//! velocity field gives its exact gradient: the mean-strain element passes the patch test.
//!

use crate::vec3::{axpy, cross, norm, sub, triple, Vec3};

/// Natural coordinates of the eight nodes (LS-DYNA order), one row per direction:
/// `NAT[0]` = ξ_a, `NAT[1]` = η_a, `NAT[2]` = ζ_a.
pub const NAT: [[f64; 8]; 3] = [
    [-1.0, 1.0, 1.0, -1.0, -1.0, 1.0, 1.0, -1.0],
    [-1.0, -1.0, 1.0, 1.0, -1.0, -1.0, 1.0, 1.0],
    [-1.0, -1.0, -1.0, -1.0, 1.0, 1.0, 1.0, 1.0],
];

/// Hourglass base vectors h_α (Flanagan & Belytschko's Γ_α; LS-DYNA Theory Manual's
/// table, the same node order): h₁ = ηζ, h₂ = ζξ, h₃ = ξη, h₄ = ξηζ at the nodes.
pub const HOURGLASS: [[f64; 8]; 4] = [
    [1.0, 1.0, -1.0, -1.0, -1.0, -1.0, 1.0, 1.0],
    [1.0, -1.0, -1.0, 1.0, -1.0, 1.0, 1.0, -1.0],
    [1.0, -1.0, 1.0, -1.0, 1.0, -1.0, 1.0, -1.0],
    [-1.0, 1.0, -1.0, 1.0, 1.0, -1.0, 1.0, -1.0],
];

/// The six faces, outward-numbered node lists (0-based, LS-DYNA order): ζ = −1, ζ = +1,
/// η = −1, ξ = +1, η = +1, ξ = −1.
pub const FACES: [[usize; 4]; 6] = [
    [0, 3, 2, 1],
    [4, 5, 6, 7],
    [0, 1, 5, 4],
    [1, 2, 6, 5],
    [2, 3, 7, 6],
    [3, 0, 4, 7],
];

/// Volume and mean gradient operator of one hexahedron.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HexGeometry {
    /// V [m³]: exact for the trilinear hexahedron (negative if inverted as a whole).
    pub volume: f64,
    /// b_a = (1/V) ∂V/∂x_a [1/m] (Flanagan & Belytschko eq. (79)).
    pub b: [[f64; 3]; 8],
}

/// The coefficients e_k = ⅛ Σ_a φ_k(a) x_a of x in the base {1, ξ, η, ζ, ηζ, ζξ, ξη, ξηζ}.
#[inline]
fn base_coefficients(x: &[[f64; 3]; 8]) -> [Vec3; 8] {
    let mut e = [[0.0; 3]; 8];
    for a in 0..8 {
        let phi = [
            1.0,
            NAT[0][a],
            NAT[1][a],
            NAT[2][a],
            HOURGLASS[0][a],
            HOURGLASS[1][a],
            HOURGLASS[2][a],
            HOURGLASS[3][a],
        ];
        for k in 0..8 {
            for d in 0..3 {
                e[k][d] += phi[k] * x[a][d];
            }
        }
    }
    for ek in e.iter_mut() {
        for c in ek.iter_mut() {
            *c *= 0.125;
        }
    }
    e
}

/// Exact volume V and mean gradient operator b_a = (1/V) ∂V/∂x_a of the trilinear
/// hexahedron (closed form: the module header; Flanagan & Belytschko (1981) eqs.
/// (76)–(79)). For V = 0 the b_a are not finite: check the volume (and
/// [`jacobian_at_nodes`]) first.
pub fn hex_geometry(x: &[[f64; 3]; 8]) -> HexGeometry {
    let e = base_coefficients(x);
    let t = 8.0 / 3.0;
    let volume = 8.0 * triple(&e[1], &e[2], &e[3])
        + t * (triple(&e[2], &e[4], &e[6])
            - triple(&e[1], &e[5], &e[6])
            - triple(&e[3], &e[4], &e[5]));
    // g_k = ∂V/∂e_k (k = 1..6; ∂V/∂e₀ = ∂V/∂e₇ = 0).
    let mut g = [[0.0; 3]; 7];
    g[1] = cross(&e[2], &e[3]);
    g[2] = cross(&e[3], &e[1]);
    g[3] = cross(&e[1], &e[2]);
    for gk in g[1..4].iter_mut() {
        for c in gk.iter_mut() {
            *c *= 8.0;
        }
    }
    // + t [e₂, e₄, e₆]
    axpy(&mut g[2], t, &cross(&e[4], &e[6]));
    axpy(&mut g[4], t, &cross(&e[6], &e[2]));
    axpy(&mut g[6], t, &cross(&e[2], &e[4]));
    // − t [e₁, e₅, e₆]
    axpy(&mut g[1], -t, &cross(&e[5], &e[6]));
    axpy(&mut g[5], -t, &cross(&e[6], &e[1]));
    axpy(&mut g[6], -t, &cross(&e[1], &e[5]));
    // − t [e₃, e₄, e₅]
    axpy(&mut g[3], -t, &cross(&e[4], &e[5]));
    axpy(&mut g[4], -t, &cross(&e[5], &e[3]));
    axpy(&mut g[5], -t, &cross(&e[3], &e[4]));
    let s = 0.125 / volume;
    let mut b = [[0.0; 3]; 8];
    for a in 0..8 {
        let phi = [
            NAT[0][a],
            NAT[1][a],
            NAT[2][a],
            HOURGLASS[0][a],
            HOURGLASS[1][a],
            HOURGLASS[2][a],
        ];
        for d in 0..3 {
            b[a][d] = s
                * (phi[0] * g[1][d]
                    + phi[1] * g[2][d]
                    + phi[2] * g[3][d]
                    + phi[3] * g[4][d]
                    + phi[4] * g[5][d]
                    + phi[5] * g[6][d]);
        }
    }
    HexGeometry { volume, b }
}

/// det J = det[x_ξ, x_η, x_ζ] at the eight corners (node order), J taken on the
/// [−1, 1]³ cube (a parallelepiped has det J = V/8 everywhere). The element is refused
/// if any value is ≤ 0: a folded or inverted corner (LS-DYNA's "negative volume"
/// check at the nodes). x_ξ at a corner is half the sum of the ξ-edge vectors there.
pub fn jacobian_at_nodes(x: &[[f64; 3]; 8]) -> [f64; 8] {
    let e = base_coefficients(x);
    std::array::from_fn(|a| {
        let (xi, eta, zeta) = (NAT[0][a], NAT[1][a], NAT[2][a]);
        let mut gx = e[1];
        axpy(&mut gx, zeta, &e[5]);
        axpy(&mut gx, eta, &e[6]);
        axpy(&mut gx, eta * zeta, &e[7]);
        let mut ge = e[2];
        axpy(&mut ge, zeta, &e[4]);
        axpy(&mut ge, xi, &e[6]);
        axpy(&mut ge, xi * zeta, &e[7]);
        let mut gz = e[3];
        axpy(&mut gz, eta, &e[4]);
        axpy(&mut gz, xi, &e[5]);
        axpy(&mut gz, xi * eta, &e[7]);
        triple(&gx, &ge, &gz)
    })
}

/// Area of a (possibly warped) quadrilateral face: ½|d₁₃ × d₂₄| (the diagonals' cross
/// product; exact for a planar quad, the projected area otherwise).
pub fn face_area(x: &[[f64; 3]; 8], face: &[usize; 4]) -> f64 {
    let d1 = sub(&x[face[2]], &x[face[0]]);
    let d2 = sub(&x[face[3]], &x[face[1]]);
    0.5 * norm(&cross(&d1, &d2))
}

/// LS-DYNA's characteristic length of a solid, l_e = V / A_max, A_max the largest face
/// area (LS-DYNA Theory Manual, "Time step control", solid elements); the stable step
/// is l_e / c.
pub fn characteristic_length(x: &[[f64; 3]; 8], volume: f64) -> f64 {
    let a_max = FACES.iter().map(|f| face_area(x, f)).fold(0.0, f64::max);
    volume / a_max
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::random::Stream;
    use crate::vec3::{dot, Mat3};

    /// General 3 × 3 inverse by cofactors.
    pub(crate) fn inverse(m: &Mat3) -> Mat3 {
        let c0 = cross(&m[1], &m[2]);
        let c1 = cross(&m[2], &m[0]);
        let c2 = cross(&m[0], &m[1]);
        let det = dot(&m[0], &c0);
        std::array::from_fn(|i| [c0[i] / det, c1[i] / det, c2[i] / det])
    }

    /// The unit cube [0, 1]³, nodes in order.
    pub(crate) fn unit_cube() -> [[f64; 3]; 8] {
        std::array::from_fn(|a| std::array::from_fn(|d| 0.5 * (1.0 + NAT[d][a])))
    }

    /// A strongly distorted, non-planar-faced hexahedron (every node displaced by up to
    /// ±30 % of the edge from a 1 × 2 × 3 box).
    pub(crate) fn distorted(seed: u64) -> [[f64; 3]; 8] {
        let mut r = Stream::new(seed);
        let size = [1.0, 2.0, 3.0];
        std::array::from_fn(|a| {
            std::array::from_fn(|d| {
                size[d] * (0.5 * (1.0 + NAT[d][a]) + 0.6 * (r.next_uniform() - 0.5))
            })
        })
    }

    /// V and ∫∇N_a dV by the 2×2×2 Gauss rule (exact: det J is at most quadratic in each
    /// natural coordinate), the textbook isoparametric route.
    fn gauss(x: &[[f64; 3]; 8]) -> (f64, [[f64; 3]; 8]) {
        let g = 1.0 / 3f64.sqrt();
        let mut vol = 0.0;
        let mut int = [[0.0; 3]; 8];
        for p in 0..8 {
            let q = [NAT[0][p] * g, NAT[1][p] * g, NAT[2][p] * g];
            // dN_a/dξ_k
            let dn: [[f64; 3]; 8] = std::array::from_fn(|a| {
                let f: [f64; 3] = std::array::from_fn(|k| 1.0 + NAT[k][a] * q[k]);
                [
                    0.125 * NAT[0][a] * f[1] * f[2],
                    0.125 * NAT[1][a] * f[0] * f[2],
                    0.125 * NAT[2][a] * f[0] * f[1],
                ]
            });
            let mut j = [[0.0; 3]; 3]; // J_ik = ∂x_i/∂ξ_k
            for a in 0..8 {
                for i in 0..3 {
                    for k in 0..3 {
                        j[i][k] += x[a][i] * dn[a][k];
                    }
                }
            }
            let det = triple(
                &[j[0][0], j[1][0], j[2][0]],
                &[j[0][1], j[1][1], j[2][1]],
                &[j[0][2], j[1][2], j[2][2]],
            );
            let inv = inverse(&j);
            vol += det;
            for a in 0..8 {
                for i in 0..3 {
                    // ∂N/∂x_i = Σ_k dN/dξ_k (J⁻¹)_ki
                    int[a][i] += det * (0..3).map(|k| dn[a][k] * inv[k][i]).sum::<f64>();
                }
            }
        }
        (vol, int)
    }

    #[test]
    fn base_vectors_are_orthogonal() {
        let mut all: Vec<[f64; 8]> = vec![[1.0; 8], NAT[0], NAT[1], NAT[2]];
        all.extend(HOURGLASS);
        for i in 0..8 {
            for j in 0..8 {
                let d: f64 = (0..8).map(|a| all[i][a] * all[j][a]).sum();
                assert_eq!(d, if i == j { 8.0 } else { 0.0 }, "{i} {j}");
            }
        }
        // h₁ = ηζ, h₂ = ζξ, h₃ = ξη, h₄ = ξηζ in this node order.
        for a in 0..8 {
            assert_eq!(HOURGLASS[0][a], NAT[1][a] * NAT[2][a]);
            assert_eq!(HOURGLASS[1][a], NAT[2][a] * NAT[0][a]);
            assert_eq!(HOURGLASS[2][a], NAT[0][a] * NAT[1][a]);
            assert_eq!(HOURGLASS[3][a], NAT[0][a] * NAT[1][a] * NAT[2][a]);
        }
    }

    #[test]
    fn unit_cube_volume_and_gradients() {
        let x = unit_cube();
        let g = hex_geometry(&x);
        assert_eq!(g.volume, 1.0);
        // ∇N_a at the centre of the unit cube: ¼(ξ_a, η_a, ζ_a), and it is the mean.
        for a in 0..8 {
            for d in 0..3 {
                assert_eq!(g.b[a][d], 0.25 * NAT[d][a]);
            }
        }
        assert_eq!(jacobian_at_nodes(&x), [0.125; 8]);
        assert_eq!(characteristic_length(&x, g.volume), 1.0);
    }

    /// Oracle: the 2×2×2 Gauss rule, exact for V and ∫∇N_a dV of the trilinear hex.
    #[test]
    fn closed_form_matches_gauss_on_distorted_hexes() {
        let mut worst = (0.0f64, 0.0f64);
        for seed in 0..50 {
            let x = distorted(seed);
            let g = hex_geometry(&x);
            let (vg, int) = gauss(&x);
            worst.0 = worst.0.max((g.volume - vg).abs() / vg);
            let scale = int.iter().flatten().fold(0.0f64, |m, v| m.max(v.abs()));
            for a in 0..8 {
                for d in 0..3 {
                    worst.1 = worst
                        .1
                        .max((g.b[a][d] * g.volume - int[a][d]).abs() / scale);
                }
            }
        }
        // Measured 7.1e-16 and 9.8e-16 (50 hexes): round-off of two different evaluations.
        assert!(worst.0 < 3e-15 && worst.1 < 3e-15, "{worst:?}");
    }

    /// Oracles: the divergence theorem, V = ⅓ ∮ x·n dA over the six bilinear faces, by
    /// the midpoint rule on 8 × 8 cells per face (exact: on a bilinear patch x = a + bs +
    /// ct + dst, x·(x_s × x_t) has no s², t², s²t or st² term since b·(b × d) = c·(d × c)
    /// = 0, so only 1, s, t, st remain; measured 4.5e-15); the 5-tetrahedron split and
    /// the frustum formula for a hex with planar faces (a sheared square frustum).
    #[test]
    fn volume_against_independent_computations() {
        // Divergence theorem on a distorted hex.
        for seed in [3u64, 17, 29] {
            let x = distorted(seed);
            let v = hex_geometry(&x).volume;
            let n = 8;
            let mut flux = 0.0;
            for f in FACES {
                let p = [x[f[0]], x[f[1]], x[f[2]], x[f[3]]];
                for i in 0..n {
                    for j in 0..n {
                        let (s, t) = ((i as f64 + 0.5) / n as f64, (j as f64 + 0.5) / n as f64);
                        // bilinear patch: p0(1−s)(1−t) + p1 s(1−t) + p2 s t + p3 (1−s) t
                        let w = [(1.0 - s) * (1.0 - t), s * (1.0 - t), s * t, (1.0 - s) * t];
                        let xs: Vec3 =
                            std::array::from_fn(|d| w.iter().zip(&p).map(|(w, p)| w * p[d]).sum());
                        let ds: Vec3 = std::array::from_fn(|d| {
                            (1.0 - t) * (p[1][d] - p[0][d]) + t * (p[2][d] - p[3][d])
                        });
                        let dt: Vec3 = std::array::from_fn(|d| {
                            (1.0 - s) * (p[3][d] - p[0][d]) + s * (p[2][d] - p[1][d])
                        });
                        flux += dot(&xs, &cross(&ds, &dt)) / (n * n) as f64;
                    }
                }
            }
            // The face lists run counter-clockwise seen from outside: outward normals.
            let vd = flux / 3.0;
            assert!(
                (v - vd).abs() / v < 2e-14,
                "V = {v}, divergence theorem {vd}"
            );
        }
        // Planar faces: a frustum (top face scaled by ½ about the axis) sheared.
        let shear = [[1.0, 0.3, -0.2], [0.1, 1.2, 0.25], [0.0, -0.15, 0.9]];
        let x: [[f64; 3]; 8] = std::array::from_fn(|a| {
            let k = if NAT[2][a] > 0.0 { 0.5 } else { 1.0 };
            let p = [k * NAT[0][a], k * NAT[1][a], NAT[2][a]];
            std::array::from_fn(|i| dot(&shear[i], &p))
        });
        let v = hex_geometry(&x).volume;
        // 5 tetrahedra: the corners 0, 2, 5, 7 and the central one (0, 2, 5, 7).
        let tet = |a: usize, b: usize, c: usize, d: usize| {
            triple(&sub(&x[b], &x[a]), &sub(&x[c], &x[a]), &sub(&x[d], &x[a])).abs() / 6.0
        };
        let v5 =
            tet(1, 0, 2, 5) + tet(3, 0, 2, 7) + tet(4, 0, 5, 7) + tet(6, 2, 5, 7) + tet(0, 2, 5, 7);
        assert!((v - v5).abs() < 2e-15 * v, "V = {v}, 5 tets {v5}"); // measured 3.5e-16
                                                                     // Frustum of square pyramid: h/3 (A₁ + A₂ + √(A₁A₂)) = 2/3 (4 + 1 + 2), times det(shear).
        let det = triple(
            &[shear[0][0], shear[1][0], shear[2][0]],
            &[shear[0][1], shear[1][1], shear[2][1]],
            &[shear[0][2], shear[1][2], shear[2][2]],
        );
        assert!((v - det * 14.0 / 3.0).abs() < 1e-14 * v);
    }

    #[test]
    fn jacobian_flags_inverted_corners() {
        let mut x = distorted(5);
        assert!(jacobian_at_nodes(&x).iter().all(|&j| j > 0.0));
        // Parallelepiped: det J = V/8 at every corner.
        let sh = [[1.0, 0.4, 0.0], [0.0, 1.0, 0.3], [0.2, 0.0, 1.0]];
        let p: [[f64; 3]; 8] =
            std::array::from_fn(|a| std::array::from_fn(|i| dot(&sh[i], &unit_cube()[a])));
        let v = hex_geometry(&p).volume;
        for j in jacobian_at_nodes(&p) {
            assert!((j - v / 8.0).abs() < 1e-15);
        }
        // Push node 7 (index 6) through the opposite corner's diagonal: its corner folds.
        let c: Vec3 = std::array::from_fn(|d| (0..8).map(|a| x[a][d]).sum::<f64>() / 8.0);
        x[6] = std::array::from_fn(|d| c[d] - 0.3 * (x[6][d] - c[d]));
        let j = jacobian_at_nodes(&x);
        assert!(j[6] < 0.0, "{j:?}");
        // Mirrored node order (an inside-out element): all negative.
        let m: [[f64; 3]; 8] =
            std::array::from_fn(|a| [-unit_cube()[a][0], unit_cube()[a][1], unit_cube()[a][2]]);
        assert!(jacobian_at_nodes(&m).iter().all(|&j| j < 0.0));
        assert!(hex_geometry(&m).volume < 0.0);
    }

    /// A 1 × 2 × 3 box: V = 6, largest face 2 × 3 = 6, so l_e = V/A_max = 1 (the
    /// shortest edge, LS-DYNA's solid characteristic length).
    #[test]
    fn characteristic_length_of_a_box() {
        let x: [[f64; 3]; 8] = std::array::from_fn(|a| {
            let u = unit_cube()[a];
            [u[0], 2.0 * u[1], 3.0 * u[2]]
        });
        let g = hex_geometry(&x);
        assert!((g.volume - 6.0).abs() < 1e-14);
        assert!((characteristic_length(&x, g.volume) - 1.0).abs() < 1e-15);
    }
}
