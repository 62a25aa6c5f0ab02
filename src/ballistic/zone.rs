//! The failed zone of impacts: where the elements that failed (and left the model) lay,
//! measured from the projectile's axis. For each eroded failure of a run
//! (`failures.parquet`), the element's centroid in the model's initial configuration
//! (the mean of its nodes' positions: `nodes.parquet` plus the initial displacement of a
//! formed model) and its distance r from the striker's axis, the line through the
//! projectile's initial position along its initial velocity. Per run and layer, the
//! largest r, its 90th percentile and twice the largest (the zone's diameter on the full
//! fabric: a quarter model's zone is symmetric), the table `failure_zone.parquet`
//! (docs/tables.md). It feeds the rule that a patch should be at least twice as large as
//! the zone where yarns fail.

use std::collections::{BTreeSet, HashMap};
use std::path::{Path, PathBuf};

use crate::error::{Result, WeftError};
use crate::model::{striker, ElementKind, Model};
use crate::table::{batch, write_table, Col, Provenance, Table};

/// The striker's axis: a point and a unit direction.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Axis {
    pub point: [f64; 3],
    pub direction: [f64; 3],
}

impl Axis {
    /// The distance of `x` from the axis [m].
    pub fn distance(&self, x: [f64; 3]) -> f64 {
        let (p, a) = (self.point, self.direction);
        let d = [x[0] - p[0], x[1] - p[1], x[2] - p[2]];
        let s = d[0] * a[0] + d[1] * a[1] + d[2] * a[2];
        let r = [d[0] - s * a[0], d[1] - s * a[1], d[2] - s * a[2]];
        (r[0] * r[0] + r[1] * r[1] + r[2] * r[2]).sqrt()
    }
}

fn unit(v: [f64; 3]) -> Option<[f64; 3]> {
    let n = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
    (n > 0.0 && n.is_finite()).then(|| [v[0] / n, v[1] / n, v[2] / n])
}

/// The nodes' initial positions: the reference coordinates plus the initial displacement
/// where the model has one (a formed or relaxed model).
pub fn initial_positions(m: &Model) -> Vec<[f64; 3]> {
    let mut x = m.coords.clone();
    for (xi, u) in x.iter_mut().zip(&m.initial_displacement) {
        for d in 0..3 {
            xi[d] += u[d];
        }
    }
    x
}

/// The striker's axis in the initial configuration `x`: the first rigid projectile's tip
/// along its initial velocity (its own axis when it starts at rest), or a deformable
/// bullet's axis point (`striker::axis_point`) along its direction
/// (`Model::bullet_direction`). `model_dir` names the folder in the error.
pub fn striker_axis(m: &Model, x: &[[f64; 3]], model_dir: &Path) -> Result<Axis> {
    if let Some(p) = m.projectiles.first() {
        let direction = unit(p.velocity).or_else(|| unit(p.axis)).ok_or_else(|| {
            WeftError::input("the projectile has neither a velocity nor an axis")
                .in_file(model_dir.join("projectile.parquet"))
                .expected(
                    "a projectile with an initial velocity or an axis (axis_x, axis_y, axis_z)",
                )
        })?;
        return Ok(Axis {
            point: p.tip,
            direction,
        });
    }
    if let (Some(nodes), Some(direction)) = (m.bullet_nodes(), m.bullet_direction()) {
        let xs: Vec<[f64; 3]> = nodes.iter().map(|&i| x[i]).collect();
        return Ok(Axis {
            point: striker::axis_point(&xs, direction),
            direction,
        });
    }
    Err(WeftError::input(format!(
        "model `{}` has no projectile: the failed zone is measured from its axis",
        model_dir.display()
    ))
    .in_file(model_dir.join("projectile.parquet"))
    .expected("a model with a projectile or a deformable bullet (node set `bullet`)")
    .hint("give --model the model folder the run used (weft-weave woven)"))
}

/// An element that failed and left the model.
#[derive(Debug, Clone, PartialEq)]
pub struct Eroded {
    pub kind: String,
    pub id: i64,
    /// When it failed [s].
    pub time: f64,
}

