//! `weft-surrogate predict`: y for every row of a table of x (or one x given inline),
//! with a warning for each input outside the training range.

use std::path::PathBuf;

use serde::Serialize;

use super::file::Surrogate;
use super::rows::{column_list, read_rows};
use crate::error::{Result, WeftError};
use crate::table::{batch, write_table, Col, Provenance, Table};

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
