//! The backing clay's drop calibration, run: the model of `weft-weave clay-drop` (the
//! standard's sphere dropped on the clay block, [`crate::generate::clay`]) run to its
//! end, the crater's depth on the axis against time, and the verdict: the indentation
//! (the depth once the sphere has rebounded off the clay, as the standard measures it)
//! within NIJ Standard-0101.06's band of 19 ± 3 mm.

use std::path::Path;

use crate::error::{Result, WeftError};
use crate::generate::clay::{Clay, DROP_BAND, DROP_TARGET, STANDARD_GRAVITY};
use crate::model::{ElementKind, Model};
use crate::table::{batch, write_table, Col, Provenance};

/// What one drop gave, with the constants of the clay it fell on.
#[derive(Debug, Clone)]
pub struct Drop {
    /// The crater's depth on the axis at the end, after the rebound [m].
    pub indentation: f64,
    /// Its deepest during the drop [m].
    pub indentation_max: f64,
    /// When the sphere left the clay [s] and its speed then [m/s] (up).
    pub separation_time: f64,
    pub rebound_velocity: f64,
    /// The sphere's diameter [m], mass [kg] (the whole sphere's), striking speed [m/s]
    /// and the drop height that gives it [m].
    pub diameter: f64,
    pub mass: f64,
    pub velocity: f64,
    pub height: f64,
    /// The clay's constants (`parts.parquet` of the part `clay`, nulls as the part reads
    /// them) and its finest cell [m].
    pub clay: Clay,
    pub fine: f64,
    /// The run: its end time [s], steps, elements and worst balance error.
    pub end_time: f64,
    pub steps: u64,
    pub elements: usize,
    pub max_balance_error_relative: f64,
    /// Per output sample: t [s], the crater's depth on the axis [m], the sphere's
    /// lowest point below the clay's top [m] and its velocity (down positive) [m/s].
    pub history: Vec<[f64; 4]>,
}

/// Runs the drop model `m` (weft-weave clay-drop) and measures it.
pub fn run_drop(m: &Model) -> Result<Drop> {
    let hint = "a model of `weft-weave clay-drop`";
    let axis = *m
        .node_sets
        .get("clay_axis_top")
        .and_then(|s| s.first())
        .ok_or_else(|| {
            WeftError::input("the model has no node set `clay_axis_top`")
                .in_file("node_sets.parquet")
                .expected(hint)
        })?;
    let part = m
        .parts
        .iter()
        .find(|p| p.name == "clay" && p.kind == ElementKind::Hex);
    let part = part.ok_or_else(|| {
        WeftError::input("the model has no hexahedron part `clay`")
            .in_file("parts.parquet")
            .expected(hint)
    })?;
    let p = m.projectiles.first().ok_or_else(|| {
        WeftError::input("the model has no projectile (the sphere)")
            .in_file("projectiles.parquet")
            .expected(hint)
    })?;
    let c = &part.props;
    let need = |v: Option<f64>, col: &str| {
        v.ok_or_else(|| {
            WeftError::input(format!("the part `clay` has no `{col}`"))
                .in_file("parts.parquet")
                .in_column(col)
                .expected("the clay's constants (weft-weave clay-drop)")
        })
    };
    let (density, youngs_modulus, a) = (
        need(c.density, "density")?,
        need(c.youngs_modulus, "youngs_modulus")?,
        need(c.plasticine_a, "plasticine_a")?,
    );
    let top = m.coords[axis][2];
    // The finest cell: the top layer's thickness on the axis.
    let fine = m
        .coords
        .iter()
        .filter(|x| x[0] == 0.0 && x[1] == 0.0 && x[2] < top)
        .map(|x| top - x[2])
        .fold(f64::INFINITY, f64::min);
    let (_, sink, stats) = crate::solver::run_in_memory(m)?;
    let j = sink.nodes.iter().position(|&i| i == axis).ok_or_else(|| {
        WeftError::input("the node `clay_axis_top` is not among the model's history nodes")
            .in_file("analysis.parquet")
            .in_column("history_sets")
            .expected("`clay_profile` (its first node is the axis's) among the history sets")
    })?;
    let history: Vec<[f64; 4]> = sink
        .t
        .iter()
        .zip(&sink.u)
        .zip(&sink.projectile)
        .map(|((&t, u), (_, _, s))| [t, -u[j][2], top - s[2], -s[5]])
        .collect();
    let indentation = history.last().map_or(0.0, |h| h[1]);
    let indentation_max = history.iter().map(|h| h[1]).fold(0.0, f64::max);
    // The sphere has left the clay when it moves up with no force on it.
    let sep = sink
        .projectile
        .iter()
        .position(|(t, _, s)| *t > 0.0 && s[5] > 0.0 && s[8] == 0.0);
    let Some(sep) = sep else {
        return Err(WeftError::input(format!(
            "the sphere had not left the clay by the end time {} s",
            m.analysis.end_time
        ))
        .in_file("analysis.parquet")
        .in_column("end_time")
        .expected("an end time past the rebound, when the crater's depth is final")
        .hint("weft-weave clay-drop --end-time"));
    };
    let (ts, _, s) = sink.projectile[sep];
    let v = p.velocity.iter().map(|v| v * v).sum::<f64>().sqrt();
    Ok(Drop {
        indentation,
        indentation_max,
        separation_time: ts,
        rebound_velocity: s[5],
        diameter: 2.0 * p.radius,
        // A quarter of the sphere in the quarter model.
        mass: 4.0 * p.mass,
        velocity: v,
        height: v * v / (2.0 * STANDARD_GRAVITY),
        clay: Clay {
            density,
            youngs_modulus,
            poisson_ratio: c.poisson_ratio.unwrap_or(0.3),
            a,
            b: c.plasticine_b.unwrap_or(0.0),
            n: c.plasticine_n.unwrap_or(1.0),
            m: c.plasticine_m.unwrap_or(0.0),
            reference_rate: c.plasticine_reference_rate.unwrap_or(1.0),
            hourglass: c.hourglass_coefficient(),
            erosion_plastic_strain: c.erosion_plastic_strain,
            selective_reduced: part.selective_reduced()?,
        },
        fine,
        end_time: stats.end_time,
        steps: stats.steps,
        elements: stats.elements,
        max_balance_error_relative: stats.max_balance_error_relative,
        history,
    })
}

