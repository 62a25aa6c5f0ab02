//! Forming a woven patch by contact equilibrium (`weft-form`; the paper's §2, after
//! Barauskas & Abraitienė, IJIE 34(7), 2007): the yarns are pulled at their held ends
//! with their residual tension, the weave settles by contact, and the equilibrium is
//! written as a model whose impact run starts at rest and in equilibrium.
//!
//! Glossary: T_w, T_f the residual tension per warp and weft yarn [N]; A the yarn's
//! section area [m²]; K kinetic energy; W the forming work (the energy the relaxation
//! removed); P ê₁ the force per reference area across a cut of a band (first
//! Piola–Kirchhoff stress along the yarn).
//!
//! Why pull the ends rather than give the yarns an initial stress T/A: the axial
//! stiffness E·A of a yarn (5300 N for the default aramid) is 10⁴ × its tension, so a
//! residual tension of 0.5 N is a strain of 10⁻⁴, the change of crimp that a contact
//! penalty's sub-micrometre give already makes: clamped yarns with an initial stress
//! relax it almost entirely (to 3·10⁻⁴ N in the 6 × 6 quarter, measured). Pulled by a
//! force, a yarn carries exactly T whatever its crimp becomes (a string over
//! frictionless supports; Irvine, *Cable Structures*, 1981, §1).
//!
//! Steps:
//! 1. the yarn ends held in x, y and z (parts named `warp…` run along x, `weft…` along y)
//!    are let go along their yarn and pulled outwards by T, shared over the end
//!    section's nodes in proportion to the section each carries (Σ = T); projectiles,
//!    loads and initial velocities are set aside; contacts are frictionless (the
//!    equilibrium must hold without friction, whose stick state an impact run does not
//!    inherit) and act on the full depth of any initial overlap (`keep`);
//! 2. dynamic relaxation with local damping ([`crate::solver::relax`]) until the largest
//!    kinetic energy of a test window is ≤ `kinetic_tolerance` × W and the largest
//!    residual force on a free degree of freedom ≤ `force_tolerance` × the largest
//!    contact force seen (or the largest pull), and then, left alone at rest (a free,
//!    undamped probe run from there), no node moves more than `creep_tolerance` × the
//!    largest yarn thickness within `creep_time` (the pretensioned patch's slow drum
//!    mode settles last); an error after `max_steps`;
//! 3. checks: no contact deeper than `penetration_limit` of its contact distance (a yarn
//!    went through another: an error naming the node and the element);
//! 4. the formed model: the reference geometry unchanged, the formed positions as the
//!    nodes' initial displacement u₀ (so strains, contact overlaps and hourglass forces
//!    are exactly those of the equilibrium), the yarn ends held again where they came
//!    to rest, contacts `keep` with their friction back, the projectile moved up by as
//!    much as the fabric's top rose;
//! 5. a report (`form.parquet`): steps, K/W, residual and contact forces, the crimp and
//!    crimp amplitude of the warp and the weft on the x axis before and after, the yarn
//!    tension measured in the bands (volume mean of (P ê₁)·f̂₁ × A) and at the held ends.
//!
//! [`form_from`] runs these steps, each a function of a module of its own: the
//! parameters and their checks (`params`); what forming reads of the weave (`weave`);
//! the yarn ends, one `YarnEnd` each (`ends`); the pulled model (`pull`); a tied
//! patch's membrane pre-stress and final settling (`membrane`); the relaxation
//! (`relax`); the measurements (`measure`); the formed model (`formed`); the report
//! (`report`); the starts other than the generated geometry (`start`: the periodic
//! [`cell`] reflected over the patch, or a formed smaller patch laid over it).

use std::path::PathBuf;
use std::time::Instant;

use serde::Serialize;

use crate::error::{Result, WeftError};
use crate::model::io::{read_model, write_model};
use crate::model::Model;
use crate::solver::relax::RelaxStats;
use crate::table::Provenance;

pub mod cell;
mod ends;
mod formed;
mod measure;
mod membrane;
mod params;
mod pull;
mod relax;
mod report;
mod start;
mod weave;

pub use params::Params;
pub use report::Report;
pub use start::{cell_start, tile_start, CellSummary, Start, StartMode, CELL_TENSION_TOLERANCE};

use ends::Ends;
use formed::formed_model;
use measure::measure;
use membrane::{settle, PreStress};
use pull::{apply_start, largest_pull, pulled_model};
use relax::{equilibrium, relax, RelaxSetup};
use report::write_report;
use start::patch_start;
use weave::{largest_thickness, yarn_elements, CentreLines};

