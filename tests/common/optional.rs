//! Test files whose oracles are tools weft does not ship (CalculiX, Slurm, python3 with
//! pandas, polars, pyarrow or VTK) run under this harness (`harness = false` in
//! Cargo.toml): where the tool is missing, its tests are reported as *ignored*, so the
//! summary line counts them (`test result: ok. 1 passed; 0 failed; 5 ignored`) and a
//! line above it names the tool, how to install it and the variable that requires it.
//! With that variable set to 1 (`.ci/run` sets them all), a missing tool fails each
//! test that needs it instead.

use libtest_mimic::{Arguments, Failed, Trial};

/// A tool some tests need.
pub struct Tool {
    /// What is needed, for the messages ("CalculiX 2.2x (`ccx`)").
    pub what: &'static str,
    /// How to get it.
    pub install: &'static str,
    /// The variable that, set to 1, makes the tests required.
    pub require: &'static str,
    /// Whether the tool is here (asked once).
    pub here: fn() -> bool,
}

/// A test of the file: its name, whether it needs the tool, and its body (which panics
/// on failure, as a `#[test]` does).
pub type Case = (&'static str, bool, fn());

/// Runs the file's tests as libtest would, those that need a missing tool ignored
/// (or failed, where `tool.require` is 1).
pub fn run(tool: &Tool, cases: Vec<Case>) -> std::process::ExitCode {
    let args = Arguments::from_args();
    let required = std::env::var(tool.require).as_deref() == Ok("1");
    let needing = cases.iter().filter(|c| c.1).count();
    // Not asked when no test needs it (a filter or --list does not matter: it is cheap
    // enough, but a stopped Slurm takes ~10 s to answer, so ask at most once).
    let here = needing == 0 || (tool.here)();
    if !here && !required {
        println!(
            "SKIPPED {needing} test(s) of this file, shown as ignored: {} not found ({}); \
             {}=1 makes them required",
            tool.what, tool.install, tool.require
        );
    }
    let trials = cases
        .into_iter()
        .map(|(name, needs, body)| {
            let missing = needs && !here;
            let msg = format!(
                "{}=1 but {} is not available ({})",
                tool.require, tool.what, tool.install
            );
            Trial::test(name, move || {
                if missing {
                    return Err(Failed::from(msg));
                }
                body();
                Ok(())
            })
            .with_ignored_flag(missing && !required)
        })
        .collect();
    libtest_mimic::run(&args, trials).exit_code()
}
