//! Measure-and-match analyses on `history.parquet`: wave speeds along a line of nodes
//! (the paper's §3) and the displacement mismatch T between two models (its eq. 2).

pub mod energy;
pub mod error;
pub mod interp;
pub mod pulse;
pub mod series;
pub mod wavespeed;

pub use interp::{interpolation, match_ids, Matching, Pairing};
pub use series::{
    components, read_nodes, read_nodes_of, read_series, read_series_of, Series, COMPONENTS,
};

use std::collections::HashMap;

use crate::error::{Result, WeftError};

/// First time |y| reaches `level`, linearly interpolated; `None` if never.
pub fn arrival(t: &[f64], y: &[f64], level: f64) -> Option<f64> {
    if y.first().is_some_and(|v| v.abs() >= level) {
        return Some(t[0]);
    }
    (1..y.len()).find(|&k| y[k].abs() >= level).map(|k| {
        let (a, b) = (y[k - 1].abs(), y[k].abs());
        t[k - 1] + (level - a) / (b - a) * (t[k] - t[k - 1])
    })
}

/// Wave speeds along an ordered line of nodes.
#[derive(Debug, Clone)]
pub struct WaveSpeeds {
    pub node_id: Vec<i64>,
    /// Distance along the line from its first node [m].
    pub position: Vec<f64>,
    pub arrival: Vec<Option<f64>>,
    /// Speed over the segment from the previous node to this one [m/s].
    pub segment_speed: Vec<Option<f64>>,
    /// Speed over the node's two neighbouring segments, their length over their time
    /// (one segment at the ends, or where the other has no speed) [m/s].
    pub node_speed: Vec<Option<f64>>,
}

/// The level whose arrival times a wave's front.
#[derive(Debug, Clone, Copy)]
pub enum Level {
    /// One absolute level for all nodes [m or m/s].
    Absolute(f64),
    /// One level for all nodes: this fraction of the largest |value| anywhere on the line
    /// at any time (the paper's "pre-selected level").
    Line(f64),
    /// A fraction of each node's own peak |value|. Only for a clean single pulse: where a
    /// reflection adds to the incident wave (near a clamp) a node's peak is not the
    /// incident one, and a node that hardly moves (at the clamp) reaches half its tiny
    /// peak with the first ripple (the §4 figure showed −10 000 to −49 000 m/s there
    /// where the lattice's speed is 3180 m/s).
    Relative(f64),
}

/// Arrival times of a level along the line and the speeds between nodes (the paper's §3:
/// v = Δx/(t₂ − t₁), a node's speed over its two segments: 2Δx/(t₊ − t₋)). The speed is signed:
/// positive when the wave runs in the set's order.
///
/// The incident front only: from the node the level reaches first, the arrival times
/// must not decrease outwards along the line in either direction; the first node where
/// one does (or that the level never reaches) and every node beyond it count as not
/// reached by the incident front (a later crossing is a reflection, or a wave that came
/// another way).
pub fn wave_speeds(s: &Series, component: usize, level: Level) -> WaveSpeeds {
    wave_speeds_with(s, component, level, 0.0)
}

