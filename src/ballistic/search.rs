//! A ballistic limit searched by running the impacts: rounds of `per_round` impacts run
//! in parallel at velocities spread over the bracket of the limit, each round narrowing
//! the bracket (the fastest stop below the slowest perforation) by a factor
//! `per_round + 1`, until it is narrower than the tolerance. Each impact keeps what it
//! cost: its steps, simulated time and elements from the solver, and the wall time of
//! its solver (set up and run) as measured.
//!
//! Near the limit the time an impact takes to decide grows without bound: a nose that
//! just gets through drags through the broken yarns at a few per cent of its striking
//! speed (measured: a 6 × 6 patch struck at 16.7 m/s, 0.8 m/s still at the 3 ms end time,
//! free at 3.09 ms). An impact still undecided at the model's end time is therefore run
//! again from the start with twice the end time, up to `extensions` times; the run is
//! deterministic, so the longer run repeats the shorter one to its end.

use super::runs::{Cost, Run};
use crate::error::{Result, WeftError};
use crate::model::Model;
use crate::solver::output::Sink;
use crate::solver::watch::{LayerValues, Outcome};
use crate::solver::{Energies, Solver};

/// How to search.
#[derive(Debug, Clone)]
pub struct Options {
    /// The first bracket [m/s]: `lo` should stop, `hi` perforate.
    pub lo: f64,
    pub hi: f64,
    /// Stop once the bracket is at most this wide [m/s].
    pub tolerance: f64,
    /// Impacts per round (run in parallel).
    pub per_round: usize,
    /// At most this many rounds.
    pub max_rounds: usize,
    /// An impact undecided at the end time is rerun with twice the end time, at most
    /// this many times (so up to 2^extensions × the model's end time).
    pub extensions: usize,
}

/// One impact of the search.
#[derive(Debug, Clone)]
pub struct Impact {
    pub round: usize,
    pub run: Run,
    /// Solver steps and the simulated time at the outcome.
    pub steps: u64,
    pub end_time: f64,
}

/// A sink that keeps nothing: the search reads the outcome from the solver.
struct Discard;

impl Sink for Discard {
    fn history(&mut self, _: f64, _: &[usize], _: &[[f64; 3]], _: &[[f64; 3]]) -> Result<()> {
        Ok(())
    }
    fn energy(&mut self, _: f64, _: &Energies) -> Result<()> {
        Ok(())
    }
    fn layers(&mut self, _: f64, _: &[LayerValues]) -> Result<()> {
        Ok(())
    }
}

/// One impact of `m` at `v` [m/s], run to its outcome; an impact undecided at the end
/// time is run again with twice the end time, at most `extensions` times. Its cost is
/// that of every attempt (steps and wall time summed).
pub fn impact(m: &Model, v: f64, label: &str, extensions: usize) -> Result<(Run, u64, f64)> {
    let mut m = m.clone();
    m.set_striking_speed(v);
    m.analysis.stop_on_outcome = true;
    let clock = std::time::Instant::now();
    let mut steps = 0u64;
    let mut attempt = 0;
    let (s, stats) = loop {
        let mut s = Solver::new(&m)?;
        let stats = s
            .run(&mut Discard, &mut |_| {})
            .map_err(|e| e.context(format!("the impact at {v} m/s stopped")))?;
        steps += stats.steps;
        if s.watch().outcome.is_decided() || attempt == extensions {
            break (s, stats);
        }
        attempt += 1;
        m.analysis.end_time *= 2.0;
    };
    let wall_time = clock.elapsed().as_secs_f64();
    let (perforated, residual, outcome) = match s.watch().outcome {
        Outcome::Perforated {
            residual_velocity, ..
        } => (true, residual_velocity, "perforated"),
        Outcome::Arrested { .. } => (false, 0.0, "arrested"),
        Outcome::Undecided => (false, 0.0, "undecided"),
    };
    let absorbed: f64 = s.watch().last_rows.iter().map(|r| r[4]).sum();
    Ok((
        Run {
            source: label.to_string(),
            group: "search".into(),
            striking_velocity: v,
            residual_velocity: residual,
            perforated,
            outcome: outcome.into(),
            energy_absorbed: if s.watch().n_layers > 0 {
                absorbed
            } else {
                f64::NAN
            },
            signature: vec![],
            cost: Cost {
                steps: i64::try_from(steps).ok(),
                simulated_time: Some(stats.end_time),
                elements: i64::try_from(stats.elements).ok(),
                wall_time: Some(wall_time),
            },
            // A run the solver stops is an error above, not a run.
            stopped: None,
        },
        steps,
        stats.end_time,
    ))
}

