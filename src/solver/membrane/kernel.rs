//! Membrane elements: three-node constant-strain triangle and four-node quadrilateral
//! with one integration point and hourglass control. Orthotropic linear elasticity in
//! material axes, large displacements and rotations, no bending stiffness.
//!
//! Glossary: X_a reference and x_a current node positions [m]; (g₁, g₂, g₃) the reference
//! material frame: g₃ the element normal, g₁ the material direction 1 (global x
//! projected on the element, turned by the material angle about g₃); X̂_a the reference
//! coordinates in (g₁, g₂); ∇̂N_a the shape-function gradients in those coordinates (at
//! the centre for the quad); A₀ reference area; s thickness.
//!
//! Kinematics (total Lagrangian): F = Σ_a x_a ⊗ ∇̂N_a (3×2: the current images of the
//! material axes), Green strain E = ½(FᵀF − I) (2×2, in material axes). Any rigid motion
//! leaves FᵀF unchanged, so the element is objective under large rotations and its
//! material axes convect with it; for small strains E is the engineering strain.
//! Material (plane stress, St Venant–Kirchhoff): S = D E with, in Voigt form
//! [S₁₁, S₂₂, S₁₂] = D [E₁₁, E₂₂, 2E₁₂],
//!   D = 1/(1 − ν₁₂ν₂₁) [[E₁, ν₁₂E₂, 0], [ν₁₂E₂, E₂, 0], [0, 0, G₁₂(1 − ν₁₂ν₂₁)]],
//! ν₂₁ = ν₁₂E₂/E₁. With `no_compression`, negative principal stresses are set to zero
//! (a tension field: the fabric wrinkles instead of carrying compression).
//! Energy W = A₀ s ½ E:S; internal force f_a = −∂W/∂x_a = −A₀ s F S ∇̂N_a.
//!
//! Hourglass control (quad; Flanagan & Belytschko, IJNME 17, 1981): γ_a = ¼(h_a −
//! (h·X̂)∇̂N_{a,1} − (h·Ŷ)∇̂N_{a,2}), h = (1, −1, 1, −1). γ is orthogonal to every affine
//! field, so q = Σ_a γ_a x_a vanishes under rigid motion and uniform strain. With n the
//! current element normal and q = q_t + q_n n: W_hg = ½ k_hg (|q_t|² + r_n q_n²),
//! f_a = −∂W_hg/∂x_a exactly (including the turning of n), k_hg = κ E_max s A₀ Σ_a|∇̂N_a|²
//! (κ = 0.1 by default, LS-DYNA's
//! default hourglass coefficient), r_n = [`NORMAL_RATIO`] for the warping mode.
//!
//! References: Belytschko, Liu, Moran, *Nonlinear Finite Elements*, §4.5 (total
//! Lagrangian), §8.7 (one-point quadrature and hourglass control); Belytschko, Lin &
//! Tsay, CMAME 42 (1984) (one-point membrane/shell element).

use crate::error::{Result, WeftError};
use crate::solver::failure::fibre_strain;
use crate::solver::vec3::{cross, dot, sub, unit};

/// Orthotropic plane-stress material in material axes.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Material {
    /// Voigt stiffness [Pa] for [E₁₁, E₂₂, 2E₁₂] → [S₁₁, S₂₂, S₁₂].
    pub d: [[f64; 3]; 3],
    pub no_compression: bool,
    /// Initial stress S₀ = [S₁₁, S₂₂, S₁₂] [Pa] in material axes (a formed, pre-stressed
    /// state): S = D E + S₀, stored energy ½ E·D E + S₀·E.
    pub s0: [f64; 3],
}

impl Material {
    pub fn orthotropic(
        e1: f64,
        e2: f64,
        nu12: f64,
        g12: f64,
        no_compression: bool,
    ) -> Result<Material> {
        let nu21 = nu12 * e2 / e1;
        let den = 1.0 - nu12 * nu21;
        if den <= 0.0 {
            return Err(WeftError::input(format!(
                "ν₁₂ = {nu12} with E₁ = {e1}, E₂ = {e2} gives 1 − ν₁₂ν₂₁ = {den}"
            ))
            .expected("ν₁₂² E₂/E₁ < 1 (a positive-definite material)"));
        }
        Ok(Material {
            d: [
                [e1 / den, nu12 * e2 / den, 0.0],
                [nu12 * e2 / den, e2 / den, 0.0],
                [0.0, 0.0, g12],
            ],
            no_compression,
            s0: [0.0; 3],
        })
    }
    /// Largest direct modulus, for the hourglass stiffness.
    pub fn e_max(&self) -> f64 {
        self.d[0][0].max(self.d[1][1])
    }
    /// The material with the material directions in `failed` (bit i: direction i + 1)
    /// carrying no normal stress: their rows and columns of D and their initial stress
    /// zeroed, the shear kept (OpenRadioss' /FAIL/FABRIC with NDIR = 2).
    pub fn with_failed(&self, failed: u8) -> Material {
        let mut m = *self;
        for i in 0..2 {
            if failed & (1 << i) != 0 {
                for j in 0..3 {
                    m.d[i][j] = 0.0;
                    m.d[j][i] = 0.0;
                }
                m.s0[i] = 0.0;
            }
        }
        m
    }
}

