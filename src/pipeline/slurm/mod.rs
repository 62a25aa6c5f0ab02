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
//!
//! Modules: `files` (the ledger, result and progress files), `queue` (`squeue`, `scancel`
//! and the live jobs), `submit` (one sbatch submission), `executor` (the controller that
//! `weft run` attaches) and `job` (what runs inside each job).

mod executor;
mod files;
mod job;
mod queue;
mod submit;

pub use executor::SlurmExecutor;
pub use files::{instance_key, jobs_dir, JobResult, Ledger};
pub use job::run_job;
pub use queue::{live_jobs, project_tag, squeue, Queued};
