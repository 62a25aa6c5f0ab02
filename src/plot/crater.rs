//! The backing clay's crater (`weft-plot crater`), from `bfs.parquet` (weft-simulate of a
//! model with clay): its depth on the shot's axis against time, or its profile at chosen
//! times (the clay's surface height against the distance from the axis, where the points
//! are then: the clay flows outwards), one series per run and time; optionally the
//! armour test's limit on the back-face signature as a line.

use std::path::{Path, PathBuf};

use super::chart::{label, Chart, Series, Style};
use crate::error::{Result, WeftError};
use crate::table::Table;

/// What to draw of each crater.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum CraterKind {
    /// The depth on the axis (the rows with r0 = 0) against time.
    Depth,
    /// The surface's height (−depth) against r at each chosen time.
    Profile,
}

/// The runs to draw: their `bfs.parquet`, with legend labels.
#[derive(Debug, Clone)]
pub struct CraterFigure {
    pub bfs: Vec<PathBuf>,
    pub label: Vec<String>,
    pub kind: CraterKind,
    /// The profile's times [s] (the nearest sample of each run); empty: its last.
    pub times: Vec<f64>,
    /// A limit on the depth [m] drawn as a line (the standard's 44 mm), if any.
    pub limit: Option<f64>,
    /// Only points whose r0 is at most this [m] (the profile's extent), if given.
    pub max_radius: Option<f64>,
}

/// A crater table's rows: (t, r0, r, depth).
struct Rows {
    t: Vec<f64>,
    r0: Vec<f64>,
    r: Vec<f64>,
    depth: Vec<f64>,
}

fn read(path: &Path) -> Result<Rows> {
    let t = Table::read(path)?;
    let cols = "t, r0, r, depth";
    let rows = Rows {
        t: t.f64("t", cols)?,
        r0: t.f64("r0", cols)?,
        r: t.f64("r", cols)?,
        depth: t.f64("depth", cols)?,
    };
    if rows.t.is_empty() {
        return Err(WeftError::input("no rows")
            .in_file(path)
            .expected("a crater sampled at least once (weft-simulate of a model with clay)"));
    }
    Ok(rows)
}

/// Each flag in its range, named.
fn check(a: &CraterFigure) -> Result<()> {
    let bad = |flag: &str, v: f64, want: &str| {
        Err(WeftError::input(format!("{flag} = {v}")).expected(want.to_string()))
    };
    if let Some(l) = a.limit.filter(|l| !(*l > 0.0 && l.is_finite())) {
        return bad("--limit", l, "a depth > 0 [m] (the standard's 0.044)");
    }
    if let Some(r) = a.max_radius.filter(|r| !(*r > 0.0)) {
        return bad("--max-radius", r, "a distance > 0 [m]");
    }
    if let Some(&t) = a.times.iter().find(|t| !(**t >= 0.0 && t.is_finite())) {
        return bad("--time", t, "an output time ≥ 0 [s]");
    }
    if !a.times.is_empty() && a.kind != CraterKind::Profile {
        return Err(WeftError::input("--time with --kind depth")
            .expected("--time only with --kind profile (the depth is drawn against time)"));
    }
    Ok(())
}

pub(super) fn crater(a: &CraterFigure) -> Result<Chart> {
    check(a)?;
    let mut series = vec![];
    let mut t_end = 0.0f64;
    for (k, path) in a.bfs.iter().enumerate() {
        let name = label(&a.label, k, path.parent().unwrap_or(path));
        let rows = read(path)?;
        let n = rows.t.len();
        t_end = t_end.max(rows.t.iter().cloned().fold(0.0, f64::max));
        match a.kind {
            CraterKind::Depth => series.push(Series {
                label: name,
                points: (0..n)
                    .filter(|&i| rows.r0[i] == 0.0)
                    .map(|i| (1e6 * rows.t[i], 1e3 * rows.depth[i]))
                    .collect(),
                style: Style::Line,
                color: k,
            }),
            CraterKind::Profile => {
                let mut samples: Vec<f64> = rows.t.clone();
                samples.dedup();
                let last = samples[samples.len() - 1];
                let wanted = if a.times.is_empty() {
                    vec![last]
                } else {
                    a.times.clone()
                };
                for (j, &w) in wanted.iter().enumerate() {
                    let at = samples
                        .iter()
                        .cloned()
                        .min_by(|x, y| (x - w).abs().total_cmp(&(y - w).abs()))
                        .unwrap_or(last);
                    let within = |i: usize| a.max_radius.is_none_or(|m| rows.r0[i] <= m);
                    series.push(Series {
                        label: format!("{name}, {:.0} µs", 1e6 * at),
                        points: (0..n)
                            .filter(|&i| rows.t[i] == at && within(i))
                            .map(|i| (1e3 * rows.r[i], -1e3 * rows.depth[i]))
                            .collect(),
                        style: if j == 0 { Style::Line } else { Style::Dashed },
                        color: k,
                    });
                }
            }
        }
    }
    if let Some(l) = a.limit {
        let (points, what) = match a.kind {
            CraterKind::Depth => (vec![(0.0, 1e3 * l), (1e6 * t_end, 1e3 * l)], "limit"),
            CraterKind::Profile => {
                let r = series
                    .iter()
                    .flat_map(|s| s.points.iter().map(|p| p.0))
                    .fold(0.0, f64::max);
                (vec![(0.0, -1e3 * l), (r, -1e3 * l)], "limit (depth)")
            }
        };
        series.push(Series {
            label: format!("{what} {:.0} mm", 1e3 * l),
            points,
            style: Style::Dashed,
            color: 7,
        });
    }
    let (x_label, y_label) = match a.kind {
        CraterKind::Depth => ("t [µs]", "crater depth on the axis [mm]"),
        CraterKind::Profile => (
            "distance from the shot's axis [mm]",
            "clay surface height [mm]",
        ),
    };
    Ok(Chart {
        title: None,
        x_label: x_label.into(),
        y_label: y_label.into(),
        log_y: false,
        series,
    })
}
