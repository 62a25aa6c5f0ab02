//! What the J2-type laws share: the hypoelastic predictor, the radial return onto a von
//! Mises yield surface with the law's own flow stress, the plastic work, and the stress
//! measures (glossary in the module above).
//!
//! Elasticity (hypoelastic, the rotated-frame update of the kernel's Hughes–Winget step):
//!   σ_tr = σ + λ tr(dε) I + 2μ dε      (so σ_xy += 2μ dε_xy with tensor dε_xy).
//! Plasticity (Simo & Hughes, *Computational Inelasticity*, §3.3: the radial
//! return, backward Euler on the associative J2 flow rule; BLM *Nonlinear Finite
//! Elements* ch. 5): with σ̄_tr the von Mises stress of the trial deviator s_tr, if
//! σ̄_tr ≤ σ_y(ε_p) the step is elastic; otherwise Δε_p solves the consistency condition
//!   r(Δε_p) = σ̄_tr − 3μ Δε_p − σ_y(ε_p + Δε_p, Δε_p/Δt, T_n) = 0,
//! and s = (1 − 3μΔε_p/σ̄_tr) s_tr, p unchanged (J2 flow is deviatoric, so the radial
//! return leaves the pressure of the trial state). A law with an explicit root (linear
//! hardening) gives it; the others call [`newton_return`]: a scalar Newton iteration on
//! Δε_p, safeguarded by bisection on the bracket [0, (σ̄_tr − σ_y(ε_p))/(3μ)] (r is
//! decreasing in Δε_p for a non-softening σ_y, r(0) > 0 and r ≤ 0 at the right end),
//! converged to |r| ≤ [`RETURN_TOLERANCE`] σ̄_tr. After the return σ̄ = σ̄_tr − 3μΔε_p
//! = σ_y at the converged point.
//!
//! Plastic work: ΔW_p = σ̄_{n+1} Δε_p with the END-of-step flow stress. This is exactly
//! σ_{n+1}:Δε^p of the backward-Euler plastic strain increment Δε^p = Δε_p (3/2)
//! s_{n+1}/σ̄_{n+1} (the return's normal), so Σ ΔW_p = Σ σ_{n+1}:Δε^p, the rectangle rule
//! for ∫σ:dε^p that the radial return itself implies (it differs from the trapezoid rule
//! by ½ Σ Δσ̄ Δε_p, first order in the step). A law that heats turns it into temperature
//! ([`super::johnson_cook`]).

use super::law::{Elastic, PointState};

/// Relative tolerance on the consistency residual |r| / σ̄_tr of the Newton return.
pub const RETURN_TOLERANCE: f64 = 1e-14;

/// p = −tr σ/3 (compression positive).
#[inline]
pub fn pressure(s: &[f64; 6]) -> f64 {
    -(s[0] + s[1] + s[2]) / 3.0
}

/// σ̄ = √(3/2 s:s) = √(½((σ₁₁−σ₂₂)² + (σ₂₂−σ₃₃)² + (σ₃₃−σ₁₁)²) + 3(σ₁₂² + σ₂₃² + σ₃₁²)).
#[inline]
pub fn von_mises(s: &[f64; 6]) -> f64 {
    let (a, b, c) = (s[0] - s[1], s[1] - s[2], s[2] - s[0]);
    (0.5 * (a * a + b * b + c * c) + 3.0 * (s[3] * s[3] + s[4] * s[4] + s[5] * s[5])).sqrt()
}

/// The elastic predictor σ_tr = σ + λ tr(dε) I + 2μ dε (module docs), with (λ, μ).
#[inline]
pub fn elastic_trial(stress: &[f64; 6], deps: &[f64; 6], (lam, mu): (f64, f64)) -> [f64; 6] {
    let tr = deps[0] + deps[1] + deps[2];
    let mut s = *stress;
    for i in 0..3 {
        s[i] += lam * tr + 2.0 * mu * deps[i];
    }
    for i in 3..6 {
        s[i] += 2.0 * mu * deps[i];
    }
    s
}

