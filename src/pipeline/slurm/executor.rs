//! The Slurm executor's controller: it submits the instances (a job array per group of a
//! stage that waits on the same jobs), adopts the live jobs of an earlier run, polls
//! `squeue` and the jobs' result files, and cancels the jobs when the run stops.

use std::collections::{BTreeMap, HashMap, HashSet};
use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, Ordering};

use super::files::{instance_key, jobs_dir, read_json, write_json, Files, JobResult, Ledger};
use super::queue::{abs, is_live, max_array_size, project_tag, scancel, squeue, Queued};
use super::submit::{manifest_text, print_dry, sbatch, Sbatch, Tasks};
use crate::error::{Result, WeftError};
use crate::pipeline::exec::{log_tail, Event, Executor, Finish, Launch};
use crate::pipeline::host::{now_unix, process_tag};
use crate::pipeline::spec::{ExecutorSpec, Pipeline};
use crate::pipeline::workspace::{Verdict, Workspace};

static INTERRUPTED: AtomicBool = AtomicBool::new(false);

extern "C" fn on_signal(_: libc::c_int) {
    INTERRUPTED.store(true, Ordering::SeqCst);
}

/// Ctrl-C, SIGTERM and SIGHUP set a flag that the poll loop acts on (cancelling the
/// jobs) instead of killing `weft` outright.
fn catch_signals() {
    let h = on_signal as extern "C" fn(libc::c_int) as libc::sighandler_t;
    unsafe {
        libc::signal(libc::SIGINT, h);
        libc::signal(libc::SIGTERM, h);
        libc::signal(libc::SIGHUP, h);
    }
}

/// A launched instance the controller waits for.
struct Track {
    job: String,
    started: bool,
    progress: f64,
    /// Polls since the job was seen over without a result file.
    over_polls: u32,
}

impl Track {
    /// A job just submitted or adopted: not seen running yet.
    fn new(job: String) -> Track {
        Track {
            job,
            started: false,
            progress: -1.0,
            over_polls: 0,
        }
    }
}

/// Runs instances as Slurm jobs (see the module `super`), and waits for them attached.
pub struct SlurmExecutor {
    spec: ExecutorSpec,
    stem: String,
    pipeline_file: PathBuf,
    root: PathBuf,
    weft_exe: PathBuf,
    files: Files,
    dry: bool,
    max_array: usize,
    out: BTreeMap<usize, Track>,
    /// Arrays this run submitted or adopted: array job id → number of tasks.
    arrays: HashMap<String, usize>,
    /// Dry runs: the number of sbatch commands printed.
    seq: usize,
    manifests: Vec<PathBuf>,
    squeue_failures: u32,
    /// `--comment` of this pipeline file's jobs.
    tag: String,
    /// Live jobs of an earlier run that [`SlurmExecutor::adopt`] cancelled.
    pub cancelled_at_start: usize,
    /// Pending reasons already reported (job and reason).
    noted: HashSet<String>,
}

impl SlurmExecutor {
    pub fn new(p: &Pipeline, dry: bool) -> Result<SlurmExecutor> {
        let weft_exe = std::env::current_exe()
            .map_err(|e| WeftError::input(format!("cannot locate the running `weft`: {e}")))?;
        let max_array = if dry { 1001 } else { max_array_size()? };
        if !dry {
            catch_signals();
        }
        Ok(SlurmExecutor {
            spec: p.executor.clone(),
            stem: p
                .file
                .file_stem()
                .map(|s| s.to_string_lossy().to_string())
                .unwrap_or_default(),
            pipeline_file: abs(&p.file),
            root: abs(&p.root),
            weft_exe,
            files: Files {
                dir: abs(&jobs_dir(p)),
            },
            dry,
            max_array,
            out: BTreeMap::new(),
            arrays: HashMap::new(),
            seq: 0,
            manifests: vec![],
            squeue_failures: 0,
            tag: project_tag(&p.file),
            cancelled_at_start: 0,
            noted: HashSet::new(),
        })
    }

