//! Surrogates of a fitted dependence x → y (the paper's §4: girder parameters x = {b_g,
//! N_g} to membrane parameters y = {G_m, s_m, ρ_m}), the stage behind `weft-surrogate`:
//!
//! - **Regression:** least squares on the monomials of total degree ≤ p of the scaled
//!   inputs (log, then mapped to [−1, 1]), solved by nalgebra's SVD; p chosen by k-fold
//!   cross-validation on the training and validation rows.
//! - **Network:** the paper's two-layer network (Fig. 6a): inputs and outputs mapped to
//!   [−1, 1] (MATLAB's `mapminmax`), one hidden layer of n₁ neurons, tanh ("tansig") or
//!   logistic ("logsig"), linear output; trained by Levenberg–Marquardt (MATLAB's
//!   `trainlm`, what the paper's "back-propagation" ran; here the `levenberg-marquardt`
//!   crate) with early stopping on the validation rows (stop after 6 epochs without a
//!   better validation error, keep the best weights, as `trainlm` does); several random
//!   initialisations.
//! - **Search:** n₁ × activation × restarts, the test MSE of each (the paper's Fig. 6b);
//!   the network of smallest validation MSE is kept.
//!
//! MSEs are in normalised output units (each output mapped to [−1, 1] by its range over
//! the training rows, averaged over outputs), as the toolbox reports them.
//!
//! Deterministic: the split and every initialisation come from the seed; experiments run
//! in parallel but each is sequential and they are collected in order, so the results do
//! not depend on the thread count.

use std::cell::{Cell, RefCell};
use std::path::{Path, PathBuf};

use nalgebra::{DMatrix, DVector};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use crate::error::{Result, WeftError};
use crate::table::{batch, write_table, Col, Provenance, Table};

/// Format tag of the surrogate file.
pub const FORMAT: &str = "weft-surrogate 1";

/// Hidden-layer transfer function.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, clap::ValueEnum)]
#[serde(rename_all = "lowercase")]
pub enum Activation {
    // No doc comments: clap would print them in the value list.
    // tanh, MATLAB's "tansig".
    Tanh,
    // 1/(1 + e^(−x)), MATLAB's "logsig".
    Logistic,
}

impl Activation {
    fn f(self, x: f64) -> f64 {
        match self {
            Activation::Tanh => x.tanh(),
            Activation::Logistic => 1.0 / (1.0 + (-x).exp()),
        }
    }
    /// Derivative as a function of the value f.
    fn df(self, f: f64) -> f64 {
        match self {
            Activation::Tanh => 1.0 - f * f,
            Activation::Logistic => f * (1.0 - f),
        }
    }
    pub fn name(self) -> &'static str {
        match self {
            Activation::Tanh => "tanh",
            Activation::Logistic => "logistic",
        }
    }
}

/// How a column is scaled before it is mapped to [−1, 1].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, clap::ValueEnum)]
#[serde(rename_all = "lowercase")]
pub enum Scale {
    Log,
    Linear,
}

/// `mapminmax`: v ↦ 2(s(v) − lo)/(hi − lo) − 1, s the scale; a constant column maps to 0.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct Map {
    pub scale: Scale,
    /// Range of s(v) over the training rows.
    pub lo: f64,
    pub hi: f64,
}

impl Map {
    fn fit(v: &[f64], scale: Scale) -> Map {
        let s: Vec<f64> = v.iter().map(|&x| scaled(x, scale)).collect();
        Map {
            scale,
            lo: s.iter().copied().fold(f64::INFINITY, f64::min),
            hi: s.iter().copied().fold(f64::NEG_INFINITY, f64::max),
        }
    }
    fn fwd(&self, v: f64) -> f64 {
        let w = self.hi - self.lo;
        if w > 0.0 {
            2.0 * (scaled(v, self.scale) - self.lo) / w - 1.0
        } else {
            0.0
        }
    }
    fn inv(&self, u: f64) -> f64 {
        let s = self.lo + (u + 1.0) * 0.5 * (self.hi - self.lo);
        match self.scale {
            Scale::Log => s.exp(),
            Scale::Linear => s,
        }
    }
}

fn scaled(x: f64, s: Scale) -> f64 {
    match s {
        Scale::Log => x.ln(),
        Scale::Linear => x,
    }
}

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

/// The two-layer network: y = W₂ f(W₁ x + b₁) + b₂ in normalised units.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct Network {
    pub hidden: usize,
    pub activation: Activation,
    /// n₁ × inputs.
    pub w1: Vec<Vec<f64>>,
    pub b1: Vec<f64>,
    /// outputs × n₁.
    pub w2: Vec<Vec<f64>>,
    pub b2: Vec<f64>,
}

