//! What forming reads of a woven model: the yarns (parts named `warp…` run along x,
//! `weft…` along y; bands of quads or chains of trusses), their spacing and centre
//! lines, and their thickness.

use crate::error::{Result, WeftError};
use crate::model::{ElementBlock, ElementKind, Model};

/// Yarn family of a part: 0 warp (along x), 1 weft (along y).
pub fn family(m: &Model, part: usize) -> Option<usize> {
    let n = &m.parts[part].name;
    if n.starts_with("warp") {
        Some(0)
    } else if n.starts_with("weft") {
        Some(1)
    } else {
        None
    }
}

/// The yarn elements of `m` (quads of bands, trusses of chains, of parts named `warp…`
/// or `weft…`): (block, nodes per element, element).
pub fn yarn_elements(m: &Model) -> impl Iterator<Item = (&ElementBlock, usize, usize)> {
    [ElementKind::Quad, ElementKind::Truss]
        .into_iter()
        .filter_map(move |k| m.elements.get(&k).map(|b| (b, k.nodes_per_element())))
        .flat_map(move |(b, npe)| {
            (0..b.len())
                .filter(move |&e| family(m, b.part[e]).is_some())
                .map(move |e| (b, npe, e))
        })
}

/// The number of yarn elements of `m`.
pub fn yarn_count(m: &Model) -> usize {
    yarn_elements(m).count()
}

/// The forming work `work` of a smaller formed model `from`, scaled to `to` by the
/// yarn element count [J].
pub fn scaled_work(work: f64, to: &Model, from: &Model) -> f64 {
    work * yarn_count(to) as f64 / yarn_count(from).max(1) as f64
}

/// The model's quads (empty if it has none).
pub fn quads(m: &Model) -> &ElementBlock {
    static NONE: std::sync::OnceLock<ElementBlock> = std::sync::OnceLock::new();
    m.elements
        .get(&ElementKind::Quad)
        .unwrap_or_else(|| NONE.get_or_init(ElementBlock::default))
}

/// The model's trusses (empty if it has none).
pub fn trusses(m: &Model) -> &ElementBlock {
    static NONE: std::sync::OnceLock<ElementBlock> = std::sync::OnceLock::new();
    m.elements
        .get(&ElementKind::Truss)
        .unwrap_or_else(|| NONE.get_or_init(ElementBlock::default))
}

/// Thickness of quad `e` of `m`: the mean of its nodal thickness, else its part's.
pub fn quad_thickness(m: &Model, e: usize) -> f64 {
    let quads = quads(m);
    if quads.thickness.is_empty() {
        m.parts[quads.part[e]].props.thickness.unwrap_or(0.0)
    } else {
        quads.thickness[4 * e..4 * e + 4].iter().sum::<f64>() / 4.0
    }
}

/// The largest yarn thickness: the bands' nodal thickness, or the chains' contact
/// thickness.
pub fn largest_thickness(m: &Model) -> f64 {
    let quads = quads(m);
    if quads.thickness.is_empty() {
        m.parts
            .iter()
            .filter_map(|q| q.props.thickness)
            .fold(0.0, f64::max)
    } else {
        quads.thickness.iter().cloned().fold(0.0, f64::max)
    }
    .max(
        m.contacts
            .iter()
            .flat_map(|c| [c.slave_thickness, c.master_thickness])
            .flatten()
            .fold(0.0, f64::max),
    )
}

/// Part name of each node (the first quad, else truss, that holds it), or "".
pub fn node_parts(m: &Model) -> Vec<&str> {
    let mut out = vec![""; m.num_nodes()];
    for kind in [ElementKind::Quad, ElementKind::Truss] {
        let Some(b) = m.elements.get(&kind) else {
            continue;
        };
        let npe = kind.nodes_per_element();
        for e in 0..b.len() {
            for &n in &b.nodes[npe * e..npe * (e + 1)] {
                if out[n].is_empty() {
                    out[n] = &m.parts[b.part[e]].name;
                }
            }
        }
    }
    out
}