    /// Take over the live jobs of an earlier, interrupted `weft run`: an instance whose
    /// job is still queued or running is waited for, not submitted again, when its work
    /// (key) is unchanged, it is not forced and everything it needs is fresh or adopted
    /// too; other live jobs of selected instances are cancelled, and so are live jobs of
    /// this pipeline file that no instance notes (submitted by a controller that died
    /// before it could write their job files). Returns the adopted instances with their
    /// job and state.
    pub fn adopt(
        &mut self,
        p: &Pipeline,
        selected: &[bool],
        force: &[bool],
        plan: &[Verdict],
    ) -> Result<Vec<(usize, String, String)>> {
        let ledgers: BTreeMap<usize, Ledger> = (0..p.instances.len())
            .filter_map(|i| Some((i, read_json(&self.files.ledger(&p.instances[i].name))?)))
            .collect();
        let q = squeue()?;
        let noted: HashSet<&str> = ledgers.values().map(|l| l.job.as_str()).collect();
        let mut cancel: Vec<String> = q
            .iter()
            .filter(|(id, j)| {
                j.comment == self.tag && is_live(&j.state) && !noted.contains(id.as_str())
            })
            .map(|(id, _)| id.clone())
            .collect();
        let mut adopted = vec![];
        let mut is_adopted = vec![false; p.instances.len()];
        for &i in &p.order {
            let Some(l) = ledgers.get(&i).filter(|_| selected[i]) else {
                continue;
            };
            let inst = &p.instances[i];
            let done = read_json::<JobResult>(&self.files.result(&inst.name))
                .is_some_and(|r| r.job == l.job);
            let state = q.get(&l.job).map(|j| j.state.clone()).unwrap_or_default();
            if done || !is_live(&state) {
                // Over: its record (if it wrote one) is what the plan judged.
                self.files.forget(&inst.name);
                continue;
            }
            let deps_ok = inst
                .deps
                .iter()
                .all(|&d| !selected[d] || plan[d].is_fresh() || is_adopted[d]);
            if l.key == instance_key(inst) && !force[i] && deps_ok {
                is_adopted[i] = true;
                self.out.insert(i, Track::new(l.job.clone()));
                adopted.push((i, l.job.clone(), state));
            } else {
                cancel.push(l.job.clone());
                self.files.forget(&inst.name);
            }
        }
        if !cancel.is_empty() {
            scancel(&cancel, None)?;
        }
        self.cancelled_at_start = cancel.len();
        Ok(adopted)
    }

    /// Submit one job (or array) of instances of one stage. `tasks`: (array task id,
    /// instance); `None` ids for a single job.
    fn submit(
        &mut self,
        p: &Pipeline,
        stage: &str,
        tasks: Tasks,
        dependency: Option<String>,
        say: &dyn Fn(String),
    ) -> Result<()> {
        let array = tasks[0].0.is_some();
        self.seq += 1;
        let nonce = format!("{}-{}-{}", stage, process_tag(), self.seq);
        let manifest = self
            .files
            .dir
            .join("manifests")
            .join(format!("{nonce}.tsv"));
        let text = manifest_text(p, &self.pipeline_file, &tasks);
        let res = self.spec.for_stage(stage);
        let slurm_dir = self.files.dir.join("slurm");
        let s = Sbatch {
            stem: &self.stem,
            stage,
            root: &self.root,
            slurm_dir: &slurm_dir,
            tag: &self.tag,
            array: array.then(|| tasks.iter().map(|(t, _)| t.expect("array")).collect()),
            dependency: dependency.as_deref(),
            resources: &res,
            weft_exe: &self.weft_exe,
            manifest: &manifest,
        };
        let args = s.args();
        let id = if self.dry {
            print_dry(p, self.seq, &args, &tasks)
        } else {
            self.manifests.push(manifest.clone());
            sbatch(&s, &args, text, &self.pipeline_file)?
        };
        if array {
            self.arrays.insert(id.clone(), tasks.len());
        }
        self.note_submitted(p, &id, &tasks, say)
    }

    /// Each instance of a submission is waited for; outside a dry run its ledger notes
    /// its job (and an old result file goes).
    fn note_submitted(
        &mut self,
        p: &Pipeline,
        id: &str,
        tasks: &Tasks,
        say: &dyn Fn(String),
    ) -> Result<()> {
        let now = now_unix();
        for (t, l) in tasks {
            let inst = &p.instances[l.idx];
            let job = match t {
                Some(t) => format!("{id}_{t}"),
                None => id.to_string(),
            };
            if !self.dry {
                let _ = std::fs::remove_file(self.files.result(&inst.name));
                write_json(
                    &self.files.ledger(&inst.name),
                    &Ledger {
                        job: job.clone(),
                        key: instance_key(inst),
                        submitted_unix: now,
                    },
                )?;
            }
            say(format!(
                "queue {} ({}): Slurm job {job}",
                inst.name, l.reason
            ));
            self.out.insert(l.idx, Track::new(job));
        }
        Ok(())
    }

