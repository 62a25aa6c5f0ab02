//! What `weft status`, `weft dag` and `weft records` print, as text.

use std::collections::BTreeMap;
use std::fmt::Write;

use super::record::RecordStore;
use super::spec::Pipeline;
use super::workspace::Verdict;

/// `weft status`: one line per instance, in order.
pub struct Status {
    /// `fresh  NAME` or `stale  NAME: REASON`, with its live Slurm job if any.
    pub text: String,
    /// How many instances would run.
    pub stale: usize,
}

/// The status of every instance from the `plan` of all of them; `jobs`: the live Slurm
/// jobs of an earlier run by instance, (job, state).
pub fn status(p: &Pipeline, plan: &[Verdict], jobs: &BTreeMap<String, (String, String)>) -> Status {
    let mut text = String::new();
    let mut stale = 0;
    for &i in &p.order {
        let name = &p.instances[i].name;
        let job = jobs
            .get(name)
            .map(|(j, s)| format!(" (Slurm job {j} {s})"))
            .unwrap_or_default();
        let _ = match &plan[i] {
            Verdict::Fresh => writeln!(text, "fresh  {name}{job}"),
            Verdict::Stale(r) | Verdict::Waiting(r) => {
                stale += 1;
                writeln!(text, "stale  {name}: {r}{job}")
            }
        };
    }
    Status { text, stale }
}

/// A node's id in the graph formats.
fn id(i: usize) -> String {
    format!("n{i}")
}

/// `weft dag`: each instance in order, with the instances it needs.
pub fn dag_text(p: &Pipeline) -> String {
    let mut s = String::new();
    for &i in &p.order {
        let inst = &p.instances[i];
        let deps: Vec<&str> = inst
            .deps
            .iter()
            .map(|&d| p.instances[d].name.as_str())
            .collect();
        let _ = if deps.is_empty() {
            writeln!(s, "{}", inst.name)
        } else {
            writeln!(s, "{} <- {}", inst.name, deps.join(", "))
        };
    }
    s
}

/// `weft dag --format dot`: the graph for Graphviz.
pub fn dag_dot(p: &Pipeline) -> String {
    let mut s = String::from("digraph weft {\n  rankdir=LR;\n  node [shape=box];\n");
    for (i, inst) in p.instances.iter().enumerate() {
        let _ = writeln!(
            s,
            "  {} [label=\"{}\"];",
            id(i),
            inst.name.replace('"', "\\\"")
        );
    }
    for (i, inst) in p.instances.iter().enumerate() {
        for &d in &inst.deps {
            let _ = writeln!(s, "  {} -> {};", id(d), id(i));
        }
    }
    s.push_str("}\n");
    s
}

/// `weft dag --format mermaid`: the graph for Mermaid.
pub fn dag_mermaid(p: &Pipeline) -> String {
    let mut s = String::from("graph LR\n");
    for (i, inst) in p.instances.iter().enumerate() {
        let _ = writeln!(s, "  {}[\"{}\"]", id(i), inst.name.replace('"', "'"));
    }
    for (i, inst) in p.instances.iter().enumerate() {
        for &d in &inst.deps {
            let _ = writeln!(s, "  {} --> {}", id(d), id(i));
        }
    }
    s
}

/// `weft records`: the record of each instance that has one, a tab-separated line each
/// under a header.
pub fn records_text(p: &Pipeline) -> String {
    let store = RecordStore::new(&p.root, &p.file);
    let mut s = String::from("instance\texit_status\tstart\tduration_s\tcommand\n");
    for inst in &p.instances {
        if let Some(r) = store.get(&inst.name) {
            let _ = writeln!(
                s,
                "{}\t{}\t{}\t{:.3}\t{}",
                r.instance,
                r.exit_status,
                r.start,
                r.end_unix - r.start_unix,
                r.command
            );
        }
    }
    s
}
