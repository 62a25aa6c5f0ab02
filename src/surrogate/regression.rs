//! The regression surrogate: least squares on the monomials of total degree ≤ p of the
//! scaled inputs, solved by nalgebra's SVD, p chosen by k-fold cross-validation.

use nalgebra::DMatrix;
use serde::{Deserialize, Serialize};

use super::numerics::{permutation, sq_err};
use crate::error::{Result, WeftError};

/// A fitted polynomial: per output, coefficients of `exponents` (normalised units).
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct Regression {
    pub degree: usize,
    /// Exponents of each monomial, one per input.
    pub exponents: Vec<Vec<u32>>,
    /// `coefficients[o][k]`: output o, monomial k.
    pub coefficients: Vec<Vec<f64>>,
    /// Cross-validated MSE of each degree tried (index = degree).
    pub cv_mse: Vec<f64>,
}

/// Monomials of total degree ≤ p in d variables, by degree then lexicographically.
pub fn monomials(d: usize, p: usize) -> Vec<Vec<u32>> {
    fn rec(d: usize, left: u32, cur: &mut Vec<u32>, out: &mut Vec<Vec<u32>>) {
        if cur.len() == d {
            out.push(cur.clone());
            return;
        }
        for e in (0..=left).rev() {
            cur.push(e);
            rec(d, left - e, cur, out);
            cur.pop();
        }
    }
    let mut out = vec![];
    for deg in 0..=p as u32 {
        let mut all = vec![];
        rec(d, deg, &mut vec![], &mut all);
        all.retain(|e| e.iter().sum::<u32>() == deg);
        out.extend(all);
    }
    out
}

fn basis(u: &[f64], exps: &[Vec<u32>]) -> Vec<f64> {
    exps.iter()
        .map(|e| e.iter().zip(u).map(|(&k, &x)| x.powi(k as i32)).product())
        .collect()
}

/// Least-squares coefficients (one column per output) of `exps` on rows `u`.
fn lsq(u: &[Vec<f64>], y: &[Vec<f64>], exps: &[Vec<u32>]) -> Vec<Vec<f64>> {
    let a = DMatrix::from_fn(u.len(), exps.len(), |r, k| basis(&u[r], &exps[k..k + 1])[0]);
    let b = DMatrix::from_fn(u.len(), y[0].len(), |r, o| y[r][o]);
    let svd = a.svd(true, true);
    let x = svd
        .solve(&b, 1e-12 * svd.singular_values.max())
        .expect("SVD with both factors");
    (0..y[0].len())
        .map(|o| (0..exps.len()).map(|k| x[(k, o)]).collect())
        .collect()
}

impl Regression {
    pub fn predict(&self, u: &[f64]) -> Vec<f64> {
        let phi = basis(u, &self.exponents);
        self.coefficients
            .iter()
            .map(|c| c.iter().zip(&phi).map(|(a, b)| a * b).sum())
            .collect()
    }
}

/// Fit the regression: the degree of least k-fold CV MSE (the lowest within 1e-9 of it
/// in normalised units, so that an exact fit picks its own degree), refitted on all rows.
pub fn fit_regression(
    u: &[Vec<f64>],
    y: &[Vec<f64>],
    max_degree: usize,
    folds: usize,
    seed: u64,
) -> Result<Regression> {
    let n = u.len();
    let d = u[0].len();
    let order = permutation(n, seed ^ 0x5eed_f01d);
    let k = folds.min(n).max(2);
    let mut cv = vec![];
    for p in 0..=max_degree {
        let exps = monomials(d, p);
        // Every fold's training rows must determine the polynomial.
        if n - n.div_ceil(k) < exps.len() {
            break;
        }
        let mut se = 0.0;
        for f in 0..k {
            let test: Vec<usize> = (0..n).filter(|i| i % k == f).map(|i| order[i]).collect();
            let train: Vec<usize> = (0..n).filter(|i| i % k != f).map(|i| order[i]).collect();
            let c = lsq(
                &train.iter().map(|&i| u[i].clone()).collect::<Vec<_>>(),
                &train.iter().map(|&i| y[i].clone()).collect::<Vec<_>>(),
                &exps,
            );
            let r = Regression {
                degree: p,
                exponents: exps.clone(),
                coefficients: c,
                cv_mse: vec![],
            };
            for &i in &test {
                se += sq_err(&r.predict(&u[i]), &y[i]);
            }
        }
        cv.push(se / (n * y[0].len()) as f64);
    }
    if cv.is_empty() {
        return Err(WeftError::input(format!(
            "{n} training and validation rows cannot determine even a constant by {k}-fold cross-validation"
        ))
        .expected("at least 2 rows")
        .hint("add rows (a larger sweep), or lower --validation/--test fractions"));
    }
    let best = cv.iter().copied().fold(f64::INFINITY, f64::min);
    let degree = cv
        .iter()
        .position(|&v| v <= best + 1e-9)
        .expect("a minimum");
    let exponents = monomials(d, degree);
    let coefficients = lsq(u, y, &exponents);
    Ok(Regression {
        degree,
        exponents,
        coefficients,
        cv_mse: cv,
    })
}
