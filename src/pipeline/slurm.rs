//! The Slurm executor: every stale instance a Slurm job, the instances of a sweep stage
//! one job array, dependencies as `afterok` (or `aftercorr` between aligned arrays) with
//! `--kill-on-invalid-dep=yes`, submitted with `sbatch --parsable`.
//!
//! `weft run --executor slurm` stays attached: it submits every stale instance at once
//! (an instance below a stale one waits in Slurm on its upstream jobs and is judged again
//! inside its job when they are done, as the local executor judges it when its turn
//! comes), then polls `squeue` and the jobs' result files, shows each running job's
//! progress, cancels the queued jobs after a failure (without `--keep-going`) and every
//! job on Ctrl-C. Each job runs `weft job`, which runs the instance exactly as the local
//! executor does and writes the instance's record itself, then a small result file for
//! the controller. So a controller that dies loses nothing: the jobs go on, and the next
//! `weft run` takes the records they wrote as the truth and adopts the jobs still queued
//! or running instead of submitting them again.
//!
//! Files, under `.weft/jobs/<pipeline>/` (on the shared file system, like the project):
//! `<instance>.job` (the job id and the instance's key, written at submission),
//! `<instance>.result` (written by the job), `<instance>.progress` (the job's latest
//! progress fraction), `manifests/` (instance names by array task) and `slurm/` (what
//! Slurm itself captured of each job: `JOB_TASK.out`).

use std::collections::{BTreeMap, HashMap, HashSet};
use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::atomic::{AtomicBool, Ordering};

use serde::{Deserialize, Serialize};

use super::exec::{
    finish, now_unix, prepare, process_tag, run_command, stage_path, Event, Executor, Finish,
    Launch,
};
use super::spec::{file_name_of, shell_quote, ExecutorSpec, Instance, Pipeline};
use super::workspace::{Verdict, Workspace};
use crate::error::{Result, WeftError};

/// What the controller writes when it submits an instance.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct Ledger {
    /// `JOBID` or `ARRAYJOBID_TASK`.
    pub job: String,
    /// [`instance_key`] at submission.
    pub key: String,
    pub submitted_unix: f64,
}

/// What a job writes when its instance is done.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct JobResult {
    pub job: String,
    /// `ran`, `fresh` or `failed`.
    pub outcome: String,
    pub status: i32,
    pub seconds: f64,
    pub why: Option<String>,
    pub log: String,
}

/// What identifies an instance's work: its command (with the final output paths), the
/// parameters it uses, its inputs and outputs. A job refuses to run when the pipeline file
/// changed it since submission.
pub fn instance_key(inst: &Instance) -> String {
    let mut h = blake3::Hasher::new();
    h.update(inst.command.as_bytes());
    for (k, v) in &inst.params {
        h.update(format!("\0p{k}={v}").as_bytes());
    }
    for (k, v) in &inst.inputs {
        h.update(format!("\0i{k}={}", v.display()).as_bytes());
    }
    for (k, v) in &inst.outputs {
        h.update(format!("\0o{k}={}", v.display()).as_bytes());
    }
    h.finalize().to_hex()[..16].to_string()
}

/// The folder of the Slurm executor's files for a pipeline.
pub fn jobs_dir(p: &Pipeline) -> PathBuf {
    let stem = p
        .file
        .file_stem()
        .map(|s| s.to_string_lossy().to_string())
        .unwrap_or_default();
    p.root.join(".weft").join("jobs").join(stem)
}

fn write_json<T: Serialize>(path: &Path, v: &T) -> Result<()> {
    if let Some(d) = path.parent() {
        std::fs::create_dir_all(d).map_err(|e| WeftError::io(d, e))?;
    }
    let tmp = path.with_extension(format!("tmp-{}", process_tag()));
    std::fs::write(&tmp, serde_json::to_string(v).expect("serialises"))
        .map_err(|e| WeftError::io(&tmp, e))?;
    std::fs::rename(&tmp, path).map_err(|e| WeftError::io(path, e))
}

fn read_json<T: for<'a> Deserialize<'a>>(path: &Path) -> Option<T> {
    serde_json::from_str(&std::fs::read_to_string(path).ok()?).ok()
}

