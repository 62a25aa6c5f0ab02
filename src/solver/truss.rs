//! Corotational two-node truss (rod) kernel.
//!
//! Glossary: x₁, x₂ current node positions [m]; d = x₂ − x₁; L = |d|; L₀ initial length;
//! k = E·A/L₀ axial stiffness [N/m]; N = k (L − L₀) axial force [N] (tension > 0),
//! N = max(N, 0) when tension-only; e = d/L the current axis.
//!
//! Internal force on node 2: f₂ = −N e, on node 1: f₁ = +N e (these are the forces the
//! element exerts, so they enter the nodal balance with a plus sign). Strain energy
//! W = ½ k (L − L₀)² (tension-only: zero when L < L₀); f = −∂W/∂x exactly, and the force
//! depends on x only through L and e, so a rigid rotation produces no force (the
//! corotational property). Small strain, large displacement and rotation: the
//! engineering strain (L − L₀)/L₀ with a constant cross-section (no Poisson thinning).
//!
//! Reference: Belytschko, Liu, Moran, *Nonlinear Finite Elements for Continua and
//! Structures*, 2nd ed., §2.8 (rod element, corotational form).

/// Force exerted by the truss on node 2 (node 1 gets the opposite).
///
/// ```
/// // A 1 m truss of k = 1000 N/m stretched by 1 mm pulls node 2 back with 1 N.
/// let f2 = weft::solver::truss::force(&[0.0; 3], &[1.001, 0.0, 0.0], 1000.0, 1.0, false);
/// assert!((f2[0] + 1.0).abs() < 1e-9 && f2[1] == 0.0);
/// ```
#[inline(always)]
pub fn force(x1: &[f64; 3], x2: &[f64; 3], k: f64, l0: f64, tension_only: bool) -> [f64; 3] {
    let d = [x2[0] - x1[0], x2[1] - x1[1], x2[2] - x1[2]];
    let l = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
    let mut n = k * (l - l0);
    if tension_only && n < 0.0 {
        n = 0.0;
    }
    let s = -n / l;
    [s * d[0], s * d[1], s * d[2]]
}

/// Strain energy ½ k (L − L₀)² [J] (zero in compression when tension-only).
#[inline(always)]
pub fn energy(x1: &[f64; 3], x2: &[f64; 3], k: f64, l0: f64, tension_only: bool) -> f64 {
    let d = [x2[0] - x1[0], x2[1] - x1[1], x2[2] - x1[2]];
    let l = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
    let e = l - l0;
    if tension_only && e < 0.0 {
        0.0
    } else {
        0.5 * k * e * e
    }
}

/// Axial force N [N] (tension positive).
#[inline(always)]
pub fn axial_force(x1: &[f64; 3], x2: &[f64; 3], k: f64, l0: f64, tension_only: bool) -> f64 {
    let d = [x2[0] - x1[0], x2[1] - x1[1], x2[2] - x1[2]];
    let l = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
    let n = k * (l - l0);
    if tension_only && n < 0.0 {
        0.0
    } else {
        n
    }
}
