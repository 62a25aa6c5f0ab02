//! The ballistic limit of each group of impact runs: the Lambert–Jonas fit of residual
//! against striking velocity, the probability of perforation, and the tables
//! `ballistic_runs.parquet` (one row per impact) and `ballistic_limit.parquet` (one row
//! per group) (docs/tables.md), each with what the impacts cost.

use std::path::Path;

use super::lambert_jonas::{self, Bounds, Shot};
use super::probability::{self, Link};
use super::runs::{group_col, GroupBy, Run};
use crate::error::{Result, WeftError};
use crate::table::{batch, write_table, Col, Provenance};

/// How to fit.
#[derive(Debug, Clone, Copy)]
pub struct Options {
    pub bounds: Bounds,
    pub link: Link,
    /// Bootstrap replicates of the Lambert–Jonas intervals, and their seed.
    pub replicates: usize,
    pub seed: u64,
}

impl Default for Options {
    fn default() -> Self {
        Options {
            bounds: Bounds::default(),
            link: Link::Logit,
            // 1000 replicates: percentiles of 2.5 % within about ±1 % of their
            // probability (Efron & Tibshirani, ch. 13).
            replicates: 1000,
            seed: 1,
        }
    }
}

/// The limit of one group.
#[derive(Debug, Clone)]
pub struct Limit {
    pub group: String,
    pub runs: usize,
    pub perforations: usize,
    pub probability: probability::Fit,
    /// The Lambert–Jonas fit (None with fewer than three perforations).
    pub lambert_jonas: Option<lambert_jonas::Fit>,
    pub fastest_stop: f64,
    pub slowest_perforation: f64,
    /// What the group's impacts cost together.
    pub cost: GroupCost,
}

/// What a group's impacts cost: the cost of its limit. Each `None` when any impact's
/// part is unknown.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct GroupCost {
    /// The sum of the impacts' wall times [s].
    pub wall_time: Option<f64>,
    /// The sum of the impacts' steps × elements.
    pub element_cycles: Option<i64>,
    /// The mean wall time of an impact [s].
    pub wall_time_per_impact: Option<f64>,
}

/// The sums over a group's impacts, in their order.
pub fn group_cost(runs: &[Run]) -> GroupCost {
    let wall_time: Option<f64> = runs.iter().map(|r| r.cost.wall_time).sum();
    let element_cycles = runs
        .iter()
        .try_fold(0i64, |s, r| s.checked_add(r.cost.element_cycles()?));
    GroupCost {
        wall_time,
        element_cycles,
        wall_time_per_impact: wall_time
            .filter(|_| !runs.is_empty())
            .map(|w| w / runs.len() as f64),
    }
}

/// Fits every group; a group whose velocities cannot bracket a limit is refused.
pub fn fit_groups(groups: &[(String, Vec<Run>)], by: &str, o: &Options) -> Result<Vec<Limit>> {
    groups
        .iter()
        .map(|(g, runs)| fit_group(g, runs, by, o))
        .collect()
}

fn fit_group(group: &str, runs: &[Run], by: &str, o: &Options) -> Result<Limit> {
    let outcomes: Vec<(f64, bool)> = runs
        .iter()
        .map(|r| (r.striking_velocity, r.perforated))
        .collect();
    let speeds = || {
        runs.iter()
            .map(|r| format!("{}", r.striking_velocity))
            .collect::<Vec<_>>()
            .join(", ")
    };
    let probability = probability::fit(&outcomes, o.link).map_err(|e| {
        let (what, hint) = match e {
            probability::Unfit::NoPerforation => {
                ("no run perforated", "add faster impacts (above the limit)")
            }
            probability::Unfit::NoStop => (
                "every run perforated",
                "add slower impacts (below the limit)",
            ),
        };
        WeftError::input(format!(
            "{by} = {group}: {what} at the striking velocities {} m/s",
            speeds()
        ))
        .expected("velocities that bracket the limit: at least one stop and one perforation")
        .hint(hint)
    })?;
    let shots: Vec<Shot> = runs
        .iter()
        .map(|r| Shot {
            striking: r.striking_velocity,
            residual: r.residual_velocity,
            perforated: r.perforated,
        })
        .collect();
    let lj = lambert_jonas::fit(&shots, &o.bounds, o.replicates, o.seed).ok();
    Ok(Limit {
        group: group.to_string(),
        runs: runs.len(),
        perforations: runs.iter().filter(|r| r.perforated).count(),
        probability,
        lambert_jonas: lj,
        fastest_stop: runs
            .iter()
            .filter(|r| !r.perforated)
            .map(|r| r.striking_velocity)
            .fold(f64::NEG_INFINITY, f64::max),
        slowest_perforation: runs
            .iter()
            .filter(|r| r.perforated)
            .map(|r| r.striking_velocity)
            .fold(f64::INFINITY, f64::min),
        cost: group_cost(runs),
    })
}

