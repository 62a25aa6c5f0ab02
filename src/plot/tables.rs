//! Figures of the stages' tables: wave speeds along a line (wavespeeds.parquet),
//! per-node errors (error.parquet), a fit's convergence (fit_trace.parquet) and a
//! network search (search.parquet).

use std::path::PathBuf;

use super::chart::{label, Chart, Series, Style};
use crate::error::{Result, WeftError};
use crate::table::Table;

/// Wave speeds along a line, one series per wavespeeds.parquet.
#[derive(Debug, Clone)]
pub struct WavespeedFigure {
    pub table: Vec<PathBuf>,
    /// Legend names (missing ones: the file name).
    pub label: Vec<String>,
    /// Segment speeds instead of node speeds.
    pub segments: bool,
    /// Closed-form speeds drawn as dashed lines across the plot: (label, speed [m/s]).
    pub expected: Vec<(String, f64)>,
}

/// Per-node peak relative errors, one series per error.parquet.
#[derive(Debug, Clone)]
pub struct ErrorFigure {
    pub table: Vec<PathBuf>,
    /// Legend names (missing ones: the file name).
    pub label: Vec<String>,
    /// Abscissa: `distance` along the set's order, or the `x` or `y` coordinate.
    pub along: String,
}

/// A fit's convergence, one series per fit_trace.parquet.
#[derive(Debug, Clone)]
pub struct FitFigure {
    pub trace: Vec<PathBuf>,
    /// Legend names (missing ones: the file name).
    pub label: Vec<String>,
    /// Also every evaluation's T as points.
    pub all: bool,
}

/// A network search (weft-surrogate's search.parquet): every experiment's test MSE as a
/// point, the best restart per n₁ as a line, per activation.
#[derive(Debug, Clone)]
pub struct SurrogateFigure {
    pub search: PathBuf,
    /// Reference points to mark, `(label, n₁, MSE)` (the paper's 0.0333 at 11 tansig).
    pub mark: Vec<(String, f64, f64)>,
    /// The regression's test MSE, drawn as a dashed line (from surrogate.json).
    pub regression: Option<f64>,
}

/// Wave speed (node or segment) against position along the line, one series per table;
/// the expected speeds as dashed lines.
pub(super) fn wavespeed(a: &WavespeedFigure) -> Result<Chart> {
    let col = if a.segments {
        "segment_speed"
    } else {
        "node_speed"
    };
    let mut series = vec![];
    for (k, p) in a.table.iter().enumerate() {
        let t = Table::read(p)?;
        const COLS: &str = "position, node_speed, segment_speed";
        let x = t.f64("position", COLS)?;
        let v = t.f64_opt(col)?.ok_or_else(|| {
            WeftError::input(format!(
                "`{}` has no column `{col}` (expected a wavespeeds.parquet)",
                p.display()
            ))
        })?;
        let points: Vec<(f64, f64)> = x
            .iter()
            .zip(v)
            .filter_map(|(x, v)| v.map(|v| (*x, v)))
            .collect();
        series.push(Series {
            label: label(&a.label, k, p),
            points,
            style: Style::LinePoints,
            color: k,
        });
    }
    let (lo, hi) = series
        .iter()
        .flat_map(|s| s.points.iter().map(|p| p.0))
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), x| {
            (l.min(x), h.max(x))
        });
    if lo < hi {
        for (j, (name, v)) in a.expected.iter().enumerate() {
            series.push(Series {
                label: name.clone(),
                points: vec![(lo, *v), (hi, *v)],
                style: Style::Dashed,
                color: a.table.len() + j,
            });
        }
    }
    Ok(Chart {
        title: None,
        x_label: "position along the line [m]".into(),
        y_label: format!("{} [m/s]", col.replace('_', " ")),
        log_y: false,
        series,
    })
}

/// Peak relative error per node against the distance along the set, or x or y.
pub(super) fn error(a: &ErrorFigure) -> Result<Chart> {
    let mut series = vec![];
    for (k, p) in a.table.iter().enumerate() {
        let t = Table::read(p)?;
        const COLS: &str = "node_id, x, y, z, peak_relative_error";
        let e: Vec<f64> = t
            .f64_opt("peak_relative_error")?
            .ok_or_else(|| {
                WeftError::input(format!(
                    "`{}` has no column `peak_relative_error` (expected an error.parquet)",
                    p.display()
                ))
            })?
            .into_iter()
            .map(|v| v.unwrap_or(f64::NAN))
            .collect();
        let (x, y, z) = (t.f64("x", COLS)?, t.f64("y", COLS)?, t.f64("z", COLS)?);
        let s: Vec<f64> = match a.along.as_str() {
            "x" => x.clone(),
            "y" => y.clone(),
            "distance" => {
                let mut d = vec![0.0];
                for i in 1..x.len() {
                    let step = ((x[i] - x[i - 1]).powi(2)
                        + (y[i] - y[i - 1]).powi(2)
                        + (z[i] - z[i - 1]).powi(2))
                    .sqrt();
                    d.push(d[i - 1] + step);
                }
                d
            }
            other => {
                return Err(WeftError::input(format!(
                    "--along `{other}`: expected distance, x or y"
                )));
            }
        };
        series.push(Series {
            label: label(&a.label, k, p),
            points: s.into_iter().zip(e).filter(|p| p.1.is_finite()).collect(),
            style: if a.along == "distance" {
                Style::LinePoints
            } else {
                Style::Points
            },
            color: k,
        });
    }
    Ok(Chart {
        title: None,
        x_label: match a.along.as_str() {
            "distance" => "distance along the node set [m]".into(),
            c => format!("{c} [m]"),
        },
        y_label: "peak relative error".into(),
        log_y: false,
        series,
    })
}

