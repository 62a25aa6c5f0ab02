//! The `simulate` stage: read a model folder, run the explicit solver, write
//! `history.parquet`, `energy.parquet` and `summary.parquet` atomically (and, when asked,
//! `elements.parquet`: [`crate::element_results`]).

use std::path::{Path, PathBuf};
use std::time::Instant;

use serde::Serialize;

use crate::element_results::{ElementResults, WithElementResults};
use crate::error::{Result, WeftError};
use crate::model::io::read_tables;
use crate::model::striker::check_striking_speed;
use crate::model::{ElementKind, Model, ValidatedModel};
use crate::solver::failure::FailureEvent;
use crate::solver::output::ParquetSink;
use crate::solver::{RunStats, Solver};
use crate::table::{batch, write_table, Col, Provenance};

/// Settings of one `simulate` run; `None` keeps the model's `analysis.parquet` value.
#[derive(Debug, Clone, Default, Serialize)]
pub struct Config {
    pub model: PathBuf,
    pub out: PathBuf,
    pub threads: Option<usize>,
    pub end_time: Option<f64>,
    pub output_interval: Option<f64>,
    pub dt_safety: Option<f64>,
    pub time_step: Option<f64>,
    pub target_time_step: Option<f64>,
    pub mass_damping: Option<f64>,
    pub history_sets: Option<Vec<String>>,
    pub max_energy_error: Option<f64>,
    /// Step budget of an explicit run (default [`DEFAULT_MAX_STEPS`]): a run that would
    /// need more is refused before it starts, naming the element that sets the step
    /// (LS-DYNA stops below a minimum step, DTMIN, for the same reason).
    #[serde(default)]
    pub max_steps: Option<u64>,
    /// Linear static solve instead of the explicit dynamic run.
    #[serde(rename = "static")]
    pub static_solve: bool,
    /// Parts whose element results go to `elements.parquet` at the output times (`all`:
    /// every part); empty: no element results.
    #[serde(default)]
    pub element_results: Vec<String>,
    /// The striking speed of every projectile [m/s], along its velocity's direction (or
    /// its axis when it starts at rest): one model, many impacts (a ballistic sweep).
    #[serde(default)]
    pub projectile_velocity: Option<f64>,
    /// End the run once the projectile's outcome is decided (analysis `stop_on_outcome`).
    #[serde(default)]
    pub stop_on_outcome: Option<bool>,
    /// Subcycle the slow solids (analysis `subcycle`).
    #[serde(default)]
    pub subcycle: Option<bool>,
}

/// What a run reports back to the binary.
#[derive(Debug, Clone)]
pub struct Report {
    pub stats: RunStats,
    pub dt: f64,
    pub dt_stable: f64,
    pub controlling: String,
    pub added_mass: f64,
    pub added_fraction: f64,
    pub out: PathBuf,
    /// Contact between parts (`contacts.parquet`), when the model has some.
    pub contact: Option<crate::solver::contact::ContactReport>,
    /// A line on failures and the projectile's outcome, when the model can fail or has
    /// fabric layers and a projectile.
    pub ballistic: Option<String>,
    /// A line on the subcycle, when the run subcycled (`analysis.subcycle`).
    pub subcycle: Option<String>,
}

/// Apply command-line overrides to a model's analysis settings.
pub fn apply_overrides(m: &mut Model, c: &Config) {
    let a = &mut m.analysis;
    if let Some(v) = c.end_time {
        a.end_time = v;
    }
    if let Some(v) = c.output_interval {
        a.output_interval = v;
    }
    if let Some(v) = c.dt_safety {
        a.dt_safety = v;
    }
    if let Some(v) = c.time_step {
        a.time_step = Some(v);
    }
    if let Some(v) = c.target_time_step {
        a.target_time_step = Some(v);
    }
    if let Some(v) = c.mass_damping {
        a.mass_damping = v;
    }
    if let Some(v) = &c.history_sets {
        a.history_sets = v.clone();
    }
    if let Some(v) = c.max_energy_error {
        a.max_energy_error = v;
    }
    if let Some(v) = c.stop_on_outcome {
        a.stop_on_outcome = v;
    }
    if let Some(v) = c.subcycle {
        a.subcycle = v;
    }
    if let Some(speed) = c.projectile_velocity {
        m.set_striking_speed(speed);
    }
}

