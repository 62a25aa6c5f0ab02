//! `weft-fit`: choose model parameters within bounds to minimise the mismatch T against
//! reference histories, running the solver in-process.

use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::sync::Mutex;
use std::time::Instant;

use anyhow::Context;
use clap::Parser;
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use weft::analysis::{components, read_series};
use weft::fit::{fit, parse_param, Case, Method, Objective, Options, Problem};
use weft::model::io::{read_model, write_model};
use weft::table::{batch, write_table, Col, Provenance};

#[derive(Parser, serde::Serialize)]
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
                  G12, G, s, b, h), comma-separated targets are tied to one value (each times its factor), and the \
                  start is the model's own value unless given.\n\n\
                  --objective arrival matches wave arrival times along the ordered --set instead (the first time \
                  --arrival-component reaches --relative-level of each node's peak, as weft-wavespeed measures \
                  them), which matches the wave speeds: W = Σ(t_c − t_r)²/Σ(t_c² + t_r²).\n\n\
                  Methods: cobyla (derivative-free, bounded) and gradient (projected BFGS, finite-difference gradients \
                  evaluated in parallel); --starts K > 1 adds a multistart global search (Halton points), the local \
                  searches running in parallel.\n\n\
                  Writes OUT/fit_trace.parquet (one row per evaluation), OUT/fit_result.parquet (one row per \
                  parameter: name, value, lower, upper, T) and OUT/models/CASE/, the fitted model of each case.\n\n\
                  Example (the membrane of a girder, static, two load cases):\n  \
                  weft-fit --reference-model g-ten --reference-history g-ten-out/history.parquet --model m-ten \\\n    \
                  --reference-model g-shr --reference-history g-shr-out/history.parquet --model m-shr \\\n    \
                  --components ux,uy --static --param membrane.G12:1e8:1e10:log --param membrane.thickness:1e-4:1e-2:log \\\n    \
                  --out runs/fit"
)]
struct Cli {
    /// Reference model folder (repeat for several cases).
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
    /// What is matched: `displacement` (the paper's T over --components) or `arrival` (the
    /// arrival times of a wave along the ordered --set, hence its speed: the first time
    /// --arrival-component reaches --relative-level of each node's peak).
    #[arg(long, value_enum, default_value_t = ObjectiveKind::Displacement)]
    objective: ObjectiveKind,
    /// Component whose arrival is timed (--objective arrival): ux … vz.
    #[arg(long, default_value = "vx")]
    arrival_component: String,
    /// Arrival level as a fraction of each node's peak (--objective arrival).
    #[arg(long, default_value_t = 0.5)]
    relative_level: f64,
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

#[derive(Clone, Copy, PartialEq, Eq, serde::Serialize, clap::ValueEnum)]
#[serde(rename_all = "lowercase")]
enum ObjectiveKind {
    Displacement,
    Arrival,
}

fn main() -> ExitCode {
    match run() {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e:#}");
            ExitCode::FAILURE
        }
    }
}

