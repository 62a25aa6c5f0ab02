//! `weft job`: what runs inside each Slurm job. It runs its instance as the local
//! executor would, writes the instance's record, then a result file for the controller.

use std::path::Path;

use super::files::{instance_key, jobs_dir, write_json, Files, JobResult};
use crate::error::{Result, WeftError};
use crate::pipeline::exec::{
    attempt_tag, finish, log_paths, prepare, run_command, stage_path, Finish,
};
use crate::pipeline::host::{now_unix, process_tag};
use crate::pipeline::spec::{Instance, Pipeline};
use crate::pipeline::workspace::{Verdict, Workspace};

/// The line of a job manifest that names this task's instance.
struct Task {
    /// The pipeline file (absolute).
    pipeline: String,
    /// The instance.
    name: String,
    /// [`instance_key`] at submission.
    key: String,
    /// Run even if fresh.
    forced: bool,
}

/// Read this task's line of a manifest: the array task given, else `$SLURM_ARRAY_TASK_ID`,
/// else `-` (a single job).
fn read_manifest(manifest: &Path, task: Option<String>) -> Result<Task> {
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
    Ok(Task {
        pipeline: pipeline.to_string(),
        name: name.to_string(),
        key: key.to_string(),
        forced: *forced == "1",
    })
}

/// This job's id as the ledger names it: `ARRAYJOBID_TASK`, `JOBID`, or `local` outside
/// Slurm.
fn job_id() -> String {
    match (
        std::env::var("SLURM_ARRAY_JOB_ID"),
        std::env::var("SLURM_ARRAY_TASK_ID"),
        std::env::var("SLURM_JOB_ID"),
    ) {
        (Ok(a), Ok(t), _) => format!("{a}_{t}"),
        (_, _, Ok(j)) => j,
        _ => "local".into(),
    }
}

/// Writes the result file of this job's instance.
struct ResultFile<'a> {
    files: Files,
    name: &'a str,
    job: String,
}

impl ResultFile<'_> {
    fn write(
        &self,
        outcome: &str,
        status: i32,
        seconds: f64,
        why: Option<String>,
        log: String,
    ) -> Result<()> {
        write_json(
            &self.files.result(self.name),
            &JobResult {
                job: self.job.clone(),
                outcome: outcome.into(),
                status,
                seconds,
                why,
                log,
            },
        )
    }

    /// The job runs nothing: the instance is gone or changed since submission (status 2).
    fn refuse(&self, why: String) -> Result<i32> {
        eprintln!("weft job: {why}");
        self.write("failed", 2, 0.0, Some(why), String::new())?;
        Ok(2)
    }
}

/// `weft job --manifest FILE`: inside a Slurm job, run the instance of this array task
/// (or the job's only instance) as the local executor would, write its record, then its
/// result file. Exits with the instance's status, so that `afterok` holds its dependants
/// back after a failure.
pub fn run_job(manifest: &Path, task: Option<String>) -> Result<i32> {
    let t = read_manifest(manifest, task)?;
    let (pipeline, name) = (&t.pipeline, t.name.as_str());
    let job = job_id();
    let p = Pipeline::load(Path::new(pipeline))?;
    let out = ResultFile {
        files: Files { dir: jobs_dir(&p) },
        name,
        job,
    };
    let Some(inst) = p.instances.iter().find(|i| i.name == *name) else {
        return out.refuse(format!("instance `{name}` is no longer in `{pipeline}`"));
    };
    if instance_key(inst) != t.key {
        return out.refuse(format!(
            "`{pipeline}` changed `{name}` (command, parameters, inputs or outputs) since this job was submitted; `weft run` submits it again"
        ));
    }
    let mut ws = Workspace::open(&p);
    if !t.forced && ws.verdict(inst)? == Verdict::Fresh {
        eprintln!("weft job: `{name}` is fresh (its upstream reproduced the same inputs)");
        out.write("fresh", 0, 0.0, None, String::new())?;
        return Ok(0);
    }
    let status = run_instance(&p, &mut ws, inst, &out)?;
    Ok(status.clamp(0, 255))
}

/// Run the instance as the local executor would (its progress to the progress file, at
/// most twice a second), write its record and its result; its exit status.
fn run_instance(
    p: &Pipeline,
    ws: &mut Workspace,
    inst: &Instance,
    out: &ResultFile,
) -> Result<i32> {
    let name = out.name;
    let a = prepare(p, ws, inst, &attempt_tag())?;
    let progress_file = out.files.progress(name);
    let mut last = 0.0f64;
    let ran = run_command(&a, &ws.root.clone(), &stage_path(ws), &mut |f| {
        let now = now_unix();
        if now - last >= 0.5 {
            last = now;
            let tmp = progress_file.with_extension(format!("progress-{}", process_tag()));
            if std::fs::write(&tmp, format!("{f}\n")).is_ok() {
                let _ = std::fs::rename(&tmp, &progress_file);
            }
        }
    });
    let fin = finish(ws, inst, a, ran.clone())?;
    let _ = std::fs::remove_file(&progress_file);
    Ok(match fin {
        Finish::Ran { seconds } => {
            out.write("ran", 0, seconds, None, log_paths(ws, inst).1)?;
            0
        }
        Finish::Failed { status, why, log } => {
            if let Some(w) = &why {
                eprintln!("weft job: `{name}` failed: {w}");
            }
            out.write("failed", status, ran.end - ran.start, why, log)?;
            status
        }
        Finish::Fresh | Finish::Lost { .. } => unreachable!("finish only runs or fails"),
    })
}
