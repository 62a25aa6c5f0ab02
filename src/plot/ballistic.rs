//! Figures of a ballistic limit (`weft-ballistic`'s tables): residual against striking
//! velocity with the fitted Lambert–Jonas laws, the energy the fabric absorbed against
//! the striking velocity, the probability of perforation with its fit, and the limit
//! against the groups (layers).

use std::path::PathBuf;

use super::chart::{Chart, Series, Style};
use crate::ballistic::lambert_jonas::Law;
use crate::error::{Result, WeftError};
use crate::table::Table;

/// Which figure of a ballistic limit.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum BallisticKind {
    /// V_r against V_s, one series of points per group and its Lambert–Jonas curve.
    Residual,
    /// The energy absorbed by the fabric against V_s, per group.
    Energy,
    /// The probability of perforation against V_s: the outcomes (0 or 1) and the fit.
    Probability,
    /// V50 (with its interval) and V_bl against the grouping value (layers).
    Limit,
}

/// A ballistic figure: the two tables of `weft-ballistic` and which figure.
#[derive(Debug, Clone)]
pub struct BallisticFigure {
    pub runs: PathBuf,
    pub limit: PathBuf,
    /// The grouping column (`layers`).
    pub by: String,
    pub kind: BallisticKind,
    /// The limit figure's abscissa: the grouping value times this factor, under this
    /// label (e.g. layers × 0.1946 kg/m² per layer: the areal density).
    pub x_factor: f64,
    pub x_label: Option<String>,
}

const RUN_COLS: &str = "striking_velocity, residual_velocity, perforated, energy_absorbed";
const LIMIT_COLS: &str = "v50, v50_low, v50_high, v_bl, a, p, v50_method";

/// The runs of each group: (group, V_s, V_r, perforated, energy absorbed).
type Runs = Vec<(String, Vec<(f64, f64, bool, f64)>)>;

fn read_runs(a: &BallisticFigure) -> Result<Runs> {
    let t = Table::read(&a.runs)?;
    let g = crate::ballistic::runs::group_column(&t, &a.by)?;
    let vs = t.f64("striking_velocity", RUN_COLS)?;
    let vr = t.f64("residual_velocity", RUN_COLS)?;
    let pf = t.bool("perforated", RUN_COLS)?;
    let ea = t
        .f64_opt("energy_absorbed")?
        .unwrap_or(vec![None; vs.len()]);
    let mut out: Runs = Vec::new();
    for i in 0..vs.len() {
        let row = (vs[i], vr[i], pf[i], ea[i].unwrap_or(f64::NAN));
        match out.iter_mut().find(|(k, _)| *k == g[i]) {
            Some((_, v)) => v.push(row),
            None => out.push((g[i].clone(), vec![row])),
        }
    }
    for (_, rs) in out.iter_mut() {
        rs.sort_by(|a, b| a.0.total_cmp(&b.0));
    }
    Ok(out)
}

/// Per group of the limit table: its V50, interval, method, fitted law, and the
/// probability's (β₀, β₁) when fitted.
#[derive(Debug, Clone)]
struct LimitRow {
    group: String,
    v50: f64,
    low: f64,
    high: f64,
    method: String,
    law: Option<Law>,
    beta: Option<(f64, f64)>,
}

fn read_limits(a: &BallisticFigure) -> Result<Vec<LimitRow>> {
    let t = Table::read(&a.limit)?;
    let g = crate::ballistic::runs::group_column(&t, &a.by)?;
    let v50 = t.f64("v50", LIMIT_COLS)?;
    let lo = t.f64("v50_low", LIMIT_COLS)?;
    let hi = t.f64("v50_high", LIMIT_COLS)?;
    let method = t.str("v50_method", LIMIT_COLS)?;
    let n = g.len();
    let o = |c: &str| -> Result<Vec<Option<f64>>> { Ok(t.f64_opt(c)?.unwrap_or(vec![None; n])) };
    let (vbl, aa, pp) = (o("v_bl")?, o("a")?, o("p")?);
    let (b0, b1) = (o("probability_beta0")?, o("probability_beta1")?);
    Ok((0..n)
        .map(|i| LimitRow {
            group: g[i].clone(),
            v50: v50[i],
            low: lo[i],
            high: hi[i],
            method: method[i].clone(),
            law: match (vbl[i], aa[i], pp[i]) {
                (Some(v_bl), Some(a), Some(p)) => Some(Law { a, p, v_bl }),
                _ => None,
            },
            beta: b0[i].zip(b1[i]),
        })
        .collect())
}

