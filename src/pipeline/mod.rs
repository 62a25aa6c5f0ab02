//! The pipeline engine behind `weft`: declarative study files (`pipelines/*.toml`) with
//! make-style reruns decided on content, parallel execution, atomic outputs, one record
//! per stage instance, local or Slurm executors (`exec`, `slurm`), and gathering of sweep outputs into one table.

pub mod engine;
pub mod exec;
pub mod gather;
pub mod hash;
pub mod host;
pub mod progress;
pub mod record;
pub mod show;
pub mod slurm;
pub mod spec;
pub mod workspace;

pub use engine::{run, ExecutorKind, RunOptions};
pub use spec::Pipeline;
pub use workspace::{Verdict, Workspace};