/// The bracket of the runs so far: the fastest stop below the slowest perforation, and
/// that perforation.
pub fn bracket(runs: &[Impact]) -> (f64, f64) {
    let hi = runs
        .iter()
        .filter(|r| r.run.perforated)
        .map(|r| r.run.striking_velocity)
        .fold(f64::INFINITY, f64::min);
    let lo = runs
        .iter()
        .filter(|r| !r.run.perforated && r.run.striking_velocity < hi)
        .map(|r| r.run.striking_velocity)
        .fold(f64::NEG_INFINITY, f64::max);
    (lo, hi)
}

/// The search: rounds of impacts until the bracket is within the tolerance. `progress`
/// hears of each round's bracket.
pub fn search(
    m: &Model,
    o: &Options,
    mut progress: impl FnMut(usize, f64, f64),
) -> Result<Vec<Impact>> {
    use rayon::prelude::*;
    if !(o.lo >= 0.0 && o.hi > o.lo && o.hi.is_finite()) {
        return Err(WeftError::input(format!("--lo {} --hi {}", o.lo, o.hi))
            .expected("0 ≤ lo < hi: striking velocities in m/s"));
    }
    if !(o.tolerance > 0.0) || o.per_round == 0 {
        return Err(WeftError::input(format!(
            "--tolerance {} with --per-round {}",
            o.tolerance, o.per_round
        ))
        .expected("a tolerance > 0 in m/s and at least one impact per round"));
    }
    if !m.has_striker() {
        return Err(WeftError::input("the model has no projectile")
            .in_file("projectile.parquet")
            .expected("a model with a projectile or a deformable bullet (node set `bullet`): weft-weave woven"));
    }
    let mut runs: Vec<Impact> = Vec::new();
    // The first round takes the bracket's ends and points between them.
    let k = o.per_round.max(2);
    let mut speeds: Vec<f64> = (0..k)
        .map(|i| o.lo + (o.hi - o.lo) * i as f64 / (k - 1) as f64)
        .collect();
    for round in 0..o.max_rounds {
        let done: Vec<Result<(Run, u64, f64)>> = speeds
            .par_iter()
            .map(|&v| impact(m, v, &format!("round {round}, {v:.3} m/s"), o.extensions))
            .collect();
        for r in done {
            let (run, steps, end_time) = r?;
            runs.push(Impact {
                round,
                run,
                steps,
                end_time,
            });
        }
        if let Some(u) = runs.iter().find(|r| r.run.outcome == "undecided") {
            return Err(WeftError::input(format!(
                "the impact at {} m/s was neither arrested nor free of the fabric by {:.3e} s ({}× the model's end time, after {} extensions)",
                u.run.striking_velocity, u.end_time, 1u64 << o.extensions.min(63), o.extensions
            ))
            .in_file("analysis.parquet")
            .in_column("end_time")
            .expected("an end time long enough for every impact's outcome")
            .hint("raise the model's end time (weft-weave woven --end-time) or --extensions"));
        }
        let (lo, hi) = bracket(&runs);
        progress(round, lo, hi);
        if !hi.is_finite() {
            return Err(WeftError::input(format!(
                "every impact up to --hi {} m/s was stopped",
                o.hi
            ))
            .expected("a bracket whose top perforates")
            .hint("raise --hi"));
        }
        if !lo.is_finite() {
            return Err(WeftError::input(format!(
                "every impact down to --lo {} m/s perforated",
                o.lo
            ))
            .expected("a bracket whose bottom is stopped")
            .hint("lower --lo"));
        }
        if hi - lo <= o.tolerance {
            break;
        }
        speeds = (1..=o.per_round)
            .map(|i| lo + (hi - lo) * i as f64 / (o.per_round + 1) as f64)
            .collect();
    }
    Ok(runs)
}
