//! Running one stage instance, and the executor seam.
//!
//! One attempt of an instance is the same three steps wherever it runs: [`prepare`]
//! (temporary output paths beside the real ones, the command rendered with them, old
//! temporaries of earlier attempts removed), [`run_command`] (`sh -c CMD` in the project
//! root, output to the instance's log, progress lines passed on), and [`finish`] (the
//! temporaries renamed into place on success, then the record written: the record is the
//! commit point). The local executor runs them in `weft run` itself; the Slurm executor
//! (`super::slurm`) runs them inside each job (`weft job`), which writes its own record.
//!
//! Temporaries are named after the attempt, not after the controller:
//! `.NAME.weft-tmp-HOST-PID` (local) or `.NAME.weft-tmp-slurmJOBID` (Slurm). At most one
//! attempt of an instance runs at a time (the project lock, and Slurm jobs of an earlier
//! run are adopted rather than doubled), so an attempt removes every other temporary of
//! its own outputs before it starts.

use std::collections::{BTreeMap, VecDeque};
use std::io::{BufRead, BufReader, Write};
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::sync::mpsc;

pub use super::host::{attempt_tag, host_name, now_unix, process_tag};
use super::record::{iso_utc, Record};
use super::spec::{file_name_of, render, Ctx, Instance, Pipeline};
use super::workspace::Workspace;
use crate::error::{Result, WeftError};

fn name_of(p: &Path) -> String {
    p.file_name()
        .map(|s| s.to_string_lossy().to_string())
        .unwrap_or_default()
}

fn tmp_sibling(p: &Path, kind: &str, tag: &str) -> PathBuf {
    p.with_file_name(format!(".{}.weft-{kind}-{tag}", name_of(p)))
}

pub fn remove_path(p: &Path) -> std::io::Result<()> {
    if p.is_dir() {
        std::fs::remove_dir_all(p)
    } else {
        std::fs::remove_file(p)
    }
}

/// Remove the temporaries (`.NAME.weft-tmp-*`, `.NAME.weft-old-*`) that earlier,
/// interrupted attempts left beside output `dest`.
fn remove_old_temporaries(dest: &Path) {
    let Some(dir) = dest.parent() else { return };
    let Ok(rd) = std::fs::read_dir(dir) else {
        return;
    };
    let stem = format!(".{}.weft-", name_of(dest));
    for e in rd.flatten() {
        let n = e.file_name().to_string_lossy().to_string();
        if let Some(rest) = n.strip_prefix(&stem) {
            if rest.starts_with("tmp-") || rest.starts_with("old-") {
                let _ = remove_path(&e.path());
            }
        }
    }
}

/// Move a finished temporary output into place, replacing the old one.
fn commit_output(tmp: &Path, dest: &Path, tag: &str) -> std::io::Result<()> {
    if dest.exists() {
        let old = tmp_sibling(dest, "old", tag);
        std::fs::rename(dest, &old)?;
        std::fs::rename(tmp, dest)?;
        let _ = remove_path(&old);
    } else {
        std::fs::rename(tmp, dest)?;
    }
    Ok(())
}

/// The log of an instance, and its path relative to the project root (as records store it).
pub fn log_paths(ws: &Workspace, inst: &Instance) -> (PathBuf, String) {
    let log = ws.logs.join(format!("{}.log", file_name_of(&inst.name)));
    let rel = log
        .strip_prefix(&ws.root)
        .unwrap_or(&log)
        .display()
        .to_string();
    (log, rel)
}

/// One attempt of an instance, ready to run.
#[derive(Debug, Clone)]
pub struct Attempt {
    pub name: String,
    /// The command with the temporary output paths.
    pub command: String,
    /// (temporary, final) absolute output paths.
    pub pairs: Vec<(PathBuf, PathBuf)>,
    pub log: PathBuf,
    pub log_rel: String,
    pub tag: String,
}

