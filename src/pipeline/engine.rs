//! Running what is stale: `weft run`'s scheduling loop, the project lock and the run's
//! report. What is stale, and why, is judged in [`super::workspace`]; an instance
//! waiting on a stale upstream one is judged again here when the upstream has run, on the
//! new content of its inputs, so an upstream rerun that reproduces the same bytes reruns
//! nothing below it.
//!
//! Execution: the scheduling loop here hands ready instances to an executor
//! (`super::exec`): the local one runs them in parallel (`-j`) as children of `weft`,
//! the Slurm one (`super::slurm`) as Slurm jobs. Either way each instance runs as
//! `sh -c CMD` in the project root, with `${outputs...}` pointing at temporary siblings
//! of the real outputs, stdout and stderr in `.weft/logs/<pipeline>/<instance>.log`. On
//! success the temporaries are renamed into place and then the record is written: the
//! record is the commit point, so an interrupted run never leaves an output that counts
//! as fresh. Local children get SIGKILL when `weft` dies (Linux `PR_SET_PDEATHSIG`).

use std::collections::BTreeMap;
use std::io::Write;
use std::path::Path;

use indicatif::{MultiProgress, ProgressBar, ProgressDrawTarget, ProgressStyle};

use super::exec::{log_tail, Event, Executor, Finish, Launch, LocalExecutor};
use super::slurm::SlurmExecutor;
use super::spec::{shell_quote, Pipeline};
pub use super::workspace::{Verdict, Workspace};
use crate::error::{Result, WeftError};

/// Options of `weft run`.
#[derive(Debug, Clone)]
pub struct RunOptions {
    pub jobs: usize,
    pub keep_going: bool,
    pub dry_run: bool,
    pub quiet: bool,
    pub executor: ExecutorKind,
}

/// Where instances run: `weft run --executor local|slurm`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum ExecutorKind {
    /// Child processes of `weft run` on this machine, `-j` at a time.
    #[default]
    Local,
    /// One Slurm job per instance, a job array per sweep stage (`super::slurm`).
    Slurm,
}

/// What happened to each instance.
#[derive(Debug, Clone, PartialEq)]
pub enum Outcome {
    Fresh,
    Ran {
        seconds: f64,
    },
    Failed {
        status: i32,
    },
    /// Not run because an upstream instance failed.
    Skipped,
    /// Not run because the run stopped after a failure (without --keep-going).
    NotStarted,
}

pub struct RunReport {
    pub outcomes: Vec<(String, Outcome)>,
}

impl RunReport {
    pub fn ran(&self) -> Vec<&str> {
        self.outcomes
            .iter()
            .filter(|o| matches!(o.1, Outcome::Ran { .. }))
            .map(|o| o.0.as_str())
            .collect()
    }
    pub fn failed(&self) -> usize {
        self.outcomes
            .iter()
            .filter(|o| matches!(o.1, Outcome::Failed { .. }))
            .count()
    }
}

/// Hold the project lock while alive.
pub struct Lock {
    _file: std::fs::File,
}

/// Take the project lock; a second `weft run` gets a clear error.
pub fn lock(root: &Path) -> Result<Lock> {
    let dot = root.join(".weft");
    std::fs::create_dir_all(&dot).map_err(|e| WeftError::io(&dot, e))?;
    let p = dot.join("lock");
    let mut f = std::fs::OpenOptions::new()
        .read(true)
        .write(true)
        .create(true)
        .truncate(false)
        .open(&p)
        .map_err(|e| WeftError::io(&p, e))?;
    match f.try_lock() {
        Ok(()) => {
            use std::io::Seek;
            let _ = f.set_len(0);
            let _ = f.seek(std::io::SeekFrom::Start(0));
            let _ = write!(f, "{}", std::process::id());
            Ok(Lock { _file: f })
        }
        Err(std::fs::TryLockError::WouldBlock) => {
            let holder = std::fs::read_to_string(&p).unwrap_or_default();
            Err(WeftError::input(format!(
                "another `weft run` (pid {}) is running in `{}`",
                holder.trim(),
                root.display()
            ))
            .in_file(&p)
            .hint("wait for it to finish; the lock is released when that process exits"))
        }
        Err(std::fs::TryLockError::Error(e)) => Err(WeftError::io(&p, e)),
    }
}

