//! The eight-node hexahedron's kinematics with one-point (mean-strain) integration and
//! viscous hourglass control: pure functions of one element's node positions and
//! velocities, no state. The element family calls them in the order of a step (below);
//! the element's geometry (node order, volume, mean gradient operator b_a) is in
//! [`crate::shape::hex8`].
//!
//! Glossary: x_a current node positions [m], a = 1..8 (0..7 in code); v_a node
//! velocities [m/s]; V the element volume; b_a the mean gradient of N_a [1/m]; L the
//! velocity gradient, D its symmetric part (rate of deformation), W its skew part
//! (spin) [1/s]; σ the Cauchy stress [Pa], Voigt order [xx, yy, zz, xy, yz, zx] (tensor
//! components); h_α (α = 1..4) the hourglass base vectors, γ_α the hourglass shape
//! vectors.
//!
//! Kinematics and stress update (what the family does each step; Belytschko, Liu &
//! Moran (BLM), *Nonlinear Finite Elements*, 2nd ed., ch. 5 (objective rates),
//! §8.7 (one-point quadrature, hourglass control); LS-DYNA Theory Manual, "Solid
//! elements"): with the central difference velocities v^{n+½},
//!  1. b at the mid-step geometry x^{n+½} = ½(x^n + x^{n+1}) ([`hex8::hex_geometry`]),
//!     L = Σ_a v_a ⊗ b_a ([`velocity_gradient`]), D, W ([`split_velocity_gradient`]);
//!  2. σ ← R σ Rᵀ with R the Hughes–Winget rotation of W Δt ([`hughes_winget`],
//!     [`rotate_stress`]: an incrementally objective update, exactly orthogonal R, so a
//!     rigid rotation leaves the invariants of σ unchanged);
//!  3. the material update with dε = D Δt (`material::update`);
//!  4. at x^{n+1}: V, b, f_a −= V (σ − q I) b_a ([`internal_forces`]) with q the bulk
//!     viscosity ([`bulk_viscosity`]) and the hourglass forces ([`hourglass_gamma`],
//!     [`hourglass_viscous`]); the stable step l_e/c ([`hex8::characteristic_length`]).

use crate::shape::hex8::HOURGLASS;
use crate::vec3::{axpy, dot, Mat3, Vec3};

/// LS-DYNA's default quadratic bulk viscosity coefficient (*CONTROL_BULK_VISCOSITY Q1).
pub const BULK_Q1: f64 = 1.5;
/// LS-DYNA's default linear bulk viscosity coefficient (*CONTROL_BULK_VISCOSITY Q2).
pub const BULK_Q2: f64 = 0.06;
/// LS-DYNA's default hourglass coefficient Q_hg (*CONTROL_HOURGLASS QH).
pub const HOURGLASS_QH: f64 = 0.1;

/// L_ij = Σ_a v_ai b_aj (the mean velocity gradient; exact for a linear velocity field).
pub fn velocity_gradient(b: &[[f64; 3]; 8], v: &[[f64; 3]; 8]) -> Mat3 {
    let mut l = [[0.0; 3]; 3];
    for a in 0..8 {
        for i in 0..3 {
            for j in 0..3 {
                l[i][j] += v[a][i] * b[a][j];
            }
        }
    }
    l
}

/// The mid-step shape x^{n−½} = xⁿ − ½Δt v^{n−½}, where the step's rates are taken.
#[inline]
pub fn mid_step_shape(x: &[Vec3; 8], v: &[Vec3; 8], dt: f64) -> [Vec3; 8] {
    std::array::from_fn(|a| std::array::from_fn(|i| x[a][i] - 0.5 * dt * v[a][i]))
}

/// σ:ε of symmetric tensors in Voigt order [xx, yy, zz, xy, yz, zx] (tensor components).
#[inline(always)]
pub fn contract(s: &[f64; 6], e: &[f64; 6]) -> f64 {
    s[0] * e[0] + s[1] * e[1] + s[2] * e[2] + 2.0 * (s[3] * e[3] + s[4] * e[4] + s[5] * e[5])
}

