//! The armour test's figure (`weft-plot armour`), from `armour_test.parquet`
//! (`weft-ballistic armour-test`): the back-face signature of each shot against the
//! pack's areal density, one series per level of the stopped shots, and the perforated
//! shots apart, drawn above the limit ([`PERFORATED_AT`]; a perforated pack fails
//! whatever its crater, which is then the bullet's own hole, not a signature), and the
//! standard's 44 mm limit as a line.

use std::path::PathBuf;

use super::chart::{Chart, Series, Style};
use crate::ballistic::nij::BFS_LIMIT;
use crate::error::{Result, WeftError};
use crate::table::Table;

/// Where a perforated shot is drawn, as a multiple of the limit, per level (IIA, II):
/// above it, apart from every signature a stopped shot could pass with, and apart from
/// each other.
pub const PERFORATED_AT: [f64; 2] = [1.1, 1.2];

/// The table to draw.
#[derive(Debug, Clone)]
pub struct ArmourFigure {
    pub table: PathBuf,
}

pub(super) fn armour(a: &ArmourFigure) -> Result<Chart> {
    let t = Table::read(&a.table)?;
    let cols = "areal_density, level, perforated, bfs";
    let density = t.f64_opt("areal_density")?.ok_or_else(|| {
        WeftError::input("no `areal_density`")
            .in_file(&a.table)
            .in_column("areal_density")
            .expected(format!("an armour_test.parquet ({cols})"))
            .hint("weft-ballistic armour-test --run … --out …")
    })?;
    let level = t.str_opt("level")?.unwrap_or_default();
    let perforated = t.bool("perforated", cols)?;
    let bfs = t.f64("bfs", cols)?;
    let mut series = vec![];
    let mut x_max = 0.0f64;
    for (k, name) in ["IIA", "II"].iter().enumerate() {
        let point = |i: usize| {
            let y = if perforated[i] {
                PERFORATED_AT[k] * BFS_LIMIT
            } else {
                bfs[i]
            };
            density[i].map(|d| (d, 1e3 * y))
        };
        let of = |i: &usize| level.get(*i).cloned().flatten().as_deref() == Some(*name);
        for (perf, what, style) in [
            (false, "stopped", Style::LinePoints),
            (true, "perforated (drawn above the limit)", Style::Points),
        ] {
            let points: Vec<(f64, f64)> = (0..bfs.len())
                .filter(|i| of(i) && perforated[*i] == perf)
                .filter_map(point)
                .collect();
            x_max = points.iter().map(|p| p.0).fold(x_max, f64::max);
            if !points.is_empty() {
                series.push(Series {
                    label: format!("level {name}, {what}"),
                    points,
                    style,
                    color: 2 * k + perf as usize,
                });
            }
        }
    }
    if series.is_empty() {
        return Err(
            WeftError::input("no shot at a level's velocity with an areal density")
                .in_file(&a.table)
                .expected(
                    "shots at 373 or 398 m/s (± 9.1) of runs whose summaries carry `areal_density`",
                ),
        );
    }
    series.push(Series {
        label: format!("limit {:.0} mm", 1e3 * BFS_LIMIT),
        points: vec![(0.0, 1e3 * BFS_LIMIT), (1.1 * x_max, 1e3 * BFS_LIMIT)],
        style: Style::Dashed,
        color: 7,
    });
    // The depth axis from 0 to room for the legend above the perforated shots (an
    // unlabelled series draws no legend row; a line through one point draws nothing).
    for y in [0.0, 1.6 * BFS_LIMIT] {
        series.push(Series {
            label: String::new(),
            points: vec![(0.0, 1e3 * y)],
            style: Style::Line,
            color: 7,
        });
    }
    Ok(Chart {
        title: None,
        x_label: "areal density of the fabric [kg/m²]".into(),
        y_label: "back-face signature [mm]".into(),
        log_y: false,
        series,
    })
}