    /// The jobs an instance must wait on, as handles for `--dependency`: the jobs of the
    /// upstream instances it must name, whole arrays where it waits on every task of one.
    fn dependency_handles(&self, p: &Pipeline, l: &Launch) -> Vec<String> {
        let deps = reduce(p, &l.waiting_on, &self.out);
        let jobs: Vec<String> = deps.iter().map(|d| self.out[d].job.clone()).collect();
        let mut per_array: BTreeMap<&str, usize> = BTreeMap::new();
        for j in &jobs {
            if let Some((a, _)) = split_task(j) {
                *per_array.entry(a).or_default() += 1;
            }
        }
        let whole: HashSet<&str> = per_array
            .iter()
            .filter(|(a, &n)| self.arrays.get(**a) == Some(&n))
            .map(|(a, _)| *a)
            .collect();
        let mut handles: Vec<String> = jobs
            .iter()
            .map(|j| match split_task(j) {
                Some((a, _)) if whole.contains(a) => a.to_string(),
                _ => j.clone(),
            })
            .collect();
        handles.sort();
        handles.dedup();
        handles
    }

    /// `squeue`, patient with a busy controller: `None` after a failure (having waited a
    /// poll), an error after about a minute of failures.
    fn poll_squeue(&mut self) -> Result<Option<HashMap<String, Queued>>> {
        match squeue() {
            Ok(q) => {
                self.squeue_failures = 0;
                Ok(Some(q))
            }
            Err(e) => {
                // A busy controller: try again, up to about a minute of failures.
                self.squeue_failures += 1;
                if f64::from(self.squeue_failures) * self.spec.poll_seconds > 60.0 {
                    return Err(e);
                }
                std::thread::sleep(std::time::Duration::from_secs_f64(self.spec.poll_seconds));
                Ok(None)
            }
        }
    }

    /// What happened to the jobs this run waits for since the last poll; the finished
    /// ones are no longer waited for.
    fn events(&mut self, p: &Pipeline, q: &HashMap<String, Queued>) -> Vec<Event> {
        let mut events = vec![];
        let mut done = vec![];
        let mut out = std::mem::take(&mut self.out);
        for (&i, t) in out.iter_mut() {
            if let Some(f) = self.look_at(&p.instances[i].name, i, t, q, &mut events) {
                done.push((i, f));
            }
        }
        self.out = out;
        for (i, f) in done {
            self.out.remove(&i);
            self.files.forget(&p.instances[i].name);
            events.push(Event::Done(i, f));
        }
        events
    }

    /// One job (instance `i`, `name`): a note when it is pending for a reason that will
    /// not pass by itself, its start and progress while it runs; its finish when its
    /// result file is there, or when it is over without one (after a grace of polls).
    fn look_at(
        &mut self,
        name: &str,
        i: usize,
        t: &mut Track,
        q: &HashMap<String, Queued>,
        events: &mut Vec<Event>,
    ) -> Option<Finish> {
        let (state, reason) = q
            .get(&t.job)
            .map(|j| (j.state.clone(), j.reason.clone()))
            .unwrap_or_else(|| ("UNKNOWN".into(), String::new()));
        if state == "PENDING" {
            events.extend(self.note_pending(name, &t.job, &reason));
            return None;
        }
        if let Some(r) = read_json::<JobResult>(&self.files.result(name)) {
            if r.job == t.job {
                return Some(match r.outcome.as_str() {
                    "ran" => Finish::Ran { seconds: r.seconds },
                    "fresh" => Finish::Fresh,
                    _ => Finish::Failed {
                        status: r.status,
                        why: r.why,
                        log: r.log,
                    },
                });
            }
        }
        if is_live(&state) {
            if !t.started {
                t.started = true;
                events.push(Event::Started(i));
            }
            if let Some(f) = std::fs::read_to_string(self.files.progress(name))
                .ok()
                .and_then(|s| s.trim().parse::<f64>().ok())
            {
                if f != t.progress {
                    t.progress = f;
                    events.push(Event::Progress(i, f));
                }
            }
            return None;
        }
        // Over, and no result (yet: on a network file system it may lag).
        t.over_polls += 1;
        let grace = if state == "COMPLETED" { 30 } else { 2 };
        if t.over_polls < grace {
            return None;
        }
        Some(self.lost(name, &t.job, &state, &reason))
    }