/// The surrogate file (JSON): columns, their maps, the training inputs' range, the
/// regression and the chosen network, and their test MSEs.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct Surrogate {
    pub format: String,
    pub inputs: Vec<String>,
    pub outputs: Vec<String>,
    pub input_maps: Vec<Map>,
    pub output_maps: Vec<Map>,
    /// Per input, [min, max] over the training table (raw units).
    pub input_range: Vec<[f64; 2]>,
    pub regression: Regression,
    pub network: Network,
    pub regression_test_mse: f64,
    pub network_test_mse: f64,
    pub network_validation_mse: f64,
    /// The stage's settings and input hashes.
    pub provenance: serde_json::Value,
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

fn sq_err(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| (x - y) * (x - y)).sum()
}

/// Mean squared error over rows and outputs.
pub fn mse(pred: &[Vec<f64>], y: &[Vec<f64>]) -> f64 {
    if y.is_empty() {
        return f64::NAN;
    }
    pred.iter().zip(y).map(|(p, t)| sq_err(p, t)).sum::<f64>() / (y.len() * y[0].len()) as f64
}

impl Network {
    fn n_params(h: usize, d: usize, m: usize) -> usize {
        h * (d + 1) + m * (h + 1)
    }
    fn from_params(h: usize, d: usize, m: usize, act: Activation, p: &[f64]) -> Network {
        let mut it = p.iter().copied();
        let mut take = |n: usize| -> Vec<f64> { (&mut it).take(n).collect() };
        let w1 = (0..h).map(|_| take(d)).collect();
        let b1 = take(h);
        let w2 = (0..m).map(|_| take(h)).collect();
        let b2 = take(m);
        Network {
            hidden: h,
            activation: act,
            w1,
            b1,
            w2,
            b2,
        }
    }
    fn hidden_values(&self, u: &[f64]) -> Vec<f64> {
        (0..self.hidden)
            .map(|j| {
                let z: f64 = self.w1[j].iter().zip(u).map(|(w, x)| w * x).sum::<f64>() + self.b1[j];
                self.activation.f(z)
            })
            .collect()
    }
    pub fn predict(&self, u: &[f64]) -> Vec<f64> {
        let a = self.hidden_values(u);
        self.w2
            .iter()
            .zip(&self.b2)
            .map(|(w, b)| w.iter().zip(&a).map(|(w, a)| w * a).sum::<f64>() + b)
            .collect()
    }
}

/// SplitMix64: the seeded stream of initial weights and of the row split.
struct Rng(u64);
impl Rng {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }
    /// Uniform in [−1, 1).
    fn sym(&mut self) -> f64 {
        (self.next() >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
    }
}

/// A seeded permutation of 0..n (Fisher–Yates).
pub fn permutation(n: usize, seed: u64) -> Vec<usize> {
    let mut r = Rng(seed);
    let mut v: Vec<usize> = (0..n).collect();
    for i in (1..n).rev() {
        let j = (r.next() % (i as u64 + 1)) as usize;
        v.swap(i, j);
    }
    v
}

/// Early-stopping settings of a training.
#[derive(Debug, Clone, Copy, Serialize)]
pub struct Training {
    /// Epochs (accepted LM steps) without a better validation MSE before stopping.
    pub max_fail: usize,
    pub max_epochs: usize,
    /// Weight of the small ridge term √λ·w added to the residuals (keeps the LM
    /// subproblem determined when the rows are fewer than the weights).
    pub ridge: f64,
}

impl Default for Training {
    fn default() -> Self {
        Training {
            max_fail: 6,
            max_epochs: 1000,
            ridge: 1e-8,
        }
    }
}

/// The result of one training.
#[derive(Debug, Clone)]
pub struct Trained {
    pub network: Network,
    pub epochs: usize,
    pub train_mse: f64,
    pub validation_mse: f64,
}

/// The LM problem: residuals (prediction − target over training rows and outputs, then
/// the ridge terms) and their analytic Jacobian; the early stopping watches the
/// validation MSE at every Jacobian evaluation (one per accepted step, an "epoch").
struct Lm<'a> {
    h: usize,
    act: Activation,
    train: (&'a [Vec<f64>], &'a [Vec<f64>]),
    val: (&'a [Vec<f64>], &'a [Vec<f64>]),
    t: Training,
    p: DVector<f64>,
    epochs: Cell<usize>,
    fails: Cell<usize>,
    best: RefCell<(f64, Vec<f64>)>,
}

