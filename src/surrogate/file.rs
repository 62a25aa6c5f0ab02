//! The surrogate file (`surrogate.json`): what `weft-surrogate train` writes and
//! `predict` reads, and its predictions in raw units.

use std::path::Path;

use serde::{Deserialize, Serialize};

use super::network::Network;
use super::regression::Regression;
use super::scale::Map;
use crate::error::{Result, WeftError};

/// Format tag of the surrogate file.
pub const FORMAT: &str = "weft-surrogate 1";

/// The surrogate file (JSON): columns, their maps, the training inputs' range, the
/// regression and the chosen network, and their test MSEs.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct Surrogate {
    pub format: String,
    pub inputs: Vec<String>,
    pub outputs: Vec<String>,
    pub input_maps: Vec<Map>,
    pub output_maps: Vec<Map>,
    /// Per input, [min, max] over the training table (raw units).
    pub input_range: Vec<[f64; 2]>,
    pub regression: Regression,
    pub network: Network,
    pub regression_test_mse: f64,
    pub network_test_mse: f64,
    pub network_validation_mse: f64,
    /// The stage's settings and input hashes.
    pub provenance: serde_json::Value,
}

/// Write `v` as pretty JSON beside the target, then rename it into place.
pub(crate) fn write_json<T: Serialize>(path: &Path, v: &T) -> Result<()> {
    let text = serde_json::to_string_pretty(v).expect("serialises");
    let name = path
        .file_name()
        .expect("a file name")
        .to_string_lossy()
        .to_string();
    let tmp = path.with_file_name(format!(".{name}.tmp-{}", std::process::id()));
    std::fs::write(&tmp, text).map_err(|e| WeftError::io(&tmp, e))?;
    std::fs::rename(&tmp, path).map_err(|e| WeftError::io(path, e))
}

impl Surrogate {
    /// Read and check a surrogate file.
    pub fn read(path: &Path) -> Result<Surrogate> {
        let text = std::fs::read_to_string(path).map_err(|e| WeftError::io(path, e))?;
        let s: Surrogate = serde_json::from_str(&text).map_err(|e| {
            WeftError::input(format!("cannot read the surrogate: {e}"))
                .in_file(path)
                .expected(format!("a `{FORMAT}` file written by weft-surrogate train"))
        })?;
        if s.format != FORMAT {
            return Err(WeftError::input(format!("surrogate format `{}`", s.format))
                .in_file(path)
                .expected(format!("`{FORMAT}`")));
        }
        Ok(s)
    }
    fn normalise(&self, x: &[f64]) -> Vec<f64> {
        x.iter()
            .zip(&self.input_maps)
            .map(|(v, m)| m.fwd(*v))
            .collect()
    }
    fn denormalise(&self, v: Vec<f64>) -> Vec<f64> {
        v.iter()
            .zip(&self.output_maps)
            .map(|(v, m)| m.inv(*v))
            .collect()
    }
    /// The regression's y at x (raw units).
    pub fn predict_regression(&self, x: &[f64]) -> Vec<f64> {
        self.denormalise(self.regression.predict(&self.normalise(x)))
    }
    /// The network's y at x (raw units).
    pub fn predict_network(&self, x: &[f64]) -> Vec<f64> {
        self.denormalise(self.network.predict(&self.normalise(x)))
    }
}
