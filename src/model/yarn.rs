//! Yarns as the model sees them: the chains of trusses through a node, and the window of
//! a yarn that a sliding link reaches along ([`crate::solver::sliding_link`]).

use super::kinds::ElementKind;
use super::types::Model;

/// Nodes of a sliding link's window on each side of the link's node. Four: a crossing's yarns may
/// slide three spacings past each other (the yarn-level reference's crossings under
/// the nose rim slid 2.7 mm at a 1 mm spacing by 50 µs, measured), and an anchor needs
/// the chord beyond its segment.
pub const HALF: usize = 4;

/// A stretch of the yarn through a node: the chain of trusses through it, up to `half`
/// nodes on each side (a sliding link's reach, [`crate::solver::sliding_link`]).
#[derive(Debug, Clone, PartialEq)]
pub struct YarnWindow {
    /// Node indices in chain order.
    pub nodes: Vec<usize>,
    /// The node's position in `nodes`.
    pub home: usize,
    /// Whether the first and the last node of the window end the yarn (rather than the
    /// window's reach).
    pub ends: [bool; 2],
}

impl Model {
    /// The truss neighbours of every node, in truss table order.
    pub fn truss_neighbours(&self) -> Vec<Vec<usize>> {
        let mut nb = vec![vec![]; self.coords.len()];
        if let Some(b) = self.block(ElementKind::Truss) {
            for e in 0..b.len() {
                let (a, c) = (b.nodes[2 * e], b.nodes[2 * e + 1]);
                nb[a].push(c);
                nb[c].push(a);
            }
        }
        nb
    }

    /// The window of the yarn through `node` (see [`YarnWindow`]), walking the truss
    /// neighbours `nb` ([`Model::truss_neighbours`]); why there is none otherwise: a node
    /// on no truss, a node where the trusses branch (more than two neighbours), a yarn
    /// that closes on itself within the window.
    pub fn yarn_window(
        &self,
        nb: &[Vec<usize>],
        node: usize,
        half: usize,
    ) -> std::result::Result<YarnWindow, String> {
        let id = |n: usize| self.node_id[n];
        match nb[node].len() {
            0 => return Err(format!("node `{}` is on no truss", id(node))),
            1 | 2 => {}
            k => {
                return Err(format!(
                    "node `{}` joins {k} trusses (a yarn is a chain: one or two)",
                    id(node)
                ))
            }
        }
        let mut sides = [vec![], vec![]];
        let mut ends = [true, true];
        for (side, &first) in nb[node].iter().enumerate() {
            let (mut prev, mut cur) = (node, first);
            loop {
                if cur == node || sides[side].contains(&cur) {
                    return Err(format!(
                        "the yarn through node `{}` closes on itself",
                        id(node)
                    ));
                }
                sides[side].push(cur);
                if nb[cur].len() > 2 {
                    return Err(format!(
                        "node `{}` on the yarn through node `{}` joins {} trusses (a yarn is a chain: one or two)",
                        id(cur),
                        id(node),
                        nb[cur].len()
                    ));
                }
                let next = nb[cur].iter().copied().find(|&n| n != prev);
                match next {
                    Some(n) if sides[side].len() < half => (prev, cur) = (cur, n),
                    Some(_) => {
                        ends[side] = false;
                        break;
                    }
                    None => break,
                }
            }
        }
        let [back, fwd] = sides;
        let home = back.len();
        let nodes: Vec<usize> = back
            .into_iter()
            .rev()
            .chain(std::iter::once(node))
            .chain(fwd)
            .collect();
        // A node with one neighbour ends the yarn: its side's walk never started, and
        // its `ends` entry stays true.
        Ok(YarnWindow { nodes, home, ends })
    }
}
