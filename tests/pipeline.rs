//! The pipeline engine, end to end through the `weft` binary on small projects in a
//! temporary folder: make-style reruns decided on content, sweeps, parallel runs,
//! interruption, locking, failures, and a corpus of malformed pipeline files.
//!
//! The expected behaviour is make's contract with content instead of timestamps (as in
//! DVC's `dvc repro`): a stage reruns exactly when its command, a parameter it uses, an
//! input's content, its binary, or an output changed or went missing; and what DVC and
//! Snakemake users ask for: parallel independent stages, outputs that never look fresh
//! after an interruption, and a one-line reason for every rerun.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::time::{Duration, Instant};

struct Project {
    dir: tempfile::TempDir,
}

impl Project {
    fn new(pipeline: &str) -> Project {
        let dir = tempfile::tempdir().unwrap();
        std::fs::create_dir_all(dir.path().join("pipelines")).unwrap();
        std::fs::create_dir_all(dir.path().join("data")).unwrap();
        let p = Project { dir };
        p.write_pipeline(pipeline);
        p
    }
    fn root(&self) -> &Path {
        self.dir.path()
    }
    fn write_pipeline(&self, s: &str) {
        std::fs::write(self.root().join("pipelines/p.toml"), s).unwrap();
    }
    fn write(&self, rel: &str, s: &str) {
        let p = self.root().join(rel);
        std::fs::create_dir_all(p.parent().unwrap()).unwrap();
        std::fs::write(p, s).unwrap();
    }
    fn read(&self, rel: &str) -> String {
        std::fs::read_to_string(self.root().join(rel)).unwrap()
    }
    fn weft(&self, args: &[&str]) -> Output {
        Command::new(env!("CARGO_BIN_EXE_weft"))
            .args(args)
            .current_dir(self.root())
            .output()
            .unwrap()
    }
    /// `weft run` with extra args; returns the instances that ran (from the `done` lines).
    fn run(&self, args: &[&str]) -> Vec<String> {
        let mut a = vec!["run", "pipelines/p.toml"];
        a.extend_from_slice(args);
        let o = self.weft(&a);
        let err = String::from_utf8_lossy(&o.stderr).to_string();
        assert!(o.status.success(), "weft run failed:\n{err}");
        ran(&err)
    }
    fn status(&self) -> String {
        let o = self.weft(&["status", "pipelines/p.toml"]);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        String::from_utf8_lossy(&o.stdout).to_string()
    }
}

fn ran(stderr: &str) -> Vec<String> {
    let mut v: Vec<String> = stderr
        .lines()
        .filter_map(|l| l.strip_prefix("done  "))
        .map(|l| l.split(" (").next().unwrap().to_string())
        .collect();
    v.sort();
    v
}

const CHAIN: &str = r#"
[vars]
n = 1

[stages.a]
cmd = "cat ${inputs.src} > ${outputs.o} && echo ${n} >> ${outputs.o}"
inputs = { src = "data/in.txt" }
outputs = { o = "out/a.txt" }

[stages.b]
cmd = "cat ${inputs.i} > ${outputs.o} && echo ${k} >> ${outputs.o}"
params = { k = 1 }
inputs = { i = "out/a.txt" }
outputs = { o = "out/b.txt" }

[stages.c]
cmd = "mkdir -p ${outputs.o} && cp ${inputs.i} ${outputs.o}/c.txt"
inputs = { i = "out/b.txt" }
outputs = { o = "out/c" }

[stages.d]
cmd = "echo independent > ${outputs.o}"
outputs = { o = "out/d.txt" }
"#;

#[test]
fn second_run_with_nothing_changed_runs_nothing() {
    let p = Project::new(CHAIN);
    p.write("data/in.txt", "hello\n");
    assert_eq!(p.run(&[]), ["a", "b", "c", "d"]);
    assert_eq!(p.read("out/c/c.txt"), "hello\n1\n1\n");
    assert_eq!(p.run(&[]), Vec::<String>::new());
    let st = p.status();
    assert_eq!(
        st.lines().filter(|l| l.starts_with("fresh")).count(),
        4,
        "{st}"
    );
}

