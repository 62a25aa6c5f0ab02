//! `weft-surrogate train`: the regression and the network search on a table's rows,
//! written as `surrogate.json`, `search.parquet` and `split.parquet`.

use std::path::PathBuf;

use rayon::prelude::*;
use serde::Serialize;

use super::file::{write_json, Surrogate, FORMAT};
use super::network::{train_network, Activation, Trained, Training};
use super::numerics::{mse, permutation};
use super::regression::fit_regression;
use super::rows::{column_list, filter_rows, read_rows};
use super::scale::{Map, Scale};
use crate::error::{Result, WeftError};
use crate::table::{batch, write_table, Col, Provenance, Table};

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

/// Train the regression and the network search; write `surrogate.json`,
/// `search.parquet` and `split.parquet` under `out`.
pub fn train(c: &TrainConfig) -> Result<TrainReport> {
    check_settings(c)?;
    let (x, y) = read_xy(c)?;
    let split = Split::draw(c, x.len())?;
    let data = Normalised::fit(c, &x, &y, &split.train);
    let (train, val, test) = (
        data.part(&split.train),
        data.part(&split.validation),
        data.part(&split.test),
    );
    // Regression: cross-validated on the training and validation rows together.
    let mut tv_rows = [split.train.clone(), split.validation.clone()].concat();
    tv_rows.sort_unstable();
    let tv = data.part(&tv_rows);
    let regression = fit_regression(&tv.u, &tv.v, c.max_degree, c.folds, c.seed)?;
    let reg_test = mse(
        &test
            .u
            .iter()
            .map(|r| regression.predict(r))
            .collect::<Vec<_>>(),
        &test.v,
    );
    let experiments = search(c, &train, &val, &test)?;
    let best = choose(&experiments);
    let prov = Provenance::new(
        "surrogate",
        serde_json::to_value(c).expect("config serialises"),
    )
    .with_input(&c.table)?;
    let input_range = (0..c.inputs.len())
        .map(|k| {
            let col = split.train.iter().map(|&r| x[r][k]);
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
        input_maps: data.input_maps,
        output_maps: data.output_maps,
        input_range,
        regression,
        network: experiments[best].trained.network.clone(),
        regression_test_mse: reg_test,
        network_test_mse: experiments[best].test_mse,
        network_validation_mse: experiments[best].trained.validation_mse,
        provenance: serde_json::to_value(&prov).expect("provenance serialises"),
    };
    std::fs::create_dir_all(&c.out).map_err(|e| WeftError::io(&c.out, e))?;
    write_json(&c.out.join("surrogate.json"), &surrogate)?;
    write_search(&c.out.join("search.parquet"), &experiments, best, &prov)?;
    write_split(c, (&x, &y), &split, &surrogate, &prov)?;
    Ok(TrainReport {
        surrogate,
        rows: [split.train.len(), split.validation.len(), split.test.len()],
        experiments,
    })
}

/// The settings' own checks: columns named, fractions that leave rows to train, a
/// search with something in it.
fn check_settings(c: &TrainConfig) -> Result<()> {
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
    Ok(())
}

/// The inputs x and outputs y of the rows the filters keep (raw units).
#[allow(clippy::type_complexity)]
fn read_xy(c: &TrainConfig) -> Result<(Vec<Vec<f64>>, Vec<Vec<f64>>)> {
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
    Ok((x, y))
}

/// The rows of each part (indices of the kept rows, ascending).
struct Split {
    train: Vec<usize>,
    validation: Vec<usize>,
    test: Vec<usize>,
}

impl Split {
    /// The seeded split of `n` rows into the settings' fractions.
    fn draw(c: &TrainConfig, n: usize) -> Result<Split> {
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
        Ok(Split {
            train: part(0..n_train),
            validation: part(n_train..n_train + n_val),
            test: part(n_train + n_val..n),
        })
    }

    /// The part row `r` belongs to, as `split.parquet` names it.
    fn name(&self, r: usize) -> &'static str {
        if self.test.binary_search(&r).is_ok() {
            "test"
        } else if self.validation.binary_search(&r).is_ok() {
            "validation"
        } else {
            "train"
        }
    }
}