/// [`wave_speeds`] with a slack: outwards from the node reached first, an arrival may
/// fall back by up to `slack` seconds behind the latest one so far and still count as
/// the incident front (a node the level reaches a little early: a tied interface node
/// on the membrane's plane, flat, beside a crimped crossing), instead of cutting the line
/// there. A segment whose arrival does not advance outwards gets no speed; its nodes keep
/// the speed of their other segment.
pub fn wave_speeds_with(s: &Series, component: usize, level: Level, slack: f64) -> WaveSpeeds {
    let n = s.node_id.len();
    let mut position = vec![0.0; n];
    for j in 1..n {
        let d: f64 = (0..3)
            .map(|c| (s.x0[j][c] - s.x0[j - 1][c]).powi(2))
            .sum::<f64>()
            .sqrt();
        position[j] = position[j - 1] + d;
    }
    let line_peak = s
        .values
        .iter()
        .flat_map(|v| v.iter().map(|u| u[component].abs()))
        .fold(0.0, f64::max);
    let mut arrival: Vec<Option<f64>> = (0..n)
        .map(|j| {
            let y: Vec<f64> = s.values.iter().map(|v| v[j][component]).collect();
            let lv = match level {
                Level::Absolute(a) => a,
                Level::Line(f) => f * line_peak,
                Level::Relative(f) => f * y.iter().map(|v| v.abs()).fold(0.0, f64::max),
            };
            if lv <= 0.0 {
                None
            } else {
                arrival(&s.t, &y, lv)
            }
        })
        .collect();
    let first = (0..n)
        .filter_map(|j| arrival[j].map(|a| (j, a)))
        .min_by(|a, b| a.1.total_cmp(&b.1))
        .map(|(j, _)| j);
    if let Some(j0) = first {
        for dir in [1isize, -1] {
            let mut last = arrival[j0].unwrap_or(f64::NEG_INFINITY);
            let mut cut = false;
            let mut j = j0 as isize + dir;
            while j >= 0 && (j as usize) < n {
                let a = &mut arrival[j as usize];
                match *a {
                    Some(t) if !cut && t >= last - slack => last = last.max(t),
                    _ => {
                        cut = true;
                        *a = None;
                    }
                }
                j += dir;
            }
        }
    }
    let segment_speed: Vec<Option<f64>> = (0..n)
        .map(|j| {
            if j == 0 {
                return None;
            }
            // Outwards from the first node reached, arrivals advance: later to the right
            // of it, earlier to its left (a wave running against the set's order).
            let outward = first.is_none_or(|j0| j > j0);
            match (arrival[j - 1], arrival[j]) {
                (Some(a), Some(b)) if (outward && b > a) || (!outward && b < a) => {
                    Some((position[j] - position[j - 1]) / (b - a))
                }
                _ => None,
            }
        })
        .collect();
    // A node between two segments of one direction: their length over their time, the
    // central difference 2Δx/(t₊ − t₋) (the mean of the two segments' slownesses, length
    // weighted). An offset that alternates from node to node cancels in it, where the
    // mean of the two speeds does not: the crossings of a crimped yarn lie alternately
    // above and below its plane, and the crimp interchange ahead of the transverse front
    // moves them ±0.08 mm apart (60 × 60 reference, §3), so a level arrives alternately
    // early and late: segments of 584 and 91 810 m/s, whose mean 46 197 m/s the §3
    // figure showed, the central difference 1 160 m/s.
    let node_speed = (0..n)
        .map(|j| {
            let right = segment_speed.get(j + 1).copied().flatten();
            match (segment_speed[j], right) {
                (Some(a), Some(b)) if a.signum() == b.signum() => {
                    let (ta, tb) = (arrival[j - 1]?, arrival[j + 1]?);
                    Some((position[j + 1] - position[j - 1]) / (tb - ta))
                }
                (Some(a), Some(b)) => Some(0.5 * (a + b)),
                (Some(a), None) | (None, Some(a)) => Some(a),
                (None, None) => None,
            }
        })
        .collect();
    WaveSpeeds {
        node_id: s.node_id.clone(),
        position,
        arrival,
        segment_speed,
        node_speed,
    }
}

/// The mismatch between a candidate (p, the reduced model) and a reference (q).
#[derive(Debug, Clone)]
pub struct Mismatch {
    /// T = ∫Σ‖p − q‖² dt / ∫Σ(‖p‖² + ‖q‖²) dt (without the integrals in static mode).
    pub t_value: f64,
    /// Per reference node: (reference id, candidate id, peak ‖p − q‖ / peak ‖q‖).
    pub per_node: Vec<(i64, i64, f64)>,
    pub max_peak_relative_error: f64,
    pub samples: usize,
}

