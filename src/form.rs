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

use std::path::{Path, PathBuf};
use std::time::Instant;

use serde::Serialize;

use crate::error::{Result, WeftError};
use crate::model::contacts::InitialPenetration;
use crate::model::io::{read_model, write_model};
use crate::model::{ElementKind, Load, Model, TimeLaw};
use crate::solver::membrane::tension_1;
use crate::solver::relax::{RelaxOptions, RelaxStats};
use crate::solver::vec3::{norm, sub};
use crate::solver::Solver;
use crate::table::{batch, write_table, Col, Provenance, Table};

pub mod cell;

/// Forming parameters.
#[derive(Debug, Clone, Serialize)]
pub struct Params {
    /// Residual tension per warp and per weft yarn [N].
    pub warp_tension: f64,
    pub weft_tension: f64,
    pub max_steps: u64,
    pub min_steps: u64,
    pub check_every: u64,
    /// Converged when the largest K of a test window ≤ this × W ...
    pub kinetic_tolerance: f64,
    /// ... and the residual force ≤ this × the largest contact force.
    pub force_tolerance: f64,
    /// Largest contact penetration after forming, as a fraction of the contact distance.
    pub penetration_limit: f64,
    /// Normal contact damping during forming, fraction of critical.
    pub contact_damping: f64,
    /// ... and, left alone at rest (a free probe run), no node moves more than this ×
    /// the largest yarn thickness within `creep_time`: the issue's "less than 1 % of the
    /// yarn thickness over 50 µs", tested directly. (Stopped on the first two tests
    /// alone, the 6 × 6 quarter drifted 1.9 % of h in 50 µs at rest, measured. A
    /// tolerance on the motion during the damped relaxation instead held the 10 × 10
    /// quarter for 10⁵ steps while its drum mode crawled, under the damping, from one
    /// equilibrium to another; a free probe at 3·10⁻³ h never passed in 4·10⁵ steps:
    /// the contacts' free vibration alone is 0.4 % of h.)
    pub creep_tolerance: f64,
    pub creep_time: f64,
    /// Local damping α of the relaxation (Cundall; 0 < α < 1). FLAC's 0.8 left the
    /// 6 × 6 quarter chattering at 20 % residual; 0.5 converges (measured).
    pub damping: f64,
    /// Keep the contacts' friction while forming (by default the weave settles
    /// frictionless, so that a yarn's tension is uniform and the impact run, which does
    /// not inherit the friction's stick state, starts in equilibrium).
    pub friction: bool,
}

impl Default for Params {
    fn default() -> Self {
        Params {
            warp_tension: 0.5,
            weft_tension: 0.5,
            max_steps: 400_000,
            min_steps: 1_000,
            check_every: 100,
            kinetic_tolerance: 1e-6,
            force_tolerance: 0.05,
            penetration_limit: 0.5,
            contact_damping: 0.5,
            creep_tolerance: 1e-2,
            creep_time: 50e-6,
            damping: 0.5,
            friction: false,
        }
    }
}

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

