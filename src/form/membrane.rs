//! A patch tied into a membrane (the §3 combined model): the membrane's pre-stress that
//! pulls the tied yarn ends with the residual tension, and the tied model's final
//! settling with that pre-stress corrected until the bands carry the tension.

use crate::error::{Result, WeftError};
use crate::model::{ElementKind, Model};
use crate::solver::relax::RelaxStats;
use crate::solver::vec3::sub;
use crate::solver::Solver;

use super::ends::Ends;
use super::measure::band_tension;
use super::params::Params;
use super::relax::Relaxation;
use super::weave::{family, quad_thickness, quads};

/// Rounds of the tied model's final settling, each with the membrane's pre-stress
/// corrected by the tension the previous one left in the bands.
const MEMBRANE_ROUNDS: usize = 6;

/// The membrane's pre-stress.
#[derive(Debug, Clone)]
pub struct PreStress {
    /// The membrane's quads (the quads of no yarn).
    pub quads: Vec<usize>,
    /// The initial stress [S₁₁, S₂₂, S₁₂] of each [Pa], in material axes 1 = x, 2 = y.
    pub stress: [f64; 3],
}

impl PreStress {
    /// The closed form: the yarns' tension per unit length of the edge their ends are
    /// tied to, N₀ = Σ T (the ends' section shares) / c = T·layers/p for the quarter
    /// patch whose edge runs from the symmetry plane to c; S₀ = N₀/s in material axes
    /// 1 = x (the warp's ends on x = c), 2 = y.
    pub fn closed_form(m: &Model, ends: &Ends, tension: [f64; 2]) -> Result<PreStress> {
        let quads = quads(m);
        let membrane: Vec<usize> = (0..quads.len())
            .filter(|&e| family(m, quads.part[e]).is_none())
            .collect();
        let s = membrane
            .iter()
            .map(|&e| quad_thickness(m, e))
            .fold(0.0, f64::max);
        let mut s0 = [0.0; 3];
        for (f, s0f) in s0.iter_mut().take(2).enumerate() {
            let (mut total, mut c) = (0.0, 0.0f64);
            for end in ends.of_family(f) {
                total += tension[f] * end.section() / ends.section[f];
                for n in &end.nodes {
                    c = c.max(m.coords[n.node][f].abs());
                }
            }
            if membrane.is_empty() || !(s > 0.0) || !(c > 0.0) {
                return Err(WeftError::input(
                    "the yarn ends are tied, but to no membrane quads of known thickness",
                )
                .in_file("ties.parquet")
                .hint("generate the combined model with `weft-weave woven --membrane-length`"));
            }
            *s0f = total / c / s;
        }
        Ok(PreStress {
            quads: membrane,
            stress: s0,
        })
    }

    /// Give the membrane quads of `m` this initial stress.
    pub fn apply(&self, m: &mut Model) {
        let b = m.elements.get_mut(&ElementKind::Quad).expect("quads");
        if b.stress0.is_empty() {
            b.stress0 = vec![[0.0; 3]; b.len()];
        }
        for &e in &self.quads {
            b.stress0[e] = self.stress;
        }
    }
}

/// The tied model `m` at the relaxed state of `r`, ready to relax once more: its ties
/// back, the contacts of the pulled model (`contacts_of`), nothing else loaded, the
/// membrane pre-stressed by `pre`.
fn tied_model(m: &Model, contacts_of: &Model, solver: &Solver, pre: &PreStress) -> Model {
    let mut m2 = m.clone();
    m2.projectiles.clear();
    m2.loads.clear();
    m2.initial_velocities.clear();
    m2.contacts = contacts_of.contacts.clone();
    m2.initial_displacement = solver
        .state()
        .x
        .iter()
        .zip(&m.coords)
        .map(|(a, b)| sub(a, b))
        .collect();
    pre.apply(&mut m2);
    m2
}

