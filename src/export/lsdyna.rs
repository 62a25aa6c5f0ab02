//! LS-DYNA keyword deck (`.k`).

use super::Report;
use crate::error::{Result, WeftError};
use crate::model::Model;

/// The deck and what it holds.
pub fn deck(_m: &Model, _dt: f64, _provenance: &str) -> Result<(String, Report)> {
    Err(WeftError::input("LS-DYNA export is not built yet"))
}