/// Solve r(Δ) = σ̄_tr − 3μΔ − σ_y(Δ) = 0 for Δ ∈ (0, hi], hi = r(0)/(3μ) (then r(hi) ≤ 0
/// for non-decreasing σ_y): Newton from hi, bisection whenever Newton leaves the bracket
/// (module docs). `sy(Δ)` returns (σ_y, dσ_y/dΔ).
pub fn newton_return(sbar_tr: f64, mu3: f64, r0: f64, sy: impl Fn(f64) -> (f64, f64)) -> f64 {
    let (mut lo, mut hi) = (0.0, r0 / mu3);
    let mut d = hi;
    for _ in 0..200 {
        let (s, ds) = sy(d);
        let r = sbar_tr - mu3 * d - s;
        if r.abs() <= RETURN_TOLERANCE * sbar_tr {
            return d;
        }
        if r > 0.0 {
            lo = d;
        } else {
            hi = d;
        }
        let dn = d + r / (mu3 + ds);
        d = if dn > lo && dn < hi {
            dn
        } else {
            0.5 * (lo + hi)
        };
        if hi - lo <= 4.0 * f64::EPSILON * hi {
            return d;
        }
    }
    d
}

/// One J2 step of a point: the elastic predictor, then, when `increment(σ̄_tr, μ)` (the
/// law's Δε_p: 0 inside the yield surface) is positive, the radial return, the plastic
/// strain and the plastic work. Returns ΔW_p [J/m³] (0 for an elastic step).
#[inline]
pub fn radial_return(
    elastic: &Elastic,
    st: &mut PointState,
    deps: &[f64; 6],
    increment: impl FnOnce(f64, f64) -> f64,
) -> f64 {
    let (lam, mu) = elastic.lame();
    let mut s = elastic_trial(&st.stress, deps, (lam, mu));
    let sbar = von_mises(&s);
    let d = increment(sbar, mu);
    let mut dw = 0.0;
    if d > 0.0 {
        let p = pressure(&s);
        let k = (1.0 - 3.0 * mu * d / sbar).max(0.0);
        for v in s[..3].iter_mut() {
            *v = k * (*v + p) - p;
        }
        for v in s[3..].iter_mut() {
            *v *= k;
        }
        dw = (sbar - 3.0 * mu * d).max(0.0) * d;
        st.plastic_strain += d;
        st.plastic_work += dw;
    }
    st.stress = s;
    dw
}

#[cfg(test)]
mod tests {
    use super::super::j2::{tests::bilinear, Hardening, J2};
    use super::super::johnson_cook::tests::copper;
    use super::super::tests::elastic;
    use super::super::{Law, Material};
    use super::*;
    use crate::random::Stream;

    /// The radial return leaves the pressure of the trial state (J2 flow is deviatoric):
    /// p_{n+1} = p_n − K tr(dε), bilinear, tabulated and Johnson–Cook, random increments.
    #[test]
    fn radial_return_keeps_the_pressure() {
        let table =
            Hardening::table(vec![0.0, 0.01, 0.05, 0.2], vec![250e6, 300e6, 340e6, 360e6]).unwrap();
        let tab = Material::new(
            elastic(200e9, 0.3, 7850.0),
            Law::J2(J2 {
                yield_stress: 250e6,
                hardening: table,
            }),
            None,
        )
        .unwrap();
        for mat in [bilinear(), tab, copper()] {
            let k = mat.bulk_modulus();
            let mut st = mat.initial_state();
            let mut r = Stream::new(3);
            let mut plastic = 0;
            for _ in 0..200 {
                let de: [f64; 6] = std::array::from_fn(|_| 2e-3 * (r.next_uniform() - 0.5));
                let p_expect = pressure(&st.stress) - k * (de[0] + de[1] + de[2]);
                let ep = st.plastic_strain;
                mat.update(&mut st, &de, 1e-6);
                plastic += (st.plastic_strain > ep) as usize;
                assert!(
                    (pressure(&st.stress) - p_expect).abs() < 2e-14 * k * 1e-3, // 3.7e-15
                    "{:?}",
                    mat.law
                );
            }
            assert!(plastic > 100);
        }
    }
}
