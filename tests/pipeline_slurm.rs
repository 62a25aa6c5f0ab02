//! `weft run --executor slurm` against a real Slurm (the single-node one of
//! `scripts/slurm-single-node.sh`, which `.ci/run` starts): the shipped rod wave pipeline
//! (4 rods × 2 step factors: 22 instances, 1 s locally) gives the same outputs through
//! Slurm as locally, value by value, the timing columns aside; its sweeps become job
//! arrays; a second run submits nothing; a controller killed mid-run (SIGKILL) leaves its
//! jobs to finish, and the next run adopts them and converges to the same outputs; a
//! failing instance has Slurm cancel its dependants, with `--keep-going` the rest runs;
//! Ctrl-C cancels the jobs.
//!
//! The reference is the local executor, which tests/pipeline.rs and tests/interruption.rs
//! check on their own. Without a responding Slurm the tests are reported as ignored
//! (tests/common/optional.rs), unless `WEFT_REQUIRE_SLURM=1` (set by `.ci/run`): then they fail.

mod common;
use common::same_outputs;

use std::path::Path;
use std::process::{Command, Output, Stdio};
use std::sync::Mutex;
use std::time::{Duration, Instant};

/// One test at a time: the single node has few CPUs, and the tests look at squeue.
static SLURM: Mutex<()> = Mutex::new(());

fn slurm_ok() -> bool {
    // Asked once: a configured but stopped Slurm takes `sinfo` ~10 s to give up.
    static UP: std::sync::OnceLock<bool> = std::sync::OnceLock::new();
    *UP.get_or_init(|| {
        Command::new("sinfo")
            .args(["--noheader", "--format=%t"])
            .output()
            .map(|o| {
                o.status.success()
                    && String::from_utf8_lossy(&o.stdout).lines().any(|l| {
                        l.starts_with("idle") || l.starts_with("mix") || l.starts_with("alloc")
                    })
            })
            .unwrap_or(false)
    })
}

/// The shipped rod wave pipeline in a fresh project: 4 weave, 8 simulate, 8 speed and
/// 2 gather instances.
fn rod_project() -> tempfile::TempDir {
    let dir = tempfile::tempdir().unwrap();
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("pipelines/rod_waves.toml");
    std::fs::create_dir_all(dir.path().join("pipelines")).unwrap();
    std::fs::copy(src, dir.path().join("pipelines/rod_waves.toml")).unwrap();
    dir
}

fn weft(root: &Path, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_weft"))
        .args(args)
        .current_dir(root)
        .output()
        .unwrap()
}

fn text(b: &[u8]) -> String {
    String::from_utf8_lossy(b).to_string()
}

/// `weft run` of the rod project through Slurm; returns stderr.
fn slurm_run(root: &Path, extra: &[&str]) -> String {
    let mut a = vec!["run", "pipelines/rod_waves.toml", "--executor", "slurm"];
    a.extend_from_slice(extra);
    let o = weft(root, &a);
    let err = text(&o.stderr);
    assert!(
        o.status.success(),
        "weft run --executor slurm failed:\n{err}"
    );
    err
}

/// `queue NAME (reason): Slurm job ID` lines → (name, job id).
fn queued(stderr: &str) -> Vec<(String, String)> {
    stderr
        .lines()
        .filter_map(|l| l.strip_prefix("queue "))
        .map(|l| {
            let name = l.split(" (").next().unwrap().to_string();
            let job = l.rsplit("Slurm job ").next().unwrap().trim().to_string();
            (name, job)
        })
        .collect()
}

fn done(stderr: &str) -> Vec<String> {
    let mut v: Vec<String> = stderr
        .lines()
        .filter_map(|l| l.strip_prefix("done  "))
        .map(|l| l.split(" (").next().unwrap().to_string())
        .collect();
    v.sort();
    v
}

