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

use std::collections::{BTreeMap, HashMap};
use std::path::{Component, Path, PathBuf};

use serde::Deserialize;
use toml::Spanned;

use crate::error::{Result, WeftError};

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawFile {
    pipeline: Option<RawMeta>,
    #[serde(default)]
    vars: BTreeMap<String, Spanned<toml::Value>>,
    #[serde(default)]
    stages: BTreeMap<String, Spanned<RawStage>>,
    executor: Option<Spanned<RawExecutor>>,
}

/// `[executor]`: Slurm resources, with `[executor.stages.NAME]` overrides.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawExecutor {
    partition: Option<Spanned<String>>,
    account: Option<Spanned<String>>,
    time: Option<Spanned<String>>,
    memory: Option<Spanned<String>>,
    cpus: Option<Spanned<i64>>,
    sbatch_args: Option<Spanned<Vec<String>>>,
    poll_seconds: Option<Spanned<f64>>,
    #[serde(default)]
    stages: BTreeMap<String, Spanned<RawResources>>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawResources {
    partition: Option<Spanned<String>>,
    account: Option<Spanned<String>>,
    time: Option<Spanned<String>>,
    memory: Option<Spanned<String>>,
    cpus: Option<Spanned<i64>>,
    sbatch_args: Option<Spanned<Vec<String>>>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawMeta {
    root: Option<String>,
    #[allow(dead_code)]
    description: Option<String>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawStage {
    cmd: Spanned<String>,
    #[allow(dead_code)]
    desc: Option<String>,
    inputs: Option<Spanned<Paths>>,
    outputs: Option<Spanned<Paths>>,
    #[serde(default)]
    params: BTreeMap<String, Spanned<toml::Value>>,
    matrix: Option<Spanned<BTreeMap<String, Vec<toml::Value>>>>,
    foreach: Option<Spanned<Vec<BTreeMap<String, toml::Value>>>>,
}

#[derive(Debug, Deserialize)]
#[serde(untagged)]
enum Paths {
    List(Vec<String>),
    Named(BTreeMap<String, String>),
}

impl Paths {
    fn named(&self) -> Vec<(String, String)> {
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

/// `sbatch` options weft sets itself, refused in `sbatch_args`.
const OWN_SBATCH_OPTS: &[&str] = &[
    "--parsable",
    "--array",
    "-a",
    "--dependency",
    "-d",
    "--kill-on-invalid-dep",
    "--wrap",
    "--output",
    "-o",
    "--error",
    "-e",
    "--chdir",
    "-D",
    "--job-name",
    "-J",
    "--comment",
];

/// A Slurm time limit: `MM`, `MM:SS`, `HH:MM:SS`, `D-HH`, `D-HH:MM`, `D-HH:MM:SS`, or
/// `UNLIMITED`/`INFINITE`.
fn is_slurm_time(s: &str) -> bool {
    if matches!(s, "UNLIMITED" | "INFINITE" | "unlimited" | "infinite") {
        return true;
    }
    let digits = |x: &str| !x.is_empty() && x.bytes().all(|b| b.is_ascii_digit());
    let rest = match s.split_once('-') {
        Some((d, r)) if digits(d) => r,
        Some(_) => return false,
        None => s,
    };
    let parts: Vec<&str> = rest.split(':').collect();
    (1..=3).contains(&parts.len()) && parts.iter().all(|p| digits(p))
}

/// A Slurm memory size: a number of MB, or with a K, M, G or T suffix.
fn is_slurm_memory(s: &str) -> bool {
    let n = s.trim_end_matches(['K', 'M', 'G', 'T', 'k', 'm', 'g', 't']);
    s.len() - n.len() <= 1 && !n.is_empty() && n.bytes().all(|b| b.is_ascii_digit())
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

fn value_str(v: &toml::Value) -> Option<String> {
    match v {
        toml::Value::String(s) => Some(s.clone()),
        toml::Value::Integer(i) => Some(i.to_string()),
        toml::Value::Float(f) => Some(format!("{f}")),
        toml::Value::Boolean(b) => Some(b.to_string()),
        _ => None,
    }
}

fn needs_quotes(s: &str) -> bool {
    s.is_empty()
        || !s
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || "/._-=,@+:%".contains(c))
}

/// Quote a path for `sh -c` when it holds shell-special characters.
pub fn shell_quote(s: &str) -> String {
    if needs_quotes(s) {
        format!("'{}'", s.replace('\'', r"'\''"))
    } else {
        s.to_string()
    }
}

/// What a template can refer to.
pub struct Ctx<'a> {
    pub values: &'a BTreeMap<String, String>,
    pub inputs: &'a [(String, String)],
    pub outputs: &'a [(String, String)],
    pub stage: &'a str,
    pub instance: &'a str,
}

/// Render `${...}` references. Returns the text and the plain names referenced.
pub fn render(t: &str, ctx: &Ctx) -> std::result::Result<(String, Vec<String>), String> {
    let mut out = String::with_capacity(t.len());
    let mut used = Vec::new();
    let mut rest = t;
    while let Some(i) = rest.find('$') {
        out.push_str(&rest[..i]);
        let after = &rest[i + 1..];
        if let Some(a) = after.strip_prefix('$') {
            out.push('$');
            rest = a;
            continue;
        }
        let Some(body) = after.strip_prefix('{') else {
            out.push('$');
            rest = after;
            continue;
        };
        let Some(end) = body.find('}') else {
            return Err(format!("unclosed `${{` in `{t}`"));
        };
        let name = body[..end].trim();
        let all = |v: &[(String, String)]| {
            v.iter()
                .map(|(_, p)| shell_quote(p))
                .collect::<Vec<_>>()
                .join(" ")
        };
        let val = match name {
            "inputs" => all(ctx.inputs),
            "outputs" => all(ctx.outputs),
            "stage" => ctx.stage.to_string(),
            "instance" => ctx.instance.to_string(),
            n if n.starts_with("inputs.") || n.starts_with("outputs.") => {
                let (kind, key) = n.split_once('.').expect("has a dot");
                let list = if kind == "inputs" { ctx.inputs } else { ctx.outputs };
                match list.iter().find(|(k, _)| k == key) {
                    Some((_, p)) => shell_quote(p),
                    None => {
                        return Err(format!(
                            "`${{{n}}}` names no {kind} entry; the stage's {kind} are [{}]",
                            list.iter().map(|(k, _)| k.as_str()).collect::<Vec<_>>().join(", ")
                        ))
                    }
                }
            }
            n => match ctx.values.get(n) {
                Some(v) => {
                    used.push(n.to_string());
                    v.clone()
                }
                None => {
                    return Err(format!(
                        "unknown variable `${{{n}}}`; known: [{}] and inputs.*, outputs.*, stage, instance",
                        ctx.values.keys().map(|k| k.as_str()).collect::<Vec<_>>().join(", ")
                    ))
                }
            },
        };
        out.push_str(&val);
        rest = &body[end + 1..];
    }
    out.push_str(rest);
    Ok((out, used))
}

/// Check and convert one table of Slurm resources (`key` is where it sits in the file).
fn resources(
    r: RawResources,
    key: &str,
    err: &dyn Fn(String, usize, &str) -> WeftError,
    line_of: &dyn Fn(&str, usize) -> usize,
) -> Result<Resources> {
    let l = |sp: std::ops::Range<usize>| line_of("", sp.start);
    let word = |v: Option<Spanned<String>>, name: &str| -> Result<Option<String>> {
        match v {
            Some(s) if s.get_ref().is_empty() || s.get_ref().contains(char::is_whitespace) => {
                Err(err(
                    format!("`{name}` is {:?}", s.get_ref()),
                    l(s.span()),
                    &format!("{key}.{name}"),
                )
                .expected("a Slurm name without spaces"))
            }
            v => Ok(v.map(|s| s.into_inner())),
        }
    };
    let partition = word(r.partition, "partition")?;
    let account = word(r.account, "account")?;
    let time = match r.time {
        Some(t) if !is_slurm_time(t.get_ref()) => {
            return Err(err(
                format!("`time` is {:?}", t.get_ref()),
                l(t.span()),
                &format!("{key}.time"),
            )
            .expected("a Slurm time limit: MM, HH:MM:SS, D-HH:MM:SS, ...")
            .hint("e.g. time = \"02:00:00\" for two hours"))
        }
        t => t.map(|t| t.into_inner()),
    };
    let memory = match r.memory {
        Some(m) if !is_slurm_memory(m.get_ref()) => {
            return Err(err(
                format!("`memory` is {:?}", m.get_ref()),
                l(m.span()),
                &format!("{key}.memory"),
            )
            .expected("a size for `sbatch --mem`: MB, or with a K, M, G or T suffix")
            .hint("e.g. memory = \"4G\""))
        }
        m => m.map(|m| m.into_inner()),
    };
    let cpus = match r.cpus {
        Some(c) if !(1..=1_000_000).contains(c.get_ref()) => {
            return Err(err(
                format!("`cpus` is {}", c.get_ref()),
                l(c.span()),
                &format!("{key}.cpus"),
            )
            .expected("a whole number of CPUs per job, at least 1"))
        }
        c => c.map(|c| *c.get_ref() as u32),
    };
    let sbatch_args = match r.sbatch_args {
        None => vec![],
        Some(a) => {
            let line = l(a.span());
            let a = a.into_inner();
            for x in &a {
                let opt = x.split('=').next().unwrap_or("");
                if !x.starts_with('-') {
                    return Err(err(
                        format!("`sbatch_args` holds {x:?}"),
                        line,
                        &format!("{key}.sbatch_args"),
                    )
                    .expected("sbatch options, each starting with `-`, e.g. \"--qos=low\""));
                }
                if OWN_SBATCH_OPTS.contains(&opt) {
                    return Err(err(
                        format!("`sbatch_args` sets `{opt}`, which weft sets itself"),
                        line,
                        &format!("{key}.sbatch_args"),
                    )
                    .hint("weft chooses the job name, comment, array, dependencies, output file and working folder; leave them out"));
                }
            }
            a
        }
    };
    Ok(Resources {
        partition,
        account,
        time,
        memory,
        cpus,
        sbatch_args,
    })
}

/// Lexically normalise a relative path; `None` when it climbs above its start.
fn normalise(p: &Path) -> Option<PathBuf> {
    let mut out = PathBuf::new();
    for c in p.components() {
        match c {
            Component::CurDir => {}
            Component::ParentDir => {
                if !out.pop() {
                    return None;
                }
            }
            Component::Normal(s) => out.push(s),
            _ => return None,
        }
    }
    Some(out)
}

/// Is `a` equal to or inside `b` (both normalised)?
pub fn within(a: &Path, b: &Path) -> bool {
    a.starts_with(b)
}

/// Make an instance name safe as a file name.
pub fn file_name_of(instance: &str) -> String {
    instance
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || "._=,@-+".contains(c) {
                c
            } else {
                '_'
            }
        })
        .collect()
}

impl Pipeline {
    /// Parse and validate a pipeline file.
    pub fn load(file: &Path) -> Result<Pipeline> {
        let src = std::fs::read_to_string(file).map_err(|e| WeftError::io(file, e))?;
        Self::parse(file, &src)
    }

    pub fn parse(file: &Path, src: &str) -> Result<Pipeline> {
        let err = |what: String, line: usize, key: &str| {
            WeftError::input(what)
                .in_file(file)
                .at_line(line)
                .at_key(key.to_string())
        };
        let lines = Lines::new(src);
        let line_of = |_src: &str, offset: usize| lines.of(offset);
        let raw: RawFile = toml::from_str(src).map_err(|e| {
            let line = e.span().map(|s| line_of(src, s.start)).unwrap_or(0);
            let msg = e.message().to_string();
            let hint = if msg.contains("unknown field") {
                "a pipeline file has [pipeline], [vars], [stages.NAME] and [executor] tables; a stage has cmd, inputs, outputs, params, matrix, foreach, desc; [executor] has partition, account, time, memory, cpus, sbatch_args, poll_seconds and [executor.stages.NAME]"
            } else if msg.contains("did not match any variant") {
                "inputs and outputs are a list of paths or a table of named paths"
            } else {
                "see the pipeline file format in src/pipeline/spec.rs or the README"
            };
            WeftError::input(format!("invalid pipeline file: {msg}"))
                .in_file(file)
                .at_line(line)
                .hint(hint)
        })?;
        let dir = file
            .parent()
            .filter(|p| !p.as_os_str().is_empty())
            .unwrap_or(Path::new("."));
        let root = match raw.pipeline.as_ref().and_then(|m| m.root.clone()) {
            Some(r) => dir.join(r),
            None if dir.file_name().is_some_and(|n| n == "pipelines") => dir
                .parent()
                .filter(|p| !p.as_os_str().is_empty())
                .unwrap_or(Path::new("."))
                .to_path_buf(),
            None => dir.to_path_buf(),
        };
        if raw.stages.is_empty() {
            return Err(WeftError::input("the pipeline has no stages")
                .in_file(file)
                .expected("at least one [stages.NAME] table with a `cmd`"));
        }

        // Vars: scalars, may refer to earlier-resolved vars.
        let mut vars: BTreeMap<String, String> = BTreeMap::new();
        let mut pending: Vec<(String, String, usize)> = Vec::new();
        for (k, v) in &raw.vars {
            let line = line_of(src, v.span().start);
            let s = value_str(v.get_ref()).ok_or_else(|| {
                err(
                    format!("var `{k}` is not a string, number or boolean"),
                    line,
                    &format!("vars.{k}"),
                )
                .expected("a scalar value")
            })?;
            pending.push((k.clone(), s, line));
        }
        for _round in 0..=pending.len() {
            let mut next = Vec::new();
            for (k, s, line) in pending.drain(..) {
                let empty: Vec<(String, String)> = vec![];
                let ctx = Ctx {
                    values: &vars,
                    inputs: &empty,
                    outputs: &empty,
                    stage: "",
                    instance: "",
                };
                match render(&s, &ctx) {
                    Ok((r, _)) => {
                        vars.insert(k, r);
                    }
                    Err(_) => next.push((k, s, line)),
                }
            }
            pending = next;
            if pending.is_empty() {
                break;
            }
        }
        if let Some((k, s, line)) = pending.first() {
            let names: Vec<String> = pending.iter().map(|(n, _, _)| format!("`{n}`")).collect();
            let refers_pending = pending
                .iter()
                .any(|(n, _, _)| s.contains(&format!("${{{n}}}")));
            let what = if refers_pending {
                format!("vars {} refer to each other in a cycle", names.join(", "))
            } else {
                let empty: Vec<(String, String)> = vec![];
                let ctx = Ctx {
                    values: &vars,
                    inputs: &empty,
                    outputs: &empty,
                    stage: "",
                    instance: "",
                };
                format!("var `{k}`: {}", render(s, &ctx).err().unwrap_or_default())
            };
            return Err(err(what, *line, &format!("vars.{k}"))
                .hint("vars may refer to other vars, without cycles"));
        }

        // Stages in file order.
        let mut stages: Vec<(&String, &Spanned<RawStage>)> = raw.stages.iter().collect();
        stages.sort_by_key(|(_, s)| s.span().start);
        let mut instances: Vec<Instance> = Vec::new();
        for (name, st) in stages {
            let line = line_of(src, st.span().start);
            let key = format!("stages.{name}");
            if !name
                .chars()
                .all(|c| c.is_ascii_alphanumeric() || "_-".contains(c))
            {
                return Err(err(format!("stage name `{name}` has characters other than letters, digits, `_` and `-`"), line, &key));
            }
            let st = st.get_ref();
            // Sweep points: each a map of values.
            let mut points: Vec<Vec<(String, String)>> = vec![vec![]];
            if let (Some(_), Some(f)) = (&st.matrix, &st.foreach) {
                return Err(err(
                    "a stage has both `matrix` and `foreach`".into(),
                    line_of(src, f.span().start),
                    &key,
                )
                .expected("one of them"));
            }
            if let Some(mx) = &st.matrix {
                let ml = line_of(src, mx.span().start);
                for (k, vals) in mx.get_ref() {
                    if vals.is_empty() {
                        return Err(err(
                            format!("matrix entry `{k}` is an empty list"),
                            ml,
                            &format!("{key}.matrix.{k}"),
                        )
                        .expected("at least one value"));
                    }
                    let mut next = Vec::new();
                    for p in &points {
                        for v in vals {
                            let s = value_str(v).ok_or_else(|| {
                                err(
                                    format!("matrix value of `{k}` is not a scalar"),
                                    ml,
                                    &format!("{key}.matrix.{k}"),
                                )
                            })?;
                            let mut q = p.clone();
                            q.push((k.clone(), s));
                            next.push(q);
                        }
                    }
                    points = next;
                }
            }
            if let Some(fe) = &st.foreach {
                let fl = line_of(src, fe.span().start);
                if fe.get_ref().is_empty() {
                    return Err(err(
                        "`foreach` is an empty list".into(),
                        fl,
                        &format!("{key}.foreach"),
                    )
                    .expected("at least one item"));
                }
                points = Vec::new();
                for (i, item) in fe.get_ref().iter().enumerate() {
                    let mut q = Vec::new();
                    for (k, v) in item {
                        let s = value_str(v).ok_or_else(|| {
                            err(
                                format!("foreach item {i}: `{k}` is not a scalar"),
                                fl,
                                &format!("{key}.foreach"),
                            )
                        })?;
                        q.push((k.clone(), s));
                    }
                    points.push(q);
                }
            }
            let mut params: BTreeMap<String, String> = BTreeMap::new();
            for (k, v) in &st.params {
                let s = value_str(v.get_ref()).ok_or_else(|| {
                    err(
                        format!("param `{k}` is not a scalar"),
                        line_of(src, v.span().start),
                        &format!("{key}.params.{k}"),
                    )
                })?;
                params.insert(k.clone(), s);
            }
            let cmd_line = line_of(src, st.cmd.span().start);
            if st.cmd.get_ref().trim().is_empty() {
                return Err(err("empty `cmd`".into(), cmd_line, &format!("{key}.cmd"))
                    .expected("a command line"));
            }
            for p in &points {
                let mut values = vars.clone();
                for (k, v) in &params {
                    values.insert(k.clone(), v.clone());
                }
                for (k, v) in p {
                    if params.contains_key(k) {
                        return Err(err(
                            format!("`{k}` is both a param and a sweep value"),
                            line,
                            &key,
                        ));
                    }
                    values.insert(k.clone(), v.clone());
                }
                let iname = if p.is_empty() {
                    name.clone()
                } else {
                    format!(
                        "{name}@{}",
                        p.iter()
                            .map(|(k, v)| format!("{k}={v}"))
                            .collect::<Vec<_>>()
                            .join(",")
                    )
                };
                let mut used: Vec<String> = params
                    .keys()
                    .cloned()
                    .chain(p.iter().map(|(k, _)| k.clone()))
                    .collect();
                let empty: Vec<(String, String)> = vec![];
                let mut resolve = |which: &str,
                                   ps: &Option<Spanned<Paths>>|
                 -> Result<Vec<(String, PathBuf)>> {
                    let Some(ps) = ps else { return Ok(vec![]) };
                    let pl = line_of(src, ps.span().start);
                    let mut v = Vec::new();
                    for (k, raw_p) in ps.get_ref().named() {
                        let ctx = Ctx {
                            values: &values,
                            inputs: &empty,
                            outputs: &empty,
                            stage: name,
                            instance: &iname,
                        };
                        let (s, u) = render(&raw_p, &ctx)
                            .map_err(|e| err(e, pl, &format!("{key}.{which}.{k}")))?;
                        used.extend(u);
                        let path = PathBuf::from(&s);
                        let norm = if path.is_absolute() {
                            None
                        } else {
                            normalise(&path)
                        };
                        let norm = match (which, norm) {
                            (_, Some(n)) if !n.as_os_str().is_empty() => n,
                            ("outputs", _) => {
                                return Err(err(format!("output `{s}` lies outside the project root `{}`", root.display()), pl, &format!("{key}.outputs.{k}"))
                                    .expected("a relative path inside the project")
                                    .hint("outputs are written under the project root; copy results elsewhere in a later stage if needed"))
                            }
                            (_, _) => path,
                        };
                        v.push((k, norm));
                    }
                    Ok(v)
                };
                let inputs = resolve("inputs", &st.inputs)?;
                let outputs = resolve("outputs", &st.outputs)?;
                let as_str = |v: &[(String, PathBuf)]| -> Vec<(String, String)> {
                    v.iter()
                        .map(|(k, p)| (k.clone(), p.display().to_string()))
                        .collect()
                };
                let (ins, outs) = (as_str(&inputs), as_str(&outputs));
                let ctx = Ctx {
                    values: &values,
                    inputs: &ins,
                    outputs: &outs,
                    stage: name,
                    instance: &iname,
                };
                let (command, u) = render(st.cmd.get_ref(), &ctx)
                    .map_err(|e| err(e, cmd_line, &format!("{key}.cmd")))?;
                used.extend(u);
                for (k, _) in &outputs {
                    let tmpl = st.cmd.get_ref();
                    if !tmpl.contains(&format!("${{outputs.{k}}}")) && !tmpl.contains("${outputs}")
                    {
                        return Err(err(format!("output `{k}` is not passed to the command"), cmd_line, &format!("{key}.cmd"))
                            .expected(format!("`${{outputs.{k}}}` in the command"))
                            .hint("the engine gives the command a temporary path and moves it into place on success; a command writing its output elsewhere cannot be made atomic"));
                    }
                }
                let used_params: BTreeMap<String, String> = used
                    .iter()
                    .filter_map(|k| values.get(k).map(|v| (k.clone(), v.clone())))
                    .collect();
                let own: BTreeMap<String, String> = params
                    .iter()
                    .map(|(k, v)| (k.clone(), v.clone()))
                    .chain(p.iter().cloned())
                    .collect();
                instances.push(Instance {
                    own,
                    name: iname,
                    stage: name.clone(),
                    cmd_template: st.cmd.get_ref().clone(),
                    command,
                    params: used_params,
                    values,
                    inputs,
                    outputs,
                    line,
                    deps: vec![],
                });
            }
        }
        let mut seen = HashMap::new();
        for (i, inst) in instances.iter().enumerate() {
            if let Some(j) = seen.insert(inst.name.clone(), i) {
                return Err(err(
                    format!("two instances are named `{}`", inst.name),
                    inst.line,
                    &format!("stages.{}", instances[j].stage),
                )
                .hint("sweep values must differ"));
            }
        }
        let executor = match raw.executor {
            None => ExecutorSpec::default(),
            Some(e) => {
                let e = e.into_inner();
                let mut spec = ExecutorSpec {
                    default: resources(
                        RawResources {
                            partition: e.partition,
                            account: e.account,
                            time: e.time,
                            memory: e.memory,
                            cpus: e.cpus,
                            sbatch_args: e.sbatch_args,
                        },
                        "executor",
                        &err,
                        &line_of,
                    )?,
                    ..ExecutorSpec::default()
                };
                if let Some(ps) = e.poll_seconds {
                    let v = *ps.get_ref();
                    if !(0.05..=600.0).contains(&v) {
                        return Err(err(
                            format!("`poll_seconds` is {v}"),
                            line_of(src, ps.span().start),
                            "executor.poll_seconds",
                        )
                        .expected("seconds between 0.05 and 600"));
                    }
                    spec.poll_seconds = v;
                }
                for (name, r) in e.stages {
                    let line = line_of(src, r.span().start);
                    if !instances.iter().any(|i| i.stage == name) {
                        let mut names: Vec<&str> =
                            instances.iter().map(|i| i.stage.as_str()).collect();
                        names.dedup();
                        return Err(err(
                            format!("`[executor.stages.{name}]` names no stage"),
                            line,
                            &format!("executor.stages.{name}"),
                        )
                        .expected(format!("one of [{}]", names.join(", "))));
                    }
                    let key = format!("executor.stages.{name}");
                    spec.stages
                        .insert(name, resources(r.into_inner(), &key, &err, &line_of)?);
                }
                spec
            }
        };
        let mut p = Pipeline {
            file: file.to_path_buf(),
            root,
            instances,
            order: vec![],
            executor,
        };
        p.link(src)?;
        Ok(p)
    }

    /// Infer dependencies from paths, refuse overlapping outputs, missing inputs and cycles.
    fn link(&mut self, _src: &str) -> Result<()> {
        let file = self.file.clone();
        let err = |what: String, line: usize, key: String| {
            WeftError::input(what)
                .in_file(&file)
                .at_line(line)
                .at_key(key)
        };
        // Outputs: unique, not nested in one another.
        let mut outs: Vec<(PathBuf, usize, String)> = Vec::new();
        for (i, inst) in self.instances.iter().enumerate() {
            for (k, p) in &inst.outputs {
                outs.push((p.clone(), i, k.clone()));
            }
        }
        outs.sort();
        for w in outs.windows(2) {
            let (a, b) = (&w[0], &w[1]);
            if within(&b.0, &a.0) {
                let (ia, ib) = (&self.instances[a.1], &self.instances[b.1]);
                let what = if a.0 == b.0 {
                    format!(
                        "`{}` and `{}` both write `{}`",
                        ia.name,
                        ib.name,
                        a.0.display()
                    )
                } else {
                    format!(
                        "output `{}` of `{}` lies inside output `{}` of `{}`",
                        b.0.display(),
                        ib.name,
                        a.0.display(),
                        ia.name
                    )
                };
                return Err(err(what, ib.line, format!("stages.{}.outputs.{}", ib.stage, b.2))
                    .expected("each path written by one stage instance only")
                    .hint("give each sweep instance its own output path, e.g. with ${name} of a sweep value"));
            }
        }
        let n = self.instances.len();
        // Outputs by path. PathBuf orders component by component, so everything inside a
        // folder follows it contiguously: one range scan finds outputs inside an input,
        // and an exact lookup of each ancestor finds outputs that contain it.
        let out_map: BTreeMap<PathBuf, usize> =
            outs.iter().map(|(p, j, _)| (p.clone(), *j)).collect();
        for i in 0..n {
            let mut deps = Vec::new();
            for (k, inp) in self.instances[i].inputs.clone() {
                let mut found: Vec<usize> = inp
                    .ancestors()
                    .filter_map(|a| out_map.get(a).copied())
                    .collect();
                found.extend(
                    out_map
                        .range(inp.clone()..)
                        .take_while(|(op, _)| op.starts_with(&inp))
                        .map(|(_, j)| *j),
                );
                if found.contains(&i) {
                    return Err(err(
                        format!(
                            "`{}` reads its own output `{}`",
                            self.instances[i].name,
                            inp.display()
                        ),
                        self.instances[i].line,
                        format!("stages.{}.inputs.{k}", self.instances[i].stage),
                    ));
                }
                let produced = !found.is_empty();
                deps.extend(found);
                if !produced && !self.root.join(&inp).exists() {
                    let inst = &self.instances[i];
                    return Err(err(
                        format!(
                            "input `{}` of `{}` is produced by no stage and does not exist",
                            inp.display(),
                            inst.name
                        ),
                        inst.line,
                        format!("stages.{}.inputs.{k}", inst.stage),
                    )
                    .expected(format!(
                        "a file or folder under `{}`, or the output of a stage",
                        self.root.display()
                    ))
                    .hint("check the path, or add the stage that writes it"));
                }
            }
            deps.sort_unstable();
            deps.dedup();
            self.instances[i].deps = deps;
        }
        // Topological order (Kahn), stable in file order.
        let mut indeg = vec![0usize; n];
        let mut down: Vec<Vec<usize>> = vec![vec![]; n];
        for i in 0..n {
            for &d in &self.instances[i].deps {
                indeg[i] += 1;
                down[d].push(i);
            }
        }
        let mut ready: std::collections::BTreeSet<usize> =
            (0..n).filter(|&i| indeg[i] == 0).collect();
        let mut order = Vec::with_capacity(n);
        while let Some(i) = ready.pop_first() {
            order.push(i);
            for &j in &down[i] {
                indeg[j] -= 1;
                if indeg[j] == 0 {
                    ready.insert(j);
                }
            }
        }
        if order.len() < n {
            // Walk back along deps from a node left over to name the cycle.
            let start = (0..n).find(|&i| indeg[i] > 0).expect("a node in a cycle");
            let mut path = vec![start];
            let mut cur = start;
            loop {
                let next = *self.instances[cur]
                    .deps
                    .iter()
                    .find(|&&d| indeg[d] > 0)
                    .expect("cycle continues");
                if let Some(pos) = path.iter().position(|&p| p == next) {
                    let cyc: Vec<String> = path[pos..]
                        .iter()
                        .rev()
                        .map(|&i| format!("`{}`", self.instances[i].name))
                        .collect();
                    let inst = &self.instances[next];
                    return Err(err(
                        format!(
                            "the stages form a cycle: {} -> {}",
                            cyc.join(" -> "),
                            cyc[0]
                        ),
                        inst.line,
                        format!("stages.{}.inputs", inst.stage),
                    )
                    .hint(
                        "a stage cannot depend, directly or through others, on its own outputs",
                    ));
                }
                path.push(next);
                cur = next;
            }
        }
        self.order = order;
        Ok(())
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
