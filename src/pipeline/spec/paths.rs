//! Paths in a pipeline: lexical normalisation of the paths a stage names, nesting, and
//! instance names made safe as file names.

use std::path::{Component, Path, PathBuf};

/// Lexically normalise a relative path; `None` when it climbs above its start.
pub(super) fn normalise(p: &Path) -> Option<PathBuf> {
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
