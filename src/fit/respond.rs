//! The candidate's in-process run: the explicit (or linear static) solve of a model,
//! recording the nodes a comparison needs and, when asked, its projectile's velocity
//! history.

use super::projectile::{self, VelocityHistory};
use crate::analysis::Series;
use crate::error::{Result, WeftError};
use crate::model::Model;
use crate::solver::output::MemorySink;
use crate::solver::Solver;

/// Solve a model in-process (explicit, or the linear static solve) and return the
/// response of node set `set` as a [`Series`] (one sample at t = 0 when static).
pub fn respond(m: &Model, set: &str, static_mode: bool) -> Result<Series> {
    respond_nodes(m, &set_nodes(m, set)?, static_mode)
}

/// The nodes of set `set` of `m`.
pub(super) fn set_nodes(m: &Model, set: &str) -> Result<Vec<usize>> {
    Ok(m.node_sets
        .get(set)
        .ok_or_else(|| {
            WeftError::input(format!("the model has no node set `{set}`")).expected(format!(
                "one of {}",
                m.node_sets.keys().cloned().collect::<Vec<_>>().join(", ")
            ))
        })?
        .clone())
}

/// [`respond`] over model nodes `nodes` (indices, in that order).
pub fn respond_nodes(m: &Model, nodes: &[usize], static_mode: bool) -> Result<Series> {
    Ok(solve(m, nodes, static_mode, false)?.series)
}

/// [`respond_nodes`] with the velocity history of the model's projectile (see
/// [`projectile`]); `nodes` may be empty (the projectile alone).
pub fn respond_with_projectile(m: &Model, nodes: &[usize]) -> Result<(Series, VelocityHistory)> {
    let r = solve(m, nodes, false, true)?;
    Ok((r.series, r.projectile.expect("solve: a projectile history")))
}

/// A run's response over the compared nodes and, when asked, its projectile's velocity
/// history.
pub(super) struct Response {
    pub(super) series: Series,
    pub(super) projectile: Option<VelocityHistory>,
}

/// Solve `m` in-process and record `nodes` (and, with `striker`, the projectile: an error
/// when the model has none; explicit runs only).
pub(super) fn solve(
    m: &Model,
    nodes: &[usize],
    static_mode: bool,
    striker: bool,
) -> Result<Response> {
    const SET: &str = "__weft_compared";
    let mut m = m.clone();
    if striker && projectile::striker(&m).is_none() {
        return Err(WeftError::input("the candidate model has no projectile").expected(
            "a rigid projectile (projectile.parquet) or a deformable bullet (node set `bullet`)",
        ));
    }
    // The solver records a non-empty set: its first node when none is compared.
    let recorded = if nodes.is_empty() {
        vec![0]
    } else {
        nodes.to_vec()
    };
    m.node_sets.insert(SET.to_string(), recorded);
    let set = SET;
    m.analysis.history_sets = vec![set.to_string()];
    if let Some(bullet) = projectile::output_set(&m).filter(|_| striker) {
        m.analysis.history_sets.push(bullet.to_string());
    }
    let solver = match Solver::new(&m) {
        // A fixed step chosen for the generator's parameters may exceed the stable step of
        // the candidate's: fall back to the stable step.
        Err(_) if m.analysis.time_step.is_some() => {
            m.analysis.time_step = None;
            Solver::new(&m)?
        }
        r => r?,
    };
    let mut history = None;
    let (t, values) = if static_mode {
        let r = solver.solve_static(&m)?;
        let v: Vec<[f64; 6]> = nodes
            .iter()
            .map(|&i| [r.u[i][0], r.u[i][1], r.u[i][2], 0.0, 0.0, 0.0])
            .collect();
        (vec![0.0], vec![v])
    } else {
        let mut solver = solver;
        let mut sink = MemorySink::default();
        solver.run(&mut sink, &mut |_| {})?;
        if striker {
            history = projectile::from_run(&m, &sink, &solver.masses());
        }
        let pos: std::collections::HashMap<usize, usize> = sink
            .nodes
            .iter()
            .enumerate()
            .map(|(j, &i)| (i, j))
            .collect();
        let values = (0..sink.t.len())
            .map(|k| {
                nodes
                    .iter()
                    .map(|i| {
                        let j = pos[i];
                        let (u, v) = (sink.u[k][j], sink.v[k][j]);
                        [u[0], u[1], u[2], v[0], v[1], v[2]]
                    })
                    .collect()
            })
            .collect();
        (sink.t.clone(), values)
    };
    if striker && history.is_none() {
        return Err(
            WeftError::input("a projectile objective with a static solve")
                .expected("an explicit (dynamic) run: a static solve has no projectile history"),
        );
    }
    Ok(Response {
        series: Series {
            t,
            node_id: nodes.iter().map(|&i| m.node_id[i]).collect(),
            x0: nodes.iter().map(|&i| m.coords[i]).collect(),
            values,
        },
        projectile: history,
    })
}
