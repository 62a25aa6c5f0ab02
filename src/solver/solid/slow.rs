//! The hexahedra's share of the subcycle ([`crate::solver::subcycle`]): which elements are
//! slow, the positions their last update saw, and the kinematics they are updated with.
//!
//! A slow element is updated only at the slow samples, every T = ratio × Δt or so: its
//! rate of deformation over the interval since its last update, T^{k−½}, is that of the
//! mean velocity (xⁿ − x^{last})/T^{k−½} of its nodes (the displacement its strain
//! increment must match; a node in contact changes its velocity within the interval),
//! and its forces, scaled by the step's weight, are the impulse of the slow step
//! (zero in the fast steps between).

use crate::solver::family::{ForceCtx, SlowChoice, SlowStep};
use crate::solver::vec3::Vec3;

/// The slow hexahedra and what their updates keep.
#[derive(Debug, Clone, Default)]
pub struct Slow {
    /// Per element: whether it is slow.
    pub slow: Vec<bool>,
    /// The fast elements and the slow ones (indices, ascending).
    pub fast_list: Vec<u32>,
    pub slow_list: Vec<u32>,
    /// The nodes of the slow elements (ascending).
    pub nodes: Vec<u32>,
    /// Per model node: its position at the last slow sample (the slow nodes' only).
    pub x_last: Vec<Vec3>,
    /// Whether the slow elements' force slots hold the last sample's impulse (cleared at
    /// the next fast step).
    pub live: bool,
    /// Per model node: the slow elements' forces at the last sample [N], unweighted (the
    /// slow nodes' only), for the kinetic energy's form at a sample ([`crate::solver::subcycle`]).
    pub force: Vec<Vec3>,
    /// Per element: the elements that share a node with it.
    pub around: Vec<Vec<u32>>,
    /// Per element: whether its erosion has been seen (its neighbours then leave the slow
    /// step: erosion uncovers them to the contact).
    pub seen: Vec<bool>,
    /// Per element: leaving the slow step at the next sample.
    pub leaving: Vec<bool>,
    pub any_leaving: bool,
    /// Per model node: whether only slow elements act on it, so that between samples no
    /// force does and it drifts (the node update then skips its slots).
    pub drift: Vec<bool>,
}

/// Per element, the other elements that share a node with it (ascending).
fn node_neighbours(nodes: &[[u32; 8]], n_nodes: usize) -> Vec<Vec<u32>> {
    let mut of_node: Vec<Vec<u32>> = vec![vec![]; n_nodes];
    for (e, ns) in nodes.iter().enumerate() {
        for &a in ns {
            of_node[a as usize].push(e as u32);
        }
    }
    nodes
        .iter()
        .enumerate()
        .map(|(e, ns)| {
            let mut v: Vec<u32> = ns
                .iter()
                .flat_map(|&a| of_node[a as usize].iter().copied())
                .filter(|&o| o as usize != e)
                .collect();
            v.sort_unstable();
            v.dedup();
            v
        })
        .collect()
}

/// The slow set and its ratio that make the family's updates per step fewest.
///
/// Element e may take ratio r_e = ⌊Δt_e/Δt⌋, Δt_e the smallest stable step of its nodes
/// (`node_dt`, with the fast step's margin) and Δt the fast step; a slow set with ratio m
/// holds the elements with r_e ≥ m and costs (fast elements) + (slow elements)/m updates
/// a step. Of the sets "the n elements of largest r_e, ratio r_(n)", the cheapest is
/// taken; `None` when no set saves a tenth of the updates (or the best ratio is below 2).
pub fn choose(
    nodes: &[[u32; 8]],
    node_dt: &[f64],
    dt: f64,
    x: &[Vec3],
) -> Option<(Slow, SlowChoice)> {
    let n = nodes.len();
    if n == 0 || !(dt > 0.0) {
        return None;
    }
    let ratio: Vec<u64> = nodes
        .iter()
        .map(|ns| {
            let dte = ns
                .iter()
                .map(|&a| node_dt[a as usize])
                .fold(f64::INFINITY, f64::min);
            let r = (dte / dt).floor();
            if r.is_finite() && r >= 1.0 {
                r.min(u32::MAX as f64) as u64
            } else {
                1
            }
        })
        .collect();
    let mut sorted = ratio.clone();
    sorted.sort_unstable_by(|a, b| b.cmp(a));
    let mut best = (n as f64, 1u64);
    for (i, &m) in sorted.iter().enumerate() {
        if m < 2 {
            break;
        }
        let k = (i + 1) as f64;
        let cost = (n as f64 - k) + k / m as f64;
        if cost < best.0 {
            best = (cost, m);
        }
    }
    let (cost, m) = best;
    if m < 2 || cost > 0.9 * n as f64 {
        return None;
    }
    let slow: Vec<bool> = ratio.iter().map(|&r| r >= m).collect();
    let (mut fast_list, mut slow_list) = (vec![], vec![]);
    let mut in_slow = vec![false; x.len()];
    let mut in_fast = vec![false; x.len()];
    for (e, ns) in nodes.iter().enumerate() {
        let mark = if slow[e] {
            slow_list.push(e as u32);
            &mut in_slow
        } else {
            fast_list.push(e as u32);
            &mut in_fast
        };
        for &a in ns {
            mark[a as usize] = true;
        }
    }
    let slow_nodes: Vec<u32> = (0..x.len() as u32)
        .filter(|&a| in_slow[a as usize])
        .collect();
    let choice = SlowChoice {
        ratio: m,
        elements: slow_list.len(),
        nodes: slow_nodes.iter().map(|&a| a as usize).collect(),
    };
    let s = Slow {
        slow,
        fast_list,
        slow_list,
        nodes: slow_nodes,
        x_last: x.to_vec(),
        live: false,
        force: vec![[0.0; 3]; x.len()],
        around: node_neighbours(nodes, x.len()),
        seen: vec![false; n],
        leaving: vec![false; n],
        any_leaving: false,
        drift: (0..x.len()).map(|a| in_slow[a] && !in_fast[a]).collect(),
    };
    Some((s, choice))
}