/// The figure's chart.
pub(super) fn ballistic(a: &BallisticFigure) -> Result<Chart> {
    let runs = read_runs(a)?;
    let limits = read_limits(a)?;
    let by = &a.by;
    let mut series = Vec::new();
    let (x_label, y_label) = match a.kind {
        BallisticKind::Residual => {
            for (k, (g, rs)) in runs.iter().enumerate() {
                series.push(Series {
                    label: format!("{by} {g}"),
                    points: rs.iter().map(|r| (r.0, r.1)).collect(),
                    style: Style::Points,
                    color: k,
                });
                if let Some(law) = limits.iter().find(|l| l.group == *g).and_then(|l| l.law) {
                    let (v0, v1) = (0.0, rs.iter().map(|r| r.0).fold(0.0, f64::max));
                    let points = (0..=200)
                        .map(|i| {
                            let v = v0 + (v1 - v0) * i as f64 / 200.0;
                            (v, law.residual(v))
                        })
                        .collect();
                    series.push(Series {
                        label: format!("V_bl {:.0} m/s, a {:.2}, p {:.2}", law.v_bl, law.a, law.p),
                        points,
                        style: Style::Line,
                        color: k,
                    });
                }
            }
            ("striking velocity V_s [m/s]", "residual velocity V_r [m/s]")
        }
        BallisticKind::Energy => {
            for (k, (g, rs)) in runs.iter().enumerate() {
                series.push(Series {
                    label: format!("{by} {g}"),
                    points: rs.iter().map(|r| (r.0, r.3)).collect(),
                    style: Style::LinePoints,
                    color: k,
                });
            }
            (
                "striking velocity V_s [m/s]",
                "energy absorbed by the fabric [J]",
            )
        }
        BallisticKind::Probability => {
            for (k, (g, rs)) in runs.iter().enumerate() {
                series.push(Series {
                    label: format!("{by} {g}"),
                    points: rs
                        .iter()
                        .map(|r| (r.0, if r.2 { 1.0 } else { 0.0 }))
                        .collect(),
                    style: Style::Points,
                    color: k,
                });
                if let Some(l) = limits.iter().find(|l| l.group == *g) {
                    series.push(probability_curve(l, rs, k));
                }
            }
            ("striking velocity V_s [m/s]", "probability of perforation")
        }
        BallisticKind::Limit => {
            let x = |g: &str| g.parse::<f64>().ok().map(|v| v * a.x_factor);
            let pts = |f: &dyn Fn(&LimitRow) -> f64| {
                limits
                    .iter()
                    .filter_map(|l| x(&l.group).map(|g| (g, f(l))))
                    .collect::<Vec<_>>()
            };
            series.push(Series {
                label: "V50".into(),
                points: pts(&|l| l.v50),
                style: Style::LinePoints,
                color: 0,
            });
            series.push(Series {
                label: "V50 interval".into(),
                points: pts(&|l| l.low),
                style: Style::Dashed,
                color: 0,
            });
            series.push(Series {
                label: String::new(),
                points: pts(&|l| l.high),
                style: Style::Dashed,
                color: 0,
            });
            series.push(Series {
                label: "V_bl (Lambert–Jonas)".into(),
                points: pts(&|l| l.law.map_or(f64::NAN, |law| law.v_bl)),
                style: Style::Points,
                color: 1,
            });
            if series[0].points.is_empty() {
                return Err(WeftError::input(format!(
                    "`{by}` values that are not numbers: a limit figure plots V50 against them"
                ))
                .in_file(&a.limit));
            }
            (
                a.x_label.as_deref().unwrap_or(by.as_str()),
                "ballistic limit [m/s]",
            )
        }
    };
    Ok(Chart {
        title: None,
        x_label: x_label.into(),
        y_label: y_label.into(),
        log_y: false,
        series,
    })
}

/// The fitted probability of perforation of a group: F(β₀ + β₁V) (F the link's), or a
/// step at V50 for a bracket.
fn probability_curve(l: &LimitRow, rs: &[(f64, f64, bool, f64)], k: usize) -> Series {
    let (v0, v1) = rs
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), r| {
            (a.min(r.0), b.max(r.0))
        });
    let points = (0..=200)
        .map(|i| {
            let v = v0 + (v1 - v0) * i as f64 / 200.0;
            let p = match l.beta {
                Some((b0, b1)) if l.method == "probit" => {
                    0.5 * libm::erfc(-(b0 + b1 * v) / std::f64::consts::SQRT_2)
                }
                Some((b0, b1)) => 1.0 / (1.0 + (-(b0 + b1 * v)).exp()),
                None => {
                    if v < l.v50 {
                        0.0
                    } else {
                        1.0
                    }
                }
            };
            (v, p)
        })
        .collect();
    Series {
        label: format!("V50 {:.0} m/s ({})", l.v50, l.method),
        points,
        style: Style::Line,
        color: k,
    }
}