fn rod_waves_through_slurm_equals_the_local_run_and_sweeps_become_arrays() {
    let _g = SLURM.lock().unwrap_or_else(|e| e.into_inner());
    let local = rod_project();
    let o = weft(local.path(), &["run", "-q", "pipelines/rod_waves.toml"]);
    assert!(o.status.success(), "{}", text(&o.stderr));

    let sl = rod_project();
    // A dry run prints the sbatch commands and submits nothing.
    let o = weft(
        sl.path(),
        &[
            "run",
            "pipelines/rod_waves.toml",
            "--executor",
            "slurm",
            "--dry-run",
        ],
    );
    let out = text(&o.stdout);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let sbatch: Vec<&str> = out
        .lines()
        .filter(|l| l.contains("=$(sbatch --parsable"))
        .collect();
    assert!(!sbatch.is_empty(), "{out}");
    assert!(
        sbatch
            .iter()
            .all(|l| l.contains("--kill-on-invalid-dep=yes")),
        "{out}"
    );
    assert!(
        sbatch
            .iter()
            .any(|l| l.contains("weft:rod_waves:weave") && l.contains("--array=0-3")),
        "the weave sweep is one array:\n{out}"
    );
    assert!(out.contains("\"--dependency=aftercorr:${J1}\""), "{out}");
    assert!(!sl.path().join("runs").exists() && !sl.path().join(".weft/jobs").exists());

    let t0 = Instant::now();
    let err = slurm_run(sl.path(), &[]);
    let wall = t0.elapsed().as_secs_f64();
    assert_eq!(done(&err).len(), 22, "{err}");
    // Each sweep stage went to Slurm as arrays: every weave, simulate and speed instance
    // is an array task (`ID_TASK`), the four weave instances share one array.
    let q = queued(&err);
    assert_eq!(q.len(), 22, "{err}");
    for (name, job) in &q {
        let sweep = !name.starts_with("summary") && !name.starts_with("speeds");
        assert_eq!(job.contains('_'), sweep, "{name}: job {job}\n{err}");
    }
    let weave: Vec<&str> = q
        .iter()
        .filter(|(n, _)| n.starts_with("weave@"))
        .map(|(_, j)| j.split('_').next().unwrap())
        .collect();
    assert_eq!(weave.len(), 4);
    assert!(weave.iter().all(|w| *w == weave[0]), "{err}");

    match same_outputs(local.path(), sl.path()) {
        Ok(n) => {
            eprintln!("{n} output files identical to the local run; Slurm run took {wall:.1} s")
        }
        Err(e) => panic!("through Slurm: {e}"),
    }
    // Nothing left to do: no job submitted, everything fresh.
    let err = slurm_run(sl.path(), &[]);
    assert!(queued(&err).is_empty(), "{err}");
    assert!(err.contains("0 ran, 22 fresh"), "{err}");
    let st = text(&weft(sl.path(), &["status", "pipelines/rod_waves.toml"]).stdout);
    assert_eq!(
        st.lines().filter(|l| l.starts_with("fresh")).count(),
        22,
        "{st}"
    );
    // The records are the jobs' own, one per instance, as locally.
    let recs = std::fs::read_dir(sl.path().join(".weft/records/rod_waves"))
        .unwrap()
        .count();
    assert_eq!(recs, 22);
}

fn a_controller_killed_mid_run_leaves_its_jobs_running_and_a_rerun_adopts_them() {
    let _g = SLURM.lock().unwrap_or_else(|e| e.into_inner());
    let local = rod_project();
    let o = weft(local.path(), &["run", "-q", "pipelines/rod_waves.toml"]);
    assert!(o.status.success(), "{}", text(&o.stderr));

    let sl = rod_project();
    let mut child = Command::new(env!("CARGO_BIN_EXE_weft"))
        .args([
            "run",
            "-q",
            "pipelines/rod_waves.toml",
            "--executor",
            "slurm",
        ])
        .current_dir(sl.path())
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    // Kill it (SIGKILL) once a first job has committed its instance: the rest is then
    // queued or running in Slurm.
    let recs = sl.path().join(".weft/records/rod_waves");
    let t0 = Instant::now();
    while std::fs::read_dir(&recs).map(|d| d.count()).unwrap_or(0) == 0 {
        assert!(
            child.try_wait().unwrap().is_none(),
            "the run ended before a first record"
        );
        assert!(
            t0.elapsed() < Duration::from_secs(120),
            "no job finished in 2 minutes"
        );
        std::thread::sleep(Duration::from_millis(20));
    }
    child.kill().unwrap();
    child.wait().unwrap();
    let st = text(&weft(sl.path(), &["status", "pipelines/rod_waves.toml"]).stdout);
    let live = st.lines().filter(|l| l.contains("(Slurm job ")).count();
    eprintln!("after the kill, {live} instances have a live Slurm job:\n{st}");
    if live > 0 {
        // The local executor does not race them (unless they all ended meanwhile).
        let o = weft(sl.path(), &["run", "pipelines/rod_waves.toml"]);
        let err = text(&o.stderr);
        assert!(
            o.status.success() || err.contains("still queued or running"),
            "{err}"
        );
    }
    let err = slurm_run(sl.path(), &[]);
    let adopted = err.lines().filter(|l| l.starts_with("adopt ")).count();
    eprintln!(
        "the rerun adopted {adopted} jobs and queued {}",
        queued(&err).len()
    );
    if live >= 10 {
        // Ten live jobs span at least three dependency levels, seconds of work in Slurm:
        // the rerun, a moment after the status, finds some of them still live.
        assert!(adopted > 0, "{err}");
    }
    // Nothing ran twice: an instance is adopted, or queued, or fresh.
    for (name, _) in queued(&err) {
        assert!(
            !err.contains(&format!("adopt {name}:")),
            "{name} both adopted and queued\n{err}"
        );
    }
    if let Err(e) = same_outputs(local.path(), sl.path()) {
        panic!("after a killed controller and a rerun: {e}");
    }
    let err = slurm_run(sl.path(), &[]);
    assert!(err.contains("0 ran, 22 fresh"), "{err}");
}