/// D = ½(L + Lᵀ) in Voigt order [xx, yy, zz, xy, yz, zx] (tensor components, not
/// engineering shear: D_xy = ½(L_xy + L_yx)).
pub fn rate_of_deformation(l: &Mat3) -> [f64; 6] {
    [
        l[0][0],
        l[1][1],
        l[2][2],
        0.5 * (l[0][1] + l[1][0]),
        0.5 * (l[1][2] + l[2][1]),
        0.5 * (l[2][0] + l[0][2]),
    ]
}

/// W = ½(L − Lᵀ) (exactly skew: W_ii = 0, W_ji = −W_ij bit for bit).
pub fn spin(l: &Mat3) -> Mat3 {
    let w01 = 0.5 * (l[0][1] - l[1][0]);
    let w12 = 0.5 * (l[1][2] - l[2][1]);
    let w20 = 0.5 * (l[2][0] - l[0][2]);
    [[0.0, w01, -w20], [-w01, 0.0, w12], [w20, -w12, 0.0]]
}

/// (D, W) = ([`rate_of_deformation`], [`spin`]) of L.
pub fn split_velocity_gradient(l: &Mat3) -> ([f64; 6], Mat3) {
    (rate_of_deformation(l), spin(l))
}

/// The Hughes–Winget rotation of a step, R = (I − ½WΔt)⁻¹(I + ½WΔt) (Hughes & Winget,
/// IJNME 15 (1980) 1862–1867; BLM ch. 5 (objective rates): the midpoint-rule integration of the
/// Jaumann rate's rotation). With A = ½ΔtW (skew, axial vector a, A² = aaᵀ − |a|²I,
/// A³ = −|a|²A) one checks (I − A)⁻¹ = I + (A + A²)/(1 + |a|²), hence the closed form
///   R = I + 2 (A + A²)/(1 + |a|²)
/// (the Cayley transform of A; Rodrigues' formula with tan(θ/2) = |a|). R is orthogonal
/// for every A (to round-off, no drift with the step size) and R → exp(WΔt) to second
/// order in Δt. Only the skew part of `w` is used.
pub fn hughes_winget(w: &Mat3, dt: f64) -> Mat3 {
    let h = 0.25 * dt; // ½Δt times ½ for the skew part
                       // A = ½Δt W, axial a with A_12 = −a_3, A_20 = −a_1..., i.e. A v = a × v.
    let a = [
        h * (w[2][1] - w[1][2]),
        h * (w[0][2] - w[2][0]),
        h * (w[1][0] - w[0][1]),
    ];
    let s = 2.0 / (1.0 + dot(&a, &a));
    let am = [[0.0, -a[2], a[1]], [a[2], 0.0, -a[0]], [-a[1], a[0], 0.0]];
    // A² = a aᵀ − |a|² I
    let aa = dot(&a, &a);
    let mut r = [[0.0; 3]; 3];
    for i in 0..3 {
        for j in 0..3 {
            let a2 = a[i] * a[j] - if i == j { aa } else { 0.0 };
            r[i][j] = if i == j { 1.0 } else { 0.0 } + s * (am[i][j] + a2);
        }
    }
    r
}

/// σ ← R σ Rᵀ for a symmetric stress in Voigt order [xx, yy, zz, xy, yz, zx].
pub fn rotate_stress(s: &mut [f64; 6], r: &Mat3) {
    let m = voigt_to_matrix(s);
    // T = R σ, then R σ Rᵀ_ij = Σ_k T_ik R_jk, only the upper triangle.
    let mut t = [[0.0; 3]; 3];
    for i in 0..3 {
        for j in 0..3 {
            t[i][j] = r[i][0] * m[0][j] + r[i][1] * m[1][j] + r[i][2] * m[2][j];
        }
    }
    let rr = |i: usize, j: usize| t[i][0] * r[j][0] + t[i][1] * r[j][1] + t[i][2] * r[j][2];
    *s = [rr(0, 0), rr(1, 1), rr(2, 2), rr(0, 1), rr(1, 2), rr(2, 0)];
}