/// Checks the overrides that have no home in the model's own validation.
fn check_overrides(m: &Model, c: &Config) -> Result<()> {
    if let Some(v) = c.projectile_velocity {
        check_striking_speed("--projectile-velocity", v)?;
        if !m.has_striker() {
            return Err(WeftError::input(format!(
                "--projectile-velocity {v} for a model without a projectile"
            ))
            .in_file(c.model.join("projectile.parquet"))
            .expected("a model with a projectile, or a deformable bullet (node set `bullet`): weft-weave woven or woven-reduced"));
        }
    }
    Ok(())
}

/// Human-readable name of the element controlling the step.
pub fn controlling_name(s: &Solver) -> String {
    let (step, ids) = (s.time_step(), s.node_ids());
    match step.element {
        Some((k, id)) => format!("{} {id} (node {})", k.name(), ids[step.node]),
        None => format!("node {}", ids[step.node]),
    }
}

/// Default step budget of an explicit run: 10⁹ steps, days for any model of more than a
/// few elements; a Young's modulus of 10³⁰⁸ in a rod asks for ~10¹⁵⁰.
pub const DEFAULT_MAX_STEPS: u64 = 1_000_000_000;

/// Run the stage. `progress` receives the fraction of simulated time done.
pub fn run(c: &Config, progress: &mut (dyn FnMut(f64) + Send)) -> Result<Report> {
    let t_setup = Instant::now();
    let m = read_with_overrides(c)?;
    let threads = c.threads.unwrap_or(0);
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .map_err(|e| WeftError::input(format!("cannot start {threads} threads: {e}")))?;
    let prov = provenance(c)?;
    let mut solver = Solver::from_validated(&m)?;
    if !c.static_solve {
        check_step_budget(c, &m, &solver)?;
    }
    let mut elements = (!c.element_results.is_empty())
        .then(|| ElementResults::new(&m, &c.element_results, solver.output_nodes()))
        .transpose()?;
    if let Some(e) = &elements {
        // The selected hexahedra's states come from the run itself (path-dependent).
        solver.sample_states_of(ElementKind::Hex, e.hex_elements());
    }
    std::fs::create_dir_all(&c.out).map_err(|e| WeftError::io(&c.out, e))?;
    if c.static_solve {
        return run_static(c, &m, &solver, &prov, t_setup, elements);
    }
    let setup = t_setup.elapsed();
    let mut sink = ParquetSink::create(&c.out, solver.node_ids().to_vec(), &prov)?;
    if !solver.crater().is_empty() {
        sink = sink.with_crater();
    }
    let (sink, result) = match elements.as_mut() {
        Some(results) => {
            let mut w = WithElementResults {
                inner: sink,
                results,
            };
            let r = pool.install(|| solver.run(&mut w, progress));
            (w.inner, r)
        }
        None => {
            let mut sink = sink;
            let r = pool.install(|| solver.run(&mut sink, progress));
            (sink, r)
        }
    };
    // A run that stops (NaN, instability, energy error, a step guard) keeps what it
    // computed: the tables up to the last good output sample, `status = stopped` and the
    // reason in the summary, and the error still returned (a non-zero exit code).
    let (mut stats, stopped) = match result {
        Ok(st) => (st, None),
        Err(e @ WeftError::Numerical { .. }) => (solver.stats_so_far(), Some(e)),
        Err(e) => return Err(e),
    };
    stats.threads = pool.current_num_threads();
    stats.times.setup = setup;
    let status = match &stopped {
        None => Status::Completed,
        Some(e) => Status::Stopped(e.to_string()),
    };
    let t_write = Instant::now();
    sink.finish(&c.out, &prov)?;
    write_element_results(&c.out, elements, &prov)?;
    write_failures(
        &c.out,
        &m,
        failure_events(&solver, &status, stats.end_time),
        &prov,
    )?;
    stats.times.output += t_write.elapsed();
    let report = Report::of(c, &solver, stats);
    write_summary(&c.out, &report, &solver, &m, &status, &prov)?;
    if let Some(e) = stopped {
        return Err(e.context(format!(
            "the run stopped; the tables up to t = {:.6e} s are in `{}` (status = stopped in summary.parquet)",
            report.stats.end_time,
            c.out.display()
        )));
    }
    Ok(report)
}

