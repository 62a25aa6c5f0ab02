//! Rotational nodes: the orientation, angular velocity, inertia and fixed axes of the
//! nodes that carry rotations (the ends of beams, which create them while they are
//! built), and the gather index of the beams' end moments onto them.

use super::vec3::Mat3;
use crate::model::Model;

/// Rotational state of the nodes that carry beams.
#[derive(Debug, Clone, Default)]
pub struct Rotations {
    /// Node index of each rotational node.
    pub node: Vec<usize>,
    /// Rotational node of each node (u32::MAX: none).
    pub of_node: Vec<u32>,
    /// Orientation R (global).
    pub r: Vec<Mat3>,
    /// Half-step angular velocity ω^{n−½} (global) [rad/s].
    pub omega: Vec<[f64; 3]>,
    /// Lumped rotational inertia J [kg·m²].
    pub j: Vec<f64>,
    /// Bit d set when the rotation about axis d is fixed.
    pub fixed: Vec<u8>,
    /// Moment slots per rotational node (CSR into the beams' end moments).
    pub ptr: Vec<u32>,
    pub slots: Vec<u32>,
}

impl Rotations {
    pub fn new(nodes: usize) -> Rotations {
        Rotations {
            of_node: vec![u32::MAX; nodes],
            ..Default::default()
        }
    }
    pub fn len(&self) -> usize {
        self.node.len()
    }
    pub fn is_empty(&self) -> bool {
        self.node.is_empty()
    }
    /// The rotational node of node n, created (at rest, J = 0) when missing.
    pub(super) fn get_or_add(&mut self, n: usize) -> u32 {
        if self.of_node[n] == u32::MAX {
            self.of_node[n] = self.node.len() as u32;
            self.node.push(n);
            self.r
                .push([[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]);
            self.omega.push([0.0; 3]);
            self.j.push(0.0);
            self.fixed.push(0);
        }
        self.of_node[n]
    }
    /// Rotation constraints and symmetry planes, and the moment gather index of the
    /// beams (two end moments per beam, gathered per rotational node in slot order;
    /// `beam_rot`: the rotational nodes of each beam's two ends, `BeamGroup::rot`).
    pub fn finish(&mut self, m: &Model, beam_rot: &[[u32; 2]]) {
        for (n, f) in &m.rot_constraints {
            if self.of_node[*n] != u32::MAX {
                for d in 0..3 {
                    if f[d] {
                        self.fixed[self.of_node[*n] as usize] |= 1 << d;
                    }
                }
            }
        }
        // On a symmetry plane with normal d the rotations about the other two axes vanish.
        for sp in &m.symmetry {
            for (k, &n) in self.node.iter().enumerate() {
                if (m.coords[n][sp.normal] - sp.position).abs() <= sp.tolerance {
                    for d in 0..3 {
                        if d != sp.normal {
                            self.fixed[k] |= 1 << d;
                        }
                    }
                }
            }
        }
        let nr = self.node.len();
        let mut cnt = vec![0u32; nr + 1];
        for r in beam_rot.iter().flatten() {
            cnt[*r as usize + 1] += 1;
        }
        for i in 0..nr {
            cnt[i + 1] += cnt[i];
        }
        self.ptr = cnt.clone();
        self.slots = vec![0; 2 * beam_rot.len()];
        for (sl, r) in beam_rot.iter().flatten().enumerate() {
            self.slots[cnt[*r as usize] as usize] = sl as u32;
            cnt[*r as usize] += 1;
        }
    }
}