/// Yarn family of a part: 0 warp (along x), 1 weft (along y).
fn family(m: &Model, part: usize) -> Option<usize> {
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
fn yarn_elements(m: &Model) -> impl Iterator<Item = (&crate::model::ElementBlock, usize, usize)> {
    [ElementKind::Quad, ElementKind::Truss]
        .into_iter()
        .filter_map(move |k| m.elements.get(&k).map(|b| (b, k.nodes_per_element())))
        .flat_map(move |(b, npe)| {
            (0..b.len())
                .filter(move |&e| family(m, b.part[e]).is_some())
                .map(move |e| (b, npe, e))
        })
}

/// The centre line of the yarn of family `fam` through the first node of `set`: the
/// nodes of its part with the same reference y (warp) or x (weft), along the yarn.
fn centre_line(m: &Model, set: &str, fam: usize) -> Vec<usize> {
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

/// Crimp (path length over projected length − 1) and amplitude (half the height range
/// of the nodes at the crossings) of a centre line at positions `x`.
fn crimp(m: &Model, x: &[[f64; 3]], line: &[usize], fam: usize, crossings: &[usize]) -> (f64, f64) {
    if line.len() < 2 {
        return (f64::NAN, f64::NAN);
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
    (path / straight - 1.0, 0.5 * (hi - lo))
}

/// A start for the relaxation other than the generated geometry.
#[derive(Debug, Clone)]
pub struct Start {
    /// Displacement of every node of the model to form [m].
    pub u: Vec<[f64; 3]>,
    /// Forming work credited to it [J] (the work that formed the state it came from).
    pub work: f64,
    /// The formed periodic cell it was tiled from, if it was: the patch is then tested
    /// at rest first, and taken as it is if it stays ([`cell`]).
    pub cell: Option<CellSummary>,
}

/// What forming the periodic cell did (for the report).
#[derive(Debug, Clone, Copy, Default, Serialize)]
pub struct CellSummary {
    pub rounds: usize,
    pub steps: u64,
    /// The cell's planes moved by δ_x, δ_y [m], and the force across them per yarn [N].
    pub stretch: [f64; 2],
    pub tension: [f64; 2],
}

/// Where forming starts (`weft-form --start`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, clap::ValueEnum)]
#[serde(rename_all = "lowercase")]
pub enum StartMode {
    /// The periodic cell formed alone and reflected over the patch ([`cell`]), then tested
    /// at rest (relaxed further only if it moves).
    Cell,
    /// The generated geometry, relaxed whole.
    Geometry,
}

/// Relative accuracy of the tension across the periodic cell's planes.
pub const CELL_TENSION_TOLERANCE: f64 = 1e-3;

/// Form `m` (a woven model from `weft-weave woven`): the formed model and the report.
pub fn form(
    m: &Model,
    p: &Params,
    progress: &mut dyn FnMut(&RelaxStats),
) -> Result<(Model, Report)> {
    form_from(m, p, None, progress)
}

/// Part name of each node (the first quad, else truss, that holds it), or "".
fn node_parts(m: &Model) -> Vec<&str> {
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
fn spacing_of(m: &Model) -> Option<f64> {
    let s = m.node_sets.get("axis_x")?;
    (s.len() >= 2)
        .then(|| (m.coords[s[1]][0] - m.coords[s[0]][0]).abs())
        .filter(|d| *d > 0.0)
}

/// A start for forming the quarter patch `m` from a formed smaller quarter patch `cell`
/// of the same weave (same spacing, yarn section, mesh and layers; `weft-form
/// --start-from`). A plain weave repeats every two spacings, so away from its edges a
/// formed patch's displacement is periodic in 2p plus a mean stretch ε̄ (the yarns'
/// strain and de-crimping). Along x (and likewise y), with X and X_c the two patches'
/// extents, D = X − X_c (a whole number of 2p: the weave's phase at the ends must
/// agree) and s = 2p·round(X_c / 4p): nodes at x < s take the displacement of the cell's
/// node at x, nodes within X_c − s of the end that of the cell's node at x − D, and nodes
/// between that of the cell's node at x − 2p·j in [s − 2p, s); to each the stretch
/// ε̄·(x − x_cell) is added, with ε̄ the cell's mean over [s − 2p, s) of
/// (u(x + 2p) − u(x)) / 2p. Nodes are matched by part name and reference position.
pub fn tile_start(m: &Model, cell: &Model, cell_name: &str) -> Result<Vec<[f64; 3]>> {
    let bad = |what: String| WeftError::input(what).in_file(cell_name.to_string());
    if cell.initial_displacement.is_empty() {
        return Err(bad(
            "the start model is not formed (its nodes.parquet has no ux0, uy0, uz0)".into(),
        )
        .hint("start from the output of `weft-form` on a smaller patch"));
    }
    let (Some(p), Some(pc)) = (spacing_of(m), spacing_of(cell)) else {
        return Err(bad(
            "a node set `axis_x` with two crossings is missing: the yarn spacing is unknown".into(),
        )
        .hint("both models must come from `weft-weave woven`"));
    };
    if (p - pc).abs() > 1e-9 * p {
        return Err(bad(format!("the start model's yarn spacing is {pc:e} m"))
            .expected(format!("the spacing of the model to form, {p:e} m")));
    }
    let ext = |mm: &Model, d: usize| {
        mm.coords
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), c| {
                (l.min(c[d]), h.max(c[d]))
            })
    };
    let tol = 1e-6 * p;
    let mut maps = vec![];
    for d in 0..2 {
        let (lo, hi) = ext(m, d);
        let (loc, hic) = ext(cell, d);
        let axis = ["x", "y"][d];
        if lo.abs() > tol || loc.abs() > tol {
            return Err(bad(format!(
                "the patches start at {axis} = {lo:e} m and {loc:e} m"
            ))
            .expected("quarter patches with symmetry planes x = 0 and y = 0")
            .hint("generate both with `weft-weave woven` (quarter, the default)"));
        }
        let dd = hi - hic;
        let periods = dd / (2.0 * p);
        let s = 2.0 * p * (hic / (4.0 * p)).round();
        if dd < -tol || (periods - periods.round()).abs() > 1e-6 || s < 2.0 * p - tol {
            return Err(bad(format!(
                "the start patch reaches {axis} = {hic:e} m and the patch to form {hi:e} m"
            ))
            .expected("a start patch at least 4 yarns wide and smaller by an even number of yarns (the weave repeats every 2 yarns)"));
        }
        maps.push((s, dd));
    }
    let map = |c: f64, (s, dd): (f64, f64)| -> f64 {
        if c < s - tol {
            c
        } else if c >= s + dd - tol {
            c - dd
        } else {
            let j = ((c - s + tol) / (2.0 * p)).floor() + 1.0;
            c - 2.0 * p * j
        }
    };
    let q = 1e-6 * p;
    let key = |x: f64, y: f64| ((x / q).round() as i64, (y / q).round() as i64);
    let mut index: std::collections::HashMap<(i64, i64), Vec<usize>> = Default::default();
    for (n, c) in cell.coords.iter().enumerate() {
        index.entry(key(c[0], c[1])).or_default().push(n);
    }
    let cell_parts = node_parts(cell);
    let parts = node_parts(m);
    let find = |x: f64, y: f64, z: f64, part: &str| -> Option<usize> {
        index
            .get(&key(x, y))?
            .iter()
            .copied()
            .find(|&n| cell_parts[n] == part && (cell.coords[n][2] - z).abs() < 1e-6 * p)
    };
    // The cell's mean stretch over its interior period along x and y.
    let mut strain = [0.0f64; 2];
    for d in 0..2 {
        let (s, _) = maps[d];
        let (mut sum, mut count) = (0.0, 0usize);
        for (n, c) in cell.coords.iter().enumerate() {
            if c[d] < s - 2.0 * p - tol || c[d] >= s - tol {
                continue;
            }
            let mut c2 = *c;
            c2[d] += 2.0 * p;
            if let Some(k) = find(c2[0], c2[1], c2[2], cell_parts[n]) {
                sum +=
                    (cell.initial_displacement[k][d] - cell.initial_displacement[n][d]) / (2.0 * p);
                count += 1;
            }
        }
        if count == 0 {
            return Err(bad(
                "the start patch has no node pairs one period (2 spacings) apart in its interior"
                    .into(),
            )
            .hint("start from a formed patch of at least 4 yarns per side"));
        }
        strain[d] = sum / count as f64;
    }
    let mut u = vec![[0.0; 3]; m.num_nodes()];
    for (n, c) in m.coords.iter().enumerate() {
        let (xc, yc) = (map(c[0], maps[0]), map(c[1], maps[1]));
        let k = find(xc, yc, c[2], parts[n]).ok_or_else(|| {
            bad(format!(
                "node `{}` ({}, at x = {:e}, y = {:e}, z = {:e} m) has no counterpart at x = {xc:e}, y = {yc:e} m in the start patch",
                m.node_id[n], parts[n], c[0], c[1], c[2]
            ))
            .hint("the start patch must be the same weave (spacing, section, crimp, mesh, layers) with fewer yarns")
        })?;
        let uc = cell.initial_displacement[k];
        u[n] = [
            uc[0] + strain[0] * (c[0] - xc),
            uc[1] + strain[1] * (c[1] - yc),
            uc[2],
        ];
    }
    Ok(u)
}

/// [`form`] from a start other than the generated geometry (a tiled smaller patch).
/// Rounds of the tied model's final settling, each with the membrane's pre-stress
/// corrected by the tension the previous one left in the bands.
const MEMBRANE_ROUNDS: usize = 6;

pub fn form_from(
    m: &Model,
    p: &Params,
    start: Option<&Start>,
    progress: &mut dyn FnMut(&RelaxStats),
) -> Result<(Model, Report)> {
    let t0 = Instant::now();
    for (n, v) in [
        ("warp-tension", p.warp_tension),
        ("weft-tension", p.weft_tension),
    ] {
        if !(v.is_finite() && v >= 0.0) {
            return Err(
                WeftError::input(format!("--{n} = `{v}`")).expected("a tension ≥ 0 in N per yarn")
            );
        }
    }
    for (n, v) in [
        ("kinetic-tolerance", p.kinetic_tolerance),
        ("force-tolerance", p.force_tolerance),
        ("penetration-limit", p.penetration_limit),
        ("creep-tolerance", p.creep_tolerance),
        ("creep-time", p.creep_time),
    ] {
        if !(v.is_finite() && v > 0.0) {
            return Err(WeftError::input(format!("--{n} = `{v}`")).expected("a number > 0"));
        }
    }
    if !(p.contact_damping.is_finite() && p.contact_damping >= 0.0) {
        return Err(
            WeftError::input(format!("--contact-damping = `{}`", p.contact_damping))
                .expected("a fraction of critical damping ≥ 0 (0.5 by default)"),
        );
    }
    if !(p.damping > 0.0 && p.damping < 1.0) {
        return Err(WeftError::input(format!("--damping = `{}`", p.damping))
            .expected("a local damping 0 < α < 1 (0.5 by default)"));
    }
    if p.max_steps == 0 || p.check_every == 0 {
        return Err(
            WeftError::input("--max-steps and --check-every must be ≥ 1".to_string())
                .expected("a step budget ≥ 1"),
        );
    }
    // The yarns: bands of quads, or chains of trusses (`weft-weave woven --yarn-model`).
    let no_elements = crate::model::ElementBlock::default();
    let quads = m.elements.get(&ElementKind::Quad).unwrap_or(&no_elements);
    let trusses = m.elements.get(&ElementKind::Truss).unwrap_or(&no_elements);
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
    let tension = [p.warp_tension, p.weft_tension];
    // The yarn ends: held at the patch edge, or tied to a membrane around the patch (the
    // §3 combined model); and the section each end node carries.
    let held: Vec<bool> = {
        let mut h = vec![false; m.num_nodes()];
        for (n, c) in &m.constraints {
            if *c == [true; 3] {
                h[*n] = true;
            }
        }
        for t in &m.ties {
            h[t.slave] = true;
        }
        h
    };
    let tied: Vec<bool> = {
        let mut t = vec![false; m.num_nodes()];
        for tie in &m.ties {
            t[tie.slave] = true;
        }
        t
    };
    let thick = |e: usize| -> f64 {
        if quads.thickness.is_empty() {
            m.parts[quads.part[e]].props.thickness.unwrap_or(0.0)
        } else {
            quads.thickness[4 * e..4 * e + 4].iter().sum::<f64>() / 4.0
        }
    };
    // Section share per end node and per yarn end: key (family, end node) → share [m²].
    let mut share = vec![0.0f64; m.num_nodes()];
    let mut end_sign = vec![0.0f64; m.num_nodes()];
    let mut end_fam = vec![usize::MAX; m.num_nodes()];
    let mut end_part = vec![0usize; m.num_nodes()];
    for e in 0..quads.len() {
        let Some(f) = family(m, quads.part[e]) else {
            continue;
        };
        let ns = &quads.nodes[4 * e..4 * e + 4];
        let hn: Vec<usize> = ns.iter().copied().filter(|&n| held[n]).collect();
        if hn.len() != 2 {
            continue;
        }
        let w = norm(&sub(&m.coords[hn[1]], &m.coords[hn[0]]));
        let inner = ns.iter().copied().find(|&n| !held[n]).unwrap_or(hn[0]);
        let sign = if m.coords[hn[0]][f] >= m.coords[inner][f] {
            1.0
        } else {
            -1.0
        };
        for &n in &hn {
            share[n] += 0.5 * w * thick(e);
            end_sign[n] = sign;
            end_fam[n] = f;
            end_part[n] = quads.part[e];
        }
    }
    // A chain's end: the held node of a truss with one node held carries its section.
    for e in 0..trusses.len() {
        let Some(f) = family(m, trusses.part[e]) else {
            continue;
        };
        let [a, b] = [trusses.nodes[2 * e], trusses.nodes[2 * e + 1]];
        let (end, inner) = match (held[a], held[b]) {
            (true, false) => (a, b),
            (false, true) => (b, a),
            _ => continue,
        };
        share[end] += trusses.truss_area(&m.parts, e);
        end_sign[end] = if m.coords[end][f] >= m.coords[inner][f] {
            1.0
        } else {
            -1.0
        };
        end_fam[end] = f;
        end_part[end] = trusses.part[e];
    }
    // Each yarn end: its nodes (connected held nodes of one part at one edge) share T.
    // The end section of one yarn is the sum of the shares of its nodes; group the end
    // nodes by (family, sign, reference across-coordinate rounded to the yarn, part).
    let mut ends: std::collections::BTreeMap<(usize, i64, i64, usize), Vec<usize>> =
        Default::default();
    let Some(spacing) = spacing_of(m) else {
        return Err(WeftError::input(
            "the model has no node set `axis_x` with two crossings: the yarn spacing is unknown",
        )
        .hint("form a model from `weft-weave woven`"));
    };
    // The yarns' centre lines lie at x₀ + jp (x₀ = 0 in a quarter patch, p/2 in a full
    // one, whose yarns straddle x = 0): a node's yarn is the nearest centre line.
    let phase = m.node_sets["axis_x"]
        .first()
        .map_or(0.0, |&n| m.coords[n][0].rem_euclid(spacing));
    for n in 0..m.num_nodes() {
        if end_fam[n] == usize::MAX {
            continue;
        }
        let f = end_fam[n];
        let across = 1 - f;
        let yarn = ((m.coords[n][across] - phase) / spacing).round() as i64;
        ends.entry((f, end_sign[n] as i64, yarn, end_part[n]))
            .or_default()
            .push(n);
    }
    if ends.is_empty() {
        return Err(WeftError::input(
            "no yarn end is held in x, y and z or tied to a membrane: nothing holds the tension",
        )
        .in_file("constraints.parquet")
        .hint("generate the patch with --edge clamped, or with --membrane-length"));
    }
    // Tied ends (the §3 combined model): the patch is formed as a patch alone, its ends
    // held and pulled as below with the membrane set aside (untied, unloaded: it does not
    // move), and the ties come back in the formed model with the membrane pre-stressed to
    // pull the ends with the residual tension (its displacement-limited pull would go
    // slack while the crimped yarns straighten: measured, a 10 × 10 patch formed against
    // the pre-stressed membrane kept no tension at all). The solver keeps each formed
    // slave's offset from its masters (the ends slid along their yarns while forming).
    let tied_ends = ends.values().flatten().filter(|&&n| tied[n]).count();
    if tied_ends > 0 && tied_ends < ends.values().map(|v| v.len()).sum::<usize>() {
        return Err(WeftError::input(
            "some yarn ends are tied to a membrane and others held: expected one or the other",
        )
        .in_file("ties.parquet"));
    }
    let membrane_pulls = tied_ends > 0;
    let mut mm = m.clone();
    if membrane_pulls {
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
    let mut pull = vec![[0.0f64; 3]; m.num_nodes()];
    let mut lid = 0;
    let mut end_nodes = vec![vec![]; 2];
    // A yarn's section: the largest end section of its family (a yarn centred on a
    // symmetry plane is half a band and carries half the tension).
    let mut section = [0.0f64; 2];
    for ((f, _, _, _), nodes) in &ends {
        section[*f] = section[*f].max(nodes.iter().map(|&n| share[n]).sum::<f64>());
    }
    for ((f, _, _, _), nodes) in &ends {
        for &n in nodes {
            pull[n][*f] = end_sign[n] * tension[*f] * share[n] / section[*f];
            end_nodes[*f].push(n);
            if tension[*f] > 0.0 {
                lid += 1;
                mm.loads.push(Load {
                    id: lid,
                    node: n,
                    force: pull[n],
                    law: TimeLaw::Step { start: 0.0 },
                });
            }
        }
    }
    for (n, c) in mm.constraints.iter_mut() {
        if end_fam[*n] != usize::MAX {
            c[end_fam[*n]] = false;
        }
    }
    // The membrane's pre-stress: the yarns' tension per unit length of the edge their ends
    // are tied to, N₀ = Σ T (the ends' section shares) / c = T·layers/p for the quarter
    // patch whose edge runs from the symmetry plane to c; S₀ = N₀/s in material axes 1 = x
    // (the warp's ends on x = c), 2 = y.
    let mut stress0: Option<(Vec<usize>, [f64; 3])> = None;
    if membrane_pulls {
        let membrane: Vec<usize> = (0..quads.len())
            .filter(|&e| family(m, quads.part[e]).is_none())
            .collect();
        let s = membrane.iter().map(|&e| thick(e)).fold(0.0, f64::max);
        let mut s0 = [0.0; 3];
        for (f, s0f) in s0.iter_mut().take(2).enumerate() {
            let (mut total, mut c) = (0.0, 0.0f64);
            for ((ff, _, _, _), nodes) in &ends {
                if *ff == f {
                    total += tension[f] * nodes.iter().map(|&n| share[n]).sum::<f64>() / section[f];
                    for &n in nodes {
                        c = c.max(m.coords[n][f].abs());
                    }
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
        stress0 = Some((membrane, s0));
    }
    // The largest yarn thickness: the bands' nodal thickness, or the chains' contact
    // thickness.
    let t_max = if quads.thickness.is_empty() {
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
    );
    let credited = start.map_or(0.0, |s| s.work);
    if let Some(s) = start {
        if s.u.len() != m.num_nodes() {
            return Err(WeftError::input(format!(
                "the start has {} displacements for {} nodes",
                s.u.len(),
                m.num_nodes()
            )));
        }
        mm.initial_displacement = s.u.clone();
    }
    let mut solver = Solver::new(&mm)?;
    // In the rest test, the pulled ends are held as the formed model holds them.
    let hold: Vec<(usize, u8)> = (0..m.num_nodes())
        .filter(|&n| end_fam[n] != usize::MAX)
        .map(|n| (n, 1u8 << end_fam[n]))
        .collect();
    let mut opts = RelaxOptions {
        max_steps: p.max_steps,
        min_steps: p.min_steps.min(p.max_steps),
        check_every: p.check_every,
        alpha: p.damping,
        kinetic_tolerance: p.kinetic_tolerance,
        force_tolerance: p.force_tolerance,
        force_scale: pull.iter().map(|f| norm(f)).fold(0.0, f64::max),
        creep_window: ((p.creep_time / (solver.stable.dt / (1.0 + p.damping).sqrt())).ceil()
            as u64)
            .max(1),
        creep_tolerance: p.creep_tolerance * t_max,
        work_offset: credited,
        contact_damping: p.contact_damping,
        hold_in_rest_test: hold,
        // A patch tiled from its formed cell is in equilibrium as it is (to the
        // contacts' discretisation): test it at rest first.
        probe_first: start.is_some_and(|s| s.cell.is_some()),
    };
    let mut st = solver.relax(&opts, progress)?;
    // The bands' tension: the volume mean of (P ê₁)·f̂₁ × the yarn's section, per family.
    let band_tension = |solver: &Solver| -> [f64; 2] {
        let x = &solver.state.x;
        let qs = &solver.op.el.quad;
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
            let tg = &solver.op.el.truss;
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
    };
    // Tied ends: with the patch formed, the ties and the membrane's pre-stress come back
    // and the whole model settles once more (the band ends meet the flat membrane at the
    // straight runs' slope, whose alternating z pull the membrane edge takes by rippling).
    if let (true, Some((membrane, s0))) = (st.converged, stress0.as_mut()) {
        // The membrane's pull is displacement-limited: where its edge ripples, the band
        // ends follow it and the crimped yarns go slacker (measured 0.453 N of 0.5 at the
        // 10 × 10), so S₀ is corrected until the bands carry the requested tension to
        // 0.3 %.
        let first = st.clone();
        opts.hold_in_rest_test = vec![];
        // With the ties back the patch is no longer in its own equilibrium: relax first.
        opts.probe_first = false;
        let s0_closed = *s0;
        let mut last: [Option<(f64, f64)>; 2] = [None, None];
        let mut off = f64::INFINITY;
        let mut measured = [f64::NAN; 2];
        for _ in 0..MEMBRANE_ROUNDS {
            let mut m2 = m.clone();
            m2.projectiles.clear();
            m2.loads.clear();
            m2.initial_velocities.clear();
            m2.contacts = mm.contacts.clone();
            m2.initial_displacement = solver
                .state
                .x
                .iter()
                .zip(&m.coords)
                .map(|(a, b)| sub(a, b))
                .collect();
            let b = m2.elements.get_mut(&ElementKind::Quad).expect("quads");
            if b.stress0.is_empty() {
                b.stress0 = vec![[0.0; 3]; b.len()];
            }
            for &e in membrane.iter() {
                b.stress0[e] = *s0;
            }
            let before = st.clone();
            solver = Solver::new(&m2)?;
            opts.work_offset = before.removed + before.kinetic + credited;
            opts.creep_window = ((p.creep_time / (solver.stable.dt / (1.0 + p.damping).sqrt()))
                .ceil() as u64)
                .max(1);
            st = solver.relax(&opts, progress)?;
            st.steps += before.steps;
            st.removed += before.removed;
            st.contact_force = st.contact_force.max(first.contact_force);
            if !st.converged {
                break;
            }
            let t = band_tension(&solver);
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
        if st.converged && off > 0.01 {
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
    }
    let dt = st.dt;
    let work = st.removed + st.kinetic + credited;
    let ratio = if work > 0.0 { st.kinetic / work } else { 0.0 };
    let creep_msg = if st.creep.is_finite() {
        format!(
            "; left alone at rest, node `{}` moved {:.3e} m within {:.1e} s (asked ≤ {:.3e} m)",
            m.node_id.get(st.creep_node).copied().unwrap_or(-1),
            st.creep,
            p.creep_time,
            p.creep_tolerance * t_max
        )
    } else {
        format!(
            "; the kinetic energy and residual force tests never passed together, so the rest test (a free run of {:.1e} s) never ran",
            p.creep_time
        )
    };
    if !st.converged {
        return Err(WeftError::input(format!(
            "forming did not reach equilibrium in {} steps ({:.3e} s): kinetic energy {:.2e} of the forming work (asked ≤ {:.1e}), largest residual force {:.3e} N on node `{}` against contact forces up to {:.3e} N (asked ≤ {:.1e} of them){creep_msg}",
            st.steps, st.steps as f64 * dt, ratio, p.kinetic_tolerance, st.residual, m.node_id[st.residual_node], st.contact_force, p.force_tolerance
        ))
        .hint("raise --max-steps, or loosen --kinetic-tolerance / --force-tolerance"));
    }
    let x = solver.state.x.clone();
    let max_pen = solver.op.surfaces.deepest();
    if let Some(d) = max_pen {
        let (r, g, cid, node, el) = (d.ratio, d.depth, d.contact_id, d.node, d.element);
        if r > p.penetration_limit {
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
                100.0 * p.penetration_limit
            ))
            .hint("lower the tension, or raise the contact penalty_scale in contacts.parquet"));
        }
    }
    // Tension in the bands: volume mean of (P ê₁)·f̂₁ × section area, per family.
    let fi = solver.internal_forces();
    let tens = band_tension(&solver);
    let mut end_t = [f64::NAN; 2];
    for f in 0..2 {
        let a = section[f];
        // At the ends: the internal force along the yarn on the end nodes, per yarn end.
        let full: Vec<&Vec<usize>> = ends
            .iter()
            .filter(|(k, ns)| {
                k.0 == f && (ns.iter().map(|&n| share[n]).sum::<f64>() - a).abs() < 1e-9 * a
            })
            .map(|(_, ns)| ns)
            .collect();
        if !full.is_empty() {
            let s: f64 = full
                .iter()
                .flat_map(|ns| ns.iter())
                .map(|&n| -end_sign[n] * fi[n][f])
                .sum();
            end_t[f] = s / full.len() as f64;
        }
    }
    let warp_line = centre_line(m, "axis_x", 0);
    let weft_line = centre_line(m, "axis_x_weft", 1);
    let xing_w = m.node_sets.get("axis_x").cloned().unwrap_or_default();
    let xing_f: Vec<usize> = {
        // The weft's crossings: along y at the warp centre lines (multiples of p).
        weft_line
            .iter()
            .copied()
            .filter(|&n| {
                let r = (m.coords[n][1] - phase) / spacing;
                (r - r.round()).abs() < 1e-9
            })
            .collect()
    };
    let (cw0, aw0) = crimp(m, &m.coords, &warp_line, 0, &xing_w);
    let (cw1, aw1) = crimp(m, &x, &warp_line, 0, &xing_w);
    let (cf0, af0) = crimp(m, &m.coords, &weft_line, 1, &xing_f);
    let (cf1, af1) = crimp(m, &x, &weft_line, 1, &xing_f);
    // The formed model.
    let mut out = m.clone();
    out.initial_displacement = x.iter().zip(&m.coords).map(|(a, b)| sub(a, b)).collect();
    if let Some((membrane, s0)) = &stress0 {
        let b = out.elements.get_mut(&ElementKind::Quad).expect("quads");
        if b.stress0.is_empty() {
            b.stress0 = vec![[0.0; 3]; b.len()];
        }
        for &e in membrane {
            b.stress0[e] = *s0;
        }
    }
    for c in &mut out.contacts {
        c.initial_penetration = InitialPenetration::Keep;
    }
    let top =
        |xs: &[[f64; 3]]| -> f64 { xs.iter().map(|x| x[2]).fold(f64::NEG_INFINITY, f64::max) };
    let rise = (top(&x) - top(&m.coords)).max(0.0);
    for pr in &mut out.projectiles {
        pr.tip[2] += rise;
    }
    out.validate()?;
    let report = Report {
        steps: st.steps,
        time_step: dt,
        kinetic_over_work: ratio,
        forming_work: work,
        start_work: credited,
        max_residual_force: st.residual,
        max_contact_force: st.contact_force,
        creep: st.creep,
        crimp_warp_before: cw0,
        crimp_warp_after: cw1,
        crimp_weft_before: cf0,
        crimp_weft_after: cf1,
        crimp_target: (1.0 + (2.0 * aw0 / spacing).powi(2)).sqrt() - 1.0,
        amplitude_warp_before: aw0,
        amplitude_warp_after: aw1,
        amplitude_weft_before: af0,
        amplitude_weft_after: af1,
        warp_tension: tens[0],
        weft_tension: tens[1],
        warp_end_tension: end_t[0],
        weft_end_tension: end_t[1],
        max_penetration_ratio: max_pen.map_or(0.0, |d| d.ratio),
        top_rise: rise,
        wall_seconds: t0.elapsed().as_secs_f64(),
        start: match start {
            None => "geometry",
            Some(Start { cell: Some(_), .. }) => "cell",
            Some(_) => "patch",
        }
        .into(),
        cell: start.and_then(|s| s.cell).unwrap_or_default(),
    };
    Ok((out, report))
}

/// `weft-form`: read, form, write the formed model folder and its `form.parquet`.
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

/// The start tiled from the formed periodic cell of `m` ([`cell`]).
pub fn cell_start(m: &Model, p: &Params, progress: &mut dyn FnMut(&RelaxStats)) -> Result<Start> {
    let spacing = spacing_of(m).ok_or_else(|| {
        WeftError::input(
            "the model has no node set `axis_x` with two crossings: the yarn spacing, hence the periodic cell, is unknown",
        )
        .hint("form a patch of at least 2 yarns per side from `weft-weave woven`, or use --start geometry")
    })?;
    let c = cell::extract(m, spacing)?;
    let f = cell::form(&c, p, CELL_TENSION_TOLERANCE, progress)
        .map_err(|e| e.context("cannot form the periodic cell".to_string()))?;
    let u = cell::tile(m, &c, &f)?;
    let yarn_count = |mm: &Model| yarn_elements(mm).count();
    Ok(Start {
        u,
        work: f.work * yarn_count(m) as f64 / yarn_count(&c.model).max(1) as f64,
        cell: Some(CellSummary {
            rounds: f.rounds,
            steps: f.steps,
            stretch: f.stretch,
            tension: f.tension,
        }),
    })
}

pub fn run(c: &Config, progress: &mut dyn FnMut(&RelaxStats)) -> Result<Report> {
    let m = read_model(&c.model)?;
    let start = match &c.start_from {
        None if c.start == StartMode::Cell => Some(
            cell_start(&m, &c.params, progress)
                .map_err(|e| e.context(format!("cannot form `{}`", c.model.display())))?,
        ),
        None => None,
        Some(dir) => {
            let cell = read_model(dir)?;
            let name = dir.display().to_string();
            let u = tile_start(&m, &cell, &name)
                .map_err(|e| e.context(format!("cannot start from `{name}`")))?;
            let rp = dir.join("form.parquet");
            let w = Table::read(&rp)?.f64("forming_work", "forming_work (from weft-form)")?;
            let yarns = |mm: &Model| yarn_elements(mm).count();
            let work =
                w.first().copied().unwrap_or(0.0) * yarns(&m) as f64 / yarns(&cell).max(1) as f64;
            Some(Start {
                u,
                work,
                cell: None,
            })
        }
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

fn write_report(path: &Path, r: &Report, prov: &Provenance) -> Result<()> {
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
