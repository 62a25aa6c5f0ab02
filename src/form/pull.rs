//! The pulled model that forming relaxes (step 1 of [`crate::form`]): the yarn ends let
//! go along their yarn and pulled outwards by T, everything but the fabric set aside.

use crate::error::{Result, WeftError};
use crate::model::contacts::InitialPenetration;
use crate::model::{Load, Model, TimeLaw};

use super::ends::{tie_slaves, Ends};
use super::params::Params;
use super::start::Start;

/// The model that forming relaxes: `m` with its projectiles, loads and initial
/// velocities set aside, its contacts frictionless (unless `p.friction`) and acting on
/// the full depth of any initial overlap (`keep`), each yarn end let go along its yarn
/// and pulled outwards by T shared over its nodes in proportion to their sections.
///
/// Tied ends (the §3 combined model): the patch is formed as a patch alone, its ends
/// held and pulled as below with the membrane set aside (untied, unloaded: it does not
/// move), and the ties come back in the formed model with the membrane pre-stressed to
/// pull the ends with the residual tension (its displacement-limited pull would go
/// slack while the crimped yarns straighten: measured, a 10 × 10 patch formed against
/// the pre-stressed membrane kept no tension at all). The solver keeps each formed
/// slave's offset from its masters (the ends slid along their yarns while forming).
pub fn pulled_model(m: &Model, p: &Params, ends: &Ends) -> Model {
    let mut mm = m.clone();
    if ends.tied {
        let tied = tie_slaves(m);
        mm.ties.retain(|t| !tied[t.slave]);
        for n in 0..m.num_nodes() {
            if tied[n] {
                mm.constraints.push((n, [true; 3]));
            }
        }
    }
    mm.projectiles.clear();
    mm.loads.clear();
    mm.initial_velocities.clear();
    for c in &mut mm.contacts {
        c.initial_penetration = InitialPenetration::Keep;
        if !p.friction {
            c.static_friction = 0.0;
            c.dynamic_friction = 0.0;
        }
    }
    let tension = p.tension();
    let mut lid = 0;
    for end in &ends.ends {
        for node in &end.nodes {
            if tension[end.family] > 0.0 {
                lid += 1;
                mm.loads.push(Load {
                    id: lid,
                    node: node.node,
                    force: ends.pull(end, node, tension),
                    law: TimeLaw::Step { start: 0.0 },
                });
            }
        }
    }
    let families = ends.node_families(m.num_nodes());
    for (n, c) in mm.constraints.iter_mut() {
        if let Some(f) = families[*n] {
            c[f] = false;
        }
    }
    mm
}

/// The largest pull on an end node [N] (the relaxation's force scale).
pub fn largest_pull(ends: &Ends, tension: [f64; 2]) -> f64 {
    ends.ends
        .iter()
        .flat_map(|e| e.nodes.iter().map(move |n| ends.pull(e, n, tension)))
        .map(|f| crate::solver::vec3::norm(&f))
        .fold(0.0, f64::max)
}

/// Put the pulled model `mm` (of `m`) at `start`, if there is one: its displacements
/// become the initial displacement. The forming work credited to it [J] (0 without).
pub fn apply_start(mm: &mut Model, m: &Model, start: Option<&Start>) -> Result<f64> {
    let Some(s) = start else {
        return Ok(0.0);
    };
    if s.u.len() != m.num_nodes() {
        return Err(WeftError::input(format!(
            "the start has {} displacements for {} nodes",
            s.u.len(),
            m.num_nodes()
        )));
    }
    mm.initial_displacement = s.u.clone();
    Ok(s.work)
}