/// Tied ends: with the patch formed, the ties and the membrane's pre-stress come back
/// and the whole model settles once more (the band ends meet the flat membrane at the
/// straight runs' slope, whose alternating z pull the membrane edge takes by rippling).
/// `r` is the pulled model `pulled`'s converged relaxation and goes on as the tied
/// model's; `pre` ends as the pre-stress the formed model gets; `section` the yarns'
/// sections per family, `credited` the work credited to the start.
///
/// The membrane's pull is displacement-limited: where its edge ripples, the band ends
/// follow it and the crimped yarns go slacker (measured 0.453 N of 0.5 at the 10 × 10),
/// so S₀ is corrected until the bands carry the requested tension to 0.3 %. An error
/// when after [`MEMBRANE_ROUNDS`] the bands are off by more than 1 %.
#[allow(clippy::too_many_arguments)]
pub fn settle(
    r: &mut Relaxation,
    m: &Model,
    pulled: &Model,
    pre: &mut PreStress,
    p: &Params,
    section: [f64; 2],
    credited: f64,
    progress: &mut dyn FnMut(&RelaxStats),
) -> Result<()> {
    let tension = p.tension();
    let first = r.stats;
    r.options.hold_in_rest_test = vec![];
    // With the ties back the patch is no longer in its own equilibrium: relax first.
    r.options.probe_first = false;
    let s0_closed = pre.stress;
    let mut last: [Option<(f64, f64)>; 2] = [None, None];
    let mut off = f64::INFINITY;
    let mut measured = [f64::NAN; 2];
    for _ in 0..MEMBRANE_ROUNDS {
        let m2 = tied_model(m, pulled, &r.solver, pre);
        let before = r.stats;
        r.solver = Solver::new(&m2)?;
        r.options.work_offset = before.removed + before.kinetic + credited;
        r.options.creep_window = p.creep_window(r.solver.time_step().dt);
        let mut st = r.solver.relax(&r.options, progress)?;
        st.steps += before.steps;
        st.removed += before.removed;
        st.contact_force = st.contact_force.max(first.contact_force);
        r.stats = st;
        if !st.converged {
            break;
        }
        let t = band_tension(m, &r.solver, section);
        measured = t;
        off = (0..2)
            .filter(|&f| tension[f] > 0.0)
            .map(|f| (t[f] / tension[f] - 1.0).abs())
            .fold(0.0, f64::max);
        if off <= 3e-3 {
            break;
        }
        // Secant on S₀ ↦ T per family (the first round scales by T/T₁): the bands
        // take only part of a change in S₀, the membrane's own relief the rest.
        let s0 = &mut pre.stress;
        for f in 0..2 {
            if tension[f] > 0.0 && t[f] > 0.0 {
                let next = match last[f] {
                    Some((s_prev, t_prev)) if (t[f] - t_prev).abs() > 1e-6 * tension[f] => {
                        s0[f] + (tension[f] - t[f]) * (s0[f] - s_prev) / (t[f] - t_prev)
                    }
                    _ => s0[f] * tension[f] / t[f],
                };
                last[f] = Some((s0[f], t[f]));
                // Never below half or above four times the closed form N₀/s.
                s0[f] = next.clamp(0.5 * s0_closed[f], 4.0 * s0_closed[f]);
            }
        }
    }
    if r.stats.converged && off > 0.01 {
        let s0 = pre.stress;
        return Err(WeftError::input(format!(
            "the membrane around the patch, pre-stressed at up to {:.3e} / {:.3e} Pa ({:.2} / {:.2} × T/(p·s)), \
             leaves {:.4} / {:.4} N in the warp / weft bands after {MEMBRANE_ROUNDS} rounds",
            s0[0],
            s0[1],
            s0[0] / s0_closed[0].max(f64::MIN_POSITIVE),
            s0[1] / s0_closed[1].max(f64::MIN_POSITIVE),
            measured[0],
            measured[1]
        ))
        .expected(format!(
            "the requested tension {} / {} N to 1 %",
            tension[0], tension[1]
        ))
        .hint("a membrane much smaller than the patch cannot hold the tension: raise --membrane-length"));
    }
    Ok(())
}
