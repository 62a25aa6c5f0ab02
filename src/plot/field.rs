//! `weft-plot field`: a colour map of one nodal quantity (uz, |u|, vx, …) over the mesh at
//! one output time, on the initial or the deformed mesh, with a colour bar — the paper's
//! Fig. 4 (z-displacement of the whole patch). Several models are drawn side by side on
//! one colour scale and one length scale, so that a reduced model and its reference can
//! be compared at a glance.
//!
//! What is drawn, seen along the view axis (top view `xy` by default):
//! - membrane faces (tri, quad), each divided into [`SUBDIVISION`]² pieces with the nodal
//!   values interpolated (bilinear on quads, linear on triangles) and each piece filled
//!   with the colour of its mean value (a flat colour per piece, no smoothing across
//!   pieces); faces are painted from the far side to the near side (painter's order by
//!   their mean depth), so the top layer of a weave hides the one below;
//! - trusses, links and beams as coloured lines (divided the same way), point masses as
//!   dots.
//!
//! Positions: the initial positions X + u₀ (the reference coordinates plus a formed
//! model's initial displacement), plus `scale`·u(t) on the deformed mesh. Colours: the
//! viridis map (perceptually uniform, readable in grey; CC0, Smith & van der Walt for
//! matplotlib 1.5) between the smallest and largest value of the nodes drawn, over all
//! models, unless a range is given.

use std::collections::HashMap;
use std::path::{Path, PathBuf};

use plotters::coord::Shift;
use plotters::prelude::*;

use super::chart::{label, readable, tick};

use crate::error::{Result, WeftError};
use crate::model::io::read_model;
use crate::model::{ElementKind, Model};
use crate::table::history::{History, COMPONENTS};

/// Each membrane face (and line element) is drawn as SUBDIVISION × SUBDIVISION pieces
/// (SUBDIVISION for a line) with interpolated values; 3 keeps a coarse mesh's colours
/// close to a smooth field while a piece's centre carries its exact interpolated value
/// (odd: the face centre is a piece centre). Meshes with more than [`MAX_PIECES`] pieces
/// at that division are drawn one piece per face.
pub const SUBDIVISION: usize = 3;
/// Above this many pieces a face is one piece (the figure would only grow, not sharpen).
pub const MAX_PIECES: usize = 400_000;

/// A colour map of a nodal quantity on one or several models at one time.
#[derive(Debug, Clone)]
pub struct FieldFigure {
    /// Model folders, one per panel.
    pub model: Vec<PathBuf>,
    /// Their history.parquet, in the same order.
    pub history: Vec<PathBuf>,
    /// Panel titles (missing ones: the folder name).
    pub label: Vec<String>,
    /// ux, uy, uz, vx, vy, vz, or u, v (magnitudes).
    pub component: String,
    /// The output time [s]: the nearest sample of each history is drawn.
    pub time: f64,
    /// Draw on the deformed mesh (X + u₀ + scale·u) rather than the initial one.
    pub deformed: bool,
    /// Displacement magnification on the deformed mesh.
    pub scale: f64,
    /// Projection plane: `xy` (seen from +z), `xz` (from −y) or `yz` (from +x).
    pub view: String,
    /// Colour range [unit of the component, SI]; None: the values' range.
    pub range: Option<(f64, f64)>,
}

/// What the field figure reports: the time drawn and nodes without a value.
#[derive(Debug, Clone)]
pub struct FieldReport {
    /// Per panel: the history sample drawn [s].
    pub times: Vec<f64>,
    /// Per panel: element nodes without a value in the history (drawn grey).
    pub missing_nodes: Vec<usize>,
    /// The colour range [SI].
    pub range: (f64, f64),
}

/// One coloured piece, in view coordinates.
struct Piece {
    pts: Vec<(f64, f64)>,
    /// Mean coordinate towards the viewer (painter's order).
    depth: f64,
    /// None: a node without a value.
    value: Option<f64>,
}

