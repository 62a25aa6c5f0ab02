//! The probability of perforation against striking velocity: V50, V10, V90.
//!
//! Glossary: V striking velocity [m/s]; y = 1 for a perforation, 0 for a stop;
//! P(V) = F(β₀ + β₁V) with F the logistic function 1/(1 + e^{−η}) (`logit`) or the
//! standard normal distribution Φ(η) (`probit`); V_q = (F⁻¹(q) − β₀)/β₁, so V50 = −β₀/β₁.
//!
//! β is the maximum-likelihood estimate, found by iteratively reweighted least squares
//! (Fisher scoring: McCullagh & Nelder, *Generalized Linear Models*, 2nd ed., §4.4; the
//! practice for armour: McKaig & Thomas, BRL-TR-02481, 1983, and the National Research
//! Council's *Testing of Body Armor Materials: Phase III*, 2012, ch. 6), on velocities
//! centred and scaled for conditioning. V50's 95 % interval is the Wald interval of the
//! delta method, V50 ± 1.96 √(∇V50ᵀ I⁻¹ ∇V50) with I the Fisher information.
//!
//! When the outcomes are separated (every stop slower than every perforation, which a
//! deterministic model gives unless it is run with statistical strengths), the
//! likelihood has no maximum (β₁ → ∞): the limit is then only bracketed, and V50 is the
//! middle of the bracket (the fastest stop, the slowest perforation), V10 and V90 its
//! ends, method `bracket`.

/// The link between velocity and probability.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Link {
    Logit,
    Probit,
}

impl Link {
    pub fn name(self) -> &'static str {
        match self {
            Link::Logit => "logit",
            Link::Probit => "probit",
        }
    }
    /// F(η).
    fn cdf(self, eta: f64) -> f64 {
        match self {
            Link::Logit => 1.0 / (1.0 + (-eta).exp()),
            Link::Probit => 0.5 * libm::erfc(-eta / std::f64::consts::SQRT_2),
        }
    }
    /// F′(η).
    fn pdf(self, eta: f64) -> f64 {
        match self {
            Link::Logit => {
                let p = self.cdf(eta);
                p * (1.0 - p)
            }
            Link::Probit => (-0.5 * eta * eta).exp() / (2.0 * std::f64::consts::PI).sqrt(),
        }
    }
    /// F⁻¹(q) for q = 0.1 and 0.9 (and 0.5).
    fn quantile(self, q: f64) -> f64 {
        match self {
            Link::Logit => (q / (1.0 - q)).ln(),
            // Φ⁻¹(0.9) = 1.2815515655446004 (Abramowitz & Stegun, Table 26.5).
            Link::Probit => {
                const Z90: f64 = 1.281_551_565_544_600_4;
                if q == 0.5 {
                    0.0
                } else if q == 0.9 {
                    Z90
                } else if q == 0.1 {
                    -Z90
                } else {
                    f64::NAN
                }
            }
        }
    }
}

/// A fitted probability of perforation.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Fit {
    /// `logit`, `probit` or `bracket`.
    pub method: &'static str,
    pub v50: f64,
    /// 95 % interval of V50 (the bracket itself for `bracket`).
    pub v50_interval: (f64, f64),
    pub v10: f64,
    pub v90: f64,
    /// β₀, β₁ in P = F(β₀ + β₁V) (NaN for `bracket`).
    pub beta: (f64, f64),
}

/// Why outcomes cannot be fitted.
#[derive(Debug, Clone, PartialEq)]
pub enum Unfit {
    NoPerforation,
    NoStop,
}

/// Fits P(V) to (velocity, perforated) outcomes.
pub fn fit(outcomes: &[(f64, bool)], link: Link) -> Result<Fit, Unfit> {
    let fastest_stop = outcomes
        .iter()
        .filter(|o| !o.1)
        .map(|o| o.0)
        .fold(f64::NEG_INFINITY, f64::max);
    let slowest_perf = outcomes
        .iter()
        .filter(|o| o.1)
        .map(|o| o.0)
        .fold(f64::INFINITY, f64::min);
    if !slowest_perf.is_finite() {
        return Err(Unfit::NoPerforation);
    }
    if !fastest_stop.is_finite() {
        return Err(Unfit::NoStop);
    }
    if fastest_stop <= slowest_perf {
        return Ok(Fit {
            method: "bracket",
            v50: 0.5 * (fastest_stop + slowest_perf),
            v50_interval: (fastest_stop, slowest_perf),
            v10: fastest_stop,
            v90: slowest_perf,
            beta: (f64::NAN, f64::NAN),
        });
    }
    Ok(maximum_likelihood(outcomes, link))
}