#[test]
fn changing_one_parameter_reruns_that_stage_and_its_descendants() {
    let p = Project::new(CHAIN);
    p.write("data/in.txt", "hello\n");
    p.run(&[]);
    p.write_pipeline(&CHAIN.replace("params = { k = 1 }", "params = { k = 2 }"));
    let st = p.status();
    assert!(st.contains("stale  b: param `k` 1 → 2"), "{st}");
    assert!(st.contains("stale  c: upstream `b` reruns"), "{st}");
    assert!(st.contains("fresh  a") && st.contains("fresh  d"), "{st}");
    assert_eq!(p.run(&[]), ["b", "c"]);
    assert_eq!(p.read("out/c/c.txt"), "hello\n1\n2\n");
    // A var used by a stage counts as its parameter too.
    p.write_pipeline(
        &CHAIN
            .replace("params = { k = 1 }", "params = { k = 2 }")
            .replace("n = 1", "n = 3"),
    );
    assert!(p.status().contains("stale  a: param `n` 1 → 3"));
    assert_eq!(p.run(&[]), ["a", "b", "c"]);
}

#[test]
fn touching_a_file_without_changing_it_reruns_nothing() {
    let p = Project::new(CHAIN);
    p.write("data/in.txt", "hello\n");
    p.run(&[]);
    // Same content, new modification time.
    std::thread::sleep(Duration::from_millis(20));
    p.write("data/in.txt", "hello\n");
    assert_eq!(p.run(&[]), Vec::<String>::new());
    // New content: a reruns; b's input is then a new file, so b and c follow.
    p.write("data/in.txt", "changed\n");
    assert!(p.status().contains("stale  a: input `data/in.txt` changed"));
    assert_eq!(p.run(&[]), ["a", "b", "c"]);
}

#[test]
fn an_upstream_rerun_with_identical_output_stops_there() {
    let p = Project::new(CHAIN);
    p.write("data/in.txt", "hello\n");
    p.run(&[]);
    // Forcing a reproduces the same bytes: b and c stay fresh.
    assert_eq!(p.run(&["--force", "a"]), ["a"]);
}

#[test]
fn a_changed_binary_reruns_its_stages() {
    let p = Project::new(
        r#"
[stages.gen]
cmd = "./tools/gen.sh ${outputs.o}"
outputs = { o = "out/gen.txt" }
[stages.other]
cmd = "echo x > ${outputs.o}"
outputs = { o = "out/other.txt" }
"#,
    );
    p.write("tools/gen.sh", "#!/bin/sh\necho v1 > \"$1\"\n");
    let script = p.root().join("tools/gen.sh");
    use std::os::unix::fs::PermissionsExt;
    std::fs::set_permissions(&script, std::fs::Permissions::from_mode(0o755)).unwrap();
    assert_eq!(p.run(&[]), ["gen", "other"]);
    std::fs::write(&script, "#!/bin/sh\necho v2 > \"$1\"\n").unwrap();
    assert!(p
        .status()
        .contains("stale  gen: binary `./tools/gen.sh` changed"));
    assert_eq!(p.run(&[]), ["gen"]);
    assert_eq!(p.read("out/gen.txt"), "v2\n");
}

#[test]
fn a_missing_or_edited_output_reruns_its_stage() {
    let p = Project::new(CHAIN);
    p.write("data/in.txt", "hello\n");
    p.run(&[]);
    std::fs::remove_file(p.root().join("out/d.txt")).unwrap();
    assert!(p.status().contains("stale  d: output `out/d.txt` missing"));
    p.write("out/b.txt", "tampered\n");
    assert!(p
        .status()
        .contains("stale  b: output `out/b.txt` changed since it was written"));
    assert_eq!(p.run(&[]), ["b", "d"]);
}