/// Temporary outputs beside the real ones (after removing earlier attempts' leftovers),
/// and the command rendered with them.
pub fn prepare(p: &Pipeline, ws: &Workspace, inst: &Instance, tag: &str) -> Result<Attempt> {
    let mut pairs = vec![];
    let mut outs_tmp = vec![];
    for (k, out) in &inst.outputs {
        let dest = ws.abs(out);
        if let Some(d) = dest.parent() {
            std::fs::create_dir_all(d).map_err(|e| WeftError::io(d, e))?;
        }
        remove_old_temporaries(&dest);
        let tmp = tmp_sibling(&dest, "tmp", tag);
        let rel = tmp
            .strip_prefix(&ws.root)
            .unwrap_or(&tmp)
            .display()
            .to_string();
        outs_tmp.push((k.clone(), rel));
        pairs.push((tmp, dest));
    }
    let ins: Vec<(String, String)> = inst
        .inputs
        .iter()
        .map(|(k, v)| (k.clone(), v.display().to_string()))
        .collect();
    let ctx = Ctx {
        values: &inst.values,
        inputs: &ins,
        outputs: &outs_tmp,
        stage: &inst.stage,
        instance: &inst.name,
    };
    let command = render(&inst.cmd_template, &ctx)
        .map_err(|e| WeftError::input(e).in_file(&p.file).at_line(inst.line))?
        .0;
    let (log, log_rel) = log_paths(ws, inst);
    Ok(Attempt {
        name: inst.name.clone(),
        command,
        pairs,
        log,
        log_rel,
        tag: tag.to_string(),
    })
}

/// How the command of an attempt ended.
#[derive(Debug, Clone)]
pub struct Ran {
    pub status: i32,
    pub start: f64,
    pub end: f64,
    pub error: Option<String>,
}

/// `PATH` for stages: the folder of the running `weft` first.
pub fn stage_path(ws: &Workspace) -> std::ffi::OsString {
    let mut dirs: Vec<PathBuf> = ws.exe_dir.iter().cloned().collect();
    dirs.extend(std::env::split_paths(
        &std::env::var_os("PATH").unwrap_or_default(),
    ));
    std::env::join_paths(dirs).unwrap_or_default()
}

/// Run the command of an attempt: `sh -c CMD` in `root`, stdout and stderr to the log,
/// `weft-progress F` lines on stderr passed to `progress` instead.
pub fn run_command(
    a: &Attempt,
    root: &Path,
    path_env: &std::ffi::OsStr,
    progress: &mut dyn FnMut(f64),
) -> Ran {
    let start = now_unix();
    let res = (|| -> std::io::Result<i32> {
        if let Some(d) = a.log.parent() {
            std::fs::create_dir_all(d)?;
        }
        let mut log = std::fs::File::create(&a.log)?;
        writeln!(
            log,
            "# weft stage `{}`\n# started {}\n# command: {}\n",
            a.name,
            iso_utc(start),
            a.command
        )?;
        let mut cmd = Command::new("sh");
        cmd.arg("-c")
            .arg(&a.command)
            .current_dir(root)
            .env("PATH", path_env)
            .env("WEFT_PROGRESS", "1")
            .env("WEFT_STAGE", &a.name)
            .stdin(Stdio::null())
            .stdout(Stdio::from(log.try_clone()?))
            .stderr(Stdio::piped());
        #[cfg(target_os = "linux")]
        unsafe {
            use std::os::unix::process::CommandExt;
            cmd.pre_exec(|| {
                // The stage dies with its parent: an interrupted run leaves no orphan writing.
                libc::prctl(libc::PR_SET_PDEATHSIG, libc::SIGKILL);
                Ok(())
            });
        }
        let mut child = cmd.spawn()?;
        let stderr = child.stderr.take().expect("piped");
        for line in BufReader::new(stderr).lines() {
            let line = line?;
            if let Some(f) = line
                .strip_prefix("weft-progress ")
                .and_then(|s| s.trim().parse::<f64>().ok())
            {
                progress(f);
            } else {
                writeln!(log, "{line}")?;
            }
        }
        let st = child.wait()?;
        Ok(st.code().unwrap_or_else(|| {
            use std::os::unix::process::ExitStatusExt;
            128 + st.signal().unwrap_or(0)
        }))
    })();
    let end = now_unix();
    let (status, error) = match res {
        Ok(s) => (s, None),
        Err(e) => (127, Some(e.to_string())),
    };
    Ran {
        status,
        start,
        end,
        error,
    }
}