fn run() -> anyhow::Result<()> {
    let cli = Cli::parse();
    let n = cli.model.len();
    anyhow::ensure!(
        cli.reference_model.len() == n && cli.reference_history.len() == n,
        "{} --reference-model, {} --reference-history and {} --model given; expected as many of each, one per case \
         (hint: repeat the three options in the same order for every case)",
        cli.reference_model.len(),
        cli.reference_history.len(),
        n
    );
    anyhow::ensure!(
        cli.case_name.is_empty() || cli.case_name.len() == n,
        "{} --case-name for {n} cases; expected none or one per case",
        cli.case_name.len()
    );
    anyhow::ensure!(
        cli.starts >= 1 && cli.max_evaluations >= 2,
        "--starts {} and --max-evaluations {}: expected at least 1 start and 2 evaluations",
        cli.starts,
        cli.max_evaluations
    );
    let comps = components(&cli.components)?;
    anyhow::ensure!(
        comps.iter().all(|&c| c < 3),
        "--components `{}`: a fit compares displacements; expected some of ux, uy, uz",
        cli.components
    );
    let objective = match cli.objective {
        ObjectiveKind::Displacement => Objective::Displacement,
        ObjectiveKind::Arrival => {
            let c = components(&cli.arrival_component)?;
            anyhow::ensure!(
                c.len() == 1,
                "--arrival-component takes one component, got `{}`",
                cli.arrival_component
            );
            anyhow::ensure!(
                cli.relative_level > 0.0 && cli.relative_level <= 1.0,
                "--relative-level {}: expected a fraction of the peak in (0, 1]",
                cli.relative_level
            );
            Objective::Arrival {
                component: c[0],
                level: weft::analysis::Level::Relative(cli.relative_level),
            }
        }
    };
    let mut cases = vec![];
    let mut prov_inputs: Vec<PathBuf> = vec![];
    for k in 0..n {
        let reference = read_series(&cli.reference_model[k], &cli.reference_history[k], &cli.set)
            .with_context(|| format!("reference of case {}", k + 1))?;
        let model = read_model(&cli.model[k])
            .with_context(|| format!("candidate model of case {}", k + 1))?;
        let name = cli.case_name.get(k).cloned().unwrap_or_else(|| {
            let base = cli.model[k]
                .file_name()
                .map(|s| s.to_string_lossy().to_string())
                .unwrap_or_else(|| format!("case{}", k + 1));
            if cli
                .model
                .iter()
                .filter(|m| m.file_name() == cli.model[k].file_name())
                .count()
                > 1
            {
                format!("{base}-{}", k + 1)
            } else {
                base
            }
        });
        prov_inputs.push(cli.reference_history[k].clone());
        prov_inputs.extend(parquet_files(&cli.model[k])?);
        cases.push(Case {
            name,
            reference,
            model,
            set: cli.candidate_set.clone().unwrap_or_else(|| cli.set.clone()),
        });
    }
    // Parameters are parsed against the first candidate; every case must have the parts.
    let params = cli
        .params
        .iter()
        .map(|s| parse_param(s, &cases[0].model))
        .collect::<weft::Result<Vec<_>>>()?;
    for c in &cases[1..] {
        for s in &cli.params {
            parse_param(s, &c.model).with_context(|| format!("case `{}`", c.name))?;
        }
    }
    let mut expected = vec![None; params.len()];
    for e in &cli.expected {
        let (name, value) = e.split_once('=').with_context(|| {
            format!("--expected `{e}`: expected NAME=VALUE, NAME one of the --param names")
        })?;
        let k =
            params
                .iter()
                .position(|p| p.name == name.trim())
                .with_context(|| {
                    format!(
                "--expected `{e}`: no fitted parameter is named `{name}` (expected one of {})",
                params.iter().map(|p| format!("`{}`", p.name)).collect::<Vec<_>>().join(", ")
            )
                })?;
        let v: f64 = value
            .trim()
            .parse()
            .ok()
            .filter(|v: &f64| v.is_finite())
            .with_context(|| format!("--expected `{e}`: `{value}` is not a finite number"))?;
        expected[k] = Some(v);
    }
    let problem = Problem {
        cases,
        params,
        components: comps,
        tolerance: cli.tolerance,
        static_mode: cli.static_mode,
        objective,
    };
    let opts = Options {
        method: cli.method,
        starts: cli.starts,
        max_evaluations: cli.max_evaluations,
        xtol: cli.xtol,
        ftol: cli.ftol,
        initial_step: cli.initial_step,
        ..Default::default()
    };
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(cli.threads)
        .build()
        .context("cannot start the worker threads")?;

    let protocol = std::env::var_os("WEFT_PROGRESS").is_some();
    let budget = (cli.starts * cli.max_evaluations) as u64;
    let bar = if cli.quiet || protocol {
        ProgressBar::hidden()
    } else {
        let b = ProgressBar::with_draw_target(Some(budget), ProgressDrawTarget::stderr());
        b.set_style(
            ProgressStyle::with_template(
                "{spinner} fit [{bar:30}] {pos}/{len} evaluations, {msg} {elapsed_precise}",
            )
            .expect("valid template"),
        );
        b
    };
    let best = Mutex::new((f64::INFINITY, 0u64));
    let on_eval = |e: &weft::fit::Evaluation| {
        let mut b = best.lock().expect("progress");
        b.0 = b.0.min(e.t);
        b.1 += 1;
        if protocol {
            eprintln!("weft-progress {:.4}", (b.1 as f64 / budget as f64).min(1.0));
        } else {
            bar.set_position(b.1);
            bar.set_message(format!("best T {:.4e}", b.0));
        }
    };
    let t0 = Instant::now();
    let r = pool.install(|| fit(&problem, &opts, &on_eval));
    bar.finish_and_clear();
    let r = r.context("the fit failed; nothing was written")?;
    let wall = t0.elapsed().as_secs_f64();

    let mut prov = Provenance::new("fit", serde_json::to_value(&cli)?);
    for p in &prov_inputs {
        prov = prov.with_input(p)?;
    }
    // fit_trace.parquet: one row per evaluation.
    let ev = &r.evaluations;
    let mut running = f64::INFINITY;
    let mut cols = vec![
        Col::I64("evaluation", (0..ev.len() as i64).collect()),
        Col::I64("start", ev.iter().map(|e| e.start as i64).collect()),
        Col::I64(
            "start_evaluation",
            ev.iter().map(|e| e.index as i64).collect(),
        ),
    ];
    for (i, p) in problem.params.iter().enumerate() {
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
    cols.push(Col::F64(
        "wall_seconds",
        ev.iter().map(|e| e.seconds).collect(),
    ));
    cols.push(Col::OptStr(
        "error",
        ev.iter().map(|e| e.error.clone()).collect(),
    ));
    write_table(&cli.out.join("fit_trace.parquet"), &batch(cols), &prov)?;

    // fit_result.parquet: one row per parameter.
    let np = problem.params.len();
    let rep = |v: f64| vec![v; np];
    let solver_runs = (ev.len() * problem.cases.len()) as i64;
    write_table(
        &cli.out.join("fit_result.parquet"),
        &batch(vec![
            Col::Str(
                "name",
                problem.params.iter().map(|p| p.name.clone()).collect(),
            ),
            Col::F64("value", r.x.clone()),
            Col::F64("lower", problem.params.iter().map(|p| p.lower).collect()),
            Col::F64("upper", problem.params.iter().map(|p| p.upper).collect()),
            Col::Str(
                "scale",
                problem
                    .params
                    .iter()
                    .map(|p| if p.log { "log" } else { "lin" }.to_string())
                    .collect(),
            ),
            Col::F64(
                "initial",
                problem.params.iter().map(|p| p.initial).collect(),
            ),
            Col::Bool(
                "at_bound",
                problem
                    .params
                    .iter()
                    .zip(&r.x)
                    .map(|(p, &v)| {
                        let z = p.unit(v);
                        !(1e-6..=1.0 - 1e-6).contains(&z)
                    })
                    .collect(),
            ),
            Col::OptF64("expected", expected.clone()),
            Col::OptF64(
                "relative_difference",
                expected
                    .iter()
                    .zip(&r.x)
                    .map(|(e, v)| e.map(|e| (v - e) / e))
                    .collect(),
            ),
            Col::F64("T", rep(r.t)),
            Col::F64("T_initial", rep(r.t_initial)),
            Col::I64("evaluations", vec![ev.len() as i64; np]),
            Col::I64("solver_runs", vec![solver_runs; np]),
            Col::Str(
                "method",
                vec![format!("{:?}", cli.method).to_lowercase(); np],
            ),
            Col::Bool("static", vec![cli.static_mode; np]),
            Col::F64("wall_seconds", rep(wall)),
        ]),
        &prov,
    )?;
    for (k, c) in problem.cases.iter().enumerate() {
        let m = problem.model_at(k, &r.x);
        let dir = cli.out.join("models").join(&c.name);
        write_model(&m, &dir, &prov)
            .with_context(|| format!("cannot write the fitted model `{}`", dir.display()))?;
    }

    eprintln!(
        "weft-fit: T {:.4e} -> {:.4e} in {} evaluations ({} solver runs, {} start(s)), {:.2} s",
        r.t_initial,
        r.t,
        ev.len(),
        solver_runs,
        cli.starts,
        wall
    );
    for ((p, v), e) in problem.params.iter().zip(&r.x).zip(&expected) {
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
    for s in &r.starts {
        if r.starts.len() > 1 {
            eprintln!(
                "  start {}: T {:.4e} after {} evaluations ({})",
                s.start, s.t, s.evaluations, s.status
            );
        }
    }
    eprintln!(
        "  wrote {}/{{fit_trace,fit_result}}.parquet and models/",
        cli.out.display()
    );
    Ok(())
}

fn parquet_files(dir: &Path) -> anyhow::Result<Vec<PathBuf>> {
    let mut v = vec![];
    for e in std::fs::read_dir(dir).with_context(|| format!("cannot list `{}`", dir.display()))? {
        let p = e?.path();
        if p.extension().is_some_and(|x| x == "parquet") {
            v.push(p);
        }
    }
    v.sort();
    Ok(v)
}