/// The model folder's tables with the command line's overrides, validated once.
fn read_with_overrides(c: &Config) -> Result<ValidatedModel> {
    let mut m = read_tables(&c.model)?;
    check_overrides(&m, c)?;
    apply_overrides(&mut m, c);
    m.validated().map_err(|e| e.in_file(&c.model))
}

/// The run's provenance: its settings and every table of the model folder.
fn provenance(c: &Config) -> Result<Provenance> {
    let mut prov = Provenance::new(
        "simulate",
        serde_json::to_value(c).expect("config serialises"),
    );
    for entry in std::fs::read_dir(&c.model).map_err(|e| WeftError::io(&c.model, e))? {
        let p = entry.map_err(|e| WeftError::io(&c.model, e))?.path();
        if p.extension().is_some_and(|x| x == "parquet") {
            prov = prov.with_input(&p)?;
        }
    }
    Ok(prov)
}

/// Refuses an explicit run that would need more steps than the budget
/// ([`DEFAULT_MAX_STEPS`] or `--max-steps`), naming the element that sets the step.
fn check_step_budget(c: &Config, m: &Model, solver: &Solver) -> Result<()> {
    let budget = c.max_steps.unwrap_or(DEFAULT_MAX_STEPS);
    let step = solver.time_step();
    let steps = (m.analysis.end_time / step.dt).ceil();
    if steps <= budget as f64 {
        return Ok(());
    }
    Err(WeftError::input(format!(
        "the run would take {steps:.3e} steps of {:.3e} s to reach the end time {:e} s: more than the budget of {budget} steps",
        step.dt, m.analysis.end_time
    ))
    .hint(format!(
        "the step is set by {} (stable step {:.3e} s): check its Young's modulus, density and size (or a link's stiffness and masses){}, or raise --max-steps",
        controlling_name(solver),
        step.dt_stable,
        // Mass damping shortens the step: Δt ≤ (2/ω)(√(1+ξ²) − ξ) ≈ 1/ξω for ξ ≫ 1.
        if m.analysis.mass_damping * step.dt_stable > 0.1 {
            format!(
                ", and the mass damping α = {:e} 1/s (analysis.parquet, column mass_damping), which shortens the step to about 2/α when it is large",
                m.analysis.mass_damping
            )
        } else {
            String::new()
        }
    )))
}

impl Report {
    /// The report of an explicit run of `solver` into `c.out`.
    fn of(c: &Config, solver: &Solver, stats: RunStats) -> Report {
        let sc = solver.mass_scaling().cloned().unwrap_or_default();
        let surfaces = &solver.operator().surfaces;
        Report {
            dt: solver.time_step().dt,
            dt_stable: solver.time_step().dt_stable,
            controlling: controlling_name(solver),
            added_mass: sc.added_mass,
            added_fraction: sc.added_fraction,
            out: c.out.clone(),
            contact: (!surfaces.is_empty()).then(|| surfaces.report(solver.node_ids())),
            ballistic: ballistic_line(solver),
            subcycle: solver.subcycle().map(|c| {
                format!(
                    "subcycle: {} hexahedra on a slow step of {} steps ({} at the end), {} slow samples",
                    c.elements, c.first_ratio, c.ratio, c.samples
                )
            }),
            stats,
        }
    }
}