impl Lm<'_> {
    fn net(&self) -> Network {
        let (d, m) = (self.train.0[0].len(), self.train.1[0].len());
        Network::from_params(self.h, d, m, self.act, self.p.as_slice())
    }
}

impl levenberg_marquardt::LeastSquaresProblem<f64, nalgebra::Dyn, nalgebra::Dyn> for Lm<'_> {
    type ResidualStorage = nalgebra::VecStorage<f64, nalgebra::Dyn, nalgebra::U1>;
    type JacobianStorage = nalgebra::VecStorage<f64, nalgebra::Dyn, nalgebra::Dyn>;
    type ParameterStorage = nalgebra::VecStorage<f64, nalgebra::Dyn, nalgebra::U1>;

    fn set_params(&mut self, x: &DVector<f64>) {
        self.p.copy_from(x);
    }
    fn params(&self) -> DVector<f64> {
        self.p.clone()
    }
    fn residuals(&self) -> Option<DVector<f64>> {
        let net = self.net();
        let (u, y) = self.train;
        let m = y[0].len();
        let np = self.p.len();
        let mut r = DVector::zeros(u.len() * m + np);
        for (i, (x, t)) in u.iter().zip(y).enumerate() {
            let o = net.predict(x);
            for k in 0..m {
                r[i * m + k] = o[k] - t[k];
            }
        }
        let s = self.t.ridge.sqrt();
        for k in 0..np {
            r[u.len() * m + k] = s * self.p[k];
        }
        r.iter().all(|v| v.is_finite()).then_some(r)
    }
    fn jacobian(&self) -> Option<DMatrix<f64>> {
        let net = self.net();
        // Early stopping: one Jacobian per accepted step.
        let e = self.epochs.get() + 1;
        self.epochs.set(e);
        // The validation rows decide; without any, the training rows.
        let (xs, ys) = if self.val.0.is_empty() {
            (self.train.0, self.train.1)
        } else {
            (self.val.0, self.val.1)
        };
        let vmse = mse(&xs.iter().map(|x| net.predict(x)).collect::<Vec<_>>(), ys);
        {
            let mut b = self.best.borrow_mut();
            if vmse < b.0 {
                *b = (vmse, self.p.as_slice().to_vec());
                self.fails.set(0);
            } else {
                self.fails.set(self.fails.get() + 1);
            }
        }
        if self.fails.get() >= self.t.max_fail || e > self.t.max_epochs {
            return None;
        }
        let (u, y) = self.train;
        let (d, m, h) = (u[0].len(), y[0].len(), self.h);
        let np = self.p.len();
        let mut j = DMatrix::zeros(u.len() * m + np, np);
        let off_b1 = h * d;
        let off_w2 = off_b1 + h;
        let off_b2 = off_w2 + m * h;
        for (i, x) in u.iter().enumerate() {
            let a = net.hidden_values(x);
            for k in 0..m {
                let row = i * m + k;
                for jn in 0..h {
                    let g = net.w2[k][jn] * self.act.df(a[jn]);
                    for c in 0..d {
                        j[(row, jn * d + c)] = g * x[c];
                    }
                    j[(row, off_b1 + jn)] = g;
                    j[(row, off_w2 + k * h + jn)] = a[jn];
                }
                j[(row, off_b2 + k)] = 1.0;
            }
        }
        let s = self.t.ridge.sqrt();
        for k in 0..np {
            j[(u.len() * m + k, k)] = s;
        }
        Some(j)
    }
}

