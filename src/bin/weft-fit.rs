//! `weft-fit`: choose model parameters within bounds to minimise the mismatch T against
//! reference histories, running the solver in-process.

use std::path::PathBuf;
use std::process::ExitCode;
use std::sync::Mutex;

use clap::Parser;
use weft::cli::Progress;
use weft::fit::stage::{self, Config, ObjectiveKind};
use weft::fit::Method;

#[derive(Parser)]
#[command(
    name = "weft-fit",
    version,
    about = "Fit model parameters (part properties, within bounds) to minimise the mismatch T against reference histories",
    long_about = "Calibrates a reduced model against a reference (the paper's eq. 1): chooses the values of named part \
                  properties, within bounds, that minimise T (the displacement mismatch of weft-error) between the \
                  candidate model's response and a reference history, running the solver in-process for every \
                  evaluation (explicit, or linear static with --static).\n\n\
                  Several cases (e.g. the same square in tension and in shear) are given by repeating \
                  --reference-model, --reference-history and --model in the same order; the objective is their mean T.\n\n\
                  A parameter is PART.PROPERTY[*FACTOR][,PART.PROPERTY[*FACTOR]...]:LOWER:UPPER[:log|lin][:INITIAL]: \
                  the property names are the columns of parts.parquet (docs/tables.md; aliases E, rho, A, E1, E2, nu12, \
                  G12, G, s, b, h, eps_f), comma-separated targets are tied to one value (each times its factor), and the \
                  start is the model's own value unless given.\n\n\
                  --objective arrival matches wave arrival times along the ordered --set instead (for each --arrival \
                  COMPONENT:LEVEL, or --arrival-component at --relative-level of each node's peak, as weft-wavespeed measures \
                  them; the mean over the terms), which matches the wave speeds: W = Σ(t_c − t_r)²/Σ(t_c² + t_r²). \
                  --objective both minimises T + --arrival-weight × W: displacements and wave speeds together.\n\n\
                  --objective projectile matches the projectile's velocity history instead: P = Σ(v_c − v_r)²/Σ(v_c² + v_r²) \
                  over the reference's output times, v the first projectile's velocity along its initial direction of \
                  flight (positive into the target), the reference's from its run's projectile.parquet (beside \
                  --reference-history, or --reference-projectile), the candidate's from its in-process run (a rigid \
                  projectile, or a deformable bullet's momentum over its mass), interpolated at the reference's times and \
                  held at its last value after a run that ended at its outcome (stop_on_outcome). Once yarns fail, the \
                  displacements of a reduced model and the yarn-level reference cannot match node by node, but what a \
                  ballistic limit depends on can: the deceleration while the fabric holds, the perforation time, the \
                  residual velocity. Use it to fit a failure law (a failure strain, a Weibull scale) of a reduced model to \
                  the reference's perforation, with several cases at striking speeds around the limit, each candidate \
                  woven at its reference's --projectile-velocity, e.g. --param yarns.eps_f,half_yarns.eps_f:0.02:0.08 \
                  --objective projectile. --projectile-weight W adds W × P to the displacement, arrival or both \
                  objective instead (T before failure and the projectile's history after, in one objective).\n\n\
                  Methods: cobyla (derivative-free, bounded) and gradient (projected BFGS, finite-difference gradients \
                  evaluated in parallel); --starts K > 1 adds a multistart global search (Halton points), the local \
                  searches running in parallel.\n\n\
                  Writes OUT/fit_trace.parquet (one row per evaluation), OUT/fit_result.parquet (one row per \
                  parameter: name, value, lower, upper, T) and OUT/models/CASE/, the fitted model of each case.\n\n\
                  Example (the membrane of a girder, static, two load cases):\n  \
                  weft-fit --reference-model g-ten --reference-history g-ten-out/history.parquet --model m-ten \\\n    \
                  --reference-model g-shr --reference-history g-shr-out/history.parquet --model m-shr \\\n    \
                  --components ux,uy --static --param membrane.G12:1e8:1e10:log \\\n    \
                  --param membrane.thickness:1e-4:1e-2:log \\\n    \
                  --out runs/fit"
)]
struct Cli {
    /// Reference model folder (repeat for several cases; not read with --objective
    /// projectile, which compares no node set).
    #[arg(long, required = true)]
    reference_model: Vec<PathBuf>,
    /// history.parquet of the reference run (repeat, one per case).
    #[arg(long, required = true)]
    reference_history: Vec<PathBuf>,
    /// Candidate model folder whose parts are fitted (repeat, one per case).
    #[arg(long, required = true)]
    model: Vec<PathBuf>,
    /// Case names (default: the candidate model folders' names).
    #[arg(long)]
    case_name: Vec<String>,
    /// Parameter to fit (repeat): PART.PROPERTY[,...]:LOWER:UPPER[:log|lin][:INITIAL].
    #[arg(long = "param", required = true)]
    params: Vec<String>,
    /// Node set compared (in the reference model).
    #[arg(long, default_value = "reference")]
    set: String,
    /// Node set of the candidate, when it differs.
    #[arg(long)]
    candidate_set: Option<String>,
    /// Displacement components compared, comma-separated (ux, uy, uz).
    #[arg(long, default_value = "ux,uy,uz")]
    components: String,
    /// Node matching tolerance [m].
    #[arg(long, default_value_t = 1e-9)]
    tolerance: f64,
    /// How reference nodes find their candidate values: position (the node there), id
    /// (the node of the same id), interpolate (the candidate's shape functions at the
    /// reference position, in any of its membrane, truss or beam elements; meshes that
    /// differ, as the combined model of the paper's Fig. 5b).
    #[arg(long = "match", value_enum, default_value = "position")]
    matching: weft::analysis::Matching,
    /// What is matched: `displacement` (the paper's T over --components), `arrival` (the
    /// arrival times of waves along the ordered --set, hence their speeds: the mean W of
    /// the --arrival terms), `both` (T + --arrival-weight × that mean W) or `projectile`
    /// (the projectile's velocity history, P; no node set compared).
    #[arg(long, value_enum, default_value_t = ObjectiveKind::Displacement)]
    objective: ObjectiveKind,
    /// An arrival term (repeat): COMPONENT:LEVEL, the first time the component reaches
    /// this absolute level [m, or m/s for vx … vz] at each node, one level for all nodes
    /// as the paper's "pre-selected level" (e.g. `--arrival ux:5e-5 --arrival uz:5e-4`).
    /// Without any: --arrival-component at --relative-level of each node's peak.
    #[arg(long)]
    arrival: Vec<String>,
    /// Component whose arrival is timed when no --arrival is given: ux … vz.
    #[arg(long, default_value = "vx")]
    arrival_component: String,
    /// Arrival level as a fraction of each node's peak when no --arrival is given.
    #[arg(long, default_value_t = 0.5)]
    relative_level: f64,
    /// Slack of the incident front [s], as weft-wavespeed --slack: an arrival may fall this
    /// far behind the latest one inwards and still count as the front.
    #[arg(long, default_value_t = 0.0)]
    arrival_slack: f64,
    /// --objective both: the weight of the arrival mismatch W beside T.
    #[arg(long, default_value_t = 1.0)]
    arrival_weight: f64,
    /// The reference run's projectile.parquet (repeat, one per case), for --objective
    /// projectile or --projectile-weight (default: the projectile.parquet beside each
    /// --reference-history).
    #[arg(long)]
    reference_projectile: Vec<PathBuf>,
    /// Adds W × P (the projectile's velocity-history mismatch, as --objective projectile)
    /// to the displacement, arrival or both objective (≥ 0; 0: not compared).
    #[arg(long, default_value_t = 0.0)]
    projectile_weight: f64,
    /// Linear static solves; T compares the final displacements.
    #[arg(long = "static")]
    static_mode: bool,
    #[arg(long, value_enum, default_value_t = Method::Cobyla)]
    method: Method,
    /// Local searches (1: local only; K > 1: multistart from K points).
    #[arg(long, default_value_t = 1)]
    starts: usize,
    /// Objective evaluations per local search, at most.
    #[arg(long, default_value_t = 200)]
    max_evaluations: usize,
    /// Stop when steps on the unit parameter box fall below this.
    #[arg(long, default_value_t = 1e-6)]
    xtol: f64,
    /// Stop when T changes by less than this, relatively.
    #[arg(long, default_value_t = 1e-10)]
    ftol: f64,
    /// First step on the unit parameter box (COBYLA's ρ_beg).
    #[arg(long, default_value_t = 0.1)]
    initial_step: f64,
    /// A value to compare a fitted parameter with (repeat): NAME=VALUE, NAME as in --param
    /// (e.g. a closed form); fit_result.parquet gets `expected` and `relative_difference`.
    #[arg(long)]
    expected: Vec<String>,
    /// Worker threads (0: all cores). Results do not depend on it.
    #[arg(long, default_value_t = 0)]
    threads: usize,
    /// No progress bar.
    #[arg(long)]
    quiet: bool,
    /// Output folder.
    #[arg(long)]
    out: PathBuf,
}

