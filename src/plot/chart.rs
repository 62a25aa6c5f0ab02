//! The line chart every figure but the field map is: series of points drawn as lines,
//! dashes or dots on linear or log axes, with a legend; and the number formats the
//! figures share.

use std::path::Path;

use plotters::coord::Shift;
use plotters::prelude::*;

/// How a series is drawn.
#[derive(Clone, Copy, PartialEq)]
pub(super) enum Style {
    Line,
    Dashed,
    Points,
    LinePoints,
}

/// One series of a chart: its legend, points, style and palette colour.
pub(super) struct Series {
    pub(super) label: String,
    pub(super) points: Vec<(f64, f64)>,
    pub(super) style: Style,
    pub(super) color: usize,
}

/// A line chart: axes' labels, the series, and the title `weft-plot` gives it.
pub(super) struct Chart {
    pub(super) title: Option<String>,
    pub(super) x_label: String,
    pub(super) y_label: String,
    /// y drawn on a log₁₀ scale (values must be > 0).
    pub(super) log_y: bool,
    pub(super) series: Vec<Series>,
}

const PALETTE: [RGBColor; 8] = [
    RGBColor(0x1f, 0x77, 0xb4),
    RGBColor(0xd6, 0x27, 0x28),
    RGBColor(0x2c, 0xa0, 0x2c),
    RGBColor(0xff, 0x7f, 0x0e),
    RGBColor(0x94, 0x67, 0xbd),
    RGBColor(0x8c, 0x56, 0x4b),
    RGBColor(0xe3, 0x77, 0xc2),
    RGBColor(0x17, 0xbe, 0xcf),
];

/// The legend name of series `k`: its label if given, else the file (or folder) stem.
pub(super) fn label(labels: &[String], k: usize, path: &Path) -> String {
    labels.get(k).cloned().unwrap_or_else(|| {
        path.file_stem()
            .map(|s| s.to_string_lossy().to_string())
            .unwrap_or_else(|| format!("{}", k + 1))
    })
}

/// Scale a quantity to a readable unit: (factor, unit prefix).
pub(super) fn readable(max_abs: f64, unit: &str) -> (f64, String) {
    let steps = [(1.0, ""), (1e3, "m"), (1e6, "µ"), (1e9, "n")];
    for (f, p) in steps {
        if max_abs * f >= 1.0 || f == 1e9 {
            return (f, format!("{p}{unit}"));
        }
    }
    (1.0, unit.into())
}

/// Draw a line chart on `root`: axes fitted to the finite points, a legend.
pub(super) fn draw<DB: DrawingBackend>(
    root: DrawingArea<DB, Shift>,
    c: &Chart,
) -> anyhow::Result<()>
where
    DB::ErrorType: 'static,
{
    let err = |e: DrawingAreaErrorKind<DB::ErrorType>| anyhow::anyhow!("drawing failed: {e:?}");
    root.fill(&WHITE).map_err(err)?;
    let ty = |y: f64| if c.log_y { y.log10() } else { y };
    let pts = c.series.iter().flat_map(|s| s.points.iter());
    let (mut x0, mut x1, mut y0, mut y1) = (f64::MAX, f64::MIN, f64::MAX, f64::MIN);
    for &(x, y) in pts {
        let y = ty(y);
        if x.is_finite() && y.is_finite() {
            x0 = x0.min(x);
            x1 = x1.max(x);
            y0 = y0.min(y);
            y1 = y1.max(y);
        }
    }
    if x1 <= x0 {
        x1 = x0 + 1.0;
    }
    if y1 <= y0 {
        let pad = if y0 == 0.0 { 1.0 } else { y0.abs() * 0.1 };
        y0 -= pad;
        y1 += pad;
    }
    let pad = 0.05 * (y1 - y0);
    let (y0, y1) = (y0 - pad, y1 + pad);
    let mut b = ChartBuilder::on(&root);
    b.margin(20).x_label_area_size(50).y_label_area_size(80);
    if let Some(t) = &c.title {
        b.caption(t, ("sans-serif", 26));
    }
    let mut ch = b.build_cartesian_2d(x0..x1, y0..y1).map_err(err)?;
    let log = c.log_y;
    ch.configure_mesh()
        .x_desc(&c.x_label)
        .y_desc(&c.y_label)
        .label_style(("sans-serif", 16))
        .axis_desc_style(("sans-serif", 18))
        .light_line_style(RGBColor(235, 235, 235))
        .y_label_formatter(&|v| {
            if log {
                // Ticks between decades (10^−2.5 …) need a second digit to tell apart.
                if (*v - v.round()).abs() < 1e-9 {
                    format!("{:.0e}", 10f64.powf(v.round()))
                } else {
                    format!("{:.1e}", 10f64.powf(*v))
                }
            } else {
                tick(*v)
            }
        })
        .x_label_formatter(&|v| tick(*v))
        .draw()
        .map_err(err)?;
    for s in &c.series {
        let color = PALETTE[s.color % PALETTE.len()];
        let data: Vec<(f64, f64)> = s
            .points
            .iter()
            .map(|&(x, y)| (x, ty(y)))
            .filter(|p| p.0.is_finite() && p.1.is_finite())
            .collect();
        let style = ShapeStyle::from(&color).stroke_width(2);
        let anno = match s.style {
            Style::Line | Style::LinePoints => ch
                .draw_series(LineSeries::new(data.clone(), style))
                .map_err(err)?,
            Style::Dashed => ch
                .draw_series(DashedLineSeries::new(data.clone(), 8, 5, style))
                .map_err(err)?,
            Style::Points => ch
                .draw_series(data.iter().map(|&p| Circle::new(p, 3, color.filled())))
                .map_err(err)?,
        };
        let st = s.style;
        // A series without a label (the second bound of an interval) has no legend row.
        if !s.label.is_empty() {
            anno.label(&s.label).legend(move |(x, y)| match st {
                Style::Points => Circle::new((x + 10, y), 3, color.filled()).into_dyn(),
                Style::Dashed => PathElement::new(vec![(x, y), (x + 8, y)], style).into_dyn(),
                _ => PathElement::new(vec![(x, y), (x + 20, y)], style).into_dyn(),
            });
        }
        if s.style == Style::LinePoints {
            ch.draw_series(data.iter().map(|&p| Circle::new(p, 3, color.filled())))
                .map_err(err)?;
        }
    }
    ch.configure_series_labels()
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .label_font(("sans-serif", 15))
        .position(SeriesLabelPosition::UpperRight)
        .draw()
        .map_err(err)?;
    root.present().map_err(err)?;
    Ok(())
}

/// A tick label: the shortest of a few significant digits, scientific when very large or
/// small.
pub(super) fn tick(v: f64) -> String {
    if v == 0.0 {
        return "0".into();
    }
    let a = v.abs();
    if !(1e-3..1e5).contains(&a) {
        return format!("{v:.2e}");
    }
    let s = format!("{v:.4}");
    let s = s.trim_end_matches('0').trim_end_matches('.');
    if s == "-0" {
        "0".into()
    } else {
        s.to_string()
    }
}
