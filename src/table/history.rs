//! `history.parquet` (docs/tables.md): one row per output time and node, columns `t`,
//! `node_id` and the six components [`COMPONENTS`], rows ordered by time as
//! `weft-simulate` writes them. [`History`] reads it once for every stage that takes a
//! history (`weft-vtk`, `weft-plot`'s figures, the analyses): the column list, the
//! checks and their messages are written here only.

use std::path::Path;

use super::Table;
use crate::error::{Result, WeftError};

/// Component names of `history.parquet`, in [`History::values`] order (and in
/// `analysis::Series::values` order): displacement, then velocity.
pub const COMPONENTS: [&str; 6] = ["ux", "uy", "uz", "vx", "vy", "vz"];

/// Largest |value| whose square (summed over nodes and samples) cannot overflow.
const SQUARE_LIMIT: f64 = 1e150;

/// A history table read into columns.
pub struct History {
    table: Table,
    /// Output time of each row [s].
    pub t: Vec<f64>,
    pub node_id: Vec<i64>,
    /// `values[c][r]`: component c ([`COMPONENTS`] order) of row r; NaN throughout a
    /// column the reader did not need and the table lacks.
    pub values: [Vec<f64>; 6],
}

impl History {
    /// Read a history with all six components.
    pub fn read(path: &Path) -> Result<History> {
        Self::read_components(path, &[0, 1, 2, 3, 4, 5])
    }

    /// Read a history needing only components `needed` (0..6 = ux … vz): a table without
    /// the others (a displacement-only history) reads with them NaN. A table with no rows
    /// is refused.
    pub fn read_components(path: &Path, needed: &[usize]) -> Result<History> {
        let h = Table::read(path)?;
        let cols_text = format!(
            "t, node_id, {}",
            needed
                .iter()
                .map(|&c| COMPONENTS[c])
                .collect::<Vec<_>>()
                .join(", ")
        );
        let t = h.f64("t", &cols_text)?;
        let ids = h.i64("node_id", &cols_text)?;
        let mut values: [Vec<f64>; 6] = Default::default();
        for (k, c) in COMPONENTS.iter().enumerate() {
            values[k] = if needed.contains(&k) || h.has(c) {
                h.f64(c, &cols_text)?
            } else {
                vec![f64::NAN; t.len()]
            };
        }
        if t.is_empty() {
            return Err(WeftError::input("the history has no rows")
                .in_file(path)
                .hint("was the run interrupted? rerun weft-simulate"));
        }
        Ok(History {
            table: h,
            t,
            node_id: ids,
            values,
        })
    }

    /// The file read.
    pub fn path(&self) -> &Path {
        &self.table.path
    }

    /// The six components of row `r`.
    pub fn row(&self, r: usize) -> [f64; 6] {
        std::array::from_fn(|c| self.values[c][r])
    }

    /// Error for a value in a given row.
    pub fn value_error(&self, col: &str, row: usize, what: String) -> WeftError {
        self.table.value_error(col, row, what)
    }

    /// Refuse a value whose square overflows (|value| > 1e150): a sum of squares of it
    /// would be inf or NaN, named nowhere. `expected` says what the caller needs.
    pub fn refuse_overflowing_squares(&self, expected: &str) -> Result<()> {
        for (c, col) in self.values.iter().enumerate() {
            if let Some(r) = col.iter().position(|x| x.abs() > SQUARE_LIMIT) {
                return Err(self
                    .value_error(COMPONENTS[c], r, format!("value `{:e}`", col[r]))
                    .expected(expected.to_string()));
            }
        }
        Ok(())
    }

    /// Walk the rows in order, grouped by output time: `row(k, r)` for row r of the k-th
    /// output time (k counts the distinct times so far). Returns the output times. A time
    /// before the previous row's is refused where it is met, so that `row`'s own
    /// refusals of earlier rows come first.
    pub fn by_time(&self, mut row: impl FnMut(usize, usize) -> Result<()>) -> Result<Vec<f64>> {
        let t = &self.t;
        let mut times: Vec<f64> = vec![];
        for r in 0..t.len() {
            if times.last() != Some(&t[r]) {
                if let Some(&last) = times.last() {
                    if t[r] < last {
                        return Err(self
                            .value_error("t", r, format!("time `{}` after `{last}`", t[r]))
                            .expected("rows ordered by time, as weft-simulate writes them"));
                    }
                }
                times.push(t[r]);
            }
            row(times.len() - 1, r)?;
        }
        Ok(times)
    }
}
