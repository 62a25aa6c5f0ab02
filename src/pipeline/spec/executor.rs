//! `[executor]`: the Slurm resources of the jobs, checked and converted, with the
//! `[executor.stages.NAME]` overrides.

use toml::Spanned;

use super::raw::{RawExecutor, RawResources, Source};
use super::resolved::{ExecutorSpec, Instance, Resources};
use crate::error::Result;

/// The `[executor]` table resolved (defaults when absent); `[executor.stages.NAME]` must
/// name a stage of `instances`.
pub(super) fn read(
    raw: Option<Spanned<RawExecutor>>,
    instances: &[Instance],
    at: &Source,
) -> Result<ExecutorSpec> {
    let Some(e) = raw else {
        return Ok(ExecutorSpec::default());
    };
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
            at,
        )?,
        ..ExecutorSpec::default()
    };
    if let Some(ps) = e.poll_seconds {
        let v = *ps.get_ref();
        if !(0.05..=600.0).contains(&v) {
            return Err(at
                .err(
                    format!("`poll_seconds` is {v}"),
                    at.line(ps.span().start),
                    "executor.poll_seconds",
                )
                .expected("seconds between 0.05 and 600"));
        }
        spec.poll_seconds = v;
    }
    for (name, r) in e.stages {
        let line = at.line(r.span().start);
        if !instances.iter().any(|i| i.stage == name) {
            let mut names: Vec<&str> = instances.iter().map(|i| i.stage.as_str()).collect();
            names.dedup();
            return Err(at
                .err(
                    format!("`[executor.stages.{name}]` names no stage"),
                    line,
                    &format!("executor.stages.{name}"),
                )
                .expected(format!("one of [{}]", names.join(", "))));
        }
        let key = format!("executor.stages.{name}");
        spec.stages
            .insert(name, resources(r.into_inner(), &key, at)?);
    }
    Ok(spec)
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

/// Check and convert one table of Slurm resources (`key` is where it sits in the file).
fn resources(r: RawResources, key: &str, at: &Source) -> Result<Resources> {
    let err = |what: String, line: usize, key: &str| at.err(what, line, key);
    let l = |sp: std::ops::Range<usize>| at.line(sp.start);
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
