//! One `sbatch` submission of the Slurm executor: the manifest its job reads, the
//! options it is submitted with, and the submission itself (or, for a dry run, the
//! command printed as a line of a shell script).

use std::path::Path;
use std::process::Command;

use super::files::instance_key;
use super::queue::tool_error;
use crate::error::{Result, WeftError};
use crate::pipeline::exec::Launch;
use crate::pipeline::spec::{shell_quote, Pipeline, Resources};

/// The instances of one submission: (array task id, instance); `None` ids for a single
/// job.
pub(super) type Tasks<'a> = Vec<(Option<usize>, &'a Launch)>;

/// The manifest of a submission: the pipeline file, then per task its instance, the
/// instance's key and whether it is forced.
pub(super) fn manifest_text(p: &Pipeline, pipeline_file: &Path, tasks: &Tasks) -> String {
    let mut text = format!(
        "# weft job manifest: task, instance, key, forced\npipeline\t{}\n",
        pipeline_file.display()
    );
    for (t, l) in tasks {
        let inst = &p.instances[l.idx];
        text.push_str(&format!(
            "{}\t{}\t{}\t{}\n",
            t.map(|t| t.to_string()).unwrap_or_else(|| "-".into()),
            inst.name,
            instance_key(inst),
            u8::from(l.force)
        ));
    }
    text
}

/// What a submission is: where and as what its job runs, and what it runs.
pub(super) struct Sbatch<'a> {
    /// The pipeline file's stem.
    pub(super) stem: &'a str,
    pub(super) stage: &'a str,
    /// The project root, where the job runs.
    pub(super) root: &'a Path,
    /// Where Slurm writes what it captures of the job.
    pub(super) slurm_dir: &'a Path,
    /// `--comment` of this pipeline file's jobs.
    pub(super) tag: &'a str,
    /// Task ids of an array; `None` for a single job.
    pub(super) array: Option<Vec<usize>>,
    pub(super) dependency: Option<&'a str>,
    pub(super) resources: &'a Resources,
    pub(super) weft_exe: &'a Path,
    pub(super) manifest: &'a Path,
}

impl Sbatch<'_> {
    /// The `sbatch` options: weft's own, then the stage's resources, then `--wrap` with
    /// `weft job`.
    pub(super) fn args(&self) -> Vec<String> {
        let res = self.resources;
        let mut args: Vec<String> = vec![
            "--parsable".into(),
            format!("--job-name=weft:{}:{}", self.stem, self.stage),
            format!("--chdir={}", self.root.display()),
            format!(
                "--output={}",
                self.slurm_dir
                    .join(if self.array.is_some() {
                        "%A_%a.out"
                    } else {
                        "%j.out"
                    })
                    .display()
            ),
            "--kill-on-invalid-dep=yes".into(),
            format!("--comment={}", self.tag),
        ];
        if let Some(ids) = &self.array {
            args.push(format!("--array={}", ranges(ids)));
        }
        if let Some(d) = &self.dependency {
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
            shell_quote(&self.manifest.display().to_string())
        ));
        args
    }
}

/// A dry run's submission `seq`: the sbatch command as a line of a shell script that
/// keeps the job id in `$Jseq`, and its instances as comments. Returns the id as later
/// commands name it, `${Jseq}`.
pub(super) fn print_dry(p: &Pipeline, seq: usize, args: &[String], tasks: &Tasks) -> String {
    let var = format!("J{seq}");
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
    for (t, l) in tasks {
        println!(
            "#   {} {}",
            t.map(|t| format!("task {t}:"))
                .unwrap_or_else(|| "job:".into()),
            p.instances[l.idx].name
        );
    }
    format!("${{{var}}}")
}

/// Write the manifest and submit: the job id `sbatch --parsable` prints.
pub(super) fn sbatch(
    s: &Sbatch,
    args: &[String],
    text: String,
    pipeline_file: &Path,
) -> Result<String> {
    let (slurm_dir, manifest, stage) = (s.slurm_dir, s.manifest, s.stage);
    std::fs::create_dir_all(slurm_dir).map_err(|e| WeftError::io(slurm_dir, e))?;
    if let Some(d) = manifest.parent() {
        std::fs::create_dir_all(d).map_err(|e| WeftError::io(d, e))?;
    }
    std::fs::write(manifest, text).map_err(|e| WeftError::io(manifest, e))?;
    let out = Command::new("sbatch")
        .args(args)
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
        .in_file(pipeline_file)
        .at_key(format!("executor (resources of stage `{stage}`)"))
        .hint("check partition, account, time, memory and cpus in [executor] against `sinfo`; `weft run --executor slurm --dry-run` prints the sbatch commands"));
    }
    Ok(id)
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
