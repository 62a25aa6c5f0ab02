//! The instances of the stages: a stage's params, then one instance per sweep point,
//! each with its input and output paths resolved against the project root and its
//! command rendered.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use toml::Spanned;

use super::paths::normalise;
use super::raw::{value_str, Paths, RawStage, Source};
use super::resolved::Instance;
use super::sweep::{self, Point};
use super::template::{render, Ctx};
use crate::error::Result;

/// The instances of every stage, stages in file order.
pub(super) fn instances(
    stages: &BTreeMap<String, Spanned<RawStage>>,
    vars: &BTreeMap<String, String>,
    root: &Path,
    at: &Source,
) -> Result<Vec<Instance>> {
    let mut stages: Vec<(&String, &Spanned<RawStage>)> = stages.iter().collect();
    stages.sort_by_key(|(_, s)| s.span().start);
    let mut instances: Vec<Instance> = Vec::new();
    for (name, st) in stages {
        let line = at.line(st.span().start);
        let key = format!("stages.{name}");
        check_name(name, line, &key, at)?;
        let points = sweep::points(st.get_ref(), &key, at)?;
        let stage = Stage::new(name, key, line, st.get_ref(), at)?;
        for p in &points {
            instances.push(stage.instance(p, vars, root, at)?);
        }
    }
    Ok(instances)
}

/// Stage names are letters, digits, `_` and `-`.
fn check_name(name: &str, line: usize, key: &str, at: &Source) -> Result<()> {
    if !name
        .chars()
        .all(|c| c.is_ascii_alphanumeric() || "_-".contains(c))
    {
        return Err(at.err(
            format!("stage name `{name}` has characters other than letters, digits, `_` and `-`"),
            line,
            key,
        ));
    }
    Ok(())
}

/// What every instance of one stage shares.
struct Stage<'a> {
    name: &'a str,
    /// `stages.NAME`.
    key: String,
    /// Line of the stage in the pipeline file.
    line: usize,
    /// Line of its `cmd`.
    cmd_line: usize,
    raw: &'a RawStage,
    /// Its `params`, as text.
    params: BTreeMap<String, String>,
}

impl<'a> Stage<'a> {
    /// The stage's params, and its `cmd` checked not to be empty.
    fn new(
        name: &'a str,
        key: String,
        line: usize,
        raw: &'a RawStage,
        at: &Source,
    ) -> Result<Stage<'a>> {
        let mut params: BTreeMap<String, String> = BTreeMap::new();
        for (k, v) in &raw.params {
            let s = value_str(v.get_ref()).ok_or_else(|| {
                at.err(
                    format!("param `{k}` is not a scalar"),
                    at.line(v.span().start),
                    &format!("{key}.params.{k}"),
                )
            })?;
            params.insert(k.clone(), s);
        }
        let cmd_line = at.line(raw.cmd.span().start);
        if raw.cmd.get_ref().trim().is_empty() {
            return Err(at
                .err("empty `cmd`".into(), cmd_line, &format!("{key}.cmd"))
                .expected("a command line"));
        }
        Ok(Stage {
            name,
            key,
            line,
            cmd_line,
            raw,
            params,
        })
    }

    /// The instance of sweep point `p`.
    fn instance(
        &self,
        p: &Point,
        vars: &BTreeMap<String, String>,
        root: &Path,
        at: &Source,
    ) -> Result<Instance> {
        let mut draft = Draft {
            stage: self,
            values: self.values(p, vars, at)?,
            name: instance_name(self.name, p),
            used: self
                .params
                .keys()
                .cloned()
                .chain(p.iter().map(|(k, _)| k.clone()))
                .collect(),
        };
        let inputs = draft.paths("inputs", &self.raw.inputs, root, at)?;
        let outputs = draft.paths("outputs", &self.raw.outputs, root, at)?;
        let command = draft.command(&inputs, &outputs, at)?;
        let Draft {
            values, name, used, ..
        } = draft;
        let used_params: BTreeMap<String, String> = used
            .iter()
            .filter_map(|k| values.get(k).map(|v| (k.clone(), v.clone())))
            .collect();
        let own: BTreeMap<String, String> = self
            .params
            .iter()
            .map(|(k, v)| (k.clone(), v.clone()))
            .chain(p.iter().cloned())
            .collect();
        Ok(Instance {
            own,
            name,
            stage: self.name.to_string(),
            cmd_template: self.raw.cmd.get_ref().clone(),
            command,
            params: used_params,
            values,
            inputs,
            outputs,
            line: self.line,
            deps: vec![],
        })
    }

    /// The template values of point `p`: the vars, the stage's params, the point's
    /// values (which may not repeat a param).
    fn values(
        &self,
        p: &Point,
        vars: &BTreeMap<String, String>,
        at: &Source,
    ) -> Result<BTreeMap<String, String>> {
        let mut values = vars.clone();
        for (k, v) in &self.params {
            values.insert(k.clone(), v.clone());
        }
        for (k, v) in p {
            if self.params.contains_key(k) {
                return Err(at.err(
                    format!("`{k}` is both a param and a sweep value"),
                    self.line,
                    &self.key,
                ));
            }
            values.insert(k.clone(), v.clone());
        }
        Ok(values)
    }
}