/// Fisher scoring on z = (V − c)/s, then back to V.
fn maximum_likelihood(outcomes: &[(f64, bool)], link: Link) -> Fit {
    let n = outcomes.len() as f64;
    let c = outcomes.iter().map(|o| o.0).sum::<f64>() / n;
    let s = (outcomes.iter().map(|o| (o.0 - c).powi(2)).sum::<f64>() / n)
        .sqrt()
        .max(f64::MIN_POSITIVE);
    let mut b = [0.0f64, 1.0];
    let mut info = [[0.0; 2]; 2];
    for _ in 0..200 {
        // Normal equations of the weighted least squares: I Δ = score.
        let (mut score, mut i2) = ([0.0; 2], [[0.0; 2]; 2]);
        for &(v, y) in outcomes {
            let z = (v - c) / s;
            let eta = b[0] + b[1] * z;
            let (p, f) = (link.cdf(eta).clamp(1e-300, 1.0 - 1e-16), link.pdf(eta));
            let w = f * f / (p * (1.0 - p));
            let r = (if y { 1.0 } else { 0.0 } - p) * f / (p * (1.0 - p));
            let x = [1.0, z];
            for j in 0..2 {
                score[j] += r * x[j];
                for k in 0..2 {
                    i2[j][k] += w * x[j] * x[k];
                }
            }
        }
        info = i2;
        let det = i2[0][0] * i2[1][1] - i2[0][1] * i2[1][0];
        if !(det > 0.0) {
            break;
        }
        let d = [
            (i2[1][1] * score[0] - i2[0][1] * score[1]) / det,
            (i2[0][0] * score[1] - i2[1][0] * score[0]) / det,
        ];
        b = [b[0] + d[0], b[1] + d[1]];
        if d[0].abs() + d[1].abs() < 1e-13 * (1.0 + b[0].abs() + b[1].abs()) {
            break;
        }
    }
    // Back to velocities: η = b₀ + b₁(V − c)/s = β₀ + β₁V.
    let beta1 = b[1] / s;
    let beta0 = b[0] - b[1] * c / s;
    let vq = |q: f64| c + s * (link.quantile(q) - b[0]) / b[1];
    // V50 = c − s b₀/b₁; gradient in b: (−s/b₁, s b₀/b₁²).
    let det = info[0][0] * info[1][1] - info[0][1] * info[1][0];
    let inv = [
        [info[1][1] / det, -info[0][1] / det],
        [-info[1][0] / det, info[0][0] / det],
    ];
    let g = [-s / b[1], s * b[0] / (b[1] * b[1])];
    let var =
        g[0] * (inv[0][0] * g[0] + inv[0][1] * g[1]) + g[1] * (inv[1][0] * g[0] + inv[1][1] * g[1]);
    let v50 = vq(0.5);
    let h = 1.96 * var.max(0.0).sqrt();
    Fit {
        method: link.name(),
        v50,
        v50_interval: (v50 - h, v50 + h),
        v10: vq(0.1),
        v90: vq(0.9),
        beta: (beta0, beta1),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn separated_outcomes_give_a_bracket() {
        let f = fit(
            &[(300.0, false), (310.0, false), (330.0, true)],
            Link::Logit,
        )
        .unwrap();
        assert_eq!(f.method, "bracket");
        assert_eq!((f.v50, f.v50_interval), (320.0, (310.0, 330.0)));
    }

    #[test]
    fn one_sided_outcomes_are_refused() {
        assert_eq!(
            fit(&[(300.0, false)], Link::Logit),
            Err(Unfit::NoPerforation)
        );
        assert_eq!(fit(&[(300.0, true)], Link::Probit), Err(Unfit::NoStop));
    }

    /// Symmetric overlapping outcomes about 300 m/s: V50 = 300 by symmetry.
    #[test]
    fn symmetric_overlap_centres_v50() {
        let o = [
            (280.0, false),
            (290.0, false),
            (295.0, true),
            (305.0, false),
            (310.0, true),
            (320.0, true),
        ];
        for link in [Link::Logit, Link::Probit] {
            let f = fit(&o, link).unwrap();
            assert!((f.v50 - 300.0).abs() < 1e-9, "{link:?}: {f:?}");
            assert!((f.v10 + f.v90 - 600.0).abs() < 1e-9, "{f:?}");
        }
    }
}