struct Panel {
    label: String,
    time: f64,
    faces: Vec<Piece>,
    lines: Vec<Piece>,
    dots: Vec<Piece>,
}

/// The figure, ready to draw.
pub(crate) struct Field {
    panels: Vec<Panel>,
    range: (f64, f64),
    /// Display factor and unit of the values and of the lengths.
    value_unit: (f64, String),
    length_unit: (f64, String),
    component: String,
    axes: (&'static str, &'static str),
    deformed: Option<f64>,
}

/// Published viridis at 0, 1/8, …, 1 (matplotlib's `_viridis_data` rows 0, 32, …, 224,
/// 255, CC0), 8-bit; linearly interpolated between them (within 1/255 of the 256-entry
/// table).
const VIRIDIS: [(u8, u8, u8); 9] = [
    (0x44, 0x01, 0x54),
    (0x47, 0x2d, 0x7b),
    (0x3b, 0x52, 0x8b),
    (0x2c, 0x72, 0x8e),
    (0x21, 0x91, 0x8c),
    (0x28, 0xae, 0x80),
    (0x5e, 0xc9, 0x62),
    (0xad, 0xdc, 0x30),
    (0xfd, 0xe7, 0x25),
];

/// Colour of the fraction s ∈ [0, 1] of the range (clamped).
pub fn viridis(s: f64) -> RGBColor {
    let s = if s.is_finite() {
        s.clamp(0.0, 1.0)
    } else {
        0.0
    };
    let x = s * (VIRIDIS.len() - 1) as f64;
    let i = (x.floor() as usize).min(VIRIDIS.len() - 2);
    let w = x - i as f64;
    let (a, b) = (VIRIDIS[i], VIRIDIS[i + 1]);
    let mix = |p: u8, q: u8| (p as f64 + w * (q as f64 - p as f64)).round() as u8;
    RGBColor(mix(a.0, b.0), mix(a.1, b.1), mix(a.2, b.2))
}

/// Grey for pieces without a value.
const NO_VALUE: RGBColor = RGBColor(200, 200, 200);

/// (component index, or 6 = |u|, 7 = |v|); the unit.
fn component(name: &str) -> Result<(usize, &'static str)> {
    match name {
        "u" => Ok((6, "m")),
        "v" => Ok((7, "m/s")),
        c => COMPONENTS
            .iter()
            .position(|n| *n == c)
            .map(|i| (i, if i < 3 { "m" } else { "m/s" }))
            .ok_or_else(|| {
                WeftError::input(format!("unknown component `{c}`")).expected(
                    "one of ux, uy, uz, vx, vy, vz, or u, v for the displacement or velocity magnitude",
                )
            }),
    }
}

/// (horizontal axis, vertical axis, towards the viewer, its sign), and the axis names.
fn view(name: &str) -> Result<([usize; 3], f64, (&'static str, &'static str))> {
    match name {
        "xy" => Ok(([0, 1, 2], 1.0, ("x", "y"))),
        "xz" => Ok(([0, 2, 1], -1.0, ("x", "z"))),
        "yz" => Ok(([1, 2, 0], 1.0, ("y", "z"))),
        v => Err(WeftError::input(format!("--view `{v}`"))
            .expected("xy (seen from +z), xz (seen from −y) or yz (seen from +x)")),
    }
}

/// The history sample nearest `time` of every node listed in the table: (time drawn,
/// node id → [ux, uy, uz, vx, vy, vz]).
fn sample(path: &Path, time: f64) -> Result<(f64, HashMap<i64, [f64; 6]>)> {
    let h = History::read(path)?;
    let t = &h.t;
    let (t0, t1) = t
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &x| {
            (a.min(x), b.max(x))
        });
    // Outside the run by more than a rounding error: refuse rather than draw another time.
    let slack = 1e-9 * (t1 - t0).abs().max(t1.abs());
    if time < t0 - slack || time > t1 + slack {
        return Err(WeftError::input(format!(
            "--time {time:e} s is outside the history, which runs from {t0:e} to {t1:e} s"
        ))
        .in_file(path)
        .hint("pick a time within the run (the nearest output sample is drawn)"));
    }
    let best = t
        .iter()
        .copied()
        .min_by(|a, b| (a - time).abs().total_cmp(&(b - time).abs()))
        .expect("non-empty");
    let mut out = HashMap::new();
    for r in (0..t.len()).filter(|&r| t[r] == best) {
        out.insert(h.node_id[r], h.row(r));
    }
    Ok((best, out))
}

