//! The section of a woven patch along a line y = y₀: the yarn along x (centre line and
//! ± t/2 envelope) and the sections of the yarns across it, reference and formed.

use std::path::PathBuf;

use super::chart::{Chart, Series, Style};
use crate::error::{Result, WeftError};

/// A woven model's section along y = y₀ (reference and, for a formed model, formed).
#[derive(Debug, Clone)]
pub struct WeaveFigure {
    /// Model folder (from `weft-weave woven` or `weft-form`).
    pub model: PathBuf,
    /// The section's y [m] (a warp's centre line: a multiple of the spacing).
    pub y: f64,
    /// Part of the yarn along x, and of the yarns across it.
    pub along_part: String,
    pub across_part: String,
    /// Only x ≤ this [m] (None: all).
    pub x_max: Option<f64>,
}

/// The section's series: per state (reference, formed), the centre line, its envelope
/// and the yarns across.
pub(super) fn weave(a: &WeaveFigure) -> Result<Chart> {
    use crate::model::ElementKind;
    let m = crate::model::io::read_model(&a.model)?;
    let b = m.elements.get(&ElementKind::Quad).ok_or_else(|| {
        WeftError::input(format!(
            "`{}` has no membrane quads: not a woven patch",
            a.model.display()
        ))
    })?;
    let part = |name: &str| {
        m.parts.iter().position(|p| p.name == name).ok_or_else(|| {
            WeftError::input(format!("no part `{name}`"))
                .in_file(a.model.join("parts.parquet"))
                .expected("a part of the model (woven: warp_1, weft_1, …)")
        })
    };
    let (pa, pc) = (part(&a.along_part)?, part(&a.across_part)?);
    // Nodal thickness and part of each node (from its quads).
    let mut t = vec![0.0f64; m.num_nodes()];
    let mut of = vec![usize::MAX; m.num_nodes()];
    for e in 0..b.len() {
        for k in 0..4 {
            let n = b.nodes[4 * e + k];
            of[n] = b.part[e];
            t[n] = if b.thickness.is_empty() {
                m.parts[b.part[e]].props.thickness.unwrap_or(0.0)
            } else {
                b.thickness[4 * e + k]
            };
        }
    }
    let tol = 1e-9 + 1e-6 * a.y.abs();
    let states: Vec<(&str, Vec<[f64; 3]>, Style)> = if m.initial_displacement.is_empty() {
        vec![("", m.coords.clone(), Style::Line)]
    } else {
        let formed = m
            .coords
            .iter()
            .zip(&m.initial_displacement)
            .map(|(x, u)| [x[0] + u[0], x[1] + u[1], x[2] + u[2]])
            .collect();
        vec![
            ("reference ", m.coords.clone(), Style::Dashed),
            ("formed ", formed, Style::Line),
        ]
    };
    let xmax = a.x_max.unwrap_or(f64::INFINITY);
    let mut series = vec![];
    for (si, (name, x, style)) in states.iter().enumerate() {
        let pick = |p: usize| -> Vec<usize> {
            let mut v: Vec<usize> = (0..m.num_nodes())
                .filter(|&n| {
                    of[n] == p && (m.coords[n][1] - a.y).abs() <= tol && m.coords[n][0] <= xmax
                })
                .collect();
            v.sort_by(|i, j| m.coords[*i][0].total_cmp(&m.coords[*j][0]));
            v
        };
        let line = pick(pa);
        if line.is_empty() {
            return Err(WeftError::input(format!(
                "part `{}` has no node on y = {}",
                a.along_part, a.y
            ))
            .expected("y on a centre line or node row of that part (a multiple of the spacing)")
            .into());
        }
        let mk =
            |f: &dyn Fn(usize) -> f64| line.iter().map(|&n| (1e3 * x[n][0], 1e6 * f(n))).collect();
        series.push(Series {
            label: format!("{name}{} centre line", a.along_part),
            points: mk(&|n| x[n][2]),
            style: *style,
            color: 2 * si,
        });
        for (sign, side) in [(1.0, "top"), (-1.0, "bottom")] {
            series.push(Series {
                label: format!("{name}{} {side} (± t/2)", a.along_part),
                points: mk(&|n| x[n][2] + sign * 0.5 * t[n]),
                style: Style::Dashed,
                color: 2 * si,
            });
        }
        // The yarns across: each node row at y₀ as its section's top and bottom points.
        let across = pick(pc);
        let mut pts = vec![];
        for &n in &across {
            pts.push((1e3 * x[n][0], 1e6 * (x[n][2] + 0.5 * t[n])));
            pts.push((1e3 * x[n][0], 1e6 * (x[n][2] - 0.5 * t[n])));
        }
        series.push(Series {
            label: format!("{name}{} sections (± t/2)", a.across_part),
            points: pts,
            style: Style::Points,
            color: 2 * si + 1,
        });
    }
    Ok(Chart {
        title: None,
        x_label: "x [mm]".into(),
        y_label: "z [µm]".into(),
        log_y: false,
        series,
    })
}
