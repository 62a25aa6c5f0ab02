//! The `fit` stage behind `weft-fit`: read the cases, parse the parameters, minimise T,
//! and write `fit_trace.parquet`, `fit_result.parquet` and the fitted models.

use std::path::{Path, PathBuf};
use std::time::Instant;

use arrow_array::RecordBatch;
use serde::Serialize;

use super::{
    fit, parse_param, projectile, ArrivalTerm, Case, Evaluation, FitResult, Method, Objective,
    Options, Parameter, Problem,
};
use crate::analysis::{components, read_series_of, Level, Series};
use crate::error::{Result, WeftError};
use crate::model::io::{read_model, write_model};
use crate::table::{batch, write_table, Col, Provenance};

/// What a fit matches (`--objective`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, clap::ValueEnum)]
#[serde(rename_all = "lowercase")]
pub enum ObjectiveKind {
    // No doc comments here: clap would print them in `weft-fit --help`'s value list.
    // The paper's T over the compared components.
    Displacement,
    // Wave arrival times along the ordered node set.
    Arrival,
    // T plus the arrival-time mismatch.
    Both,
    // The projectile's velocity history alone (P).
    Projectile,
}

/// Settings of one fit, as `weft-fit`'s flags give them (and as its tables' provenance
/// records them). Cases are given by `reference_model`, `reference_history` and `model`
/// in the same order.
#[derive(Debug, Clone, Serialize)]
pub struct Config {
    pub reference_model: Vec<PathBuf>,
    pub reference_history: Vec<PathBuf>,
    pub model: Vec<PathBuf>,
    /// Case names (empty: the candidate model folders' names).
    pub case_name: Vec<String>,
    /// `PART.PROPERTY[,...]:LOWER:UPPER[:log|lin][:INITIAL]` specs.
    pub params: Vec<String>,
    pub set: String,
    pub candidate_set: Option<String>,
    pub components: String,
    pub tolerance: f64,
    /// How reference nodes find their candidate values (position, id, interpolate).
    pub matching: crate::analysis::Matching,
    pub objective: ObjectiveKind,
    pub arrival_component: String,
    pub relative_level: f64,
    /// `COMPONENT:LEVEL` arrival terms at absolute levels (empty: one term,
    /// `arrival_component` at `relative_level` of each node's peak).
    pub arrival: Vec<String>,
    /// The front's slack [s] (as `weft-wavespeed --slack`).
    pub arrival_slack: f64,
    /// `both`: the arrival mismatch's weight beside T.
    pub arrival_weight: f64,
    /// Each case's reference projectile table (empty: the `projectile.parquet` beside its
    /// reference history).
    pub reference_projectile: Vec<PathBuf>,
    /// The weight of the projectile mismatch P added to a displacement or arrival
    /// objective (0: not compared).
    pub projectile_weight: f64,
    pub static_mode: bool,
    pub method: Method,
    pub starts: usize,
    pub max_evaluations: usize,
    pub xtol: f64,
    pub ftol: f64,
    pub initial_step: f64,
    /// `NAME=VALUE`: values to compare fitted parameters with.
    pub expected: Vec<String>,
    /// Worker threads (0: all cores).
    pub threads: usize,
    /// The caller shows no progress; the stage does not use it, the provenance records it.
    pub quiet: bool,
    pub out: PathBuf,
}

/// What a fit reports back to the binary.
#[derive(Debug, Clone)]
pub struct Report {
    pub problem: Problem,
    pub result: FitResult,
    /// Per parameter, the value given with `expected`.
    pub expected: Vec<Option<f64>>,
    /// Solver runs: evaluations × cases.
    pub solver_runs: usize,
    pub wall_seconds: f64,
}

fn check(ok: bool, what: String) -> Result<()> {
    if ok {
        Ok(())
    } else {
        Err(WeftError::input(what))
    }
}

