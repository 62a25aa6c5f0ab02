//! The projectile's velocity history as a fit's objective: what a ballistic limit depends
//! on (the deceleration while the fabric holds, the perforation time, the residual
//! velocity after), which a reduced model and the yarn-level reference can share once
//! yarns fail, when their displacement histories no longer match node by node.
//!
//! - v(t) is the first projectile's velocity component along its initial direction of
//!   flight (positive into the target): from the reference run's `projectile.parquet`
//!   (result table), and from the candidate's in-process run at its output samples (a
//!   rigid projectile's velocity; a deformable bullet's momentum over its mass, the node
//!   set [`crate::model::striker::BULLET_SET`]).
//! - P = Σ_k (v_c(t_k) − v_r(t_k))² / Σ_k (v_c(t_k)² + v_r(t_k)²) over the reference's
//!   output times t_k: T's form, 0 when the histories are equal, at most 2. The candidate's
//!   samples are interpolated linearly at the reference's times; past its last sample (a
//!   run that ended at its outcome, `stop_on_outcome`) its last velocity holds: free
//!   flight after a perforation, rest after an arrest.
//! - The two must strike at the same speed (relative [`SPEED_TOLERANCE`]): P compares
//!   the histories of one impact.

use std::path::{Path, PathBuf};

use crate::error::{Result, WeftError};
use crate::model::striker::BULLET_SET;
use crate::model::Model;
use crate::solver::output::MemorySink;
use crate::table::Table;

/// Relative difference of the striking speeds within which a candidate and its reference
/// count as the same impact.
pub const SPEED_TOLERANCE: f64 = 1e-9;

/// The reference run's table of the projectile's states, beside its `history.parquet`.
pub const FILE: &str = "projectile.parquet";

/// A projectile's velocity along its initial direction of flight at output times.
#[derive(Debug, Clone, PartialEq)]
pub struct VelocityHistory {
    /// Output times [s], increasing.
    pub t: Vec<f64>,
    /// Velocity along the initial direction of flight [m/s] (positive into the target).
    pub v: Vec<f64>,
    /// The speed at the first sample (t = 0) [m/s].
    pub striking_speed: f64,
    /// The table it was read from (a reference), for messages.
    pub source: Option<PathBuf>,
}

/// The candidate's velocities at the times `times`: linear interpolation between its
/// samples, its first value before its first sample and its last value after its last
/// (the run ended at its outcome; no sample: 0).
pub fn at_times(candidate: &VelocityHistory, times: &[f64]) -> Vec<f64> {
    let (t, v) = (&candidate.t, &candidate.v);
    let Some(&last) = v.last() else {
        return vec![0.0; times.len()];
    };
    let mut i = 0;
    times
        .iter()
        .map(|&tk| {
            if tk >= t[t.len() - 1] {
                return last;
            }
            if tk <= t[0] {
                return v[0];
            }
            // t[i] ≤ tk < t[i + 1]: the reference's times increase, so i only advances.
            while t[i + 1] <= tk {
                i += 1;
            }
            if tk == t[i] {
                v[i]
            } else {
                let w = (tk - t[i]) / (t[i + 1] - t[i]);
                v[i] + w * (v[i + 1] - v[i])
            }
        })
        .collect()
}

/// P of a candidate against a reference (see the module's docs): 0 when equal. The
/// reference strikes at a speed > 0 ([`read_reference`] checks it), so the denominator
/// is > 0.
pub fn mismatch(reference: &VelocityHistory, candidate: &VelocityHistory) -> f64 {
    let vc = at_times(candidate, &reference.t);
    let (mut num, mut den) = (0.0, 0.0);
    for (c, r) in vc.iter().zip(&reference.v) {
        num += (c - r) * (c - r);
        den += c * c + r * r;
    }
    num / den
}

/// Where a case's reference projectile table is: `given` (`--reference-projectile`), else
/// the `projectile.parquet` in the folder of its `history.parquet`.
pub fn reference_path(history: &Path, given: Option<&Path>) -> PathBuf {
    match given {
        Some(p) => p.to_path_buf(),
        None => history
            .parent()
            .map_or_else(|| PathBuf::from(FILE), |d| d.join(FILE)),
    }
}

const COLUMNS: &str = "t, projectile_id, vx, vy, vz (a result projectile.parquet, docs/tables.md)";