/// Train one network from the initialisation drawn from `seed`: weights uniform in
/// [−1, 1] scaled by 1/√fan-in (the inputs are in [−1, 1]), LM with early stopping.
pub fn train_network(
    h: usize,
    act: Activation,
    train: (&[Vec<f64>], &[Vec<f64>]),
    val: (&[Vec<f64>], &[Vec<f64>]),
    t: Training,
    seed: u64,
) -> Trained {
    let (d, m) = (train.0[0].len(), train.1[0].len());
    let np = Network::n_params(h, d, m);
    let mut rng = Rng(seed);
    let mut p0 = vec![0.0; np];
    for (k, v) in p0.iter_mut().enumerate() {
        let fan_in = if k < h * (d + 1) { d + 1 } else { h + 1 };
        *v = rng.sym() * 2.0 / (fan_in as f64).sqrt();
    }
    let lm = Lm {
        h,
        act,
        train,
        val,
        t,
        p: DVector::from_vec(p0.clone()),
        epochs: Cell::new(0),
        fails: Cell::new(0),
        best: RefCell::new((f64::INFINITY, p0)),
    };
    let (lm, _report) = levenberg_marquardt::LevenbergMarquardt::new()
        .with_patience(100 * t.max_epochs)
        .minimize(lm);
    // The final point of a run that ended by convergence has not been scored yet.
    let end = lm.net();
    let score = |n: &Network, rows: (&[Vec<f64>], &[Vec<f64>])| {
        mse(
            &rows.0.iter().map(|x| n.predict(x)).collect::<Vec<_>>(),
            rows.1,
        )
    };
    let watch = if val.0.is_empty() { train } else { val };
    let (best_v, best_p) = lm.best.borrow().clone();
    let network = if score(&end, watch) < best_v {
        end
    } else {
        Network::from_params(h, d, m, act, &best_p)
    };
    Trained {
        train_mse: score(&network, train),
        validation_mse: if val.0.is_empty() {
            f64::NAN
        } else {
            score(&network, val)
        },
        epochs: lm.epochs.get(),
        network,
    }
}

/// One experiment of the search.
#[derive(Debug, Clone)]
pub struct Experiment {
    pub hidden: usize,
    pub activation: Activation,
    pub restart: usize,
    pub seed: u64,
    pub trained: Trained,
    pub test_mse: f64,
}

/// Settings of `weft-surrogate train`.
#[derive(Debug, Clone, Serialize)]
pub struct TrainConfig {
    pub table: PathBuf,
    /// `COLUMN=VALUE`: train on the rows where the column (string or number) equals it.
    pub filter: Vec<String>,
    pub inputs: Vec<String>,
    pub outputs: Vec<String>,
    pub input_scale: Scale,
    pub output_scale: Scale,
    /// Fractions of the rows for validation and test (the rest trains).
    pub validation: f64,
    pub test: f64,
    pub hidden_min: usize,
    pub hidden_max: usize,
    pub activations: Vec<Activation>,
    pub restarts: usize,
    pub max_degree: usize,
    pub folds: usize,
    pub seed: u64,
    pub training: Training,
    /// Worker threads (0: all cores); the results do not depend on it.
    pub threads: usize,
    pub out: PathBuf,
}

/// What training reports back to the binary.
#[derive(Debug, Clone)]
pub struct TrainReport {
    pub surrogate: Surrogate,
    pub experiments: Vec<Experiment>,
    pub rows: [usize; 3],
}

fn column_list(c: &[String]) -> String {
    c.iter()
        .map(|s| format!("`{s}`"))
        .collect::<Vec<_>>()
        .join(", ")
}

/// The rows every `COLUMN=VALUE` filter keeps (a string column compared as text, a
/// numeric one as a number).
fn filter_rows(t: &Table, filters: &[String]) -> Result<Vec<bool>> {
    let mut keep = vec![true; t.num_rows()];
    for f in filters {
        let (col, val) = f.split_once('=').ok_or_else(|| {
            WeftError::input(format!("--filter `{f}`"))
                .expected("COLUMN=VALUE, e.g. match=position")
        })?;
        let (col, val) = (col.trim(), val.trim());
        let hits: Vec<bool> = match t.str(col, col) {
            Ok(v) => v.iter().map(|s| s == val).collect(),
            Err(_) => {
                let num: f64 = val.parse().map_err(|_| {
                    WeftError::input(format!("--filter `{f}`: `{val}` is not a number"))
                        .in_file(&t.path)
                        .in_column(col.to_string())
                        .expected("a number for a numeric column")
                })?;
                t.f64(col, col)?.iter().map(|&v| v == num).collect()
            }
        };
        for (k, h) in keep.iter_mut().zip(hits) {
            *k &= h;
        }
    }
    if !keep.iter().any(|&k| k) {
        return Err(WeftError::input(format!(
            "no row of the table passes --filter {}",
            filters.join(" --filter ")
        ))
        .in_file(&t.path)
        .expected("a filter some rows match"));
    }
    Ok(keep)
}