impl Slow {
    /// After a force pass in which some element eroded (`eroded`: each element's state):
    /// the slow elements that share a node with one newly eroded leave the slow step at
    /// the next sample (the faces its erosion uncovers have only its nodes, and the
    /// crater's new floor meets the contact on the fast step).
    pub fn uncovered(&mut self, eroded: impl Fn(usize) -> bool) {
        for e in 0..self.seen.len() {
            if self.seen[e] || !eroded(e) {
                continue;
            }
            self.seen[e] = true;
            for &o in &self.around[e] {
                if self.slow[o as usize] {
                    self.leaving[o as usize] = true;
                    self.any_leaving = true;
                }
            }
        }
    }

    /// After a sample: the elements that left the slow step there are fast from now on.
    fn left(&mut self, nodes: &[[u32; 8]]) {
        if !self.any_leaving {
            return;
        }
        for e in 0..self.slow.len() {
            if self.leaving[e] {
                self.slow[e] = false;
                self.leaving[e] = false;
                for &a in &nodes[e] {
                    self.drift[a as usize] = false;
                }
            }
        }
        self.any_leaving = false;
        self.slow_list.retain(|&e| self.slow[e as usize]);
        self.fast_list = (0..self.slow.len() as u32)
            .filter(|&e| !self.slow[e as usize])
            .collect();
    }

    /// The mean velocities of element `ns`'s nodes over the slow interval `t`
    /// ((xⁿ − x^{last})/T; zero at the first sample, T = 0).
    #[inline]
    pub fn velocities(&self, ns: &[u32; 8], x: &[Vec3; 8], t: f64) -> [Vec3; 8] {
        if t > 0.0 {
            let r = 1.0 / t;
            std::array::from_fn(|a| {
                let xl = self.x_last[ns[a] as usize];
                [
                    (x[a][0] - xl[0]) * r,
                    (x[a][1] - xl[1]) * r,
                    (x[a][2] - xl[2]) * r,
                ]
            })
        } else {
            [[0.0; 3]; 8]
        }
    }

    /// Slow element `e`'s forces in `slots` made the impulse of this sample: scaled by
    /// the sample's weight, or, for an element that leaves the slow step or erodes
    /// (`eroded`) at this sample, by the weight that closes its interval (its force acts
    /// from here over the fast step only).
    #[inline]
    pub fn weigh(&self, e: usize, eroded: bool, slow: &SlowStep, slots: &mut [Vec3]) {
        let w = if self.leaving[e] || eroded {
            slow.close
        } else {
            slow.weight
        };
        for f in slots.iter_mut() {
            *f = [f[0] * w, f[1] * w, f[2] * w];
        }
    }

    /// After the family's force pass: at a sample, [`Slow::sampled`]; between, the slots
    /// are zero from now on. Then, when some element eroded in the pass (`eroded`: each
    /// element's state), the slow ones it uncovers leave at the next sample.
    pub fn after_pass(
        &mut self,
        ctx: &ForceCtx,
        nodes: &[[u32; 8]],
        fe: &[Vec3],
        eroded: Option<impl Fn(usize) -> bool + Copy>,
    ) {
        if ctx.slow.sample {
            let w = [ctx.slow.weight, ctx.slow.close];
            self.sampled(ctx.x, nodes, fe, w, |e| eroded.is_some_and(|f| f(e)));
        } else {
            self.live = false;
        }
        if let Some(f) = eroded {
            self.uncovered(f);
        }
    }

    /// After a sample: the slow nodes' positions kept for the next interval, and the
    /// slow elements' forces gathered per node from their slots `fe` (weighted by
    /// `weight`: [the sample's, that of an element closing its interval, one leaving or
    /// eroded at this pass], `eroded`: each element's state), element by element in
    /// order.
    pub fn sampled(
        &mut self,
        x: &[Vec3],
        nodes: &[[u32; 8]],
        fe: &[Vec3],
        weight: [f64; 2],
        eroded: impl Fn(usize) -> bool,
    ) {
        for &a in &self.nodes {
            self.x_last[a as usize] = x[a as usize];
            self.force[a as usize] = [0.0; 3];
        }
        for &e in &self.slow_list {
            let e = e as usize;
            // Eroded at this pass: its erosion is not seen yet.
            let closing = self.leaving[e] || (eroded(e) && !self.seen[e]);
            let r = 1.0 / if closing { weight[1] } else { weight[0] };
            for (a, &n) in nodes[e].iter().enumerate() {
                let f = fe[8 * e + a];
                let g = &mut self.force[n as usize];
                g[0] += f[0] * r;
                g[1] += f[1] * r;
                g[2] += f[2] * r;
            }
        }
        self.live = true;
        self.left(nodes);
    }
}