/// Every row mapped to [−1, 1] by maps fitted on the training rows.
struct Normalised {
    input_maps: Vec<Map>,
    output_maps: Vec<Map>,
    /// `u[r]`, `v[r]`: row r's inputs and outputs, normalised.
    u: Vec<Vec<f64>>,
    v: Vec<Vec<f64>>,
}

/// Some rows in normalised units: inputs `u`, outputs `v`.
struct Rows {
    u: Vec<Vec<f64>>,
    v: Vec<Vec<f64>>,
}

impl Normalised {
    /// Maps from the training rows, applied to every row.
    fn fit(c: &TrainConfig, x: &[Vec<f64>], y: &[Vec<f64>], train_rows: &[usize]) -> Normalised {
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
        Normalised {
            input_maps,
            output_maps,
            u,
            v,
        }
    }

    /// The rows `rows`, in that order.
    fn part(&self, rows: &[usize]) -> Rows {
        let sel =
            |a: &[Vec<f64>]| -> Vec<Vec<f64>> { rows.iter().map(|&r| a[r].clone()).collect() };
        Rows {
            u: sel(&self.u),
            v: sel(&self.v),
        }
    }
}

/// The network search, n₁ × activation × restarts in a fixed order, each experiment its
/// own seed; run in parallel, collected in order.
fn search(c: &TrainConfig, train: &Rows, val: &Rows, test: &Rows) -> Result<Vec<Experiment>> {
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
    Ok(pool.install(|| {
        plan.par_iter()
            .map(|&(h, a, r, s)| {
                let trained =
                    train_network(h, a, (&train.u, &train.v), (&val.u, &val.v), c.training, s);
                let test_mse = mse(
                    &test
                        .u
                        .iter()
                        .map(|x| trained.network.predict(x))
                        .collect::<Vec<_>>(),
                    &test.v,
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
    }))
}

/// The experiment kept: the smallest validation MSE (training MSE without validation
/// rows); the first wins ties.
fn choose(experiments: &[Experiment]) -> usize {
    let key = |e: &Experiment| {
        if e.trained.validation_mse.is_nan() {
            e.trained.train_mse
        } else {
            e.trained.validation_mse
        }
    };
    experiments
        .iter()
        .enumerate()
        .fold(None::<(usize, &Experiment)>, |b, (i, e)| match b {
            Some((j, b)) if key(b) <= key(e) => Some((j, b)),
            _ => Some((i, e)),
        })
        .expect("at least one experiment")
        .0
}

/// `search.parquet`: one row per experiment, the chosen one marked.
fn write_search(
    path: &std::path::Path,
    experiments: &[Experiment],
    best: usize,
    prov: &Provenance,
) -> Result<()> {
    write_table(
        path,
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
                (0..experiments.len()).map(|i| i == best).collect(),
            ),
        ]),
        prov,
    )
}

/// `split.parquet`: every row, its part, and both surrogates' predictions.
fn write_split(
    c: &TrainConfig,
    (x, y): (&[Vec<f64>], &[Vec<f64>]),
    split: &Split,
    s: &Surrogate,
    prov: &Provenance,
) -> Result<()> {
    let names: Vec<String> = (0..x.len()).map(|r| split.name(r).to_string()).collect();
    let reg: Vec<Vec<f64>> = x.iter().map(|r| s.predict_regression(r)).collect();
    let net: Vec<Vec<f64>> = x.iter().map(|r| s.predict_network(r)).collect();
    let mut cols = vec![Col::Str("split", names)];
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
    write_table(&c.out.join("split.parquet"), &batch(cols), prov)
}
