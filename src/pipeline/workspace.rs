//! Where the engine keeps its state for a pipeline (the records, logs and content-hash
//! cache under `.weft/`, the binaries stages start), and the verdict it judges with it.
//!
//! An instance reruns when it never ran or its last run failed, a param it uses or its
//! command changed, its binary changed, an input's content changed, or an output is
//! missing or was changed since the run. Before its upstream instances have run, an
//! instance downstream of a stale one is reported as waiting on it ([`Workspace::plan`]);
//! when the upstream has run, `super::engine` judges it again on the new content of its
//! inputs.

use std::path::{Path, PathBuf};

use super::hash::HashCache;
use super::record::RecordStore;
use super::spec::{Instance, Pipeline};
use crate::error::Result;

/// Why an instance must run, or that it need not.
#[derive(Debug, Clone, PartialEq)]
pub enum Verdict {
    Fresh,
    Stale(String),
    /// Stale because an upstream instance will run first.
    Waiting(String),
}

impl Verdict {
    pub fn is_fresh(&self) -> bool {
        matches!(self, Verdict::Fresh)
    }
}

/// Where the engine keeps its state for a pipeline.
pub struct Workspace {
    pub root: PathBuf,
    pub records: RecordStore,
    pub logs: PathBuf,
    pub cache: HashCache,
    /// Directory of the running `weft` binary: stage binaries are looked up there first.
    pub exe_dir: Option<PathBuf>,
    /// Resolved executables by command word.
    bin_memo: std::cell::RefCell<std::collections::HashMap<String, Option<PathBuf>>>,
}

impl Workspace {
    pub fn open(p: &Pipeline) -> Workspace {
        let dot = p.root.join(".weft");
        let _ = std::fs::create_dir_all(&dot);
        let gi = dot.join(".gitignore");
        if !gi.exists() {
            let _ = std::fs::write(
                &gi,
                "# records/ is meant to be committed; the rest is local\nlogs/\ncache/\njobs/\nlock\n",
            );
        } else if let Ok(s) = std::fs::read_to_string(&gi) {
            // Projects from before the Slurm executor: its job files are local too.
            if !s.lines().any(|l| l.trim() == "jobs/") {
                let _ = std::fs::write(
                    &gi,
                    format!(
                        "{}jobs/\n",
                        if s.ends_with('\n') || s.is_empty() {
                            s
                        } else {
                            s + "\n"
                        }
                    ),
                );
            }
        }
        let stem = p
            .file
            .file_stem()
            .map(|s| s.to_string_lossy().to_string())
            .unwrap_or_default();
        Workspace {
            root: p.root.clone(),
            records: RecordStore::new(&p.root, &p.file),
            logs: dot.join("logs").join(stem),
            cache: HashCache::load(&dot.join("cache").join("hashes.tsv")),
            exe_dir: std::env::current_exe()
                .ok()
                .and_then(|e| e.parent().map(Path::to_path_buf)),
            bin_memo: Default::default(),
        }
    }

    /// The program a stage is judged by, as the command names it: the first weft tool at
    /// a command's position (the start, or after `&&`, `||`, `;` or `|`; an executable
    /// beside `weft`: `mkdir -p D && weft-plot …` is weft-plot's), else the word the
    /// command starts with.
    pub fn program_of(&self, command: &str) -> Option<String> {
        let word = |w: &str| w.trim_matches(|c| c == '\'' || c == '"').to_string();
        let mut programs = vec![];
        let mut at_command = true;
        for w in command.split_whitespace() {
            match w {
                "&&" | "||" | ";" | "|" => at_command = true,
                "\\" => {}
                _ if at_command && w.contains('=') && !w.starts_with('-') => {} // VAR=value
                _ => {
                    if at_command {
                        programs.push(word(w.trim_end_matches(';')));
                    }
                    at_command = w.ends_with(';');
                }
            }
        }
        let tool = self.exe_dir.as_ref().and_then(|d| {
            programs
                .iter()
                .find(|w| !w.is_empty() && !w.contains(['/', '$']) && d.join(w).is_file())
                .cloned()
        });
        tool.or_else(|| programs.into_iter().next())
    }

    /// The executable of [`Self::program_of`], resolved like the shell would (the
    /// directory of `weft` first, then PATH).
    pub fn binary_of(&self, command: &str) -> Option<PathBuf> {
        let first = self.program_of(command)?;
        let first = first.as_str();
        if let Some(hit) = self.bin_memo.borrow().get(first) {
            return hit.clone();
        }
        let found = self.resolve(first);
        self.bin_memo
            .borrow_mut()
            .insert(first.to_string(), found.clone());
        found
    }