struct Files {
    dir: PathBuf,
}

impl Files {
    fn of(&self, inst: &str, ext: &str) -> PathBuf {
        self.dir.join(format!("{}.{ext}", file_name_of(inst)))
    }
    fn ledger(&self, inst: &str) -> PathBuf {
        self.of(inst, "job")
    }
    fn result(&self, inst: &str) -> PathBuf {
        self.of(inst, "result")
    }
    fn progress(&self, inst: &str) -> PathBuf {
        self.of(inst, "progress")
    }
    fn slurm_out(&self, job: &str) -> PathBuf {
        self.dir.join("slurm").join(format!("{job}.out"))
    }
    fn forget(&self, inst: &str) {
        for e in ["job", "result", "progress"] {
            let _ = std::fs::remove_file(self.of(inst, e));
        }
    }
}

/// Job states `squeue` reports for jobs that are not over.
fn is_live(state: &str) -> bool {
    matches!(
        state,
        "PENDING"
            | "RUNNING"
            | "CONFIGURING"
            | "COMPLETING"
            | "SUSPENDED"
            | "REQUEUED"
            | "REQUEUE_HOLD"
            | "REQUEUE_FED"
            | "RESIZING"
            | "SIGNALING"
            | "STAGE_OUT"
            | "STOPPED"
    )
}

/// A job as `squeue` lists it.
#[derive(Debug, Clone)]
pub struct Queued {
    pub state: String,
    pub reason: String,
    /// `--comment`: `weft:TAG` for the jobs of a pipeline file (see [`project_tag`]).
    pub comment: String,
}

/// `squeue` of this user's jobs, array tasks one per line, finished ones included while
/// Slurm remembers them, by job id (`ID` or `ID_TASK`).
pub fn squeue() -> Result<HashMap<String, Queued>> {
    let out = Command::new("squeue")
        .args([
            "--noheader",
            "--array",
            "--states=all",
            "--me",
            "--format=%i|%T|%k|%r",
        ])
        .output()
        .map_err(|e| tool_error("squeue", e))?;
    if !out.status.success() {
        return Err(WeftError::input(format!(
            "`squeue` failed: {}",
            String::from_utf8_lossy(&out.stderr).trim()
        ))
        .hint("is the Slurm controller reachable from here (`sinfo`)?"));
    }
    Ok(String::from_utf8_lossy(&out.stdout)
        .lines()
        .filter_map(|l| {
            let mut it = l.trim().splitn(4, '|');
            let id = it.next()?.to_string();
            let state = it.next()?.to_string();
            let comment = it.next().unwrap_or("").to_string();
            let reason = it.next().unwrap_or("").to_string();
            Some((
                id,
                Queued {
                    state,
                    reason,
                    comment,
                },
            ))
        })
        .collect())
}

/// The `--comment` of the jobs of a pipeline file: `weft:` and a hash of its absolute
/// path, so that jobs submitted just before their controller died, before it could note
/// them, are recognised (and cancelled) by the next run.
pub fn project_tag(pipeline_file: &Path) -> String {
    let h = blake3::hash(abs(pipeline_file).display().to_string().as_bytes());
    format!("weft:{}", &h.to_hex()[..12])
}

fn tool_error(tool: &str, e: std::io::Error) -> WeftError {
    if e.kind() == std::io::ErrorKind::NotFound {
        WeftError::input(format!("`{tool}` not found: the Slurm executor needs the Slurm client commands"))
            .hint("run on a Slurm login node, or start a single-node Slurm with `scripts/slurm-single-node.sh start`; `weft run` without `--executor slurm` runs locally")
    } else {
        WeftError::input(format!("cannot run `{tool}`: {e}"))
    }
}