const FAILING: &str = r#"
[stages.make]
cmd = "test ${n} != 2 || { echo no good >&2; exit 3; }; echo ${n} > ${outputs.o}"
matrix = { n = [1, 2, 3] }
outputs = { o = "out/make-${n}.txt" }

[stages.use]
cmd = "cat ${inputs.i} > ${outputs.o}"
matrix = { n = [1, 2, 3] }
inputs = { i = "out/make-${n}.txt" }
outputs = { o = "out/use-${n}.txt" }

[stages.both]
cmd = "cat ${inputs} > ${outputs.o}"
inputs = ["out/use-1.txt", "out/use-3.txt"]
outputs = { o = "out/both.txt" }

[stages.other]
cmd = "echo other > ${outputs.o}"
outputs = { o = "other/x.txt" }

[executor]
poll_seconds = 0.3
"#;

fn a_failing_instance_cancels_its_dependants_and_keep_going_runs_the_rest() {
    let _g = SLURM.lock().unwrap_or_else(|e| e.into_inner());
    let dir = tempfile::tempdir().unwrap();
    std::fs::create_dir_all(dir.path().join("pipelines")).unwrap();
    std::fs::write(dir.path().join("pipelines/f.toml"), FAILING).unwrap();
    let run = |extra: &[&str]| {
        let mut a = vec!["run", "pipelines/f.toml", "--executor", "slurm"];
        a.extend_from_slice(extra);
        let o = weft(dir.path(), &a);
        assert!(!o.status.success(), "a failing pipeline succeeded");
        text(&o.stderr)
    };
    let err = run(&["--keep-going"]);
    // `use@n=2` waits on the failed job through `aftercorr`; Slurm cancels it.
    assert!(
        err.contains("FAIL  make@n=2 (exit status 3)") && err.contains("| no good"),
        "{err}"
    );
    assert!(
        err.contains("skip  use@n=2 (an upstream stage failed"),
        "{err}"
    );
    assert!(err.contains("DependencyNeverSatisfied"), "{err}");
    assert_eq!(
        done(&err),
        ["both", "make@n=1", "make@n=3", "other", "use@n=1", "use@n=3"],
        "{err}"
    );
    assert!(err.contains("6 ran, 0 fresh, 1 failed, 1 not run"), "{err}");
    assert_eq!(
        std::fs::read_to_string(dir.path().join("out/both.txt")).unwrap(),
        "1\n3\n"
    );
    assert!(!dir.path().join("out/use-2.txt").exists());
    let st = text(&weft(dir.path(), &["status", "pipelines/f.toml"]).stdout);
    assert!(
        st.contains("stale  make@n=2: last run failed (exit status 3)"),
        "{st}"
    );
    assert!(st.contains("stale  use@n=2: never run"), "{st}");

    // Without --keep-going: the same failure, its dependant skipped, the queued jobs
    // cancelled, and a hint.
    let err = run(&[]);
    assert!(err.contains("FAIL  make@n=2 (exit status 3)"), "{err}");
    assert!(err.contains("skip  use@n=2"), "{err}");
    assert!(
        done(&err).is_empty(),
        "only the failed instance was stale:\n{err}"
    );
}

