//! Which plies still lie in front of the projectile's nose ([`super::watch`]'s
//! perforation of a ply): the yarn and membrane elements around the shot, within
//! [`super::watch::CUT_REACH`] projectile radii of its line, and at each output sample
//! the nodes among them still joined through live elements to the ply beyond that
//! reach. A piece cut free on both sides (a fragment riding on the nose) is not the ply.

use std::collections::HashMap;

use crate::model::{ElementKind, Model};

/// The elements around the shot and their connections.
#[derive(Debug, Clone, Default)]
pub struct Around {
    /// Per element around the shot: its kind and index, its nodes (up to four, `u32::MAX`
    /// past the last), whether it has failed.
    elements: Vec<(ElementKind, u32)>,
    nodes: Vec<[u32; 4]>,
    dead: Vec<bool>,
    index: HashMap<(ElementKind, u32), u32>,
    /// Per node (of the model), the elements around the shot that hold it (CSR).
    ptr: Vec<u32>,
    of_node: Vec<u32>,
    /// Per node: it lies within the reach and is neither tied nor held (an element
    /// with a node that is not inner is anchored to the ply beyond).
    inner: Vec<bool>,
}

impl Around {
    /// The layered elements of `m` (trusses and membranes with a `layer`) with a node
    /// whose reference distance from the shot's line (`lateral`) is at most `reach`. A
    /// node tied to others (a patch's yarn end tied into its membrane) or held is an
    /// anchor wherever it lies: the ply goes on through the tie.
    pub fn new(m: &Model, lateral: impl Fn(&[f64; 3]) -> f64, reach: f64) -> Around {
        let n = m.num_nodes();
        let mut inner: Vec<bool> = m.coords.iter().map(|x| lateral(x) <= reach).collect();
        for t in &m.ties {
            inner[t.slave] = false;
        }
        for (i, held) in &m.constraints {
            if held.iter().any(|&h| h) {
                inner[*i] = false;
            }
        }
        let mut a = Around {
            inner,
            ..Default::default()
        };
        for kind in [ElementKind::Truss, ElementKind::Tri, ElementKind::Quad] {
            let Some(b) = m.block(kind) else { continue };
            let npe = kind.nodes_per_element();
            for e in 0..b.len() {
                let ns = &b.nodes[npe * e..npe * e + npe];
                if b.layer_of(e).is_none_or(|l| l <= 0) || !ns.iter().any(|&i| a.inner[i]) {
                    continue;
                }
                let mut row = [u32::MAX; 4];
                for (r, &i) in row.iter_mut().zip(ns) {
                    *r = i as u32;
                }
                a.index.insert((kind, e as u32), a.elements.len() as u32);
                a.elements.push((kind, e as u32));
                a.nodes.push(row);
            }
        }
        a.dead = vec![false; a.elements.len()];
        let mut count = vec![0u32; n + 1];
        for row in &a.nodes {
            for &i in row.iter().filter(|&&i| i != u32::MAX) {
                count[i as usize + 1] += 1;
            }
        }
        for i in 0..n {
            count[i + 1] += count[i];
        }
        a.of_node = vec![0; count[n] as usize];
        let mut at = count.clone();
        for (k, row) in a.nodes.iter().enumerate() {
            for &i in row.iter().filter(|&&i| i != u32::MAX) {
                a.of_node[at[i as usize] as usize] = k as u32;
                at[i as usize] += 1;
            }
        }
        a.ptr = count;
        a
    }

    /// Element e of kind `kind` has failed.
    pub fn on_erosion(&mut self, kind: ElementKind, e: usize) {
        if let Some(&k) = self.index.get(&(kind, e as u32)) {
            self.dead[k as usize] = true;
        }
    }

    /// Calls `f` with each node around the shot still joined to the ply beyond the reach
    /// through live elements (each once).
    pub fn for_joined(&self, mut f: impl FnMut(usize)) {
        let mut seen = vec![false; self.ptr.len().saturating_sub(1)];
        let mut stack: Vec<u32> = vec![];
        let live = |k: usize| !self.dead[k];
        for (k, row) in self.nodes.iter().enumerate() {
            let anchored = row
                .iter()
                .any(|&i| i != u32::MAX && !self.inner[i as usize]);
            if live(k) && anchored {
                for &i in row.iter().filter(|&&i| i != u32::MAX) {
                    if !seen[i as usize] {
                        seen[i as usize] = true;
                        stack.push(i);
                    }
                }
            }
        }
        while let Some(i) = stack.pop() {
            let i = i as usize;
            f(i);
            for &k in &self.of_node[self.ptr[i] as usize..self.ptr[i + 1] as usize] {
                if !live(k as usize) {
                    continue;
                }
                for &j in self.nodes[k as usize].iter().filter(|&&j| j != u32::MAX) {
                    if !seen[j as usize] {
                        seen[j as usize] = true;
                        stack.push(j);
                    }
                }
            }
        }
    }
}
