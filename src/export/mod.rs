//! The `export` stage behind `weft-export`: a model folder as an input deck of another
//! explicit code, to check weft against a solver people already trust.
//!
//! - [`calculix`]: a CalculiX (ccx 2.20) `.inp` deck for `*DYNAMIC, EXPLICIT`. Only what
//!   CalculiX's explicit scheme runs faithfully is exported; the rest is refused with
//!   the element kind and the reason (measured with ccx 2.20, see that module).
//! - [`lsdyna`]: an LS-DYNA keyword `.k` deck (checked structurally here; LS-DYNA is not
//!   available to the tests).
//!
//! Both use SI units (m, kg, s, N, Pa) as weft does, and write the deck beside the target
//! and rename it into place. The time step of a CalculiX deck is fixed and divides the
//! output interval (ccx prints every n-th increment); run weft with the same
//! `--time-step` to compare the two step for step.

pub mod calculix;
pub mod lsdyna;

use std::path::{Path, PathBuf};

use serde::Serialize;

use crate::error::{Result, WeftError};
use crate::model::io::read_model;
use crate::model::Model;
use crate::table::Provenance;

/// Which deck.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, clap::ValueEnum)]
#[serde(rename_all = "lowercase")]
pub enum Format {
    /// CalculiX `.inp` (ccx, `*DYNAMIC, EXPLICIT`).
    Calculix,
    /// LS-DYNA keyword `.k`.
    Lsdyna,
}

/// Settings of one export.
#[derive(Debug, Clone, Serialize)]
pub struct Config {
    pub model: PathBuf,
    /// The deck to write.
    pub out: PathBuf,
    pub format: Format,
    /// Time step [s]; None: weft's own (stable step × safety, or the model's fixed step),
    /// lowered to divide the output interval.
    pub time_step: Option<f64>,
}

/// What an export wrote.
#[derive(Debug, Clone, Default)]
pub struct Report {
    /// Time step of the deck [s] and increments per output sample.
    pub dt: f64,
    pub increments_per_output: u64,
    pub end_time: f64,
    pub nodes: usize,
    /// Cards written: (what, count), e.g. ("SPRINGA (trusses)", 200).
    pub written: Vec<(String, usize)>,
    /// Nodes whose displacements the deck prints.
    pub output_nodes: usize,
}

/// Refusal: the model holds something the format cannot reproduce faithfully.
pub(crate) fn refuse(format: &str, what: &str, why: &str) -> WeftError {
    WeftError::input(format!("cannot export {what} to {format}: {why}"))
        .hint("export a model without it (the deck would not be the same model), or compare it in weft alone")
}

/// Write the deck for `c`.
pub fn run(c: &Config) -> Result<Report> {
    let m = read_model(&c.model)?;
    let mut prov = Provenance::new(
        "export",
        serde_json::to_value(c).expect("config serialises"),
    );
    for entry in std::fs::read_dir(&c.model).map_err(|e| WeftError::io(&c.model, e))? {
        let p = entry.map_err(|e| WeftError::io(&c.model, e))?.path();
        if p.extension().is_some_and(|x| x == "parquet") {
            prov = prov.with_input(&p)?;
        }
    }
    let prov = serde_json::to_string(&prov).expect("provenance serialises");
    let (dt, nsub) = time_step(&m, c.time_step)?;
    let (text, report) = match c.format {
        Format::Calculix => calculix::deck(&m, dt, nsub, &prov)?,
        Format::Lsdyna => lsdyna::deck(&m, dt, &prov)?,
    };
    write_atomic(&c.out, &text)?;
    Ok(report)
}

/// The deck's step: at most weft's step (or the one asked for), lowered so that a whole
/// number of steps n makes the output interval: (Δt, n).
pub fn time_step(m: &Model, asked: Option<f64>) -> Result<(f64, u64)> {
    let dt = match asked {
        Some(v) if v.is_finite() && v > 0.0 => v,
        Some(v) => {
            return Err(WeftError::input(format!("--time-step {v}")).expected("a step > 0 in s"))
        }
        None => crate::solver::Solver::new(m)?.stable.dt,
    };
    let out = m.analysis.output_interval;
    let n = (out / dt * (1.0 - 1e-12)).ceil().max(1.0);
    // The step as the deck writes it (14 digits), so that weft can run on the same one.
    let dt: f64 = num(out / n).parse().expect("a formatted number parses");
    Ok((dt, n as u64))
}

/// A number as CalculiX and LS-DYNA read it: at most 20 characters (ccx reads fields of
/// 20), 14 significant digits.
pub fn num(x: f64) -> String {
    if x == 0.0 {
        "0.".into()
    } else {
        format!("{x:.13e}")
    }
}

fn write_atomic(path: &Path, text: &str) -> Result<()> {
    if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir).map_err(|e| WeftError::io(dir, e))?;
    }
    let name = path
        .file_name()
        .ok_or_else(|| WeftError::input(format!("--out `{}` has no file name", path.display())))?
        .to_string_lossy()
        .to_string();
    let tmp = path.with_file_name(format!(".{name}.tmp-{}", std::process::id()));
    std::fs::write(&tmp, text).map_err(|e| WeftError::io(&tmp, e))?;
    std::fs::rename(&tmp, path).map_err(|e| WeftError::io(path, e))
}

/// Samples (t, g(t)) of a load's time law on [0, end], for tabulated amplitudes: the
/// law's corners exactly, and a sine pulse at every step Δt inside it (so that a code
/// evaluating the load at its steps sees the exact sine; at most `MAX_SAMPLES`, else
/// evenly).
pub fn law_samples(law: &crate::model::TimeLaw, end: f64, dt: f64) -> Vec<(f64, f64)> {
    use crate::model::TimeLaw;
    const MAX_SAMPLES: usize = 20_000;
    let mut v: Vec<(f64, f64)> = vec![];
    // A jump at t0 is a rise over a millionth of a step.
    let eps = 1e-6 * dt;
    match law {
        TimeLaw::SinePulse { start, duration } => {
            if *start > 0.0 {
                v.push((0.0, 0.0));
            }
            v.push((*start, 0.0));
            let (k0, k1) = ((start / dt).ceil(), ((start + duration) / dt).floor());
            if k1 - k0 < MAX_SAMPLES as f64 {
                for k in k0 as u64..=k1 as u64 {
                    let t = k as f64 * dt;
                    v.push((t, law.eval(t)));
                }
            } else {
                for j in 0..=MAX_SAMPLES {
                    let t = start + duration * j as f64 / MAX_SAMPLES as f64;
                    v.push((t, law.eval(t)));
                }
            }
            v.push((start + duration, 0.0));
        }
        TimeLaw::Step { start } => {
            if *start > 0.0 {
                v.push((0.0, 0.0));
                v.push((start - eps, 0.0));
            }
            v.push((start.max(0.0), 1.0));
        }
        TimeLaw::Ramp { start, duration } => {
            if *start > 0.0 {
                v.push((0.0, 0.0));
            }
            v.push((*start, 0.0));
            v.push((start + duration, 1.0));
        }
        TimeLaw::Tabulated { curve, .. } => {
            if curve.t[0] > 0.0 {
                v.push((0.0, curve.value[0]));
            }
            v.extend(curve.t.iter().copied().zip(curve.value.iter().copied()));
        }
    }
    // Hold the last value to beyond the end; keep times strictly increasing.
    let last = v.last().map_or(0.0, |p| p.1);
    let tl = v.last().map_or(0.0, |p| p.0);
    if tl < end * 1.01 {
        v.push((end * 1.01 + dt, last));
    }
    v.dedup_by(|b, a| b.0 <= a.0);
    v
}