fn ctrl_c_cancels_the_jobs_of_the_run() {
    let _g = SLURM.lock().unwrap_or_else(|e| e.into_inner());
    let dir = tempfile::tempdir().unwrap();
    std::fs::create_dir_all(dir.path().join("pipelines")).unwrap();
    std::fs::write(
        dir.path().join("pipelines/c.toml"),
        "[stages.long]\ncmd = \"sleep 60 && echo x > ${outputs.o}\"\noutputs = { o = \"out/x.txt\" }\n\
         [stages.after]\ncmd = \"cp ${inputs.i} ${outputs.o}\"\ninputs = { i = \"out/x.txt\" }\noutputs = { o = \"out/y.txt\" }\n\
         [executor]\npoll_seconds = 0.2\n",
    )
    .unwrap();
    let child = Command::new(env!("CARGO_BIN_EXE_weft"))
        .args(["run", "pipelines/c.toml", "--executor", "slurm"])
        .current_dir(dir.path())
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let ledger = dir.path().join(".weft/jobs/c/after.job");
    let t0 = Instant::now();
    while !ledger.exists() {
        assert!(
            t0.elapsed() < Duration::from_secs(60),
            "nothing submitted in a minute"
        );
        std::thread::sleep(Duration::from_millis(20));
    }
    let job = |name: &str| -> String {
        let s =
            std::fs::read_to_string(dir.path().join(format!(".weft/jobs/c/{name}.job"))).unwrap();
        let v: serde_json::Value = serde_json::from_str(&s).unwrap();
        v["job"].as_str().unwrap().to_string()
    };
    let jobs = [job("long"), job("after")];
    unsafe { libc::kill(child.id() as i32, libc::SIGINT) };
    let o = child.wait_with_output().unwrap();
    let err = text(&o.stderr);
    assert!(!o.status.success());
    assert!(
        err.contains("interrupted: cancelled the 2 Slurm jobs"),
        "{err}"
    );
    // Slurm has them cancelled (or, at worst, still cancelling).
    let q = Command::new("squeue")
        .args([
            "--noheader",
            "--states=all",
            "--format=%i %T",
            "--jobs",
            &jobs.join(","),
        ])
        .output()
        .unwrap();
    let q = text(&q.stdout);
    for j in &jobs {
        let line = q
            .lines()
            .find(|l| l.starts_with(&format!("{j} ")))
            .unwrap_or("");
        assert!(
            line.contains("CANCELLED") || line.contains("COMPLETING"),
            "job {j}: {q}"
        );
    }
    assert!(!dir.path().join("out/x.txt").exists());
}

fn an_upstream_rerun_with_the_same_bytes_leaves_its_dependant_fresh_inside_its_job() {
    let _g = SLURM.lock().unwrap_or_else(|e| e.into_inner());
    let dir = tempfile::tempdir().unwrap();
    std::fs::create_dir_all(dir.path().join("pipelines")).unwrap();
    std::fs::write(
        dir.path().join("pipelines/u.toml"),
        "[stages.a]\ncmd = \"echo same > ${outputs.o}\"\noutputs = { o = \"out/a.txt\" }\n\
         [stages.b]\ncmd = \"cp ${inputs.i} ${outputs.o}\"\ninputs = { i = \"out/a.txt\" }\noutputs = { o = \"out/b.txt\" }\n\
         [executor]\npoll_seconds = 0.2\n",
    )
    .unwrap();
    let run = |extra: &[&str]| {
        let mut a = vec!["run", "pipelines/u.toml", "--executor", "slurm"];
        a.extend_from_slice(extra);
        let o = weft(dir.path(), &a);
        let err = text(&o.stderr);
        assert!(o.status.success(), "{err}");
        err
    };
    assert_eq!(done(&run(&[])), ["a", "b"]);
    let b_record = std::fs::read_to_string(dir.path().join(".weft/records/u/b.json")).unwrap();
    // `b` waits in Slurm on the forced `a`, then finds its input unchanged: as the local
    // executor, it does not run.
    let err = run(&["--force", "a"]);
    assert_eq!(queued(&err).len(), 2, "{err}");
    assert_eq!(done(&err), ["a"], "{err}");
    assert!(
        err.contains("fresh b (its upstream reproduced the same inputs)"),
        "{err}"
    );
    assert_eq!(
        std::fs::read_to_string(dir.path().join(".weft/records/u/b.json")).unwrap(),
        b_record
    );
}

fn jobs_a_dying_controller_submitted_but_did_not_note_are_cancelled_by_the_next_run() {
    let _g = SLURM.lock().unwrap_or_else(|e| e.into_inner());
    let dir = tempfile::tempdir().unwrap();
    std::fs::create_dir_all(dir.path().join("pipelines")).unwrap();
    let file = dir.path().join("pipelines/o.toml");
    std::fs::write(
        &file,
        "[stages.a]\ncmd = \"echo a > ${outputs.o}\"\noutputs = { o = \"out/a.txt\" }\n\
         [executor]\npoll_seconds = 0.2\n",
    )
    .unwrap();
    // A job of this pipeline file (by its comment) that no job file notes: as if the
    // controller died between sbatch and writing `.weft/jobs/o/a.job`.
    let tag = weft::pipeline::slurm::project_tag(&file);
    let o = Command::new("sbatch")
        .args([
            "--parsable",
            &format!("--comment={tag}"),
            "--output=/dev/null",
            "--wrap=sleep 60",
        ])
        .current_dir(dir.path())
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", text(&o.stderr));
    let orphan = text(&o.stdout).trim().to_string();
    let o = weft(
        dir.path(),
        &["run", "pipelines/o.toml", "--executor", "slurm"],
    );
    assert!(o.status.success(), "{}", text(&o.stderr));
    let q = Command::new("squeue")
        .args([
            "--noheader",
            "--states=all",
            "--format=%T",
            "--jobs",
            &orphan,
        ])
        .output()
        .unwrap();
    let state = text(&q.stdout);
    assert!(
        state.contains("CANCELLED") || state.contains("COMPLETING"),
        "orphan {orphan}: {state}"
    );
}