/// Reference geometry of one membrane element with `N` nodes.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Reference<const N: usize> {
    /// ∇̂N_a in material axes [1/m].
    pub grad: [[f64; 2]; N],
    /// Reference area A₀ [m²].
    pub area: f64,
    /// Hourglass vector γ (zero for the triangle).
    pub gamma: [f64; N],
}

impl<const N: usize> Reference<N> {
    /// Set up from the reference positions; `angle` turns material direction 1 from the
    /// projected global x about the element normal [rad]. `None` for a degenerate
    /// element (zero area, inverted or non-convex quad).
    pub fn new(x: &[[f64; 3]; N], angle: f64) -> Option<Reference<N>> {
        assert!(N == 3 || N == 4);
        let n = if N == 3 {
            cross(&sub(&x[1], &x[0]), &sub(&x[2], &x[0]))
        } else {
            cross(&sub(&x[2], &x[0]), &sub(&x[3], &x[1]))
        };
        let g3 = unit(n)?;
        let proj = |e: [f64; 3]| {
            unit(sub(&e, &{
                let d = dot(&e, &g3);
                [d * g3[0], d * g3[1], d * g3[2]]
            }))
        };
        let a = proj([1.0, 0.0, 0.0])
            .filter(|a| dot(a, &[1.0, 0.0, 0.0]).abs() > 1e-6)
            .or_else(|| proj([0.0, 1.0, 0.0]))?;
        let b = cross(&g3, &a);
        let (c, s) = (angle.cos(), angle.sin());
        let g1 = [
            c * a[0] + s * b[0],
            c * a[1] + s * b[1],
            c * a[2] + s * b[2],
        ];
        let g2 = cross(&g3, &g1);
        let mut p = [[0.0; 2]; N];
        for i in 0..N {
            let d = sub(&x[i], &x[0]);
            p[i] = [dot(&d, &g1), dot(&d, &g2)];
        }
        let mut grad = [[0.0; 2]; N];
        let mut gamma = [0.0; N];
        let area;
        if N == 3 {
            let a2 = (p[1][0] - p[0][0]) * (p[2][1] - p[0][1])
                - (p[2][0] - p[0][0]) * (p[1][1] - p[0][1]);
            if a2 <= 0.0 {
                return None;
            }
            area = 0.5 * a2;
            for i in 0..3 {
                let (j, k) = ((i + 1) % 3, (i + 2) % 3);
                grad[i] = [(p[j][1] - p[k][1]) / a2, (p[k][0] - p[j][0]) / a2];
            }
        } else {
            let a2 = (p[2][0] - p[0][0]) * (p[3][1] - p[1][1])
                + (p[1][0] - p[3][0]) * (p[2][1] - p[0][1]);
            if a2 <= 0.0 {
                return None;
            }
            area = 0.5 * a2;
            for i in 0..4 {
                let (j, l) = ((i + 1) % 4, (i + 3) % 4);
                grad[i] = [(p[j][1] - p[l][1]) / a2, (p[l][0] - p[j][0]) / a2];
            }
            // Convexity: each corner's cross product has the orientation of the whole.
            for i in 0..4 {
                let (j, l) = ((i + 1) % 4, (i + 3) % 4);
                let e1 = [p[j][0] - p[i][0], p[j][1] - p[i][1]];
                let e2 = [p[l][0] - p[i][0], p[l][1] - p[i][1]];
                if e1[0] * e2[1] - e1[1] * e2[0] <= 0.0 {
                    return None;
                }
            }
            let h = [1.0, -1.0, 1.0, -1.0];
            let hx: f64 = (0..4).map(|i| h[i] * p[i][0]).sum();
            let hy: f64 = (0..4).map(|i| h[i] * p[i][1]).sum();
            for i in 0..4 {
                gamma[i] = 0.25 * (h[i] - hx * grad[i][0] - hy * grad[i][1]);
            }
        }
        Some(Reference { grad, area, gamma })
    }

