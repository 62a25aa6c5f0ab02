//! The strain a chain's truss is failed by, averaged over a length of its chain.
//!
//! Glossary: ℓ the part's `failure_length`; a chain the trusses of one part joined end to
//! end (a node shared by exactly two of them continues it; a node of one, or of three or
//! more, ends it); s the arc length along the chain in reference lengths L_ref; ε_j a
//! truss's own engineering strain.
//!
//! Each truss e of a part with ℓ > 0 compares with its failure strain
//! ε̄_e = Σ_j w_j ε_j / Σ_j w_j, the weights w_j the reference length of truss j inside the
//! window s ∈ [s_e − ℓ/2, s_e + ℓ/2] about e's centre s_e (truncated where the chain ends;
//! failed trusses leave the sums). A window shorter than e itself is e alone.
//!
//! Why: a discrete chain struck by a nose overshoots the strain of Smith's theory in its
//! first elements for a few steps (the central difference's ringing behind a wave front:
//! its amplitude does not shrink as the mesh is refined, only its length, a few
//! elements), so a chain compared element by element breaks early, and earlier the finer
//! the mesh. Averaged over a fixed length of yarn, the peak shrinks with the elements,
//! while a strain that varies over lengths beyond ℓ (the Smith strain behind the
//! longitudinal front, the yarn's tension between crossings) is compared as it is: the
//! nonlocal regularisation of Pijaudier-Cabot & Bažant (*Nonlocal damage theory*, J. Eng.
//! Mech. 113, 1987), a physical length in place of the element's. weft-weave sets ℓ to
//! the crossing spacing of the weave (docs/theory.md, "Failure, perforation and the
//! ballistic limit").

use std::collections::HashMap;

/// The windows of a group of trusses: per truss, its (truss, weight) terms.
#[derive(Debug, Clone, Default)]
pub struct Windows {
    /// Per truss, the range of its terms in `el` and `w` (`at[e]..at[e + 1]`); empty
    /// when no truss has a failure length.
    at: Vec<u32>,
    el: Vec<u32>,
    w: Vec<f64>,
    /// Scratch: each truss's own strain at this step (NaN for a failed one).
    pub(super) own: Vec<f64>,
}

impl Windows {
    /// The windows of trusses `nodes` of reference lengths `l0`, each of part `part` with
    /// failure length `length[part]` (0: none).
    pub fn new(nodes: &[[u32; 2]], l0: &[f64], part: &[usize], length: &[f64]) -> Windows {
        let n = nodes.len();
        if !part.iter().any(|&p| length[p] > 0.0) {
            return Windows::default();
        }
        // (node, part) → the trusses of that part at that node.
        let mut at_node: HashMap<(u32, usize), Vec<u32>> = HashMap::new();
        for (e, nd) in nodes.iter().enumerate() {
            for &a in nd {
                at_node.entry((a, part[e])).or_default().push(e as u32);
            }
        }
        // The truss continuing a chain from truss `e` through its node `a`, if any.
        let next = |e: u32, a: u32| -> Option<u32> {
            let here = &at_node[&(a, part[e as usize])];
            (here.len() == 2).then(|| if here[0] == e { here[1] } else { here[0] })
        };
        let mut w = Windows {
            at: Vec::with_capacity(n + 1),
            own: vec![0.0; n],
            ..Default::default()
        };
        w.at.push(0);
        for e in 0..n {
            let half = 0.5 * length[part[e]];
            w.el.push(e as u32);
            w.w.push(
                l0[e]
                    .min(2.0 * half)
                    .max(if half > 0.0 { 0.0 } else { l0[e] }),
            );
            if half > 0.0 {
                // Both ways along the chain from e's centre.
                for end in 0..2 {
                    let (mut cur, mut node) = (e as u32, nodes[e][end]);
                    let mut s = 0.5 * l0[e];
                    while s < half {
                        let Some(j) = next(cur, node) else { break };
                        if j as usize == e {
                            break; // a closed loop
                        }
                        let lj = l0[j as usize];
                        w.el.push(j);
                        w.w.push(lj.min(half - s));
                        s += lj;
                        let [p, q] = nodes[j as usize];
                        node = if p == node { q } else { p };
                        cur = j;
                    }
                }
            }
            w.at.push(w.el.len() as u32);
        }
        w
    }

    pub fn is_empty(&self) -> bool {
        self.at.is_empty()
    }

    /// ε̄_e from the trusses' own strains in `self.own` (NaN: failed, left out).
    #[inline(always)]
    pub fn mean(&self, e: usize) -> f64 {
        let (mut sum, mut wsum) = (0.0, 0.0);
        for t in self.at[e] as usize..self.at[e + 1] as usize {
            let eps = self.own[self.el[t] as usize];
            if !eps.is_nan() {
                sum += self.w[t] * eps;
                wsum += self.w[t];
            }
        }
        sum / wsum
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A straight chain of 8 trusses of 1 mm: with ℓ = 3 mm, an inner truss's window
    /// is itself and one truss either side whole (1 + 1 + 1 = 3 mm); a strain step is
    /// averaged with those weights; the end truss's window is truncated.
    #[test]
    fn windows_weigh_the_chain_within_half_the_length_either_side() {
        let nodes: Vec<[u32; 2]> = (0..8).map(|i| [i, i + 1]).collect();
        let l0 = vec![1e-3; 8];
        let mut w = Windows::new(&nodes, &l0, &[0; 8], &[3e-3]);
        w.own = vec![0.0, 0.0, 0.0, 0.03, 0.0, 0.0, 0.0, 0.0];
        assert!((w.mean(3) - 0.01).abs() < 1e-15);
        assert!((w.mean(2) - 0.01).abs() < 1e-15);
        assert_eq!(w.mean(0), 0.0);
        // ℓ = 2 mm: half a truss either side.
        let mut w = Windows::new(&nodes, &l0, &[0; 8], &[2e-3]);
        w.own = vec![0.0, 0.0, 0.0, 0.03, 0.0, 0.0, 0.0, 0.0];
        assert!((w.mean(3) - 0.015).abs() < 1e-15);
        assert!((w.mean(4) - 0.0075).abs() < 1e-15);
        // The end truss: itself and half the next, 1.5 mm.
        w.own = vec![0.03, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0];
        assert!((w.mean(0) - 0.02).abs() < 1e-15);
        // A failed neighbour leaves the sums.
        w.own[1] = f64::NAN;
        assert_eq!(w.mean(0), 0.03);
    }

    /// Two parts meeting at a node are two chains; a node of three trusses ends a chain.
    #[test]
    fn chains_end_at_other_parts_and_branches() {
        let nodes = vec![[0, 1], [1, 2], [1, 3]];
        let w = Windows::new(&nodes, &[1.0; 3], &[0, 0, 1], &[4.0, 4.0]);
        // Truss 0 continues into truss 1 (two trusses of part 0 at node 1).
        assert_eq!(&w.el[w.at[0] as usize..w.at[1] as usize], &[0, 1]);
        let nodes = vec![[0, 1], [1, 2], [1, 3]];
        let w = Windows::new(&nodes, &[1.0; 3], &[0, 0, 0], &[4.0]);
        assert_eq!(&w.el[w.at[0] as usize..w.at[1] as usize], &[0]);
    }
}