/// The arrival terms of `--objective arrival|both`: each `--arrival COMPONENT:LEVEL` at its
/// absolute level, or without any, `--arrival-component` at `--relative-level` of each
/// node's peak.
fn arrival_terms(c: &Config) -> Result<Vec<ArrivalTerm>> {
    if c.arrival.is_empty() {
        let k = components(&c.arrival_component)?;
        check(
            k.len() == 1,
            format!(
                "--arrival-component takes one component, got `{}`",
                c.arrival_component
            ),
        )?;
        return Ok(vec![ArrivalTerm {
            component: k[0],
            level: Level::Relative(c.relative_level),
        }]);
    }
    c.arrival
        .iter()
        .map(|spec| {
            let bad = |why: &str| {
                WeftError::input(format!("--arrival `{spec}`: {why}")).expected(
                    "COMPONENT:LEVEL, e.g. `ux:5e-5` (the level in m, or m/s for vx … vz)",
                )
            };
            let (comp, level) = spec.split_once(':').ok_or_else(|| bad("no `:`"))?;
            let k = components(comp.trim()).map_err(|_| bad("unknown component"))?;
            if k.len() != 1 {
                return Err(bad("one component per --arrival"));
            }
            let v: f64 = level
                .trim()
                .parse()
                .ok()
                .filter(|v: &f64| v.is_finite() && *v > 0.0)
                .ok_or_else(|| bad("the level is not a finite number > 0"))?;
            Ok(ArrivalTerm {
                component: k[0],
                level: Level::Absolute(v),
            })
        })
        .collect()
}

/// Evaluations a fit may make at most: the length of its progress.
pub fn budget(c: &Config) -> u64 {
    (c.starts * c.max_evaluations) as u64
}

/// Run the stage. `on_eval` sees every evaluation as it completes (progress).
pub fn run(c: &Config, on_eval: &(dyn Fn(&Evaluation) + Sync)) -> Result<Report> {
    check_counts(c)?;
    check_settings(c)?;
    let comps = compared_components(c)?;
    let objective = objective(c)?;
    let read = read_cases(c, &comps, &objective)?;
    let params = parse_params(c, &read.cases)?;
    let expected = expected_values(c, &params)?;
    let problem = Problem {
        cases: read.cases,
        params,
        components: comps,
        tolerance: c.tolerance,
        matching: c.matching,
        static_mode: c.static_mode,
        objective,
        projectile_weight: c.projectile_weight,
    };
    let (result, wall_seconds) = minimise(c, &problem, on_eval)?;
    let mut prov = Provenance::new("fit", serde_json::to_value(c).expect("config serialises"));
    for p in &read.inputs {
        prov = prov.with_input(p)?;
    }
    let report = Report {
        solver_runs: result.evaluations.len() * problem.cases.len(),
        problem,
        result,
        expected,
        wall_seconds,
    };
    write_outputs(c, &report, &prov)?;
    Ok(report)
}

/// As many reference models, reference histories and candidate models (and case names,
/// if any), at least one start and two evaluations.
fn check_counts(c: &Config) -> Result<()> {
    let n = c.model.len();
    check(
        c.reference_model.len() == n && c.reference_history.len() == n,
        format!(
            "{} --reference-model, {} --reference-history and {} --model given; expected as many of each, one per case \
             (hint: repeat the three options in the same order for every case)",
            c.reference_model.len(),
            c.reference_history.len(),
            n
        ),
    )?;
    check(
        c.reference_projectile.is_empty() || c.reference_projectile.len() == n,
        format!(
            "{} --reference-projectile for {n} cases; expected none (each case's projectile.parquet beside its --reference-history) or one per case",
            c.reference_projectile.len()
        ),
    )?;
    check(
        c.case_name.is_empty() || c.case_name.len() == n,
        format!(
            "{} --case-name for {n} cases; expected none or one per case",
            c.case_name.len()
        ),
    )?;
    check(
        c.starts >= 1 && c.max_evaluations >= 2,
        format!(
            "--starts {} and --max-evaluations {}: expected at least 1 start and 2 evaluations",
            c.starts, c.max_evaluations
        ),
    )
}

