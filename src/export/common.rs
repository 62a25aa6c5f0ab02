//! What the CalculiX and LS-DYNA decks share: the [`Report`] of what a deck holds,
//! numbers as both codes read them ([`num`]), a load's time law as samples
//! ([`law_samples`]), the translations a node is held in, and the nodes a deck prints.

use std::fmt::Write as _;

use crate::model::Model;

/// What an export wrote.
#[derive(Debug, Clone, Default)]
pub struct Report {
    /// Time step of the deck [s] and increments per output sample.
    pub dt: f64,
    pub increments_per_output: u64,
    pub end_time: f64,
    pub nodes: usize,
    /// Cards written: (what, count), e.g. ("SPRINGA (trusses)", 200).
    pub written: Vec<(String, usize)>,
    /// Nodes whose displacements the deck prints.
    pub output_nodes: usize,
}

/// A number as CalculiX and LS-DYNA read it: at most 20 characters (ccx reads fields of
/// 20), 14 significant digits.
pub fn num(x: f64) -> String {
    if x == 0.0 {
        "0.".into()
    } else {
        format!("{x:.13e}")
    }
}

/// Samples (t, g(t)) of a load's time law on [0, end], for tabulated amplitudes: the
/// law's corners exactly, and a sine pulse at every step Δt inside it (so that a code
/// evaluating the load at its steps sees the exact sine; at most `MAX_SAMPLES`, else
/// evenly).
pub fn law_samples(law: &crate::model::TimeLaw, end: f64, dt: f64) -> Vec<(f64, f64)> {
    use crate::model::TimeLaw;
    const MAX_SAMPLES: usize = 20_000;
    let mut v: Vec<(f64, f64)> = vec![];
    // A jump at t0 is a rise over a millionth of a step.
    let eps = 1e-6 * dt;
    match law {
        TimeLaw::SinePulse { start, duration } => {
            if *start > 0.0 {
                v.push((0.0, 0.0));
            }
            v.push((*start, 0.0));
            let (k0, k1) = ((start / dt).ceil(), ((start + duration) / dt).floor());
            if k1 - k0 < MAX_SAMPLES as f64 {
                for k in k0 as u64..=k1 as u64 {
                    let t = k as f64 * dt;
                    v.push((t, law.eval(t)));
                }
            } else {
                for j in 0..=MAX_SAMPLES {
                    let t = start + duration * j as f64 / MAX_SAMPLES as f64;
                    v.push((t, law.eval(t)));
                }
            }
            v.push((start + duration, 0.0));
        }
        TimeLaw::Step { start } => {
            if *start > 0.0 {
                v.push((0.0, 0.0));
                v.push((start - eps, 0.0));
            }
            v.push((start.max(0.0), 1.0));
        }
        TimeLaw::Ramp { start, duration } => {
            if *start > 0.0 {
                v.push((0.0, 0.0));
            }
            v.push((*start, 0.0));
            v.push((start + duration, 1.0));
        }
        TimeLaw::Tabulated { curve, .. } => {
            if curve.t[0] > 0.0 {
                v.push((0.0, curve.value[0]));
            }
            v.extend(curve.t.iter().copied().zip(curve.value.iter().copied()));
        }
    }
    // Hold the last value to beyond the end; keep times strictly increasing.
    let last = v.last().map_or(0.0, |p| p.1);
    let tl = v.last().map_or(0.0, |p| p.0);
    if tl < end * 1.01 {
        v.push((end * 1.01 + dt, last));
    }
    v.dedup_by(|b, a| b.0 <= a.0);
    v
}

/// The node lines of `*NODE` (id, x, y, z), as both codes read them.
pub(crate) fn node_lines(s: &mut String, m: &Model) {
    for (i, x) in m.coords.iter().enumerate() {
        let _ = writeln!(
            s,
            "{}, {}, {}, {}",
            m.node_id[i],
            num(x[0]),
            num(x[1]),
            num(x[2])
        );
    }
}

/// Per node, the translations held: fixed translations and symmetry planes.
pub(crate) fn fixed_translations(m: &Model) -> Vec<[bool; 3]> {
    let mut fixed = vec![[false; 3]; m.num_nodes()];
    for (i, f) in &m.constraints {
        for d in 0..3 {
            fixed[*i][d] |= f[d];
        }
    }
    for sp in &m.symmetry {
        for (i, x) in m.coords.iter().enumerate() {
            if (x[sp.normal] - sp.position).abs() <= sp.tolerance {
                fixed[i][sp.normal] = true;
            }
        }
    }
    fixed
}

/// The nodes a deck prints (indices, ascending): the history sets', or every node.
pub(crate) fn output_nodes(m: &Model) -> Vec<usize> {
    if m.analysis.history_sets.is_empty() {
        (0..m.num_nodes()).collect()
    } else {
        let mut v: Vec<usize> = m
            .analysis
            .history_sets
            .iter()
            .filter_map(|n| m.node_sets.get(n))
            .flatten()
            .copied()
            .collect();
        v.sort_unstable();
        v.dedup();
        v
    }
}