/// `ballistic_runs.parquet`: every impact with its group and the fitted law's residual
/// velocity at its striking velocity.
pub fn write_runs(
    path: &Path,
    groups: &[(String, Vec<Run>)],
    limits: &[Limit],
    by: GroupBy,
    prov: &Provenance,
) -> Result<()> {
    let mut cols: (Vec<String>, Vec<String>, Vec<f64>, Vec<f64>, Vec<bool>) = Default::default();
    let (mut outcome, mut absorbed, mut fitted) = (vec![], vec![], vec![]);
    let mut cost = vec![];
    for ((_, runs), l) in groups.iter().zip(limits) {
        for r in runs {
            cost.push(r.cost);
            cols.0.push(r.source.clone());
            cols.1.push(r.group.clone());
            cols.2.push(r.striking_velocity);
            cols.3.push(r.residual_velocity);
            cols.4.push(r.perforated);
            outcome.push(r.outcome.clone());
            absorbed.push(Some(r.energy_absorbed).filter(|x| x.is_finite()));
            fitted.push(l.lambert_jonas.map(|f| f.law.residual(r.striking_velocity)));
        }
    }
    write_table(
        path,
        &batch(vec![
            Col::Str("run", cols.0),
            group_col(by, cols.1),
            Col::F64("striking_velocity", cols.2),
            Col::F64("residual_velocity", cols.3),
            Col::Bool("perforated", cols.4),
            Col::Str("outcome", outcome),
            Col::OptF64("energy_absorbed", absorbed),
            Col::OptF64("residual_velocity_fit", fitted),
            Col::OptI64("steps", cost.iter().map(|c| c.steps).collect()),
            Col::OptF64(
                "simulated_time",
                cost.iter().map(|c| c.simulated_time).collect(),
            ),
            Col::OptI64("elements", cost.iter().map(|c| c.elements).collect()),
            Col::OptI64(
                "element_cycles",
                cost.iter().map(|c| c.element_cycles()).collect(),
            ),
            Col::OptF64("wall_time", cost.iter().map(|c| c.wall_time).collect()),
        ]),
        prov,
    )
}

/// `ballistic_limit.parquet`: one row per group.
pub fn write_limits(path: &Path, limits: &[Limit], by: GroupBy, prov: &Provenance) -> Result<()> {
    let lj = |f: fn(&lambert_jonas::Fit) -> f64| {
        limits
            .iter()
            .map(|l| l.lambert_jonas.as_ref().map(f))
            .collect::<Vec<_>>()
    };
    let pr = |f: fn(&probability::Fit) -> f64| {
        limits
            .iter()
            .map(|l| Some(f(&l.probability)).filter(|x| x.is_finite()))
            .collect::<Vec<_>>()
    };
    write_table(
        path,
        &batch(vec![
            group_col(by, limits.iter().map(|l| l.group.clone()).collect()),
            Col::I64("runs", limits.iter().map(|l| l.runs as i64).collect()),
            Col::I64(
                "perforated_runs",
                limits.iter().map(|l| l.perforations as i64).collect(),
            ),
            Col::F64("v50", limits.iter().map(|l| l.probability.v50).collect()),
            Col::F64(
                "v50_low",
                limits
                    .iter()
                    .map(|l| l.probability.v50_interval.0)
                    .collect(),
            ),
            Col::F64(
                "v50_high",
                limits
                    .iter()
                    .map(|l| l.probability.v50_interval.1)
                    .collect(),
            ),
            Col::OptF64("v10", pr(|f| f.v10)),
            Col::OptF64("v90", pr(|f| f.v90)),
            Col::Str(
                "v50_method",
                limits
                    .iter()
                    .map(|l| l.probability.method.to_string())
                    .collect(),
            ),
            Col::OptF64("probability_beta0", pr(|f| f.beta.0)),
            Col::OptF64("probability_beta1", pr(|f| f.beta.1)),
            Col::F64(
                "fastest_stop",
                limits.iter().map(|l| l.fastest_stop).collect(),
            ),
            Col::F64(
                "slowest_perforation",
                limits.iter().map(|l| l.slowest_perforation).collect(),
            ),
            Col::OptF64("v_bl", lj(|f| f.law.v_bl)),
            Col::OptF64("v_bl_low", lj(|f| f.v_bl_interval.0)),
            Col::OptF64("v_bl_high", lj(|f| f.v_bl_interval.1)),
            Col::OptF64("a", lj(|f| f.law.a)),
            Col::OptF64("a_low", lj(|f| f.a_interval.0)),
            Col::OptF64("a_high", lj(|f| f.a_interval.1)),
            Col::OptF64("p", lj(|f| f.law.p)),
            Col::OptF64("p_low", lj(|f| f.p_interval.0)),
            Col::OptF64("p_high", lj(|f| f.p_interval.1)),
            Col::OptF64("rms_residual", lj(|f| f.rms)),
            Col::OptI64(
                "bootstrap_replicates",
                limits
                    .iter()
                    .map(|l| l.lambert_jonas.as_ref().map(|f| f.replicates as i64))
                    .collect(),
            ),
            Col::OptF64(
                "impacts_wall_time",
                limits.iter().map(|l| l.cost.wall_time).collect(),
            ),
            Col::OptI64(
                "impacts_element_cycles",
                limits.iter().map(|l| l.cost.element_cycles).collect(),
            ),
            Col::OptF64(
                "wall_time_per_impact",
                limits.iter().map(|l| l.cost.wall_time_per_impact).collect(),
            ),
        ]),
        prov,
    )
}