/// Run the selected instances that are stale, in dependency order.
pub fn run(
    p: &Pipeline,
    ws: &mut Workspace,
    selected: &[bool],
    force: &[bool],
    o: &RunOptions,
) -> Result<RunReport> {
    let plan = ws.plan(p, selected, force)?;
    if o.dry_run {
        let mut outcomes = vec![];
        for &i in &p.order {
            if selected[i] {
                let inst = &p.instances[i];
                match &plan[i] {
                    Verdict::Fresh => println!("fresh      {}", inst.name),
                    Verdict::Stale(r) | Verdict::Waiting(r) => {
                        println!("would run  {}: {r}", inst.name)
                    }
                }
                outcomes.push((inst.name.clone(), Outcome::Fresh));
            }
        }
        if o.executor == ExecutorKind::Slurm && plan.iter().any(|v| !v.is_fresh()) {
            println!("\n# the sbatch commands `weft run --executor slurm` would submit:");
            let mut ex = SlurmExecutor::new(p, true)?;
            let quiet = RunOptions {
                quiet: true,
                ..o.clone()
            };
            schedule(p, ws, selected, force, &plan, &quiet, &mut ex, vec![])?;
        }
        ws.cache.save()?;
        return Ok(RunReport { outcomes });
    }
    let _lock = lock(&p.root)?;
    match o.executor {
        ExecutorKind::Local => {
            let live = super::slurm::live_jobs(p).unwrap_or_default();
            if let Some((inst, (job, state))) = live.iter().next() {
                return Err(WeftError::input(format!(
                    "{} Slurm jobs of an earlier `weft run --executor slurm` are still queued or running (`{inst}`: job {job}, {state})",
                    live.len()
                ))
                .in_file(&p.file)
                .hint("running them here too would race them; `weft run --executor slurm` waits for them, or cancel them with scancel"));
            }
            let mut ex = LocalExecutor::new(ws);
            schedule(p, ws, selected, force, &plan, o, &mut ex, vec![])
        }
        ExecutorKind::Slurm => {
            let mut ex = SlurmExecutor::new(p, false)?;
            let adopted = ex.adopt(p, selected, force, &plan)?;
            if ex.cancelled_at_start > 0 && !o.quiet {
                eprintln!(
                    "cancel {} Slurm jobs of an earlier `weft run` (their work changed, they were forced, something they need is stale again, or the run died before noting them)",
                    ex.cancelled_at_start
                );
            }
            let r = schedule(p, ws, selected, force, &plan, o, &mut ex, adopted);
            if r.is_err() {
                ex.cancel_all();
            }
            r
        }
    }
}