/// Read the models and histories and build the pieces of every panel.
pub(crate) fn build(a: &FieldFigure) -> anyhow::Result<(Field, FieldReport)> {
    check_figure(a)?;
    let (comp, unit) = component(&a.component)?;
    let (axes, sign, names) = view(&a.view)?;
    let mut panels = vec![];
    let mut report = FieldReport {
        times: vec![],
        missing_nodes: vec![],
        range: (0.0, 0.0),
    };
    let mut seen = Seen {
        lo: f64::INFINITY,
        hi: f64::NEG_INFINITY,
    };
    for (k, (mdir, hpath)) in a.model.iter().zip(&a.history).enumerate() {
        let (panel, missing) = panel(a, k, (mdir, hpath), comp, (axes, sign), &mut seen)?;
        report.times.push(panel.time);
        report.missing_nodes.push(missing);
        panels.push(panel);
    }
    let (lo, hi) = (seen.lo, seen.hi);
    let range = match a.range {
        Some(r) => r,
        None if hi > lo => (lo, hi),
        None => {
            let d = if lo == 0.0 { 1e-12 } else { 1e-3 * lo.abs() };
            (lo - d, hi + d)
        }
    };
    report.range = range;
    let vmax = range.0.abs().max(range.1.abs());
    let mut ext = 0.0f64;
    for p in &panels {
        for q in p.faces.iter().chain(&p.lines).chain(&p.dots) {
            for &(x, y) in &q.pts {
                ext = ext.max(x.abs()).max(y.abs());
            }
        }
    }
    let field = Field {
        panels,
        range,
        value_unit: readable(vmax, unit),
        length_unit: readable(ext, "m"),
        component: match comp {
            6 => "|u|".into(),
            7 => "|v|".into(),
            _ => a.component.clone(),
        },
        axes: names,
        deformed: a.deformed.then_some(a.scale),
    };
    Ok((field, report))
}

/// The settings' own checks: one history per model, a magnification and a colour range
/// that make sense.
fn check_figure(a: &FieldFigure) -> Result<()> {
    if a.model.len() != a.history.len() {
        return Err(WeftError::input(format!(
            "{} --model and {} --history given; expected one history per model, in the same order",
            a.model.len(),
            a.history.len()
        )));
    }
    if a.model.is_empty() {
        return Err(WeftError::input("no --model given"));
    }
    if !(a.scale.is_finite() && a.scale >= 0.0) {
        return Err(
            WeftError::input(format!("--scale {}", a.scale)).expected("a finite magnification ≥ 0")
        );
    }
    if let Some((lo, hi)) = a.range {
        if !(lo.is_finite() && hi.is_finite() && lo < hi) {
            return Err(WeftError::input(format!("--range {lo}:{hi}"))
                .expected("MIN:MAX with finite MIN < MAX, in the component's SI unit"));
        }
    }
    Ok(())
}

/// The smallest and largest value drawn so far, over all panels.
struct Seen {
    lo: f64,
    hi: f64,
}

