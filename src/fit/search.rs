//! The local searches of a fit on the unit box of its parameters' scales: COBYLA
//! (derivative-free, bounded) and a projected BFGS with central finite-difference
//! gradients evaluated in parallel.

use serde::Serialize;

/// What a local search minimises: the objective at points of the unit parameter box,
/// evaluated together (in parallel by the caller's implementation), and how many
/// evaluations it has taken so far.
pub(super) trait Unit {
    fn eval_many(&self, zs: &[Vec<f64>]) -> Vec<f64>;
    fn eval(&self, z: &[f64]) -> f64;
    fn count(&self) -> usize;
}

/// Local method.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, clap::ValueEnum)]
#[serde(rename_all = "lowercase")]
pub enum Method {
    /// COBYLA: derivative-free, bounded (Powell 1994).
    Cobyla,
    /// Projected BFGS with central finite-difference gradients.
    Gradient,
}

/// Stopping rules and the global search.
#[derive(Debug, Clone, Serialize)]
pub struct Options {
    pub method: Method,
    /// Local searches: 1 = local only; more = multistart.
    pub starts: usize,
    /// Objective evaluations per local search, at most.
    pub max_evaluations: usize,
    /// Stop when steps on the unit box are below this.
    pub xtol: f64,
    /// Stop when T changes by less than this, relatively.
    pub ftol: f64,
    /// Stop a search when T falls below this.
    pub target: f64,
    /// Initial step on the unit box (COBYLA's ρ_beg).
    pub initial_step: f64,
}

impl Default for Options {
    fn default() -> Self {
        Options {
            method: Method::Cobyla,
            starts: 1,
            max_evaluations: 200,
            xtol: 1e-6,
            ftol: 1e-10,
            target: 0.0,
            initial_step: 0.1,
        }
    }
}

pub(super) fn cobyla_search(ev: &impl Unit, z0: &[f64], opts: &Options) -> (Vec<f64>, f64, String) {
    let n = z0.len();
    let f = |z: &[f64], _: &mut ()| ev.eval(z);
    let cons: Vec<&dyn cobyla::Func<()>> = vec![];
    let stop = cobyla::StopTols {
        ftol_rel: opts.ftol,
        xtol_abs: vec![opts.xtol; n],
        ..Default::default()
    };
    // Stop on the target T through COBYLA's own `stopval`-like check: the crate has none,
    // so the evaluation budget and tolerances end the search.
    match cobyla::minimize(
        f,
        z0,
        &vec![(0.0, 1.0); n],
        &cons,
        (),
        opts.max_evaluations,
        cobyla::RhoBeg::All(opts.initial_step),
        Some(stop),
    ) {
        Ok((status, z, t)) => (z, t, format!("{status:?}")),
        Err((status, z, t)) => (z, t, format!("{status:?}")),
    }
}