/// The eroded failures of a run folder, from its `failures.parquet`.
pub fn read_eroded(run: &Path) -> Result<Vec<Eroded>> {
    let path = run.join("failures.parquet");
    if !run.is_dir() {
        return Err(
            WeftError::input(format!("no run folder `{}`", run.display()))
                .expected("the output folder of a weft-simulate run (--run)"),
        );
    }
    if !path.exists() {
        let what = if run.join("summary.parquet").exists() {
            "its model had no failure law, so nothing could fail"
        } else {
            "nor a summary.parquet: it is not the output folder of a weft-simulate run"
        };
        return Err(WeftError::input(format!(
            "run `{}` has no failures.parquet: {what}",
            run.display()
        ))
        .in_file(&path)
        .expected("a run of a model whose elements can fail (weft-simulate --out)")
        .hint("give the yarns a failure strain (weft-weave woven --failure-strain 0.036) and run the model again"));
    }
    let t = Table::read(&path)?;
    let cols = "t, element_kind, element_id, eroded";
    let (time, kind) = (t.f64("t", cols)?, t.str("element_kind", cols)?);
    let (id, eroded) = (t.i64("element_id", cols)?, t.bool("eroded", cols)?);
    Ok((0..t.num_rows())
        .filter(|&r| eroded[r])
        .map(|r| Eroded {
            kind: kind[r].clone(),
            id: id[r],
            time: time[r],
        })
        .collect())
}

/// A run of another model is refused: its summary's `nodes` (when it has one) must be
/// the model's.
pub fn check_same_model(m: &Model, at: Folders) -> Result<()> {
    let path = at.run.join("summary.parquet");
    if !path.exists() {
        return Ok(());
    }
    let t = Table::read(&path)?;
    let Some(nodes) = t
        .i64_opt("nodes")?
        .and_then(|v| v.first().copied().flatten())
    else {
        return Ok(());
    };
    if nodes != m.num_nodes() as i64 {
        return Err(WeftError::input(format!(
            "run `{}` was of a model of {nodes} nodes, but model `{}` has {}",
            at.run.display(),
            at.model.display(),
            m.num_nodes()
        ))
        .in_file(&path)
        .in_column("nodes")
        .expected("a run of the model given (--model)")
        .hint("give --model the model folder that this run simulated"));
    }
    Ok(())
}

/// A failed element placed: its layer (0: none), its distance from the axis [m] and
/// when it failed [s].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Placed {
    pub layer: i64,
    pub radius: f64,
    pub time: f64,
}

/// A run folder and the model folder it used (the errors name both).
#[derive(Debug, Clone, Copy)]
pub struct Folders<'a> {
    pub run: &'a Path,
    pub model: &'a Path,
}

/// The element rows of `m` by kind and id.
fn rows_by_id(m: &Model) -> HashMap<(ElementKind, i64), usize> {
    m.elements
        .iter()
        .flat_map(|(&k, b)| b.id.iter().enumerate().map(move |(r, &id)| ((k, id), r)))
        .collect()
}

/// Each eroded element's layer, centroid distance from `axis` and time.
pub fn place(
    m: &Model,
    x: &[[f64; 3]],
    axis: &Axis,
    eroded: &[Eroded],
    at: Folders,
) -> Result<Vec<Placed>> {
    let rows = rows_by_id(m);
    let failures = at.run.join("failures.parquet");
    eroded
        .iter()
        .map(|e| {
            let not_in_model = |what: &str| {
                WeftError::input(format!(
                    "run `{}` failed element {} of kind `{}`, {what} `{}`",
                    at.run.display(),
                    e.id,
                    e.kind,
                    at.model.display()
                ))
                .in_file(&failures)
                .in_column("element_id")
                .expected("the elements of the model the run used")
                .hint("give --model the model folder that this run simulated")
            };
            let kind = ElementKind::parse(&e.kind)
                .ok_or_else(|| not_in_model("which is no element kind: not in model"))?;
            let &row = rows
                .get(&(kind, e.id))
                .ok_or_else(|| not_in_model("which is not in model"))?;
            let b = &m.elements[&kind];
            let npe = kind.nodes_per_element();
            let mut c = [0.0; 3];
            for &n in &b.nodes[npe * row..npe * row + npe] {
                for d in 0..3 {
                    c[d] += x[n][d];
                }
            }
            let c = c.map(|s| s / npe as f64);
            Ok(Placed {
                layer: b.layer_of(row).unwrap_or(0),
                radius: axis.distance(c),
                time: e.time,
            })
        })
        .collect()
}

