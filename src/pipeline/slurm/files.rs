//! The Slurm executor's files, under `.weft/jobs/<pipeline>/`: the ledger the controller
//! writes at submission, the result and progress a job writes, Slurm's own output.

use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use crate::error::{Result, WeftError};
use crate::pipeline::host::process_tag;
use crate::pipeline::spec::{file_name_of, Instance, Pipeline};

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

/// Write `v` as JSON to `path` atomically (a temporary renamed into place).
pub(super) fn write_json<T: Serialize>(path: &Path, v: &T) -> Result<()> {
    if let Some(d) = path.parent() {
        std::fs::create_dir_all(d).map_err(|e| WeftError::io(d, e))?;
    }
    let tmp = path.with_extension(format!("tmp-{}", process_tag()));
    std::fs::write(&tmp, serde_json::to_string(v).expect("serialises"))
        .map_err(|e| WeftError::io(&tmp, e))?;
    std::fs::rename(&tmp, path).map_err(|e| WeftError::io(path, e))
}

/// `path` read as JSON; `None` when missing or unreadable.
pub(super) fn read_json<T: for<'a> Deserialize<'a>>(path: &Path) -> Option<T> {
    serde_json::from_str(&std::fs::read_to_string(path).ok()?).ok()
}

/// The executor's files of each instance, in the pipeline's jobs folder.
pub(super) struct Files {
    pub(super) dir: PathBuf,
}

impl Files {
    pub(super) fn of(&self, inst: &str, ext: &str) -> PathBuf {
        self.dir.join(format!("{}.{ext}", file_name_of(inst)))
    }
    pub(super) fn ledger(&self, inst: &str) -> PathBuf {
        self.of(inst, "job")
    }
    pub(super) fn result(&self, inst: &str) -> PathBuf {
        self.of(inst, "result")
    }
    pub(super) fn progress(&self, inst: &str) -> PathBuf {
        self.of(inst, "progress")
    }
    pub(super) fn slurm_out(&self, job: &str) -> PathBuf {
        self.dir.join("slurm").join(format!("{job}.out"))
    }
    pub(super) fn forget(&self, inst: &str) {
        for e in ["job", "result", "progress"] {
            let _ = std::fs::remove_file(self.of(inst, e));
        }
    }
}
