//! The resolved form of a pipeline file: stage instances with their templates rendered,
//! sweeps expanded and paths checked, in a dependency order, and the Slurm resources of
//! `[executor]`. What `super::raw` reads is validated into this form.

use std::collections::BTreeMap;
use std::path::PathBuf;

use crate::error::{Result, WeftError};

/// One runnable stage instance (a stage, or one point of its sweep).
#[derive(Debug, Clone)]
pub struct Instance {
    /// `stage` or `stage@k=v,k=v`.
    pub name: String,
    pub stage: String,
    /// The command template (outputs still as `${outputs...}`).
    pub cmd_template: String,
    /// The command with final output paths: what the record stores.
    pub command: String,
    /// Values of the vars, params and sweep values this instance uses.
    pub params: BTreeMap<String, String>,
    /// All template values (vars, params, sweep values) for rendering.
    pub values: BTreeMap<String, String>,
    /// The stage's own params and sweep values (what distinguishes instances): the
    /// parameter columns of `weft gather`.
    pub own: BTreeMap<String, String>,
    /// (name, path relative to the root, or absolute for inputs outside it)
    pub inputs: Vec<(String, PathBuf)>,
    pub outputs: Vec<(String, PathBuf)>,
    /// Line of the stage in the pipeline file.
    pub line: usize,
    /// Upstream instances (indices into `Pipeline::instances`).
    pub deps: Vec<usize>,
}

/// A pipeline file, resolved: its project root, its stage instances in a dependency
/// order, and the Slurm resources of its jobs.
#[derive(Debug, Clone)]
pub struct Pipeline {
    pub file: PathBuf,
    pub root: PathBuf,
    pub instances: Vec<Instance>,
    /// Instances in a topological order.
    pub order: Vec<usize>,
    /// The `[executor]` table (Slurm resources); defaults when absent.
    pub executor: ExecutorSpec,
}

/// Slurm resources of a stage's jobs: `[executor]`, overridden by `[executor.stages.NAME]`.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Resources {
    pub partition: Option<String>,
    pub account: Option<String>,
    /// Wall-time limit in a Slurm format (`MM`, `HH:MM:SS`, `D-HH:MM`, ...).
    pub time: Option<String>,
    /// Memory per job (`--mem`): a number of MB, or with a K, M, G or T suffix.
    pub memory: Option<String>,
    pub cpus: Option<u32>,
    /// Further `sbatch` options, passed as given (e.g. `--qos=low`).
    pub sbatch_args: Vec<String>,
}

impl Resources {
    /// `self` with the fields `over` sets replaced; `sbatch_args` are appended.
    fn overridden(&self, over: &Resources) -> Resources {
        Resources {
            partition: over.partition.clone().or_else(|| self.partition.clone()),
            account: over.account.clone().or_else(|| self.account.clone()),
            time: over.time.clone().or_else(|| self.time.clone()),
            memory: over.memory.clone().or_else(|| self.memory.clone()),
            cpus: over.cpus.or(self.cpus),
            sbatch_args: self
                .sbatch_args
                .iter()
                .chain(&over.sbatch_args)
                .cloned()
                .collect(),
        }
    }
}

/// The `[executor]` table: what `weft run --executor slurm` asks Slurm for.
#[derive(Debug, Clone, PartialEq)]
pub struct ExecutorSpec {
    pub default: Resources,
    pub stages: BTreeMap<String, Resources>,
    /// How often the attached controller polls `squeue` and the jobs' result files.
    pub poll_seconds: f64,
}

impl Default for ExecutorSpec {
    fn default() -> Self {
        ExecutorSpec {
            default: Resources::default(),
            stages: BTreeMap::new(),
            poll_seconds: 1.0,
        }
    }
}

impl ExecutorSpec {
    /// The resources of one stage's jobs.
    pub fn for_stage(&self, stage: &str) -> Resources {
        match self.stages.get(stage) {
            Some(o) => self.default.overridden(o),
            None => self.default.clone(),
        }
    }
}

impl Pipeline {
    /// The instances `weft run TARGETS` selects: every one without targets, else the
    /// targets (stages or instances) with everything upstream of them, or with `single`
    /// only the targets.
    pub fn selection(&self, targets: &[String], single: bool) -> Result<Vec<bool>> {
        let n = self.instances.len();
        if targets.is_empty() {
            return Ok(vec![true; n]);
        }
        let mut sel = vec![];
        for t in targets {
            sel.extend(self.select(t)?);
        }
        if single {
            let mut v = vec![false; n];
            for i in sel {
                v[i] = true;
            }
            Ok(v)
        } else {
            Ok(self.with_ancestors(&sel))
        }
    }

    /// The instances `--force` forces: an empty name every selected instance, a stage or
    /// instance name its instances.
    pub fn forced(&self, force: &[String], selected: &[bool]) -> Result<Vec<bool>> {
        let mut forced = vec![false; self.instances.len()];
        for f in force {
            if f.is_empty() {
                forced = selected.to_vec();
            } else {
                for i in self.select(f)? {
                    forced[i] = true;
                }
            }
        }
        Ok(forced)
    }

    /// Instances matching a selector: an instance name, or a stage name (all its instances).
    pub fn select(&self, sel: &str) -> Result<Vec<usize>> {
        let v: Vec<usize> = (0..self.instances.len())
            .filter(|&i| self.instances[i].name == sel || self.instances[i].stage == sel)
            .collect();
        if v.is_empty() {
            let mut stages: Vec<&str> = self.instances.iter().map(|i| i.stage.as_str()).collect();
            stages.dedup();
            return Err(
                WeftError::input(format!("no stage or instance named `{sel}`"))
                    .in_file(&self.file)
                    .expected(format!(
                        "one of [{}] or an instance name from `weft status`",
                        stages.join(", ")
                    )),
            );
        }
        Ok(v)
    }

    /// The closure of `sel` and everything upstream of it.
    pub fn with_ancestors(&self, sel: &[usize]) -> Vec<bool> {
        let mut keep = vec![false; self.instances.len()];
        let mut stack = sel.to_vec();
        while let Some(i) = stack.pop() {
            if !keep[i] {
                keep[i] = true;
                stack.extend(self.instances[i].deps.iter().copied());
            }
        }
        keep
    }
}