/// `scancel` the given jobs (ids or array tasks), optionally only those in `state`.
fn scancel(jobs: &[String], state: Option<&str>) -> Result<()> {
    for chunk in jobs.chunks(500) {
        let mut c = Command::new("scancel");
        if let Some(s) = state {
            c.arg(format!("--state={s}"));
        }
        let out = c
            .args(chunk)
            .output()
            .map_err(|e| tool_error("scancel", e))?;
        if !out.status.success() {
            let err = String::from_utf8_lossy(&out.stderr);
            // Jobs that ended meanwhile are not an error.
            if !err.lines().all(|l| {
                l.contains("already completing or completed")
                    || l.contains("Invalid job id")
                    || l.trim().is_empty()
            }) {
                return Err(WeftError::input(format!(
                    "`scancel` failed: {}",
                    err.trim()
                )));
            }
        }
    }
    Ok(())
}

/// Live Slurm jobs of earlier `weft run --executor slurm` of this pipeline, by instance:
/// (job, state). Empty without job files (without calling `squeue`).
pub fn live_jobs(p: &Pipeline) -> Result<BTreeMap<String, (String, String)>> {
    let files = Files { dir: jobs_dir(p) };
    let ledgers: Vec<(String, Ledger)> = p
        .instances
        .iter()
        .filter_map(|i| Some((i.name.clone(), read_json(&files.ledger(&i.name))?)))
        .collect();
    if ledgers.is_empty() {
        return Ok(BTreeMap::new());
    }
    let q = squeue()?;
    Ok(ledgers
        .into_iter()
        .filter_map(|(name, l)| {
            let j = q.get(&l.job)?;
            is_live(&j.state).then(|| (name, (l.job.clone(), j.state.clone())))
        })
        .collect())
}

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