/// Read columns `names` of a table as rows; log-scaled columns must be positive.
fn read_rows(
    t: &Table,
    names: &[String],
    all: &str,
    scale: Scale,
    what: &str,
) -> Result<Vec<Vec<f64>>> {
    let cols: Vec<Vec<f64>> = names
        .iter()
        .map(|n| {
            t.f64(n, all).map_err(|e| {
                e.hint(format!(
                    "the {what} columns are {}; name them with --{what}s (a NaN usually is a failed fit upstream: drop that row)",
                    column_list(names)
                ))
            })
        })
        .collect::<Result<_>>()?;
    if scale == Scale::Log {
        for (c, col) in cols.iter().enumerate() {
            if let Some(r) = col.iter().position(|&v| v <= 0.0) {
                return Err(WeftError::input(format!(
                    "{what} `{}` is {} in row {r}, which a log scale cannot take",
                    names[c], col[r]
                ))
                .in_file(&t.path)
                .in_column(names[c].clone())
                .expected("positive values")
                .hint(format!("--{what}-scale linear")));
            }
        }
    }
    Ok((0..t.num_rows())
        .map(|r| cols.iter().map(|c| c[r]).collect())
        .collect())
}

/// Train the regression and the network search; write `surrogate.json`,
/// `search.parquet` and `split.parquet` under `out`.
pub fn train(c: &TrainConfig) -> Result<TrainReport> {
    if c.inputs.is_empty() || c.outputs.is_empty() {
        return Err(WeftError::input("no --inputs or no --outputs named")
            .expected("the input columns x and output columns y, comma-separated"));
    }
    if !(0.0..1.0).contains(&c.validation)
        || !(0.0..1.0).contains(&c.test)
        || c.validation + c.test >= 1.0
    {
        return Err(WeftError::input(format!(
            "--validation {} and --test {}: fractions of the rows",
            c.validation, c.test
        ))
        .expected("each in [0, 1) and together below 1 (the rest trains)"));
    }
    if c.hidden_min < 1 || c.hidden_max < c.hidden_min || c.restarts < 1 || c.activations.is_empty()
    {
        return Err(WeftError::input(format!(
            "--hidden {}..{}, --restarts {}, {} activations",
            c.hidden_min,
            c.hidden_max,
            c.restarts,
            c.activations.len()
        ))
        .expected("1 ≤ min ≤ max neurons, at least one restart and one activation"));
    }
    let t = Table::read(&c.table)?;
    let all = column_list(&[c.inputs.clone(), c.outputs.clone()].concat());
    let keep = filter_rows(&t, &c.filter)?;
    let pick = |v: Vec<Vec<f64>>| -> Vec<Vec<f64>> {
        v.into_iter()
            .zip(&keep)
            .filter(|p| *p.1)
            .map(|p| p.0)
            .collect()
    };
    let x = pick(read_rows(&t, &c.inputs, &all, c.input_scale, "input")?);
    let y = pick(read_rows(&t, &c.outputs, &all, c.output_scale, "output")?);
    let n = x.len();
    let n_test = (c.test * n as f64).round() as usize;
    let n_val = (c.validation * n as f64).round() as usize;
    let n_train = n.saturating_sub(n_test + n_val);
    if (c.test > 0.0 && n_test == 0) || (c.validation > 0.0 && n_val == 0) || n_train < 2 {
        return Err(WeftError::input(format!(
            "{n} rows cannot be split into {:.0} % validation and {:.0} % test rows with at least 2 to train \
             (that gives {n_train} train, {n_val} validation, {n_test} test)",
            100.0 * c.validation,
            100.0 * c.test
        ))
        .in_file(&c.table)
        .expected("at least one row in each requested part and 2 training rows")
        .hint("add rows (a larger sweep: docs/pipelines.md), or lower --validation/--test"));
    }
    let order = permutation(n, c.seed);
    let part = |range: std::ops::Range<usize>| -> Vec<usize> {
        let mut v = order[range].to_vec();
        v.sort_unstable();
        v
    };
    let (train_rows, val_rows, test_rows) = (
        part(0..n_train),
        part(n_train..n_train + n_val),
        part(n_train + n_val..n),
    );
    // Maps from the training rows.
    let input_maps: Vec<Map> = (0..c.inputs.len())
        .map(|k| {
            Map::fit(
                &train_rows.iter().map(|&r| x[r][k]).collect::<Vec<_>>(),
                c.input_scale,
            )
        })
        .collect();
    let output_maps: Vec<Map> = (0..c.outputs.len())
        .map(|k| {
            Map::fit(
                &train_rows.iter().map(|&r| y[r][k]).collect::<Vec<_>>(),
                c.output_scale,
            )
        })
        .collect();
    let u: Vec<Vec<f64>> = x
        .iter()
        .map(|r| r.iter().zip(&input_maps).map(|(v, m)| m.fwd(*v)).collect())
        .collect();
    let v: Vec<Vec<f64>> = y
        .iter()
        .map(|r| r.iter().zip(&output_maps).map(|(v, m)| m.fwd(*v)).collect())
        .collect();
    let sel = |rows: &[usize], a: &[Vec<f64>]| -> Vec<Vec<f64>> {
        rows.iter().map(|&r| a[r].clone()).collect()
    };
    let (ut, vt) = (sel(&train_rows, &u), sel(&train_rows, &v));
    let (uv, vv) = (sel(&val_rows, &u), sel(&val_rows, &v));
    let (us, vs) = (sel(&test_rows, &u), sel(&test_rows, &v));

    // Regression: cross-validated on the training and validation rows together.
    let mut tv_rows = [train_rows.clone(), val_rows.clone()].concat();
    tv_rows.sort_unstable();
    let regression = fit_regression(
        &sel(&tv_rows, &u),
        &sel(&tv_rows, &v),
        c.max_degree,
        c.folds,
        c.seed,
    )?;
    let reg_test = mse(
        &us.iter().map(|r| regression.predict(r)).collect::<Vec<_>>(),
        &vs,
    );

    // The network search, in a fixed order; each experiment its own seed.
    let mut plan = vec![];
    for h in c.hidden_min..=c.hidden_max {
        for &a in &c.activations {
            for r in 0..c.restarts {
                let s = c
                    .seed
                    .wrapping_mul(0x100_0000_01b3)
                    .wrapping_add((h as u64) << 32 | (a as u64) << 24 | r as u64);
                plan.push((h, a, r, s));
            }
        }
    }
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(c.threads)
        .build()
        .map_err(|e| WeftError::input(format!("cannot start the worker threads: {e}")))?;
    let experiments: Vec<Experiment> = pool.install(|| {
        plan.par_iter()
            .map(|&(h, a, r, s)| {
                let trained = train_network(h, a, (&ut, &vt), (&uv, &vv), c.training, s);
                let test_mse = mse(
                    &us.iter()
                        .map(|x| trained.network.predict(x))
                        .collect::<Vec<_>>(),
                    &vs,
                );
                Experiment {
                    hidden: h,
                    activation: a,
                    restart: r,
                    seed: s,
                    trained,
                    test_mse,
                }
            })
            .collect()
    });
    // Chosen by validation MSE (training MSE without validation rows); the first wins ties.
    let key = |e: &Experiment| {
        if e.trained.validation_mse.is_nan() {
            e.trained.train_mse
        } else {
            e.trained.validation_mse
        }
    };
    let best = experiments
        .iter()
        .fold(None::<&Experiment>, |b, e| match b {
            Some(b) if key(b) <= key(e) => Some(b),
            _ => Some(e),
        })
        .expect("at least one experiment");

    let prov = Provenance::new(
        "surrogate",
        serde_json::to_value(c).expect("config serialises"),
    )
    .with_input(&c.table)?;
    let input_range = (0..c.inputs.len())
        .map(|k| {
            let col = train_rows.iter().map(|&r| x[r][k]);
            [
                col.clone().fold(f64::INFINITY, f64::min),
                col.fold(f64::NEG_INFINITY, f64::max),
            ]
        })
        .collect();
    let surrogate = Surrogate {
        format: FORMAT.into(),
        inputs: c.inputs.clone(),
        outputs: c.outputs.clone(),
        input_maps,
        output_maps,
        input_range,
        regression,
        network: best.trained.network.clone(),
        regression_test_mse: reg_test,
        network_test_mse: best.test_mse,
        network_validation_mse: best.trained.validation_mse,
        provenance: serde_json::to_value(&prov).expect("provenance serialises"),
    };
    std::fs::create_dir_all(&c.out).map_err(|e| WeftError::io(&c.out, e))?;
    write_json(&c.out.join("surrogate.json"), &surrogate)?;
    write_table(
        &c.out.join("search.parquet"),
        &batch(vec![
            Col::I64(
                "hidden",
                experiments.iter().map(|e| e.hidden as i64).collect(),
            ),
            Col::Str(
                "activation",
                experiments
                    .iter()
                    .map(|e| e.activation.name().to_string())
                    .collect(),
            ),
            Col::I64(
                "restart",
                experiments.iter().map(|e| e.restart as i64).collect(),
            ),
            Col::I64("seed", experiments.iter().map(|e| e.seed as i64).collect()),
            Col::I64(
                "epochs",
                experiments
                    .iter()
                    .map(|e| e.trained.epochs as i64)
                    .collect(),
            ),
            Col::F64(
                "train_mse",
                experiments.iter().map(|e| e.trained.train_mse).collect(),
            ),
            Col::OptF64(
                "validation_mse",
                experiments
                    .iter()
                    .map(|e| Some(e.trained.validation_mse).filter(|v| v.is_finite()))
                    .collect(),
            ),
            Col::OptF64(
                "test_mse",
                experiments
                    .iter()
                    .map(|e| Some(e.test_mse).filter(|v| v.is_finite()))
                    .collect(),
            ),
            Col::Bool(
                "chosen",
                experiments.iter().map(|e| std::ptr::eq(e, best)).collect(),
            ),
        ]),
        &prov,
    )?;
    // Every row: its part and both predictions.
    let split: Vec<String> = (0..n)
        .map(|r| {
            if test_rows.binary_search(&r).is_ok() {
                "test"
            } else if val_rows.binary_search(&r).is_ok() {
                "validation"
            } else {
                "train"
            }
            .to_string()
        })
        .collect();
    let s = &surrogate;
    let reg: Vec<Vec<f64>> = x.iter().map(|r| s.predict_regression(r)).collect();
    let net: Vec<Vec<f64>> = x.iter().map(|r| s.predict_network(r)).collect();
    let mut cols = vec![Col::Str("split", split)];
    for (k, name) in c.inputs.iter().enumerate() {
        cols.push(Col::F64Named(
            name.clone(),
            x.iter().map(|r| r[k]).collect(),
        ));
    }
    for (k, name) in c.outputs.iter().enumerate() {
        cols.push(Col::F64Named(
            name.clone(),
            y.iter().map(|r| r[k]).collect(),
        ));
        cols.push(Col::F64Named(
            format!("{name}_regression"),
            reg.iter().map(|r| r[k]).collect(),
        ));
        cols.push(Col::F64Named(
            format!("{name}_network"),
            net.iter().map(|r| r[k]).collect(),
        ));
    }
    write_table(&c.out.join("split.parquet"), &batch(cols), &prov)?;
    Ok(TrainReport {
        surrogate,
        rows: [train_rows.len(), val_rows.len(), test_rows.len()],
        experiments,
    })
}