/// The yarn spacing from the node set `axis_x` (its first two crossings).
pub fn spacing_of(m: &Model) -> Option<f64> {
    let s = m.node_sets.get("axis_x")?;
    (s.len() >= 2)
        .then(|| (m.coords[s[1]][0] - m.coords[s[0]][0]).abs())
        .filter(|d| *d > 0.0)
}

/// Where the yarns' centre lines lie: at x₀ + jp (x₀ = 0 in a quarter patch, p/2 in a
/// full one, whose yarns straddle x = 0), likewise in y.
#[derive(Debug, Clone, Copy)]
pub struct CentreLines {
    /// The yarn spacing p [m].
    pub spacing: f64,
    /// x₀ modulo p [m].
    pub phase: f64,
}

impl CentreLines {
    /// The centre lines of `m` from its node set `axis_x`.
    pub fn of(m: &Model) -> Result<CentreLines> {
        let Some(spacing) = spacing_of(m) else {
            return Err(WeftError::input(
                "the model has no node set `axis_x` with two crossings: the yarn spacing is unknown",
            )
            .hint("form a model from `weft-weave woven`"));
        };
        let phase = m.node_sets["axis_x"]
            .first()
            .map_or(0.0, |&n| m.coords[n][0].rem_euclid(spacing));
        Ok(CentreLines { spacing, phase })
    }

    /// The yarn whose centre line is nearest to the coordinate `c` across it.
    pub fn yarn(&self, c: f64) -> i64 {
        ((c - self.phase) / self.spacing).round() as i64
    }

    /// Whether `c` lies on a centre line.
    pub fn on_line(&self, c: f64) -> bool {
        let r = (c - self.phase) / self.spacing;
        (r - r.round()).abs() < 1e-9
    }
}

/// The centre line of the yarn of family `fam` through the first node of `set`: the
/// nodes of its part with the same reference y (warp) or x (weft), along the yarn.
pub fn centre_line(m: &Model, set: &str, fam: usize) -> Vec<usize> {
    let Some(&n0) = m.node_sets.get(set).and_then(|s| s.first()) else {
        return vec![];
    };
    let (across, along) = if fam == 0 { (1, 0) } else { (0, 1) };
    let c = m.coords[n0][across];
    // The yarn's elements: band quads or chain trusses.
    let Some((b, npe)) = [ElementKind::Quad, ElementKind::Truss]
        .into_iter()
        .filter_map(|k| m.block(k).map(|b| (b, k.nodes_per_element())))
        .find(|(b, npe)| (0..b.len()).any(|e| b.nodes[npe * e..npe * (e + 1)].contains(&n0)))
    else {
        return vec![];
    };
    let part = (0..b.len())
        .find(|&e| b.nodes[npe * e..npe * (e + 1)].contains(&n0))
        .map(|e| b.part[e]);
    let mut nodes: Vec<usize> = (0..b.len())
        .filter(|&e| Some(b.part[e]) == part)
        .flat_map(|e| b.nodes[npe * e..npe * (e + 1)].to_vec())
        .filter(|&n| (m.coords[n][across] - c).abs() < 1e-12)
        .collect();
    nodes.sort_unstable_by(|a, b| m.coords[*a][along].total_cmp(&m.coords[*b][along]));
    nodes.dedup();
    nodes
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_coordinate_belongs_to_the_nearest_centre_line() {
        // A full patch's yarns straddle x = 0: centre lines at p/2 + jp.
        let lines = CentreLines {
            spacing: 1e-3,
            phase: 0.5e-3,
        };
        assert_eq!(lines.yarn(0.5e-3), 0);
        assert_eq!(lines.yarn(1.4e-3), 1);
        assert_eq!(lines.yarn(-0.5e-3), -1);
        assert!(lines.on_line(2.5e-3));
        assert!(!lines.on_line(2e-3));
    }
}
