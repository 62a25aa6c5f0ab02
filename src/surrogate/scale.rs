//! How a column is scaled and mapped to [−1, 1] before the fits (MATLAB's `mapminmax`).

use serde::{Deserialize, Serialize};

/// How a column is scaled before it is mapped to [−1, 1].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, clap::ValueEnum)]
#[serde(rename_all = "lowercase")]
pub enum Scale {
    Log,
    Linear,
}

/// `mapminmax`: v ↦ 2(s(v) − lo)/(hi − lo) − 1, s the scale; a constant column maps to 0.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct Map {
    pub scale: Scale,
    /// Range of s(v) over the training rows.
    pub lo: f64,
    pub hi: f64,
}

impl Map {
    pub(crate) fn fit(v: &[f64], scale: Scale) -> Map {
        let s: Vec<f64> = v.iter().map(|&x| scaled(x, scale)).collect();
        Map {
            scale,
            lo: s.iter().copied().fold(f64::INFINITY, f64::min),
            hi: s.iter().copied().fold(f64::NEG_INFINITY, f64::max),
        }
    }
    pub(crate) fn fwd(&self, v: f64) -> f64 {
        let w = self.hi - self.lo;
        if w > 0.0 {
            2.0 * (scaled(v, self.scale) - self.lo) / w - 1.0
        } else {
            0.0
        }
    }
    pub(crate) fn inv(&self, u: f64) -> f64 {
        let s = self.lo + (u + 1.0) * 0.5 * (self.hi - self.lo);
        match self.scale {
            Scale::Log => s.exp(),
            Scale::Linear => s,
        }
    }
}

fn scaled(x: f64, s: Scale) -> f64 {
    match s {
        Scale::Log => x.ln(),
        Scale::Linear => x,
    }
}