/// Panel `k`: model `mdir` coloured by the sample of `hpath` nearest the figure's time,
/// and the number of element nodes without a value; `seen` widened by the values of the
/// element nodes. A panel with no value at all is refused.
fn panel(
    a: &FieldFigure,
    k: usize,
    (mdir, hpath): (&Path, &Path),
    comp: usize,
    (axes, sign): ([usize; 3], f64),
    seen: &mut Seen,
) -> Result<(Panel, usize)> {
    let m = read_model(mdir)?;
    let (t, rows) = sample(hpath, a.time)?;
    let n = m.num_nodes();
    let (value, pos) = nodal_values(a, &m, &rows, comp);
    let project = |p: [f64; 3]| (p[axes[0]], p[axes[1]], sign * p[axes[2]]);
    let mut panel = Panel {
        label: label(&a.label, k, mdir),
        time: t,
        faces: vec![],
        lines: vec![],
        dots: vec![],
    };
    let used = element_pieces(&m, &pos, &value, project, &mut panel);
    for i in (0..n).filter(|&i| used[i]) {
        if let Some(v) = value[i] {
            seen.lo = seen.lo.min(v);
            seen.hi = seen.hi.max(v);
        }
    }
    let missing = (0..n).filter(|&i| used[i] && value[i].is_none()).count();
    if missing == (0..n).filter(|&i| used[i]).count() {
        return Err(WeftError::input(format!(
            "no node of model `{}` has a value at t = {t:e} s",
            mdir.display()
        ))
        .in_file(hpath)
        .expected("the history of the model's nodes (node ids as in nodes.parquet)")
        .hint("is this the history of that model? a run with --history-set holds only that set's nodes"));
    }
    for list in [&mut panel.faces, &mut panel.lines, &mut panel.dots] {
        list.sort_by(|p, q| p.depth.total_cmp(&q.depth));
    }
    Ok((panel, missing))
}

/// Per model node, the drawn value (None: not in the sample) and position: X + u₀, plus
/// `scale`·u on the deformed mesh.
fn nodal_values(
    a: &FieldFigure,
    m: &Model,
    rows: &HashMap<i64, [f64; 6]>,
    comp: usize,
) -> (Vec<Option<f64>>, Vec<[f64; 3]>) {
    let n = m.num_nodes();
    let mut value: Vec<Option<f64>> = vec![None; n];
    let mut pos: Vec<[f64; 3]> = (0..n)
        .map(|i| {
            let u0 = m.initial_displacement.get(i).copied().unwrap_or([0.0; 3]);
            std::array::from_fn(|d| m.coords[i][d] + u0[d])
        })
        .collect();
    for i in 0..n {
        if let Some(r) = rows.get(&m.node_id[i]) {
            value[i] = Some(match comp {
                6 => (r[0] * r[0] + r[1] * r[1] + r[2] * r[2]).sqrt(),
                7 => (r[3] * r[3] + r[4] * r[4] + r[5] * r[5]).sqrt(),
                c => r[c],
            });
            if a.deformed {
                for d in 0..3 {
                    pos[i][d] += a.scale * r[d];
                }
            }
        }
    }
    (value, pos)
}

