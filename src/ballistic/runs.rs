//! Impact runs gathered for a ballistic limit: one [`Run`] per impact, read from the
//! `summary.parquet` of each run folder (or from one table that gathers them, as
//! `weft gather` writes), grouped by a column (`layers`, by default), each group checked
//! to be one model. Each run keeps what it cost ([`Cost`]: steps, simulated time, the
//! model's elements, wall time), from the summary's columns where it has them.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use crate::error::{Result, WeftError};
use crate::table::Table;

/// One impact.
#[derive(Debug, Clone, PartialEq)]
pub struct Run {
    /// Where it comes from: the run folder, or `TABLE row N`.
    pub source: String,
    /// The value of the grouping column.
    pub group: String,
    pub striking_velocity: f64,
    /// 0 when stopped.
    pub residual_velocity: f64,
    pub perforated: bool,
    /// `perforated`, `arrested` (or `undecided`: refused before a fit).
    pub outcome: String,
    /// The energy the fabric absorbed by the end of the run [J] (NaN when unknown).
    pub energy_absorbed: f64,
    /// What must agree within a group: layers, the projectile's mass and radius, and the
    /// model's nodes and elements.
    pub signature: Vec<(&'static str, f64)>,
    /// What the impact cost (unknown parts `None`).
    pub cost: Cost,
    /// Why the run stopped, when the solver stopped it (the summary's `status =
    /// stopped` and `stop_reason`): its outcome is not one to fit ([`leave_out_stopped`]).
    pub stopped: Option<String>,
}

/// What one impact cost: its solver steps and simulated time to its outcome, the
/// model's elements (the solver's count, point masses left out: the summary's
/// `elements`), and the wall time of its run. `None` where unknown (a summary written
/// before these columns).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Cost {
    pub steps: Option<i64>,
    /// [s]
    pub simulated_time: Option<f64>,
    pub elements: Option<i64>,
    /// [s]: a measurement of the machine, not reproducible.
    pub wall_time: Option<f64>,
}

impl Cost {
    /// Steps × elements: the element updates the run took (`None` when either is
    /// unknown, or the product overflows).
    pub fn element_cycles(&self) -> Option<i64> {
        self.steps?.checked_mul(self.elements?)
    }
}

/// The summary's wall-time columns whose sum is a run's wall time (setup, external
/// loads, forces, node update, output; the contact's time is within the forces').
pub const WALL_TIME_COLUMNS: [&str; 5] = [
    "wall_time_setup",
    "wall_time_loads",
    "wall_time_forces",
    "wall_time_update",
    "wall_time_output",
];

/// The summary columns a run must have.
const REQUIRED: &str = "striking_velocity, outcome, perforated, residual_velocity, layers";

/// The columns that say two runs are of one model (a velocity and a seed may differ).
const SIGNATURE: [&str; 5] = [
    "layers",
    "projectile_mass",
    "projectile_radius",
    "nodes",
    "elements",
];