fn write_json<T: Serialize>(path: &Path, v: &T) -> Result<()> {
    let text = serde_json::to_string_pretty(v).expect("serialises");
    let name = path
        .file_name()
        .expect("a file name")
        .to_string_lossy()
        .to_string();
    let tmp = path.with_file_name(format!(".{name}.tmp-{}", std::process::id()));
    std::fs::write(&tmp, text).map_err(|e| WeftError::io(&tmp, e))?;
    std::fs::rename(&tmp, path).map_err(|e| WeftError::io(path, e))
}

impl Surrogate {
    /// Read and check a surrogate file.
    pub fn read(path: &Path) -> Result<Surrogate> {
        let text = std::fs::read_to_string(path).map_err(|e| WeftError::io(path, e))?;
        let s: Surrogate = serde_json::from_str(&text).map_err(|e| {
            WeftError::input(format!("cannot read the surrogate: {e}"))
                .in_file(path)
                .expected(format!("a `{FORMAT}` file written by weft-surrogate train"))
        })?;
        if s.format != FORMAT {
            return Err(WeftError::input(format!("surrogate format `{}`", s.format))
                .in_file(path)
                .expected(format!("`{FORMAT}`")));
        }
        Ok(s)
    }
    fn normalise(&self, x: &[f64]) -> Vec<f64> {
        x.iter()
            .zip(&self.input_maps)
            .map(|(v, m)| m.fwd(*v))
            .collect()
    }
    fn denormalise(&self, v: Vec<f64>) -> Vec<f64> {
        v.iter()
            .zip(&self.output_maps)
            .map(|(v, m)| m.inv(*v))
            .collect()
    }
    /// The regression's y at x (raw units).
    pub fn predict_regression(&self, x: &[f64]) -> Vec<f64> {
        self.denormalise(self.regression.predict(&self.normalise(x)))
    }
    /// The network's y at x (raw units).
    pub fn predict_network(&self, x: &[f64]) -> Vec<f64> {
        self.denormalise(self.network.predict(&self.normalise(x)))
    }
}

