//! Slurm's own commands, as the executor uses them: `squeue` (the jobs and their states),
//! `scancel`, `scontrol show config` (the largest array), and the live jobs of a
//! pipeline's earlier runs.

use std::collections::{BTreeMap, HashMap};
use std::path::{Path, PathBuf};
use std::process::Command;

use super::files::{jobs_dir, read_json, Files, Ledger};
use crate::error::{Result, WeftError};
use crate::pipeline::spec::Pipeline;

/// Job states `squeue` reports for jobs that are not over.
pub(super) fn is_live(state: &str) -> bool {
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

/// What a Slurm command that could not be run says: missing (not a Slurm machine), or why.
pub(super) fn tool_error(tool: &str, e: std::io::Error) -> WeftError {
    if e.kind() == std::io::ErrorKind::NotFound {
        WeftError::input(format!("`{tool}` not found: the Slurm executor needs the Slurm client commands"))
            .hint("run on a Slurm login node, or start a single-node Slurm with `scripts/slurm-single-node.sh start`; `weft run` without `--executor slurm` runs locally")
    } else {
        WeftError::input(format!("cannot run `{tool}`: {e}"))
    }
}

/// `scancel` the given jobs (ids or array tasks), optionally only those in `state`.
pub(super) fn scancel(jobs: &[String], state: Option<&str>) -> Result<()> {
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

/// `MaxArraySize` of the cluster (array task ids must stay below it).
pub(super) fn max_array_size() -> Result<usize> {
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

/// `p` made absolute (as given when that fails).
pub(super) fn abs(p: &Path) -> PathBuf {
    std::path::absolute(p).unwrap_or_else(|_| p.to_path_buf())
}
