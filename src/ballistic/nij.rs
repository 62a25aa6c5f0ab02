//! The armour test's verdict (`weft-ballistic nij`): a shot of a pack on the clay (the
//! summary of `weft-simulate` on `weft-weave woven --backing clay`) judged as NIJ
//! Standard-0101.06 judges a fair hit: the bullet must not perforate the pack and the
//! back-face signature, the crater's depth in the clay, must not exceed 44 mm; the
//! striking velocity must lie within the level's tolerance for the shot to count.
//! Levels (9 mm FMJ RN, 8.0 g): IIA 373 m/s, II 398 m/s, both ± 9.1 m/s (1225 and
//! 1305 ft/s ± 30 ft/s), as the NRC's review *Testing of Body Armor Materials: Phase
//! III* (2012, ch. 4) restates them.

use std::path::{Path, PathBuf};

use crate::error::{Result, WeftError};
use crate::table::{batch, write_table, Col, Provenance, Table};

/// The standard's limit on the back-face signature [m].
pub const BFS_LIMIT: f64 = 0.044;

/// The striking velocity's tolerance about a level's reference velocity [m/s].
pub const VELOCITY_TOLERANCE: f64 = 9.1;

/// A protection level of NIJ Standard-0101.06 for the 9 mm FMJ RN.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum Level {
    /// 373 m/s.
    #[value(name = "IIA", alias = "iia", alias = "2a")]
    IIA,
    /// 398 m/s.
    #[value(name = "II", alias = "ii", alias = "2")]
    II,
}

impl Level {
    pub fn name(&self) -> &'static str {
        match self {
            Level::IIA => "IIA",
            Level::II => "II",
        }
    }
    /// The reference velocity [m/s].
    pub fn velocity(&self) -> f64 {
        match self {
            Level::IIA => 373.0,
            Level::II => 398.0,
        }
    }
    /// The level whose fair hits a shot at `v` [m/s] is one of (the levels' velocity
    /// bands do not overlap: 373 + 9.1 < 398 − 9.1), if any.
    pub fn of_velocity(v: f64) -> Option<Level> {
        [Level::IIA, Level::II]
            .into_iter()
            .find(|l| (v - l.velocity()).abs() <= VELOCITY_TOLERANCE)
    }
}

/// One shot judged.
#[derive(Debug, Clone)]
pub struct Verdict {
    pub run: PathBuf,
    pub striking_velocity: f64,
    /// Within the level's velocity ± [`VELOCITY_TOLERANCE`].
    pub velocity_in_range: bool,
    /// The run's outcome (`arrested`, `perforated`, `undecided`) and its BFS [m].
    pub outcome: String,
    pub perforated: bool,
    /// The pack's plies (the summary's `layers`), those perforated, and its areal
    /// density [kg/m²] (null in older runs' summaries).
    pub plies: i64,
    pub plies_perforated: Option<i64>,
    pub areal_density: Option<f64>,
    /// The level the shot was judged at.
    pub level: Option<Level>,
    pub bfs: f64,
    /// [`BFS_LIMIT`] − BFS [m]: positive when the crater is within the limit.
    pub bfs_margin: f64,
    /// Pass, fail, or none (no verdict: `reason` says why).
    pub pass: Option<bool>,
    pub reason: String,
}

impl Verdict {
    /// `PASS`, `FAIL` or `no verdict`, then the reason in brackets when there is one:
    /// how the binaries print it.
    pub fn said(&self) -> String {
        let word = match self.pass {
            Some(true) => "PASS",
            Some(false) => "FAIL",
            None => "no verdict",
        };
        if self.reason.is_empty() {
            word.into()
        } else {
            format!("{word} ({})", self.reason)
        }
    }
}

/// The verdict's columns both tables end with: `pass` and `reason`.
fn verdict_columns(vs: &[Verdict]) -> [Col; 2] {
    [
        Col::OptBool("pass", vs.iter().map(|v| v.pass).collect()),
        Col::OptStr(
            "reason",
            vs.iter()
                .map(|v| (!v.reason.is_empty()).then(|| v.reason.clone()))
                .collect(),
        ),
    ]
}

