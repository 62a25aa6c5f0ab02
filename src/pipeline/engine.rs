//! Deciding what is stale (and why), and running it.
//!
//! An instance reruns when it never ran or its last run failed, a param it uses or its
//! command changed, its binary changed, an input's content changed, or an output is
//! missing or was changed since the run. Before its upstream instances have run, an
//! instance downstream of a stale one is reported as waiting on it; when the upstream
//! has run, the instance is judged again on the new content of its inputs, so an
//! upstream rerun that reproduces the same bytes reruns nothing below it.
//!
//! Execution: ready instances run in parallel (`-j`), each as `sh -c CMD` in the
//! project root, with `${outputs...}` pointing at temporary siblings of the real
//! outputs, stdout and stderr in `.weft/logs/<pipeline>/<instance>.log`. On success the
//! temporaries are renamed into place and then the record is written: the record is the
//! commit point, so an interrupted run never leaves an output that counts as fresh.
//! Children get SIGKILL when `weft` dies (Linux `PR_SET_PDEATHSIG`).

use std::collections::BTreeMap;
use std::io::{BufRead, BufReader, Write};
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::sync::mpsc;
use std::time::{SystemTime, UNIX_EPOCH};

use indicatif::{MultiProgress, ProgressBar, ProgressDrawTarget, ProgressStyle};

use super::hash::HashCache;
use super::record::{iso_utc, Record, RecordStore};
use super::spec::{render, shell_quote, Ctx, Instance, Pipeline};
use crate::error::{Result, WeftError};

/// Why an instance must run, or that it need not.
#[derive(Debug, Clone, PartialEq)]
pub enum Verdict {
    Fresh,
    Stale(String),
    /// Stale because an upstream instance will run first.
    Waiting(String),
}

impl Verdict {
    pub fn is_fresh(&self) -> bool {
        matches!(self, Verdict::Fresh)
    }
}

/// Where the engine keeps its state for a pipeline.
pub struct Workspace {
    pub root: PathBuf,
    pub records: RecordStore,
    pub logs: PathBuf,
    pub cache: HashCache,
    /// Directory of the running `weft` binary: stage binaries are looked up there first.
    pub exe_dir: Option<PathBuf>,
    /// Resolved executables by command word.
    bin_memo: std::cell::RefCell<std::collections::HashMap<String, Option<PathBuf>>>,
}

impl Workspace {
    pub fn open(p: &Pipeline) -> Workspace {
        let dot = p.root.join(".weft");
        let _ = std::fs::create_dir_all(&dot);
        let gi = dot.join(".gitignore");
        if !gi.exists() {
            let _ = std::fs::write(
                &gi,
                "# records/ is meant to be committed; the rest is local\nlogs/\ncache/\nlock\n",
            );
        }
        let stem = p
            .file
            .file_stem()
            .map(|s| s.to_string_lossy().to_string())
            .unwrap_or_default();
        Workspace {
            root: p.root.clone(),
            records: RecordStore::new(&p.root, &p.file),
            logs: dot.join("logs").join(stem),
            cache: HashCache::load(&dot.join("cache").join("hashes.tsv")),
            exe_dir: std::env::current_exe()
                .ok()
                .and_then(|e| e.parent().map(Path::to_path_buf)),
            bin_memo: Default::default(),
        }
    }

    /// The executable a command starts with, resolved like the shell would (the
    /// directory of `weft` first, then PATH).
    pub fn binary_of(&self, command: &str) -> Option<PathBuf> {
        let first = command
            .split_whitespace()
            .next()?
            .trim_matches(|c| c == '\'' || c == '"');
        if let Some(hit) = self.bin_memo.borrow().get(first) {
            return hit.clone();
        }
        let found = self.resolve(first);
        self.bin_memo
            .borrow_mut()
            .insert(first.to_string(), found.clone());
        found
    }

