//! `weft-energy pulse`: a model given a smooth velocity pulse on a band of nodes, the
//! start of a wave-reflection study ([`super::energy`] measures what the pulse's energy
//! does at an interface).

use std::collections::BTreeMap;
use std::path::PathBuf;

use serde::Serialize;

use super::energy::{part_list, Region, RegionSpec};
use crate::error::{Result, WeftError};
use crate::model::io::{read_model, write_model};
use crate::model::Model;
use crate::table::Provenance;

/// A pulse: velocity `velocity` · sin²(π (x − from)/(to − from)) along `axis` (0, 1, 2)
/// on the nodes of `parts` whose reference coordinate x along that axis lies in
/// [from, to] (a smooth bell, zero at both ends, so that a lattice carries it with
/// little dispersion). Nodes held in that direction (constraints, symmetry planes) and
/// tied nodes (which move with their masters) get none; other initial velocities of the
/// chosen nodes are replaced; the projectiles are removed. `within`, when given, limits
/// the nodes further to a box of reference coordinates, [min, max] along x, y, z.
/// Returns the number of nodes given a velocity.
pub fn launch_pulse(
    m: &mut Model,
    parts: &[String],
    axis: usize,
    from: f64,
    to: f64,
    velocity: f64,
    within: Option<[[f64; 2]; 3]>,
) -> Result<usize> {
    if !(from.is_finite() && to.is_finite() && from < to) {
        return Err(WeftError::input(format!("strip {from:e} m to {to:e} m"))
            .expected("--from < --to, finite, in m"));
    }
    if !(velocity.is_finite() && velocity != 0.0) {
        return Err(WeftError::input(format!("--velocity = `{velocity}`"))
            .expected("a peak velocity ≠ 0 in m/s"));
    }
    let mut keep = vec![false; m.parts.len()];
    for p in parts {
        let i = m.part_index(p).ok_or_else(|| {
            WeftError::input(format!("--part `{p}` is not a part of the model"))
                .expected(format!("one of {}", part_list(m)))
        })?;
        keep[i] = true;
    }
    let nn = m.num_nodes();
    let mut chosen = vec![false; nn];
    for b in m.elements.values() {
        let npe = b.nodes.len() / b.len().max(1);
        for e in 0..b.len() {
            if keep[b.part[e]] {
                for &i in &b.nodes[npe * e..npe * (e + 1)] {
                    chosen[i] = true;
                }
            }
        }
    }
    let mut held = vec![false; nn];
    for (n, f) in &m.constraints {
        held[*n] |= f[axis];
    }
    for sp in &m.symmetry {
        if sp.normal == axis {
            for (i, h) in held.iter_mut().enumerate() {
                *h |= (m.coords[i][axis] - sp.position).abs() <= sp.tolerance;
            }
        }
    }
    for t in &m.ties {
        held[t.slave] = true;
    }
    let mut vel: BTreeMap<usize, [f64; 3]> = m.initial_velocities.iter().copied().collect();
    let mut count = 0;
    for i in 0..nn {
        let x = m.coords[i][axis];
        let inside = within
            .is_none_or(|b| (0..3).all(|d| m.coords[i][d] >= b[d][0] && m.coords[i][d] <= b[d][1]));
        if chosen[i] && !held[i] && inside && x >= from && x <= to {
            let s = (std::f64::consts::PI * (x - from) / (to - from)).sin();
            let mut v3 = [0.0; 3];
            v3[axis] = velocity * s * s;
            vel.insert(i, v3);
            count += 1;
        }
    }
    if count == 0 {
        return Err(WeftError::input(format!(
            "no free node of {} lies in the strip {from:e} m to {to:e} m",
            parts.join(", ")
        ))
        .expected("a strip across some nodes of the parts")
        .hint("check --axis, --from and --to against the model's coordinates (nodes.parquet)"));
    }
    m.initial_velocities = vel.into_iter().collect();
    m.projectiles.clear();
    Ok(count)
}

/// Settings of `weft-energy pulse`.
#[derive(Debug, Clone, Serialize)]
pub struct PulseConfig {
    pub model: PathBuf,
    pub parts: Vec<String>,
    /// x, y or z.
    pub axis: String,
    pub from: f64,
    pub to: f64,
    pub velocity: f64,
    /// Only nodes in this box: XMIN,XMAX,YMIN,YMAX,ZMIN,ZMAX [m].
    pub within: Option<String>,
    /// Drop a formed model's formed state (initial displacements and stresses) first.
    pub unformed: bool,
    pub out: PathBuf,
}

/// Write a copy of a model folder with a pulse instead of its projectiles; returns the
/// number of nodes given a velocity.
pub fn run_pulse(c: &PulseConfig) -> Result<usize> {
    let axis = match c.axis.as_str() {
        "x" => 0,
        "y" => 1,
        "z" => 2,
        a => {
            return Err(WeftError::input(format!("--axis `{a}`")).expected("x, y or z"));
        }
    };
    let within = match &c.within {
        None => None,
        Some(w) => match Region::parse(&format!("within=box:{w}")).map(|r| r.spec) {
            Ok(RegionSpec::Box(b)) => Some(b),
            _ => {
                return Err(WeftError::input(format!("--within `{w}`"))
                    .expected("XMIN,XMAX,YMIN,YMAX,ZMIN,ZMAX: six numbers [m], min ≤ max along each axis (inf allowed)"));
            }
        },
    };
    let mut m = read_model(&c.model)?;
    let stressed = m
        .elements
        .values()
        .any(|b| b.stress0.iter().any(|s| *s != [0.0; 3]));
    if !m.initial_displacement.is_empty() || stressed {
        if !c.unformed {
            return Err(WeftError::input(format!(
                "`{}` is a formed model (initial displacements or stresses)",
                c.model.display()
            ))
            .expected("a model without a pre-stressed state: a region's energy would hold the pre-stress's first-order work, as large as a small pulse's energy")
            .hint("add --unformed to start the pulse from the model's reference geometry"));
        }
        // As `weft-weave` built it: the geometry's small initial overlaps tracked, not
        // pushed apart (a formed model's contacts act on its overlaps from the start).
        m.initial_displacement.clear();
        for b in m.elements.values_mut() {
            b.stress0.clear();
        }
        for d in &mut m.contacts {
            d.initial_penetration = crate::model::contacts::InitialPenetration::Track;
        }
    }
    let n = launch_pulse(&mut m, &c.parts, axis, c.from, c.to, c.velocity, within)?;
    let prov = Provenance::new("pulse", serde_json::to_value(c).expect("config serialises"));
    write_model(&m, &c.out, &prov)?;
    Ok(n)
}