/// Judges the shot of the run folder `run` (its summary.parquet) at `level`, or, with
/// none, at the level whose velocity band its striking velocity lies in (no verdict
/// when it lies in neither).
pub fn judge(run: &Path, level: Option<Level>) -> Result<Verdict> {
    let path = run.join("summary.parquet");
    let t = Table::read(&path)?;
    let one = |c: &str| -> Result<Option<f64>> {
        Ok(t.f64_opt(c)?.and_then(|v| v.first().copied().flatten()))
    };
    let missing = |c: &str, what: &str| {
        WeftError::input(format!("no `{c}`"))
            .in_file(&path)
            .in_column(c)
            .expected(what.to_string())
    };
    let v = one("striking_velocity")?.ok_or_else(|| {
        missing(
            "striking_velocity",
            "a shot's run (a model with a projectile)",
        )
    })?;
    let bfs = one("bfs")?.ok_or_else(|| {
        missing("bfs", "a shot on the clay").hint("weft-weave woven --backing clay")
    })?;
    let status = t
        .str("status", "status")?
        .first()
        .cloned()
        .unwrap_or_default();
    let outcome = t
        .str_opt("outcome")?
        .and_then(|v| v.first().cloned().flatten())
        .unwrap_or_else(|| "undecided".into());
    let perforated = outcome == "perforated";
    let level = level.or_else(|| Level::of_velocity(v));
    let velocity_in_range = level.is_some_and(|l| (v - l.velocity()).abs() <= VELOCITY_TOLERANCE);
    let (pass, reason) = if status != "completed" {
        (
            None,
            format!("the run {status}: its outcome and crater are not the shot's"),
        )
    } else if !velocity_in_range {
        (
            None,
            match level {
                Some(level) => format!(
                    "striking velocity {v:.1} m/s outside level {}'s {:.0} ± {VELOCITY_TOLERANCE} m/s: not a fair hit",
                    level.name(),
                    level.velocity()
                ),
                None => format!(
                    "striking velocity {v:.1} m/s within no level's band (IIA 373, II 398 ± {VELOCITY_TOLERANCE} m/s): not a fair hit"
                ),
            },
        )
    } else if perforated {
        (Some(false), "perforated".into())
    } else if outcome != "arrested" {
        (
            None,
            "the run ended before the bullet was arrested: the crater may still deepen; run it on with a later --end-time"
                .into(),
        )
    } else if bfs > BFS_LIMIT {
        (
            Some(false),
            format!("back-face signature {:.1} mm over 44 mm", 1e3 * bfs),
        )
    } else {
        (Some(true), String::new())
    };
    let int = |c: &str| -> Result<Option<i64>> {
        Ok(t.i64_opt(c)?.and_then(|v| v.first().copied().flatten()))
    };
    Ok(Verdict {
        run: run.to_path_buf(),
        striking_velocity: v,
        velocity_in_range,
        outcome,
        perforated,
        plies: int("layers")?.unwrap_or(0),
        plies_perforated: int("plies_perforated")?,
        areal_density: one("areal_density")?,
        level,
        bfs,
        bfs_margin: BFS_LIMIT - bfs,
        pass,
        reason,
    })
}

/// `armour_test.parquet`: one row per shot, each judged at the level of its velocity
/// (docs/tables.md).
pub fn write_armour_test(path: &Path, vs: &[Verdict], prov: &Provenance) -> Result<()> {
    let f = |g: fn(&Verdict) -> f64| vs.iter().map(g).collect::<Vec<f64>>();
    write_table(
        path,
        &batch(
            vec![
                Col::I64("plies", vs.iter().map(|v| v.plies).collect()),
                Col::OptF64(
                    "areal_density",
                    vs.iter().map(|v| v.areal_density).collect(),
                ),
                Col::F64("velocity", f(|v| v.striking_velocity)),
                Col::OptStr(
                    "level",
                    vs.iter()
                        .map(|v| v.level.map(|l| l.name().into()))
                        .collect(),
                ),
                Col::Str("outcome", vs.iter().map(|v| v.outcome.clone()).collect()),
                Col::Bool("perforated", vs.iter().map(|v| v.perforated).collect()),
                Col::OptI64(
                    "plies_perforated",
                    vs.iter().map(|v| v.plies_perforated).collect(),
                ),
                Col::F64("bfs", f(|v| v.bfs)),
                Col::F64("bfs_margin", f(|v| v.bfs_margin)),
            ]
            .into_iter()
            .chain(verdict_columns(vs))
            .chain([Col::Str(
                "run",
                vs.iter().map(|v| v.run.display().to_string()).collect(),
            )])
            .collect(),
        ),
        prov,
    )
}

/// `nij.parquet`: one row per shot judged at `level` (docs/tables.md).
pub fn write(path: &Path, level: Level, vs: &[Verdict], prov: &Provenance) -> Result<()> {
    let n = vs.len();
    let f = |g: fn(&Verdict) -> f64| vs.iter().map(g).collect::<Vec<f64>>();
    write_table(
        path,
        &batch(
            vec![
                Col::Str(
                    "run",
                    vs.iter().map(|v| v.run.display().to_string()).collect(),
                ),
                Col::Str("level", vec![level.name().into(); n]),
                Col::F64("velocity", vec![level.velocity(); n]),
                Col::F64("velocity_tolerance", vec![VELOCITY_TOLERANCE; n]),
                Col::F64("striking_velocity", f(|v| v.striking_velocity)),
                Col::Bool(
                    "velocity_in_range",
                    vs.iter().map(|v| v.velocity_in_range).collect(),
                ),
                Col::Str("outcome", vs.iter().map(|v| v.outcome.clone()).collect()),
                Col::Bool("perforated", vs.iter().map(|v| v.perforated).collect()),
                Col::F64("bfs", f(|v| v.bfs)),
                Col::F64("bfs_limit", vec![BFS_LIMIT; n]),
                Col::F64("bfs_margin", f(|v| v.bfs_margin)),
            ]
            .into_iter()
            .chain(verdict_columns(vs))
            .collect(),
        ),
        prov,
    )
}