    /// A line for a job pending for a reason that will not pass by itself, once per job
    /// and reason.
    fn note_pending(&mut self, name: &str, job: &str, reason: &str) -> Option<Event> {
        // Reasons that pass by themselves are not worth a line.
        let waits = matches!(
            reason,
            "" | "None"
                | "Priority"
                | "Resources"
                | "Dependency"
                | "DependencyNeverSatisfied"
                | "BeginTime"
                | "JobArrayTaskLimit"
        );
        (!waits && self.noted.insert(format!("{job}\0{reason}"))).then(|| {
            Event::Note(format!(
                "wait  {name}: Slurm job {job} is pending ({reason}); `scontrol show job {job}` says more, Ctrl-C cancels the run"
            ))
        })
    }

    /// A job over without a result: what Slurm says of it, and its own output.
    fn lost(&self, name: &str, job: &str, state: &str, reason: &str) -> Finish {
        let out = self.files.slurm_out(job);
        let rel = out
            .strip_prefix(&self.root)
            .unwrap_or(&out)
            .display()
            .to_string();
        let what = match (state, reason) {
            ("UNKNOWN", _) => "no longer known to squeue".to_string(),
            ("COMPLETED", _) => format!(
                "completed, but its result file `{}` never appeared: is the project folder on a file system shared with the compute nodes?",
                self.files.result(name).strip_prefix(&self.root).unwrap_or(&self.files.result(name)).display()
            ),
            (s, "" | "None") => s.to_string(),
            (s, r) => format!("{s}, {r}"),
        };
        Finish::Lost {
            why: format!("Slurm job {job} {what}"),
            more: format!("Slurm's output: {rel}{}", log_tail(&out, 4)),
        }
    }

    fn all_jobs(&self) -> Vec<String> {
        self.out.values().map(|t| t.job.clone()).collect()
    }

    /// Cancel every job this run waits for (Ctrl-C, or an error).
    pub fn cancel_all(&mut self) -> usize {
        let jobs = self.all_jobs();
        if !self.dry && !jobs.is_empty() {
            let _ = scancel(&jobs, None);
        }
        jobs.len()
    }
}

/// Upstream instances an instance must name as dependencies: those it waits on, less
/// those another of them already waits on (through queued jobs).
fn reduce(p: &Pipeline, waiting: &[usize], queued: &BTreeMap<usize, Track>) -> Vec<usize> {
    if waiting.len() < 2 {
        return waiting.to_vec();
    }
    let mut below: HashSet<usize> = HashSet::new();
    let mut stack: Vec<usize> = vec![];
    for &w in waiting {
        stack.extend(p.instances[w].deps.iter().copied());
    }
    while let Some(d) = stack.pop() {
        if queued.contains_key(&d) && below.insert(d) {
            stack.extend(p.instances[d].deps.iter().copied());
        }
    }
    waiting
        .iter()
        .copied()
        .filter(|w| !below.contains(w))
        .collect()
}

/// `123_4` → (`123`, 4).
fn split_task(job: &str) -> Option<(&str, usize)> {
    let (a, t) = job.split_once('_')?;
    Some((a, t.parse().ok()?))
}

/// One `sbatch` of a stage's instances: a job or an array, and what it waits on.
struct Submission<'a> {
    tasks: Tasks<'a>,
    /// `--dependency`: `afterok:...` or `aftercorr:ARRAY`; `None` when it waits on nothing.
    dependency: Option<String>,
}