/// `stage`, or `stage@k=v,k=v` for a sweep point.
fn instance_name(stage: &str, p: &Point) -> String {
    if p.is_empty() {
        stage.to_string()
    } else {
        format!(
            "{stage}@{}",
            p.iter()
                .map(|(k, v)| format!("{k}={v}"))
                .collect::<Vec<_>>()
                .join(",")
        )
    }
}

/// One instance being resolved: its template values, its name, and the names its
/// templates used so far (the params its record keeps).
struct Draft<'a> {
    stage: &'a Stage<'a>,
    values: BTreeMap<String, String>,
    name: String,
    used: Vec<String>,
}

impl Draft<'_> {
    /// The instance's `inputs` or `outputs` (`which`): rendered, normalised relative to
    /// the project root; an output must lie inside it.
    fn paths(
        &mut self,
        which: &str,
        ps: &Option<Spanned<Paths>>,
        root: &Path,
        at: &Source,
    ) -> Result<Vec<(String, PathBuf)>> {
        let Some(ps) = ps else { return Ok(vec![]) };
        let key = &self.stage.key;
        let pl = at.line(ps.span().start);
        let mut v = Vec::new();
        for (k, raw_p) in ps.get_ref().named() {
            let ctx = Ctx {
                values: &self.values,
                inputs: &[],
                outputs: &[],
                stage: self.stage.name,
                instance: &self.name,
            };
            let (s, u) =
                render(&raw_p, &ctx).map_err(|e| at.err(e, pl, &format!("{key}.{which}.{k}")))?;
            self.used.extend(u);
            let path = PathBuf::from(&s);
            let norm = if path.is_absolute() {
                None
            } else {
                normalise(&path)
            };
            let norm = match (which, norm) {
                (_, Some(n)) if !n.as_os_str().is_empty() => n,
                ("outputs", _) => {
                    return Err(at.err(format!("output `{s}` lies outside the project root `{}`", root.display()), pl, &format!("{key}.outputs.{k}"))
                        .expected("a relative path inside the project")
                        .hint("outputs are written under the project root; copy results elsewhere in a later stage if needed"))
                }
                (_, _) => path,
            };
            v.push((k, norm));
        }
        Ok(v)
    }

    /// The command with the final paths; every output must be passed to it.
    fn command(
        &mut self,
        inputs: &[(String, PathBuf)],
        outputs: &[(String, PathBuf)],
        at: &Source,
    ) -> Result<String> {
        let (key, cmd_line) = (&self.stage.key, self.stage.cmd_line);
        let as_str = |v: &[(String, PathBuf)]| -> Vec<(String, String)> {
            v.iter()
                .map(|(k, p)| (k.clone(), p.display().to_string()))
                .collect()
        };
        let (ins, outs) = (as_str(inputs), as_str(outputs));
        let ctx = Ctx {
            values: &self.values,
            inputs: &ins,
            outputs: &outs,
            stage: self.stage.name,
            instance: &self.name,
        };
        let tmpl = self.stage.raw.cmd.get_ref();
        let (command, u) =
            render(tmpl, &ctx).map_err(|e| at.err(e, cmd_line, &format!("{key}.cmd")))?;
        self.used.extend(u);
        for (k, _) in outputs {
            if !tmpl.contains(&format!("${{outputs.{k}}}")) && !tmpl.contains("${outputs}") {
                return Err(at.err(format!("output `{k}` is not passed to the command"), cmd_line, &format!("{key}.cmd"))
                    .expected(format!("`${{outputs.{k}}}` in the command"))
                    .hint("the engine gives the command a temporary path and moves it into place on success; a command writing its output elsewhere cannot be made atomic"));
            }
        }
        Ok(command)
    }
}
