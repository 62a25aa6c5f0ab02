//! Pipeline files: parsing (raw serde form with spans), then validation into stage
//! instances with resolved templates, sweeps expanded, paths checked and the DAG built.
//!
//! ```toml
//! [pipeline]                 # optional
//! root = ".."                # project root, relative to this file
//!
//! [vars]                     # ${name} anywhere in the stages
//! out = "runs/rod"
//!
//! [stages.weave]
//! cmd = "weft-weave rod --out ${outputs.model} --elements ${elements}"
//! params = { elements = 200 }
//! outputs = { model = "${out}/model-${elements}" }
//!
//! [stages.sweep]
//! cmd = "weft-simulate --model ${inputs.model} --out ${outputs.result} --dt-safety ${safety}"
//! matrix = { safety = [0.5, 0.9] }          # or foreach = [{ safety = 0.5 }, ...]
//! inputs = { model = "${out}/model-200" }
//! outputs = { result = "${out}/sim-${safety}" }
//! ```
//!
//! Templates: `${name}` (a var, a stage param or a sweep value), `${inputs.NAME}`,
//! `${outputs.NAME}`, `${inputs}` and `${outputs}` (all, space-separated), `${stage}`,
//! `${instance}`; `$$` is a literal `$`. Inputs and outputs may be tables (named) or
//! lists (named `0`, `1`, ...). Every output must be passed to the command through
//! `${outputs...}`: the engine hands the command a temporary path and renames it into
//! place only when the command succeeds.
//!
//! Reading a file is a short list of steps, one module each: `raw` reads the serde form
//! (with spans for line numbers), `vars` renders `[vars]`, `stage` expands each stage
//! into its instances (sweep points from `sweep`), `executor` checks `[executor]`, and
//! `link` infers the dependencies and the order; the result is the `resolved` form.
//! `template` renders `${...}` and `paths` normalises paths.

use std::path::Path;

use crate::error::{Result, WeftError};

mod executor;
mod link;
mod paths;
mod raw;
mod resolved;
mod stage;
mod sweep;
mod template;
mod vars;

pub use paths::{file_name_of, within};
pub use resolved::{ExecutorSpec, Instance, Pipeline, Resources};
pub use template::{render, shell_quote, Ctx};

use raw::{RawFile, RawMeta, Source};

impl Pipeline {
    /// Parse and validate a pipeline file.
    pub fn load(file: &Path) -> Result<Pipeline> {
        let src = std::fs::read_to_string(file).map_err(|e| WeftError::io(file, e))?;
        Self::parse(file, &src)
    }

    /// Parse and validate the text `src` of pipeline file `file`.
    pub fn parse(file: &Path, src: &str) -> Result<Pipeline> {
        let at = Source::new(file, src);
        let RawFile {
            pipeline,
            vars,
            stages,
            executor,
        } = raw::read(src, &at)?;
        let root = project_root(file, pipeline.as_ref());
        if stages.is_empty() {
            return Err(WeftError::input("the pipeline has no stages")
                .in_file(file)
                .expected("at least one [stages.NAME] table with a `cmd`"));
        }
        let vars = vars::resolve(&vars, &at)?;
        let instances = stage::instances(&stages, &vars, &root, &at)?;
        check_unique_names(&instances, &at)?;
        let executor = executor::read(executor, &instances, &at)?;
        let mut p = Pipeline {
            file: file.to_path_buf(),
            root,
            instances,
            order: vec![],
            executor,
        };
        p.link()?;
        Ok(p)
    }
}

/// The project root: `[pipeline] root` relative to the file's folder, else the folder
/// above a `pipelines/` folder, else the file's folder.
fn project_root(file: &Path, meta: Option<&RawMeta>) -> std::path::PathBuf {
    let dir = file
        .parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    match meta.and_then(|m| m.root.clone()) {
        Some(r) => dir.join(r),
        None if dir.file_name().is_some_and(|n| n == "pipelines") => dir
            .parent()
            .filter(|p| !p.as_os_str().is_empty())
            .unwrap_or(Path::new("."))
            .to_path_buf(),
        None => dir.to_path_buf(),
    }
}

/// Instance names are unique (two sweep points with the same values are not).
fn check_unique_names(instances: &[Instance], at: &Source) -> Result<()> {
    let mut seen = std::collections::HashMap::new();
    for (i, inst) in instances.iter().enumerate() {
        if let Some(j) = seen.insert(inst.name.clone(), i) {
            return Err(at
                .err(
                    format!("two instances are named `{}`", inst.name),
                    inst.line,
                    &format!("stages.{}", instances[j].stage),
                )
                .hint("sweep values must differ"));
        }
    }
    Ok(())
}