    /// Σ_a |∇̂N_a|² [1/m²].
    pub fn grad2(&self) -> f64 {
        self.grad.iter().map(|g| g[0] * g[0] + g[1] * g[1]).sum()
    }
}

/// Deformation gradient F (3×2 as two columns) and Green strain in Voigt form.
#[inline(always)]
fn kinematics<const N: usize>(x: &[[f64; 3]; N], r: &Reference<N>) -> ([[f64; 3]; 2], [f64; 3]) {
    let mut f = [[0.0; 3]; 2];
    for a in 0..N {
        for c in 0..2 {
            let g = r.grad[a][c];
            f[c][0] += x[a][0] * g;
            f[c][1] += x[a][1] * g;
            f[c][2] += x[a][2] * g;
        }
    }
    let c11 = dot(&f[0], &f[0]);
    let c22 = dot(&f[1], &f[1]);
    let c12 = dot(&f[0], &f[1]);
    (f, [0.5 * (c11 - 1.0), 0.5 * (c22 - 1.0), c12])
}

/// Green strain in Voigt form [E₁₁, E₂₂, 2E₁₂] in material axes at current positions
/// `x` (for output: `weft-simulate --element-results`).
pub fn green_strain<const N: usize>(x: &[[f64; 3]; N], r: &Reference<N>) -> [f64; 3] {
    kinematics(x, r).1
}

/// How far the element has stiffened since the reference configuration, the stable
/// step's basis: an estimate of λ_max(K_t)/λ_max(K₀) for the total-Lagrangian membrane.
/// Its material part is E₁(f₁·δf₁)² + E₂(f₂·δf₂)² + G(f₁·δf₂ + f₂·δf₁)² with f_i = F e_i,
/// |f_i|² = C_ii: the fibre terms grow as C₁₁ and C₂₂, the shear term at most as 2 max C_ii
/// (D's diagonal E₁, E₂, G; ν's coupling left out); the geometric part adds the largest
/// principal stress over the stiffest modulus. Uniaxial St Venant–Kirchhoff: 1 + 3E₁₁,
/// the tangent modulus (3λ² − 1)/2 over E. A band sheared in its plane (G ≪ E₁) stiffens
/// little: its fibre terms do not see the shear. Returns it with the Green strain.
pub fn stiffening<const N: usize>(
    x: &[[f64; 3]; N],
    r: &Reference<N>,
    m: &Material,
) -> (f64, [f64; 3]) {
    let (_, e) = kinematics(x, r);
    let (c11, c22) = (1.0 + 2.0 * e[0], 1.0 + 2.0 * e[1]);
    let (e1, e2, g) = (m.d[0][0], m.d[1][1], m.d[2][2]);
    let material = ((e1 * c11).max(e2 * c22) + 2.0 * g * c11.max(c22)) / (e1.max(e2) + 2.0 * g);
    let sv = stress(m, &e);
    let s_max =
        (0.5 * (sv[0] + sv[1])).abs() + (0.25 * (sv[0] - sv[1]).powi(2) + sv[2] * sv[2]).sqrt();
    (material + s_max / m.e_max(), e)
}

/// Second Piola–Kirchhoff stress [S₁₁, S₂₂, S₁₂] from Voigt strain.
#[inline(always)]
pub fn stress(m: &Material, e: &[f64; 3]) -> [f64; 3] {
    let d = &m.d;
    let mut s = [
        d[0][0] * e[0] + d[0][1] * e[1] + d[0][2] * e[2],
        d[1][0] * e[0] + d[1][1] * e[1] + d[1][2] * e[2],
        d[2][0] * e[0] + d[2][1] * e[1] + d[2][2] * e[2],
    ];
    if m.no_compression {
        // Principal stresses of [[s0, s2], [s2, s1]]; drop the compressive ones.
        let mean = 0.5 * (s[0] + s[1]);
        let rad = (0.25 * (s[0] - s[1]).powi(2) + s[2] * s[2]).sqrt();
        let (p1, p2) = (mean + rad, mean - rad);
        if p1 <= 0.0 {
            s = [0.0; 3];
        } else if p2 < 0.0 {
            // Keep p1 along its direction n: S = p1 n⊗n.
            let (nx, ny) = if rad > 0.0 {
                let t = 0.5 * (2.0 * s[2]).atan2(s[0] - s[1]);
                (t.cos(), t.sin())
            } else {
                (1.0, 0.0)
            };
            s = [p1 * nx * nx, p1 * ny * ny, p1 * nx * ny];
        }
    }
    [s[0] + m.s0[0], s[1] + m.s0[1], s[2] + m.s0[2]]
}

