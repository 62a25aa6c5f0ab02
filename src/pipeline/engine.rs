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

use super::exec::{log_tail, Event, Executor, Finish, Launch, LocalExecutor};
use super::progress::View;
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

/// Each selected instance's outcome, in a dependency order.
pub struct RunReport {
    pub outcomes: Vec<(String, Outcome)>,
}

/// How many instances of a run ran, were fresh, failed, or were not run.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Tally {
    pub ran: usize,
    pub fresh: usize,
    pub failed: usize,
    /// Skipped after an upstream failure, or not started after a failure.
    pub not_run: usize,
}

impl RunReport {
    /// The counts `weft run` ends with.
    pub fn tally(&self) -> Tally {
        Tally {
            ran: self.ran().len(),
            fresh: self
                .outcomes
                .iter()
                .filter(|o| o.1 == Outcome::Fresh)
                .count(),
            failed: self.failed(),
            not_run: self
                .outcomes
                .iter()
                .filter(|o| matches!(o.1, Outcome::Skipped | Outcome::NotStarted))
                .count(),
        }
    }

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
        return dry_run(p, ws, selected, force, &plan, o);
    }
    let _lock = lock(&p.root)?;
    match o.executor {
        ExecutorKind::Local => {
            refuse_live_slurm_jobs(p)?;
            let mut ex = LocalExecutor::new(ws);
            schedule(p, ws, selected, force, &plan, o, &mut ex, vec![])
        }
        ExecutorKind::Slurm => run_on_slurm(p, ws, selected, force, &plan, o),
    }
}

/// `--dry-run`: say what would run and why (with `--executor slurm`, print the sbatch
/// commands too); run nothing.
fn dry_run(
    p: &Pipeline,
    ws: &mut Workspace,
    selected: &[bool],
    force: &[bool],
    plan: &[Verdict],
    o: &RunOptions,
) -> Result<RunReport> {
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
        schedule(p, ws, selected, force, plan, &quiet, &mut ex, vec![])?;
    }
    ws.cache.save()?;
    Ok(RunReport { outcomes })
}

/// A local run refuses to start while Slurm jobs of an earlier run are live: it would
/// race them.
fn refuse_live_slurm_jobs(p: &Pipeline) -> Result<()> {
    let live = super::slurm::live_jobs(p).unwrap_or_default();
    if let Some((inst, (job, state))) = live.iter().next() {
        return Err(WeftError::input(format!(
            "{} Slurm jobs of an earlier `weft run --executor slurm` are still queued or running (`{inst}`: job {job}, {state})",
            live.len()
        ))
        .in_file(&p.file)
        .hint("running them here too would race them; `weft run --executor slurm` waits for them, or cancel them with scancel"));
    }
    Ok(())
}

/// `--executor slurm`: adopt the live jobs of an earlier run, submit the rest, wait; on
/// an error, cancel the jobs of this run.
fn run_on_slurm(
    p: &Pipeline,
    ws: &mut Workspace,
    selected: &[bool],
    force: &[bool],
    plan: &[Verdict],
    o: &RunOptions,
) -> Result<RunReport> {
    let mut ex = SlurmExecutor::new(p, false)?;
    let adopted = ex.adopt(p, selected, force, plan)?;
    if ex.cancelled_at_start > 0 && !o.quiet {
        eprintln!(
            "cancel {} Slurm jobs of an earlier `weft run` (their work changed, they were forced, something they need is stale again, or the run died before noting them)",
            ex.cancelled_at_start
        );
    }
    let r = schedule(p, ws, selected, force, plan, o, &mut ex, adopted);
    if r.is_err() {
        ex.cancel_all();
    }
    r
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
    let mut s = Schedule::new(p, selected, force, plan, o, ex.dry());
    s.adopt(adopted);
    loop {
        // Hand over every ready instance; those it needs must be done or, for an eager
        // executor, handed over in an earlier pass (so that they have a job to wait on).
        let (batch, mut progressed) = s.ready(ws, &*ex)?;
        if !batch.is_empty() {
            s.running += batch.len();
            ex.launch(p, ws, batch, &|m| s.view.say(m))?;
            progressed = true;
        }
        if progressed {
            continue;
        }
        if s.running == 0 || ex.dry() {
            break;
        }
        for ev in ex.wait(p, ws)? {
            s.on_event(ev, ws, ex)?;
        }
    }
    s.view.finish();
    ex.close(ws)?;
    ws.cache.save()?;
    Ok(s.report())
}

