//! Where forming starts other than the generated geometry: the formed periodic cell
//! reflected over the patch ([`cell_start`], the default of `weft-form`), or a formed
//! smaller patch of the same weave laid over it ([`tile_start`], `--start-from`).

use std::path::Path;

use serde::Serialize;

use crate::error::{Result, WeftError};
use crate::model::io::read_model;
use crate::model::Model;
use crate::solver::relax::RelaxStats;
use crate::table::Table;

use super::cell;
use super::params::Params;
use super::weave::{node_parts, scaled_work, spacing_of};

/// A start for the relaxation other than the generated geometry.
#[derive(Debug, Clone)]
pub struct Start {
    /// Displacement of every node of the model to form [m].
    pub u: Vec<[f64; 3]>,
    /// Forming work credited to it [J] (the work that formed the state it came from).
    pub work: f64,
    /// The formed periodic cell it was tiled from, if it was: the patch is then tested
    /// at rest first, and taken as it is if it stays ([`cell`]).
    pub cell: Option<CellSummary>,
}

/// What forming the periodic cell did (for the report).
#[derive(Debug, Clone, Copy, Default, Serialize)]
pub struct CellSummary {
    pub rounds: usize,
    pub steps: u64,
    /// The cell's planes moved by δ_x, δ_y [m], and the force across them per yarn [N].
    pub stretch: [f64; 2],
    pub tension: [f64; 2],
}

/// Where forming starts (`weft-form --start`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, clap::ValueEnum)]
#[serde(rename_all = "lowercase")]
pub enum StartMode {
    /// The periodic cell formed alone and reflected over the patch ([`cell`]), then tested
    /// at rest (relaxed further only if it moves).
    Cell,
    /// The generated geometry, relaxed whole.
    Geometry,
}

/// Relative accuracy of the tension across the periodic cell's planes.
pub const CELL_TENSION_TOLERANCE: f64 = 1e-3;

