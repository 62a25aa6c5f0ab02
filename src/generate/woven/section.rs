//! The yarn's cross-section as the mesh carries it: the lenticular section
//! ([`Lenticular`]) and its band of scaled nodal thicknesses ([`Section`]), and the crimp:
//! the amplitude at which crossing yarns just touch and the path length it adds.

use super::params::{WovenBandParams, YarnModel};
use crate::error::{Result, WeftError};

/// The lenticular section: arc radius R, thickness at y, exact area.
#[derive(Debug, Clone, Copy)]
pub struct Lenticular {
    pub w: f64,
    pub h: f64,
    pub r: f64,
}

impl Lenticular {
    pub fn new(w: f64, h: f64) -> Lenticular {
        Lenticular {
            w,
            h,
            r: (w * w + h * h) / (4.0 * h),
        }
    }
    /// t(y) = 2(√(R² − y²) − R + h/2), clamped at 0.
    pub fn thickness(&self, y: f64) -> f64 {
        let y = y.abs().min(0.5 * self.w);
        (2.0 * ((self.r * self.r - y * y).sqrt() - self.r + 0.5 * self.h)).max(0.0)
    }
    /// A band of `across` quads across the width: the node offsets from the centre line,
    /// their thickness t(y) scaled so that the one-point quads (mean of their nodal
    /// thicknesses) carry exactly [`Self::area`], and that scale.
    pub fn band(&self, across: usize) -> (Vec<f64>, Vec<f64>, f64) {
        let offs: Vec<f64> = (0..=across)
            .map(|k| -0.5 * self.w + self.w * k as f64 / across as f64)
            .collect();
        let t: Vec<f64> = offs.iter().map(|&y| self.thickness(y)).collect();
        let dy = self.w / across as f64;
        let trapezoid: f64 = (0..across).map(|k| 0.5 * dy * (t[k] + t[k + 1])).sum();
        let scale = self.area() / trapezoid;
        (offs, t.iter().map(|x| x * scale).collect(), scale)
    }
    /// Exact area of the two circular segments of chord w and height h/2.
    pub fn area(&self) -> f64 {
        let d = self.r - 0.5 * self.h;
        2.0 * (self.r * self.r * (d / self.r).acos() - d * (self.r * self.r - d * d).sqrt())
    }
}

/// The crimp amplitude at which truss chains of contact thickness t just touch: a node at
/// a crossing, z = a, lies t + 2 nm from the crossing yarn's chords, which leave its node
/// at z = −a along the cosine (z = −a cos(πs/p) at s = p/n). At a = t/2, the centre
/// lines' distance at the crossing, the chords rising from the lower node come within
/// 0.7 µm of the upper one (the default weave); the bands' curved faces do not.
pub fn chain_touching_amplitude(t: f64, p: f64, per_spacing: usize) -> f64 {
    use crate::solver::contact::projectile::closest_on_segment;
    let s = p / per_spacing as f64;
    // Distance from (0, 0, a) to the chord from (0, 0, −a) to (s, 0, −a cos(πs/p)).
    let dist = |a: f64| {
        let (node, c0) = ([0.0, 0.0, a], [0.0, 0.0, -a]);
        let c1 = [s, 0.0, -a * (std::f64::consts::PI * s / p).cos()];
        let u = closest_on_segment(&node, &c0, &c1);
        let foot: [f64; 3] = std::array::from_fn(|d| c0[d] + u * (c1[d] - c0[d]));
        crate::solver::vec3::norm(&crate::solver::vec3::sub(&node, &foot))
    };
    let want = t + 2e-9;
    let (mut lo, mut hi) = (0.5 * t, t);
    for _ in 0..100 {
        let mid = 0.5 * (lo + hi);
        if dist(mid) < want {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    hi
}

/// The band's cross-section as the mesh carries it.
pub(super) struct Section {
    pub(super) lens: Lenticular,
    /// Quads across the width (`across`).
    pub(super) na: usize,
    /// Offsets of the nodes across the band from its centre line, and their nodal
    /// thicknesses scaled by `scale` = A/A_h (see [`Lenticular::band`]).
    pub(super) offs: Vec<f64>,
    pub(super) t_node: Vec<f64>,
    pub(super) scale: f64,
    /// The (scaled) centre thickness t_c: the chains' contact thickness too.
    pub(super) t_centre: f64,
    /// Truss chains instead of bands.
    pub(super) chain: bool,
}

impl Section {
    pub(super) fn new(p: &WovenBandParams) -> Section {
        let lens = Lenticular::new(p.width, p.thickness);
        // Offsets across the band and the trapezoid area of the nodal profile.
        let na = p.across;
        let (offs, t_node, scale) = lens.band(na);
        let t_centre = t_node[na / 2];
        Section {
            lens,
            na,
            offs,
            t_node,
            scale,
            t_centre,
            chain: p.yarn_model == YarnModel::Chain,
        }
    }
}

/// The crimp amplitude a: the given one, which must be at least t_c/2, or by default the
/// one at which crossing yarns just touch (bands: t_c/2 + 1 nm; chains:
/// [`chain_touching_amplitude`]).
pub(super) fn crimp_amplitude(p: &WovenBandParams, s: &Section) -> Result<f64> {
    let t_centre = s.t_centre;
    let amp = p.crimp_amplitude.unwrap_or_else(|| {
        if s.chain {
            chain_touching_amplitude(t_centre, p.spacing, p.per_spacing)
        } else {
            0.5 * t_centre + 1e-9
        }
    });
    if amp < 0.5 * t_centre {
        return Err(WeftError::input(format!(
            "--crimp-amplitude = `{amp}` m is below half the yarns' centre thickness {:.4e} m",
            0.5 * t_centre
        ))
        .expected("a ≥ t_c/2: crossing yarns would start inside each other")
        .hint("leave --crimp-amplitude out for yarns that just touch"));
    }
    Ok(amp)
}

/// Crimp of z = a cos(πx/p): ∫₀^p √(1 + k² sin²) dx / p − 1, by Simpson's rule.
pub(super) fn crimp_of(amp: f64, spacing: f64) -> f64 {
    let k_c = std::f64::consts::PI * amp / spacing;
    let n = 2000;
    let f = |x: f64| (1.0 + (k_c * (std::f64::consts::PI * x).sin()).powi(2)).sqrt();
    let s: f64 = (0..=n)
        .map(|i| {
            let w = if i == 0 || i == n {
                1.0
            } else if i % 2 == 1 {
                4.0
            } else {
                2.0
            };
            w * f(i as f64 / n as f64)
        })
        .sum();
    s / (3.0 * n as f64) - 1.0
}