/// The end of an instance, as the engine reports it.
#[derive(Debug, Clone, PartialEq)]
pub enum Finish {
    Ran {
        seconds: f64,
    },
    /// Judged fresh when its turn came (its upstream reran and reproduced the same bytes).
    Fresh,
    Failed {
        status: i32,
        why: Option<String>,
        /// The log, relative to the project root.
        log: String,
    },
    /// The executor lost it without a result (a Slurm job cancelled, timed out, killed);
    /// the engine decides whether that is a failure or a skip.
    Lost {
        /// What Slurm says of the job, e.g. `Slurm job 12_3 CANCELLED, DependencyNeverSatisfied`.
        why: String,
        /// Where to look further (Slurm's own output of the job), with its last lines.
        more: String,
    },
}

/// Commit an attempt: on success move the temporaries into place, else remove them;
/// then write the record.
pub fn finish(ws: &mut Workspace, inst: &Instance, a: Attempt, ran: Ran) -> Result<Finish> {
    let mut status = ran.status;
    let mut why = ran.error;
    if status == 0 {
        if let Some((_, dest)) = a.pairs.iter().find(|(tmp, _)| !tmp.exists()) {
            status = 1;
            why = Some(format!(
                "the command succeeded but did not write output `{}`",
                dest.strip_prefix(&ws.root).unwrap_or(dest).display()
            ));
        }
    }
    if status == 0 {
        for (tmp, dest) in &a.pairs {
            commit_output(tmp, dest, &a.tag).map_err(|e| WeftError::io(dest, e))?;
        }
    } else {
        for (tmp, _) in &a.pairs {
            let _ = remove_path(tmp);
        }
    }
    let rec = make_record(ws, inst, status, ran.start, ran.end, a.log_rel.clone())?;
    ws.records.put(&rec)?;
    Ok(if status == 0 {
        Finish::Ran {
            seconds: ran.end - ran.start,
        }
    } else {
        Finish::Failed {
            status,
            why,
            log: a.log_rel,
        }
    })
}

pub fn make_record(
    ws: &mut Workspace,
    inst: &Instance,
    status: i32,
    start: f64,
    end: f64,
    log: String,
) -> Result<Record> {
    let mut inputs = BTreeMap::new();
    let mut input_files = BTreeMap::new();
    for (_, p) in &inst.inputs {
        let key = p.display().to_string();
        if let Some(h) = ws.cache.path(&ws.abs(p))? {
            for (f, fh) in h.files {
                input_files.insert(format!("{key}/{f}"), fh);
            }
            inputs.insert(key, h.hash);
        }
    }
    let mut outputs = BTreeMap::new();
    if status == 0 {
        for (_, p) in &inst.outputs {
            if let Some(h) = ws.cache.path(&ws.abs(p))? {
                outputs.insert(p.display().to_string(), h.hash);
            }
        }
    }
    let bin = ws.binary_of(&inst.command);
    let binary_hash = match &bin {
        Some(b) => Some(ws.cache.file(b)?),
        None => None,
    };
    Ok(Record {
        instance: inst.name.clone(),
        stage: inst.stage.clone(),
        command: inst.command.clone(),
        params: inst.params.clone(),
        inputs,
        input_files,
        outputs,
        binary: bin.map(|b| b.display().to_string()),
        binary_hash,
        tool_version: env!("CARGO_PKG_VERSION").to_string(),
        start_unix: start,
        end_unix: end,
        start: iso_utc(start),
        end: iso_utc(end),
        exit_status: status,
        log,
    })
}

/// The last non-empty lines of a log, indented, for failure messages.
pub fn log_tail(p: &Path, n: usize) -> String {
    let s = std::fs::read_to_string(p).unwrap_or_default();
    let lines: Vec<&str> = s
        .lines()
        .filter(|l| !l.trim().is_empty() && !l.starts_with("# "))
        .collect();
    let start = lines.len().saturating_sub(n);
    lines[start..]
        .iter()
        .map(|l| format!("\n    | {l}"))
        .collect()
}

/// An instance handed to an executor.
pub struct Launch {
    pub idx: usize,
    /// Why it runs (for the run line).
    pub reason: String,
    /// Run even if judged fresh when its turn comes.
    pub force: bool,
    /// Upstream instances still running or queued (only for eager executors): the
    /// instance must wait for them, and is judged again when they are done.
    pub waiting_on: Vec<usize>,
}

