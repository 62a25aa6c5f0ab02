//! The `export` stage behind `weft-export`: a model folder as an input deck of another
//! explicit code, to check weft against a solver people already trust.
//!
//! - [`calculix`]: a CalculiX (ccx 2.20) `.inp` deck for `*DYNAMIC, EXPLICIT`. Only what
//!   CalculiX's explicit scheme runs faithfully is exported; the rest is refused with
//!   the element kind and the reason (measured with ccx 2.20, see that module).
//! - [`lsdyna`]: an LS-DYNA keyword `.k` deck (checked structurally here; LS-DYNA is not
//!   available to the tests).
//!
//! What the two decks share is in `common.rs`; what either refuses is one list of model
//! features in `unsupported.rs`, each format giving its own reasons.
//!
//! Both use SI units (m, kg, s, N, Pa) as weft does, and write the deck beside the target
//! and rename it into place. The time step of a CalculiX deck is fixed and divides the
//! output interval (ccx prints every n-th increment); run weft with the same
//! `--time-step` to compare the two step for step.

pub mod calculix;
mod common;
pub mod lsdyna;
mod unsupported;

pub use common::{law_samples, num, Report};

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
        None => crate::solver::Solver::new(m)?.time_step().dt,
    };
    let out = m.analysis.output_interval;
    let n = (out / dt * (1.0 - 1e-12)).ceil().max(1.0);
    // The step as the deck writes it (14 digits), so that weft can run on the same one.
    let dt: f64 = num(out / n).parse().expect("a formatted number parses");
    Ok((dt, n as u64))
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