/// The line the binary prints on failures and the outcome.
fn ballistic_line(s: &Solver) -> Option<String> {
    use crate::solver::watch::Outcome;
    let w = s.watch();
    if !s.failure_log().active && !(w.n_layers > 0 && w.axis().is_some()) {
        return None;
    }
    let eroded = s
        .failure_log()
        .events
        .iter()
        .filter(|e| e.failure.eroded)
        .count();
    let broken: u32 = (1..=w.n_layers).map(|l| w.counts(l).1).sum();
    let outcome = match w.outcome {
        Outcome::Undecided => "outcome undecided at the end time".to_string(),
        Outcome::Arrested { time } => format!("projectile arrested at {time:.4e} s"),
        Outcome::Perforated {
            time,
            residual_velocity,
        } => format!("perforated at {time:.4e} s, residual velocity {residual_velocity:.2} m/s"),
    };
    Some(format!(
        "failures: {eroded} elements, {broken} yarns broken over {} layers; {outcome}; back-face deflection peak {:.3e} m",
        w.n_layers, w.back_face_peak
    ))
}

/// How a run ended.
#[derive(Debug, Clone, PartialEq)]
pub enum Status {
    Completed,
    /// Stopped by the solver, with the reason.
    Stopped(String),
}

/// The failures a run's tables report: every one of a completed run; of a stopped run,
/// those up to its last output sample at `end` (the time its other tables end at), not
/// those of the steps between that sample and the stop. `None` when the model cannot fail.
fn failure_events<'a>(s: &'a Solver, status: &Status, end: f64) -> Option<&'a [FailureEvent]> {
    let log = s.failure_log();
    if !log.active {
        return None;
    }
    Some(match status {
        Status::Completed => &log.events,
        // The log is in the order of the failures, so in time.
        Status::Stopped(_) => {
            let n = log.events.partition_point(|e| e.time <= end);
            &log.events[..n]
        }
    })
}

/// `failures.parquet`: one row per failure of `events`, in the order they happened, when
/// the model can fail; otherwise (`None`) a stale one from an earlier run into the same
/// folder is removed.
fn write_failures(
    out: &Path,
    m: &Model,
    events: Option<&[FailureEvent]>,
    prov: &Provenance,
) -> Result<()> {
    let path = out.join("failures.parquet");
    let Some(ev) = events else {
        if path.exists() {
            std::fs::remove_file(&path).map_err(|e| WeftError::io(&path, e))?;
        }
        return Ok(());
    };
    // Each failure's element row in its table: the family's index for trusses and
    // membranes, the id's row for links (their families split the link table).
    let row = |e: &FailureEvent| -> Option<usize> {
        let b = m.block(e.failure.kind)?;
        if e.failure.kind == crate::model::ElementKind::Link {
            b.id.iter().position(|&i| i == e.id)
        } else {
            Some(e.failure.element)
        }
    };
    let rows: Vec<Option<usize>> = ev.iter().map(row).collect();
    let block = |e: &FailureEvent| m.block(e.failure.kind);
    write_table(
        &path,
        &batch(vec![
            Col::F64("t", ev.iter().map(|e| e.time).collect()),
            Col::I64("step", ev.iter().map(|e| e.step as i64).collect()),
            Col::Str(
                "element_kind",
                ev.iter()
                    .map(|e| e.failure.kind.name().to_string())
                    .collect(),
            ),
            Col::I64("element_id", ev.iter().map(|e| e.id).collect()),
            Col::Str(
                "part",
                ev.iter()
                    .zip(&rows)
                    .map(|(e, r)| {
                        r.and_then(|r| block(e).map(|b| m.parts[b.part[r]].name.clone()))
                            .unwrap_or_default()
                    })
                    .collect(),
            ),
            Col::OptI64(
                "layer",
                ev.iter()
                    .zip(&rows)
                    .map(|(e, r)| r.and_then(|r| block(e)?.layer_of(r)))
                    .collect(),
            ),
            Col::OptI64(
                "yarn",
                ev.iter()
                    .zip(&rows)
                    .map(|(e, r)| r.and_then(|r| block(e)?.yarn_of(r)))
                    .collect(),
            ),
            Col::Str(
                "criterion",
                ev.iter()
                    .map(|e| e.failure.criterion.name().to_string())
                    .collect(),
            ),
            Col::F64("value", ev.iter().map(|e| e.failure.value).collect()),
            Col::F64("limit", ev.iter().map(|e| e.failure.limit).collect()),
            Col::Bool("eroded", ev.iter().map(|e| e.failure.eroded).collect()),
            Col::F64("energy", ev.iter().map(|e| e.failure.energy).collect()),
        ]),
        prov,
    )
}