fn abs(p: &Path) -> PathBuf {
    std::path::absolute(p).unwrap_or_else(|_| p.to_path_buf())
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
                self.out.insert(
                    i,
                    Track {
                        job: l.job.clone(),
                        started: false,
                        progress: -1.0,
                        over_polls: 0,
                    },
                );
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
        tasks: Vec<(Option<usize>, &Launch)>,
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
        let mut text = format!(
            "# weft job manifest: task, instance, key, forced\npipeline\t{}\n",
            self.pipeline_file.display()
        );
        for (t, l) in &tasks {
            let inst = &p.instances[l.idx];
            text.push_str(&format!(
                "{}\t{}\t{}\t{}\n",
                t.map(|t| t.to_string()).unwrap_or_else(|| "-".into()),
                inst.name,
                instance_key(inst),
                u8::from(l.force)
            ));
        }
        let res = self.spec.for_stage(stage);
        let slurm_dir = self.files.dir.join("slurm");
        let mut args: Vec<String> = vec![
            "--parsable".into(),
            format!("--job-name=weft:{}:{stage}", self.stem),
            format!("--chdir={}", self.root.display()),
            format!(
                "--output={}",
                slurm_dir
                    .join(if array { "%A_%a.out" } else { "%j.out" })
                    .display()
            ),
            "--kill-on-invalid-dep=yes".into(),
            format!("--comment={}", self.tag),
        ];
        if array {
            let ids: Vec<usize> = tasks.iter().map(|(t, _)| t.expect("array")).collect();
            args.push(format!("--array={}", ranges(&ids)));
        }
        if let Some(d) = &dependency {
            args.push(format!("--dependency={d}"));
        }
        if let Some(x) = &res.partition {
            args.push(format!("--partition={x}"));
        }
        if let Some(x) = &res.account {
            args.push(format!("--account={x}"));
        }
        if let Some(x) = &res.time {
            args.push(format!("--time={x}"));
        }
        if let Some(x) = &res.memory {
            args.push(format!("--mem={x}"));
        }
        if let Some(x) = res.cpus {
            args.push(format!("--cpus-per-task={x}"));
        }
        args.extend(res.sbatch_args.iter().cloned());
        args.push(format!(
            "--wrap={} job --manifest {}",
            shell_quote(&self.weft_exe.display().to_string()),
            shell_quote(&manifest.display().to_string())
        ));
        let id = if self.dry {
            let var = format!("J{}", self.seq);
            // Dependencies on earlier jobs of the dry run name them as `${Jn}`, in double
            // quotes so that the printed script expands them.
            let quote = |a: &String| {
                if a.starts_with("--dependency=") {
                    format!("\"{a}\"")
                } else {
                    shell_quote(a)
                }
            };
            println!(
                "{var}=$(sbatch {})",
                args.iter().map(quote).collect::<Vec<_>>().join(" ")
            );
            for (t, l) in &tasks {
                println!(
                    "#   {} {}",
                    t.map(|t| format!("task {t}:"))
                        .unwrap_or_else(|| "job:".into()),
                    p.instances[l.idx].name
                );
            }
            format!("${{{var}}}")
        } else {
            std::fs::create_dir_all(&slurm_dir).map_err(|e| WeftError::io(&slurm_dir, e))?;
            if let Some(d) = manifest.parent() {
                std::fs::create_dir_all(d).map_err(|e| WeftError::io(d, e))?;
            }
            std::fs::write(&manifest, text).map_err(|e| WeftError::io(&manifest, e))?;
            self.manifests.push(manifest.clone());
            let out = Command::new("sbatch")
                .args(&args)
                .output()
                .map_err(|e| tool_error("sbatch", e))?;
            let stdout = String::from_utf8_lossy(&out.stdout);
            let id = stdout.trim().split(';').next().unwrap_or("").to_string();
            if !out.status.success() || id.is_empty() || !id.bytes().all(|b| b.is_ascii_digit()) {
                return Err(WeftError::input(format!(
                    "`sbatch` refused the job of stage `{stage}`: {}{}",
                    String::from_utf8_lossy(&out.stderr).trim(),
                    stdout.trim()
                ))
                .in_file(&self.pipeline_file)
                .at_key(format!("executor (resources of stage `{stage}`)"))
                .hint("check partition, account, time, memory and cpus in [executor] against `sinfo`; `weft run --executor slurm --dry-run` prints the sbatch commands"));
            }
            id
        };
        if array {
            self.arrays.insert(id.clone(), tasks.len());
        }
        let now = now_unix();
        for (t, l) in &tasks {
            let inst = &p.instances[l.idx];
            let job = match t {
                Some(t) => format!("{id}_{t}"),
                None => id.clone(),
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
            self.out.insert(
                l.idx,
                Track {
                    job,
                    started: false,
                    progress: -1.0,
                    over_polls: 0,
                },
            );
        }
        Ok(())
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

/// Array task ids as Slurm's `--array` wants them: `0-3,7,9-10`.
fn ranges(ids: &[usize]) -> String {
    let mut v = ids.to_vec();
    v.sort_unstable();
    let mut parts = vec![];
    let mut i = 0;
    while i < v.len() {
        let mut j = i;
        while j + 1 < v.len() && v[j + 1] == v[j] + 1 {
            j += 1;
        }
        parts.push(if i == j {
            v[i].to_string()
        } else {
            format!("{}-{}", v[i], v[j])
        });
        i = j + 1;
    }
    parts.join(",")
}

/// `MaxArraySize` of the cluster (array task ids must stay below it).
fn max_array_size() -> Result<usize> {
    let out = Command::new("scontrol")
        .args(["show", "config"])
        .output()
        .map_err(|e| tool_error("scontrol", e))?;
    if !out.status.success() {
        return Err(WeftError::input(format!(
            "`scontrol show config` failed: {}",
            String::from_utf8_lossy(&out.stderr).trim()
        ))
        .hint("is the Slurm controller reachable from here (`sinfo`)?"));
    }
    Ok(String::from_utf8_lossy(&out.stdout)
        .lines()
        .find_map(|l| {
            let (k, v) = l.split_once('=')?;
            (k.trim() == "MaxArraySize").then(|| v.trim().parse().ok())?
        })
        .unwrap_or(1001))
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
        let mut reqs: Vec<(&Launch, Vec<String>)> = vec![];
        for l in &batch {
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
            reqs.push((l, handles));
        }
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
                        self.submit(p, stage, vec![(None, *l)], Some(dep), say)?;
                    } else {
                        let tasks = m.into_iter().map(|(t, l)| (Some(t), l)).collect();
                        self.submit(p, stage, tasks, Some(format!("aftercorr:{a}")), say)?;
                    }
                }
            }
            for (h, ls) in grouped {
                let dep = (!h.is_empty()).then(|| format!("afterok:{}", h.join(":")));
                if ls.len() == 1 {
                    self.submit(p, stage, vec![(None, ls[0])], dep, say)?;
                    continue;
                }
                for chunk in ls.chunks(self.max_array.saturating_sub(1).max(1)) {
                    let tasks = chunk
                        .iter()
                        .enumerate()
                        .map(|(t, l)| (Some(t), *l))
                        .collect();
                    self.submit(p, stage, tasks, dep.clone(), say)?;
                }
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
            let q = match squeue() {
                Ok(q) => {
                    self.squeue_failures = 0;
                    q
                }
                Err(e) => {
                    // A busy controller: try again, up to about a minute of failures.
                    self.squeue_failures += 1;
                    if f64::from(self.squeue_failures) * self.spec.poll_seconds > 60.0 {
                        return Err(e);
                    }
                    std::thread::sleep(std::time::Duration::from_secs_f64(self.spec.poll_seconds));
                    continue;
                }
            };
            let mut events = vec![];
            let mut done = vec![];
            for (&i, t) in self.out.iter_mut() {
                let name = &p.instances[i].name;
                let (state, reason) = q
                    .get(&t.job)
                    .map(|j| (j.state.clone(), j.reason.clone()))
                    .unwrap_or_else(|| ("UNKNOWN".into(), String::new()));
                if state == "PENDING" {
                    // Reasons that pass by themselves are not worth a line.
                    let waits = matches!(
                        reason.as_str(),
                        "" | "None"
                            | "Priority"
                            | "Resources"
                            | "Dependency"
                            | "DependencyNeverSatisfied"
                            | "BeginTime"
                            | "JobArrayTaskLimit"
                    );
                    if !waits && self.noted.insert(format!("{}\0{reason}", t.job)) {
                        events.push(Event::Note(format!(
                            "wait  {name}: Slurm job {} is pending ({reason}); `scontrol show job {}` says more, Ctrl-C cancels the run",
                            t.job, t.job
                        )));
                    }
                    continue;
                }
                if let Some(r) = read_json::<JobResult>(&self.files.result(name)) {
                    if r.job == t.job {
                        done.push((
                            i,
                            match r.outcome.as_str() {
                                "ran" => Finish::Ran { seconds: r.seconds },
                                "fresh" => Finish::Fresh,
                                _ => Finish::Failed {
                                    status: r.status,
                                    why: r.why,
                                    log: r.log,
                                },
                            },
                        ));
                        continue;
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
                    continue;
                }
                // Over, and no result (yet: on a network file system it may lag).
                t.over_polls += 1;
                let grace = if state == "COMPLETED" { 30 } else { 2 };
                if t.over_polls < grace {
                    continue;
                }
                let out = self.files.slurm_out(&t.job);
                let rel = out
                    .strip_prefix(&self.root)
                    .unwrap_or(&out)
                    .display()
                    .to_string();
                let what = match (state.as_str(), reason.as_str()) {
                    ("UNKNOWN", _) => "no longer known to squeue".to_string(),
                    ("COMPLETED", _) => format!(
                        "completed, but its result file `{}` never appeared: is the project folder on a file system shared with the compute nodes?",
                        self.files.result(name).strip_prefix(&self.root).unwrap_or(&self.files.result(name)).display()
                    ),
                    (s, "" | "None") => s.to_string(),
                    (s, r) => format!("{s}, {r}"),
                };
                done.push((
                    i,
                    Finish::Lost {
                        why: format!("Slurm job {} {what}", t.job),
                        more: format!("Slurm's output: {rel}{}", super::exec::log_tail(&out, 4)),
                    },
                ));
            }
            for (i, f) in done {
                self.out.remove(&i);
                self.files.forget(&p.instances[i].name);
                events.push(Event::Done(i, f));
            }
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

/// `weft job --manifest FILE`: inside a Slurm job, run the instance of this array task
/// (or the job's only instance) as the local executor would, write its record, then its
/// result file. Exits with the instance's status, so that `afterok` holds its dependants
/// back after a failure.
pub fn run_job(manifest: &Path, task: Option<String>) -> Result<i32> {
    let text = std::fs::read_to_string(manifest).map_err(|e| WeftError::io(manifest, e))?;
    let bad = |what: &str| {
        WeftError::input(format!("job manifest: {what}"))
            .in_file(manifest)
            .hint("manifests are written by `weft run --executor slurm`; submit through it")
    };
    let mut lines = text.lines().filter(|l| !l.starts_with('#'));
    let pipeline = lines
        .next()
        .and_then(|l| l.strip_prefix("pipeline\t"))
        .ok_or_else(|| bad("no `pipeline` line"))?;
    let task = task
        .or_else(|| std::env::var("SLURM_ARRAY_TASK_ID").ok())
        .unwrap_or_else(|| "-".into());
    let line = lines
        .find(|l| l.split('\t').next() == Some(task.as_str()))
        .ok_or_else(|| bad(&format!("no line for task `{task}`")))?;
    let f: Vec<&str> = line.split('\t').collect();
    let [_, name, key, forced] = f.as_slice() else {
        return Err(bad(&format!("malformed line {line:?}")));
    };
    let job = match (
        std::env::var("SLURM_ARRAY_JOB_ID"),
        std::env::var("SLURM_ARRAY_TASK_ID"),
        std::env::var("SLURM_JOB_ID"),
    ) {
        (Ok(a), Ok(t), _) => format!("{a}_{t}"),
        (_, _, Ok(j)) => j,
        _ => "local".into(),
    };
    let p = Pipeline::load(Path::new(pipeline))?;
    let files = Files { dir: jobs_dir(&p) };
    let result = |outcome: &str, status: i32, seconds: f64, why: Option<String>, log: String| {
        write_json(
            &files.result(name),
            &JobResult {
                job: job.clone(),
                outcome: outcome.into(),
                status,
                seconds,
                why,
                log,
            },
        )
    };
    let Some(inst) = p.instances.iter().find(|i| i.name == *name) else {
        let why = format!("instance `{name}` is no longer in `{pipeline}`");
        eprintln!("weft job: {why}");
        result("failed", 2, 0.0, Some(why), String::new())?;
        return Ok(2);
    };
    if instance_key(inst) != *key {
        let why = format!(
            "`{pipeline}` changed `{name}` (command, parameters, inputs or outputs) since this job was submitted; `weft run` submits it again"
        );
        eprintln!("weft job: {why}");
        result("failed", 2, 0.0, Some(why), String::new())?;
        return Ok(2);
    }
    let mut ws = Workspace::open(&p);
    if *forced != "1" && ws.verdict(inst)? == Verdict::Fresh {
        eprintln!("weft job: `{name}` is fresh (its upstream reproduced the same inputs)");
        result("fresh", 0, 0.0, None, String::new())?;
        return Ok(0);
    }
    let a = prepare(&p, &ws, inst, &super::exec::attempt_tag())?;
    let progress_file = files.progress(name);
    let mut last = 0.0f64;
    let ran = run_command(&a, &ws.root.clone(), &stage_path(&ws), &mut |f| {
        let now = now_unix();
        if now - last >= 0.5 {
            last = now;
            let tmp = progress_file.with_extension(format!("progress-{}", process_tag()));
            if std::fs::write(&tmp, format!("{f}\n")).is_ok() {
                let _ = std::fs::rename(&tmp, &progress_file);
            }
        }
    });
    let fin = finish(&mut ws, inst, a, ran.clone())?;
    let _ = std::fs::remove_file(&progress_file);
    let status = match fin {
        Finish::Ran { seconds } => {
            result("ran", 0, seconds, None, inst_log(&ws, inst))?;
            0
        }
        Finish::Failed { status, why, log } => {
            if let Some(w) = &why {
                eprintln!("weft job: `{name}` failed: {w}");
            }
            result("failed", status, ran.end - ran.start, why, log)?;
            status
        }
        Finish::Fresh | Finish::Lost { .. } => unreachable!("finish only runs or fails"),
    };
    Ok(status.clamp(0, 255))
}

fn inst_log(ws: &Workspace, inst: &Instance) -> String {
    super::exec::log_paths(ws, inst).1
}