    fn resolve(&self, first: &str) -> Option<PathBuf> {
        if first.contains('/') {
            let p = self.root.join(first);
            return p.is_file().then_some(p);
        }
        let path = std::env::var_os("PATH").unwrap_or_default();
        self.exe_dir
            .iter()
            .cloned()
            .chain(std::env::split_paths(&path))
            .map(|d| d.join(first))
            .find(|p| p.is_file())
    }

    pub fn abs(&self, p: &Path) -> PathBuf {
        if p.is_absolute() {
            p.to_path_buf()
        } else {
            self.root.join(p)
        }
    }

    /// Judge one instance against its record, on the current content of its inputs.
    pub fn verdict(&mut self, inst: &Instance) -> Result<Verdict> {
        let Some(rec) = self.records.get(&inst.name) else {
            return Ok(Verdict::Stale("never run".into()));
        };
        if rec.exit_status != 0 {
            return Ok(Verdict::Stale(format!(
                "last run failed (exit status {})",
                rec.exit_status
            )));
        }
        for (k, v) in &inst.params {
            match rec.params.get(k) {
                Some(old) if old != v => {
                    return Ok(Verdict::Stale(format!("param `{k}` {old} → {v}")))
                }
                None => return Ok(Verdict::Stale(format!("param `{k}` added ({v})"))),
                _ => {}
            }
        }
        if let Some(k) = rec.params.keys().find(|k| !inst.params.contains_key(*k)) {
            return Ok(Verdict::Stale(format!("param `{k}` no longer used")));
        }
        if rec.command != inst.command {
            return Ok(Verdict::Stale("command changed".into()));
        }
        let bin = self.binary_of(&inst.command);
        let bin_hash = match &bin {
            Some(b) => Some(self.cache.file(b)?),
            None => None,
        };
        if bin_hash != rec.binary_hash {
            let name = self.program_of(&inst.command).unwrap_or_default();
            return Ok(Verdict::Stale(match bin {
                None => format!("binary `{name}` not found"),
                Some(_) => format!("binary `{name}` changed"),
            }));
        }
        for (_, p) in &inst.inputs {
            let key = p.display().to_string();
            let h = self.cache.path(&self.abs(p))?;
            match (h, rec.inputs.get(&key)) {
                (None, _) => return Ok(Verdict::Stale(format!("input `{key}` missing"))),
                (Some(h), Some(old)) if &h.hash == old => {}
                (Some(h), Some(_)) => {
                    // Name the file inside a folder input that changed, when known.
                    let changed = h
                        .files
                        .iter()
                        .find(|(f, fh)| rec.input_files.get(&format!("{key}/{f}")) != Some(*fh));
                    let removed = rec
                        .input_files
                        .keys()
                        .filter_map(|f| f.strip_prefix(&format!("{key}/")))
                        .find(|f| !h.files.contains_key(*f));
                    return Ok(Verdict::Stale(match (changed, removed) {
                        (Some((f, _)), _) => format!("input `{key}/{f}` changed"),
                        (None, Some(f)) => format!("input `{key}/{f}` removed"),
                        _ => format!("input `{key}` changed"),
                    }));
                }
                (Some(_), None) => return Ok(Verdict::Stale(format!("input `{key}` added"))),
            }
        }
        for (_, p) in &inst.outputs {
            let key = p.display().to_string();
            match (self.cache.path(&self.abs(p))?, rec.outputs.get(&key)) {
                (None, _) => return Ok(Verdict::Stale(format!("output `{key}` missing"))),
                (Some(h), Some(old)) if &h.hash == old => {}
                _ => {
                    return Ok(Verdict::Stale(format!(
                        "output `{key}` changed since it was written"
                    )))
                }
            }
        }
        Ok(Verdict::Fresh)
    }

    /// Verdicts for all selected instances, in topological order, without running.
    pub fn plan(
        &mut self,
        p: &Pipeline,
        selected: &[bool],
        force: &[bool],
    ) -> Result<Vec<Verdict>> {
        let mut v = vec![Verdict::Fresh; p.instances.len()];
        for &i in &p.order {
            if !selected[i] {
                continue;
            }
            let inst = &p.instances[i];
            v[i] = if force[i] {
                Verdict::Stale("forced".into())
            } else {
                match self.verdict(inst)? {
                    Verdict::Fresh => {
                        match inst.deps.iter().find(|&&d| selected[d] && !v[d].is_fresh()) {
                            Some(&d) => Verdict::Waiting(format!(
                                "upstream `{}` reruns",
                                p.instances[d].name
                            )),
                            None => Verdict::Fresh,
                        }
                    }
                    s => s,
                }
            };
        }
        Ok(v)
    }
}
