//! A deformable bullet's shape against time (`weft-plot bullet`): its length along the
//! strike direction and its diameter (twice the largest distance of its nodes from its
//! axis, [`crate::model::striker::axis_point`]: the mushroom), from the history of
//! its node set `bullet` (`weft-weave woven --projectile deformable` writes it into the
//! history), one pair of series per model.

use std::path::PathBuf;

use super::chart::{label, Chart, Series, Style};
use crate::analysis::series::read_nodes_of;
use crate::error::{Result, WeftError};
use crate::model::striker::BULLET_SET;

/// The runs to draw: model folders and their histories, with legend labels.
#[derive(Debug, Clone)]
pub struct BulletFigure {
    pub model: Vec<PathBuf>,
    pub history: Vec<PathBuf>,
    pub label: Vec<String>,
}

/// Length and diameter of a bullet at each sample: (t, length, diameter) [s, m, m].
pub fn shape(model: &std::path::Path, history: &std::path::Path) -> Result<Vec<(f64, f64, f64)>> {
    let m = crate::model::io::read_model(model)?;
    let a = m.bullet_direction().ok_or_else(|| {
        WeftError::input(format!(
            "model `{}` has no deformable bullet (node set `{BULLET_SET}`)",
            model.display()
        ))
        .hint("weft-weave woven --projectile deformable")
    })?;
    let nodes = m.bullet_nodes().unwrap_or_default();
    let s = read_nodes_of(&m, history, nodes, "of set `bullet`", &[0, 1, 2])?;
    let along = |x: &[f64; 3]| x[0] * a[0] + x[1] * a[1] + x[2] * a[2];
    let tip = crate::model::striker::axis_point(&s.x0, a);
    Ok(s.t
        .iter()
        .zip(&s.values)
        .map(|(&t, vals)| {
            let (mut lo, mut hi, mut r) = (f64::MAX, f64::MIN, 0.0f64);
            for (x0, u) in s.x0.iter().zip(vals) {
                let x = [x0[0] + u[0], x0[1] + u[1], x0[2] + u[2]];
                let d = [x[0] - tip[0], x[1] - tip[1], x[2] - tip[2]];
                let s = along(&d);
                let lat = [d[0] - s * a[0], d[1] - s * a[1], d[2] - s * a[2]];
                r = r.max((lat[0] * lat[0] + lat[1] * lat[1] + lat[2] * lat[2]).sqrt());
                lo = lo.min(s);
                hi = hi.max(s);
            }
            (t, hi - lo, 2.0 * r)
        })
        .collect())
}

pub(super) fn bullet(a: &BulletFigure) -> Result<Chart> {
    if a.model.len() != a.history.len() {
        return Err(WeftError::input(format!(
            "{} --model and {} --history",
            a.model.len(),
            a.history.len()
        ))
        .expected("one history per model, in the same order"));
    }
    let mut series = vec![];
    for (k, (m, h)) in a.model.iter().zip(&a.history).enumerate() {
        let name = label(&a.label, k, m);
        let rows = shape(m, h)?;
        for (what, style, f) in [
            (
                "length",
                Style::Line,
                (|r: &(f64, f64, f64)| r.1) as fn(&_) -> f64,
            ),
            ("diameter", Style::Dashed, |r: &(f64, f64, f64)| r.2),
        ] {
            series.push(Series {
                label: format!("{name}: {what}"),
                points: rows.iter().map(|r| (1e6 * r.0, 1e3 * f(r))).collect(),
                style,
                color: k,
            });
        }
    }
    Ok(Chart {
        title: None,
        x_label: "t [µs]".into(),
        y_label: "bullet length and diameter [mm]".into(),
        log_y: false,
        series,
    })
}