/// How the instances of one stage are submitted, in order (`mine`: each instance with the
/// job handles it waits on), arrays at most `max_array` tasks.
fn submissions<'a>(mine: Vec<&(&'a Launch, Vec<String>)>, max_array: usize) -> Vec<Submission<'a>> {
    // Aligned: each instance waits on exactly one task of one array A. Either
    // `aftercorr:A` arrays, task t of which waits on task t of A (one array per
    // instance waiting on the same task: `simulate@e,s` for both s after
    // `weave@e`), or one `afterok:A_t` array per task of A (many instances after
    // one task); whichever makes fewer submissions.
    let mut aligned: BTreeMap<String, BTreeMap<usize, Vec<&Launch>>> = BTreeMap::new();
    let mut grouped: BTreeMap<Vec<String>, Vec<&Launch>> = BTreeMap::new();
    for (l, h) in mine {
        match (h.as_slice(), h.first().and_then(|j| split_task(j))) {
            ([_], Some((a, t))) => aligned
                .entry(a.to_string())
                .or_default()
                .entry(t)
                .or_default()
                .push(*l),
            _ => grouped.entry(h.clone()).or_default().push(*l),
        }
    }
    let mut subs: Vec<Submission> = vec![];
    for (a, by_task) in aligned {
        let rounds = by_task.values().map(Vec::len).max().unwrap_or(0);
        if rounds > by_task.len() {
            for (t, ls) in by_task {
                grouped
                    .entry(vec![format!("{a}_{t}")])
                    .or_default()
                    .extend(ls);
            }
            continue;
        }
        for r in 0..rounds {
            let m: Vec<(usize, &Launch)> = by_task
                .iter()
                .filter_map(|(&t, ls)| ls.get(r).map(|l| (t, *l)))
                .collect();
            if let [(t, l)] = m.as_slice() {
                let dep = format!("afterok:{a}_{t}");
                subs.push(Submission {
                    tasks: vec![(None, *l)],
                    dependency: Some(dep),
                });
            } else {
                let tasks = m.into_iter().map(|(t, l)| (Some(t), l)).collect();
                subs.push(Submission {
                    tasks,
                    dependency: Some(format!("aftercorr:{a}")),
                });
            }
        }
    }
    for (h, ls) in grouped {
        let dep = (!h.is_empty()).then(|| format!("afterok:{}", h.join(":")));
        if ls.len() == 1 {
            subs.push(Submission {
                tasks: vec![(None, ls[0])],
                dependency: dep,
            });
            continue;
        }
        for chunk in ls.chunks(max_array.saturating_sub(1).max(1)) {
            let tasks = chunk
                .iter()
                .enumerate()
                .map(|(t, l)| (Some(t), *l))
                .collect();
            subs.push(Submission {
                tasks,
                dependency: dep.clone(),
            });
        }
    }
    subs
}

impl Executor for SlurmExecutor {
    fn eager(&self) -> bool {
        true
    }

    fn dry(&self) -> bool {
        self.dry
    }

    fn launch(
        &mut self,
        p: &Pipeline,
        _ws: &mut Workspace,
        batch: Vec<Launch>,
        say: &dyn Fn(String),
    ) -> Result<()> {
        // Dependencies of each instance as job handles, whole arrays where it waits on
        // every task of one.
        let reqs: Vec<(&Launch, Vec<String>)> = batch
            .iter()
            .map(|l| (l, self.dependency_handles(p, l)))
            .collect();
        // By stage, in the order the stages come.
        let mut stages: Vec<&str> = vec![];
        for (l, _) in &reqs {
            let s = p.instances[l.idx].stage.as_str();
            if !stages.contains(&s) {
                stages.push(s);
            }
        }
        for stage in stages {
            let mine: Vec<&(&Launch, Vec<String>)> = reqs
                .iter()
                .filter(|(l, _)| p.instances[l.idx].stage == stage)
                .collect();
            for s in submissions(mine, self.max_array) {
                self.submit(p, stage, s.tasks, s.dependency, say)?;
            }
        }
        Ok(())
    }

    fn wait(&mut self, p: &Pipeline, _ws: &mut Workspace) -> Result<Vec<Event>> {
        loop {
            if INTERRUPTED.load(Ordering::SeqCst) {
                let n = self.cancel_all();
                return Err(WeftError::input(format!(
                    "interrupted: cancelled the {n} Slurm jobs of this run"
                ))
                .hint("finished instances keep their outputs and records; `weft run --executor slurm` again runs the rest"));
            }
            let Some(q) = self.poll_squeue()? else {
                continue;
            };
            let events = self.events(p, &q);
            if !events.is_empty() {
                return Ok(events);
            }
            std::thread::sleep(std::time::Duration::from_secs_f64(self.spec.poll_seconds));
        }
    }

    fn stop_pending(&mut self, say: &dyn Fn(String)) -> Result<()> {
        let jobs = self.all_jobs();
        if jobs.is_empty() || self.dry {
            return Ok(());
        }
        say("stop  cancelling the queued jobs of this run (running ones finish)".into());
        scancel(&jobs, Some("PENDING"))
    }

    fn close(&mut self, _ws: &mut Workspace) -> Result<()> {
        if self.out.is_empty() {
            for m in self.manifests.drain(..) {
                let _ = std::fs::remove_file(m);
            }
        }
        Ok(())
    }
}
