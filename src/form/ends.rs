//! The yarn ends that forming pulls: held at the patch edge, or tied to a membrane
//! around the patch (the §3 combined model), one [`YarnEnd`] per end of a yarn with the
//! section each of its nodes carries.

use std::collections::BTreeMap;

use crate::error::{Result, WeftError};
use crate::model::Model;
use crate::solver::vec3::{norm, sub};

use super::weave::{family, quad_thickness, quads, trusses, CentreLines};

/// One node of a yarn end and the part of the yarn's section it carries.
#[derive(Debug, Clone, Copy)]
pub struct EndNode {
    pub node: usize,
    /// Section share [m²]: half the width times the thickness of each band quad it
    /// ends, or the area of the chain truss it ends.
    pub share: f64,
}

/// One end of one yarn: the held (or tied) nodes of one part at one edge, which share
/// the yarn's pull T in proportion to their section shares.
#[derive(Debug, Clone)]
pub struct YarnEnd {
    /// 0 warp (along x), 1 weft (along y).
    pub family: usize,
    /// +1 where the end lies beyond the yarn (the pull is outwards, along +x or +y), −1
    /// before it.
    pub sign: f64,
    pub nodes: Vec<EndNode>,
}

impl YarnEnd {
    /// The end's section: the sum of its nodes' shares [m²].
    pub fn section(&self) -> f64 {
        self.nodes.iter().map(|n| n.share).sum::<f64>()
    }
}

/// The yarn ends of a model.
#[derive(Debug, Clone)]
pub struct Ends {
    /// In the order of (family, sign, yarn, part), their nodes in node order.
    pub ends: Vec<YarnEnd>,
    /// A yarn's section per family: the largest end section of the family (a yarn
    /// centred on a symmetry plane is half a band and carries half the tension) [m²].
    pub section: [f64; 2],
    /// The ends are tied to a membrane (else held).
    pub tied: bool,
}

/// What an end node carries, gathered over the yarn elements that end at it.
#[derive(Debug, Clone, Copy)]
struct NodeEnd {
    share: f64,
    sign: f64,
    family: usize,
    part: usize,
}

/// Nodes held in x, y and z, or tied (the slaves of ties).
fn held_nodes(m: &Model) -> Vec<bool> {
    let mut h = vec![false; m.num_nodes()];
    for (n, c) in &m.constraints {
        if *c == [true; 3] {
            h[*n] = true;
        }
    }
    for t in &m.ties {
        h[t.slave] = true;
    }
    h
}

/// The slaves of the model's ties.
pub fn tie_slaves(m: &Model) -> Vec<bool> {
    let mut t = vec![false; m.num_nodes()];
    for tie in &m.ties {
        t[tie.slave] = true;
    }
    t
}

/// The end nodes of the yarns (held nodes at the end of a yarn element) with the
/// section share each carries, its yarn's family and part, and the pull's sign.
fn end_nodes(m: &Model, held: &[bool]) -> Vec<Option<NodeEnd>> {
    let quads = quads(m);
    let trusses = trusses(m);
    let mut out: Vec<Option<NodeEnd>> = vec![None; m.num_nodes()];
    let mut add = |n: usize, share: f64, sign: f64, family: usize, part: usize| {
        let e = out[n].get_or_insert(NodeEnd {
            share: 0.0,
            sign,
            family,
            part,
        });
        e.share += share;
        (e.sign, e.family, e.part) = (sign, family, part);
    };
    // A band's end: the two held nodes of a quad share its section.
    for e in 0..quads.len() {
        let Some(f) = family(m, quads.part[e]) else {
            continue;
        };
        let ns = &quads.nodes[4 * e..4 * e + 4];
        let hn: Vec<usize> = ns.iter().copied().filter(|&n| held[n]).collect();
        if hn.len() != 2 {
            continue;
        }
        let w = norm(&sub(&m.coords[hn[1]], &m.coords[hn[0]]));
        let inner = ns.iter().copied().find(|&n| !held[n]).unwrap_or(hn[0]);
        let sign = if m.coords[hn[0]][f] >= m.coords[inner][f] {
            1.0
        } else {
            -1.0
        };
        for &n in &hn {
            add(n, 0.5 * w * quad_thickness(m, e), sign, f, quads.part[e]);
        }
    }
    // A chain's end: the held node of a truss with one node held carries its section.
    for e in 0..trusses.len() {
        let Some(f) = family(m, trusses.part[e]) else {
            continue;
        };
        let [a, b] = [trusses.nodes[2 * e], trusses.nodes[2 * e + 1]];
        let (end, inner) = match (held[a], held[b]) {
            (true, false) => (a, b),
            (false, true) => (b, a),
            _ => continue,
        };
        let sign = if m.coords[end][f] >= m.coords[inner][f] {
            1.0
        } else {
            -1.0
        };
        add(
            end,
            trusses.truss_area(&m.parts, e),
            sign,
            f,
            trusses.part[e],
        );
    }
    out
}