    fn resolve(&self, first: &str) -> Option<PathBuf> {
        if first.contains('/') {
            let p = self.root.join(first);
            return p.is_file().then_some(p);
        }
        let path = std::env::var_os("PATH").unwrap_or_default();
        self.exe_dir
            .iter()
            .cloned()
            .chain(std::env::split_paths(&path))
            .map(|d| d.join(first))
            .find(|p| p.is_file())
    }

    fn abs(&self, p: &Path) -> PathBuf {
        if p.is_absolute() {
            p.to_path_buf()
        } else {
            self.root.join(p)
        }
    }

    /// Judge one instance against its record, on the current content of its inputs.
    pub fn verdict(&mut self, inst: &Instance) -> Result<Verdict> {
        let Some(rec) = self.records.get(&inst.name) else {
            return Ok(Verdict::Stale("never run".into()));
        };
        if rec.exit_status != 0 {
            return Ok(Verdict::Stale(format!(
                "last run failed (exit status {})",
                rec.exit_status
            )));
        }
        for (k, v) in &inst.params {
            match rec.params.get(k) {
                Some(old) if old != v => {
                    return Ok(Verdict::Stale(format!("param `{k}` {old} → {v}")))
                }
                None => return Ok(Verdict::Stale(format!("param `{k}` added ({v})"))),
                _ => {}
            }
        }
        if let Some(k) = rec.params.keys().find(|k| !inst.params.contains_key(*k)) {
            return Ok(Verdict::Stale(format!("param `{k}` no longer used")));
        }
        if rec.command != inst.command {
            return Ok(Verdict::Stale("command changed".into()));
        }
        let bin = self.binary_of(&inst.command);
        let bin_hash = match &bin {
            Some(b) => Some(self.cache.file(b)?),
            None => None,
        };
        if bin_hash != rec.binary_hash {
            let name = inst
                .command
                .split_whitespace()
                .next()
                .unwrap_or("")
                .to_string();
            return Ok(Verdict::Stale(match bin {
                None => format!("binary `{name}` not found"),
                Some(_) => format!("binary `{name}` changed"),
            }));
        }
        for (_, p) in &inst.inputs {
            let key = p.display().to_string();
            let h = self.cache.path(&self.abs(p))?;
            match (h, rec.inputs.get(&key)) {
                (None, _) => return Ok(Verdict::Stale(format!("input `{key}` missing"))),
                (Some(h), Some(old)) if &h.hash == old => {}
                (Some(h), Some(_)) => {
                    // Name the file inside a folder input that changed, when known.
                    let changed = h
                        .files
                        .iter()
                        .find(|(f, fh)| rec.input_files.get(&format!("{key}/{f}")) != Some(*fh));
                    let removed = rec
                        .input_files
                        .keys()
                        .filter_map(|f| f.strip_prefix(&format!("{key}/")))
                        .find(|f| !h.files.contains_key(*f));
                    return Ok(Verdict::Stale(match (changed, removed) {
                        (Some((f, _)), _) => format!("input `{key}/{f}` changed"),
                        (None, Some(f)) => format!("input `{key}/{f}` removed"),
                        _ => format!("input `{key}` changed"),
                    }));
                }
                (Some(_), None) => return Ok(Verdict::Stale(format!("input `{key}` added"))),
            }
        }
        for (_, p) in &inst.outputs {
            let key = p.display().to_string();
            match (self.cache.path(&self.abs(p))?, rec.outputs.get(&key)) {
                (None, _) => return Ok(Verdict::Stale(format!("output `{key}` missing"))),
                (Some(h), Some(old)) if &h.hash == old => {}
                _ => {
                    return Ok(Verdict::Stale(format!(
                        "output `{key}` changed since it was written"
                    )))
                }
            }
        }
        Ok(Verdict::Fresh)
    }

