//! What strikes the target: the rigid projectiles (`projectile.parquet`) or a deformable
//! bullet, the hexahedra whose nodes form the node set [`BULLET_SET`] (`weft-weave woven
//! --projectile deformable` writes it). One place for what the stages that set a striking
//! speed (`weft-simulate --projectile-velocity`, `weft-ballistic search`) and the run's
//! watch of the outcome need of either.

use super::types::Model;
use crate::error::{Result, WeftError};

/// A striking speed `v` [m/s], given by `flag` (`--projectile-velocity` of the woven
/// generators and of `weft-simulate`), must be finite and ≥ 0: the projectile flies
/// along its axis, towards the fabric, so the speed carries no sign. One wording
/// wherever a speed is given.
pub fn check_striking_speed(flag: &str, v: f64) -> Result<()> {
    if v.is_finite() && v >= 0.0 {
        return Ok(());
    }
    Err(WeftError::input(format!("{flag} = `{v}`"))
        .expected("a finite striking speed ≥ 0 in m/s")
        .hint("give the speed without a sign: the projectile flies along its axis, towards the fabric (0: at rest)"))
}

/// The node set of a deformable projectile.
pub const BULLET_SET: &str = "bullet";

/// A point of a bullet's axis, from its initial positions `x` and direction `a`: of its
/// most advanced nodes (its tip face, within 10⁻⁹ of the largest x·a), the one nearest
/// the line through the origin along `a`, where the generators put the axis (a quarter or
/// whole bullet alike: the tip face's centre node).
pub fn axis_point(x: &[[f64; 3]], a: [f64; 3]) -> [f64; 3] {
    let along = |p: &[f64; 3]| p[0] * a[0] + p[1] * a[1] + p[2] * a[2];
    let lateral = |p: &[f64; 3]| {
        let s = along(p);
        let r = [p[0] - s * a[0], p[1] - s * a[1], p[2] - s * a[2]];
        r[0] * r[0] + r[1] * r[1] + r[2] * r[2]
    };
    let front = x.iter().map(along).fold(f64::NEG_INFINITY, f64::max);
    x.iter()
        .filter(|p| along(p) >= front - 1e-9)
        .copied()
        .min_by(|p, q| lateral(p).total_cmp(&lateral(q)))
        .unwrap_or([0.0; 3])
}

impl Model {
    /// Whether something strikes: a rigid projectile or a deformable bullet.
    pub fn has_striker(&self) -> bool {
        !self.projectiles.is_empty() || self.node_sets.contains_key(BULLET_SET)
    }

    /// The deformable bullet's nodes, when the model has one (and no rigid projectile,
    /// which takes precedence).
    pub fn bullet_nodes(&self) -> Option<&[usize]> {
        if !self.projectiles.is_empty() {
            return None;
        }
        self.node_sets.get(BULLET_SET).map(|v| v.as_slice())
    }

    /// The direction a deformable bullet flies: the mean of its nodes' initial
    /// velocities, unit; −z when they start at rest.
    pub fn bullet_direction(&self) -> Option<[f64; 3]> {
        let nodes = self.bullet_nodes()?;
        let mut in_set = vec![false; self.num_nodes()];
        for &i in nodes {
            in_set[i] = true;
        }
        let mut s = [0.0; 3];
        for (i, v) in &self.initial_velocities {
            if in_set[*i] {
                for d in 0..3 {
                    s[d] += v[d];
                }
            }
        }
        let n = (s[0] * s[0] + s[1] * s[1] + s[2] * s[2]).sqrt();
        Some(if n > 0.0 {
            [s[0] / n, s[1] / n, s[2] / n]
        } else {
            [0.0, 0.0, -1.0]
        })
    }

    /// The striking speed [m/s]: the first rigid projectile's, or the deformable
    /// bullet's (its nodes' mean initial velocity); `None` without a striker.
    pub fn striking_speed(&self) -> Option<f64> {
        let norm = |v: [f64; 3]| (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
        if let Some(p) = self.projectiles.first() {
            return Some(norm(p.velocity));
        }
        let nodes = self.bullet_nodes()?;
        let mut in_set = vec![false; self.num_nodes()];
        for &i in nodes {
            in_set[i] = true;
        }
        let (mut s, mut n) = ([0.0; 3], 0usize);
        for (i, v) in &self.initial_velocities {
            if in_set[*i] {
                for d in 0..3 {
                    s[d] += v[d];
                }
                n += 1;
            }
        }
        Some(norm(s) / nodes.len().max(n).max(1) as f64)
    }

    /// Strike at `speed` [m/s] along the striker's direction: each rigid projectile's
    /// velocity (along its axis when at rest), or every node of the deformable bullet's
    /// initial velocity.
    pub fn set_striking_speed(&mut self, speed: f64) {
        for p in &mut self.projectiles {
            let v = p.velocity;
            let n = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
            let dir = if n > 0.0 {
                [v[0] / n, v[1] / n, v[2] / n]
            } else {
                p.axis
            };
            p.velocity = [speed * dir[0], speed * dir[1], speed * dir[2]];
        }
        let Some(dir) = self.bullet_direction() else {
            return;
        };
        let v = [speed * dir[0], speed * dir[1], speed * dir[2]];
        let nodes = self.node_sets[BULLET_SET].clone();
        let mut in_set = vec![false; self.num_nodes()];
        for &i in &nodes {
            in_set[i] = true;
        }
        self.initial_velocities.retain(|(i, _)| !in_set[*i]);
        self.initial_velocities
            .extend(nodes.iter().map(|&i| (i, v)));
    }
}