/// For each reference node, the candidate node nearest to it (within `tol` metres).
///
/// Two candidate nodes within `tol` of a reference node (coincident nodes, as the warp
/// and weft nodes of a crossing) are a tie that position cannot break: an error, never a
/// silent pick of one of them.
pub fn match_nodes(reference: &Series, candidate: &Series, tol: f64) -> Result<Vec<usize>> {
    let mut used = HashMap::new();
    let mut out = Vec::with_capacity(reference.node_id.len());
    const HOW: &str =
        "compare node sets that hold one node per position (--set, --candidate-set), \
                       or match by node id (--match id) when both models number the nodes alike";
    for (j, x) in reference.x0.iter().enumerate() {
        let d = |y: &[f64; 3]| {
            ((x[0] - y[0]).powi(2) + (x[1] - y[1]).powi(2) + (x[2] - y[2]).powi(2)).sqrt()
        };
        let (k, dk) = candidate
            .x0
            .iter()
            .enumerate()
            .map(|(k, y)| (k, d(y)))
            .min_by(|a, b| a.1.total_cmp(&b.1))
            .ok_or_else(|| WeftError::input("the candidate node set is empty"))?;
        if dk > tol {
            return Err(WeftError::input(format!(
                "reference node `{}` at {:?} has no candidate node within {tol:e} m (nearest: `{}` at {dk:.3e} m)",
                reference.node_id[j], x, candidate.node_id[k]
            ))
            .expected("a candidate node at every reference position")
            .hint("compare node sets on the same positions, raise --tolerance, or interpolate in the candidate's elements (--match interpolate) when the meshes differ"));
        }
        let near: Vec<(usize, f64)> = candidate
            .x0
            .iter()
            .enumerate()
            .map(|(k, y)| (k, d(y)))
            .filter(|&(_, e)| e <= tol)
            .collect();
        if near.len() > 1 {
            return Err(WeftError::input(format!(
                "reference node `{}` at {:?} is tied between {} candidate nodes within {tol:e} m: {}",
                reference.node_id[j],
                x,
                near.len(),
                near.iter()
                    .map(|&(k, e)| format!("`{}` at {e:.3e} m", candidate.node_id[k]))
                    .collect::<Vec<_>>()
                    .join(", ")
            ))
            .expected("one candidate node per reference position (coincident nodes, as at a yarn crossing, cannot be told apart by position)")
            .hint(HOW));
        }
        if let Some(prev) = used.insert(k, j) {
            return Err(WeftError::input(format!(
                "reference nodes `{}` and `{}` both match candidate node `{}` (at {:.3e} m and {dk:.3e} m)",
                reference.node_id[prev],
                reference.node_id[j],
                candidate.node_id[k],
                dist3(&reference.x0[prev], &candidate.x0[k]),
            ))
            .expected("one candidate node per reference node")
            .hint(if dk < tol * 0.5 && dist3(&reference.x0[prev], &candidate.x0[k]) < tol * 0.5 {
                HOW.to_string()
            } else {
                format!("lower --tolerance, or {HOW}")
            }));
        }
        out.push(k);
    }
    Ok(out)
}

fn dist3(a: &[f64; 3], b: &[f64; 3]) -> f64 {
    ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt()
}

/// Pair reference nodes with candidate series entries by position or by id (see
/// [`Matching`]); interpolation needs the candidate's elements: [`interpolation`].
pub fn pair(reference: &Series, candidate: &Series, tol: f64, how: Matching) -> Result<Pairing> {
    let k = match how {
        Matching::Position => match_nodes(reference, candidate, tol)?,
        Matching::Id => match_ids(reference, candidate)?,
        Matching::Interpolate => {
            return Err(
                WeftError::input("interpolation needs the candidate model's elements")
                    .expected("analysis::interpolation to pair the nodes"),
            )
        }
    };
    Ok(k.into_iter().map(|k| vec![(k, 1.0)]).collect())
}

/// Linear interpolation of the candidate's samples onto times `t`.
fn resample(c: &Series, t: &[f64]) -> Result<Vec<Vec<[f64; 6]>>> {
    if c.t == t {
        return Ok(c.values.clone());
    }
    let (t0, t1) = (c.t[0], *c.t.last().expect("samples"));
    let eps = 1e-9 * (t1 - t0).abs().max(1e-30);
    t.iter()
        .map(|&tt| {
            if tt < t0 - eps || tt > t1 + eps {
                return Err(WeftError::input(format!("the candidate history covers [{t0:e}, {t1:e}] s but the reference has a sample at {tt:e} s"))
                    .expected("a candidate history that covers the reference's time grid")
                    .hint("simulate the candidate at least as long as the reference"));
            }
            let k = c.t.partition_point(|&x| x <= tt).clamp(1, c.t.len().max(2) - 1);
            if c.t.len() == 1 {
                return Ok(c.values[0].clone());
            }
            let w = ((tt - c.t[k - 1]) / (c.t[k] - c.t[k - 1])).clamp(0.0, 1.0);
            Ok((0..c.node_id.len()).map(|j| std::array::from_fn(|q| c.values[k - 1][j][q] + w * (c.values[k][j][q] - c.values[k - 1][j][q]))).collect())
        })
        .collect()
}

