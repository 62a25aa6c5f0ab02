//! The collapse criterion of the membranes that can fail: an element whose own stable
//! step, at its current shape, has fallen below half the step the run takes
//! ([`FRACTION`]) is removed, the way OpenRadioss' `/DT/SHELL/DEL` (the default for
//! shells) and LS-DYNA's ERODE with DTMIN remove an element that would otherwise hold
//! the run's step down (docs/theory.md, "Failure, perforation and the ballistic limit",
//! Collapse).
//!
//! Glossary: A the element's area (a quad's |d₁ × d₂|/2, d₁, d₂ its diagonals, the area
//! of its projection on the plane the diagonals span; a triangle's |e₁ × e₂|/2); ℓ its
//! longest side; L its characteristic length, A/ℓ for a quad and 2A/ℓ for a triangle
//! (LS-DYNA's shell length with β = 0 and 1); Δt_e its stable step.
//!
//! The element's step at the reference shape is 2√(m_min/k_max), k_max the largest
//! eigenvalue of its stiffness and m_min the smallest mass of its nodes that can move
//! (with what ties and mass scaling added): the step of the nodal bound the run's step
//! comes from, for a node that had this element alone, so it is never below the run's
//! step at the start (`stable`: S_i ≥ k_max). A one-point element's stable step scales as
//! its characteristic length (the Courant condition; Belytschko et al. §6.3.2), so at the
//! current shape Δt_e = 2√(m_min/k_max) · L/L₀.
//!
//! Why it matters: a membrane next to eroded ones can be crushed flat in its plane by
//! the motion the failures release (an St Venant–Kirchhoff membrane offers no resistance
//! at a stretch of zero). Its quad's hourglass warping mode is measured along the normal
//! of its diagonals, n = d₁ × d₂/|d₁ × d₂|, which turns as 1/A: as the area passes
//! through zero the normal swings round within a step or two, and the central
//! difference, which samples the hourglass force once a step, makes energy (measured on
//! the combined patch-in-membrane model: the balance error rose by 0.024 J, 9 % of the
//! impact's energy, in two steps).

use super::vec3::{cross, dot, sub};

/// The fraction of the run's step below which an element's own step removes it.
/// Below 1 because Δt_e ∝ L is a conservative proxy for a total-Lagrangian membrane,
/// whose in-plane stiffness does not grow as it is sheared or compressed: only the
/// hourglass normal's turning stiffness does, and steeply only as A → 0. With ½ a
/// membrane that sets the run's step (Δt = 0.9 Δt_e,0) stays until L < 0.45 L₀, a
/// rhombus sheared past 63°, far past a fabric's locking angle. Measured on the
/// combined model: the crushed quad is removed at 6 % of its reference area, four steps
/// before its area passes through zero (with 1, 0.25 and 0.1: eight, one and zero steps
/// before; at 0.1 it leaves at the very step the energy would have jumped), and the quad
/// of `tests/membrane_collapse.rs` keeps its balance to 3.9·10⁻⁵ with 1 to 0.25,
/// 3.5·10⁻⁴ with 0.1.
pub const FRACTION: f64 = 0.5;

/// The step below which an element's own step removes it, when the run takes `dt`.
#[inline(always)]
pub fn limit(dt: f64) -> f64 {
    FRACTION * dt
}

/// What the criterion keeps of one element at its reference shape.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CollapseRef {
    /// L₀, the characteristic length at the reference shape [m].
    pub length: f64,
    /// 2√(m_min/k_max), the element's stable step at the reference shape [s]
    /// (`f64::INFINITY`: never removed by the criterion).
    pub step: f64,
}

/// The characteristic length L [m] of a membrane element (3 nodes: a triangle, 4: a
/// quad) at positions `x`: A/ℓ for a quad, 2A/ℓ for a triangle (see the module docs).
#[inline(always)]
pub fn char_length<const N: usize>(x: &[[f64; 3]; N]) -> f64 {
    let c = if N == 3 {
        cross(&sub(&x[1], &x[0]), &sub(&x[2], &x[0]))
    } else {
        cross(&sub(&x[2], &x[0]), &sub(&x[3 % N], &x[1]))
    };
    let area = 0.5 * dot(&c, &c).sqrt();
    let mut side2: f64 = 0.0;
    for a in 0..N {
        let d = sub(&x[(a + 1) % N], &x[a]);
        side2 = side2.max(dot(&d, &d));
    }
    let beta = if N == 3 { 2.0 } else { 1.0 };
    if side2 > 0.0 {
        beta * area / side2.sqrt()
    } else {
        0.0
    }
}

impl CollapseRef {
    /// At the reference positions `x` with the largest stiffness eigenvalue `k_max`
    /// [N/m] and the masses [kg] of the element's nodes that can move.
    pub fn new<const N: usize>(
        x: &[[f64; 3]; N],
        k_max: f64,
        masses: impl Iterator<Item = f64>,
    ) -> CollapseRef {
        let m_min = masses.filter(|&m| m > 0.0).fold(f64::INFINITY, f64::min);
        let step = if k_max > 0.0 && m_min.is_finite() {
            2.0 * (m_min / k_max).sqrt()
        } else {
            f64::INFINITY
        };
        CollapseRef {
            length: char_length(x),
            step,
        }
    }

    /// The element's stable step at positions `x` when it is below [`limit`]`(dt)`, `dt`
    /// the step the run takes (none while `dt` is zero, before the first step).
    #[inline(always)]
    pub fn below<const N: usize>(&self, x: &[[f64; 3]; N], dt: f64) -> Option<f64> {
        if !(dt > 0.0) || !self.step.is_finite() || !(self.length > 0.0) {
            return None;
        }
        let step = self.step * char_length(x) / self.length;
        (step < limit(dt)).then_some(step)
    }
}