/// The model's layers (the element tables' `layer` column), or `{0}` when it has none.
pub fn model_layers(m: &Model) -> BTreeSet<i64> {
    let mut s: BTreeSet<i64> = m
        .elements
        .values()
        .flat_map(|b| b.layer.iter().flatten().copied())
        .collect();
    if s.is_empty() {
        s.insert(0);
    }
    s
}

/// The nearest-rank percentile `pct` (0–100] of sorted values: the value of rank
/// ⌈pct·n/100⌉ (1-based).
pub fn nearest_rank(sorted: &[f64], pct: usize) -> Option<f64> {
    let n = sorted.len();
    if n == 0 {
        return None;
    }
    let rank = (pct * n).div_ceil(100).clamp(1, n);
    Some(sorted[rank - 1])
}

/// One row of `failure_zone.parquet`.
#[derive(Debug, Clone, PartialEq)]
pub struct ZoneRow {
    pub run: String,
    pub layer: i64,
    pub failed_elements: i64,
    /// [m]
    pub radius_max: Option<f64>,
    /// [m]
    pub radius_p90: Option<f64>,
    /// 2 × radius_max [m].
    pub diameter: Option<f64>,
    /// [s]
    pub first_failure_time: Option<f64>,
    pub last_failure_time: Option<f64>,
}

/// A run's rows: one per layer of the model (and any other layer an element failed in).
pub fn zone_rows(run: &str, layers: &BTreeSet<i64>, placed: &[Placed]) -> Vec<ZoneRow> {
    let mut all = layers.clone();
    all.extend(placed.iter().map(|p| p.layer));
    all.into_iter()
        .map(|layer| {
            let of: Vec<&Placed> = placed.iter().filter(|p| p.layer == layer).collect();
            let mut r: Vec<f64> = of.iter().map(|p| p.radius).collect();
            r.sort_by(f64::total_cmp);
            let times = of.iter().map(|p| p.time);
            let radius_max = r.last().copied();
            ZoneRow {
                run: run.to_string(),
                layer,
                failed_elements: of.len() as i64,
                radius_max,
                radius_p90: nearest_rank(&r, 90),
                diameter: radius_max.map(|r| 2.0 * r),
                first_failure_time: times.clone().reduce(f64::min),
                last_failure_time: times.reduce(f64::max),
            }
        })
        .collect()
}

/// The failed zone of each run of `model_dir`'s model, rows in the runs' order.
pub fn failure_zone(runs: &[PathBuf], model_dir: &Path) -> Result<Vec<ZoneRow>> {
    let m = crate::model::io::read_model(model_dir)?;
    let x = initial_positions(&m);
    let axis = striker_axis(&m, &x, model_dir)?;
    let layers = model_layers(&m);
    let mut rows = Vec::new();
    for run in runs {
        let eroded = read_eroded(run)?;
        let at = Folders {
            run,
            model: model_dir,
        };
        check_same_model(&m, at)?;
        let placed = place(&m, &x, &axis, &eroded, at)?;
        rows.extend(zone_rows(&run.display().to_string(), &layers, &placed));
    }
    Ok(rows)
}

/// `failure_zone.parquet`.
pub fn write_zone(path: &Path, rows: &[ZoneRow], prov: &Provenance) -> Result<()> {
    let f = |g: fn(&ZoneRow) -> Option<f64>| rows.iter().map(g).collect::<Vec<_>>();
    write_table(
        path,
        &batch(vec![
            Col::Str("run", rows.iter().map(|r| r.run.clone()).collect()),
            Col::I64("layer", rows.iter().map(|r| r.layer).collect()),
            Col::I64(
                "failed_elements",
                rows.iter().map(|r| r.failed_elements).collect(),
            ),
            Col::OptF64("radius_max", f(|r| r.radius_max)),
            Col::OptF64("radius_p90", f(|r| r.radius_p90)),
            Col::OptF64("diameter", f(|r| r.diameter)),
            Col::OptF64("first_failure_time", f(|r| r.first_failure_time)),
            Col::OptF64("last_failure_time", f(|r| r.last_failure_time)),
        ]),
        prov,
    )
}
