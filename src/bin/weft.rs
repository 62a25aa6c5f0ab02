//! `weft`: run study pipelines (`pipelines/*.toml`) with make-style reruns.

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use anyhow::{bail, Context};
use clap::{Args, Parser, Subcommand, ValueEnum};

use weft::pipeline::engine::Tally;
use weft::pipeline::gather::{gather, records_table};
use weft::pipeline::show;
use weft::pipeline::{run, ExecutorKind, Pipeline, RunOptions, Workspace};
use weft::table::{write_table, Provenance};

#[derive(Parser)]
#[command(
    name = "weft",
    version,
    about = "Run weft study pipelines: only stages whose inputs, parameters, command or binary changed run again",
    long_about = "Run weft study pipelines (pipelines/*.toml): stages with a command, inputs, outputs and \
                  parameters, sweeps that expand a stage into named instances, and make-style reruns decided \
                  on content (blake3), not timestamps.\n\nExamples:\n  weft run pipelines/rod_waves.toml          run what is stale\n  \
                  weft status pipelines/rod_waves.toml       say what is stale and why\n  \
                  weft run pipelines/rod_waves.toml -j 2 simulate   a stage and what it needs\n  \
                  weft run pipelines/rod_waves.toml --executor slurm   each stale stage a Slurm job\n  \
                  weft gather pipelines/rod_waves.toml --stage simulate --table summary.parquet \\\n    \
                  --out runs/summary.parquet"
)]
struct Cli {
    #[command(subcommand)]
    cmd: Cmd,
}

#[derive(Subcommand)]
enum Cmd {
    /// Run the stale stages (all, or the named stages and what they need).
    #[command(
        after_help = "Example:\n  weft run pipelines/woven_patch.toml\n  weft run -n pipelines/woven_patch.toml   (a dry run: what would run, and why)"
    )]
    Run(RunArgs),
    /// Say for each stage instance whether it is fresh, or why it would run (and its
    /// Slurm job, while one of an interrupted `weft run --executor slurm` is queued or running).
    #[command(after_help = "Example:\n  weft status pipelines/woven_patch.toml")]
    Status { pipeline: Option<PathBuf> },
    /// Print the stage graph.
    #[command(after_help = "Example:\n  weft dag pipelines/woven_patch.toml --format mermaid")]
    Dag {
        pipeline: Option<PathBuf>,
        #[arg(long, value_enum, default_value_t = DagFormat::Text)]
        format: DagFormat,
    },
    /// The record of every stage instance (command, parameters, hashes, times, exit status).
    #[command(
        after_help = "Example:\n  weft records pipelines/woven_patch.toml --out records.parquet"
    )]
    Records {
        pipeline: Option<PathBuf>,
        /// Write the records as a Parquet table instead of printing them.
        #[arg(long)]
        out: Option<PathBuf>,
    },
    /// Gather one table of every instance of a (sweep) stage into one Parquet table, with
    /// the instance name and its parameters as columns.
    #[command(
        after_help = "Example:\n  weft gather pipelines/ballistic_limit.toml --stage impact --table summary.parquet \\\n    --out impacts.parquet"
    )]
    Gather {
        pipeline: Option<PathBuf>,
        /// The stage whose instances to gather.
        #[arg(long)]
        stage: String,
        /// Which output of the stage [default: its only output].
        #[arg(long)]
        output: Option<String>,
        /// A table inside the output folder (e.g. `summary.parquet`); omit when the output is the table.
        #[arg(long)]
        table: Option<String>,
        /// The gathered table.
        #[arg(long)]
        out: PathBuf,
    },
    /// Run one stage instance inside a Slurm job (what `weft run --executor slurm` submits).
    #[command(hide = true)]
    Job {
        /// The job's manifest (pipeline file, and instance by array task).
        #[arg(long)]
        manifest: PathBuf,
        /// Array task [default: $SLURM_ARRAY_TASK_ID, or the manifest's only instance].
        #[arg(long)]
        task: Option<String>,
    },
}

// The options of `weft run` (a plain comment: clap would print a doc comment as the
// subcommand's help).
#[derive(Args)]
struct RunArgs {
    /// Pipeline file [default: the only file in pipelines/].
    pipeline: Option<PathBuf>,
    /// Stages (all instances) or instances to run, with their upstream stages.
    targets: Vec<String>,
    /// Parallel stages [default: number of cores] (local executor; Slurm decides for its jobs).
    #[arg(short, long)]
    jobs: Option<usize>,
    /// Where stages run: `local` (children of this process) or `slurm` (one Slurm job
    /// per stale instance, a job array per sweep stage, resources from the pipeline's
    /// [executor] table; `weft run` waits for the jobs and Ctrl-C cancels them; the
    /// project folder must be on a file system the compute nodes share).
    #[arg(long, value_enum, default_value_t = Exec::Local)]
    executor: Exec,
    /// After a failure, keep running stages that do not depend on it.
    #[arg(short, long)]
    keep_going: bool,
    /// Say what would run and why; run nothing (with `--executor slurm`, also print
    /// the sbatch commands it would submit).
    #[arg(short = 'n', long)]
    dry_run: bool,
    /// Run even if fresh: every selected stage, or the named stage (repeatable).
    #[arg(long, num_args = 0..=1, default_missing_value = "")]
    force: Vec<String>,
    /// Run only the targets, not their upstream stages (their inputs must exist).
    #[arg(long)]
    single: bool,
    /// No progress view or stage lines.
    #[arg(short, long)]
    quiet: bool,
}

#[derive(Clone, Copy, ValueEnum)]
enum Exec {
    Local,
    Slurm,
}

#[derive(Clone, Copy, ValueEnum)]
enum DagFormat {
    Text,
    Dot,
    Mermaid,
}