/// The symmetric matrix of a Voigt vector [xx, yy, zz, xy, yz, zx] (tensor components).
pub fn voigt_to_matrix(s: &[f64; 6]) -> Mat3 {
    [[s[0], s[3], s[5]], [s[3], s[1], s[4]], [s[5], s[4], s[2]]]
}

/// Flanagan & Belytschko's hourglass shape vectors (1981; their eq. (72) is the quad's,
/// the hexahedron's is its three-dimensional counterpart; BLM §8.7):
///   γ_aα = ¼ (h_aα − (Σ_c h_cα x_c) · b_a),  α = 1..4.
/// γ_α is orthogonal to every linear nodal field (Σ_a γ_aα (A x_a + c) = 0, from Σ_a b_a = 0
/// and Σ_a x_a ⊗ b_a = I), so hourglass forces built on it do no work in rigid motion or
/// uniform straining. On a parallelepiped Σ_c h_cα x_c = 0 and γ_α = h_α/4. Returned per
/// node: `gamma[a][α]`.
pub fn hourglass_gamma(x: &[[f64; 3]; 8], b: &[[f64; 3]; 8]) -> [[f64; 4]; 8] {
    let mut hx = [[0.0; 3]; 4];
    for (al, h) in HOURGLASS.iter().enumerate() {
        for a in 0..8 {
            axpy(&mut hx[al], h[a], &x[a]);
        }
    }
    std::array::from_fn(|a| {
        std::array::from_fn(|al| 0.25 * (HOURGLASS[al][a] - dot(&hx[al], &b[a])))
    })
}

/// Viscous hourglass forces (Flanagan & Belytschko 1981 §5; LS-DYNA IHQ = 1 form with
/// FB's projected vectors): q_iα = Σ_a v_ai γ_aα (the hourglass velocity of mode α in
/// direction i), f_ai −= coef Σ_α q_iα γ_aα. Returns the power the forces take,
/// P = −Σ_a f_a·v_a (of this contribution) = coef Σ_α |q_α|² ≥ 0, the rate of hourglass
/// energy for the ledger.
pub fn hourglass_viscous(
    gamma: &[[f64; 4]; 8],
    v: &[[f64; 3]; 8],
    coef: f64,
    f: &mut [[f64; 3]; 8],
) -> f64 {
    let cq = hourglass_mode_forces(gamma, v, coef);
    add_hourglass_forces(gamma, &cq, f);
    let mut p = 0.0;
    for a in 0..8 {
        for al in 0..4 {
            for i in 0..3 {
                p += gamma[a][al] * cq[al][i] * v[a][i];
            }
        }
    }
    p
}

/// The viscous hourglass control's mode forces coef·q_α = coef Σ_a γ_aα v_a [N], one
/// vector per mode α (the family keeps them for the next step's energy booking).
pub fn hourglass_mode_forces(gamma: &[[f64; 4]; 8], v: &[[f64; 3]; 8], coef: f64) -> [Vec3; 4] {
    let mut cq = [[0.0; 3]; 4];
    for a in 0..8 {
        for (al, m) in cq.iter_mut().enumerate() {
            for i in 0..3 {
                m[i] += coef * gamma[a][al] * v[a][i];
            }
        }
    }
    cq
}

/// f_a −= Σ_α γ_aα (coef q_α): the nodal forces of the mode forces `cq`.
pub fn add_hourglass_forces(gamma: &[[f64; 4]; 8], cq: &[Vec3; 4], f: &mut [[f64; 3]; 8]) {
    for a in 0..8 {
        for al in 0..4 {
            for i in 0..3 {
                f[a][i] += -gamma[a][al] * cq[al][i];
            }
        }
    }
}