/// Read the first projectile's velocity history from a result `projectile.parquet` (its
/// first row's `projectile_id`): times increasing from t = 0, a speed > 0 at t = 0,
/// whose direction is the direction of flight.
pub fn read_reference(path: &Path) -> Result<VelocityHistory> {
    if !path.is_file() {
        return Err(WeftError::input("no reference projectile table")
            .in_file(path)
            .expected("the reference run's projectile.parquet (weft-simulate writes it beside history.parquet when the model has a rigid projectile)")
            .hint("give the file with --reference-projectile FILE (one per case), or rerun the reference with a rigid projectile (weft-simulate writes none for a deformable bullet)"));
    }
    let tab = Table::read(path)?;
    let t = tab.f64("t", COLUMNS)?;
    let id = tab.i64("projectile_id", COLUMNS)?;
    let vel = [
        tab.f64("vx", COLUMNS)?,
        tab.f64("vy", COLUMNS)?,
        tab.f64("vz", COLUMNS)?,
    ];
    let Some(&first) = id.first() else {
        return Err(WeftError::input("the projectile table has no rows")
            .in_file(path)
            .expected("one row per output time and projectile"));
    };
    let rows: Vec<usize> = (0..id.len()).filter(|&r| id[r] == first).collect();
    let r0 = rows[0];
    if t[r0].abs() > 1e-12 {
        return Err(tab
            .value_error(
                "t",
                r0,
                format!("projectile {first}'s first sample is at t = {:e} s", t[r0]),
            )
            .expected("the first sample at t = 0 (the striking velocity)"));
    }
    for w in rows.windows(2) {
        if t[w[1]] <= t[w[0]] {
            return Err(tab
                .value_error(
                    "t",
                    w[1],
                    format!(
                        "projectile {first}: t = {:e} s after t = {:e} s",
                        t[w[1]], t[w[0]]
                    ),
                )
                .expected("increasing output times for each projectile"));
        }
    }
    let v0 = [vel[0][r0], vel[1][r0], vel[2][r0]];
    let speed = norm(&v0);
    if !(speed > 0.0 && speed.is_finite()) {
        return Err(tab
            .value_error(
                "vx",
                r0,
                format!("projectile {first} is at rest at t = 0 (speed {speed:e} m/s)"),
            )
            .expected(
                "a projectile in flight at t = 0: its velocity sets the direction of flight",
            ));
    }
    let dir = [v0[0] / speed, v0[1] / speed, v0[2] / speed];
    Ok(VelocityHistory {
        t: rows.iter().map(|&r| t[r]).collect(),
        v: rows
            .iter()
            .map(|&r| vel[0][r] * dir[0] + vel[1][r] * dir[1] + vel[2][r] * dir[2])
            .collect(),
        striking_speed: speed,
        source: Some(path.to_path_buf()),
    })
}

fn norm(v: &[f64; 3]) -> f64 {
    (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt()
}

/// What strikes in a model, as the projectile objective follows it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Striker {
    /// The first rigid projectile (its id).
    Rigid { id: i64 },
    /// The deformable bullet: the node set [`BULLET_SET`].
    Bullet,
}

/// A model's striker, its initial direction of flight (unit) and striking speed [m/s]:
/// the first rigid projectile's velocity, or a deformable bullet's mean initial velocity
/// over its nodes (its direction as [`Model::bullet_direction`]); `None` without either.
pub fn striker(m: &Model) -> Option<(Striker, [f64; 3], f64)> {
    if let Some(p) = m.projectiles.first() {
        let speed = norm(&p.velocity);
        let dir = if speed > 0.0 {
            [
                p.velocity[0] / speed,
                p.velocity[1] / speed,
                p.velocity[2] / speed,
            ]
        } else {
            p.axis
        };
        return Some((Striker::Rigid { id: p.id }, dir, speed));
    }
    let nodes = m.bullet_nodes()?;
    let dir = m.bullet_direction()?;
    let mut in_set = vec![false; m.num_nodes()];
    for &i in nodes {
        in_set[i] = true;
    }
    let mut s = [0.0; 3];
    for (i, v) in &m.initial_velocities {
        if in_set[*i] {
            for d in 0..3 {
                s[d] += v[d];
            }
        }
    }
    let n = nodes.len().max(1) as f64;
    Some((Striker::Bullet, dir, norm(&[s[0] / n, s[1] / n, s[2] / n])))
}

/// The nodes whose history the candidate's run must record for its striker: a bullet's.
pub fn output_set(m: &Model) -> Option<&'static str> {
    match striker(m)? {
        (Striker::Bullet, _, _) => Some(BULLET_SET),
        _ => None,
    }
}