/// The force per unit reference area across a cut normal to material direction 1,
/// along the current image of that direction: (P ê₁)·f₁/|f₁| with P = F S the first
/// Piola–Kirchhoff stress and f₁ = F ê₁ [Pa]. Along a yarn band, times the section area,
/// the yarn's tension.
pub fn tension_1<const N: usize>(x: &[[f64; 3]; N], r: &Reference<N>, m: &Material) -> f64 {
    let (f, e) = kinematics(x, r);
    let s = stress(m, &e);
    let l = dot(&f[0], &f[0]).sqrt();
    if l == 0.0 {
        return 0.0;
    }
    (s[0] * dot(&f[0], &f[0]) + s[2] * dot(&f[1], &f[0])) / l
}

/// Internal forces on the nodes [N] (membrane and hourglass).
#[inline(always)]
pub fn forces<const N: usize>(
    x: &[[f64; 3]; N],
    r: &Reference<N>,
    m: &Material,
    thickness: f64,
    k_hg: f64,
) -> [[f64; 3]; N] {
    forces_with(x, r, m, thickness, k_hg, NORMAL_RATIO)
}

/// [`forces`] with a chosen warping ratio r_n (statics uses 0: a linear solve of a flat
/// membrane has no out-of-plane stiffness to speak of).
#[inline(always)]
pub fn forces_with<const N: usize>(
    x: &[[f64; 3]; N],
    r: &Reference<N>,
    m: &Material,
    thickness: f64,
    k_hg: f64,
    normal_ratio: f64,
) -> [[f64; 3]; N] {
    let (f, e) = kinematics(x, r);
    let s = stress(m, &e);
    let w = r.area * thickness;
    let mut out = [[0.0; 3]; N];
    for a in 0..N {
        let g = r.grad[a];
        // (S ∇N_a) in material axes, then F·that.
        let t0 = s[0] * g[0] + s[2] * g[1];
        let t1 = s[2] * g[0] + s[1] * g[1];
        for c in 0..3 {
            out[a][c] = -w * (f[0][c] * t0 + f[1][c] * t1);
        }
    }
    if N == 4 && k_hg > 0.0 {
        let (q, n) = hourglass_q(x, r);
        // Warping (normal) part of q with the stiffness k_hg·normal_ratio.
        let qn = dot(&q, &n);
        let kq: [f64; 3] =
            std::array::from_fn(|c| k_hg * (q[c] - qn * n[c]) + k_hg * normal_ratio * qn * n[c]);
        for a in 0..N {
            for c in 0..3 {
                out[a][c] -= r.gamma[a] * kq[c];
            }
        }
        // The normal n = c/|c|, c = d₁ × d₂ (d₁ = x₃ − x₁, d₂ = x₄ − x₂), turns with the
        // nodes: −∂W/∂x_a gains k(1 − r_n) q_n (∂c/∂x_a)ᵀ q_t / |c|.
        let d1 = sub(&x[2], &x[0]);
        let d2 = sub(&x[3 % N], &x[1]);
        let cn = cross(&d1, &d2);
        let cl = dot(&cn, &cn).sqrt();
        if cl > 0.0 {
            let s = k_hg * (1.0 - normal_ratio) * qn / cl;
            let w: [f64; 3] = std::array::from_fn(|c| s * (q[c] - qn * n[c]));
            let (a1, a2) = (cross(&d2, &w), cross(&w, &d1));
            for c in 0..3 {
                out[0][c] -= a1[c];
                out[2][c] += a1[c];
                out[1][c] -= a2[c];
                out[3 % N][c] += a2[c];
            }
        }
    }
    out
}

/// The out-of-plane (warping) hourglass stiffness relative to the in-plane one. An
/// unstressed membrane has no transverse stiffness at all; the transverse stiffness of a
/// membrane under tension N is N/(E s) ≈ the strain (≈ 1 %) of its in-plane stiffness, so
/// the warping mode gets 1 % of the in-plane hourglass stiffness. With the full κ E s it
/// stiffens the membrane against transverse motion and throws nodes the wrong way under
/// a point impact.
pub const NORMAL_RATIO: f64 = 0.01;