/// Settings of `weft-surrogate predict`.
#[derive(Debug, Clone, Serialize)]
pub struct PredictConfig {
    pub surrogate: PathBuf,
    /// A table with the surrogate's input columns; or
    pub table: Option<PathBuf>,
    /// one x given as `NAME=VALUE` per input.
    pub x: Vec<String>,
    /// Predictions table (none: not written).
    pub out: Option<PathBuf>,
}

/// What prediction reports back: per row outside the training range, a warning.
#[derive(Debug, Clone)]
pub struct PredictReport {
    pub rows: usize,
    pub warnings: Vec<String>,
    /// Per row, per output: the predictions (raw units).
    pub regression: Vec<Vec<f64>>,
    pub network: Vec<Vec<f64>>,
    pub outputs: Vec<String>,
}

/// One x from `NAME=VALUE` entries, one per input.
fn inline_x(s: &Surrogate, entries: &[String]) -> Result<Vec<f64>> {
    let mut x = vec![None; s.inputs.len()];
    for e in entries {
        let (k, v) = e.split_once('=').ok_or_else(|| {
            WeftError::input(format!("--x `{e}`")).expected("NAME=VALUE, NAME an input")
        })?;
        let i = s.inputs.iter().position(|n| n == k.trim()).ok_or_else(|| {
            WeftError::input(format!("--x `{e}`: `{k}` is not an input of the surrogate"))
                .expected(format!("one of {}", column_list(&s.inputs)))
        })?;
        let v: f64 = v
            .trim()
            .parse()
            .ok()
            .filter(|v: &f64| v.is_finite())
            .ok_or_else(|| WeftError::input(format!("--x `{e}`: `{v}` is not a finite number")))?;
        x[i] = Some(v);
    }
    x.iter()
        .enumerate()
        .map(|(i, v)| {
            v.ok_or_else(|| {
                WeftError::input(format!("--x gives no value for input `{}`", s.inputs[i]))
                    .expected(format!("a value for each of {}", column_list(&s.inputs)))
            })
        })
        .collect()
}