/// The viscous hourglass coefficient coef = Q_hg ρ c V^{2/3} / 4 [kg/s] (LS-DYNA Theory
/// Manual, hourglass control, a_h = Q_hg ρ v_e^{2/3} c / 4; Q_hg = [`HOURGLASS_QH`] = 0.1
/// by default), c the dilatational wave speed.
///
/// Scale: LS-DYNA applies a_h to the unprojected base vectors Γ (entries ±1), f = a_h
/// (Γ·v)Γ; here the ¼-normalised γ (γ = h/4 on a parallelepiped) gives f = coef (γ·v)γ =
/// coef/16 (h·v)h. For the same Q_hg these forces are therefore 1/16 of LS-DYNA's IHQ = 1
/// forces; to reproduce LS-DYNA's magnitude, pass 16 × this value.
pub fn hourglass_coefficient(q_hg: f64, rho: f64, c: f64, volume: f64) -> f64 {
    0.25 * q_hg * rho * c * volume.abs().powf(2.0 / 3.0)
}

/// Bulk viscosity pressure q = ρ l (Q₁ l d_kk² − Q₂ c d_kk) for d_kk < 0, else 0 (LS-DYNA
/// Theory Manual, "Bulk viscosity", the von Neumann–Richtmyer quadratic term plus
/// Landshoff's linear term; defaults [`BULK_Q1`] = 1.5, [`BULK_Q2`] = 0.06). l the
/// characteristic length, c the wave speed, d_kk = tr D. Added to the pressure
/// (compression positive): the element's stress is σ − q I. Its power per unit volume
/// is −q d_kk ≥ 0.
pub fn bulk_viscosity(rho: f64, l: f64, c: f64, d_kk: f64, q1: f64, q2: f64) -> f64 {
    if d_kk < 0.0 {
        rho * l * (q1 * l * d_kk * d_kk - q2 * c * d_kk)
    } else {
        0.0
    }
}