/// The runs of a table of summaries: `summary.parquet` of one run (one row), or a table
/// that gathers several (`weft gather --table summary.parquet`), grouped by `by`.
pub fn read_table(path: &Path, by: &str, label: &dyn Fn(usize) -> String) -> Result<Vec<Run>> {
    let t = Table::read(path)?;
    let n = t.num_rows();
    let sv = t.f64("striking_velocity", REQUIRED)?;
    let outcome = t.str("outcome", REQUIRED)?;
    let perforated = t.bool("perforated", REQUIRED)?;
    let residual = t.f64_opt("residual_velocity")?.unwrap_or(vec![None; n]);
    let absorbed = t.f64_opt("energy_absorbed")?.unwrap_or(vec![None; n]);
    let group = group_column(&t, by)?;
    let cost = costs(&t)?;
    let stopped = stop_reasons(&t)?;
    let sig: Vec<(&'static str, Vec<f64>)> = SIGNATURE
        .iter()
        .filter(|c| t.has(c))
        .map(|&c| Ok((c, numeric(&t, c)?)))
        .collect::<Result<_>>()?;
    let mut runs = Vec::with_capacity(n);
    for row in 0..n {
        runs.push(Run {
            source: label(row),
            group: group[row].clone(),
            striking_velocity: sv[row],
            residual_velocity: if perforated[row] {
                residual[row].unwrap_or(f64::NAN)
            } else {
                0.0
            },
            perforated: perforated[row],
            outcome: outcome[row].clone(),
            energy_absorbed: absorbed[row].unwrap_or(f64::NAN),
            signature: sig.iter().map(|(c, v)| (*c, v[row])).collect(),
            cost: cost[row],
            stopped: stopped[row].clone(),
        });
    }
    Ok(runs)
}

/// Each row's stop reason: `Some` where `status` is `stopped` (the reason from
/// `stop_reason`, or a placeholder where it is null); `None` where it is `completed` or
/// the table has no `status` (a gathered `ballistic_runs.parquet`, whose runs were
/// checked when it was written).
fn stop_reasons(t: &Table) -> Result<Vec<Option<String>>> {
    let n = t.num_rows();
    if !t.has("status") {
        return Ok(vec![None; n]);
    }
    let status = t.str("status", "status")?;
    let reason = t.str_opt("stop_reason")?.unwrap_or(vec![None; n]);
    status
        .iter()
        .zip(reason)
        .enumerate()
        .map(|(row, (s, r))| match s.as_str() {
            "completed" => Ok(None),
            "stopped" => Ok(Some(r.unwrap_or_else(|| "no reason recorded".into()))),
            other => Err(t.value_error(
                "status",
                row,
                format!("`status` = `{other}`: expected `completed` or `stopped` (weft-simulate's summary)"),
            )),
        })
        .collect()
}

/// Each row's cost from a table of summaries: `steps`, `end_time`, `elements` and the
/// sum of [`WALL_TIME_COLUMNS`], `None` where a column is absent or its cell null. A
/// table of `ballistic_runs.parquet` rows (searches gathered by `weft gather`, fitted
/// again by group) carries its own `simulated_time` and `wall_time`, read as they are.
fn costs(t: &Table) -> Result<Vec<Cost>> {
    let n = t.num_rows();
    let steps = count_column(t, "steps")?.unwrap_or(vec![None; n]);
    let end = match t.f64_opt("simulated_time")? {
        Some(v) => v,
        None => t.f64_opt("end_time")?.unwrap_or(vec![None; n]),
    };
    let elements = count_column(t, "elements")?.unwrap_or(vec![None; n]);
    let wall = match t.f64_opt("wall_time")? {
        Some(v) => v,
        None => summed_wall_time(t)?,
    };
    Ok((0..n)
        .map(|row| Cost {
            steps: steps[row],
            simulated_time: end[row],
            elements: elements[row],
            wall_time: wall[row],
        })
        .collect())
}

/// The sum of a summary's [`WALL_TIME_COLUMNS`] per row (`None` where one is missing).
fn summed_wall_time(t: &Table) -> Result<Vec<Option<f64>>> {
    let n = t.num_rows();
    let mut wall: Vec<Option<f64>> = vec![Some(0.0); n];
    for c in WALL_TIME_COLUMNS {
        let v = t.f64_opt(c)?.unwrap_or(vec![None; n]);
        for (w, x) in wall.iter_mut().zip(v) {
            *w = w.zip(x).map(|(a, b)| a + b);
        }
    }
    Ok(wall)
}

/// A count column (`steps`, `elements`): integers, or the floats a table gathered by
/// another tool may hold (pandas writes an integer column with nulls so), each a whole
/// number; `None` when the column is absent.
fn count_column(t: &Table, c: &str) -> Result<Option<Vec<Option<i64>>>> {
    if let Ok(v) = t.i64_opt(c) {
        return Ok(v);
    }
    let Some(v) = t.f64_opt(c)? else {
        return Ok(None);
    };
    v.iter()
        .enumerate()
        .map(|(row, x)| match x {
            Some(x) if x.fract() != 0.0 || x.abs() > 9e15 => {
                Err(t.value_error(c, row, format!("`{c}` = {x} is not a count")))
            }
            x => Ok(x.map(|x| x as i64)),
        })
        .collect::<Result<Vec<_>>>()
        .map(Some)
}

/// A numeric column as f64 (integers included).
fn numeric(t: &Table, c: &str) -> Result<Vec<f64>> {
    t.f64(c, REQUIRED)
}

/// The grouping column as text (integers and floats as written).
pub fn group_column(t: &Table, by: &str) -> Result<Vec<String>> {
    if !t.has(by) {
        return Err(
            WeftError::input(format!("no column `{by}` to group the runs by"))
                .in_file(&t.path)
                .expected(format!("a column `{by}` (--by), e.g. `layers`"))
                .hint("give --by a column of the runs' summaries, or of the gathered table"),
        );
    }
    if let Ok(v) = t.str(by, by) {
        return Ok(v);
    }
    Ok(t.f64(by, by)?
        .iter()
        .map(|x| {
            if x.fract() == 0.0 && x.abs() < 1e15 {
                format!("{}", *x as i64)
            } else {
                format!("{x}")
            }
        })
        .collect())
}

/// The runs of run folders (each with its `summary.parquet`).
pub fn read_folders(dirs: &[PathBuf], by: &str) -> Result<Vec<Run>> {
    let mut runs = Vec::new();
    for d in dirs {
        let path = d.join("summary.parquet");
        if !path.exists() {
            return Err(
                WeftError::input(format!("`{}` has no summary.parquet", d.display()))
                    .in_file(&path)
                    .expected("the output folder of a weft-simulate run")
                    .hint("a run that was killed writes nothing; rerun it"),
            );
        }
        let label = |_| d.display().to_string();
        runs.extend(read_table(&path, by, &label)?);
    }
    Ok(runs)
}

/// The runs the solver did not stop. A stopped run (NaN, instability, an energy error)
/// has an outcome, if any, of a run that went wrong: with `skip`, each is left out and
/// told to `note`; without, the first is refused with its reason.
pub fn leave_out_stopped(
    runs: Vec<Run>,
    skip: bool,
    note: &mut dyn FnMut(&Run),
) -> Result<Vec<Run>> {
    let mut kept = Vec::with_capacity(runs.len());
    for r in runs {
        match &r.stopped {
            None => kept.push(r),
            Some(_) if skip => note(&r),
            Some(why) => {
                return Err(WeftError::input(format!(
                    "run `{}` at {} m/s stopped before its end: {why}",
                    r.source, r.striking_velocity
                ))
                .in_column("status")
                .expected("runs with `status = completed` in their summary: a stopped run's outcome is not one to fit")
                .hint("rerun it with a smaller time step (weft-simulate --dt-safety) or what its reason asks, or pass --skip-stopped to fit without it"))
            }
        }
    }
    Ok(kept)
}

/// The runs by group (in the groups' order: numeric when they all are), each group
/// checked: decided outcomes only, and one model (the same signature).
pub fn group(runs: Vec<Run>) -> Result<Vec<(String, Vec<Run>)>> {
    let mut by: BTreeMap<String, Vec<Run>> = BTreeMap::new();
    for r in runs {
        if r.outcome != "perforated" && r.outcome != "arrested" {
            return Err(WeftError::input(format!(
                "run `{}` at {} m/s ended `{}`",
                r.source, r.striking_velocity, r.outcome
            ))
            .expected("perforated or arrested: a run whose outcome is decided")
            .hint("raise the run's end time (weft-simulate --end-time) so that the projectile is stopped or free of the fabric"));
        }
        by.entry(r.group.clone()).or_default().push(r);
    }
    for (g, rs) in &by {
        check_one_model(g, rs)?;
    }
    let mut groups: Vec<(String, Vec<Run>)> = by.into_iter().collect();
    if groups.iter().all(|(g, _)| g.parse::<f64>().is_ok()) {
        groups.sort_by(|a, b| {
            a.0.parse::<f64>()
                .unwrap()
                .total_cmp(&b.0.parse::<f64>().unwrap())
        });
    }
    for (_, rs) in groups.iter_mut() {
        rs.sort_by(|a, b| a.striking_velocity.total_cmp(&b.striking_velocity));
    }
    Ok(groups)
}

/// The runs of one group must be of one model: the same signature.
fn check_one_model(group: &str, runs: &[Run]) -> Result<()> {
    let first = &runs[0];
    for r in &runs[1..] {
        for ((c, a), (_, b)) in first.signature.iter().zip(&r.signature) {
            if a != b && !(a.is_nan() && b.is_nan()) {
                return Err(WeftError::input(format!(
                    "runs `{}` and `{}` of group `{group}` are of different models: {c} = {a} and {b}",
                    first.source, r.source
                ))
                .expected("one model per group: only the striking velocity (and a seed) may differ")
                .hint("group the runs by the column that tells the models apart (--by), or fit them separately"));
            }
        }
    }
    Ok(())
}

/// How the grouping column is typed when written.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum GroupType {
    /// As the values read: integers, numbers or text (`fit --by layers`).
    Inferred,
    /// Always text: a model folder's name (`search`), so that searches over folders named
    /// `6` and `reference` gather into one table.
    Text,
}