/// `elements.parquet` when element results were asked for; otherwise a stale one from
/// an earlier run into the same folder is removed (weft-vtk would read it).
fn write_element_results(
    out: &Path,
    elements: Option<ElementResults>,
    prov: &Provenance,
) -> Result<()> {
    let path = out.join("elements.parquet");
    match elements {
        Some(e) => e.write(&path, prov),
        None if path.exists() => std::fs::remove_file(&path).map_err(|e| WeftError::io(&path, e)),
        None => Ok(()),
    }
}

/// The static branch: K u = F, one `history` sample at t = 0, a static summary.
fn run_static(
    c: &Config,
    m: &Model,
    solver: &Solver,
    prov: &Provenance,
    t_setup: Instant,
    mut elements: Option<ElementResults>,
) -> Result<Report> {
    let r = solver.solve_static(m)?;
    let mut sink = ParquetSink::create(&c.out, solver.node_ids().to_vec(), prov)?;
    let nodes = solver.output_nodes();
    let u: Vec<[f64; 3]> = nodes.iter().map(|&i| r.u[i]).collect();
    let v = vec![[0.0; 3]; nodes.len()];
    crate::solver::Sink::history(&mut sink, 0.0, nodes, &u, &v)?;
    if let Some(e) = elements.as_mut() {
        e.sample(0.0, &u, &v);
    }
    sink.finish_history_only()?;
    write_element_results(&c.out, elements, prov)?;
    let elements = solver.families().updated_elements();
    write_table(
        &c.out.join("summary.parquet"),
        &batch(vec![
            Col::Str("analysis", vec!["static".into()]),
            Col::I64("dofs", vec![r.dofs as i64]),
            Col::I64("held_dofs", vec![r.held as i64]),
            Col::I64("nonzeros", vec![r.nonzeros as i64]),
            Col::I64("nodes", vec![solver.node_ids().len() as i64]),
            Col::I64("elements", vec![elements as i64]),
            Col::F64("model_mass", vec![solver.physical_mass()]),
            Col::F64(
                "wall_time_setup",
                vec![t_setup.elapsed().as_secs_f64() - r.assemble_seconds - r.solve_seconds],
            ),
            Col::F64("wall_time_assemble", vec![r.assemble_seconds]),
            Col::F64("wall_time_solve", vec![r.solve_seconds]),
        ]),
        prov,
    )?;
    let stats = crate::solver::RunStats {
        steps: 0,
        end_time: 0.0,
        times: Default::default(),
        threads: 1,
        max_balance_error_relative: 0.0,
        final_energies: Default::default(),
        elements,
        nodes: solver.node_ids().len(),
    };
    eprintln!(
        "weft-simulate --static: {} equations ({} held without stiffness), {} non-zeros; assemble {:.3} s, solve {:.3} s",
        r.dofs, r.held, r.nonzeros, r.assemble_seconds, r.solve_seconds
    );
    Ok(Report {
        stats,
        dt: 0.0,
        dt_stable: 0.0,
        controlling: String::new(),
        added_mass: 0.0,
        added_fraction: 0.0,
        out: c.out.clone(),
        contact: None,
        ballistic: None,
        subcycle: None,
    })
}

/// `summary.parquet`: one row describing the run. Written last, so its presence means
/// the run completed.
pub fn write_summary(
    out: &Path,
    r: &Report,
    s: &Solver,
    m: &Model,
    status: &Status,
    prov: &Provenance,
) -> Result<()> {
    let st = &r.stats;
    let mut cols = run_columns(r, s, st);
    cols.extend(ballistic_columns(s, m, status, r.stats.end_time));
    write_table(&out.join("summary.parquet"), &batch(cols), prov)
}