fn a_job_held_back_for_a_reason_that_does_not_pass_is_reported_while_waiting() {
    let _g = SLURM.lock().unwrap_or_else(|e| e.into_inner());
    let dir = tempfile::tempdir().unwrap();
    std::fs::create_dir_all(dir.path().join("pipelines")).unwrap();
    // `--hold` keeps the job pending (JobHeldUser) until released.
    std::fs::write(
        dir.path().join("pipelines/h.toml"),
        "[stages.a]\ncmd = \"echo a > ${outputs.o}\"\noutputs = { o = \"out/a.txt\" }\n\
         [executor]\npoll_seconds = 0.2\nsbatch_args = [\"--hold\"]\n",
    )
    .unwrap();
    let mut child = Command::new(env!("CARGO_BIN_EXE_weft"))
        .args(["run", "pipelines/h.toml", "--executor", "slurm"])
        .current_dir(dir.path())
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    use std::io::BufRead;
    let mut lines = std::io::BufReader::new(child.stderr.take().unwrap()).lines();
    let mut seen = vec![];
    let job = loop {
        let l = lines
            .next()
            .expect("weft ended before reporting the held job")
            .unwrap();
        seen.push(l.clone());
        if let Some(rest) = l.strip_prefix("wait  a: Slurm job ") {
            assert!(rest.contains("JobHeldUser"), "{l}");
            break rest.split(' ').next().unwrap().to_string();
        }
    };
    let o = Command::new("scontrol")
        .args(["release", &job])
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", text(&o.stderr));
    let rest: Vec<String> = lines.map(|l| l.unwrap()).collect();
    assert!(child.wait().unwrap().success(), "{seen:?} {rest:?}");
    assert!(rest.iter().any(|l| l.starts_with("done  a")), "{rest:?}");
}

/// a responding Slurm (`sinfo`): its tests are ignored where it is missing, unless `WEFT_REQUIRE_SLURM=1`.
const SLURM_TOOL: common::optional::Tool = common::optional::Tool {
    what: "a responding Slurm (`sinfo`)",
    install: "scripts/slurm-single-node.sh install && scripts/slurm-single-node.sh start",
    require: "WEFT_REQUIRE_SLURM",
    here: slurm_ok,
};

fn main() -> std::process::ExitCode {
    common::optional::run(
        &SLURM_TOOL,
        vec![
            (
                "rod_waves_through_slurm_equals_the_local_run_and_sweeps_become_arrays",
                true,
                rod_waves_through_slurm_equals_the_local_run_and_sweeps_become_arrays,
            ),
            (
                "a_controller_killed_mid_run_leaves_its_jobs_running_and_a_rerun_adopts_them",
                true,
                a_controller_killed_mid_run_leaves_its_jobs_running_and_a_rerun_adopts_them,
            ),
            (
                "a_failing_instance_cancels_its_dependants_and_keep_going_runs_the_rest",
                true,
                a_failing_instance_cancels_its_dependants_and_keep_going_runs_the_rest,
            ),
            (
                "ctrl_c_cancels_the_jobs_of_the_run",
                true,
                ctrl_c_cancels_the_jobs_of_the_run,
            ),
            (
                "an_upstream_rerun_with_the_same_bytes_leaves_its_dependant_fresh_inside_its_job",
                true,
                an_upstream_rerun_with_the_same_bytes_leaves_its_dependant_fresh_inside_its_job,
            ),
            (
                "jobs_a_dying_controller_submitted_but_did_not_note_are_cancelled_by_the_next_run",
                true,
                jobs_a_dying_controller_submitted_but_did_not_note_are_cancelled_by_the_next_run,
            ),
            (
                "a_job_held_back_for_a_reason_that_does_not_pass_is_reported_while_waiting",
                true,
                a_job_held_back_for_a_reason_that_does_not_pass_is_reported_while_waiting,
            ),
        ],
    )
}
