//! The raw form of a pipeline file, as serde reads it (with spans, before any check),
//! and where things sit in the file: line numbers for the error messages.

use std::collections::BTreeMap;
use std::path::Path;

use serde::Deserialize;
use toml::Spanned;

use crate::error::{Result, WeftError};

/// The whole file: `[pipeline]`, `[vars]`, `[stages.NAME]` and `[executor]`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawFile {
    pub(super) pipeline: Option<RawMeta>,
    #[serde(default)]
    pub(super) vars: BTreeMap<String, Spanned<toml::Value>>,
    #[serde(default)]
    pub(super) stages: BTreeMap<String, Spanned<RawStage>>,
    pub(super) executor: Option<Spanned<RawExecutor>>,
}

/// `[executor]`: Slurm resources, with `[executor.stages.NAME]` overrides.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawExecutor {
    pub(super) partition: Option<Spanned<String>>,
    pub(super) account: Option<Spanned<String>>,
    pub(super) time: Option<Spanned<String>>,
    pub(super) memory: Option<Spanned<String>>,
    pub(super) cpus: Option<Spanned<i64>>,
    pub(super) sbatch_args: Option<Spanned<Vec<String>>>,
    pub(super) poll_seconds: Option<Spanned<f64>>,
    #[serde(default)]
    pub(super) stages: BTreeMap<String, Spanned<RawResources>>,
}

/// A table of Slurm resources: `[executor.stages.NAME]`, or `[executor]`'s own fields.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawResources {
    pub(super) partition: Option<Spanned<String>>,
    pub(super) account: Option<Spanned<String>>,
    pub(super) time: Option<Spanned<String>>,
    pub(super) memory: Option<Spanned<String>>,
    pub(super) cpus: Option<Spanned<i64>>,
    pub(super) sbatch_args: Option<Spanned<Vec<String>>>,
}

/// `[pipeline]`: the project root (relative to the file) and a description.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawMeta {
    pub(super) root: Option<String>,
    #[allow(dead_code)]
    pub(super) description: Option<String>,
}

/// `[stages.NAME]`: a command template, its paths, params and sweep.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawStage {
    pub(super) cmd: Spanned<String>,
    #[allow(dead_code)]
    pub(super) desc: Option<String>,
    pub(super) inputs: Option<Spanned<Paths>>,
    pub(super) outputs: Option<Spanned<Paths>>,
    #[serde(default)]
    pub(super) params: BTreeMap<String, Spanned<toml::Value>>,
    pub(super) matrix: Option<Spanned<BTreeMap<String, Vec<toml::Value>>>>,
    pub(super) foreach: Option<Spanned<Vec<BTreeMap<String, toml::Value>>>>,
}

/// A stage's `inputs` or `outputs`: a list of paths or a table of named paths.
#[derive(Debug, Deserialize)]
#[serde(untagged)]
pub(super) enum Paths {
    List(Vec<String>),
    Named(BTreeMap<String, String>),
}

impl Paths {
    /// (name, path) pairs; a list's paths are named `0`, `1`, ...
    pub(super) fn named(&self) -> Vec<(String, String)> {
        match self {
            Paths::List(v) => v
                .iter()
                .enumerate()
                .map(|(i, p)| (i.to_string(), p.clone()))
                .collect(),
            Paths::Named(m) => m.iter().map(|(k, v)| (k.clone(), v.clone())).collect(),
        }
    }
}

/// Offsets of line starts, for byte offset → line number in O(log n).
struct Lines(Vec<usize>);

impl Lines {
    fn new(src: &str) -> Lines {
        Lines(
            std::iter::once(0)
                .chain(src.match_indices('\n').map(|(i, _)| i + 1))
                .collect(),
        )
    }
    fn of(&self, offset: usize) -> usize {
        self.0.partition_point(|&s| s <= offset)
    }
}

/// The pipeline file being read: its name, and the line of each byte offset of its text.
pub(super) struct Source<'a> {
    pub(super) file: &'a Path,
    lines: Lines,
}

impl<'a> Source<'a> {
    pub(super) fn new(file: &'a Path, src: &str) -> Source<'a> {
        Source {
            file,
            lines: Lines::new(src),
        }
    }

    /// The line (from 1) of a byte offset of the text.
    pub(super) fn line(&self, offset: usize) -> usize {
        self.lines.of(offset)
    }

    /// An input error in this file, at `line` and `key`.
    pub(super) fn err(&self, what: String, line: usize, key: &str) -> WeftError {
        WeftError::input(what)
            .in_file(self.file)
            .at_line(line)
            .at_key(key.to_string())
    }
}

/// Read the raw form: the TOML syntax and the shape of the tables, with a hint for the
/// usual mistakes (an unknown key, paths given as neither a list nor a table).
pub(super) fn read(src: &str, at: &Source) -> Result<RawFile> {
    toml::from_str(src).map_err(|e| {
        let line = e.span().map(|s| at.line(s.start)).unwrap_or(0);
        let msg = e.message().to_string();
        let hint = if msg.contains("unknown field") {
            "a pipeline file has [pipeline], [vars], [stages.NAME] and [executor] tables; a stage has cmd, inputs, outputs, params, matrix, foreach, desc; [executor] has partition, account, time, memory, cpus, sbatch_args, poll_seconds and [executor.stages.NAME]"
        } else if msg.contains("did not match any variant") {
            "inputs and outputs are a list of paths or a table of named paths"
        } else {
            "see the pipeline file format in docs/pipelines.md"
        };
        WeftError::input(format!("invalid pipeline file: {msg}"))
            .in_file(at.file)
            .at_line(line)
            .hint(hint)
    })
}

/// A scalar's text as templates use it; `None` for arrays and tables.
pub(super) fn value_str(v: &toml::Value) -> Option<String> {
    match v {
        toml::Value::String(s) => Some(s.clone()),
        toml::Value::Integer(i) => Some(i.to_string()),
        toml::Value::Float(f) => Some(format!("{f}")),
        toml::Value::Boolean(b) => Some(b.to_string()),
        _ => None,
    }
}