impl Ends {
    /// The yarn ends of `m`: held in x, y and z at the patch edge, or tied to a
    /// membrane; an error when there are none, or some of each.
    pub fn find(m: &Model, lines: &CentreLines) -> Result<Ends> {
        let tied = tie_slaves(m);
        let nodes = end_nodes(m, &held_nodes(m));
        // Each yarn end: its nodes (connected held nodes of one part at one edge) share
        // T. The end section of one yarn is the sum of the shares of its nodes; group the
        // end nodes by (family, sign, reference across-coordinate rounded to the yarn,
        // part). A node's yarn is the nearest centre line.
        let mut groups: BTreeMap<(usize, i64, i64, usize), Vec<EndNode>> = Default::default();
        for (n, e) in nodes.iter().enumerate() {
            let Some(e) = e else {
                continue;
            };
            let yarn = lines.yarn(m.coords[n][1 - e.family]);
            groups
                .entry((e.family, e.sign as i64, yarn, e.part))
                .or_default()
                .push(EndNode {
                    node: n,
                    share: e.share,
                });
        }
        if groups.is_empty() {
            return Err(WeftError::input(
                "no yarn end is held in x, y and z or tied to a membrane: nothing holds the tension",
            )
            .in_file("constraints.parquet")
            .hint("generate the patch with --edge clamped, or with --membrane-length"));
        }
        let ends: Vec<YarnEnd> = groups
            .into_iter()
            .map(|((family, sign, _, _), nodes)| YarnEnd {
                family,
                sign: sign as f64,
                nodes,
            })
            .collect();
        let tied_ends = ends
            .iter()
            .flat_map(|e| &e.nodes)
            .filter(|n| tied[n.node])
            .count();
        if tied_ends > 0 && tied_ends < ends.iter().map(|e| e.nodes.len()).sum::<usize>() {
            return Err(WeftError::input(
                "some yarn ends are tied to a membrane and others held: expected one or the other",
            )
            .in_file("ties.parquet"));
        }
        let mut section = [0.0f64; 2];
        for e in &ends {
            section[e.family] = section[e.family].max(e.section());
        }
        Ok(Ends {
            ends,
            section,
            tied: tied_ends > 0,
        })
    }

    /// The ends of family `f`.
    pub fn of_family(&self, f: usize) -> impl Iterator<Item = &YarnEnd> {
        self.ends.iter().filter(move |e| e.family == f)
    }

    /// The pull on `node` of `end` with the tensions per yarn `tension` [N]: outwards
    /// along the yarn, T × its share of the yarn's section.
    pub fn pull(&self, end: &YarnEnd, node: &EndNode, tension: [f64; 2]) -> [f64; 3] {
        let f = end.family;
        let mut force = [0.0f64; 3];
        force[f] = end.sign * tension[f] * node.share / self.section[f];
        force
    }

    /// The family of each node's yarn end (`None` for a node at no end).
    pub fn node_families(&self, num_nodes: usize) -> Vec<Option<usize>> {
        let mut out = vec![None; num_nodes];
        for e in &self.ends {
            for n in &e.nodes {
                out[n.node] = Some(e.family);
            }
        }
        out
    }

    /// The end nodes' degree of freedom along their yarn (node, bit mask x = 1, y = 2),
    /// in node order: what the formed model holds of them.
    pub fn along_yarn(&self) -> Vec<(usize, u8)> {
        let mut out: Vec<(usize, u8)> = self
            .ends
            .iter()
            .flat_map(|e| e.nodes.iter().map(move |n| (n.node, 1u8 << e.family)))
            .collect();
        out.sort_unstable();
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::form::params::Params;
    use crate::form::pull::pulled_model;
    use crate::generate::woven::{woven, WovenBandParams};

    fn quarter(yarns: usize) -> Model {
        woven(&WovenBandParams {
            yarns,
            ..WovenBandParams::default()
        })
        .unwrap()
        .0
    }

    #[test]
    fn a_clamped_quarter_has_one_pulled_end_per_yarn_at_its_far_edges() {
        let m = quarter(4);
        let ends = Ends::find(&m, &CentreLines::of(&m).unwrap()).unwrap();
        assert!(!ends.tied);
        for f in 0..2 {
            let of_f: Vec<_> = ends.of_family(f).collect();
            assert_eq!(of_f.len(), 4, "family {f}");
            // Outwards at the far edge; the yarn on the symmetry plane is half a band.
            assert!(of_f.iter().all(|e| e.sign == 1.0));
            let halves = of_f
                .iter()
                .filter(|e| (e.section() - 0.5 * ends.section[f]).abs() < 1e-9 * ends.section[f])
                .count();
            assert_eq!(halves, 1, "family {f}");
        }
    }

    #[test]
    fn the_pulled_model_loads_each_end_with_its_share_of_t_and_lets_it_go_along_its_yarn() {
        let m = quarter(4);
        let ends = Ends::find(&m, &CentreLines::of(&m).unwrap()).unwrap();
        let p = Params {
            warp_tension: 0.5,
            weft_tension: 0.25,
            ..Params::default()
        };
        let mm = pulled_model(&m, &p, &ends);
        let force = |n: usize| mm.loads.iter().find(|l| l.node == n).unwrap().force;
        for e in &ends.ends {
            let along: f64 = e.nodes.iter().map(|n| force(n.node)[e.family]).sum();
            let t = p.tension()[e.family] * e.section() / ends.section[e.family];
            assert!((along - t).abs() < 1e-12, "{along} vs {t}");
            for n in &e.nodes {
                let held = mm.constraints.iter().find(|c| c.0 == n.node).unwrap().1;
                assert!(!held[e.family] && held[1 - e.family] && held[2]);
            }
        }
        assert!(mm.projectiles.is_empty());
        assert!(mm.contacts.iter().all(|c| c.static_friction == 0.0));
    }
}