/// Hourglass vector q = Σ γ_a x_a and the current unit normal (from the diagonals).
#[inline(always)]
fn hourglass_q<const N: usize>(x: &[[f64; 3]; N], r: &Reference<N>) -> ([f64; 3], [f64; 3]) {
    let mut q = [0.0; 3];
    for a in 0..N {
        for c in 0..3 {
            q[c] += r.gamma[a] * x[a][c];
        }
    }
    let n = unit(cross(&sub(&x[2], &x[0]), &sub(&x[3 % N], &x[1]))).unwrap_or([0.0, 0.0, 1.0]);
    (q, n)
}

/// (membrane strain energy, hourglass energy) [J].
#[inline(always)]
pub fn energy<const N: usize>(
    x: &[[f64; 3]; N],
    r: &Reference<N>,
    m: &Material,
    thickness: f64,
    k_hg: f64,
) -> (f64, f64) {
    let (_, e) = kinematics(x, r);
    let s = stress(m, &e);
    let s0 = m.s0;
    let w = 0.5
        * r.area
        * thickness
        * ((s[0] - s0[0]) * e[0] + (s[1] - s0[1]) * e[1] + (s[2] - s0[2]) * e[2])
        + r.area * thickness * (s0[0] * e[0] + s0[1] * e[1] + s0[2] * e[2]);
    let mut hg = 0.0;
    if N == 4 && k_hg > 0.0 {
        let (q, n) = hourglass_q(x, r);
        let qn = dot(&q, &n);
        hg = 0.5 * k_hg * (dot(&q, &q) - qn * qn + NORMAL_RATIO * qn * qn);
    }
    (w, hg)
}

/// Largest eigenvalue of the element's small-strain stiffness (membrane + hourglass) at
/// the reference configuration [N/m], for the stable time step.
pub fn max_stiffness<const N: usize>(
    r: &Reference<N>,
    m: &Material,
    thickness: f64,
    k_hg: f64,
) -> f64 {
    // In-plane stiffness in material axes: K = A₀ s Bᵀ D B (2N × 2N); the out-of-plane
    // directions carry only the hourglass stiffness k_hg γγᵀ, whose eigenvalue is k_hg|γ|².
    let n2 = 2 * N;
    let mut k = nalgebra::DMatrix::<f64>::zeros(n2, n2);
    let w = r.area * thickness;
    for a in 0..N {
        for b in 0..N {
            let ba = [
                [r.grad[a][0], 0.0],
                [0.0, r.grad[a][1]],
                [r.grad[a][1], r.grad[a][0]],
            ];
            let bb = [
                [r.grad[b][0], 0.0],
                [0.0, r.grad[b][1]],
                [r.grad[b][1], r.grad[b][0]],
            ];
            for i in 0..2 {
                for j in 0..2 {
                    let mut v = 0.0;
                    for p in 0..3 {
                        for q in 0..3 {
                            v += ba[p][i] * m.d[p][q] * bb[q][j];
                        }
                    }
                    k[(2 * a + i, 2 * b + j)] += w * v;
                }
            }
            for i in 0..2 {
                k[(2 * a + i, 2 * b + i)] += k_hg * r.gamma[a] * r.gamma[b];
            }
        }
    }
    let g2: f64 = r.gamma.iter().map(|g| g * g).sum();
    let lam = k
        .symmetric_eigenvalues()
        .iter()
        .cloned()
        .fold(0.0, f64::max);
    lam.max(k_hg * g2)
}

/// The fibre strains √(1 + 2E_ii) − 1 along the two material directions, and their rates
/// (Ė_ii/√(1 + 2E_ii), Ė_ii = f_i·ḟ_i with ḟ_i = Σ_a v_a ∇̂N_{a,i}), at positions `x` and
/// velocities `v`.
#[inline(always)]
pub fn fibre_strains<const N: usize>(
    x: &[[f64; 3]; N],
    v: &[[f64; 3]; N],
    r: &Reference<N>,
    with_rate: bool,
) -> ([f64; 2], [f64; 2]) {
    let (f, e) = kinematics(x, r);
    let eps = [fibre_strain(e[0]), fibre_strain(e[1])];
    if !with_rate {
        return (eps, [0.0; 2]);
    }
    let mut fd = [[0.0; 3]; 2];
    for a in 0..N {
        for c in 0..2 {
            let g = r.grad[a][c];
            for d in 0..3 {
                fd[c][d] += v[a][d] * g;
            }
        }
    }
    let rate = std::array::from_fn(|i| {
        let lam = 1.0 + eps[i];
        if lam > 0.0 {
            dot(&f[i], &fd[i]) / lam
        } else {
            0.0
        }
    });
    (eps, rate)
}