    /// Verdicts for all selected instances, in topological order, without running.
    pub fn plan(
        &mut self,
        p: &Pipeline,
        selected: &[bool],
        force: &[bool],
    ) -> Result<Vec<Verdict>> {
        let mut v = vec![Verdict::Fresh; p.instances.len()];
        for &i in &p.order {
            if !selected[i] {
                continue;
            }
            let inst = &p.instances[i];
            v[i] = if force[i] {
                Verdict::Stale("forced".into())
            } else {
                match self.verdict(inst)? {
                    Verdict::Fresh => {
                        match inst.deps.iter().find(|&&d| selected[d] && !v[d].is_fresh()) {
                            Some(&d) => Verdict::Waiting(format!(
                                "upstream `{}` reruns",
                                p.instances[d].name
                            )),
                            None => Verdict::Fresh,
                        }
                    }
                    s => s,
                }
            };
        }
        Ok(v)
    }
}

/// Options of `weft run`.
#[derive(Debug, Clone)]
pub struct RunOptions {
    pub jobs: usize,
    pub keep_going: bool,
    pub dry_run: bool,
    pub quiet: bool,
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

fn now_unix() -> f64 {
    SystemTime::now()
        .duration_since(UNIX_EPOCH)
        .map(|d| d.as_secs_f64())
        .unwrap_or(0.0)
}

fn tmp_sibling(p: &Path, tag: &str) -> PathBuf {
    let name = p
        .file_name()
        .map(|s| s.to_string_lossy().to_string())
        .unwrap_or_default();
    p.with_file_name(format!(".{name}.weft-{tag}-{}", std::process::id()))
}

/// Remove temporaries (`.NAME.weft-tmp-PID`, `.NAME.weft-old-PID`) left in a folder by
/// runs whose process is gone. Called once per output folder per run.
fn clean_stale_tmps(dir: &Path) {
    let Ok(rd) = std::fs::read_dir(dir) else {
        return;
    };
    for e in rd.flatten() {
        let n = e.file_name().to_string_lossy().to_string();
        if !(n.starts_with('.') && (n.contains(".weft-tmp-") || n.contains(".weft-old-"))) {
            continue;
        }
        let pid = n.rsplit('-').next().and_then(|s| s.parse::<u32>().ok());
        let alive = pid
            .is_some_and(|p| p == std::process::id() || Path::new(&format!("/proc/{p}")).exists());
        if !alive {
            let _ = std::fs::remove_dir_all(e.path()).or_else(|_| std::fs::remove_file(e.path()));
        }
    }
}

fn remove_path(p: &Path) -> std::io::Result<()> {
    if p.is_dir() {
        std::fs::remove_dir_all(p)
    } else {
        std::fs::remove_file(p)
    }
}

/// Move a finished temporary output into place, replacing the old one.
fn commit_output(tmp: &Path, dest: &Path) -> std::io::Result<()> {
    if dest.exists() {
        let old = tmp_sibling(dest, "old");
        std::fs::rename(dest, &old)?;
        std::fs::rename(tmp, dest)?;
        let _ = remove_path(&old);
    } else {
        std::fs::rename(tmp, dest)?;
    }
    Ok(())
}

struct Job {
    idx: usize,
    name: String,
    command: String,
    root: PathBuf,
    log: PathBuf,
    path_env: std::ffi::OsString,
}

struct Done {
    idx: usize,
    status: i32,
    start: f64,
    end: f64,
    error: Option<String>,
}

enum Msg {
    Progress(usize, f64),
    Done(Done),
}

fn run_job(job: Job, tx: mpsc::Sender<Msg>) {
    let start = now_unix();
    let res = (|| -> std::io::Result<i32> {
        if let Some(d) = job.log.parent() {
            std::fs::create_dir_all(d)?;
        }
        let mut log = std::fs::File::create(&job.log)?;
        writeln!(
            log,
            "# weft stage `{}`\n# started {}\n# command: {}\n",
            job.name,
            iso_utc(start),
            job.command
        )?;
        let mut cmd = Command::new("sh");
        cmd.arg("-c")
            .arg(&job.command)
            .current_dir(&job.root)
            .env("PATH", &job.path_env)
            .env("WEFT_PROGRESS", "1")
            .env("WEFT_STAGE", &job.name)
            .stdin(Stdio::null())
            .stdout(Stdio::from(log.try_clone()?))
            .stderr(Stdio::piped());
        #[cfg(target_os = "linux")]
        unsafe {
            use std::os::unix::process::CommandExt;
            cmd.pre_exec(|| {
                // The stage dies with weft: an interrupted run leaves no orphan writing.
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
                let _ = tx.send(Msg::Progress(job.idx, f));
            } else {
                writeln!(log, "{line}")?;
            }
        }
        let st = child.wait()?;
        Ok(st.code().unwrap_or_else(|| {
            #[cfg(unix)]
            {
                use std::os::unix::process::ExitStatusExt;
                128 + st.signal().unwrap_or(0)
            }
            #[cfg(not(unix))]
            1
        }))
    })();
    let end = now_unix();
    let (status, error) = match res {
        Ok(s) => (s, None),
        Err(e) => (127, Some(e.to_string())),
    };
    let _ = tx.send(Msg::Done(Done {
        idx: job.idx,
        status,
        start,
        end,
        error,
    }));
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
    let n = p.instances.len();
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
        ws.cache.save()?;
        return Ok(RunReport { outcomes });
    }
    let _lock = lock(&p.root)?;
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
    main.enable_steady_tick(std::time::Duration::from_millis(250));
    let say = |s: String| {
        if attended {
            let _ = mp.println(s);
        } else if !o.quiet {
            eprintln!("{s}");
        }
    };
    let path_env = {
        let mut dirs: Vec<PathBuf> = ws.exe_dir.iter().cloned().collect();
        dirs.extend(std::env::split_paths(
            &std::env::var_os("PATH").unwrap_or_default(),
        ));
        std::env::join_paths(dirs).unwrap_or_default()
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
    let mut forced_or_changed = force.to_vec();
    let (tx, rx) = mpsc::channel::<Msg>();
    let mut bars: BTreeMap<usize, ProgressBar> = BTreeMap::new();
    let mut tmp_outputs: BTreeMap<usize, Vec<(PathBuf, PathBuf)>> = BTreeMap::new();
    let mut cleaned: std::collections::HashSet<PathBuf> = Default::default();
    loop {
        // Launch every ready instance (deps done), judging it on current content.
        let mut progressed = false;
        for &i in &p.order {
            if !selected[i] || st[i] != St::Pending {
                continue;
            }
            let inst = &p.instances[i];
            if inst
                .deps
                .iter()
                .any(|&d| selected[d] && matches!(st[d], St::Failed | St::Skipped))
            {
                st[i] = St::Skipped;
                outcome.insert(i, Outcome::Skipped);
                say(format!("skip  {} (an upstream stage failed)", inst.name));

                progressed = true;
                continue;
            }
            if inst
                .deps
                .iter()
                .any(|&d| selected[d] && matches!(st[d], St::Pending | St::Running))
            {
                continue;
            }
            if stop || running >= o.jobs.max(1) {
                continue;
            }
            let verdict = if forced_or_changed[i] {
                Verdict::Stale("forced".into())
            } else {
                ws.verdict(inst)?
            };
            let reason = match verdict {
                Verdict::Fresh => {
                    st[i] = St::Ok;
                    outcome.insert(i, Outcome::Fresh);

                    progressed = true;
                    continue;
                }
                Verdict::Stale(r) | Verdict::Waiting(r) => r,
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
            // Temporary outputs beside the real ones.
            let mut pairs = vec![];
            let mut outs_tmp = vec![];
            for (k, out) in &inst.outputs {
                let dest = ws.abs(out);
                if let Some(d) = dest.parent() {
                    std::fs::create_dir_all(d).map_err(|e| WeftError::io(d, e))?;
                }
                if let Some(d) = dest.parent() {
                    if cleaned.insert(d.to_path_buf()) {
                        clean_stale_tmps(d);
                    }
                }
                let tmp = tmp_sibling(&dest, "tmp");
                let _ = remove_path(&tmp);
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
            tmp_outputs.insert(i, pairs);
            let log = ws
                .logs
                .join(format!("{}.log", super::spec::file_name_of(&inst.name)));
            st[i] = St::Running;
            running += 1;
            progressed = true;
            say(format!("run   {} ({reason})", inst.name));

            let bar = mp.insert_before(&main, ProgressBar::new(1000));
            bar.set_style(
                ProgressStyle::with_template(
                    "  {spinner} {msg:40!} [{bar:20}] {percent:>3}% {elapsed}",
                )
                .expect("template"),
            );
            bar.set_message(inst.name.clone());
            bar.enable_steady_tick(std::time::Duration::from_millis(200));
            bars.insert(i, bar);
            let job = Job {
                idx: i,
                name: inst.name.clone(),
                command,
                root: ws.root.clone(),
                log,
                path_env: path_env.clone(),
            };
            let txc = tx.clone();
            std::thread::spawn(move || run_job(job, txc));
        }
        if running == 0 && !progressed {
            break;
        }
        if running == 0 {
            continue;
        }
        // Wait for progress or a finished job.
        let msg = rx.recv().expect("a running job reports back");
        match msg {
            Msg::Progress(i, f) => {
                if let Some(b) = bars.get(&i) {
                    b.set_position((f.clamp(0.0, 1.0) * 1000.0) as u64);
                }
            }
            Msg::Done(d) => {
                running -= 1;

                main.inc(1);
                if let Some(b) = bars.remove(&d.idx) {
                    b.finish_and_clear();
                    mp.remove(&b);
                }
                let inst = &p.instances[d.idx];
                let pairs = tmp_outputs.remove(&d.idx).unwrap_or_default();
                let mut status = d.status;
                let mut why = d.error.clone();
                if status == 0 {
                    if let Some((_, dest)) = pairs.iter().find(|(tmp, _)| !tmp.exists()) {
                        status = 1;
                        why = Some(format!(
                            "the command succeeded but did not write output `{}`",
                            dest.strip_prefix(&ws.root).unwrap_or(dest).display()
                        ));
                    }
                }
                let log_rel = ws
                    .logs
                    .join(format!("{}.log", super::spec::file_name_of(&inst.name)));
                let log_rel = log_rel
                    .strip_prefix(&ws.root)
                    .unwrap_or(&log_rel)
                    .display()
                    .to_string();
                if status == 0 {
                    for (tmp, dest) in &pairs {
                        commit_output(tmp, dest).map_err(|e| WeftError::io(dest, e))?;
                    }
                } else {
                    for (tmp, _) in &pairs {
                        let _ = remove_path(tmp);
                    }
                }
                let rec = make_record(ws, inst, status, d.start, d.end, log_rel.clone())?;
                ws.records.put(&rec)?;
                if status == 0 {
                    st[d.idx] = St::Ok;
                    outcome.insert(
                        d.idx,
                        Outcome::Ran {
                            seconds: d.end - d.start,
                        },
                    );
                    say(format!("done  {} ({:.2} s)", inst.name, d.end - d.start));
                } else {
                    st[d.idx] = St::Failed;
                    outcome.insert(d.idx, Outcome::Failed { status });
                    let tail = log_tail(&ws.root.join(&log_rel), 6);
                    say(format!(
                        "FAIL  {} (exit status {status}{}); log: {log_rel}{tail}",
                        inst.name,
                        why.map(|w| format!(": {w}")).unwrap_or_default()
                    ));
                    if !o.keep_going {
                        stop = true;
                    }
                }
                forced_or_changed[d.idx] = false;
            }
        }
    }
    main.finish_and_clear();
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

fn make_record(
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
fn log_tail(p: &Path, n: usize) -> String {
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

/// Shell-quoted path for messages.
pub fn q(p: &Path) -> String {
    shell_quote(&p.display().to_string())
}