/// Form `m` (a woven model from `weft-weave woven`): the formed model and the report.
pub fn form(
    m: &Model,
    p: &Params,
    progress: &mut dyn FnMut(&RelaxStats),
) -> Result<(Model, Report)> {
    form_from(m, p, None, progress)
}

/// [`form`] from a start other than the generated geometry (a tiled smaller patch, or
/// the periodic cell reflected over the patch).
pub fn form_from(
    m: &Model,
    p: &Params,
    start: Option<&Start>,
    progress: &mut dyn FnMut(&RelaxStats),
) -> Result<(Model, Report)> {
    let began = Instant::now();
    p.validate()?;
    check_unformed_weave(m)?;
    let lines = CentreLines::of(m)?;
    let ends = Ends::find(m, &lines)?;
    let mut pulled = pulled_model(m, p, &ends);
    let mut pre_stress = ends
        .tied
        .then(|| PreStress::closed_form(m, &ends, p.tension()))
        .transpose()?;
    let credited = apply_start(&mut pulled, m, start)?;
    let thickness = largest_thickness(m);
    let setup = RelaxSetup {
        force_scale: largest_pull(&ends, p.tension()),
        thickness,
        credited,
        hold: ends.along_yarn(),
        probe_first: start.is_some_and(|s| s.cell.is_some()),
    };
    let mut r = relax(&pulled, p, setup, progress)?;
    if let (true, Some(pre)) = (r.stats.converged, pre_stress.as_mut()) {
        settle(&mut r, m, &pulled, pre, p, ends.section, credited, progress)?;
    }
    let eq = equilibrium(m, p, &r.stats, credited, thickness)?;
    let measured = measure(m, &mut r.solver, &ends, &lines, p.penetration_limit)?;
    let formed = formed_model(m, &r.solver.state().x, pre_stress.as_ref())?;
    let report = Report::new(
        &r.stats,
        &eq,
        credited,
        &measured,
        formed.top_rise,
        start,
        began,
    );
    Ok((formed.model, report))
}

/// Check that `m` has yarns to put under tension (bands of quads, or chains of trusses:
/// `weft-weave woven --yarn-model`) and is not formed already.
fn check_unformed_weave(m: &Model) -> Result<()> {
    if yarn_elements(m).next().is_none() {
        return Err(WeftError::input(
            "the model has no yarns (quads or trusses of parts named `warp…` or `weft…`): nothing to put under tension",
        )
        .in_file("parts.parquet")
        .hint("form a model from `weft-weave woven`"));
    }
    if !m.initial_displacement.is_empty() {
        return Err(WeftError::input(
            "the model is already formed (nodes.parquet has ux0, uy0, uz0)",
        )
        .in_file("nodes.parquet")
        .hint("form the generator's model, not a formed one"));
    }
    Ok(())
}

/// What `weft-form` is asked: the model folder to form, the folder to write, the
/// parameters and where to start.
#[derive(Debug, Clone, Serialize)]
pub struct Config {
    pub model: PathBuf,
    pub out: PathBuf,
    pub params: Params,
    /// A formed smaller patch of the same weave to start from ([`tile_start`]); else
    /// `start`.
    pub start_from: Option<PathBuf>,
    pub start: StartMode,
}

/// `weft-form`: read, form, write the formed model folder and its `form.parquet`.
pub fn run(c: &Config, progress: &mut dyn FnMut(&RelaxStats)) -> Result<Report> {
    let m = read_model(&c.model)?;
    let start = match &c.start_from {
        None if c.start == StartMode::Cell => Some(
            cell_start(&m, &c.params, progress)
                .map_err(|e| e.context(format!("cannot form `{}`", c.model.display())))?,
        ),
        None => None,
        Some(dir) => Some(patch_start(&m, dir)?),
    };
    let (formed, r) = form_from(&m, &c.params, start.as_ref(), progress)
        .map_err(|e| e.context(format!("cannot form `{}`", c.model.display())))?;
    let mut prov = Provenance::new("form", serde_json::to_value(c).expect("serialise"))
        .with_input(&c.model.join("nodes.parquet"))?;
    if let Some(dir) = &c.start_from {
        prov = prov.with_input(&dir.join("nodes.parquet"))?;
    }
    write_model(&formed, &c.out, &prov)?;
    write_report(&c.out.join("form.parquet"), &r, &prov)?;
    Ok(r)
}
