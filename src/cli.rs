//! What every stage binary shares: the `main` wrapper (the error, its context chain and
//! its `hint:` lines on stderr, the exit code) and progress reporting, either the
//! `weft-progress <fraction>` lines that `weft run` reads or an indicatif bar.
//!
//! A binary is `fn main() -> ExitCode { weft::cli::main(run) }`, where `run` parses the
//! arguments, calls its stage's library `run`, prints a short summary and returns the
//! exit code.

use std::process::ExitCode;

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};

/// Run a binary's body: its exit code, or on error `error: <context: cause>` (the anyhow
/// chain, whose weft errors end with their `hint:` lines) on stderr and failure.
pub fn main(run: impl FnOnce() -> anyhow::Result<ExitCode>) -> ExitCode {
    match run() {
        Ok(code) => code,
        Err(e) => {
            eprintln!("error: {e:#}");
            ExitCode::FAILURE
        }
    }
}

/// Set by `weft run` for the stages it starts: report progress as protocol lines.
pub const PROGRESS_ENV: &str = "WEFT_PROGRESS";

/// Progress of a stage: `weft-progress <fraction>` lines on stderr under `weft run`
/// (when `WEFT_PROGRESS` is set), else an indicatif bar on stderr, hidden when quiet.
pub struct Progress {
    protocol: bool,
    bar: ProgressBar,
}

impl Progress {
    /// A bar of `len` steps drawn with the indicatif `template`.
    pub fn new(quiet: bool, len: u64, template: &str) -> Self {
        let protocol = std::env::var_os(PROGRESS_ENV).is_some();
        let bar = if quiet || protocol {
            ProgressBar::hidden()
        } else {
            let b = ProgressBar::with_draw_target(Some(len), ProgressDrawTarget::stderr());
            b.set_style(ProgressStyle::with_template(template).expect("valid template"));
            b
        };
        Progress { protocol, bar }
    }

    /// Whether progress goes out as protocol lines (under `weft run`).
    pub fn protocol(&self) -> bool {
        self.protocol
    }

    /// One protocol line: `weft-progress <fraction>`, four decimals.
    pub fn line(&self, fraction: f64) {
        eprintln!("weft-progress {fraction:.4}");
    }

    /// The bar (hidden under the protocol or when quiet).
    pub fn bar(&self) -> &ProgressBar {
        &self.bar
    }

    /// A callback for the fraction done: a protocol line each time it has moved by 1 %
    /// (and at the end), else the bar at fraction × its length.
    pub fn fraction(&self) -> impl FnMut(f64) + Send + '_ {
        let mut last = -1.0;
        move |f: f64| {
            if self.protocol {
                if f - last >= 0.01 || f >= 1.0 {
                    self.line(f);
                    last = f;
                }
            } else {
                let len = self.bar.length().unwrap_or(0) as f64;
                self.bar.set_position((f * len) as u64)
            }
        }
    }

    /// Clear the bar.
    pub fn finish(&self) {
        self.bar.finish_and_clear();
    }
}
