//! The relaxed start of a pretensioned reduced model ([`PretensionStart::Relaxed`]):
//! the crimped crossings settled by dynamic relaxation, written as the model's initial
//! displacements.
//!
//! [`PretensionStart::Relaxed`]: super::params::PretensionStart::Relaxed

use super::params::WovenParams;
use crate::error::{Result, WeftError};
use crate::model::{ElementKind, Model};

/// How the relaxed start ([`PretensionStart::Relaxed`]) is stopped. Why these: the
/// crossings settle in a few hundred steps (their link springs are the model's stiffest
/// parts, and set the step); the test window of 200 steps and the free rest probe of
/// 2000 steps (≈ 10 µs at the default model's 5 ns step, long against a crossing's
/// period ≈ 30 ns) are far longer.
const RELAX_MAX_STEPS: u64 = 1_000_000;
const RELAX_CHECK_EVERY: u64 = 200;
const RELAX_PROBE_STEPS: u64 = 2000;
/// Residual force ≤ 10⁻⁴ of the yarn tension E·A·ε₀; kinetic energy ≤ 10⁻⁸ of the work
/// the relaxation took; left alone at rest, no node moves more than 10⁻³ of the crimp.
const RELAX_FORCE_TOLERANCE: f64 = 1e-4;
const RELAX_KINETIC_TOLERANCE: f64 = 1e-8;
const RELAX_CREEP_TOLERANCE: f64 = 1e-3;

/// The relaxed start: relax a copy of the model (no projectile, link sliders stuck) and
/// write its equilibrium as the initial displacements.
pub(super) fn relax_start(m: &mut Model, p: &WovenParams) -> Result<()> {
    let mut r = m.clone();
    r.projectiles.clear();
    for part in r.parts.iter_mut().filter(|q| q.kind == ElementKind::Link) {
        part.props.slip_force = None;
        part.props.friction = None;
        part.props.unilateral = None;
    }
    let mut solver = crate::solver::Solver::new(&r)?;
    let tension = p.yarn_modulus * p.yarn_area * p.pretension_strain.abs();
    let stats = solver.relax(
        &crate::solver::relax::RelaxOptions {
            max_steps: RELAX_MAX_STEPS,
            min_steps: RELAX_CHECK_EVERY,
            check_every: RELAX_CHECK_EVERY,
            alpha: 0.8,
            kinetic_tolerance: RELAX_KINETIC_TOLERANCE,
            force_tolerance: RELAX_FORCE_TOLERANCE,
            force_scale: tension,
            creep_window: RELAX_PROBE_STEPS,
            creep_tolerance: RELAX_CREEP_TOLERANCE * p.crimp.abs().max(p.spacing * 1e-3),
            work_offset: 0.0,
            contact_damping: 0.0,
            hold_in_rest_test: vec![],
            probe_first: false,
        },
        &mut |_| {},
    )?;
    if !stats.converged {
        return Err(WeftError::input(format!(
            "the pretensioned model did not settle in {} steps (residual force {:.3e} N of the yarn tension {tension:.3e} N; a free node moved {:.3e} m at rest)",
            stats.steps, stats.residual, stats.creep
        ))
        .expected("an equilibrium of the crimped crossings under the pretension")
        .hint("check --crimp and --k-z, or start with --pretension-start balanced"));
    }
    check_unilateral_links(m, &solver, tension)?;
    m.initial_displacement = solver
        .state()
        .x
        .iter()
        .zip(&m.coords)
        .map(|(x, x0)| [x[0] - x0[0], x[1] - x0[1], x[2] - x0[2]])
        .collect();
    m.validate()
}

/// A unilateral link found pulling at the equilibrium would let go at the start.
fn check_unilateral_links(m: &Model, solver: &crate::solver::Solver, tension: f64) -> Result<()> {
    let Some(b) = m.block(ElementKind::Link) else {
        return Ok(());
    };
    // The solver's three link families keep the table's order within each.
    let el = &solver.operator().el;
    let (plain, framed, sliding) = (&el.link, &el.framed_link, &el.sliding_link);
    let (mut ip, mut ifr, mut isl) = (0, 0, 0);
    for e in 0..b.len() {
        let props = &m.parts[b.part[e]].props;
        let f = if props.sliding == Some(true) {
            isl += 1;
            sliding.normal_spring_force(isl - 1, &solver.state().x)
        } else if props.local_frame == Some(true) {
            ifr += 1;
            framed.normal_spring_force(ifr - 1, &solver.state().x)
        } else {
            ip += 1;
            plain.normal_spring_force(ip - 1, &solver.state().x)
        };
        if props.unilateral != Some(true) {
            continue;
        }
        if f < -RELAX_FORCE_TOLERANCE * tension {
            return Err(WeftError::input(format!(
                "unilateral link `{}` pulls its yarns together with {:.3e} N at the relaxed equilibrium",
                b.id[e], -f
            ))
            .expected("every unilateral link in compression at the pretensioned equilibrium")
            .hint("a crossing whose yarns separate under the pretension: use two-way links, or --pretension-start balanced"));
        }
    }
    Ok(())
}
