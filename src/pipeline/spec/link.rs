//! The stage graph: dependencies inferred from paths (an instance reading what another
//! writes, or something inside or around it, depends on it), overlapping outputs, missing
//! inputs and cycles refused, and a topological order.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use super::paths::within;
use super::resolved::{Instance, Pipeline};
use crate::error::{Result, WeftError};

/// One output of one instance.
#[derive(Debug, Clone, PartialEq, Eq, PartialOrd, Ord)]
struct Output {
    path: PathBuf,
    /// Index of the instance that writes it.
    instance: usize,
    /// Its name among the instance's outputs.
    key: String,
}

/// An input error in the pipeline file, at `line` and `key`.
fn err(file: &Path, what: String, line: usize, key: String) -> WeftError {
    WeftError::input(what)
        .in_file(file)
        .at_line(line)
        .at_key(key)
}

impl Pipeline {
    /// Infer dependencies from paths, refuse overlapping outputs, missing inputs and cycles.
    pub(super) fn link(&mut self) -> Result<()> {
        let outs = disjoint_outputs(&self.file, &self.instances)?;
        // Outputs by path. PathBuf orders component by component, so everything inside a
        // folder follows it contiguously: one range scan finds outputs inside an input,
        // and an exact lookup of each ancestor finds outputs that contain it.
        let out_map: BTreeMap<PathBuf, usize> =
            outs.iter().map(|o| (o.path.clone(), o.instance)).collect();
        for i in 0..self.instances.len() {
            let deps = dependencies(self, i, &out_map)?;
            self.instances[i].deps = deps;
        }
        self.order = topological_order(&self.file, &self.instances)?;
        Ok(())
    }
}

/// Every output, sorted by path; refused when two are the same or one lies inside another.
fn disjoint_outputs(file: &Path, instances: &[Instance]) -> Result<Vec<Output>> {
    let mut outs: Vec<Output> = Vec::new();
    for (i, inst) in instances.iter().enumerate() {
        for (k, p) in &inst.outputs {
            outs.push(Output {
                path: p.clone(),
                instance: i,
                key: k.clone(),
            });
        }
    }
    outs.sort();
    for w in outs.windows(2) {
        let (a, b) = (&w[0], &w[1]);
        if within(&b.path, &a.path) {
            let (ia, ib) = (&instances[a.instance], &instances[b.instance]);
            let what = if a.path == b.path {
                format!(
                    "`{}` and `{}` both write `{}`",
                    ia.name,
                    ib.name,
                    a.path.display()
                )
            } else {
                format!(
                    "output `{}` of `{}` lies inside output `{}` of `{}`",
                    b.path.display(),
                    ib.name,
                    a.path.display(),
                    ia.name
                )
            };
            return Err(err(
                file,
                what,
                ib.line,
                format!("stages.{}.outputs.{}", ib.stage, b.key),
            )
            .expected("each path written by one stage instance only")
            .hint(
                "give each sweep instance its own output path, e.g. with ${name} of a sweep value",
            ));
        }
    }
    Ok(outs)
}

/// The upstream instances of instance `i` (sorted, once each): those writing one of its
/// inputs, a folder around it or something inside it (`out_map`: the writer of each
/// output path). Refused when it reads its own
/// output, or an input that no stage writes does not exist.
fn dependencies(p: &Pipeline, i: usize, out_map: &BTreeMap<PathBuf, usize>) -> Result<Vec<usize>> {
    let inst = &p.instances[i];
    let mut deps = Vec::new();
    for (k, inp) in inst.inputs.clone() {
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
                &p.file,
                format!("`{}` reads its own output `{}`", inst.name, inp.display()),
                inst.line,
                format!("stages.{}.inputs.{k}", inst.stage),
            ));
        }
        let produced = !found.is_empty();
        deps.extend(found);
        if !produced && !p.root.join(&inp).exists() {
            return Err(err(
                &p.file,
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
                p.root.display()
            ))
            .hint("check the path, or add the stage that writes it"));
        }
    }
    deps.sort_unstable();
    deps.dedup();
    Ok(deps)
}

/// A topological order of the instances (Kahn's), stable in file order; refused with the
/// cycle named when there is one.
fn topological_order(file: &Path, instances: &[Instance]) -> Result<Vec<usize>> {
    let n = instances.len();
    let mut indeg = vec![0usize; n];
    let mut down: Vec<Vec<usize>> = vec![vec![]; n];
    for i in 0..n {
        for &d in &instances[i].deps {
            indeg[i] += 1;
            down[d].push(i);
        }
    }
    let mut ready: std::collections::BTreeSet<usize> = (0..n).filter(|&i| indeg[i] == 0).collect();
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
        return Err(cycle(file, instances, &indeg));
    }
    Ok(order)
}

/// The error naming a cycle among the instances Kahn's order left over (`indeg` > 0).
fn cycle(file: &Path, instances: &[Instance], indeg: &[usize]) -> WeftError {
    // Walk back along deps from a node left over to name the cycle.
    let n = instances.len();
    let start = (0..n).find(|&i| indeg[i] > 0).expect("a node in a cycle");
    let mut path = vec![start];
    let mut cur = start;
    loop {
        let next = *instances[cur]
            .deps
            .iter()
            .find(|&&d| indeg[d] > 0)
            .expect("cycle continues");
        if let Some(pos) = path.iter().position(|&p| p == next) {
            let cyc: Vec<String> = path[pos..]
                .iter()
                .rev()
                .map(|&i| format!("`{}`", instances[i].name))
                .collect();
            let inst = &instances[next];
            return err(
                file,
                format!(
                    "the stages form a cycle: {} -> {}",
                    cyc.join(" -> "),
                    cyc[0]
                ),
                inst.line,
                format!("stages.{}.inputs", inst.stage),
            )
            .hint("a stage cannot depend, directly or through others, on its own outputs");
        }
        path.push(next);
        cur = next;
    }
}