#[test]
fn a_sweep_of_3_by_4_expands_to_12_named_instances_and_gathers_into_one_table() {
    let p = Project::new(
        r#"
[stages.rod]
cmd = "weft-weave rod --out ${outputs.model} --elements ${elements} --force ${force}"
matrix = { elements = [10, 20, 30], force = [1.0, 2.0, 3.0, 4.0] }
outputs = { model = "runs/rod/${elements}-${force}" }

[stages.gather]
cmd = "weft gather pipelines/p.toml --stage rod --table loads.parquet --out ${outputs.t}"
inputs = { all = "runs/rod" }
outputs = { t = "runs/loads.parquet" }
"#,
    );
    let dag = p.weft(&["dag", "pipelines/p.toml"]);
    let dag = String::from_utf8_lossy(&dag.stdout).to_string();
    let names: Vec<&str> = dag.lines().filter(|l| l.starts_with("rod@")).collect();
    assert_eq!(names.len(), 12, "{dag}");
    assert!(names.contains(&"rod@elements=20,force=3"), "{dag}");
    assert!(dag.contains("gather <- rod@elements=10,force=1, "), "{dag}");
    let ran = p.run(&["-j", "2"]);
    assert_eq!(ran.len(), 13);
    let t = weft::table::Table::read(&p.root().join("runs/loads.parquet")).unwrap();
    assert_eq!(t.num_rows(), 12);
    let inst = t.str("instance", "").unwrap();
    assert_eq!(
        inst.iter().collect::<std::collections::BTreeSet<_>>().len(),
        12
    );
    // Parameters became typed columns, matching the data they produced.
    let el = t.i64("elements", "").unwrap();
    let f = t.f64("force", "").unwrap();
    let fx = t.f64("fx", "").unwrap();
    for r in 0..12 {
        assert_eq!(fx[r], f[r], "row {r}: the load equals the swept force");
        assert!([10, 20, 30].contains(&el[r]));
    }
    assert!(t.provenance.as_deref().unwrap_or("").contains("gather"));
}

#[test]
fn two_independent_slow_stages_overlap_with_two_jobs() {
    let p = Project::new(
        r#"
[stages.slow1]
cmd = "sleep 1 && echo 1 > ${outputs.o}"
outputs = { o = "out/1.txt" }
[stages.slow2]
cmd = "sleep 1 && echo 2 > ${outputs.o}"
outputs = { o = "out/2.txt" }
"#,
    );
    let t0 = Instant::now();
    p.run(&["-j", "2"]);
    let wall = t0.elapsed().as_secs_f64();
    let rec = |n: &str| -> (f64, f64) {
        let s = p.read(&format!(".weft/records/p/{n}.json"));
        let v: serde_json::Value = serde_json::from_str(&s).unwrap();
        (
            v["start_unix"].as_f64().unwrap(),
            v["end_unix"].as_f64().unwrap(),
        )
    };
    let (s1, e1) = rec("slow1");
    let (s2, e2) = rec("slow2");
    assert!(
        s1 < e2 && s2 < e1,
        "intervals [{s1}, {e1}] and [{s2}, {e2}] do not overlap"
    );
    // Speed is not asserted (the machine is shared): the records' overlap above is the
    // proof of parallelism.
    eprintln!("two 1 s stages took {wall:.2} s with -j 2");
}

