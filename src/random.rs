//! Counter-based random numbers: reproducible draws that do not depend on the order in
//! which they are taken, nor on the thread count.
//!
//! A draw is a pure function of a seed and a key (a yarn number, an element number, a
//! bootstrap replicate): u = H(seed, key) with H the SplitMix64 finaliser applied twice
//! (Steele, Lea & Flood, *Fast splittable pseudorandom number generators*, OOPSLA 2014;
//! the finaliser is Stafford's "Mix13"). So a model generated with a seed gives every
//! element the same strength whether its yarns are visited in one order or another, and
//! a set of seeds gives independent samples.
//!
//! Weibull strengths with the weakest-link length effect (Weibull 1951; for yarns,
//! e.g. the gauge-length series of Kevlar 49 yarns at ICF13, 2013, paper 389): the
//! probability that a length L fails at or below strain ε is
//! P_f = 1 − exp(−(L/L₀)(ε/ε₀)^m), so a draw is ε = ε₀ (L₀/L)^{1/m} (−ln(1 − u))^{1/m}.

/// SplitMix64's increment (2⁶⁴/φ) and finaliser.
const GOLDEN: u64 = 0x9E37_79B9_7F4A_7C15;

#[inline]
fn mix(mut z: u64) -> u64 {
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

/// A 64-bit hash of (seed, key): two rounds of SplitMix64's finaliser.
#[inline]
pub fn hash(seed: u64, key: u64) -> u64 {
    mix(mix(seed.wrapping_add(GOLDEN)) ^ key.wrapping_mul(GOLDEN).wrapping_add(GOLDEN))
}

/// A uniform draw in the open interval (0, 1) for (seed, key): the top 53 bits, offset
/// by half a unit so that neither 0 nor 1 can come out.
///
/// ```
/// let u = weft::random::uniform(7, 3);
/// assert!(u > 0.0 && u < 1.0);
/// assert_eq!(u, weft::random::uniform(7, 3)); // a function of (seed, key) alone
/// assert_ne!(u, weft::random::uniform(8, 3));
/// ```
#[inline]
pub fn uniform(seed: u64, key: u64) -> f64 {
    ((hash(seed, key) >> 11) as f64 + 0.5) * (1.0 / (1u64 << 53) as f64)
}

/// A Weibull draw of modulus `m` and scale `scale` at the gauge length `gauge` for a
/// piece of length `length`: scale (gauge/length)^{1/m} (−ln(1 − u))^{1/m}.
///
/// ```
/// // The median of a Weibull law is scale (ln 2)^{1/m}; u = 1/2 gives it.
/// let e = weft::random::weibull(0.5, 10.0, 0.03, 1.0, 1.0);
/// assert!((e - 0.03 * 2f64.ln().powf(0.1)).abs() < 1e-15);
/// ```
#[inline]
pub fn weibull(u: f64, m: f64, scale: f64, gauge: f64, length: f64) -> f64 {
    scale * (gauge / length).powf(1.0 / m) * (-(1.0 - u).ln()).powf(1.0 / m)
}

/// A sequential stream of uniform draws from one seed: draw k is `uniform(seed, k)`.
#[derive(Debug, Clone)]
pub struct Stream {
    seed: u64,
    k: u64,
}

impl Stream {
    pub fn new(seed: u64) -> Stream {
        Stream { seed, k: 0 }
    }
    /// The next uniform draw in (0, 1).
    pub fn next_uniform(&mut self) -> f64 {
        let u = uniform(self.seed, self.k);
        self.k += 1;
        u
    }
    /// The next index in 0..n (n > 0).
    pub fn next_index(&mut self, n: usize) -> usize {
        ((self.next_uniform() * n as f64) as usize).min(n - 1)
    }
    /// The next standard normal draw (Box–Muller, the cosine branch).
    pub fn next_normal(&mut self) -> f64 {
        let (u1, u2) = (self.next_uniform(), self.next_uniform());
        (-2.0 * u1.ln()).sqrt() * (std::f64::consts::TAU * u2).cos()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Uniformity: the mean and variance of 10⁵ draws against 1/2 and 1/12, within
    /// four standard errors (σ/√n: 9·10⁻⁴ for the mean, 2.1·10⁻⁴ for the variance).
    #[test]
    fn uniform_moments() {
        let n = 100_000;
        let u: Vec<f64> = (0..n).map(|k| uniform(42, k)).collect();
        let mean = u.iter().sum::<f64>() / n as f64;
        let var = u.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / n as f64;
        assert!((mean - 0.5).abs() < 4.0 * (1.0 / 12.0f64).sqrt() / (n as f64).sqrt());
        // Var of (x − ½)² is 1/180: standard error of the variance √(1/180/n).
        assert!((var - 1.0 / 12.0).abs() < 4.0 * (1.0 / 180.0 / n as f64).sqrt());
    }

    /// Neighbouring keys and seeds are uncorrelated: the lag-1 correlation of 10⁵
    /// draws within four standard errors (1/√n) of 0.
    #[test]
    fn neighbouring_keys_uncorrelated() {
        let n = 100_000u64;
        let c = |f: &dyn Fn(u64) -> (f64, f64)| {
            let mut s = 0.0;
            for k in 0..n {
                let (a, b) = f(k);
                s += (a - 0.5) * (b - 0.5);
            }
            (s / n as f64) * 12.0
        };
        let lim = 4.0 / (n as f64).sqrt();
        assert!(c(&|k| (uniform(1, k), uniform(1, k + 1))).abs() < lim);
        assert!(c(&|k| (uniform(k, 5), uniform(k + 1, 5))).abs() < lim);
    }
}
