//! What forming measures of the relaxed weave (steps 3 and 5 of [`crate::form`]): the
//! deepest contact, the yarn tension in the bands and at the held ends, and the crimp of
//! the warp and the weft on the x axis.

use crate::error::{Result, WeftError};
use crate::model::Model;
use crate::solver::membrane::tension_1;
use crate::solver::vec3::{norm, sub};
use crate::solver::Solver;

use super::ends::Ends;
use super::weave::{centre_line, family, quads, trusses, CentreLines};

/// The deepest contact penetration over its contact distance (0 without contact), or
/// an error when it exceeds `limit` (a yarn went through another: naming the node and
/// the element).
pub fn check_penetration(m: &Model, solver: &Solver, limit: f64) -> Result<f64> {
    let max_pen = solver.operator().surfaces.deepest();
    if let Some(d) = max_pen {
        let (r, g, cid, node, el) = (d.ratio, d.depth, d.contact_id, d.node, d.element);
        if r > limit {
            // The surface's element kind (of the definition's master part; a two-way
            // definition between bands or between chains has one kind on both sides).
            let kind = m
                .contacts
                .iter()
                .find(|c| c.id == cid)
                .map_or("element", |c| m.parts[c.master].kind.name());
            return Err(WeftError::input(format!(
                "after forming, node `{}` is {g:.3e} m inside the surface of {kind} `{el}` (contact `{cid}`): {:.0} % of the contact distance",
                m.node_id[node],
                100.0 * r
            ))
            .expected(format!(
                "penetrations below {:.0} % of the contact distance (deeper, a yarn may have gone through another)",
                100.0 * limit
            ))
            .hint("lower the tension, or raise the contact penalty_scale in contacts.parquet"));
        }
    }
    Ok(max_pen.map_or(0.0, |d| d.ratio))
}

/// The bands' tension per family: the volume mean of (P ê₁)·f̂₁ × the yarn's section
/// `section` (chains: the length-weighted mean of the trusses' stress N/A × it) at the
/// solver's state [N] (NaN for a family without yarns).
pub fn band_tension(m: &Model, solver: &Solver, section: [f64; 2]) -> [f64; 2] {
    let quads = quads(m);
    let trusses = trusses(m);
    let x = &solver.state().x;
    let qs = &solver.operator().el.quad;
    let mut tens = [f64::NAN; 2];
    for (f, t) in tens.iter_mut().enumerate() {
        let (mut sv, mut v) = (0.0, 0.0);
        for e in 0..qs.id.len() {
            if family(m, quads.part[e]) != Some(f) {
                continue;
            }
            let xe: [[f64; 3]; 4] = std::array::from_fn(|a| x[qs.nodes[e][a] as usize]);
            let vol = qs.reference[e].area * qs.thickness[e];
            sv += tension_1(&xe, &qs.reference[e], &qs.material[e]) * vol;
            v += vol;
        }
        // Chains: the length-weighted mean of the trusses' stress N/A.
        let tg = &solver.operator().el.truss;
        for e in 0..tg.id.len() {
            if family(m, trusses.part[e]) != Some(f) {
                continue;
            }
            let [a, b] = tg.nodes[e].map(|n| n as usize);
            let n = crate::solver::truss::axial_force(
                &x[a],
                &x[b],
                tg.k[e],
                tg.l0[e],
                tg.tension_only[e],
            );
            sv += n * tg.l0[e];
            v += trusses.truss_area(&m.parts, e) * tg.l0[e];
        }
        if v > 0.0 {
            *t = sv / v * section[f];
        }
    }
    tens
}

/// The tension per yarn at the ends, per family: the internal force `fi` along the yarn
/// on the end nodes, per yarn end, over the ends that carry a whole yarn's section [N]
/// (NaN for a family without one).
pub fn end_tension(ends: &Ends, fi: &[[f64; 3]]) -> [f64; 2] {
    let mut end_t = [f64::NAN; 2];
    for (f, t) in end_t.iter_mut().enumerate() {
        let a = ends.section[f];
        let full: Vec<_> = ends
            .of_family(f)
            .filter(|e| (e.section() - a).abs() < 1e-9 * a)
            .collect();
        if !full.is_empty() {
            let s: f64 = full
                .iter()
                .flat_map(|e| e.nodes.iter().map(|n| -e.sign * fi[n.node][f]))
                .sum();
            *t = s / full.len() as f64;
        }
    }
    end_t
}