/// The summary's columns about the run itself: step, controlling element, masses, sizes,
/// wall times, contact, throughput, balance.
fn run_columns(r: &Report, s: &Solver, st: &RunStats) -> Vec<Col> {
    let (kind, id) = match s.time_step().element {
        Some((k, id)) => (k.name().to_string(), id),
        None => (String::new(), -1),
    };
    let sc = s.mass_scaling().cloned();
    vec![
        Col::Str("analysis", vec!["explicit".into()]),
        Col::I64("steps", vec![st.steps as i64]),
        Col::F64("end_time", vec![st.end_time]),
        Col::F64("dt", vec![r.dt]),
        Col::F64("dt_stable", vec![r.dt_stable]),
        Col::F64("dt_min", vec![s.time_step().dt_min]),
        Col::Str("controlling_kind", vec![kind]),
        Col::I64("controlling_element", vec![id]),
        Col::I64("controlling_node", vec![s.node_ids()[s.time_step().node]]),
        Col::OptI64(
            "subcycle_ratio",
            vec![s.subcycle().map(|c| c.first_ratio as i64)],
        ),
        Col::OptI64(
            "subcycle_ratio_min",
            vec![s.subcycle().map(|c| c.ratio as i64)],
        ),
        Col::I64(
            "slow_elements",
            vec![s.subcycle().map_or(0, |c| c.elements as i64)],
        ),
        Col::I64(
            "slow_samples",
            vec![s.subcycle().map_or(0, |c| c.samples as i64)],
        ),
        Col::OptF64(
            "dt_stable_unscaled",
            vec![sc.as_ref().map(|x| x.dt_stable_unscaled)],
        ),
        Col::F64("added_mass", vec![r.added_mass]),
        Col::F64("added_mass_fraction", vec![r.added_fraction]),
        Col::F64("model_mass", vec![s.physical_mass()]),
        Col::I64("nodes", vec![st.nodes as i64]),
        Col::I64("elements", vec![st.elements as i64]),
        Col::I64("threads", vec![st.threads as i64]),
        Col::F64("wall_time_setup", vec![st.times.setup.as_secs_f64()]),
        Col::F64("wall_time_loads", vec![st.times.loads.as_secs_f64()]),
        Col::F64("wall_time_forces", vec![st.times.forces.as_secs_f64()]),
        Col::F64("wall_time_update", vec![st.times.update.as_secs_f64()]),
        Col::F64("wall_time_output", vec![st.times.output.as_secs_f64()]),
        Col::F64("wall_time_contact", vec![st.times.contact.as_secs_f64()]),
        Col::I64(
            "contact_builds",
            vec![r.contact.as_ref().map_or(0, |c| c.builds as i64)],
        ),
        Col::I64(
            "contact_active",
            vec![r.contact.as_ref().map_or(0, |c| c.active as i64)],
        ),
        Col::I64(
            "initial_penetrations",
            vec![r
                .contact
                .as_ref()
                .map_or(0, |c| c.initial_penetrations as i64)],
        ),
        Col::OptF64(
            "max_initial_penetration",
            vec![r.contact.as_ref().and_then(|c| c.deepest.map(|d| d.3))],
        ),
        Col::F64(
            "element_updates_per_second",
            vec![st.element_updates_per_second()],
        ),
        Col::F64(
            "max_balance_error_relative",
            vec![st.max_balance_error_relative],
        ),
    ]
}

/// The fabric's areal density [kg/m²]: per layer, the `ply_areal_density` of its yarn
/// parts (weft-weave woven writes it), summed over the layers; `None` without layers or
/// when a layer's parts give none.
fn areal_density(s: &Solver, m: &Model) -> Option<f64> {
    let w = s.watch();
    let mut per_layer: Vec<Option<f64>> = vec![None; w.n_layers];
    for b in m.elements.values() {
        for e in 0..b.len() {
            let (Some(l), Some(d)) = (b.layer_of(e), m.parts[b.part[e]].props.ply_areal_density)
            else {
                continue;
            };
            if let Some(slot) = usize::try_from(l - 1)
                .ok()
                .and_then(|k| per_layer.get_mut(k))
            {
                *slot = Some(slot.map_or(d, |x: f64| x.max(d)));
            }
        }
    }
    if per_layer.is_empty() {
        return None;
    }
    per_layer.into_iter().sum()
}

