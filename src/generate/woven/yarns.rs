//! The yarns of every layer: where they lie ([`Weave`]), their nodes (crimped over and
//! under, held at the patch edge), their bands of quads or chains of trusses, and the
//! centre-line node sets gathered on the way ([`Built`]).

use std::collections::BTreeMap;

use super::params::{Edge, WovenBandParams};
use super::section::{Lenticular, Section};
use crate::model::{ElementKind, Model, PartProps};

/// What every yarn is built from: the parameters, the band's section, the crimp
/// amplitude, and where the yarns lie.
pub(super) struct Weave<'a> {
    p: &'a WovenBandParams,
    pub(super) section: Section,
    amp: f64,
    /// The yarns' indices j = first … last of each family.
    first: i64,
    last: i64,
    /// The yarns run from `lo` to `hi` along their length, in `n_along` elements.
    lo: f64,
    hi: f64,
    n_along: usize,
    /// Along-index of each crossing: the other family's yarn centre lines.
    crossing_at: BTreeMap<usize, i64>,
}

impl<'a> Weave<'a> {
    pub(super) fn new(p: &'a WovenBandParams, section: Section, amp: f64) -> Weave<'a> {
        let (first, last) = if p.quarter {
            (0i64, p.yarns as i64 - 1)
        } else {
            (-(p.yarns as i64) / 2, p.yarns as i64 / 2 - 1)
        };
        let (lo, hi) = if p.quarter {
            (0.0, (p.yarns as f64 - 0.5) * p.spacing)
        } else {
            (
                -(p.yarns as f64) * 0.5 * p.spacing,
                p.yarns as f64 * 0.5 * p.spacing,
            )
        };
        let n_along = ((hi - lo) / p.spacing * p.per_spacing as f64).round() as usize;
        let crossing_at = (first..=last)
            .map(|jj| {
                (
                    ((yarn_centre(p, jj) - lo) / p.spacing * p.per_spacing as f64).round() as usize,
                    jj,
                )
            })
            .collect();
        Weave {
            p,
            section,
            amp,
            first,
            last,
            lo,
            hi,
            n_along,
            crossing_at,
        }
    }

    /// The length of a yarn along the patch [m] (the modelled one: half the yarn on a
    /// quarter model).
    pub(super) fn length(&self) -> f64 {
        self.hi - self.lo
    }

    /// Elements along a yarn.
    pub(super) fn elements_along(&self) -> usize {
        self.n_along
    }

    /// The centre line of yarn j (see [`yarn_centre`]).
    fn centre(&self, j: i64) -> f64 {
        yarn_centre(self.p, j)
    }

    /// The across-indices k0 ..= k1 of yarn j's nodes: all of a band's, the upper half of
    /// a band on a symmetry plane, a chain's centre line.
    fn across(&self, j: i64) -> (usize, usize) {
        let (na, chain) = (self.section.na, self.section.chain);
        // Across offsets: a yarn on a symmetry plane keeps its upper half.
        let k0 = if chain || (self.p.quarter && j == 0) {
            na / 2
        } else {
            0
        };
        let k1 = if chain { na / 2 } else { na };
        (k0, k1)
    }
}

/// Yarn centre lines at j·p (quarter) or (j + ½)·p (full, no yarn on x = 0).
fn yarn_centre(p: &WovenBandParams, j: i64) -> f64 {
    if p.quarter {
        j as f64 * p.spacing
    } else {
        (j as f64 + 0.5) * p.spacing
    }
}

/// (−1)^j.
fn sign(j: i64) -> f64 {
    if j.rem_euclid(2) == 0 {
        1.0
    } else {
        -1.0
    }
}

/// The band quads' properties: orthotropic, the material axis at `angle` (0 for the
/// warp, π/2 for the weft).
fn band_props(p: &WovenBandParams, t_centre: f64, angle: f64) -> PartProps {
    PartProps {
        youngs_modulus_1: Some(p.modulus),
        youngs_modulus_2: Some(p.transverse_modulus),
        shear_modulus_12: Some(p.shear_modulus),
        poisson_ratio_12: Some(0.0),
        density: Some(p.density),
        thickness: Some(t_centre),
        material_angle: Some(angle),
        // Tension-field yarns (no compression) would be closer to a bundle of filaments,
        // but that stress has no potential, and in crushed regions under the nose the
        // energy balance drifts (10.9 % at 57 µs in the 60 × 60 quarter, measured):
        // opt-in only.
        no_compression: Some(p.tension_field),
        ..Default::default()
    }
}

/// Chains: trusses of the band's exact section along its centre line (half of it
/// for a yarn on a symmetry plane, which carries half a band).
fn chain_props(p: &WovenBandParams, lens: &Lenticular) -> PartProps {
    PartProps {
        youngs_modulus: Some(p.modulus),
        density: Some(p.density),
        area: Some(lens.area()),
        tension_only: Some(p.tension_field),
        ..Default::default()
    }
}

/// What the yarns leave besides their nodes and elements: each layer's (warp, weft)
/// parts, the centre-line node sets of the first layer, the yarn-end nodes, the top of
/// the fabric, and the last node and element ids.
pub(super) struct Built {
    pub(super) parts: Vec<(usize, usize)>,
    axis_x: Vec<usize>,
    axis_x_weft: Vec<usize>,
    diagonal: Vec<usize>,
    diagonal_weft: Vec<usize>,
    edge_nodes: Vec<usize>,
    pub(super) top: f64,
    /// Per yarn element, in the order they were added: its layer, family and yarn.
    pub(super) tags: Vec<Tag>,
    nid: i64,
    eid: i64,
}

/// A yarn element's place in the fabric: its layer (from 0), family (0 warp, 1 weft),
/// yarn within its part (from 1) and element id.
#[derive(Debug, Clone, Copy)]
pub(super) struct Tag {
    pub(super) layer: usize,
    pub(super) family: usize,
    pub(super) yarn: i64,
    pub(super) element: i64,
}

impl Built {
    pub(super) fn new() -> Built {
        Built {
            parts: vec![],
            axis_x: vec![],
            axis_x_weft: vec![],
            diagonal: vec![],
            diagonal_weft: vec![],
            edge_nodes: vec![],
            top: f64::NEG_INFINITY,
            tags: vec![],
            nid: 0,
            eid: 0,
        }
    }
}

/// One yarn: its family (0 warp along x, 1 weft along y), index j, part, layer and the
/// layer's mid-plane height.
#[derive(Clone, Copy)]
struct Yarn {
    fam: usize,
    j: i64,
    part: usize,
    layer: usize,
    zl: f64,
}

/// A layer at height `zl`: its warp and weft parts, then every warp yarn and every weft
/// yarn.
pub(super) fn add_layer(m: &mut Model, w: &Weave, layer: usize, zl: f64, b: &mut Built) {
    let p = w.p;
    let (kind, warp_props, weft_props) = if w.section.chain {
        let chain = chain_props(p, &w.section.lens);
        (ElementKind::Truss, chain.clone(), chain)
    } else {
        (
            ElementKind::Quad,
            band_props(p, w.section.t_centre, 0.0),
            band_props(p, w.section.t_centre, std::f64::consts::FRAC_PI_2),
        )
    };
    let warp = m.add_part(
        2 * layer as i64 + 1,
        &format!("warp_{}", layer + 1),
        kind,
        warp_props,
    );
    let weft = m.add_part(
        2 * layer as i64 + 2,
        &format!("weft_{}", layer + 1),
        kind,
        weft_props,
    );
    b.parts.push((warp, weft));
    for (fam, part) in [(0, warp), (1, weft)] {
        for j in w.first..=w.last {
            let yarn = Yarn {
                fam,
                j,
                part,
                layer,
                zl,
            };
            let idx = add_yarn_nodes(m, w, yarn, b);
            if w.section.chain {
                add_chain_elements(m, w, yarn, &idx, b);
            } else {
                add_band_elements(m, w, yarn, &idx, b);
            }
        }
    }
}

/// A yarn's nodes, `idx[i][k]` at along-index i and across-index k (a chain's, and a band's
/// on a symmetry plane, from k = na/2): the yarn ends held as `edge` says, the crossing
/// nodes of the first layer gathered into the node sets.
fn add_yarn_nodes(m: &mut Model, w: &Weave, y: Yarn, b: &mut Built) -> Vec<Vec<usize>> {
    let (p, s) = (w.p, &w.section);
    let (na, n_along, j) = (s.na, w.n_along, y.j);
    let c = w.centre(j);
    let (k0, k1) = w.across(j);
    let mut idx = vec![vec![usize::MAX; na + 1]; n_along + 1];
    for i in 0..=n_along {
        let sa = w.lo + (w.hi - w.lo) * i as f64 / n_along as f64;
        // Warp (fam 0) follows (−1)^j a cos(π(x − x₀)/p); weft
        // −(−1)^j a cos(π(y − x₀)/p), x₀ a yarn centre line (0 in the quarter,
        // p/2 in the full patch), so that the crests lie at the crossings.
        let z = y.zl
            + if y.fam == 0 { sign(j) } else { -sign(j) }
                * w.amp
                * (std::f64::consts::PI * (sa - w.centre(0)) / p.spacing).cos();
        b.top = b.top.max(z + 0.5 * s.t_centre);
        for k in k0..=k1 {
            let r = c + s.offs[k];
            let x = if y.fam == 0 { [sa, r, z] } else { [r, sa, z] };
            b.nid += 1;
            let n = m.add_node(b.nid, x);
            idx[i][k] = n;
            let at_edge = (i == n_along) || (!p.quarter && i == 0);
            if at_edge {
                b.edge_nodes.push(n);
                let hold = match p.edge {
                    Edge::Clamped => true,
                    Edge::Pinned => k == na / 2,
                    Edge::Free => false,
                };
                if hold {
                    m.constraints.push((n, [true, true, true]));
                }
            }
        }
        // Crossing nodes: the centre-line node at each crossing position.
        if let Some(&other) = w.crossing_at.get(&i) {
            if y.layer == 0 {
                gather_crossing(b, y, other, idx[i][na / 2]);
            }
        }
    }
    idx
}

/// The first layer's crossing node `n` of yarn `y`, where the yarn `other` of the other
/// family crosses it, into the centre-line node sets.
fn gather_crossing(b: &mut Built, y: Yarn, other: i64, n: usize) {
    // The x axis line: the warp j = 0 and the wefts where they cross it.
    if y.fam == 0 && y.j == 0 {
        b.axis_x.push(n);
    }
    if y.fam == 1 && other == 0 {
        b.axis_x_weft.push(n);
    }
    if other == y.j {
        if y.fam == 0 {
            b.diagonal.push(n)
        } else {
            b.diagonal_weft.push(n)
        }
    }
}

/// The tag of element `eid` of yarn `y`.
fn tag(w: &Weave, y: Yarn, eid: i64) -> Tag {
    Tag {
        layer: y.layer,
        family: y.fam,
        yarn: y.j - w.first + 1,
        element: eid,
    }
}

/// A chain's trusses along the centre-line nodes (half the section on a symmetry plane).
fn add_chain_elements(m: &mut Model, w: &Weave, y: Yarn, idx: &[Vec<usize>], b: &mut Built) {
    let na = w.section.na;
    let half = w.p.quarter && y.j == 0;
    for i in 0..w.n_along {
        b.eid += 1;
        b.tags.push(tag(w, y, b.eid));
        let ends = [idx[i][na / 2], idx[i + 1][na / 2]];
        if half {
            m.add_truss_with_area(b.eid, y.part, ends, 0.5 * w.section.lens.area());
        } else {
            m.add_element(b.eid, y.part, &ends);
        }
    }
}

/// A band's quads with their nodal thicknesses.
fn add_band_elements(m: &mut Model, w: &Weave, y: Yarn, idx: &[Vec<usize>], b: &mut Built) {
    let (na, t_node) = (w.section.na, &w.section.t_node);
    let (k0, _) = w.across(y.j);
    for i in 0..w.n_along {
        for k in k0..na {
            b.eid += 1;
            b.tags.push(tag(w, y, b.eid));
            let q = if y.fam == 0 {
                [idx[i][k], idx[i + 1][k], idx[i + 1][k + 1], idx[i][k + 1]]
            } else {
                [idx[i][k], idx[i][k + 1], idx[i + 1][k + 1], idx[i + 1][k]]
            };
            let t = if y.fam == 0 {
                [t_node[k], t_node[k], t_node[k + 1], t_node[k + 1]]
            } else {
                [t_node[k], t_node[k + 1], t_node[k + 1], t_node[k]]
            };
            m.add_element_with_thickness(b.eid, y.part, &q, &t);
        }
    }
}

/// The node sets `axis_x`, `axis_x_weft`, `diagonal`, `diagonal_weft` and `edge`.
pub(super) fn insert_sets(m: &mut Model, b: Built) {
    m.node_sets.insert("axis_x".into(), b.axis_x);
    m.node_sets.insert("axis_x_weft".into(), b.axis_x_weft);
    m.node_sets.insert("diagonal".into(), b.diagonal);
    m.node_sets.insert("diagonal_weft".into(), b.diagonal_weft);
    let mut edge_nodes = b.edge_nodes;
    edge_nodes.sort_unstable();
    m.node_sets.insert("edge".into(), edge_nodes);
}