/// The shape of a yarn's centre line.
#[derive(Debug, Clone, Copy)]
pub struct Crimp {
    /// Path length over projected length − 1.
    pub crimp: f64,
    /// Half the peak-to-peak height of the centre line over the crossings [m].
    pub amplitude: f64,
}

/// Crimp and amplitude (half the height range of the nodes at the crossings) of a
/// centre line at positions `x`.
fn crimp(m: &Model, x: &[[f64; 3]], line: &[usize], fam: usize, crossings: &[usize]) -> Crimp {
    if line.len() < 2 {
        return Crimp {
            crimp: f64::NAN,
            amplitude: f64::NAN,
        };
    }
    let along = fam;
    let path: f64 = line
        .windows(2)
        .map(|w| norm(&sub(&x[w[1]], &x[w[0]])))
        .sum();
    let straight = (x[*line.last().unwrap()][along] - x[line[0]][along]).abs();
    // Crossing nodes: the line's nodes at the reference positions of the crossings.
    let zs: Vec<f64> = line
        .iter()
        .filter(|&&n| {
            crossings
                .iter()
                .any(|&c| (m.coords[c][along] - m.coords[n][along]).abs() < 1e-12)
        })
        .map(|&n| x[n][2])
        .collect();
    let (lo, hi) = zs
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), &z| {
            (l.min(z), h.max(z))
        });
    Crimp {
        crimp: path / straight - 1.0,
        amplitude: 0.5 * (hi - lo),
    }
}

/// The crimp of the warp and the weft on the x axis, before forming and after.
#[derive(Debug, Clone, Copy)]
pub struct Crimps {
    /// Warp, weft at the reference positions ...
    pub before: [Crimp; 2],
    /// ... and at the formed ones.
    pub after: [Crimp; 2],
    /// The crimp of a string pulled over point supports at the crossings: straight
    /// segments between heights ±a, √(1 + (2a/p)²) − 1, with a the warp's amplitude
    /// before.
    pub target: f64,
}

impl Crimps {
    /// The crimps of the warp through `axis_x` and the weft through `axis_x_weft` of `m`,
    /// formed to the positions `x`.
    pub fn measure(m: &Model, x: &[[f64; 3]], lines: &CentreLines) -> Crimps {
        let warp_line = centre_line(m, "axis_x", 0);
        let weft_line = centre_line(m, "axis_x_weft", 1);
        let xing_w = m.node_sets.get("axis_x").cloned().unwrap_or_default();
        // The weft's crossings: along y at the warp centre lines (multiples of p).
        let xing_f: Vec<usize> = weft_line
            .iter()
            .copied()
            .filter(|&n| lines.on_line(m.coords[n][1]))
            .collect();
        let at = |xs: &[[f64; 3]]| {
            [
                crimp(m, xs, &warp_line, 0, &xing_w),
                crimp(m, xs, &weft_line, 1, &xing_f),
            ]
        };
        let before = at(&m.coords);
        Crimps {
            before,
            after: at(x),
            target: (1.0 + (2.0 * before[0].amplitude / lines.spacing).powi(2)).sqrt() - 1.0,
        }
    }
}

/// What forming measured of the relaxed weave.
#[derive(Debug, Clone, Copy)]
pub struct Measured {
    /// Tension per yarn in the bands, warp and weft ([`band_tension`]) [N] ...
    pub band_tension: [f64; 2],
    /// ... and at the pulled ends ([`end_tension`]) [N].
    pub end_tension: [f64; 2],
    pub crimps: Crimps,
    /// Deepest contact penetration over its contact distance.
    pub max_penetration_ratio: f64,
}

/// Measure the weave relaxed by `solver` (the pulled model of `m`, its yarn ends
/// `ends`): an error when a contact is deeper than `penetration_limit` of its contact
/// distance.
pub fn measure(
    m: &Model,
    solver: &mut Solver,
    ends: &Ends,
    lines: &CentreLines,
    penetration_limit: f64,
) -> Result<Measured> {
    let max_penetration_ratio = check_penetration(m, solver, penetration_limit)?;
    let fi = solver.internal_forces();
    Ok(Measured {
        band_tension: band_tension(m, solver, ends.section),
        end_tension: end_tension(ends, &fi),
        crimps: Crimps::measure(m, &solver.state().x, lines),
        max_penetration_ratio,
    })
}
