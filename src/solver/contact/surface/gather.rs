//! The gather of a step's contact forces onto the nodes: each slave in contact gets its
//! force f, and the nodes of each face it penetrates get −w_a f (its [`Reaction`] shares).
//!
//! **Order.** Every node's contributions are added in one canonical order, the same on
//! any thread count: side, then fixed chunk of slaves (`SLAVE_CHUNK`), then within the
//! chunk its slaves' forces in slave order, then its reactions in slave order (each
//! over the face's nodes in order). So a node's sum is bit-identical however the work is
//! split.
//!
//! **Parallel.** Each chunk of the narrow phase, as it ends (its results still in cache),
//! sorts its contributions by fixed node block ([`NODE_BLOCKS`] blocks whatever the
//! thread count), keeping the chunk's order within each block (a stable counting sort:
//! [`ChunkContribs::fill`]); then each block (in parallel) adds, chunk after chunk, its
//! part of each chunk's list. Each contribution is computed once and read once, where a
//! split of the nodes into one block per thread whose every block scanned every
//! contribution read them all once per thread. Small jobs (under [`PARALLEL_ACTIVE`]
//! slaves in contact) and one thread (whose narrow phase fills no lists) take the
//! canonical order directly.

use rayon::prelude::*;

use super::side::{ChunkContribs, Contrib, PairOut, Reaction, Side};
use crate::solver::vec3::add;

/// Node blocks of the parallel gather: fixed, so that the split does not depend on the
/// thread count (it would not change a bit anyway; fixed keeps the work the same).
pub(super) const NODE_BLOCKS: usize = 64;

/// Slaves in contact below which the gather stays on one thread (same sums, no
/// scheduling cost).
const PARALLEL_ACTIVE: usize = 2048;

/// What the contributions of a side's chunk are made of: its slaves' nodes, its faces'
/// nodes (`nf` each), and the slaves' results from slave `first` on.
pub(super) struct ChunkParts<'a> {
    pub(super) slaves: &'a [u32],
    pub(super) faces: &'a [[u32; 4]],
    pub(super) nf: usize,
    pub(super) first: usize,
    pub(super) outs: &'a [PairOut],
    pub(super) active: &'a [u32],
    pub(super) reactions: &'a [Reaction],
}

/// The node blocks' size for `nodes` nodes.
pub(super) fn block_size(nodes: usize) -> usize {
    nodes.div_ceil(NODE_BLOCKS).max(1)
}

/// The contributions of one chunk of a side, in the canonical order: `each(node, f)`.
#[inline(always)]
fn for_each_contribution(p: &ChunkParts, mut each: impl FnMut(usize, [f64; 3])) {
    for &si in p.active {
        each(
            p.slaves[si as usize] as usize,
            p.outs[si as usize - p.first].f,
        );
    }
    for r in p.reactions {
        let f = r
            .own
            .as_ref()
            .unwrap_or(&p.outs[r.slave as usize - p.first].f);
        let face = &p.faces[r.face as usize];
        for a in 0..p.nf {
            each(
                face[a] as usize,
                [-r.w[a] * f[0], -r.w[a] * f[1], -r.w[a] * f[2]],
            );
        }
    }
}

impl ChunkContribs {
    /// This chunk's lists from the chunk's parts `p`, node blocks of `bs` nodes
    /// ([`block_size`]).
    pub(super) fn fill(&mut self, p: &ChunkParts, bs: usize) {
        let mut count = [0u32; NODE_BLOCKS];
        for &si in p.active {
            count[p.slaves[si as usize] as usize / bs] += 1;
        }
        for r in p.reactions {
            for &n in &p.faces[r.face as usize][..p.nf] {
                count[n as usize / bs] += 1;
            }
        }
        self.ptr.clear();
        self.ptr.push(0);
        for c in count {
            self.ptr.push(self.ptr.last().copied().unwrap_or(0) + c);
        }
        let total = self.ptr[NODE_BLOCKS] as usize;
        self.items.resize(total, Contrib::default());
        let mut next: [u32; NODE_BLOCKS] = std::array::from_fn(|b| self.ptr[b]);
        let items = &mut self.items;
        for_each_contribution(p, |node, f| {
            let b = node / bs;
            items[next[b] as usize] = Contrib {
                node: node as u32,
                f,
            };
            next[b] += 1;
        });
    }
}

/// Adds the forces of the last narrow phase of `sides` into `fcon`, in the canonical
/// order. `fcon` must be zero at the slaves' and faces' nodes before (the operator clears
/// it), and its length the node count the narrow phase was given.
pub(super) fn gather(sides: &[Side], fcon: &mut [[f64; 3]]) {
    let active: usize = sides
        .iter()
        .map(|s| s.chunk_active.iter().map(|a| a.len()).sum::<usize>())
        .sum();
    if active < PARALLEL_ACTIVE || rayon::current_num_threads() <= 1 {
        for s in sides {
            for (a, r) in s.chunk_active.iter().zip(&s.chunk_reactions) {
                let p = ChunkParts {
                    slaves: &s.slaves,
                    faces: &s.faces,
                    nf: s.nf,
                    first: 0,
                    outs: &s.out,
                    active: a,
                    reactions: r,
                };
                for_each_contribution(&p, |n, f| add(&mut fcon[n], &f));
            }
        }
        return;
    }
    // (More than one thread: every chunk of the narrow phase filled its lists.)
    let bs = block_size(fcon.len());
    fcon.par_chunks_mut(bs).enumerate().for_each(|(b, block)| {
        let lo = b * bs;
        for s in sides {
            for c in &s.chunk_contribs {
                for it in &c.items[c.ptr[b] as usize..c.ptr[b + 1] as usize] {
                    add(&mut block[it.node as usize - lo], &it.f);
                }
            }
        }
    });
}