/// What an executor reports.
pub enum Event {
    /// The instance started running (its bar appears).
    Started(usize),
    Progress(usize, f64),
    Done(usize, Finish),
    /// Something the user should know while waiting (a job held back for a reason that
    /// will not pass by itself).
    Note(String),
}

/// Launching, polling and cancelling stage instances. Scheduling (what is stale, what is
/// ready, what a failure skips), the progress view and the records are the engine's.
pub trait Executor {
    /// Whether instances may be handed over before their upstream instances are done
    /// (the executor then makes them wait, as Slurm does with dependencies).
    fn eager(&self) -> bool;
    /// Nothing is run: launches are only printed.
    fn dry(&self) -> bool {
        false
    }
    /// Start (or queue) the instances.
    fn launch(
        &mut self,
        p: &Pipeline,
        ws: &mut Workspace,
        batch: Vec<Launch>,
        say: &dyn Fn(String),
    ) -> Result<()>;
    /// Block until something happens to a launched instance.
    fn wait(&mut self, p: &Pipeline, ws: &mut Workspace) -> Result<Vec<Event>>;
    /// After a failure without `--keep-going`: start nothing new (running ones finish).
    fn stop_pending(&mut self, say: &dyn Fn(String)) -> Result<()>;
    /// The run is over (every launched instance is done).
    fn close(&mut self, _ws: &mut Workspace) -> Result<()> {
        Ok(())
    }
}

enum Msg {
    Progress(usize, f64),
    Done(usize, Ran),
}

/// Instances run as child processes of `weft run`, up to `-j` at a time (the engine
/// keeps the count).
pub struct LocalExecutor {
    tx: mpsc::Sender<Msg>,
    rx: mpsc::Receiver<Msg>,
    attempts: BTreeMap<usize, Attempt>,
    queued: VecDeque<Event>,
    path_env: std::ffi::OsString,
}

impl LocalExecutor {
    pub fn new(ws: &Workspace) -> LocalExecutor {
        let (tx, rx) = mpsc::channel();
        LocalExecutor {
            tx,
            rx,
            attempts: BTreeMap::new(),
            queued: VecDeque::new(),
            path_env: stage_path(ws),
        }
    }
}

impl Executor for LocalExecutor {
    fn eager(&self) -> bool {
        false
    }

    fn launch(
        &mut self,
        p: &Pipeline,
        ws: &mut Workspace,
        batch: Vec<Launch>,
        say: &dyn Fn(String),
    ) -> Result<()> {
        let tag = process_tag();
        for l in batch {
            let inst = &p.instances[l.idx];
            let a = prepare(p, ws, inst, &tag)?;
            say(format!("run   {} ({})", inst.name, l.reason));
            let job = a.clone();
            self.attempts.insert(l.idx, a);
            self.queued.push_back(Event::Started(l.idx));
            let (tx, root, path_env, idx) = (
                self.tx.clone(),
                ws.root.clone(),
                self.path_env.clone(),
                l.idx,
            );
            std::thread::spawn(move || {
                let ptx = tx.clone();
                let ran = run_command(&job, &root, &path_env, &mut |f| {
                    let _ = ptx.send(Msg::Progress(idx, f));
                });
                let _ = tx.send(Msg::Done(idx, ran));
            });
        }
        Ok(())
    }

    fn wait(&mut self, p: &Pipeline, ws: &mut Workspace) -> Result<Vec<Event>> {
        if !self.queued.is_empty() {
            return Ok(self.queued.drain(..).collect());
        }
        let msg = self.rx.recv().expect("a running instance reports back");
        Ok(vec![match msg {
            Msg::Progress(i, f) => Event::Progress(i, f),
            Msg::Done(i, ran) => {
                let a = self.attempts.remove(&i).expect("launched");
                Event::Done(i, finish(ws, &p.instances[i], a, ran)?)
            }
        }])
    }

    fn stop_pending(&mut self, _say: &dyn Fn(String)) -> Result<()> {
        // Nothing is queued here: the engine starts no new instance.
        Ok(())
    }
}