/// Every element as pieces of `panel` (faces, lines, dots), in element-table order, seen
/// through `project`; the nodes of the elements, marked.
fn element_pieces(
    m: &Model,
    pos: &[[f64; 3]],
    value: &[Option<f64>],
    project: impl Fn([f64; 3]) -> (f64, f64, f64),
    panel: &mut Panel,
) -> Vec<bool> {
    let faces_total: usize = [ElementKind::Tri, ElementKind::Quad]
        .iter()
        .filter_map(|&kd| m.block(kd))
        .map(|b| b.len())
        .sum();
    let div = if faces_total * SUBDIVISION * SUBDIVISION <= MAX_PIECES {
        SUBDIVISION
    } else {
        1
    };
    let mut used = vec![false; m.num_nodes()];
    for (&kind, b) in &m.elements {
        let npe = kind.nodes_per_element();
        for e in 0..b.len() {
            let nodes = &b.nodes[npe * e..npe * (e + 1)];
            for &i in nodes {
                used[i] = true;
            }
            let x: Vec<(f64, f64, f64)> = nodes.iter().map(|&i| project(pos[i])).collect();
            let v: Option<Vec<f64>> = nodes.iter().map(|&i| value[i]).collect();
            match kind {
                ElementKind::Quad => quad_pieces(&x, v.as_deref(), div, &mut panel.faces),
                ElementKind::Tri => tri_pieces(&x, v.as_deref(), div, &mut panel.faces),
                ElementKind::Hex => {
                    // Its six faces, each a quad (the depth order hides the far ones).
                    for f in [
                        [0, 1, 2, 3],
                        [4, 5, 6, 7],
                        [0, 1, 5, 4],
                        [1, 2, 6, 5],
                        [2, 3, 7, 6],
                        [3, 0, 4, 7],
                    ] {
                        let xf: Vec<(f64, f64, f64)> = f.iter().map(|&k| x[k]).collect();
                        let vf: Option<Vec<f64>> =
                            v.as_ref().map(|v| f.iter().map(|&k| v[k]).collect());
                        quad_pieces(&xf, vf.as_deref(), div, &mut panel.faces);
                    }
                }
                ElementKind::Truss | ElementKind::Link | ElementKind::Beam => {
                    if (x[0].0 - x[1].0).hypot(x[0].1 - x[1].1) > 0.0 {
                        line_pieces(&x, v.as_deref(), div, &mut panel.lines)
                    }
                }
                ElementKind::PointMass => panel.dots.push(Piece {
                    pts: vec![(x[0].0, x[0].1)],
                    depth: x[0].2,
                    value: v.map(|v| v[0]),
                }),
            }
        }
    }
    used
}

/// Bilinear pieces of a quad (nodes counter-clockwise).
fn quad_pieces(x: &[(f64, f64, f64)], v: Option<&[f64]>, n: usize, out: &mut Vec<Piece>) {
    let at = |r: f64, s: f64| {
        let w = [(1.0 - r) * (1.0 - s), r * (1.0 - s), r * s, (1.0 - r) * s];
        let p = (0..4).fold((0.0, 0.0, 0.0), |acc, k| {
            (
                acc.0 + w[k] * x[k].0,
                acc.1 + w[k] * x[k].1,
                acc.2 + w[k] * x[k].2,
            )
        });
        (p, v.map(|v| (0..4).map(|k| w[k] * v[k]).sum::<f64>()))
    };
    let h = 1.0 / n as f64;
    for i in 0..n {
        for j in 0..n {
            let corners = [
                at(i as f64 * h, j as f64 * h),
                at((i + 1) as f64 * h, j as f64 * h),
                at((i + 1) as f64 * h, (j + 1) as f64 * h),
                at(i as f64 * h, (j + 1) as f64 * h),
            ];
            out.push(piece(&corners));
        }
    }
}

/// Linear pieces of a triangle: n² sub-triangles of the barycentric grid.
fn tri_pieces(x: &[(f64, f64, f64)], v: Option<&[f64]>, n: usize, out: &mut Vec<Piece>) {
    let at = |i: usize, j: usize| {
        let (a, b) = (i as f64 / n as f64, j as f64 / n as f64);
        let w = [1.0 - a - b, a, b];
        let p = (0..3).fold((0.0, 0.0, 0.0), |acc, k| {
            (
                acc.0 + w[k] * x[k].0,
                acc.1 + w[k] * x[k].1,
                acc.2 + w[k] * x[k].2,
            )
        });
        (p, v.map(|v| (0..3).map(|k| w[k] * v[k]).sum::<f64>()))
    };
    for i in 0..n {
        for j in 0..n - i {
            out.push(piece(&[at(i, j), at(i + 1, j), at(i, j + 1)]));
            if i + j + 1 < n {
                out.push(piece(&[at(i + 1, j), at(i + 1, j + 1), at(i, j + 1)]));
            }
        }
    }
}