#[test]
fn sigkill_in_the_middle_of_a_stage_leaves_nothing_fresh_and_a_rerun_completes() {
    let pipeline = r#"
[stages.a]
cmd = "echo ${v} > ${outputs.o}"
params = { v = 1 }
outputs = { o = "out/a.txt" }
[stages.slow]
cmd = "cp ${inputs.i} ${outputs.o} && sleep 1.5 && echo end >> ${outputs.o}"
inputs = { i = "out/a.txt" }
outputs = { o = "out/slow.txt" }
"#;
    let p = Project::new(pipeline);
    p.run(&[]);
    assert_eq!(p.read("out/slow.txt"), "1\nend\n");
    // Change a param and kill `weft run` while `slow` runs.
    p.write_pipeline(&pipeline.replace("v = 1", "v = 2"));
    let mut child = Command::new(env!("CARGO_BIN_EXE_weft"))
        .args(["run", "pipelines/p.toml", "-q"])
        .current_dir(p.root())
        .spawn()
        .unwrap();
    std::thread::sleep(Duration::from_millis(700));
    child.kill().unwrap(); // SIGKILL
    child.wait().unwrap();
    std::thread::sleep(Duration::from_millis(1500));
    // The old output is untouched and not taken as fresh; no half-written file under
    // the real name; the stage's child died with weft (it never appended "end").
    assert_eq!(p.read("out/slow.txt"), "1\nend\n");
    let st = p.status();
    assert!(st.contains("stale  slow:"), "{st}");
    let leftovers: Vec<String> = std::fs::read_dir(p.root().join("out"))
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().to_string())
        .filter(|n| n.contains("weft-tmp"))
        .collect();
    for l in &leftovers {
        let s = p.read(&format!("out/{l}"));
        assert!(
            !s.contains("end"),
            "the killed stage's child kept running: {l} = {s:?}"
        );
    }
    let ran = p.run(&[]);
    assert!(ran.contains(&"slow".to_string()), "{ran:?}");
    assert_eq!(p.read("out/slow.txt"), "2\nend\n");
    assert_eq!(p.run(&[]), Vec::<String>::new());
    // Leftover temporaries of the dead run were cleaned.
    let left = std::fs::read_dir(p.root().join("out"))
        .unwrap()
        .filter(|e| {
            e.as_ref()
                .unwrap()
                .file_name()
                .to_string_lossy()
                .contains("weft-tmp")
        });
    assert_eq!(left.count(), 0);
}