/// The numeric settings, whether or not this objective or method uses them (a value that
/// could never be valid is refused, not silently ignored).
fn check_settings(c: &Config) -> Result<()> {
    check(
        c.relative_level > 0.0 && c.relative_level <= 1.0,
        format!(
            "--relative-level {}: expected a fraction of the peak in (0, 1]",
            c.relative_level
        ),
    )?;
    check(
        c.arrival_slack >= 0.0 && c.arrival_slack.is_finite(),
        format!(
            "--arrival-slack {}: expected a time ≥ 0 in s",
            c.arrival_slack
        ),
    )?;
    check(
        c.arrival_weight > 0.0 && c.arrival_weight.is_finite(),
        format!(
            "--arrival-weight {}: expected a finite weight > 0",
            c.arrival_weight
        ),
    )?;
    check(
        c.projectile_weight >= 0.0 && c.projectile_weight.is_finite(),
        format!(
            "--projectile-weight {}: expected a finite weight ≥ 0 of the projectile mismatch P (0: not compared)",
            c.projectile_weight
        ),
    )?;
    check(
        c.xtol > 0.0 && c.xtol < 1.0,
        format!(
            "--xtol {}: expected a step on the unit parameter box, 0 < xtol < 1",
            c.xtol
        ),
    )?;
    check(
        c.ftol >= 0.0 && c.ftol < 1.0,
        format!(
            "--ftol {}: expected a relative change of T, 0 ≤ ftol < 1 (0: never stop on it)",
            c.ftol
        ),
    )?;
    check(
        c.initial_step > 0.0 && c.initial_step <= 1.0,
        format!(
            "--initial-step {}: expected a first step on the unit parameter box, 0 < ρ ≤ 1",
            c.initial_step
        ),
    )
}

/// The displacement components T compares (`--components`).
fn compared_components(c: &Config) -> Result<Vec<usize>> {
    let comps = components(&c.components)?;
    check(
        comps.iter().all(|&k| k < 3),
        format!(
            "--components `{}`: a fit compares displacements; expected some of ux, uy, uz",
            c.components
        ),
    )?;
    Ok(comps)
}

/// What the fit matches (`--objective`), with its arrival terms, slack and weight checked.
fn objective(c: &Config) -> Result<Objective> {
    Ok(match c.objective {
        ObjectiveKind::Displacement => {
            check(
                c.arrival.is_empty(),
                format!(
                    "--arrival {} with --objective displacement; expected --objective arrival or both",
                    c.arrival.join(" --arrival ")
                ),
            )?;
            Objective::Displacement
        }
        ObjectiveKind::Projectile => {
            check(
                c.arrival.is_empty(),
                format!(
                    "--arrival {} with --objective projectile; expected --objective arrival or both",
                    c.arrival.join(" --arrival ")
                ),
            )?;
            check(
                c.projectile_weight == 0.0,
                format!(
                    "--projectile-weight {} with --objective projectile; expected it beside --objective displacement, arrival or both (projectile minimises P alone)",
                    c.projectile_weight
                ),
            )?;
            Objective::Projectile
        }
        ObjectiveKind::Arrival | ObjectiveKind::Both => {
            let terms = arrival_terms(c)?;
            if c.objective == ObjectiveKind::Arrival {
                Objective::Arrival {
                    terms,
                    slack: c.arrival_slack,
                }
            } else {
                Objective::Both {
                    terms,
                    slack: c.arrival_slack,
                    weight: c.arrival_weight,
                }
            }
        }
    })
}

/// The cases as read, and the files the provenance records as the fit's inputs.
struct ReadCases {
    cases: Vec<Case>,
    /// Each case's reference history (unless the projectile alone is compared), its
    /// reference projectile table (when compared), then its candidate model's tables.
    inputs: Vec<PathBuf>,
}