/// Where a selected instance stands in the scheduling loop.
#[derive(Clone, Copy, PartialEq)]
enum State {
    Pending,
    Running,
    Ok,
    Failed,
    Skipped,
}

/// The scheduling loop's state: what the run was asked (the selected and the forced
/// instances, the plan, the options), where each instance stands, and the progress view.
struct Schedule<'a> {
    p: &'a Pipeline,
    selected: &'a [bool],
    force: &'a [bool],
    plan: &'a [Verdict],
    o: &'a RunOptions,
    st: Vec<State>,
    outcome: BTreeMap<usize, Outcome>,
    /// Instances handed over and not done yet.
    running: usize,
    /// A failure stopped the run (without `--keep-going`): nothing new starts.
    stop: bool,
    view: View,
}

impl<'a> Schedule<'a> {
    fn new(
        p: &'a Pipeline,
        selected: &'a [bool],
        force: &'a [bool],
        plan: &'a [Verdict],
        o: &'a RunOptions,
        dry: bool,
    ) -> Schedule<'a> {
        let n = p.instances.len();
        let stale_count = (0..n)
            .filter(|&i| selected[i] && !plan[i].is_fresh())
            .count();
        Schedule {
            p,
            selected,
            force,
            plan,
            o,
            st: vec![State::Pending; n],
            outcome: BTreeMap::new(),
            running: 0,
            stop: false,
            view: View::new(o.quiet, stale_count as u64, !dry),
        }
    }

    /// The live jobs of an earlier run that the executor took over: running already.
    fn adopt(&mut self, adopted: Vec<(usize, String, String)>) {
        for (i, job, state) in adopted {
            self.st[i] = State::Running;
            self.running += 1;
            self.view.say(format!(
                "adopt {}: Slurm job {job} ({state}) of an earlier `weft run`",
                self.p.instances[i].name
            ));
        }
    }

    /// Instance `i` is over: where it stands, and its outcome.
    fn settle(&mut self, i: usize, state: State, outcome: Outcome) {
        self.st[i] = state;
        self.outcome.insert(i, outcome);
    }

    /// Whether a selected upstream instance of `i` failed or was skipped.
    fn upstream_failed(&self, i: usize) -> bool {
        self.p.instances[i]
            .deps
            .iter()
            .any(|&d| self.selected[d] && matches!(self.st[d], State::Failed | State::Skipped))
    }

    /// One pass over the instances in order: skip those a failure cut off, settle those
    /// judged fresh now, and return those ready to hand over, with whether anything
    /// changed.
    fn ready(&mut self, ws: &mut Workspace, ex: &dyn Executor) -> Result<(Vec<Launch>, bool)> {
        let (p, selected) = (self.p, self.selected);
        let mut progressed = false;
        let mut batch: Vec<Launch> = vec![];
        let mut this_pass = vec![false; p.instances.len()];
        for &i in &p.order {
            if !selected[i] || self.st[i] != State::Pending {
                continue;
            }
            let inst = &p.instances[i];
            let deps = || inst.deps.iter().copied().filter(|&d| selected[d]);
            if self.upstream_failed(i) {
                self.settle(i, State::Skipped, Outcome::Skipped);
                self.view
                    .say(format!("skip  {} (an upstream stage failed)", inst.name));
                progressed = true;
                continue;
            }
            if deps().any(|d| self.st[d] == State::Pending || this_pass[d]) {
                continue;
            }
            let waiting_on: Vec<usize> = deps().filter(|&d| self.st[d] == State::Running).collect();
            if self.stop || (!waiting_on.is_empty() && !ex.eager()) {
                continue;
            }
            if !ex.eager() && self.running + batch.len() >= self.o.jobs.max(1) {
                continue;
            }
            let Some(reason) = self.reason(i, &waiting_on, ws)? else {
                self.settle(i, State::Ok, Outcome::Fresh);
                progressed = true;
                continue;
            };
            check_command(p, ws, i)?;
            self.st[i] = State::Running;
            this_pass[i] = true;
            batch.push(Launch {
                idx: i,
                reason,
                force: self.force[i],
                waiting_on,
            });
        }
        Ok((batch, progressed))
    }

    /// Why instance `i` runs now (`waiting_on`: the upstream instances it waits on);
    /// `None` when, its upstream done, it is fresh on the current content of its inputs.
    fn reason(&self, i: usize, waiting_on: &[usize], ws: &mut Workspace) -> Result<Option<String>> {
        Ok(Some(if self.force[i] {
            "forced".to_string()
        } else if !waiting_on.is_empty() {
            match &self.plan[i] {
                Verdict::Stale(r) | Verdict::Waiting(r) => r.clone(),
                Verdict::Fresh => "upstream reruns".into(),
            }
        } else {
            match ws.verdict(&self.p.instances[i])? {
                Verdict::Fresh => return Ok(None),
                Verdict::Stale(r) | Verdict::Waiting(r) => r,
            }
        }))
    }

    /// What an executor reports: the progress view follows it, a done instance settles.
    fn on_event(&mut self, ev: Event, ws: &Workspace, ex: &mut dyn Executor) -> Result<()> {
        match ev {
            Event::Started(i) => self.view.started(i, &self.p.instances[i].name),
            Event::Note(s) => self.view.say(s),
            Event::Progress(i, f) => self.view.progress(i, f),
            Event::Done(i, fin) => {
                self.running -= 1;
                self.view.done(i);
                self.on_done(i, fin, ws, ex)?;
            }
        }
        Ok(())
    }

    /// Settle a finished instance: ran, fresh after all, skipped (its job lost after an
    /// upstream failure or a stop) or failed (which stops the run without `--keep-going`).
    fn on_done(
        &mut self,
        i: usize,
        fin: Finish,
        ws: &Workspace,
        ex: &mut dyn Executor,
    ) -> Result<()> {
        let p = self.p;
        let inst = &p.instances[i];
        match fin {
            Finish::Ran { seconds } => {
                self.settle(i, State::Ok, Outcome::Ran { seconds });
                self.view
                    .say(format!("done  {} ({seconds:.2} s)", inst.name));
            }
            Finish::Fresh => {
                self.settle(i, State::Ok, Outcome::Fresh);
                self.view.say(format!(
                    "fresh {} (its upstream reproduced the same inputs)",
                    inst.name
                ));
            }
            Finish::Lost { why, .. } if self.upstream_failed(i) => {
                self.settle(i, State::Skipped, Outcome::Skipped);
                self.view.say(format!(
                    "skip  {} (an upstream stage failed; {why})",
                    inst.name
                ));
            }
            Finish::Lost { .. } if self.stop => {
                self.settle(i, State::Skipped, Outcome::NotStarted);
            }
            Finish::Lost { why, more } => {
                self.settle(i, State::Failed, Outcome::Failed { status: 1 });
                self.view
                    .say(format!("FAIL  {} ({why}); {more}", inst.name));
                self.stop_after_failure(ex)?;
            }
            Finish::Failed { status, why, log } => {
                self.settle(i, State::Failed, Outcome::Failed { status });
                let tail = log_tail(&ws.root.join(&log), 6);
                self.view.say(format!(
                    "FAIL  {} (exit status {status}{}); log: {log}{tail}",
                    inst.name,
                    why.map(|w| format!(": {w}")).unwrap_or_default()
                ));
                self.stop_after_failure(ex)?;
            }
        }
        Ok(())
    }

    /// Without `--keep-going`, the first failure stops the run: nothing new starts.
    fn stop_after_failure(&mut self, ex: &mut dyn Executor) -> Result<()> {
        if !self.o.keep_going && !self.stop {
            self.stop = true;
            ex.stop_pending(&|s| self.view.say(s))?;
        }
        Ok(())
    }

    /// Each selected instance's outcome, in order; not started when it has none.
    fn report(&self) -> RunReport {
        let mut outcomes = vec![];
        for &i in &self.p.order {
            if self.selected[i] {
                outcomes.push((
                    self.p.instances[i].name.clone(),
                    self.outcome.get(&i).cloned().unwrap_or(Outcome::NotStarted),
                ));
            }
        }
        RunReport { outcomes }
    }
}

/// A stage whose command's program is found neither beside `weft` nor on PATH is an
/// error of the pipeline, not a failure of the stage.
fn check_command(p: &Pipeline, ws: &Workspace, i: usize) -> Result<()> {
    let inst = &p.instances[i];
    if ws.binary_of(&inst.command).is_none() {
        let name = ws.program_of(&inst.command).unwrap_or_default();
        return Err(
            WeftError::input(format!("stage `{}`: command `{name}` not found", inst.name))
                .in_file(&p.file)
                .at_line(inst.line)
                .at_key(format!("stages.{}.cmd", inst.stage))
                .hint("build the weft binaries (`cargo build --release`) or put the tool on PATH"),
        );
    }
    Ok(())
}

/// Shell-quoted path for messages.
pub fn q(p: &Path) -> String {
    shell_quote(&p.display().to_string())
}