/// The grouping column of the tables written: its name and how it is typed.
#[derive(Clone, Copy, Debug)]
pub struct GroupBy<'a> {
    pub column: &'a str,
    pub kind: GroupType,
}

/// The grouping column to write: with [`GroupType::Inferred`], integers when every value
/// is one as written (`layers`), numbers when every value is one, text otherwise, so that
/// a table read back in pandas or polars sorts and plots its groups as the source table
/// did; with [`GroupType::Text`], text.
pub fn group_col(by: GroupBy, groups: Vec<String>) -> crate::table::Col {
    use crate::table::Col;
    let GroupBy { column: by, kind } = by;
    if kind == GroupType::Text {
        return Col::StrNamed(by.to_string(), groups);
    }
    let ints: Option<Vec<i64>> = groups
        .iter()
        .map(|g| g.parse::<i64>().ok().filter(|i| i.to_string() == *g))
        .collect();
    if let Some(v) = ints {
        return Col::I64Named(by.to_string(), v);
    }
    let floats: Option<Vec<f64>> = groups.iter().map(|g| g.parse::<f64>().ok()).collect();
    match floats {
        Some(v) if v.iter().all(|x| x.is_finite()) => Col::F64Named(by.to_string(), v),
        _ => Col::StrNamed(by.to_string(), groups),
    }
}