/// Read each case: the reference's series of the components the objective needs (the
/// compared ones, then the arrival terms' others; none with the projectile alone), its
/// projectile's velocity history when compared, and the candidate model.
fn read_cases(c: &Config, comps: &[usize], objective: &Objective) -> Result<ReadCases> {
    let projectile_only = matches!(objective, Objective::Projectile);
    let compares_projectile = projectile_only || c.projectile_weight > 0.0;
    if let (false, Some(p)) = (compares_projectile, c.reference_projectile.first()) {
        return Err(WeftError::input(format!(
            "--reference-projectile {} without a projectile objective",
            p.display()
        ))
        .expected("--objective projectile or --projectile-weight > 0"));
    }
    let mut cases = vec![];
    let mut prov_inputs: Vec<PathBuf> = vec![];
    for k in 0..c.model.len() {
        let mut needed = comps.to_vec();
        for a in objective.arrival_terms() {
            if !needed.contains(&a.component) {
                needed.push(a.component);
            }
        }
        let reference = if projectile_only {
            Series {
                t: vec![],
                node_id: vec![],
                x0: vec![],
                values: vec![],
            }
        } else {
            prov_inputs.push(c.reference_history[k].clone());
            read_series_of(
                &c.reference_model[k],
                &c.reference_history[k],
                &c.set,
                &needed,
            )
            .map_err(|e| e.context(format!("reference of case {}", k + 1)))?
        };
        let projectile = if compares_projectile {
            let path = projectile::reference_path(
                &c.reference_history[k],
                c.reference_projectile.get(k).map(|p| p.as_path()),
            );
            let h = projectile::read_reference(&path)
                .map_err(|e| e.context(format!("reference projectile of case {}", k + 1)))?;
            prov_inputs.push(path);
            Some(h)
        } else {
            None
        };
        let model = read_model(&c.model[k])
            .map_err(|e| e.context(format!("candidate model of case {}", k + 1)))?;
        prov_inputs.extend(parquet_files(&c.model[k])?);
        cases.push(Case {
            name: case_name(c, k),
            reference,
            model,
            set: c.candidate_set.clone().unwrap_or_else(|| c.set.clone()),
            projectile,
        });
    }
    Ok(ReadCases {
        cases,
        inputs: prov_inputs,
    })
}

/// The fitted parameters, parsed against the first candidate; every case must have the
/// parts.
fn parse_params(c: &Config, cases: &[Case]) -> Result<Vec<Parameter>> {
    let params = c
        .params
        .iter()
        .map(|s| parse_param(s, &cases[0].model))
        .collect::<Result<Vec<_>>>()?;
    for case in &cases[1..] {
        for s in &c.params {
            parse_param(s, &case.model).map_err(|e| e.context(format!("case `{}`", case.name)))?;
        }
    }
    Ok(params)
}

/// Per parameter, the value `--expected NAME=VALUE` gives it.
fn expected_values(c: &Config, params: &[Parameter]) -> Result<Vec<Option<f64>>> {
    let mut expected = vec![None; params.len()];
    for e in &c.expected {
        let (name, value) = e.split_once('=').ok_or_else(|| {
            WeftError::input(format!(
                "--expected `{e}`: expected NAME=VALUE, NAME one of the --param names"
            ))
        })?;
        let k = params
            .iter()
            .position(|p| p.name == name.trim())
            .ok_or_else(|| {
                WeftError::input(format!(
                    "--expected `{e}`: no fitted parameter is named `{name}` (expected one of {})",
                    params
                        .iter()
                        .map(|p| format!("`{}`", p.name))
                        .collect::<Vec<_>>()
                        .join(", ")
                ))
            })?;
        let v: f64 = value
            .trim()
            .parse()
            .ok()
            .filter(|v: &f64| v.is_finite())
            .ok_or_else(|| {
                WeftError::input(format!(
                    "--expected `{e}`: `{value}` is not a finite number"
                ))
            })?;
        expected[k] = Some(v);
    }
    Ok(expected)
}