/// The scheduling loop, the same for every executor: hand over each instance when it is
/// ready (its upstream done, or for an eager executor queued), judge it on the current
/// content of its inputs when its upstream is done, skip what a failure cuts off, stop
/// starting new ones after a failure without `--keep-going`, and show progress.
#[allow(clippy::too_many_arguments)]
fn schedule(
    p: &Pipeline,
    ws: &mut Workspace,
    selected: &[bool],
    force: &[bool],
    plan: &[Verdict],
    o: &RunOptions,
    ex: &mut dyn Executor,
    adopted: Vec<(usize, String, String)>,
) -> Result<RunReport> {
    let n = p.instances.len();
    let stale_count = (0..n)
        .filter(|&i| selected[i] && !plan[i].is_fresh())
        .count();
    let mp = MultiProgress::with_draw_target(if o.quiet {
        ProgressDrawTarget::hidden()
    } else {
        ProgressDrawTarget::stderr()
    });
    let attended = !o.quiet && !mp.is_hidden();
    let main = mp.add(ProgressBar::new(stale_count as u64));
    main.set_style(
        ProgressStyle::with_template(
            "{spinner} stages [{bar:30}] {pos}/{len} {elapsed_precise} {msg}",
        )
        .expect("template"),
    );
    if !ex.dry() {
        main.enable_steady_tick(std::time::Duration::from_millis(250));
    }
    let say = |s: String| {
        if attended {
            let _ = mp.println(s);
        } else if !o.quiet {
            eprintln!("{s}");
        }
    };
    #[derive(Clone, Copy, PartialEq)]
    enum St {
        Pending,
        Running,
        Ok,
        Failed,
        Skipped,
    }
    let mut st = vec![St::Pending; n];
    let mut outcome: BTreeMap<usize, Outcome> = BTreeMap::new();
    let mut running = 0usize;
    let mut stop = false;
    let mut bars: BTreeMap<usize, ProgressBar> = BTreeMap::new();
    for (i, job, state) in adopted {
        st[i] = St::Running;
        running += 1;
        say(format!(
            "adopt {}: Slurm job {job} ({state}) of an earlier `weft run`",
            p.instances[i].name
        ));
    }
    loop {
        // Hand over every ready instance; those it needs must be done or, for an eager
        // executor, handed over in an earlier pass (so that they have a job to wait on).
        let mut progressed = false;
        let mut batch: Vec<Launch> = vec![];
        let mut this_pass = vec![false; n];
        for &i in &p.order {
            if !selected[i] || st[i] != St::Pending {
                continue;
            }
            let inst = &p.instances[i];
            let deps = || inst.deps.iter().copied().filter(|&d| selected[d]);
            if deps().any(|d| matches!(st[d], St::Failed | St::Skipped)) {
                st[i] = St::Skipped;
                outcome.insert(i, Outcome::Skipped);
                say(format!("skip  {} (an upstream stage failed)", inst.name));
                progressed = true;
                continue;
            }
            if deps().any(|d| st[d] == St::Pending || this_pass[d]) {
                continue;
            }
            let waiting_on: Vec<usize> = deps().filter(|&d| st[d] == St::Running).collect();
            if stop || (!waiting_on.is_empty() && !ex.eager()) {
                continue;
            }
            if !ex.eager() && running + batch.len() >= o.jobs.max(1) {
                continue;
            }
            let reason = if force[i] {
                "forced".to_string()
            } else if !waiting_on.is_empty() {
                match &plan[i] {
                    Verdict::Stale(r) | Verdict::Waiting(r) => r.clone(),
                    Verdict::Fresh => "upstream reruns".into(),
                }
            } else {
                match ws.verdict(inst)? {
                    Verdict::Fresh => {
                        st[i] = St::Ok;
                        outcome.insert(i, Outcome::Fresh);
                        progressed = true;
                        continue;
                    }
                    Verdict::Stale(r) | Verdict::Waiting(r) => r,
                }
            };
            if ws.binary_of(&inst.command).is_none() {
                let name = inst.command.split_whitespace().next().unwrap_or("");
                return Err(WeftError::input(format!(
                    "stage `{}`: command `{name}` not found",
                    inst.name
                ))
                .in_file(&p.file)
                .at_line(inst.line)
                .at_key(format!("stages.{}.cmd", inst.stage))
                .hint(
                    "build the weft binaries (`cargo build --release`) or put the tool on PATH",
                ));
            }
            st[i] = St::Running;
            this_pass[i] = true;
            batch.push(Launch {
                idx: i,
                reason,
                force: force[i],
                waiting_on,
            });
        }
        if !batch.is_empty() {
            running += batch.len();
            ex.launch(p, ws, batch, &say)?;
            progressed = true;
        }
        if progressed {
            continue;
        }
        if running == 0 || ex.dry() {
            break;
        }
        for ev in ex.wait(p, ws)? {
            match ev {
                Event::Started(i) => {
                    let bar = mp.insert_before(&main, ProgressBar::new(1000));
                    bar.set_style(
                        ProgressStyle::with_template(
                            "  {spinner} {msg:40!} [{bar:20}] {percent:>3}% {elapsed}",
                        )
                        .expect("template"),
                    );
                    bar.set_message(p.instances[i].name.clone());
                    bar.enable_steady_tick(std::time::Duration::from_millis(200));
                    bars.insert(i, bar);
                }
                Event::Note(s) => say(s),
                Event::Progress(i, f) => {
                    if let Some(b) = bars.get(&i) {
                        b.set_position((f.clamp(0.0, 1.0) * 1000.0) as u64);
                    }
                }
                Event::Done(i, fin) => {
                    running -= 1;
                    main.inc(1);
                    if let Some(b) = bars.remove(&i) {
                        b.finish_and_clear();
                        mp.remove(&b);
                    }
                    let inst = &p.instances[i];
                    match fin {
                        Finish::Ran { seconds } => {
                            st[i] = St::Ok;
                            outcome.insert(i, Outcome::Ran { seconds });
                            say(format!("done  {} ({seconds:.2} s)", inst.name));
                        }
                        Finish::Fresh => {
                            st[i] = St::Ok;
                            outcome.insert(i, Outcome::Fresh);
                            say(format!(
                                "fresh {} (its upstream reproduced the same inputs)",
                                inst.name
                            ));
                        }
                        Finish::Lost { why, .. }
                            if inst.deps.iter().any(|&d| {
                                selected[d] && matches!(st[d], St::Failed | St::Skipped)
                            }) =>
                        {
                            st[i] = St::Skipped;
                            outcome.insert(i, Outcome::Skipped);
                            say(format!(
                                "skip  {} (an upstream stage failed; {why})",
                                inst.name
                            ));
                        }
                        Finish::Lost { .. } if stop => {
                            st[i] = St::Skipped;
                            outcome.insert(i, Outcome::NotStarted);
                        }
                        Finish::Lost { why, more } => {
                            st[i] = St::Failed;
                            outcome.insert(i, Outcome::Failed { status: 1 });
                            say(format!("FAIL  {} ({why}); {more}", inst.name));
                            if !o.keep_going && !stop {
                                stop = true;
                                ex.stop_pending(&say)?;
                            }
                        }
                        Finish::Failed { status, why, log } => {
                            st[i] = St::Failed;
                            outcome.insert(i, Outcome::Failed { status });
                            let tail = log_tail(&ws.root.join(&log), 6);
                            say(format!(
                                "FAIL  {} (exit status {status}{}); log: {log}{tail}",
                                inst.name,
                                why.map(|w| format!(": {w}")).unwrap_or_default()
                            ));
                            if !o.keep_going && !stop {
                                stop = true;
                                ex.stop_pending(&say)?;
                            }
                        }
                    }
                }
            }
        }
    }
    main.finish_and_clear();
    ex.close(ws)?;
    ws.cache.save()?;
    let mut outcomes = vec![];
    for &i in &p.order {
        if selected[i] {
            outcomes.push((
                p.instances[i].name.clone(),
                outcome.get(&i).cloned().unwrap_or(Outcome::NotStarted),
            ));
        }
    }
    Ok(RunReport { outcomes })
}

/// Shell-quoted path for messages.
pub fn q(p: &Path) -> String {
    shell_quote(&p.display().to_string())
}