/// `clay_calibration.parquet`: one row per drop (docs/tables.md).
pub fn write_calibration(path: &Path, drops: &[(String, Drop)], prov: &Provenance) -> Result<()> {
    let f = |g: fn(&Drop) -> f64| drops.iter().map(|(_, d)| g(d)).collect::<Vec<f64>>();
    let (lo, hi) = DROP_BAND;
    write_table(
        path,
        &batch(vec![
            Col::Str("model", drops.iter().map(|(n, _)| n.clone()).collect()),
            Col::F64("indentation", f(|d| d.indentation)),
            Col::F64("band_low", vec![lo; drops.len()]),
            Col::F64("band_high", vec![hi; drops.len()]),
            Col::F64("target", vec![DROP_TARGET; drops.len()]),
            Col::Bool(
                "in_band",
                drops
                    .iter()
                    .map(|(_, d)| d.indentation >= lo && d.indentation <= hi)
                    .collect(),
            ),
            Col::F64("indentation_max", f(|d| d.indentation_max)),
            Col::F64("separation_time", f(|d| d.separation_time)),
            Col::F64("rebound_velocity", f(|d| d.rebound_velocity)),
            Col::F64("sphere_diameter", f(|d| d.diameter)),
            Col::F64("sphere_mass", f(|d| d.mass)),
            Col::F64("drop_height", f(|d| d.height)),
            Col::F64("striking_velocity", f(|d| d.velocity)),
            Col::F64("density", f(|d| d.clay.density)),
            Col::F64("youngs_modulus", f(|d| d.clay.youngs_modulus)),
            Col::F64("poisson_ratio", f(|d| d.clay.poisson_ratio)),
            Col::F64("plasticine_a", f(|d| d.clay.a)),
            Col::F64("plasticine_b", f(|d| d.clay.b)),
            Col::F64("plasticine_n", f(|d| d.clay.n)),
            Col::F64("plasticine_m", f(|d| d.clay.m)),
            Col::F64("plasticine_reference_rate", f(|d| d.clay.reference_rate)),
            Col::F64("cell_size", f(|d| d.fine)),
            Col::F64("end_time", f(|d| d.end_time)),
            Col::I64("steps", drops.iter().map(|(_, d)| d.steps as i64).collect()),
            Col::I64(
                "elements",
                drops.iter().map(|(_, d)| d.elements as i64).collect(),
            ),
            Col::F64(
                "max_balance_error_relative",
                f(|d| d.max_balance_error_relative),
            ),
        ]),
        prov,
    )
}

/// `clay_drop.parquet`: per drop and output sample, the crater's depth on the axis and
/// the sphere's (docs/tables.md).
pub fn write_history(path: &Path, drops: &[(String, Drop)], prov: &Provenance) -> Result<()> {
    let rows = || {
        drops
            .iter()
            .flat_map(|(n, d)| d.history.iter().map(move |h| (n, h)))
    };
    write_table(
        path,
        &batch(vec![
            Col::Str("model", rows().map(|(n, _)| n.clone()).collect()),
            Col::F64("t", rows().map(|(_, h)| h[0]).collect()),
            Col::F64("depth", rows().map(|(_, h)| h[1]).collect()),
            Col::F64("sphere_depth", rows().map(|(_, h)| h[2]).collect()),
            Col::F64("sphere_velocity", rows().map(|(_, h)| h[3]).collect()),
        ]),
        prov,
    )
}