/// Pieces of a two-node element.
fn line_pieces(x: &[(f64, f64, f64)], v: Option<&[f64]>, n: usize, out: &mut Vec<Piece>) {
    let at = |r: f64| {
        let p = (
            x[0].0 + r * (x[1].0 - x[0].0),
            x[0].1 + r * (x[1].1 - x[0].1),
            x[0].2 + r * (x[1].2 - x[0].2),
        );
        (p, v.map(|v| v[0] + r * (v[1] - v[0])))
    };
    for i in 0..n {
        out.push(piece(&[
            at(i as f64 / n as f64),
            at((i + 1) as f64 / n as f64),
        ]));
    }
}

/// A piece's corner: view coordinates (across, up, towards the viewer) and its value.
type Corner = ((f64, f64, f64), Option<f64>);

fn piece(c: &[Corner]) -> Piece {
    let k = c.len() as f64;
    Piece {
        pts: c.iter().map(|(p, _)| (p.0, p.1)).collect(),
        depth: c.iter().map(|(p, _)| p.2).sum::<f64>() / k,
        value: c
            .iter()
            .map(|(_, v)| *v)
            .sum::<Option<f64>>()
            .map(|s| s / k),
    }
}

/// Width of the colour bar's area [px].
const BAR_WIDTH: u32 = 130;

