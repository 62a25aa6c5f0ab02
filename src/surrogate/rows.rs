//! The x and y of a table: the rows the filters keep, the named columns as rows.

use super::scale::Scale;
use crate::error::{Result, WeftError};
use crate::table::Table;

/// Column names as `a`, `b`, … for messages.
pub(crate) fn column_list(c: &[String]) -> String {
    c.iter()
        .map(|s| format!("`{s}`"))
        .collect::<Vec<_>>()
        .join(", ")
}

/// The rows every `COLUMN=VALUE` filter keeps (a string column compared as text, a
/// numeric one as a number).
pub(crate) fn filter_rows(t: &Table, filters: &[String]) -> Result<Vec<bool>> {
    let mut keep = vec![true; t.num_rows()];
    for f in filters {
        let (col, val) = f.split_once('=').ok_or_else(|| {
            WeftError::input(format!("--filter `{f}`"))
                .expected("COLUMN=VALUE, e.g. match=position")
        })?;
        let (col, val) = (col.trim(), val.trim());
        let hits: Vec<bool> = match t.str(col, col) {
            Ok(v) => v.iter().map(|s| s == val).collect(),
            Err(_) => {
                let num: f64 = val.parse().map_err(|_| {
                    WeftError::input(format!("--filter `{f}`: `{val}` is not a number"))
                        .in_file(&t.path)
                        .in_column(col.to_string())
                        .expected("a number for a numeric column")
                })?;
                t.f64(col, col)?.iter().map(|&v| v == num).collect()
            }
        };
        for (k, h) in keep.iter_mut().zip(hits) {
            *k &= h;
        }
    }
    if !keep.iter().any(|&k| k) {
        return Err(WeftError::input(format!(
            "no row of the table passes --filter {}",
            filters.join(" --filter ")
        ))
        .in_file(&t.path)
        .expected("a filter some rows match"));
    }
    Ok(keep)
}

/// Read columns `names` of a table as rows; log-scaled columns must be positive.
pub(crate) fn read_rows(
    t: &Table,
    names: &[String],
    all: &str,
    scale: Scale,
    what: &str,
) -> Result<Vec<Vec<f64>>> {
    let cols: Vec<Vec<f64>> = names
        .iter()
        .map(|n| {
            t.f64(n, all).map_err(|e| {
                e.hint(format!(
                    "the {what} columns are {}; name them with --{what}s (a NaN usually is a failed fit upstream: drop that row)",
                    column_list(names)
                ))
            })
        })
        .collect::<Result<_>>()?;
    if scale == Scale::Log {
        for (c, col) in cols.iter().enumerate() {
            if let Some(r) = col.iter().position(|&v| v <= 0.0) {
                return Err(WeftError::input(format!(
                    "{what} `{}` is {} in row {r}, which a log scale cannot take",
                    names[c], col[r]
                ))
                .in_file(&t.path)
                .in_column(names[c].clone())
                .expected("positive values")
                .hint(format!("--{what}-scale linear")));
            }
        }
    }
    Ok((0..t.num_rows())
        .map(|r| cols.iter().map(|c| c[r]).collect())
        .collect())
}