/// The candidate's velocity history from its run: the rigid projectile's rows of the
/// sink, or the bullet's momentum over its mass (`mass`: the solver's lumped nodal
/// masses) from the sink's node velocities (the run recorded [`output_set`]).
pub fn from_run(m: &Model, sink: &MemorySink, mass: &[f64]) -> Option<VelocityHistory> {
    let (s, dir, speed) = striker(m)?;
    let along = |v: &[f64]| v[0] * dir[0] + v[1] * dir[1] + v[2] * dir[2];
    let (t, v) = match s {
        Striker::Rigid { id } => sink
            .projectile
            .iter()
            .filter(|r| r.1 == id)
            .map(|r| (r.0, along(&r.2[3..6])))
            .unzip(),
        Striker::Bullet => {
            let nodes = m.bullet_nodes()?;
            let mut in_set = vec![false; m.num_nodes()];
            for &i in nodes {
                in_set[i] = true;
            }
            let cols: Vec<usize> = (0..sink.nodes.len())
                .filter(|&j| in_set[sink.nodes[j]])
                .collect();
            let total: f64 = cols.iter().map(|&j| mass[sink.nodes[j]]).sum();
            let v = sink
                .v
                .iter()
                .map(|vk| {
                    let mut p = [0.0; 3];
                    for &j in &cols {
                        let mi = mass[sink.nodes[j]];
                        for d in 0..3 {
                            p[d] += mi * vk[j][d];
                        }
                    }
                    along(&[p[0] / total, p[1] / total, p[2] / total])
                })
                .collect();
            (sink.t.clone(), v)
        }
    };
    Some(VelocityHistory {
        t,
        v,
        striking_speed: speed,
        source: None,
    })
}

/// A case's candidate can be compared with its reference: it has a striker that strikes
/// at the reference's speed, and its run reaches the reference's last output time (or
/// ends at its outcome before, when the last velocity holds).
pub fn check_case(case: &str, m: &Model, reference: &VelocityHistory) -> Result<()> {
    let src = reference
        .source
        .as_ref()
        .map_or_else(String::new, |p| format!(" (`{}`)", p.display()));
    let Some((_, _, speed)) = striker(m) else {
        return Err(WeftError::input(format!(
            "case `{case}`: the candidate model has no projectile"
        ))
        .expected("a candidate with a rigid projectile (projectile.parquet) or a deformable bullet (node set `bullet`): the projectile objective compares its velocity history with the reference's")
        .hint("weave the candidate with its projectile (weft-weave woven, woven-reduced), or fit without --objective projectile and --projectile-weight"));
    };
    let r = reference.striking_speed;
    if (speed - r).abs() > SPEED_TOLERANCE * r {
        return Err(WeftError::input(format!(
            "case `{case}`: the candidate strikes at {speed} m/s, the reference at {r} m/s{src}"
        ))
        .expected(format!(
            "the same striking speed (relative {SPEED_TOLERANCE:e}): P compares the velocity histories of one impact"
        ))
        .hint(format!(
            "weave the candidate with the reference's --projectile-velocity {r}"
        )));
    }
    let a = &m.analysis;
    let last = (a.end_time / a.output_interval).round() * a.output_interval;
    let r_last = *reference.t.last().expect("read_reference: rows");
    if r_last > last + 1e-9 * a.output_interval {
        return Err(WeftError::input(format!(
            "case `{case}`: the candidate's run ends at t = {last:e} s (analysis end_time), before the reference's last output time {r_last:e} s{src}"
        ))
        .expected("a candidate run that lasts as long as the reference's (it may end earlier at its outcome, stop_on_outcome)")
        .hint(format!("weave the candidate with --end-time {r_last:e} or more")));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn h(t: &[f64], v: &[f64]) -> VelocityHistory {
        VelocityHistory {
            t: t.to_vec(),
            v: v.to_vec(),
            striking_speed: v.first().copied().unwrap_or(0.0),
            source: None,
        }
    }

    /// Interpolation between samples, the first value before them, the last after.
    #[test]
    fn interpolates_and_holds() {
        let c = h(&[0.0, 2.0, 4.0], &[10.0, 6.0, 5.0]);
        assert_eq!(
            at_times(&c, &[0.0, 1.0, 2.0, 3.0, 4.0, 7.0]),
            vec![10.0, 8.0, 6.0, 5.5, 5.0, 5.0]
        );
        assert_eq!(at_times(&h(&[], &[]), &[1.0]), vec![0.0]);
    }
}