/// Minimise the objective on `c.threads` worker threads: the result and its wall time [s].
fn minimise(
    c: &Config,
    problem: &Problem,
    on_eval: &(dyn Fn(&Evaluation) + Sync),
) -> Result<(FitResult, f64)> {
    let opts = Options {
        method: c.method,
        starts: c.starts,
        max_evaluations: c.max_evaluations,
        xtol: c.xtol,
        ftol: c.ftol,
        initial_step: c.initial_step,
        ..Default::default()
    };
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(c.threads)
        .build()
        .map_err(|e| WeftError::input(format!("cannot start the worker threads: {e}")))?;

    let t0 = Instant::now();
    let result = pool
        .install(|| fit(problem, &opts, on_eval))
        .map_err(|e| e.context("the fit failed; nothing was written"))?;
    Ok((result, t0.elapsed().as_secs_f64()))
}

/// Write `fit_trace.parquet`, `fit_result.parquet`, `fit_row.parquet` and the fitted
/// model of each case under `models/CASE`.
fn write_outputs(c: &Config, report: &Report, prov: &Provenance) -> Result<()> {
    write_table(&c.out.join("fit_trace.parquet"), &trace_table(report), prov)?;
    write_table(
        &c.out.join("fit_result.parquet"),
        &result_table(report, c),
        prov,
    )?;
    write_table(&c.out.join("fit_row.parquet"), &row_table(report, c), prov)?;
    for (k, case) in report.problem.cases.iter().enumerate() {
        let m = report.problem.model_at(k, &report.result.x);
        let dir = c.out.join("models").join(&case.name);
        write_model(&m, &dir, prov)
            .map_err(|e| e.context(format!("cannot write the fitted model `{}`", dir.display())))?;
    }
    Ok(())
}

/// Case `k`'s name: as given, else its candidate folder's name (numbered when two
/// candidates share a folder name).
fn case_name(c: &Config, k: usize) -> String {
    c.case_name.get(k).cloned().unwrap_or_else(|| {
        let base = c.model[k]
            .file_name()
            .map(|s| s.to_string_lossy().to_string())
            .unwrap_or_else(|| format!("case{}", k + 1));
        if c.model
            .iter()
            .filter(|m| m.file_name() == c.model[k].file_name())
            .count()
            > 1
        {
            format!("{base}-{}", k + 1)
        } else {
            base
        }
    })
}

/// `fit_trace.parquet`: one row per evaluation, ordered by start, then evaluation:
/// `evaluation`, `start`, `start_evaluation`, one column per parameter (its name),
/// `T`, `best_T` (the running minimum), `projectile_mismatch` (P, mean over the cases;
/// null when not compared or the solve failed), `wall_seconds`, `error` (null when it ran).
pub fn trace_table(r: &Report) -> RecordBatch {
    let ev = &r.result.evaluations;
    let mut running = f64::INFINITY;
    let mut cols = vec![
        Col::I64("evaluation", (0..ev.len() as i64).collect()),
        Col::I64("start", ev.iter().map(|e| e.start as i64).collect()),
        Col::I64(
            "start_evaluation",
            ev.iter().map(|e| e.index as i64).collect(),
        ),
    ];
    for (i, p) in r.problem.params.iter().enumerate() {
        cols.push(Col::F64Named(
            p.name.clone(),
            ev.iter().map(|e| e.x[i]).collect(),
        ));
    }
    cols.push(Col::F64("T", ev.iter().map(|e| e.t).collect()));
    cols.push(Col::F64(
        "best_T",
        ev.iter()
            .map(|e| {
                running = running.min(e.t);
                running
            })
            .collect(),
    ));
    cols.push(Col::OptF64(
        "projectile_mismatch",
        ev.iter().map(|e| e.projectile).collect(),
    ));
    cols.push(Col::F64(
        "wall_seconds",
        ev.iter().map(|e| e.seconds).collect(),
    ));
    cols.push(Col::OptStr(
        "error",
        ev.iter().map(|e| e.error.clone()).collect(),
    ));
    batch(cols)
}