/// T between a candidate p and a reference q over matched nodes and chosen components;
/// `static_mode` compares the last samples only.
pub fn mismatch(
    reference: &Series,
    candidate: &Series,
    comps: &[usize],
    tol: f64,
    static_mode: bool,
) -> Result<Mismatch> {
    let pairs = pair(reference, candidate, tol, Matching::Position)?;
    mismatch_paired(reference, candidate, &pairs, comps, static_mode)
}

/// T between a candidate and a reference whose nodes are paired by `pairs` (a
/// reference node's candidate value is the weighted sum of the candidate entries).
pub fn mismatch_paired(
    reference: &Series,
    candidate: &Series,
    pairs: &Pairing,
    comps: &[usize],
    static_mode: bool,
) -> Result<Mismatch> {
    let (t, q_all): (Vec<f64>, Vec<Vec<[f64; 6]>>) = if static_mode {
        (
            vec![*reference.t.last().expect("samples")],
            vec![reference.values.last().expect("samples").clone()],
        )
    } else {
        (reference.t.clone(), reference.values.clone())
    };
    let p_all = if static_mode {
        vec![candidate.values.last().expect("samples").clone()]
    } else {
        resample(candidate, &t)?
    };
    let n = pairs.len();
    let mut num = vec![0.0; t.len()];
    let mut den = vec![0.0; t.len()];
    let mut peak_d = vec![0.0f64; n];
    let mut peak_q = vec![0.0f64; n];
    for k in 0..t.len() {
        for (j, w) in pairs.iter().enumerate() {
            let (mut d2, mut p2, mut q2) = (0.0, 0.0, 0.0);
            for &comp in comps {
                let p: f64 = w.iter().map(|&(c, wt)| wt * p_all[k][c][comp]).sum();
                let q = q_all[k][j][comp];
                d2 += (p - q) * (p - q);
                p2 += p * p;
                q2 += q * q;
            }
            num[k] += d2;
            den[k] += p2 + q2;
            peak_d[j] = peak_d[j].max(d2.sqrt());
            peak_q[j] = peak_q[j].max(q2.sqrt());
        }
    }
    let integrate = |f: &[f64]| -> f64 {
        if f.len() == 1 {
            f[0]
        } else {
            (1..f.len())
                .map(|k| 0.5 * (f[k] + f[k - 1]) * (t[k] - t[k - 1]))
                .sum()
        }
    };
    let (nu, de) = (integrate(&num), integrate(&den));
    if de <= 0.0 {
        return Err(WeftError::input(
            "both histories are zero on the compared nodes and components",
        )
        .expected("some motion to compare"));
    }
    let per_node: Vec<(i64, i64, f64)> = (0..n)
        .map(|j| {
            (
                reference.node_id[j],
                // The entry of largest weight (the node itself unless interpolated).
                candidate.node_id[pairs[j]
                    .iter()
                    .fold((0usize, f64::NEG_INFINITY), |b, &(c, w)| {
                        if w > b.1 {
                            (c, w)
                        } else {
                            b
                        }
                    })
                    .0],
                if peak_q[j] > 0.0 {
                    peak_d[j] / peak_q[j]
                } else {
                    f64::NAN
                },
            )
        })
        .collect();
    let max = per_node
        .iter()
        .map(|r| r.2)
        .filter(|v| v.is_finite())
        .fold(0.0, f64::max);
    Ok(Mismatch {
        t_value: nu / de,
        per_node,
        max_peak_relative_error: max,
        samples: t.len(),
    })
}
