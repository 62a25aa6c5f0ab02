//! The network surrogate: the paper's two-layer network (Fig. 6a), trained by
//! Levenberg–Marquardt with early stopping on the validation rows.

use std::cell::{Cell, RefCell};

use nalgebra::{DMatrix, DVector};
use serde::{Deserialize, Serialize};

use super::numerics::{mse, Rng};

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