/// Best T (and every T) against evaluations, log scale.
pub(super) fn fit(a: &FitFigure) -> Result<Chart> {
    let mut series = vec![];
    for (k, p) in a.trace.iter().enumerate() {
        let t = Table::read(p)?;
        const COLS: &str = "evaluation, T, best_T";
        let n: Vec<f64> = t
            .i64("evaluation", COLS)?
            .iter()
            .map(|&v| v as f64 + 1.0)
            .collect();
        let best = t.f64("best_T", COLS)?;
        let all = t.f64("T", COLS)?;
        let name = label(&a.label, k, p);
        if a.all {
            series.push(Series {
                label: format!("{name}: T"),
                points: n
                    .iter()
                    .zip(&all)
                    .filter(|p| *p.1 > 0.0)
                    .map(|(x, y)| (*x, *y))
                    .collect(),
                style: Style::Points,
                color: k,
            });
        }
        series.push(Series {
            label: format!("{name}: best T"),
            points: n
                .iter()
                .zip(&best)
                .filter(|p| *p.1 > 0.0)
                .map(|(x, y)| (*x, *y))
                .collect(),
            style: Style::Line,
            color: k,
        });
    }
    Ok(Chart {
        title: None,
        x_label: "evaluations".into(),
        y_label: "T".into(),
        log_y: true,
        series,
    })
}

/// Test MSE against n₁ per activation: every restart, the best restart, the regression
/// and marked reference points.
pub(super) fn surrogate(a: &SurrogateFigure) -> Result<Chart> {
    let t = Table::read(&a.search)?;
    const COLS: &str = "hidden, activation, test_mse";
    let h = t.i64("hidden", COLS)?;
    let act = t.str("activation", COLS)?;
    let mse = t.f64_opt("test_mse")?.ok_or_else(|| {
        WeftError::input("missing column `test_mse`")
            .in_file(&a.search)
            .expected(format!("columns {COLS} (weft-surrogate's search.parquet)"))
    })?;
    let mut names: Vec<String> = act.clone();
    names.dedup();
    names.sort();
    names.dedup();
    let (x_lo, x_hi) = (
        h.iter().copied().min().unwrap_or(0) as f64,
        h.iter().copied().max().unwrap_or(1) as f64,
    );
    let mut series = vec![];
    for (k, name) in names.iter().enumerate() {
        let pts: Vec<(f64, f64)> = (0..h.len())
            .filter(|&r| &act[r] == name)
            .filter_map(|r| mse[r].filter(|v| *v > 0.0).map(|v| (h[r] as f64, v)))
            .collect();
        let mut best: std::collections::BTreeMap<i64, f64> = Default::default();
        for &(x, y) in &pts {
            let e = best.entry(x as i64).or_insert(f64::INFINITY);
            *e = e.min(y);
        }
        series.push(Series {
            label: format!("{name}: each restart"),
            points: pts,
            style: Style::Points,
            color: k,
        });
        series.push(Series {
            label: format!("{name}: best restart"),
            points: best.into_iter().map(|(x, y)| (x as f64, y)).collect(),
            style: Style::Line,
            color: k,
        });
    }
    if let Some(r) = a.regression.filter(|v| *v > 0.0) {
        series.push(Series {
            label: format!("regression ({r:.3e})"),
            points: vec![(x_lo, r), (x_hi, r)],
            style: Style::Dashed,
            color: names.len() + 1,
        });
    }
    for (k, (l, x, y)) in a.mark.iter().enumerate() {
        series.push(Series {
            label: l.clone(),
            points: vec![(*x, *y)],
            style: Style::Points,
            color: names.len() + 2 + k,
        });
    }
    Ok(Chart {
        title: None,
        x_label: "hidden neurons n₁".into(),
        y_label: "test MSE (normalised outputs)".into(),
        log_y: true,
        series,
    })
}
