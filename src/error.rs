//! Typed errors of the weft library.
//!
//! Every error names the object it concerns (file, table, column, row, node, element,
//! step) and the offending value, says what was expected, and carries a `hint:` where a
//! fix is known. Binaries wrap these in `anyhow` context chains.

use std::fmt;
use std::path::PathBuf;

/// Where in the input a problem was found.
#[derive(Debug, Clone, Default)]
pub struct Location {
    /// The file (a Parquet table of a model folder, a pipeline file, ...).
    pub file: Option<PathBuf>,
    /// The column of a table.
    pub column: Option<String>,
    /// Zero-based row of a table.
    pub row: Option<usize>,
    /// One-based line of a text file (pipeline files).
    pub line: Option<usize>,
    /// Dotted key in a text file (`stages.fit.outputs`).
    pub key: Option<String>,
}

impl fmt::Display for Location {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let mut parts = Vec::new();
        if let Some(p) = &self.file {
            parts.push(format!("file `{}`", p.display()));
        }
        if let Some(c) = &self.column {
            parts.push(format!("column `{c}`"));
        }
        if let Some(r) = self.row {
            parts.push(format!("row {r}"));
        }
        if let Some(l) = self.line {
            parts.push(format!("line {l}"));
        }
        if let Some(k) = &self.key {
            parts.push(format!("key `{k}`"));
        }
        write!(f, "{}", parts.join(", "))
    }
}

#[derive(Debug, thiserror::Error)]
pub enum WeftError {
    /// Invalid user input: a table, a value, a flag.
    #[error("{what}{}{}{}", loc_suffix(.at), expected_suffix(.expected), hint_suffix(.hint))]
    Input {
        what: String,
        at: Location,
        expected: Option<String>,
        hint: Option<String>,
    },
    /// The numerical solution broke down (NaN, Inf, runaway energy).
    #[error("{what} at step {step}, t = {time:.6e} s{}", hint_suffix(.hint))]
    Numerical {
        what: String,
        step: u64,
        time: f64,
        hint: Option<String>,
    },
    #[error("I/O error on `{}`: {source}", .path.display())]
    Io {
        path: PathBuf,
        #[source]
        source: std::io::Error,
    },
    #[error("Parquet error on `{}`: {message}", .path.display())]
    Parquet { path: PathBuf, message: String },
    /// An error with what was being done when it happened, displayed as
    /// `context: error` (as an anyhow context chain prints).
    #[error("{context}: {error}")]
    Context {
        context: String,
        error: Box<WeftError>,
    },
}

fn loc_suffix(at: &Location) -> String {
    let s = at.to_string();
    if s.is_empty() {
        String::new()
    } else {
        format!(" (in {s})")
    }
}
fn expected_suffix(e: &Option<String>) -> String {
    e.as_ref()
        .map(|e| format!("; expected {e}"))
        .unwrap_or_default()
}
fn hint_suffix(h: &Option<String>) -> String {
    h.as_ref()
        .map(|h| format!("\n  hint: {h}"))
        .unwrap_or_default()
}

pub type Result<T, E = WeftError> = std::result::Result<T, E>;

impl WeftError {
    /// An input error with no location yet.
    pub fn input(what: impl Into<String>) -> Self {
        WeftError::Input {
            what: what.into(),
            at: Location::default(),
            expected: None,
            hint: None,
        }
    }
    /// Say what was being done when the error happened.
    pub fn context(self, context: impl Into<String>) -> Self {
        WeftError::Context {
            context: context.into(),
            error: Box::new(self),
        }
    }
    pub fn io(path: impl Into<PathBuf>, source: std::io::Error) -> Self {
        WeftError::Io {
            path: path.into(),
            source,
        }
    }
    /// Set what was expected (input errors only).
    pub fn expected(mut self, e: impl Into<String>) -> Self {
        if let WeftError::Input { expected, .. } = &mut self {
            *expected = Some(e.into());
        }
        self
    }
    /// Attach a hint (input and numerical errors).
    pub fn hint(mut self, h: impl Into<String>) -> Self {
        match &mut self {
            WeftError::Input { hint, .. } | WeftError::Numerical { hint, .. } => {
                *hint = Some(h.into())
            }
            _ => {}
        }
        self
    }
    pub fn in_file(mut self, p: impl Into<PathBuf>) -> Self {
        if let WeftError::Input { at, .. } = &mut self {
            if at.file.is_none() {
                at.file = Some(p.into());
            }
        }
        self
    }
    pub fn in_column(mut self, c: impl Into<String>) -> Self {
        if let WeftError::Input { at, .. } = &mut self {
            at.column = Some(c.into());
        }
        self
    }
    pub fn at_line(mut self, l: usize) -> Self {
        if let WeftError::Input { at, .. } = &mut self {
            at.line = Some(l);
        }
        self
    }
    pub fn at_key(mut self, k: impl Into<String>) -> Self {
        if let WeftError::Input { at, .. } = &mut self {
            at.key = Some(k.into());
        }
        self
    }
    pub fn at_row(mut self, r: usize) -> Self {
        if let WeftError::Input { at, .. } = &mut self {
            at.row = Some(r);
        }
        self
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    #[test]
    fn message_names_everything() {
        let e = WeftError::input("area `-1e-6` is not positive")
            .in_file("m/parts.parquet")
            .in_column("area")
            .at_row(3)
            .expected("a value > 0 in m²")
            .hint("check the part's cross-section");
        let s = e.to_string();
        assert!(s.contains("`m/parts.parquet`"), "{s}");
        assert!(s.contains("column `area`"), "{s}");
        assert!(s.contains("row 3"), "{s}");
        assert!(s.contains("expected a value > 0"), "{s}");
        assert!(s.contains("hint: check"), "{s}");
    }
}
