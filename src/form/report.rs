//! What forming did: the [`Report`] and its table `form.parquet`.

use std::path::Path;
use std::time::Instant;

use serde::Serialize;

use crate::error::Result;
use crate::solver::relax::RelaxStats;
use crate::table::{batch, write_table, Col, Provenance};

use super::measure::Measured;
use super::relax::Equilibrium;
use super::start::{CellSummary, Start};

/// What forming did.
#[derive(Debug, Clone, Default, Serialize)]
pub struct Report {
    pub steps: u64,
    pub time_step: f64,
    pub kinetic_over_work: f64,
    pub forming_work: f64,
    /// Of which credited to the start (a tiled smaller patch's forming work scaled by
    /// the element count; 0 from the generated geometry) [J].
    pub start_work: f64,
    pub max_residual_force: f64,
    pub max_contact_force: f64,
    /// Largest node displacement in the last rest test (a free run of `creep_time` from
    /// the relaxed state at rest) [m].
    pub creep: f64,
    pub crimp_warp_before: f64,
    pub crimp_warp_after: f64,
    pub crimp_weft_before: f64,
    pub crimp_weft_after: f64,
    /// The crimp of a string pulled over point supports at the crossings: straight
    /// segments between heights ±a, √(1 + (2a/p)²) − 1, with a the amplitude before.
    pub crimp_target: f64,
    /// Half the peak-to-peak height of the centre line over the crossings [m].
    pub amplitude_warp_before: f64,
    pub amplitude_warp_after: f64,
    pub amplitude_weft_before: f64,
    pub amplitude_weft_after: f64,
    /// Tension per yarn in the bands: volume mean of (P ê₁)·f̂₁ times the section area [N].
    pub warp_tension: f64,
    pub weft_tension: f64,
    /// Tension per yarn from the internal forces at the pulled ends [N].
    pub warp_end_tension: f64,
    pub weft_end_tension: f64,
    /// Deepest contact penetration after forming over its contact distance.
    pub max_penetration_ratio: f64,
    /// How far the fabric's top rose [m] (the projectile is moved up by as much).
    pub top_rise: f64,
    pub wall_seconds: f64,
    /// Where forming started: `geometry`, `cell` (tiled from the formed periodic cell) or
    /// `patch` (tiled from a formed smaller patch).
    pub start: String,
    /// The periodic cell's forming, when the start was `cell` (zeros otherwise).
    pub cell: CellSummary,
}

impl Report {
    /// The report of a forming from `start` (the generated geometry when `None`) that
    /// began at `began`: the relaxation `st` and its energy account `eq` (of which
    /// `credited` credited to the start), what was measured, how far the fabric rose.
    pub fn new(
        st: &RelaxStats,
        eq: &Equilibrium,
        credited: f64,
        measured: &Measured,
        top_rise: f64,
        start: Option<&Start>,
        began: Instant,
    ) -> Report {
        let [warp_before, weft_before] = measured.crimps.before;
        let [warp_after, weft_after] = measured.crimps.after;
        Report {
            steps: st.steps,
            time_step: st.dt,
            kinetic_over_work: eq.kinetic_over_work,
            forming_work: eq.work,
            start_work: credited,
            max_residual_force: st.residual,
            max_contact_force: st.contact_force,
            creep: st.creep,
            crimp_warp_before: warp_before.crimp,
            crimp_warp_after: warp_after.crimp,
            crimp_weft_before: weft_before.crimp,
            crimp_weft_after: weft_after.crimp,
            crimp_target: measured.crimps.target,
            amplitude_warp_before: warp_before.amplitude,
            amplitude_warp_after: warp_after.amplitude,
            amplitude_weft_before: weft_before.amplitude,
            amplitude_weft_after: weft_after.amplitude,
            warp_tension: measured.band_tension[0],
            weft_tension: measured.band_tension[1],
            warp_end_tension: measured.end_tension[0],
            weft_end_tension: measured.end_tension[1],
            max_penetration_ratio: measured.max_penetration_ratio,
            top_rise,
            wall_seconds: began.elapsed().as_secs_f64(),
            start: match start {
                None => "geometry",
                Some(Start { cell: Some(_), .. }) => "cell",
                Some(_) => "patch",
            }
            .into(),
            cell: start.and_then(|s| s.cell).unwrap_or_default(),
        }
    }
}

/// Write the report as the one-row table `form.parquet` at `path`.
pub fn write_report(path: &Path, r: &Report, prov: &Provenance) -> Result<()> {
    write_table(
        path,
        &batch(vec![
            Col::I64("steps", vec![r.steps as i64]),
            Col::F64("time_step", vec![r.time_step]),
            Col::F64("kinetic_over_work", vec![r.kinetic_over_work]),
            Col::F64("forming_work", vec![r.forming_work]),
            Col::F64("start_work", vec![r.start_work]),
            Col::F64("max_residual_force", vec![r.max_residual_force]),
            Col::F64("max_contact_force", vec![r.max_contact_force]),
            Col::F64("creep", vec![r.creep]),
            Col::F64("crimp_warp_before", vec![r.crimp_warp_before]),
            Col::F64("crimp_warp_after", vec![r.crimp_warp_after]),
            Col::F64("crimp_weft_before", vec![r.crimp_weft_before]),
            Col::F64("crimp_weft_after", vec![r.crimp_weft_after]),
            Col::F64("crimp_target", vec![r.crimp_target]),
            Col::F64("amplitude_warp_before", vec![r.amplitude_warp_before]),
            Col::F64("amplitude_warp_after", vec![r.amplitude_warp_after]),
            Col::F64("amplitude_weft_before", vec![r.amplitude_weft_before]),
            Col::F64("amplitude_weft_after", vec![r.amplitude_weft_after]),
            Col::F64("warp_tension", vec![r.warp_tension]),
            Col::F64("weft_tension", vec![r.weft_tension]),
            Col::F64("warp_end_tension", vec![r.warp_end_tension]),
            Col::F64("weft_end_tension", vec![r.weft_end_tension]),
            Col::F64("max_penetration_ratio", vec![r.max_penetration_ratio]),
            Col::F64("top_rise", vec![r.top_rise]),
            Col::F64("wall_seconds", vec![r.wall_seconds]),
            Col::Str("start", vec![r.start.clone()]),
            Col::I64("cell_rounds", vec![r.cell.rounds as i64]),
            Col::I64("cell_steps", vec![r.cell.steps as i64]),
            Col::F64("cell_stretch_x", vec![r.cell.stretch[0]]),
            Col::F64("cell_stretch_y", vec![r.cell.stretch[1]]),
            Col::F64("cell_warp_tension", vec![r.cell.tension[0]]),
            Col::F64("cell_weft_tension", vec![r.cell.tension[1]]),
        ]),
        prov,
    )
}