fn main() -> ExitCode {
    weft::cli::main(main_inner)
}

/// The pipeline file given, else the only one in `pipelines/`.
fn find_pipeline(p: Option<PathBuf>) -> anyhow::Result<PathBuf> {
    if let Some(p) = p {
        return Ok(p);
    }
    let dir = Path::new("pipelines");
    let files: Vec<PathBuf> = std::fs::read_dir(dir)
        .map(|rd| {
            rd.flatten()
                .map(|e| e.path())
                .filter(|p| p.extension().is_some_and(|x| x == "toml"))
                .collect()
        })
        .unwrap_or_default();
    match files.as_slice() {
        [one] => Ok(one.clone()),
        [] => bail!("no pipeline file given and none found in `pipelines/`\n  hint: `weft run pipelines/NAME.toml`"),
        many => bail!(
            "several pipeline files in `pipelines/`: {}\n  hint: name one, e.g. `weft run {}`",
            many.iter().map(|p| p.display().to_string()).collect::<Vec<_>>().join(", "),
            many[0].display()
        ),
    }
}

/// Load and validate the pipeline file given (or the only one in `pipelines/`).
fn load(p: Option<PathBuf>) -> anyhow::Result<Pipeline> {
    let f = find_pipeline(p)?;
    Ok(Pipeline::load(&f)?)
}

fn main_inner() -> anyhow::Result<ExitCode> {
    let cli: Cli = weft::cli::parse();
    match cli.cmd {
        Cmd::Run(a) => run_stale(a),
        Cmd::Status { pipeline } => status(pipeline),
        Cmd::Dag { pipeline, format } => dag(pipeline, format),
        Cmd::Records { pipeline, out } => records(pipeline, out),
        Cmd::Job { manifest, task } => {
            let status = weft::pipeline::slurm::run_job(&manifest, task)?;
            Ok(ExitCode::from(status as u8))
        }
        Cmd::Gather {
            pipeline,
            stage,
            output,
            table,
            out,
        } => {
            let p = load(pipeline)?;
            let rows = gather(&p, &stage, output.as_deref(), table.as_deref(), &out)?;
            eprintln!(
                "weft: gathered {rows} rows of `{stage}` -> {}",
                out.display()
            );
            Ok(ExitCode::SUCCESS)
        }
    }
}

/// `weft run`: the selected stale instances, then a closing line of counts.
fn run_stale(a: RunArgs) -> anyhow::Result<ExitCode> {
    let p = load(a.pipeline)?;
    let selected = p.selection(&a.targets, a.single)?;
    let forced = p.forced(&a.force, &selected)?;
    let jobs = a.jobs.unwrap_or_else(|| {
        std::thread::available_parallelism()
            .map(|n| n.get())
            .unwrap_or(1)
    });
    let mut ws = Workspace::open(&p);
    let opts = RunOptions {
        jobs,
        keep_going: a.keep_going,
        dry_run: a.dry_run,
        quiet: a.quiet,
        executor: match a.executor {
            Exec::Local => ExecutorKind::Local,
            Exec::Slurm => ExecutorKind::Slurm,
        },
    };
    let rep = run(&p, &mut ws, &selected, &forced, &opts)?;
    if a.dry_run {
        return Ok(ExitCode::SUCCESS);
    }
    let Tally {
        ran,
        fresh,
        failed,
        not_run,
    } = rep.tally();
    if !a.quiet {
        eprintln!("weft: {ran} ran, {fresh} fresh, {failed} failed, {not_run} not run");
    }
    if failed > 0 {
        if !a.keep_going && not_run > 0 {
            eprintln!("  hint: `--keep-going` runs the stages that do not depend on the failure");
        }
        return Ok(ExitCode::FAILURE);
    }
    Ok(ExitCode::SUCCESS)
}

/// `weft status`: fresh or why it would run, for every instance.
fn status(pipeline: Option<PathBuf>) -> anyhow::Result<ExitCode> {
    let p = load(pipeline)?;
    let mut ws = Workspace::open(&p);
    let n = p.instances.len();
    let plan = ws.plan(&p, &vec![true; n], &vec![false; n])?;
    ws.cache.save()?;
    let jobs = match weft::pipeline::slurm::live_jobs(&p) {
        Ok(j) => j,
        Err(e) => {
            eprintln!("weft: cannot ask Slurm about the jobs of an earlier run: {e}");
            Default::default()
        }
    };
    let s = show::status(&p, &plan, &jobs);
    print!("{}", s.text);
    eprintln!("weft: {} of {n} stage instances would run", s.stale);
    Ok(ExitCode::SUCCESS)
}

/// `weft dag`: the stage graph.
fn dag(pipeline: Option<PathBuf>, format: DagFormat) -> anyhow::Result<ExitCode> {
    let p = load(pipeline)?;
    print!(
        "{}",
        match format {
            DagFormat::Text => show::dag_text(&p),
            DagFormat::Dot => show::dag_dot(&p),
            DagFormat::Mermaid => show::dag_mermaid(&p),
        }
    );
    Ok(ExitCode::SUCCESS)
}

/// `weft records`: printed, or written as a Parquet table.
fn records(pipeline: Option<PathBuf>, out: Option<PathBuf>) -> anyhow::Result<ExitCode> {
    let p = load(pipeline)?;
    let b = records_table(&p);
    match out {
        Some(o) => {
            let prov = Provenance::new(
                "records",
                serde_json::json!({ "pipeline": p.file.display().to_string() }),
            );
            write_table(&o, &b, &prov)
                .with_context(|| format!("cannot write `{}`", o.display()))?;
            eprintln!("weft: {} records -> {}", b.num_rows(), o.display());
        }
        None => print!("{}", show::records_text(&p)),
    }
    Ok(ExitCode::SUCCESS)
}