/// Predict y for every row of a table of x; write `out` (the inputs, then per output
/// `NAME_regression` and `NAME_network`, and `in_range`).
pub fn predict(c: &PredictConfig) -> Result<PredictReport> {
    let s = Surrogate::read(&c.surrogate)?;
    let x = match (&c.table, c.x.is_empty()) {
        (Some(table), true) => {
            let t = Table::read(table)?;
            read_rows(
                &t,
                &s.inputs,
                &column_list(&s.inputs),
                s.input_maps[0].scale,
                "input",
            )?
        }
        (None, false) => vec![inline_x(&s, &c.x)?],
        _ => {
            return Err(WeftError::input("give either --table or --x")
                .expected("a table of inputs, or one x as NAME=VALUE,...")
                .hint(format!("the inputs are {}", column_list(&s.inputs))))
        }
    };
    let mut warnings = vec![];
    let mut in_range = vec![];
    for (r, row) in x.iter().enumerate() {
        let mut ok = true;
        for (k, v) in row.iter().enumerate() {
            let [lo, hi] = s.input_range[k];
            let slack = 1e-9 * (hi - lo).abs().max(hi.abs());
            if *v < lo - slack || *v > hi + slack {
                ok = false;
                warnings.push(format!(
                    "row {r}: input `{}` = {v} is outside the training range [{lo}, {hi}]; the prediction extrapolates",
                    s.inputs[k]
                ));
            }
        }
        in_range.push(ok);
    }
    let reg: Vec<Vec<f64>> = x.iter().map(|r| s.predict_regression(r)).collect();
    let net: Vec<Vec<f64>> = x.iter().map(|r| s.predict_network(r)).collect();
    let mut cols = vec![];
    for (k, name) in s.inputs.iter().enumerate() {
        cols.push(Col::F64Named(
            name.clone(),
            x.iter().map(|r| r[k]).collect(),
        ));
    }
    for (k, name) in s.outputs.iter().enumerate() {
        cols.push(Col::F64Named(
            format!("{name}_regression"),
            reg.iter().map(|r| r[k]).collect(),
        ));
        cols.push(Col::F64Named(
            format!("{name}_network"),
            net.iter().map(|r| r[k]).collect(),
        ));
    }
    cols.push(Col::Bool("in_range", in_range));
    if let Some(out) = &c.out {
        let mut prov = Provenance::new(
            "surrogate",
            serde_json::to_value(c).expect("config serialises"),
        )
        .with_input(&c.surrogate)?;
        if let Some(t) = &c.table {
            prov = prov.with_input(t)?;
        }
        write_table(out, &batch(cols), &prov)?;
    }
    Ok(PredictReport {
        rows: x.len(),
        warnings,
        regression: reg,
        network: net,
        outputs: s.outputs.clone(),
    })
}