/// The summary's columns about how the run ended and what an armour engineer reads:
/// status and stop reason; the first projectile's striking velocity, outcome, residual
/// velocity, mass and radius (null without a projectile); the layers, failures, broken
/// yarns, back-face deflection peak and energy absorbed (docs/tables.md). The failures
/// counted are those of failures.parquet: a stopped run's up to `end`, its last sample.
fn ballistic_columns(s: &Solver, m: &Model, status: &Status, end: f64) -> Vec<Col> {
    use crate::solver::watch::Outcome;
    let w = s.watch();
    // The striker: the first rigid projectile, or the deformable bullet (its mass the
    // lumped mass of its nodes, its radius about its axis).
    let p = m.has_striker().then_some(());
    let (mass, radius) = match (m.projectiles.first(), m.bullet_nodes()) {
        (Some(p), _) => (Some(p.mass), Some(p.radius)),
        (None, Some(nodes)) => (
            Some(nodes.iter().map(|&i| s.masses()[i]).sum::<f64>()),
            Some(w.bullet_radius),
        ),
        (None, None) => (None, None),
    };
    let (outcome, perforated, residual, when) = match (p, w.outcome) {
        (None, _) => (None, None, None, None),
        (Some(_), Outcome::Undecided) => (Some("undecided"), Some(false), None, None),
        (Some(_), Outcome::Arrested { time }) => {
            (Some("arrested"), Some(false), Some(0.0), Some(time))
        }
        (
            Some(_),
            Outcome::Perforated {
                time,
                residual_velocity,
            },
        ) => (
            Some("perforated"),
            Some(true),
            Some(residual_velocity),
            Some(time),
        ),
    };
    let layered = w.n_layers > 0;
    // The failures of failures.parquet (a stopped run's up to its last sample).
    let events = failure_events(s, status, end).unwrap_or(&[]);
    let first_failure = events.iter().find(|e| e.failure.eroded).map(|e| e.time);
    let eroded = events.iter().filter(|e| e.failure.eroded).count();
    let broken: u32 = (1..=w.n_layers).map(|l| w.counts(l).1).sum();
    let absorbed: f64 = w.last_rows.iter().map(|r| r[4]).sum();
    vec![
        Col::Str(
            "status",
            vec![match status {
                Status::Completed => "completed",
                Status::Stopped(_) => "stopped",
            }
            .into()],
        ),
        Col::OptStr(
            "stop_reason",
            vec![match status {
                Status::Completed => None,
                Status::Stopped(why) => Some(why.clone()),
            }],
        ),
        Col::OptF64("striking_velocity", vec![m.striking_speed()]),
        Col::OptStr("outcome", vec![outcome.map(String::from)]),
        Col::OptBool("perforated", vec![perforated]),
        Col::OptF64("residual_velocity", vec![residual]),
        Col::OptF64("outcome_time", vec![when]),
        Col::OptF64("projectile_mass", vec![mass]),
        Col::OptF64("projectile_radius", vec![radius]),
        Col::I64("layers", vec![w.n_layers as i64]),
        Col::OptI64(
            "plies_perforated",
            vec![(layered && p.is_some()).then_some(w.plies_perforated() as i64)],
        ),
        Col::I64("failed_elements", vec![eroded as i64]),
        Col::OptI64("broken_yarns", vec![layered.then_some(broken as i64)]),
        Col::OptF64("first_failure_time", vec![first_failure]),
        Col::OptF64(
            "back_face_deflection_peak",
            vec![layered.then_some(w.back_face_peak)],
        ),
        Col::OptF64("energy_absorbed", vec![layered.then_some(absorbed)]),
        Col::OptF64("areal_density", vec![areal_density(s, m)]),
        // The back-face signature: the backing clay's crater at the run's end, its
        // deepest point along `clay_profile` (a model with clay; `solver::crater`).
        Col::OptF64(
            "bfs",
            vec![{
                let c = s.crater();
                (!c.is_empty()).then(|| c.iter().map(|r| r[2]).fold(f64::NEG_INFINITY, f64::max))
            }],
        ),
    ]
}
