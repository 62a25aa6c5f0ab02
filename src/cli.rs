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

/// Parse the command line as clap's `C::parse()` does, except that
/// - a usage error (an unknown flag, a value that does not parse) exits with 1, as every
///   other refusal does, not clap's 2 (`--help` and `--version` still exit 0);
/// - a flag's value may start with `-` (`--force -1`, `--level -inf`): the value is then
///   judged, and named with its flag, instead of being taken for an unknown flag `-1`;
/// - a floating-point flag given NaN or ±inf is refused, naming the flag (no flag takes
///   an infinite value).
pub fn parse<C: clap::Parser>() -> C {
    let mut cmd = hyphen_values(C::command());
    let r = cmd
        .try_get_matches_from_mut(std::env::args_os())
        .and_then(|mut m| {
            if let Err(msg) = finite_values(&cmd, &m) {
                eprintln!("error: {msg}\n  hint: give a finite number (see --help)");
                std::process::exit(1);
            }
            C::from_arg_matches_mut(&mut m)
        });
    r.unwrap_or_else(|e| {
        let code = if e.use_stderr() { 1 } else { 0 };
        let _ = e.format(&mut cmd).print();
        std::process::exit(code)
    })
}

/// Every flag that takes exactly one value accepts one starting with `-`.
fn hyphen_values(c: clap::Command) -> clap::Command {
    let subs: Vec<String> = c
        .get_subcommands()
        .map(|s| s.get_name().to_string())
        .collect();
    let mut c = c.mut_args(|a| {
        let one = a
            .get_num_args()
            .is_none_or(|r| r.min_values() == 1 && r.max_values() == 1);
        if a.get_long().is_some() && a.get_action().takes_values() && one {
            a.allow_hyphen_values(true)
        } else {
            a
        }
    });
    for s in subs {
        c = c.mut_subcommand(s, hyphen_values);
    }
    c
}

/// The first floating-point flag given on the command line with a non-finite value.
fn finite_values(cmd: &clap::Command, m: &clap::ArgMatches) -> Result<(), String> {
    for a in cmd.get_arguments() {
        let id = a.get_id().as_str();
        if a.get_value_parser().type_id() != std::any::TypeId::of::<f64>()
            || m.value_source(id) != Some(clap::parser::ValueSource::CommandLine)
        {
            continue;
        }
        if let Ok(Some(vs)) = m.try_get_many::<f64>(id) {
            if let Some(v) = vs.into_iter().find(|v| !v.is_finite()) {
                return Err(format!(
                    "--{} `{v}` is not a finite number",
                    a.get_long().unwrap_or(id)
                ));
            }
        }
    }
    if let Some((name, sm)) = m.subcommand() {
        if let Some(sc) = cmd.find_subcommand(name) {
            finite_values(sc, sm)?;
        }
    }
    Ok(())
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