/// Projected BFGS on the unit box with central-difference gradients (one-sided at a
/// bound), the 2n gradient evaluations in parallel; Armijo backtracking along the
/// projected path.
pub(super) fn gradient_search(
    ev: &impl Unit,
    z0: &[f64],
    opts: &Options,
) -> (Vec<f64>, f64, String) {
    let n = z0.len();
    let h = 1e-5;
    let grad = |z: &[f64], f: f64| -> Vec<f64> {
        let mut pts = vec![];
        for i in 0..n {
            let (mut zp, mut zm) = (z.to_vec(), z.to_vec());
            zp[i] = (z[i] + h).min(1.0);
            zm[i] = (z[i] - h).max(0.0);
            pts.push(zp);
            pts.push(zm);
        }
        let fs = ev.eval_many(&pts);
        (0..n)
            .map(|i| {
                let (zp, zm) = (pts[2 * i][i], pts[2 * i + 1][i]);
                // The centre value stands in for a side clipped to the bound.
                let fp = if zp > z[i] { fs[2 * i] } else { f };
                let fm = if zm < z[i] { fs[2 * i + 1] } else { f };
                (fp - fm) / (zp.max(z[i]) - zm.min(z[i]))
            })
            .collect()
    };
    let project = |z: &mut [f64]| z.iter_mut().for_each(|v| *v = v.clamp(0.0, 1.0));
    let mut z = z0.to_vec();
    let mut f = ev.eval(&z);
    let mut g = grad(&z, f);
    let mut hinv = nalgebra::DMatrix::<f64>::identity(n, n);
    let status = loop {
        if ev.count() >= opts.max_evaluations {
            break "MaxEvalReached".to_string();
        }
        if f <= opts.target {
            break "StopValReached".to_string();
        }
        // Variables held at a bound by the gradient are out of the step.
        let free: Vec<bool> = (0..n)
            .map(|i| !((z[i] <= 0.0 && g[i] > 0.0) || (z[i] >= 1.0 && g[i] < 0.0)))
            .collect();
        let pg: f64 = (0..n)
            .filter(|&i| free[i])
            .map(|i| g[i].abs())
            .fold(0.0, f64::max);
        if pg < 1e-12 {
            break "GradientSmall".to_string();
        }
        let gv =
            nalgebra::DVector::from_iterator(n, (0..n).map(|i| if free[i] { g[i] } else { 0.0 }));
        let mut d: Vec<f64> = (-(&hinv * &gv)).iter().copied().collect();
        for i in 0..n {
            if !free[i] {
                d[i] = 0.0;
            }
        }
        if d.iter().zip(&g).map(|(a, b)| a * b).sum::<f64>() >= 0.0 {
            hinv = nalgebra::DMatrix::identity(n, n);
            d = (0..n).map(|i| if free[i] { -g[i] } else { 0.0 }).collect();
        }
        // Keep a first step within the box's scale.
        let dmax = d.iter().map(|v| v.abs()).fold(0.0, f64::max);
        let mut alpha = if dmax > 0.5 { 0.5 / dmax } else { 1.0 };
        let mut accepted = None;
        for _ in 0..30 {
            let mut zn: Vec<f64> = z.iter().zip(&d).map(|(a, b)| a + alpha * b).collect();
            project(&mut zn);
            let dz: Vec<f64> = zn.iter().zip(&z).map(|(a, b)| a - b).collect();
            let decrease: f64 = dz.iter().zip(&g).map(|(a, b)| a * b).sum();
            if dz.iter().all(|v| v.abs() < opts.xtol * 1e-3) {
                break;
            }
            let fn_ = ev.eval(&zn);
            if fn_ <= f + 1e-4 * decrease {
                accepted = Some((zn, fn_));
                break;
            }
            alpha *= 0.5;
        }
        let Some((zn, fnew)) = accepted else {
            break "LineSearchStalled".to_string();
        };
        let step: f64 = zn
            .iter()
            .zip(&z)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        let df = (f - fnew).abs();
        let gn = grad(&zn, fnew);
        let s = nalgebra::DVector::from_iterator(n, zn.iter().zip(&z).map(|(a, b)| a - b));
        let y = nalgebra::DVector::from_iterator(n, gn.iter().zip(&g).map(|(a, b)| a - b));
        let sy = s.dot(&y);
        if sy > 1e-14 * s.norm() * y.norm() && sy > 0.0 {
            let rho = 1.0 / sy;
            let i = nalgebra::DMatrix::<f64>::identity(n, n);
            let a = &i - rho * &s * y.transpose();
            let b = &i - rho * &y * s.transpose();
            hinv = &a * &hinv * &b + rho * &s * s.transpose();
        }
        z = zn;
        f = fnew;
        g = gn;
        if step < opts.xtol {
            break "XtolReached".to_string();
        }
        if df <= opts.ftol * f.abs().max(1e-300) {
            break "FtolReached".to_string();
        }
    };
    (z, f, status)
}