#[test]
fn a_second_concurrent_run_is_refused_with_a_clear_message() {
    let p = Project::new(
        r#"
[stages.slow]
cmd = "sleep 1 && echo x > ${outputs.o}"
outputs = { o = "out/x.txt" }
"#,
    );
    let mut first = Command::new(env!("CARGO_BIN_EXE_weft"))
        .args(["run", "pipelines/p.toml", "-q"])
        .current_dir(p.root())
        .spawn()
        .unwrap();
    std::thread::sleep(Duration::from_millis(300));
    let o = p.weft(&["run", "pipelines/p.toml"]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(!o.status.success());
    assert!(
        err.contains("another `weft run`") && err.contains("hint:"),
        "{err}"
    );
    assert!(first.wait().unwrap().success());
    assert_eq!(p.read("out/x.txt"), "x\n");
}

#[test]
fn a_failure_skips_its_descendants_and_keep_going_runs_the_rest() {
    let pipeline = r#"
[stages.bad]
cmd = "echo about to fail; exit 3; echo > ${outputs.o}"
outputs = { o = "out/bad.txt" }
[stages.after_bad]
cmd = "cp ${inputs.i} ${outputs.o}"
inputs = { i = "out/bad.txt" }
outputs = { o = "out/after.txt" }
[stages.good]
cmd = "echo ok > ${outputs.o}"
outputs = { o = "out/good.txt" }
"#;
    let p = Project::new(pipeline);
    let o = p.weft(&["run", "pipelines/p.toml", "-j", "1"]);
    let err = String::from_utf8_lossy(&o.stderr).to_string();
    assert!(!o.status.success());
    assert!(
        err.contains("FAIL  bad (exit status 3)") && err.contains("| about to fail"),
        "{err}"
    );
    assert!(!p.root().join("out/after.txt").exists());
    let o = p.weft(&["run", "pipelines/p.toml", "-j", "1", "--keep-going"]);
    let err = String::from_utf8_lossy(&o.stderr).to_string();
    assert!(!o.status.success());
    assert_eq!(ran(&err), ["good"], "{err}");
    assert!(err.contains("skip  after_bad"), "{err}");
    assert!(p
        .status()
        .contains("stale  bad: last run failed (exit status 3)"));
}

#[test]
fn status_and_dry_run_give_a_reason_for_every_stage() {
    let p = Project::new(CHAIN);
    p.write("data/in.txt", "hello\n");
    let st = p.status();
    for s in ["a", "b", "c", "d"] {
        assert!(st.contains(&format!("stale  {s}: ")), "{st}");
    }
    let o = p.weft(&["run", "pipelines/p.toml", "--dry-run"]);
    let out = String::from_utf8_lossy(&o.stdout);
    assert_eq!(
        out.lines()
            .filter(|l| l.starts_with("would run") && l.contains(": "))
            .count(),
        4,
        "{out}"
    );
    assert!(!p.root().join("out").exists(), "a dry run wrote outputs");
    p.run(&[]);
    let o = p.weft(&["run", "pipelines/p.toml", "--dry-run"]);
    assert_eq!(
        String::from_utf8_lossy(&o.stdout)
            .lines()
            .filter(|l| l.starts_with("fresh"))
            .count(),
        4
    );
}

#[test]
fn targets_single_and_force() {
    let p = Project::new(CHAIN);
    p.write("data/in.txt", "hello\n");
    // A target runs with what it needs, nothing else.
    assert_eq!(p.run(&["b"]), ["a", "b"]);
    // --single runs just the target.
    assert_eq!(p.run(&["d", "--single"]), ["d"]);
    assert_eq!(p.run(&["--force", "d"]), ["c", "d"]);
}

#[test]
fn records_dag_and_logs_are_readable() {
    let p = Project::new(CHAIN);
    p.write("data/in.txt", "hello\n");
    p.run(&[]);
    let o = p.weft(&["records", "pipelines/p.toml", "--out", "records.parquet"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let t = weft::table::Table::read(&p.root().join("records.parquet")).unwrap();
    assert_eq!(t.num_rows(), 4);
    for c in [
        "instance",
        "command",
        "params",
        "inputs",
        "outputs",
        "binary_hash",
        "tool_version",
        "exit_status",
        "start",
        "end",
    ] {
        assert!(t.has(c), "records table lacks `{c}`");
    }
    let dot = String::from_utf8_lossy(
        &p.weft(&["dag", "pipelines/p.toml", "--format", "dot"])
            .stdout,
    )
    .to_string();
    assert!(
        dot.starts_with("digraph") && dot.contains("n0 -> n1"),
        "{dot}"
    );
    let mm = String::from_utf8_lossy(
        &p.weft(&["dag", "pipelines/p.toml", "--format", "mermaid"])
            .stdout,
    )
    .to_string();
    assert!(mm.contains("n1 --> n2"), "{mm}");
    let log = p.read(".weft/logs/p/b.log");
    assert!(log.contains("# command: cat out/a.txt"), "{log}");
    // One record per instance, not a lock file.
    let recs: Vec<PathBuf> = std::fs::read_dir(p.root().join(".weft/records/p"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .collect();
    assert_eq!(recs.len(), 4);
}

#[test]
fn a_stage_that_does_not_write_its_output_fails() {
    let p = Project::new(
        "[stages.lazy]\ncmd = \"true ${outputs.o}\"\noutputs = { o = \"out/x.txt\" }\n",
    );
    let o = p.weft(&["run", "pipelines/p.toml"]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(!o.status.success());
    assert!(err.contains("did not write output `out/x.txt`"), "{err}");
}

#[test]
fn every_malformed_pipeline_file_gives_a_clear_error() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/pipelines_bad");
    let mut files: Vec<PathBuf> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .collect();
    files.sort();
    assert!(files.len() >= 20, "the corpus has {} files", files.len());
    for f in files {
        let src = std::fs::read_to_string(&f).unwrap();
        let expect = src
            .lines()
            .next()
            .unwrap()
            .strip_prefix("# expect: ")
            .expect("first line names the expected error");
        let o = Command::new(env!("CARGO_BIN_EXE_weft"))
            .arg("status")
            .arg(&f)
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&o.stderr);
        let name = f.file_name().unwrap().to_string_lossy();
        assert_eq!(
            o.status.code(),
            Some(1),
            "{name}: exit code; stderr:\n{err}"
        );
        assert!(!err.contains("panicked"), "{name} panicked:\n{err}");
        assert!(err.starts_with("error: "), "{name}:\n{err}");
        assert!(
            err.contains(expect),
            "{name}: expected `{expect}` in:\n{err}"
        );
        assert!(
            err.contains(&*name) && err.contains("line "),
            "{name}: the message must name the file and line:\n{err}"
        );
    }
}

#[test]
fn a_slurm_dry_run_prints_the_sbatch_commands_with_the_executor_resources() {
    // Needs no Slurm: a dry run submits nothing (tests/pipeline_slurm.rs runs a real one).
    let p = Project::new(
        r#"
[stages.gen]
cmd = "echo ${n} > ${outputs.o}"
matrix = { n = [1, 2, 3] }
outputs = { o = "out/gen/${n}.txt" }

[stages.use]
cmd = "cat ${inputs.i} > ${outputs.o}"
matrix = { n = [1, 2, 3] }
inputs = { i = "out/gen/${n}.txt" }
outputs = { o = "out/use/${n}.txt" }

[stages.all]
cmd = "cat ${inputs.u}/* > ${outputs.o}"
inputs = { u = "out/use" }
outputs = { o = "out/all.txt" }

[executor]
partition = "short"
account = "proj42"
time = "00:10:00"
memory = "1G"
sbatch_args = ["--qos=low"]

[executor.stages.use]
time = "02:00:00"
cpus = 4
sbatch_args = ["--constraint=fast"]
"#,
    );
    let o = p.weft(&[
        "run",
        "pipelines/p.toml",
        "--executor",
        "slurm",
        "--dry-run",
    ]);
    let out = String::from_utf8_lossy(&o.stdout).to_string();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let line = |stage: &str| -> String {
        out.lines()
            .find(|l| l.contains(&format!("--job-name=weft:p:{stage} ")))
            .unwrap_or_else(|| panic!("no sbatch line for `{stage}`:\n{out}"))
            .to_string()
    };
    let (gen, use_, all) = (line("gen"), line("use"), line("all"));
    assert!(gen.starts_with("J1=$(sbatch --parsable "), "{gen}");
    for l in [&gen, &use_, &all] {
        assert!(
            l.contains("--kill-on-invalid-dep=yes")
                && l.contains("--partition=short")
                && l.contains("--account=proj42")
                && l.contains("--mem=1G")
                && l.contains("--qos=low"),
            "{l}"
        );
    }
    assert!(
        gen.contains("--array=0-2") && gen.contains("--time=00:10:00"),
        "{gen}"
    );
    assert!(!gen.contains("--dependency"), "{gen}");
    // Task t of `use` needs task t of `gen`: one array with aftercorr; the stage's
    // overrides replace time and cpus, and add to sbatch_args.
    assert!(
        use_.contains("--array=0-2")
            && use_.contains("\"--dependency=aftercorr:${J1}\"")
            && use_.contains("--time=02:00:00")
            && use_.contains("--cpus-per-task=4")
            && use_.contains("--constraint=fast"),
        "{use_}"
    );
    // `all` needs every task of `use`: the whole array.
    assert!(
        all.contains("\"--dependency=afterok:${J2}\"") && !all.contains("--array"),
        "{all}"
    );
    assert!(out.contains("#   task 1: use@n=2"), "{out}");
    // Nothing was written or submitted.
    assert!(!p.root().join("out").exists() && !p.root().join(".weft/jobs").exists());
}

#[test]
fn the_slurm_executor_without_slurm_says_what_is_missing() {
    let p =
        Project::new("[stages.a]\ncmd = \"echo > ${outputs.o}\"\noutputs = { o = \"out/a\" }\n");
    let o = Command::new(env!("CARGO_BIN_EXE_weft"))
        .args(["run", "pipelines/p.toml", "--executor", "slurm"])
        .current_dir(p.root())
        .env("PATH", p.root().join("no-such-dir"))
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(
        err.contains("needs the Slurm client commands") && err.contains("hint:"),
        "{err}"
    );
}

#[test]
fn a_slurm_dry_run_puts_many_instances_after_one_task_in_one_array() {
    // Three instances after each task of a two-task array: one `afterok:A_t` array per
    // task (2 submissions) rather than three `aftercorr` arrays.
    let p = Project::new(
        r#"
[stages.gen]
cmd = "echo ${n} > ${outputs.o}"
matrix = { n = [1, 2] }
outputs = { o = "out/gen/${n}.txt" }

[stages.use]
cmd = "cat ${inputs.i} > ${outputs.o} && echo ${k} >> ${outputs.o}"
matrix = { n = [1, 2], k = [1, 2, 3] }
inputs = { i = "out/gen/${n}.txt" }
outputs = { o = "out/use/${n}-${k}.txt" }
"#,
    );
    let o = p.weft(&[
        "run",
        "pipelines/p.toml",
        "--executor",
        "slurm",
        "--dry-run",
    ]);
    let out = String::from_utf8_lossy(&o.stdout).to_string();
    let uses: Vec<&str> = out
        .lines()
        .filter(|l| l.contains("--job-name=weft:p:use "))
        .collect();
    assert_eq!(uses.len(), 2, "{out}");
    assert!(
        uses[0].contains("--array=0-2") && uses[0].contains("\"--dependency=afterok:${J1}_0\""),
        "{out}"
    );
    assert!(
        uses[1].contains("--array=0-2") && uses[1].contains("\"--dependency=afterok:${J1}_1\""),
        "{out}"
    );
}

/// A stage judged by the weft tool its command runs, not by a `mkdir` before it: the
/// figure stages of the shipped pipelines start `mkdir -p … && weft-plot …`, and a new
/// weft-plot must make them stale; `weft` as an argument is not a command.
#[test]
fn a_stage_is_judged_by_the_weft_tool_it_runs() {
    let p = Project::new(
        r#"
[stages.figs]
cmd = "mkdir -p out/figs && \\\n  weft --version > ${outputs.o}"
outputs = { o = "out/figs/v.txt" }
[stages.words]
cmd = "echo weft > ${outputs.o}"
outputs = { o = "out/words.txt" }
"#,
    );
    assert_eq!(p.run(&[]), ["figs", "words"]);
    let t = p.root().join("records.parquet");
    let o = p.weft(&["records", "pipelines/p.toml", "--out", t.to_str().unwrap()]);
    assert!(o.status.success());
    let r = weft::table::Table::read(&t).unwrap();
    let (inst, bin) = (r.str("instance", "").unwrap(), r.str("binary", "").unwrap());
    let weft = std::path::PathBuf::from(env!("CARGO_BIN_EXE_weft"));
    let of = |i: &str| std::path::PathBuf::from(&bin[inst.iter().position(|x| x == i).unwrap()]);
    assert_eq!(of("figs"), weft, "{inst:?} {bin:?}");
    // A weft word that is an argument, not a command, does not count.
    assert!(of("words").ends_with("echo"), "{inst:?} {bin:?}");
}