/// Draw the panels side by side and the colour bar on the right.
pub(crate) fn draw<DB: DrawingBackend>(
    root: DrawingArea<DB, Shift>,
    f: &Field,
    title: Option<&str>,
) -> anyhow::Result<()>
where
    DB::ErrorType: 'static,
{
    let err = |e: DrawingAreaErrorKind<DB::ErrorType>| anyhow::anyhow!("drawing failed: {e:?}");
    root.fill(&WHITE).map_err(err)?;
    let root = match title {
        Some(t) => root.titled(t, ("sans-serif", 26)).map_err(err)?,
        None => root,
    };
    let (w, _) = root.dim_in_pixel();
    let (plots, bar) = root.split_horizontally(w.saturating_sub(BAR_WIDTH));
    let panels = plots.split_evenly((1, f.panels.len()));
    // One length scale for all panels: the union of their extents.
    let (mut x0, mut x1, mut y0, mut y1) = (f64::MAX, f64::MIN, f64::MAX, f64::MIN);
    for p in &f.panels {
        for q in p.faces.iter().chain(&p.lines).chain(&p.dots) {
            for &(x, y) in &q.pts {
                x0 = x0.min(x);
                x1 = x1.max(x);
                y0 = y0.min(y);
                y1 = y1.max(y);
            }
        }
    }
    let (fl, ul) = (f.length_unit.0, f.length_unit.1.clone());
    let span = (x1 - x0).max(y1 - y0).max(1e-300);
    let pad = 0.03 * span;
    let (x0, x1, y0, y1) = (
        (x0 - pad) * fl,
        (x1 + pad) * fl,
        (y0 - pad) * fl,
        (y1 + pad) * fl,
    );
    let (lo, hi) = f.range;
    let colour = |v: Option<f64>| match v {
        Some(v) => viridis((v - lo) / (hi - lo)),
        None => NO_VALUE,
    };
    for (area, p) in panels.iter().zip(&f.panels) {
        let (head, body) = area.split_vertically(36);
        let caption = match f.deformed {
            Some(s) if s != 1.0 => format!("{}, t = {} (deformed ×{})", p.label, time(p.time), s),
            Some(_) => format!("{}, t = {} (deformed)", p.label, time(p.time)),
            None => format!("{}, t = {}", p.label, time(p.time)),
        };
        head.draw(&Text::new(
            caption,
            (10, 10),
            ("sans-serif", 18).into_font().color(&BLACK),
        ))
        .map_err(err)?;
        // Equal scales on both axes: widen the range that is short for the pixel box.
        let build = |xr: (f64, f64), yr: (f64, f64)| {
            let mut b = ChartBuilder::on(&body);
            b.margin(10).x_label_area_size(45).y_label_area_size(70);
            b.build_cartesian_2d(xr.0..xr.1, yr.0..yr.1)
        };
        let probe = build((x0, x1), (y0, y1)).map_err(err)?;
        let (pw, ph) = probe.plotting_area().dim_in_pixel();
        let (pw, ph) = (pw.max(1) as f64, ph.max(1) as f64);
        let (dx, dy) = (x1 - x0, y1 - y0);
        let (xr, yr) = if dx / dy > pw / ph {
            let h = dx * ph / pw;
            let c = 0.5 * (y0 + y1);
            ((x0, x1), (c - 0.5 * h, c + 0.5 * h))
        } else {
            let wd = dy * pw / ph;
            let c = 0.5 * (x0 + x1);
            ((c - 0.5 * wd, c + 0.5 * wd), (y0, y1))
        };
        let mut ch = build(xr, yr).map_err(err)?;
        ch.configure_mesh()
            .disable_mesh()
            .x_desc(format!("{} [{ul}]", f.axes.0))
            .y_desc(format!("{} [{ul}]", f.axes.1))
            .label_style(("sans-serif", 15))
            .axis_desc_style(("sans-serif", 17))
            .x_label_formatter(&|v| tick(*v))
            .y_label_formatter(&|v| tick(*v))
            .draw()
            .map_err(err)?;
        let sc = |pts: &[(f64, f64)]| -> Vec<(f64, f64)> {
            pts.iter().map(|&(x, y)| (x * fl, y * fl)).collect()
        };
        // A filled piece and its outline in the same colour: neighbours leave no gap.
        for q in &p.faces {
            let c = colour(q.value);
            let pts = sc(&q.pts);
            ch.draw_series(std::iter::once(Polygon::new(pts.clone(), c.filled())))
                .map_err(err)?;
            let mut ring = pts;
            ring.push(ring[0]);
            ch.draw_series(std::iter::once(PathElement::new(ring, c.stroke_width(1))))
                .map_err(err)?;
        }
        for q in &p.lines {
            let c = colour(q.value);
            ch.draw_series(std::iter::once(PathElement::new(
                sc(&q.pts),
                c.stroke_width(3),
            )))
            .map_err(err)?;
        }
        for q in &p.dots {
            let c = colour(q.value);
            ch.draw_series(std::iter::once(Circle::new(sc(&q.pts)[0], 4, c.filled())))
                .map_err(err)?;
        }
    }
    // The colour bar: 256 bands from lo to hi, its axis in the values' display unit.
    let (fv, uv) = (f.value_unit.0, f.value_unit.1.clone());
    let (_, bar_body) = bar.split_vertically(36);
    let mut b = ChartBuilder::on(&bar_body);
    b.margin_top(10)
        .margin_bottom(55)
        .margin_left(8)
        .margin_right(5)
        .set_label_area_size(LabelAreaPosition::Right, 75);
    let mut ch = b
        .build_cartesian_2d(0.0..1.0, lo * fv..hi * fv)
        .map_err(err)?;
    const BANDS: usize = 256;
    ch.draw_series((0..BANDS).map(|k| {
        let (s0, s1) = (k as f64 / BANDS as f64, (k + 1) as f64 / BANDS as f64);
        let v = |s: f64| (lo + s * (hi - lo)) * fv;
        Rectangle::new(
            [(0.0, v(s0)), (1.0, v(s1))],
            viridis(0.5 * (s0 + s1)).filled(),
        )
    }))
    .map_err(err)?;
    ch.configure_mesh()
        .disable_mesh()
        .disable_x_axis()
        .y_desc(format!("{} [{uv}]", f.component))
        .label_style(("sans-serif", 15))
        .axis_desc_style(("sans-serif", 17))
        .y_label_formatter(&|v| tick(*v))
        .draw()
        .map_err(err)?;
    root.present().map_err(err)?;
    Ok(())
}

/// A time in a readable unit.
fn time(t: f64) -> String {
    let (f, u) = readable(t.abs(), "s");
    format!("{} {u}", tick(t * f))
}