/// `fit_result.parquet`: one row per parameter: `name`, `value`, `lower`, `upper`,
/// `scale`, `initial`, `at_bound`, `expected`, `relative_difference`, and the fit's
/// `T`, `T_initial`, `evaluations`, `solver_runs`, `method`, `static`, `wall_seconds`
/// repeated on every row.
pub fn result_table(r: &Report, c: &Config) -> RecordBatch {
    let params = &r.problem.params;
    let x = &r.result.x;
    let np = params.len();
    let rep = |v: f64| vec![v; np];
    batch(vec![
        Col::Str("name", params.iter().map(|p| p.name.clone()).collect()),
        Col::F64("value", x.clone()),
        Col::F64("lower", params.iter().map(|p| p.lower).collect()),
        Col::F64("upper", params.iter().map(|p| p.upper).collect()),
        Col::Str(
            "scale",
            params
                .iter()
                .map(|p| if p.log { "log" } else { "lin" }.to_string())
                .collect(),
        ),
        Col::F64("initial", params.iter().map(|p| p.initial).collect()),
        Col::Bool(
            "at_bound",
            params
                .iter()
                .zip(x)
                .map(|(p, &v)| {
                    let z = p.unit(v);
                    !(1e-6..=1.0 - 1e-6).contains(&z)
                })
                .collect(),
        ),
        Col::OptF64("expected", r.expected.clone()),
        Col::OptF64(
            "relative_difference",
            r.expected
                .iter()
                .zip(x)
                .map(|(e, v)| e.map(|e| (v - e) / e))
                .collect(),
        ),
        Col::F64("T", rep(r.result.t)),
        Col::F64("T_initial", rep(r.result.t_initial)),
        Col::I64("evaluations", vec![r.result.evaluations.len() as i64; np]),
        Col::I64("solver_runs", vec![r.solver_runs as i64; np]),
        Col::Str("method", vec![format!("{:?}", c.method).to_lowercase(); np]),
        Col::Bool("static", vec![c.static_mode; np]),
        Col::F64("wall_seconds", rep(r.wall_seconds)),
    ])
}

/// `fit_row.parquet`: the result as one row, for sweeps (`weft gather` joins one row
/// per instance into a table x → y): per parameter a column named as the parameter (its
/// fitted value) and `NAME_expected` (the --expected value, null when none), then `T`,
/// `T_initial`, `evaluations`, `static`.
pub fn row_table(r: &Report, c: &Config) -> RecordBatch {
    let mut cols = vec![];
    for (i, p) in r.problem.params.iter().enumerate() {
        cols.push(Col::F64Named(p.name.clone(), vec![r.result.x[i]]));
    }
    for (i, p) in r.problem.params.iter().enumerate() {
        cols.push(Col::OptF64Named(
            format!("{}_expected", p.name),
            vec![r.expected[i]],
        ));
    }
    cols.push(Col::F64("T", vec![r.result.t]));
    cols.push(Col::F64("T_initial", vec![r.result.t_initial]));
    cols.push(Col::I64(
        "evaluations",
        vec![r.result.evaluations.len() as i64],
    ));
    cols.push(Col::Bool("static", vec![c.static_mode]));
    batch(cols)
}

/// The model's tables, sorted: the inputs the provenance records.
fn parquet_files(dir: &Path) -> Result<Vec<PathBuf>> {
    let mut v = vec![];
    for e in std::fs::read_dir(dir).map_err(|e| WeftError::io(dir, e))? {
        let p = e.map_err(|e| WeftError::io(dir, e))?.path();
        if p.extension().is_some_and(|x| x == "parquet") {
            v.push(p);
        }
    }
    v.sort();
    Ok(v)
}