/// A start for forming the quarter patch `m` from a formed smaller quarter patch `cell`
/// of the same weave (same spacing, yarn section, mesh and layers; `weft-form
/// --start-from`). A plain weave repeats every two spacings, so away from its edges a
/// formed patch's displacement is periodic in 2p plus a mean stretch ε̄ (the yarns'
/// strain and de-crimping). Along x (and likewise y), with X and X_c the two patches'
/// extents, D = X − X_c (a whole number of 2p: the weave's phase at the ends must
/// agree) and s = 2p·round(X_c / 4p): nodes at x < s take the displacement of the cell's
/// node at x, nodes within X_c − s of the end that of the cell's node at x − D, and nodes
/// between that of the cell's node at x − 2p·j in [s − 2p, s); to each the stretch
/// ε̄·(x − x_cell) is added, with ε̄ the cell's mean over [s − 2p, s) of
/// (u(x + 2p) − u(x)) / 2p. Nodes are matched by part name and reference position.
pub fn tile_start(m: &Model, cell: &Model, cell_name: &str) -> Result<Vec<[f64; 3]>> {
    let bad = |what: String| WeftError::input(what).in_file(cell_name.to_string());
    if cell.initial_displacement.is_empty() {
        return Err(bad(
            "the start model is not formed (its nodes.parquet has no ux0, uy0, uz0)".into(),
        )
        .hint("start from the output of `weft-form` on a smaller patch"));
    }
    let (Some(p), Some(pc)) = (spacing_of(m), spacing_of(cell)) else {
        return Err(bad(
            "a node set `axis_x` with two crossings is missing: the yarn spacing is unknown".into(),
        )
        .hint("both models must come from `weft-weave woven`"));
    };
    if (p - pc).abs() > 1e-9 * p {
        return Err(bad(format!("the start model's yarn spacing is {pc:e} m"))
            .expected(format!("the spacing of the model to form, {p:e} m")));
    }
    let ext = |mm: &Model, d: usize| {
        mm.coords
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), c| {
                (l.min(c[d]), h.max(c[d]))
            })
    };
    let tol = 1e-6 * p;
    let mut maps = vec![];
    for d in 0..2 {
        let (lo, hi) = ext(m, d);
        let (loc, hic) = ext(cell, d);
        let axis = ["x", "y"][d];
        if lo.abs() > tol || loc.abs() > tol {
            return Err(bad(format!(
                "the patches start at {axis} = {lo:e} m and {loc:e} m"
            ))
            .expected("quarter patches with symmetry planes x = 0 and y = 0")
            .hint("generate both with `weft-weave woven` (quarter, the default)"));
        }
        let dd = hi - hic;
        let periods = dd / (2.0 * p);
        let s = 2.0 * p * (hic / (4.0 * p)).round();
        if dd < -tol || (periods - periods.round()).abs() > 1e-6 || s < 2.0 * p - tol {
            return Err(bad(format!(
                "the start patch reaches {axis} = {hic:e} m and the patch to form {hi:e} m"
            ))
            .expected("a start patch at least 4 yarns wide and smaller by an even number of yarns (the weave repeats every 2 yarns)"));
        }
        maps.push((s, dd));
    }
    let map = |c: f64, (s, dd): (f64, f64)| -> f64 {
        if c < s - tol {
            c
        } else if c >= s + dd - tol {
            c - dd
        } else {
            let j = ((c - s + tol) / (2.0 * p)).floor() + 1.0;
            c - 2.0 * p * j
        }
    };
    let q = 1e-6 * p;
    let key = |x: f64, y: f64| ((x / q).round() as i64, (y / q).round() as i64);
    let mut index: std::collections::HashMap<(i64, i64), Vec<usize>> = Default::default();
    for (n, c) in cell.coords.iter().enumerate() {
        index.entry(key(c[0], c[1])).or_default().push(n);
    }
    let cell_parts = node_parts(cell);
    let parts = node_parts(m);
    let find = |x: f64, y: f64, z: f64, part: &str| -> Option<usize> {
        index
            .get(&key(x, y))?
            .iter()
            .copied()
            .find(|&n| cell_parts[n] == part && (cell.coords[n][2] - z).abs() < 1e-6 * p)
    };
    // The cell's mean stretch over its interior period along x and y.
    let mut strain = [0.0f64; 2];
    for d in 0..2 {
        let (s, _) = maps[d];
        let (mut sum, mut count) = (0.0, 0usize);
        for (n, c) in cell.coords.iter().enumerate() {
            if c[d] < s - 2.0 * p - tol || c[d] >= s - tol {
                continue;
            }
            let mut c2 = *c;
            c2[d] += 2.0 * p;
            if let Some(k) = find(c2[0], c2[1], c2[2], cell_parts[n]) {
                sum +=
                    (cell.initial_displacement[k][d] - cell.initial_displacement[n][d]) / (2.0 * p);
                count += 1;
            }
        }
        if count == 0 {
            return Err(bad(
                "the start patch has no node pairs one period (2 spacings) apart in its interior"
                    .into(),
            )
            .hint("start from a formed patch of at least 4 yarns per side"));
        }
        strain[d] = sum / count as f64;
    }
    let mut u = vec![[0.0; 3]; m.num_nodes()];
    for (n, c) in m.coords.iter().enumerate() {
        let (xc, yc) = (map(c[0], maps[0]), map(c[1], maps[1]));
        let k = find(xc, yc, c[2], parts[n]).ok_or_else(|| {
            bad(format!(
                "node `{}` ({}, at x = {:e}, y = {:e}, z = {:e} m) has no counterpart at x = {xc:e}, y = {yc:e} m in the start patch",
                m.node_id[n], parts[n], c[0], c[1], c[2]
            ))
            .hint("the start patch must be the same weave (spacing, section, crimp, mesh, layers) with fewer yarns")
        })?;
        let uc = cell.initial_displacement[k];
        u[n] = [
            uc[0] + strain[0] * (c[0] - xc),
            uc[1] + strain[1] * (c[1] - yc),
            uc[2],
        ];
    }
    Ok(u)
}

/// The start tiled from the formed periodic cell of `m` ([`cell`]).
pub fn cell_start(m: &Model, p: &Params, progress: &mut dyn FnMut(&RelaxStats)) -> Result<Start> {
    let spacing = spacing_of(m).ok_or_else(|| {
        WeftError::input(
            "the model has no node set `axis_x` with two crossings: the yarn spacing, hence the periodic cell, is unknown",
        )
        .hint("form a patch of at least 2 yarns per side from `weft-weave woven`, or use --start geometry")
    })?;
    let c = cell::extract(m, spacing)?;
    let f = cell::form(&c, p, CELL_TENSION_TOLERANCE, progress)
        .map_err(|e| e.context("cannot form the periodic cell".to_string()))?;
    let u = cell::tile(m, &c, &f)?;
    Ok(Start {
        u,
        work: scaled_work(f.work, m, &c.model),
        cell: Some(CellSummary {
            rounds: f.rounds,
            steps: f.steps,
            stretch: f.stretch,
            tension: f.tension,
        }),
    })
}

/// The start laid over `m` from the formed smaller patch in the folder `dir` (a
/// `weft-form` output; [`tile_start`]), credited with its forming work scaled by the
/// yarn element count.
pub fn patch_start(m: &Model, dir: &Path) -> Result<Start> {
    let cell = read_model(dir)?;
    let name = dir.display().to_string();
    let u = tile_start(m, &cell, &name)
        .map_err(|e| e.context(format!("cannot start from `{name}`")))?;
    let rp = dir.join("form.parquet");
    let w = Table::read(&rp)?.f64("forming_work", "forming_work (from weft-form)")?;
    let work = scaled_work(w.first().copied().unwrap_or(0.0), m, &cell);
    Ok(Start {
        u,
        work,
        cell: None,
    })
}
