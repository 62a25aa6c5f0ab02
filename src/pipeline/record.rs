//! One record per stage instance: `.weft/records/<pipeline>/<instance>.json`. Small,
//! one file each, so that records of different stages never conflict in git.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use crate::error::{Result, WeftError};

#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
pub struct Record {
    pub instance: String,
    pub stage: String,
    /// The command as run (with the final output paths).
    pub command: String,
    /// Vars, params and sweep values the instance uses.
    pub params: BTreeMap<String, String>,
    /// Input path → content hash.
    pub inputs: BTreeMap<String, String>,
    /// For folder inputs: `path/file` → hash, to say which file changed.
    #[serde(default)]
    pub input_files: BTreeMap<String, String>,
    pub outputs: BTreeMap<String, String>,
    /// The stage's executable and its hash.
    pub binary: Option<String>,
    pub binary_hash: Option<String>,
    pub tool_version: String,
    pub start_unix: f64,
    pub end_unix: f64,
    pub start: String,
    pub end: String,
    pub exit_status: i32,
    pub log: String,
}

/// Record files of one pipeline.
pub struct RecordStore {
    pub dir: PathBuf,
}

impl RecordStore {
    pub fn new(root: &Path, pipeline: &Path) -> RecordStore {
        let stem = pipeline
            .file_stem()
            .map(|s| s.to_string_lossy().to_string())
            .unwrap_or_else(|| "pipeline".into());
        RecordStore {
            dir: root.join(".weft").join("records").join(stem),
        }
    }

    pub fn path(&self, instance: &str) -> PathBuf {
        self.dir
            .join(format!("{}.json", super::spec::file_name_of(instance)))
    }

    /// The record of an instance; `None` if it never ran (an unreadable record counts as none).
    pub fn get(&self, instance: &str) -> Option<Record> {
        let s = std::fs::read_to_string(self.path(instance)).ok()?;
        serde_json::from_str(&s).ok()
    }

    /// Write a record atomically.
    pub fn put(&self, r: &Record) -> Result<()> {
        std::fs::create_dir_all(&self.dir).map_err(|e| WeftError::io(&self.dir, e))?;
        let p = self.path(&r.instance);
        let tmp = p.with_extension(format!("json.tmp-{}", super::host::process_tag()));
        let s = serde_json::to_string_pretty(r).expect("record serialises");
        std::fs::write(&tmp, s).map_err(|e| WeftError::io(&tmp, e))?;
        std::fs::rename(&tmp, &p).map_err(|e| WeftError::io(&p, e))?;
        Ok(())
    }

    /// All records (any order).
    pub fn all(&self) -> Vec<Record> {
        let Ok(rd) = std::fs::read_dir(&self.dir) else {
            return vec![];
        };
        rd.filter_map(|e| e.ok())
            .filter(|e| e.path().extension().is_some_and(|x| x == "json"))
            .filter_map(|e| std::fs::read_to_string(e.path()).ok())
            .filter_map(|s| serde_json::from_str(&s).ok())
            .collect()
    }
}

/// UTC time as `YYYY-MM-DDTHH:MM:SS.mmmZ` from Unix seconds.
pub fn iso_utc(unix: f64) -> String {
    let secs = unix.floor() as i64;
    let ms = ((unix - secs as f64) * 1000.0).round().min(999.0) as i64;
    let days = secs.div_euclid(86_400);
    let sod = secs.rem_euclid(86_400);
    // Civil from days (H. Hinnant's algorithm).
    let z = days + 719_468;
    let era = z.div_euclid(146_097);
    let doe = z - era * 146_097;
    let yoe = (doe - doe / 1460 + doe / 36_524 - doe / 146_096) / 365;
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    let mp = (5 * doy + 2) / 153;
    let d = doy - (153 * mp + 2) / 5 + 1;
    let m = if mp < 10 { mp + 3 } else { mp - 9 };
    let y = yoe + era * 400 + i64::from(m <= 2);
    format!(
        "{y:04}-{m:02}-{d:02}T{:02}:{:02}:{:02}.{ms:03}Z",
        sod / 3600,
        sod % 3600 / 60,
        sod % 60
    )
}

#[cfg(test)]
mod tests {
    #[test]
    fn iso_dates() {
        assert_eq!(super::iso_utc(0.0), "1970-01-01T00:00:00.000Z");
        assert_eq!(super::iso_utc(1_795_000_000.25), "2026-11-18T11:06:40.250Z");
        assert_eq!(super::iso_utc(951_782_400.0), "2000-02-29T00:00:00.000Z");
    }
}