fn main() -> ExitCode {
    weft::cli::main(run)
}

fn run() -> anyhow::Result<ExitCode> {
    let cli: Cli = weft::cli::parse();
    let cfg = Config {
        reference_model: cli.reference_model,
        reference_history: cli.reference_history,
        model: cli.model,
        case_name: cli.case_name,
        params: cli.params,
        set: cli.set,
        candidate_set: cli.candidate_set,
        components: cli.components,
        tolerance: cli.tolerance,
        matching: cli.matching,
        objective: cli.objective,
        arrival_component: cli.arrival_component,
        relative_level: cli.relative_level,
        arrival: cli.arrival,
        arrival_slack: cli.arrival_slack,
        arrival_weight: cli.arrival_weight,
        reference_projectile: cli.reference_projectile,
        projectile_weight: cli.projectile_weight,
        static_mode: cli.static_mode,
        method: cli.method,
        starts: cli.starts,
        max_evaluations: cli.max_evaluations,
        xtol: cli.xtol,
        ftol: cli.ftol,
        initial_step: cli.initial_step,
        expected: cli.expected,
        threads: cli.threads,
        quiet: cli.quiet,
        out: cli.out,
    };
    let budget = stage::budget(&cfg);
    let progress = Progress::new(
        cfg.quiet,
        budget,
        "{spinner} fit [{bar:30}] {pos}/{len} evaluations, {msg} {elapsed_precise}",
    );
    let best = Mutex::new((f64::INFINITY, 0u64));
    let on_eval = |e: &weft::fit::Evaluation| {
        let mut b = best.lock().expect("progress");
        b.0 = b.0.min(e.t);
        b.1 += 1;
        if progress.protocol() {
            progress.line((b.1 as f64 / budget as f64).min(1.0));
        } else {
            progress.bar().set_position(b.1);
            progress.bar().set_message(format!("best T {:.4e}", b.0));
        }
    };
    let r = stage::run(&cfg, &on_eval);
    progress.finish();
    let r = r?;
    let res = &r.result;
    eprintln!(
        "weft-fit: T {:.4e} -> {:.4e} in {} evaluations ({} solver runs, {} start(s)), {:.2} s",
        res.t_initial,
        res.t,
        res.evaluations.len(),
        r.solver_runs,
        cfg.starts,
        r.wall_seconds
    );
    let best = res.evaluations.iter().min_by(|a, b| a.t.total_cmp(&b.t));
    if let Some(p) = best.and_then(|e| e.projectile) {
        eprintln!("  projectile mismatch P at the fitted values {p:.4e}");
    }
    for ((p, v), e) in r.problem.params.iter().zip(&res.x).zip(&r.expected) {
        let cmp = e
            .map(|e| format!(", expected {e:.4e}: {:+.2} %", 100.0 * (v - e) / e))
            .unwrap_or_default();
        eprintln!(
            "  {:<32} {:.6e}  (start {:.4e}, bounds {:.3e} … {:.3e}, {}{cmp})",
            p.name,
            v,
            p.initial,
            p.lower,
            p.upper,
            if p.log { "log" } else { "lin" }
        );
    }
    if res.starts.len() > 1 {
        for s in &res.starts {
            eprintln!(
                "  start {}: T {:.4e} after {} evaluations ({})",
                s.start, s.t, s.evaluations, s.status
            );
        }
    }
    eprintln!(
        "  wrote {}/{{fit_trace,fit_result}}.parquet and models/",
        cfg.out.display()
    );
    Ok(ExitCode::SUCCESS)
}