/// f_a −= V σ b_a: the forces the element's stress exerts on its nodes (one-point
/// mean-stress quadrature, Flanagan & Belytschko 1981; BLM §8.7). Their sum is zero (Σ b_a = 0) and,
/// for symmetric σ, their moment Σ x_a × f_a is zero (Σ x_a ⊗ b_a = I).
pub fn internal_forces(b: &[[f64; 3]; 8], volume: f64, s: &[f64; 6], f: &mut [[f64; 3]; 8]) {
    let m = voigt_to_matrix(s);
    for a in 0..8 {
        for i in 0..3 {
            f[a][i] -= volume * (m[i][0] * b[a][0] + m[i][1] * b[a][1] + m[i][2] * b[a][2]);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::random::Stream;
    use crate::shape::hex8::hex_geometry;
    use crate::shape::hex8::tests::{distorted, inverse, unit_cube};
    use crate::vec3::{cross, norm, triple};

    fn random_mat(r: &mut Stream) -> Mat3 {
        std::array::from_fn(|_| std::array::from_fn(|_| r.next_uniform() - 0.5))
    }

    fn matmul(a: &Mat3, b: &Mat3) -> Mat3 {
        std::array::from_fn(|i| std::array::from_fn(|j| (0..3).map(|k| a[i][k] * b[k][j]).sum()))
    }

    /// Σ_a b_a = 0 and Σ_a x_a ⊗ b_a = I for any hexahedron (Flanagan & Belytschko 1981; the patch
    /// test's condition).
    #[test]
    fn gradient_operator_is_exact_for_linear_fields() {
        for seed in 0..50 {
            let x = distorted(seed);
            let g = hex_geometry(&x);
            let bscale = g.b.iter().flatten().fold(0.0f64, |m, v| m.max(v.abs()));
            for d in 0..3 {
                let s: f64 = (0..8).map(|a| g.b[a][d]).sum();
                assert!(s.abs() < 2e-15 * bscale, "Σb = {s}"); // measured 4.6e-16
            }
            let xb = velocity_gradient(&g.b, &x); // Σ x_a ⊗ b_a
            for i in 0..3 {
                for j in 0..3 {
                    let e = xb[i][j] - if i == j { 1.0 } else { 0.0 };
                    assert!(e.abs() < 2e-15, "x⊗b − I = {e} at {i}{j}"); // measured 4.4e-16
                }
            }
            // A linear velocity field v = A x + c gives L = A exactly.
            let mut r = Stream::new(1000 + seed);
            let am = random_mat(&mut r);
            let c = [r.next_uniform(), r.next_uniform(), r.next_uniform()];
            let v: [[f64; 3]; 8] =
                std::array::from_fn(|a| std::array::from_fn(|i| dot(&am[i], &x[a]) + c[i]));
            let l = velocity_gradient(&g.b, &v);
            for i in 0..3 {
                for j in 0..3 {
                    assert!(
                        (l[i][j] - am[i][j]).abs() < 1e-14,
                        "{} vs {}",
                        l[i][j],
                        am[i][j]
                    );
                }
            }
            let (d, w) = split_velocity_gradient(&l);
            for i in 0..3 {
                for j in 0..3 {
                    let dm = voigt_to_matrix(&d);
                    assert_eq!(
                        dm[i][j] + w[i][j],
                        0.5 * (l[i][j] + l[j][i]) + 0.5 * (l[i][j] - l[j][i])
                    );
                    assert_eq!(w[i][j], -w[j][i]);
                }
            }
        }
    }

    #[test]
    fn hughes_winget_is_orthogonal_and_matches_the_definition() {
        let mut r = Stream::new(7);
        for _ in 0..100 {
            let l = random_mat(&mut r);
            let w = spin(&l);
            let dt = 10.0 * r.next_uniform(); // large rotations too
            let rot = hughes_winget(&w, dt);
            let rrt = matmul(
                &rot,
                &std::array::from_fn(|i| std::array::from_fn(|j| rot[j][i])),
            );
            for i in 0..3 {
                for j in 0..3 {
                    let e = rrt[i][j] - if i == j { 1.0 } else { 0.0 };
                    assert!(e.abs() < 2e-15, "RRᵀ − I = {e}"); // measured 4.4e-16
                }
            }
            // The definition (I − ½WΔt)⁻¹(I + ½WΔt) by a general inverse.
            let im: Mat3 = std::array::from_fn(|i| {
                std::array::from_fn(|j| if i == j { 1.0 } else { 0.0 } - 0.5 * dt * w[i][j])
            });
            let ip: Mat3 = std::array::from_fn(|i| {
                std::array::from_fn(|j| if i == j { 1.0 } else { 0.0 } + 0.5 * dt * w[i][j])
            });
            let rd = matmul(&inverse(&im), &ip);
            for i in 0..3 {
                for j in 0..3 {
                    assert!(
                        (rd[i][j] - rot[i][j]).abs() < 2e-15, // measured 3.3e-16
                        "{} vs {}",
                        rd[i][j],
                        rot[i][j]
                    );
                }
            }
        }
    }

    /// A constant spin about z, over n steps totalling 90°, turns a uniaxial σ_xx into
    /// σ_yy: Hughes–Winget's R per step is the rotation by 2 atan(ωΔt/2), so the total
    /// angle is 2n atan(π/(4n)) (not exactly π/2: the midpoint rule's phase error,
    /// O(Δt²)); the invariants (principal values) are kept to round-off regardless.
    #[test]
    fn constant_spin_rotates_stress_objectively() {
        let n = 1000;
        let omega = 2.0; // rad/s
        let dt = std::f64::consts::FRAC_PI_2 / omega / n as f64;
        let w = [[0.0, -omega, 0.0], [omega, 0.0, 0.0], [0.0, 0.0, 0.0]];
        let r = hughes_winget(&w, dt);
        let s0 = 100e6;
        let mut s = [s0, 0.0, 0.0, 0.0, 0.0, 0.0];
        for _ in 0..n {
            rotate_stress(&mut s, &r);
        }
        let theta = 2.0 * n as f64 * (0.5 * omega * dt).atan();
        let (c, sn) = (theta.cos(), theta.sin());
        let expect = [s0 * c * c, s0 * sn * sn, 0.0, s0 * c * sn, 0.0, 0.0];
        for k in 0..6 {
            assert!(
                (s[k] - expect[k]).abs() < 2e-13 * s0, // measured 4.7e-14 (1000 steps)
                "{k}: {} vs {}",
                s[k],
                expect[k]
            );
        }
        // Within the phase error of 90°: θ − π/2 ≈ −(π/2)(ωΔt)²/12.
        assert!((theta - std::f64::consts::FRAC_PI_2).abs() < 1e-6);
        assert!(s[1] > (1.0 - 1e-11) * s0 && s[0].abs() < 1e-11 * s0);
        // Invariants: tr σ, σ:σ and det σ unchanged to round-off.
        let tr = s[0] + s[1] + s[2];
        let ss = s[0] * s[0]
            + s[1] * s[1]
            + s[2] * s[2]
            + 2.0 * (s[3] * s[3] + s[4] * s[4] + s[5] * s[5]);
        assert!(
            (tr - s0).abs() < 1e-13 * s0 && (ss.sqrt() - s0).abs() < 1e-13 * s0,
            "{tr} {ss}"
        );
        // A general stress: the principal values (via the invariants) survive the turn.
        let mut g = [3.0, -1.0, 2.0, 0.5, -0.7, 1.1];
        let inv = |s: &[f64; 6]| {
            let m = voigt_to_matrix(s);
            let i1 = m[0][0] + m[1][1] + m[2][2];
            let i2 = (0..3)
                .flat_map(|i| (0..3).map(move |j| (i, j)))
                .map(|(i, j)| m[i][j] * m[j][i])
                .sum::<f64>();
            (i1, i2, triple(&m[0], &m[1], &m[2]))
        };
        let before = inv(&g);
        let r2 = hughes_winget(
            &[[0.0, -0.3, 0.8], [0.3, 0.0, -1.7], [-0.8, 1.7, 0.0]],
            0.01,
        );
        for _ in 0..1000 {
            rotate_stress(&mut g, &r2);
        }
        let after = inv(&g);
        // R is orthogonal to a few ulp, and the same R applied n times drifts the scale
        // systematically: bound n·4ε relative (8.9e-13); measured ≤ 1.6e-13.
        let tol = 1000.0 * 4.0 * f64::EPSILON;
        assert!(
            (before.0 - after.0).abs() < tol * before.0.abs()
                && (before.1 - after.1).abs() < tol * before.1.abs()
                && (before.2 - after.2).abs() < tol * before.2.abs(),
            "{before:?} {after:?}"
        );
    }

    /// γ_α is orthogonal to every linear field on a distorted hex (FB's defining property).
    #[test]
    fn hourglass_vectors_are_orthogonal_to_linear_fields() {
        for seed in 0..30 {
            let x = distorted(seed);
            let g = hex_geometry(&x);
            let gam = hourglass_gamma(&x, &g.b);
            let mut r = Stream::new(500 + seed);
            let am = random_mat(&mut r);
            let c = [r.next_uniform(), r.next_uniform(), r.next_uniform()];
            let v: [[f64; 3]; 8] =
                std::array::from_fn(|a| std::array::from_fn(|i| dot(&am[i], &x[a]) + c[i]));
            for al in 0..4 {
                for i in 0..3 {
                    let s: f64 = (0..8).map(|a| gam[a][al] * v[a][i]).sum();
                    assert!(s.abs() < 1e-15, "seed {seed} mode {al}: {s}"); // measured 2.5e-16
                }
            }
            // No force, no power for a linear velocity field; a positive power otherwise.
            let mut f = [[0.0; 3]; 8];
            let p = hourglass_viscous(&gam, &v, 3.0, &mut f);
            assert!(
                p.abs() < 1e-26 && f.iter().flatten().all(|v| v.abs() < 1e-13),
                "{p}"
            );
            let mut vh = v;
            for a in 0..8 {
                vh[a][2] += 0.1 * HOURGLASS[seed as usize % 4][a];
            }
            let mut f = [[0.0; 3]; 8];
            let p = hourglass_viscous(&gam, &vh, 3.0, &mut f);
            let work: f64 = (0..8).map(|a| dot(&f[a], &vh[a])).sum();
            assert!(p > 0.0 && (p + work).abs() < 1e-14 * p, "{p} vs {work}"); // 1.6e-15
                                                                               // Hourglass forces have no resultant (Σ_a γ_aα = 0).
            for d in 0..3 {
                assert!((0..8).map(|a| f[a][d]).sum::<f64>().abs() < 1e-14);
            }
        }
        // Parallelepiped: γ = h/4 exactly.
        let x = unit_cube();
        let gam = hourglass_gamma(&x, &hex_geometry(&x).b);
        for a in 0..8 {
            for al in 0..4 {
                assert_eq!(gam[a][al], 0.25 * HOURGLASS[al][a]);
            }
        }
        let c = hourglass_coefficient(0.1, 8000.0, 5000.0, 1e-9);
        assert!((c - 0.25 * 0.1 * 8000.0 * 5000.0 * 1e-6).abs() < 1e-15 * c);
    }

    /// Zero resultant and zero moment of the stress forces for any symmetric stress on a
    /// distorted hex; an unsymmetric "stress" would leave the moment V ε_ijk σ_kj (the
    /// check that the moment balance relies on σ's symmetry).
    #[test]
    fn internal_forces_are_self_equilibrated() {
        for seed in 0..30 {
            let x = distorted(seed);
            let g = hex_geometry(&x);
            let mut r = Stream::new(900 + seed);
            let s: [f64; 6] = std::array::from_fn(|_| 1e8 * (r.next_uniform() - 0.5));
            let mut f = [[0.0; 3]; 8];
            internal_forces(&g.b, g.volume, &s, &mut f);
            let fs = 1e8 * g.volume;
            let mut tot = [0.0; 3];
            let mut mom = [0.0; 3];
            for a in 0..8 {
                axpy(&mut tot, 1.0, &f[a]);
                axpy(&mut mom, 1.0, &cross(&x[a], &f[a]));
            }
            assert!(
                norm(&tot) < 1e-15 * fs && norm(&mom) < 2e-15 * fs, // 1.1e-16, 3.8e-16
                "{tot:?} {mom:?}"
            );
            // The power of the forces is −V σ:L for any velocity (virtual power).
            let v: [[f64; 3]; 8] =
                std::array::from_fn(|_| std::array::from_fn(|_| r.next_uniform() - 0.5));
            let l = velocity_gradient(&g.b, &v);
            let m = voigt_to_matrix(&s);
            let sl: f64 = (0..3)
                .flat_map(|i| (0..3).map(move |j| (i, j)))
                .map(|(i, j)| m[i][j] * l[i][j])
                .sum();
            let pw: f64 = (0..8).map(|a| dot(&f[a], &v[a])).sum();
            assert!((pw + g.volume * sl).abs() < 1e-15 * fs); // measured 6.4e-17
        }
        // An unsymmetric tensor on the unit cube: the moment is −V ε_ijk σ_kj ≠ 0.
        let x = unit_cube();
        let g = hex_geometry(&x);
        let sig = [[0.0, 1.0, 0.0], [0.0, 0.0, 0.0], [0.0, 0.0, 0.0]]; // σ_xy = 1, σ_yx = 0
        let mut mom = [0.0; 3];
        for a in 0..8 {
            let fa = [
                -dot(&sig[0], &g.b[a]),
                -dot(&sig[1], &g.b[a]),
                -dot(&sig[2], &g.b[a]),
            ];
            axpy(&mut mom, 1.0, &cross(&x[a], &fa));
        }
        assert_eq!(mom, [0.0, 0.0, 1.0]); // −(ε_3jk σ_kj) = −(σ_yx − σ_xy)
    }

    #[test]
    fn bulk_viscosity_acts_in_compression_only() {
        assert_eq!(
            bulk_viscosity(7800.0, 1e-3, 5000.0, 10.0, BULK_Q1, BULK_Q2),
            0.0
        );
        let d = -1e4;
        let q = bulk_viscosity(7800.0, 1e-3, 5000.0, d, BULK_Q1, BULK_Q2);
        assert_eq!(q, 7800.0 * 1e-3 * (1.5 * 1e-3 * 1e8 + 0.06 * 5000.0 * 1e4));
        assert!(q > 0.0 && -q * d > 0.0);
    }
}
