//! The figures behind `weft-plot`: charts built from the tables the stages write
//! (displacement time laws, wave speeds, per-node errors, a fit's convergence), drawn with
//! plotters as PNG or SVG (by the output's extension) with a bundled font (DejaVu Sans),
//! and written atomically (beside the target, then renamed); and colour maps of a nodal
//! quantity over the mesh ([`field`]: the paper's Fig. 4).
//!
//! Errors are `anyhow` errors: problems with the input are [`WeftError`]s inside them;
//! the file system and the drawing backend fail with their own errors under a context.

pub mod field;

use std::collections::HashMap;
use std::path::{Path, PathBuf};

use anyhow::Context as _;
use plotters::coord::Shift;
use plotters::prelude::*;

use crate::analysis::interp::interpolation;
use crate::analysis::{components, read_nodes};
use crate::error::{Result, WeftError};
use crate::model::io::read_model;
use crate::table::Table;

static FONT: &[u8] = include_bytes!("../../assets/fonts/DejaVuSans.ttf");

/// One figure, as `weft-plot`'s flags give it.
#[derive(Debug, Clone)]
pub struct Config {
    pub figure: Figure,
    pub output: Output,
}

/// Which figure, with its settings.
#[derive(Debug, Clone)]
pub enum Figure {
    /// Displacement (or velocity) time laws of chosen nodes, one line style per model.
    History(HistoryFigure),
    /// Wave speed against position along the line, one series per table.
    Wavespeed(WavespeedFigure),
    /// Per-node peak relative error along the compared node set (error.parquet).
    Error(ErrorFigure),
    /// Best T against evaluations (fit_trace.parquet), one series per trace.
    Fit(FitFigure),
    /// Section of a woven patch along a line y = y₀: the centre line and envelope of
    /// the yarn along x there, and the sections of the yarns across it.
    Weave(WeaveFigure),
    /// A colour map of a nodal quantity over the mesh at one time, several models side
    /// by side on one colour scale (the paper's Fig. 4).
    Field(field::FieldFigure),
    /// Test MSE of a network search against the hidden neurons n₁, per activation
    /// (search.parquet; the paper's Fig. 6b).
    Surrogate(SurrogateFigure),
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

/// Where and how large the figure is drawn.
#[derive(Debug, Clone)]
pub struct Output {
    /// Output file: .png or .svg.
    pub out: PathBuf,
    /// Figure title (none when `None`).
    pub title: Option<String>,
    /// Width [px] (at least 200).
    pub width: u32,
    /// Height [px] (at least 150).
    pub height: u32,
}

/// Time laws of chosen nodes of several models.
#[derive(Debug, Clone)]
pub struct HistoryFigure {
    /// Model folders, one per model.
    pub model: Vec<PathBuf>,
    /// Their history.parquet, in the same order.
    pub history: Vec<PathBuf>,
    /// Legend name of each model (missing ones: the folder name).
    pub label: Vec<String>,
    /// Node ids, comma-separated (matched by position in the other models).
    pub nodes: Option<String>,
    /// A node set of the first model (at most 8 nodes), when `nodes` is `None`.
    pub set: Option<String>,
    /// Component: ux, uy, uz, vx, vy, vz.
    pub component: String,
    /// Position matching tolerance across models [m].
    pub tolerance: f64,
    /// The other models read at the chosen positions through their elements' shape
    /// functions (a coarser mesh, a membrane beyond a tied interface) instead of a node
    /// within `tolerance` (which then bounds the distance to an element).
    pub interpolate: bool,
}

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

/// What drawing a figure reports back to the binary.
#[derive(Debug, Clone)]
pub struct Report {
    /// Series drawn (empty ones included; a field figure: its panels).
    pub series: usize,
    /// A field figure's times, missing nodes and colour range.
    pub field: Option<field::FieldReport>,
}

/// Build the figure and write it to `output.out`.
pub fn run(c: &Config) -> anyhow::Result<Report> {
    plotters::style::register_font("sans-serif", FontStyle::Normal, FONT)
        .map_err(|_| anyhow::anyhow!("the bundled font could not be loaded"))?;
    let mut chart = match &c.figure {
        Figure::History(a) => history(a)?,
        Figure::Wavespeed(a) => wavespeed(a)?,
        Figure::Error(a) => error(a)?,
        Figure::Fit(a) => fit(a)?,
        Figure::Surrogate(a) => surrogate(a)?,
        Figure::Weave(a) => weave(a)?,
        Figure::Field(a) => {
            let (f, report) = field::build(a)?;
            let panels = a.model.len();
            save(&Drawing::Field(f, c.output.title.clone()), &c.output)?;
            return Ok(Report {
                series: panels,
                field: Some(report),
            });
        }
    };
    chart.title = c.output.title.clone();
    if chart.series.iter().all(|s| s.points.is_empty()) {
        return Err(WeftError::input("nothing to plot: every series is empty").into());
    }
    let series = chart.series.len();
    save(&Drawing::Chart(chart), &c.output)?;
    Ok(Report {
        series,
        field: None,
    })
}

/// What `save` draws: a line chart, or a field figure with its title.
enum Drawing {
    Chart(Chart),
    Field(field::Field, Option<String>),
}

fn draw_any<DB: DrawingBackend>(root: DrawingArea<DB, Shift>, d: &Drawing) -> anyhow::Result<()>
where
    DB::ErrorType: 'static,
{
    match d {
        Drawing::Chart(c) => draw(root, c),
        Drawing::Field(f, title) => field::draw(root, f, title.as_deref()),
    }
}

/// How a series is drawn.
#[derive(Clone, Copy, PartialEq)]
enum Style {
    Line,
    Dashed,
    Points,
    LinePoints,
}

struct Series {
    label: String,
    points: Vec<(f64, f64)>,
    style: Style,
    color: usize,
}

struct Chart {
    title: Option<String>,
    x_label: String,
    y_label: String,
    /// y drawn on a log₁₀ scale (values must be > 0).
    log_y: bool,
    series: Vec<Series>,
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

fn label(labels: &[String], k: usize, path: &Path) -> String {
    labels.get(k).cloned().unwrap_or_else(|| {
        path.file_stem()
            .map(|s| s.to_string_lossy().to_string())
            .unwrap_or_else(|| format!("{}", k + 1))
    })
}

/// Scale a quantity to a readable unit: (factor, unit prefix).
fn readable(max_abs: f64, unit: &str) -> (f64, String) {
    let steps = [(1.0, ""), (1e3, "m"), (1e6, "µ"), (1e9, "n")];
    for (f, p) in steps {
        if max_abs * f >= 1.0 || f == 1e9 {
            return (f, format!("{p}{unit}"));
        }
    }
    (1.0, unit.into())
}

fn history(a: &HistoryFigure) -> Result<Chart> {
    if a.model.len() != a.history.len() {
        return Err(WeftError::input(format!(
            "{} --model and {} --history given; expected one history per model, in the same order",
            a.model.len(),
            a.history.len()
        )));
    }
    let comp = components(&a.component)?;
    if comp.len() != 1 {
        return Err(WeftError::input(format!(
            "--component takes one component, got `{}`",
            a.component
        )));
    }
    let c = comp[0];
    // The first model fixes the nodes (by id or set); the others are matched by position.
    let first = read_model(&a.model[0])?;
    let ids: Vec<i64> = match (&a.nodes, &a.set) {
        (Some(list), _) => list
            .split(',')
            .map(|s| {
                s.trim().parse::<i64>().map_err(|e| {
                    WeftError::input(format!(
                        "--nodes: `{s}` is not a node id (expected comma-separated integers): {e}"
                    ))
                })
            })
            .collect::<Result<_>>()?,
        (None, Some(set)) => {
            let nodes = first.node_sets.get(set).ok_or_else(|| {
                WeftError::input(format!(
                    "model `{}` has no node set `{set}` (expected one of {})",
                    a.model[0].display(),
                    first
                        .node_sets
                        .keys()
                        .cloned()
                        .collect::<Vec<_>>()
                        .join(", ")
                ))
            })?;
            if nodes.len() > 8 {
                return Err(WeftError::input(format!(
                    "node set `{set}` has {} nodes; a time-law figure takes at most 8 (hint: --nodes ID,ID,...)",
                    nodes.len()
                )));
            }
            nodes.iter().map(|&i| first.node_id[i]).collect()
        }
        (None, None) => {
            return Err(WeftError::input("give --nodes ID,ID,... or --set NAME"));
        }
    };
    let index: HashMap<i64, usize> = first
        .node_id
        .iter()
        .enumerate()
        .map(|(i, &id)| (id, i))
        .collect();
    let mut positions = vec![];
    for id in &ids {
        let i = index.get(id).ok_or_else(|| {
            WeftError::input(format!(
                "--nodes: model `{}` has no node `{id}`",
                a.model[0].display()
            ))
        })?;
        positions.push(first.coords[*i]);
    }
    let mut raw: Vec<(String, Vec<(String, Vec<(f64, f64)>)>)> = vec![];
    for (k, (m, h)) in a.model.iter().zip(&a.history).enumerate() {
        let model = read_model(m)?;
        if k > 0 && a.interpolate {
            // Each chosen position read through the element of this model that holds it.
            let (read, pairs) = interpolation(&model, None, &positions, &ids, a.tolerance)
                .map_err(|e| e.context(format!("model `{}`", m.display())))?;
            // `pairs` index the nodes read, in the order read.
            let s = read_nodes(&model, h, &read, "interpolated for the figure")?;
            let lines = ids
                .iter()
                .zip(&pairs)
                .map(|(id, w)| {
                    (
                        format!("node {id}"),
                        s.t.iter()
                            .zip(&s.values)
                            .map(|(t, v)| (*t, w.iter().map(|&(j, wj)| wj * v[j][c]).sum()))
                            .collect::<Vec<_>>(),
                    )
                })
                .collect();
            raw.push((label(&a.label, k, m), lines));
            continue;
        }
        // A one-off node set of the nodes nearest the chosen positions.
        let mut chosen = vec![];
        for (id, p) in ids.iter().zip(&positions) {
            let (i, d) = model
                .coords
                .iter()
                .enumerate()
                .map(|(i, x)| {
                    (
                        i,
                        ((x[0] - p[0]).powi(2) + (x[1] - p[1]).powi(2) + (x[2] - p[2]).powi(2))
                            .sqrt(),
                    )
                })
                .min_by(|x, y| x.1.total_cmp(&y.1))
                .ok_or_else(|| WeftError::input("empty model"))?;
            if d > a.tolerance {
                return Err(WeftError::input(format!(
                    "model `{}` has no node at the position of node {id} {:?} (nearest {:.3e} m away; hint: raise --tolerance)",
                    m.display(),
                    p,
                    d
                )));
            }
            chosen.push(i);
        }
        let s = read_nodes(&model, h, &chosen, "chosen for the figure")?;
        let lines = ids
            .iter()
            .enumerate()
            .map(|(j, id)| {
                (
                    format!("node {id}"),
                    s.t.iter()
                        .zip(&s.values)
                        .map(|(t, v)| (*t, v[j][c]))
                        .collect::<Vec<_>>(),
                )
            })
            .collect();
        raw.push((label(&a.label, k, m), lines));
    }
    let tmax = raw
        .iter()
        .flat_map(|r| r.1.iter().flat_map(|l| l.1.iter().map(|p| p.0.abs())))
        .fold(0.0, f64::max);
    let ymax = raw
        .iter()
        .flat_map(|r| r.1.iter().flat_map(|l| l.1.iter().map(|p| p.1.abs())))
        .fold(0.0, f64::max);
    let (ft, ut) = readable(tmax, "s");
    let (fy, uy) = readable(ymax, if c < 3 { "m" } else { "m/s" });
    let styles = [Style::Line, Style::Dashed, Style::LinePoints, Style::Points];
    let mut series = vec![];
    for (k, (name, lines)) in raw.into_iter().enumerate() {
        for (j, (node, pts)) in lines.into_iter().enumerate() {
            series.push(Series {
                label: format!("{name}, {node}"),
                points: pts.into_iter().map(|(t, y)| (t * ft, y * fy)).collect(),
                style: styles[k % styles.len()],
                color: j,
            });
        }
    }
    Ok(Chart {
        title: None,
        x_label: format!("t [{ut}]"),
        y_label: format!("{} [{uy}]", a.component),
        log_y: false,
        series,
    })
}

fn wavespeed(a: &WavespeedFigure) -> Result<Chart> {
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

fn error(a: &ErrorFigure) -> Result<Chart> {
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

fn weave(a: &WeaveFigure) -> Result<Chart> {
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

fn fit(a: &FitFigure) -> Result<Chart> {
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

fn surrogate(a: &SurrogateFigure) -> Result<Chart> {
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

fn save(chart: &Drawing, c: &Output) -> anyhow::Result<()> {
    let ext = c
        .out
        .extension()
        .map(|e| e.to_string_lossy().to_lowercase())
        .unwrap_or_default();
    if c.width < 200 || c.height < 150 {
        return Err(WeftError::input(format!(
            "--width {} --height {}: expected at least 200 × 150 pixels",
            c.width, c.height
        ))
        .into());
    }
    if !matches!(ext.as_str(), "png" | "svg") {
        // Before any folder is made: a refusal leaves nothing behind.
        return Err(WeftError::input(format!(
            "--out `{}`: unknown figure format `{ext}` (expected a .png or .svg file name)",
            c.out.display()
        ))
        .into());
    }
    if let Some(dir) = c.out.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir)
            .with_context(|| format!("cannot create `{}`", dir.display()))?;
    }
    // Written beside the target, then renamed: an interrupted run leaves no half figure.
    let name = c
        .out
        .file_name()
        .ok_or_else(|| WeftError::input("--out has no file name"))?
        .to_string_lossy()
        .to_string();
    let tmp = c
        .out
        .with_file_name(format!(".{name}.tmp-{}.{ext}", std::process::id()));
    let size = (c.width, c.height);
    let r = match ext.as_str() {
        "png" => draw_any(BitMapBackend::new(&tmp, size).into_drawing_area(), chart),
        "svg" => draw_any(SVGBackend::new(&tmp, size).into_drawing_area(), chart),
        other => {
            return Err(WeftError::input(format!(
                "--out `{}`: unknown figure format `{other}` (expected a .png or .svg file name)",
                c.out.display()
            ))
            .into())
        }
    };
    if let Err(e) = r {
        let _ = std::fs::remove_file(&tmp);
        return Err(e);
    }
    std::fs::rename(&tmp, &c.out)
        .with_context(|| format!("cannot move the figure to `{}`", c.out.display()))?;
    Ok(())
}

fn draw<DB: DrawingBackend>(root: DrawingArea<DB, Shift>, c: &Chart) -> anyhow::Result<()>
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
        anno.label(&s.label).legend(move |(x, y)| match st {
            Style::Points => Circle::new((x + 10, y), 3, color.filled()).into_dyn(),
            Style::Dashed => PathElement::new(vec![(x, y), (x + 8, y)], style).into_dyn(),
            _ => PathElement::new(vec![(x, y), (x + 20, y)], style).into_dyn(),
        });
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
fn tick(v: f64) -> String {
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::generate::grid::rectangle;
    use crate::model::io::write_model;
    use crate::model::{ElementKind, Model, PartProps};
    use crate::table::{batch, write_table, Col, Provenance};

    /// A square [0, 1]² of `n` × `n` quads, node ids from 1, and its history.parquet with
    /// u_x(t, x, y) = t·(x + 2y) at t = 0, 1, 2 (the other components 0).
    fn square(dir: &Path, n: usize) -> (PathBuf, PathBuf) {
        let mut m = Model::default();
        let (nodes, elems) = rectangle(n, n, 1.0, 1.0, ElementKind::Quad);
        for (i, x) in nodes.iter().enumerate() {
            m.add_node(i as i64 + 1, *x);
        }
        let part = m.add_part(
            1,
            "sheet",
            ElementKind::Quad,
            PartProps {
                youngs_modulus_1: Some(1e9),
                youngs_modulus_2: Some(1e9),
                poisson_ratio_12: Some(0.3),
                shear_modulus_12: Some(4e8),
                thickness: Some(1e-3),
                density: Some(1e3),
                ..Default::default()
            },
        );
        for (e, ns) in elems.iter().enumerate() {
            m.add_element(e as i64 + 1, part, ns);
        }
        let prov = Provenance::new("test", serde_json::json!({}));
        let folder = dir.join(format!("m{n}"));
        write_model(&m, &folder, &prov).unwrap();
        let (mut t, mut id, mut ux) = (vec![], vec![], vec![]);
        for k in 0..3 {
            for (i, x) in nodes.iter().enumerate() {
                t.push(k as f64);
                id.push(i as i64 + 1);
                ux.push(k as f64 * (x[0] + 2.0 * x[1]));
            }
        }
        let zero = vec![0.0; t.len()];
        let h = dir.join(format!("h{n}.parquet"));
        let b = batch(vec![
            Col::F64("t", t),
            Col::I64("node_id", id),
            Col::F64("ux", ux),
            Col::F64("uy", zero.clone()),
            Col::F64("uz", zero.clone()),
            Col::F64("vx", zero.clone()),
            Col::F64("vy", zero.clone()),
            Col::F64("vz", zero),
        ]);
        write_table(&h, &b, &prov).unwrap();
        (folder, h)
    }

    /// `--interpolate` reads a coarser mesh at the fine nodes through its bilinear shape
    /// functions, which reproduce a field linear in x and y exactly (the patch test of
    /// the bilinear quad, e.g. Zienkiewicz & Taylor, *The Finite Element Method*, vol. 1,
    /// §9.4): the coarse model's lines equal the fine model's at nodes the coarse mesh
    /// does not have, to round-off. Without it, those positions have no coarse node.
    #[test]
    fn interpolated_lines_reproduce_a_linear_field() {
        let dir = tempfile::tempdir().unwrap();
        let (fine, hf) = square(dir.path(), 4);
        let (coarse, hc) = square(dir.path(), 2);
        // Fine nodes 2 (0.25, 0), 7 (0.25, 0.25) and 13 (0.5, 0.5): only the last is a
        // coarse node; given in this order so that the coarse nodes read are not in
        // the order of the chosen positions (the pairing indexes the nodes read).
        let mut fig = HistoryFigure {
            model: vec![fine, coarse],
            history: vec![hf, hc],
            label: vec!["fine".into(), "coarse".into()],
            nodes: Some("13,7,2".into()),
            set: None,
            component: "ux".into(),
            tolerance: 1e-9,
            interpolate: true,
        };
        let chart = history(&fig).unwrap();
        assert_eq!(chart.series.len(), 6);
        for j in 0..3 {
            let (f, c) = (&chart.series[j], &chart.series[3 + j]);
            assert_eq!(f.label.split(", ").nth(1), c.label.split(", ").nth(1));
            assert_eq!(f.points.len(), 3);
            for (p, q) in f.points.iter().zip(&c.points) {
                assert_eq!(p.0, q.0);
                // Measured: 0 (the weights are exact binary fractions here).
                assert!(
                    (p.1 - q.1).abs() <= 1e-12 * p.1.abs().max(1.0),
                    "{p:?} vs {q:?}"
                );
            }
        }
        // The fine lines themselves: t·(x + 2y) at t = 2 for node 7 (0.25, 0.25): 1.5,
        // scaled by the same unit factor as the others (max |u| = 3 m: factor 1).
        assert!((chart.series[1].points[2].1 - 1.5).abs() < 1e-12);
        fig.interpolate = false;
        let e = match history(&fig) {
            Ok(_) => panic!("positions without a coarse node were read"),
            Err(e) => e.to_string(),
        };
        assert!(e.contains("no node at the position of node 7"), "{e}");
    }
}
