//! The `fit` stage: choose named part properties of a model, within bounds, to minimise
//! the mismatch T (the paper's eq. 2) between its response and reference histories.
//!
//! - **Parameters** are part properties named `part.property` (`membrane.shear_modulus_12`;
//!   short aliases such as `membrane.G12` are accepted). One parameter may drive several
//!   properties, tied (`links.kx,links.ky`), each with an optional factor
//!   (`membrane.density,membrane_half.density*0.5`). Each has bounds and a linear or log
//!   scale; the optimisers work on the unit box z ∈ [0, 1]ⁿ of those scales.
//! - **Objective:** for each case (a reference history and the candidate model loaded the
//!   same way) the candidate is solved in-process (explicit, or the linear static solve) and
//!   T is computed over a node set; the objective is the mean T over the cases. A run that
//!   fails (instability, a parameter the solver refuses) scores [`FAILED_T`], above the
//!   largest possible T (2), and its message goes into the trace. Wave arrival times
//!   ([`Objective::Arrival`]) or the projectile's velocity history ([`projectile`]: P, alone
//!   with [`Objective::Projectile`] or weighted beside the others) may be matched instead
//!   or as well.
//! - **Methods:** COBYLA (derivative-free, bounded: Powell's linear-approximation trust
//!   region, the `cobyla` crate's pure-Rust translation of NLopt's), and a projected BFGS
//!   with central finite-difference gradients evaluated in parallel (the bounded
//!   quasi-Newton fmincon-like option). `starts > 1` adds a multistart global search: the
//!   first start is the initial point, the others a Halton sequence over the box; the
//!   local searches run in parallel and the best result wins.
//! - **Reproducible:** every evaluation is deterministic and each local search is
//!   sequential, so the result and the trace (ordered by start, then evaluation) do not
//!   depend on the thread count; only the wall times do.

pub mod projectile;
mod respond;
mod search;
pub mod stage;

use std::sync::Mutex;
use std::time::Instant;

use rayon::prelude::*;
use serde::Serialize;

use crate::analysis::{interpolation, mismatch_paired, pair, Matching, Pairing, Series};
use crate::error::{Result, WeftError};
use crate::model::{props, ElementKind, Model, PartProps};
use projectile::VelocityHistory;
pub use respond::{respond, respond_nodes, respond_with_projectile};
use respond::{set_nodes, solve};
use search::{cobyla_search, gradient_search, Unit};
pub use search::{Method, Options};

/// T scored by an evaluation whose solve failed: above any real T (which lies in [0, 2]).
pub const FAILED_T: f64 = 4.0;

/// The value slot of a numeric part property (see [`crate::model::props`]).
fn slot<'a>(p: &'a mut PartProps, name: &str) -> Option<&'a mut Option<f64>> {
    match props::property(name)?.access {
        props::Access::F64 { slot, .. } => Some(slot(p)),
        props::Access::Bool { .. } | props::Access::Str { .. } => None,
    }
}

/// One part property a parameter sets: value × factor.
#[derive(Debug, Clone, Serialize)]
pub struct Target {
    pub part: String,
    pub property: String,
    pub factor: f64,
    #[serde(skip)]
    part_index: usize,
}

/// A fitted parameter.
#[derive(Debug, Clone, Serialize)]
pub struct Parameter {
    /// The name as given (`membrane.shear_modulus_12`, `links.kx,links.ky`).
    pub name: String,
    pub targets: Vec<Target>,
    pub lower: f64,
    pub upper: f64,
    pub log: bool,
    /// Start value (the model's own when not given).
    pub initial: f64,
}

impl Parameter {
    /// Value at z ∈ [0, 1] of the parameter's scale.
    pub fn value(&self, z: f64) -> f64 {
        let z = z.clamp(0.0, 1.0);
        if self.log {
            (self.lower.ln() + z * (self.upper.ln() - self.lower.ln())).exp()
        } else {
            self.lower + z * (self.upper - self.lower)
        }
    }
    /// Position of `v` on the parameter's scale.
    pub fn unit(&self, v: f64) -> f64 {
        let z = if self.log {
            (v.ln() - self.lower.ln()) / (self.upper.ln() - self.lower.ln())
        } else {
            (v - self.lower) / (self.upper - self.lower)
        };
        z.clamp(0.0, 1.0)
    }
}

fn bad_param(spec: &str, what: impl Into<String>) -> WeftError {
    WeftError::input(format!("--param `{spec}`: {}", what.into())).expected(
        "PART.PROPERTY[*FACTOR][,PART.PROPERTY[*FACTOR]...]:LOWER:UPPER[:log|lin][:INITIAL], \
         e.g. `membrane.shear_modulus_12:1e8:1e10:log`",
    )
}

fn number(spec: &str, field: &str, s: &str) -> Result<f64> {
    s.trim()
        .parse::<f64>()
        .ok()
        .filter(|v| v.is_finite())
        .ok_or_else(|| bad_param(spec, format!("{field} `{s}` is not a finite number")))
}

/// One target of `--param` (`PART.PROPERTY` or `PART.PROPERTY*FACTOR`) against the
/// model: the part must exist and the property be fittable for its kind (aliases
/// resolved); a truss area set per element would not follow the part's.
fn parse_target(spec: &str, t: &str, m: &Model) -> Result<Target> {
    let (name, factor) = match t.split_once('*') {
        Some((n, f)) => (n.trim(), number(spec, "factor", f)?),
        None => (t.trim(), 1.0),
    };
    let (part, prop) = name
        .split_once('.')
        .ok_or_else(|| bad_param(spec, format!("`{name}` is not of the form PART.PROPERTY")))?;
    let prop = props::resolve_alias(prop);
    let pi = m.parts.iter().position(|p| p.name == part).ok_or_else(|| {
        bad_param(spec, format!("the model has no part named `{part}`")).hint(format!(
            "parts: {}",
            m.parts
                .iter()
                .map(|p| format!("`{}` ({})", p.name, p.kind.name()))
                .collect::<Vec<_>>()
                .join(", ")
        ))
    })?;
    let kind = m.parts[pi].kind;
    let applies: Vec<&str> = props::fittable(kind).map(|p| p.name).collect();
    if !applies.contains(&prop) {
        return Err(bad_param(
            spec,
            format!("part `{part}` ({}) has no property `{prop}`", kind.name()),
        )
        .hint(format!(
            "a {} part's fittable properties: {}",
            kind.name(),
            applies.join(", ")
        )));
    }
    // A truss with an area of its own (elements_truss.parquet `area`) would keep it
    // whatever the part's area is set to.
    if prop == "area" {
        if let Some(b) = m.block(ElementKind::Truss) {
            if let Some(e) = (0..b.len()).find(|&e| {
                b.part[e] == pi
                    && b.area
                        .get(e)
                        .is_some_and(|&a| Some(a) != m.parts[pi].props.area)
            }) {
                return Err(bad_param(
                    spec,
                    format!(
                        "truss `{}` of part `{part}` has a cross-section area of its own ({:e} m², elements_truss.parquet `area`), which the part's area does not set",
                        b.id[e], b.area[e]
                    ),
                )
                .hint("fit a part whose trusses all take the part's area (their `area` null in elements_truss.parquet)"));
            }
        }
    }
    Ok(Target {
        part: part.to_string(),
        property: prop.to_string(),
        factor,
        part_index: pi,
    })
}

/// Parse `--param` against the model whose parts it names.
pub fn parse_param(spec: &str, m: &Model) -> Result<Parameter> {
    let fields: Vec<&str> = spec.split(':').collect();
    if !(3..=5).contains(&fields.len()) {
        return Err(bad_param(
            spec,
            format!("{} `:`-separated fields", fields.len()),
        ));
    }
    let lower = number(spec, "lower bound", fields[1])?;
    let upper = number(spec, "upper bound", fields[2])?;
    let mut log = false;
    let mut initial = None;
    for f in &fields[3..] {
        match f.trim() {
            "log" => log = true,
            "lin" => log = false,
            v => initial = Some(number(spec, "initial value", v)?),
        }
    }
    if lower >= upper {
        return Err(bad_param(
            spec,
            format!("lower bound {lower:e} is not below the upper bound {upper:e}"),
        ));
    }
    if log && lower <= 0.0 {
        return Err(bad_param(
            spec,
            format!("a log scale needs bounds > 0, the lower bound is {lower:e}"),
        ));
    }
    let targets = fields[0]
        .split(',')
        .map(|t| parse_target(spec, t, m))
        .collect::<Result<Vec<Target>>>()?;
    let current = {
        let t = &targets[0];
        let mut p = m.parts[t.part_index].props.clone();
        slot(&mut p, &t.property)
            .and_then(|v| *v)
            .map(|v| v / t.factor)
    };
    let initial = match initial.or(current) {
        Some(v) if (lower..=upper).contains(&v) => v,
        Some(v) if initial.is_some() => {
            return Err(bad_param(
                spec,
                format!("initial value {v:e} lies outside [{lower:e}, {upper:e}]"),
            ))
        }
        // The model's own value is outside the bounds: start from the middle of the scale.
        _ => {
            let mid = Parameter {
                name: String::new(),
                targets: vec![],
                lower,
                upper,
                log,
                initial: 0.0,
            };
            mid.value(0.5)
        }
    };
    Ok(Parameter {
        name: fields[0].trim().to_string(),
        targets,
        lower,
        upper,
        log,
        initial,
    })
}

/// Set the parameters' values (physical units) on a model.
pub fn apply(m: &mut Model, params: &[Parameter], values: &[f64]) {
    for (p, &v) in params.iter().zip(values) {
        for t in &p.targets {
            let s = slot(&mut m.parts[t.part_index].props, &t.property)
                .expect("checked by parse_param");
            *s = Some(v * t.factor);
        }
    }
}

/// One reference to match: its history over a node set, and the candidate model loaded
/// the same way.
#[derive(Debug, Clone)]
pub struct Case {
    pub name: String,
    pub reference: Series,
    pub model: Model,
    /// The candidate's node set compared with the reference's.
    pub set: String,
    /// The reference's projectile velocity history, when the objective compares it
    /// ([`Problem::projectile_weight`] > 0 or [`Objective::Projectile`]).
    pub projectile: Option<VelocityHistory>,
}

/// What is minimised.
#[derive(Debug, Clone)]
pub struct Problem {
    pub cases: Vec<Case>,
    pub params: Vec<Parameter>,
    /// Displacement components compared (0..3 = ux, uy, uz).
    pub components: Vec<usize>,
    /// Node matching tolerance [m].
    pub tolerance: f64,
    /// How reference nodes find their candidate values: by position, by id, or
    /// interpolated in the candidate's elements (meshes that differ).
    pub matching: Matching,
    /// Linear static solves, comparing final displacements.
    pub static_mode: bool,
    /// What is compared: displacement histories (T), wave arrival times, or the
    /// projectile's velocity history.
    pub objective: Objective,
    /// The weight of the projectile mismatch P ([`projectile`]) added to a displacement
    /// or arrival objective (0: P is not computed).
    pub projectile_weight: f64,
}

/// One wave whose arrival times a fit matches: `component` (0..6 = ux … vz) reaching
/// `level` (as `weft-wavespeed` measures them).
#[derive(Debug, Clone, Copy)]
pub struct ArrivalTerm {
    pub component: usize,
    pub level: crate::analysis::Level,
}

/// The quantity a fit matches.
#[derive(Debug, Clone)]
pub enum Objective {
    /// The paper's T over the node set and `components`.
    Displacement,
    /// Arrival times of waves along the (ordered) node set: for each term, the first time
    /// its component reaches its level at each node, the incident front only (`slack` as
    /// in [`crate::analysis::wave_speeds_with`]): W = Σ(t_c − t_r)² / Σ(t_c² + t_r²) over
    /// the nodes the reference wave reaches, T's form for arrival times (0 equal); a node
    /// the candidate's wave never reaches counts as reached at the end of its run. The
    /// objective is the mean W over the terms. Matching arrival times matches the wave
    /// speeds.
    Arrival { terms: Vec<ArrivalTerm>, slack: f64 },
    /// T + `weight` × the mean W of `terms`: displacements and wave speeds together
    /// (the paper's §3 asks for both).
    Both {
        terms: Vec<ArrivalTerm>,
        slack: f64,
        weight: f64,
    },
    /// The projectile's velocity history alone: P ([`projectile`]); no node set is
    /// compared.
    Projectile,
}

impl Objective {
    /// The arrival terms, if the objective has any.
    pub fn arrival_terms(&self) -> &[ArrivalTerm] {
        match self {
            Objective::Displacement | Objective::Projectile => &[],
            Objective::Arrival { terms, .. } | Objective::Both { terms, .. } => terms,
        }
    }
}

/// The arrival-time mismatch W of a candidate against a reference (see
/// [`Objective::Arrival`]).
pub fn arrival_mismatch(
    reference: &Series,
    candidate: &Series,
    component: usize,
    level: crate::analysis::Level,
    tol: f64,
) -> Result<f64> {
    let pairs = crate::analysis::match_nodes(reference, candidate, tol)?;
    arrival_mismatch_paired(reference, candidate, &pairs, component, level, 0.0)
}

/// [`arrival_mismatch`] with reference node j paired to candidate entry `pairs[j]`, and
/// the front's `slack` [s] (see [`crate::analysis::wave_speeds_with`]).
pub fn arrival_mismatch_paired(
    reference: &Series,
    candidate: &Series,
    pairs: &[usize],
    component: usize,
    level: crate::analysis::Level,
    slack: f64,
) -> Result<f64> {
    let wr = crate::analysis::wave_speeds_with(reference, component, level, slack);
    let wc = crate::analysis::wave_speeds_with(candidate, component, level, slack);
    let end = *candidate.t.last().expect("samples");
    let (mut num, mut den, mut n) = (0.0, 0.0, 0);
    for (j, &k) in pairs.iter().enumerate() {
        if let Some(tr) = wr.arrival[j] {
            let tc = wc.arrival[k].unwrap_or(end);
            num += (tc - tr) * (tc - tr);
            den += tc * tc + tr * tr;
            n += 1;
        }
    }
    if n == 0 || den <= 0.0 {
        return Err(WeftError::input(
            "the reference wave reaches none of the compared nodes after t = 0",
        )
        .expected("a reference history in which the chosen component reaches the level")
        .hint(
            "choose the component the load excites (vx for tension, vy for shear) or a lower level",
        ));
    }
    Ok(num / den)
}

impl Problem {
    /// Check the cases once: node sets exist and match the references.
    pub fn check(&self) -> Result<()> {
        if self.static_mode && !self.objective.arrival_terms().is_empty() {
            return Err(WeftError::input("a wave-arrival objective with --static")
                .expected("an explicit (dynamic) fit: a static solve has no waves"));
        }
        if self.params.is_empty() {
            return Err(WeftError::input("no parameter to fit")
                .expected("at least one --param PART.PROPERTY:LOWER:UPPER"));
        }
        self.check_projectile()?;
        if matches!(self.objective, Objective::Projectile) {
            // No node set is compared.
            return Ok(());
        }
        for c in &self.cases {
            let set = c.model.node_sets.get(&c.set).ok_or_else(|| {
                WeftError::input(format!(
                    "case `{}`: the candidate model has no node set `{}`",
                    c.name, c.set
                ))
                .expected(format!(
                    "one of {}",
                    c.model
                        .node_sets
                        .keys()
                        .cloned()
                        .collect::<Vec<_>>()
                        .join(", ")
                ))
            })?;
            if self.matching == Matching::Interpolate {
                interpolation(
                    &c.model,
                    None,
                    &c.reference.x0,
                    &c.reference.node_id,
                    self.tolerance,
                )
                .map_err(|e| prefix(e, &c.name))?;
                continue;
            }
            let cand = Series {
                t: vec![0.0],
                node_id: set.iter().map(|&i| c.model.node_id[i]).collect(),
                x0: set.iter().map(|&i| c.model.coords[i]).collect(),
                values: vec![vec![[0.0; 6]; set.len()]],
            };
            pair(&c.reference, &cand, self.tolerance, self.matching)
                .map_err(|e| prefix(e, &c.name))?;
        }
        Ok(())
    }

    /// Whether the objective compares the projectile's velocity history (P).
    pub fn compares_projectile(&self) -> bool {
        matches!(self.objective, Objective::Projectile) || self.projectile_weight > 0.0
    }

    /// The projectile term's weight and each case's striker, speed and duration against
    /// its reference's.
    fn check_projectile(&self) -> Result<()> {
        let w = self.projectile_weight;
        if !(w >= 0.0 && w.is_finite()) {
            return Err(WeftError::input(format!("--projectile-weight {w}"))
                .expected("a finite weight ≥ 0 of the projectile mismatch P (0: not compared)"));
        }
        if matches!(self.objective, Objective::Projectile) && w > 0.0 {
            return Err(WeftError::input(format!(
                "--projectile-weight {w} with --objective projectile"
            ))
            .expected("--projectile-weight beside --objective displacement, arrival or both; --objective projectile minimises P alone"));
        }
        if !self.compares_projectile() {
            return Ok(());
        }
        if self.static_mode {
            return Err(WeftError::input("a projectile objective with --static")
                .expected("an explicit (dynamic) fit: a static solve has no projectile history"));
        }
        for c in &self.cases {
            let r = c.projectile.as_ref().ok_or_else(|| {
                WeftError::input(format!(
                    "case `{}`: no reference projectile history",
                    c.name
                ))
                .expected("the reference run's projectile.parquet for every case")
            })?;
            projectile::check_case(&c.name, &c.model, r)?;
        }
        Ok(())
    }

    /// The candidate model of case `k` at parameter values `x`.
    pub fn model_at(&self, k: usize, x: &[f64]) -> Model {
        let mut m = self.cases[k].model.clone();
        apply(&mut m, &self.params, x);
        m
    }

    /// The candidate's run at `m`: its response over the nodes the comparison needs and
    /// the pairing of the reference's nodes onto it (interpolation searches all of the
    /// candidate's membrane, truss and beam elements; none with the projectile alone), and
    /// its projectile's velocity history when the objective compares it.
    fn candidate_response(&self, c: &Case, m: &Model) -> Result<Candidate> {
        let striker = self.compares_projectile();
        if matches!(self.objective, Objective::Projectile) {
            let r = solve(m, &[], false, true)?;
            return Ok(Candidate {
                series: r.series,
                pairs: vec![],
                projectile: r.projectile,
            });
        }
        if self.matching == Matching::Interpolate {
            let (nodes, pairs) = interpolation(
                m,
                None,
                &c.reference.x0,
                &c.reference.node_id,
                self.tolerance,
            )?;
            let r = solve(m, &nodes, self.static_mode, striker)?;
            return Ok(Candidate {
                series: r.series,
                pairs,
                projectile: r.projectile,
            });
        }
        let r = solve(m, &set_nodes(m, &c.set)?, self.static_mode, striker)?;
        let pairs = pair(&c.reference, &r.series, self.tolerance, self.matching)?;
        Ok(Candidate {
            series: r.series,
            pairs,
            projectile: r.projectile,
        })
    }

    /// The objective of one case at `x` (physical values), and its P when compared.
    pub fn case_score(&self, k: usize, x: &[f64]) -> Result<Score> {
        let c = &self.cases[k];
        let Candidate {
            series: cand,
            pairs,
            projectile: cand_projectile,
        } = self.candidate_response(c, &self.model_at(k, x))?;
        let t = || -> Result<f64> {
            Ok(mismatch_paired(
                &c.reference,
                &cand,
                &pairs,
                &self.components,
                self.static_mode,
            )?
            .t_value)
        };
        let w = |terms: &[ArrivalTerm], slack: f64| -> Result<f64> {
            let aligned = aligned(&cand, &pairs, &c.reference);
            let identity: Vec<usize> = (0..pairs.len()).collect();
            let mut sum = 0.0;
            for a in terms {
                sum += arrival_mismatch_paired(
                    &c.reference,
                    &aligned,
                    &identity,
                    a.component,
                    a.level,
                    slack,
                )?;
            }
            Ok(sum / terms.len().max(1) as f64)
        };
        let p = match (&c.projectile, &cand_projectile) {
            (Some(r), Some(v)) => Some(projectile::mismatch(r, v)),
            _ => None,
        };
        let p_value = || {
            p.ok_or_else(|| {
                WeftError::input("no projectile velocity history to compare")
                    .expected("a reference projectile history and a candidate with a projectile")
            })
        };
        let value = match &self.objective {
            Objective::Displacement => t()?,
            Objective::Arrival { terms, slack } => w(terms, *slack)?,
            Objective::Both {
                terms,
                slack,
                weight,
            } => t()? + weight * w(terms, *slack)?,
            Objective::Projectile => p_value()?,
        };
        let value =
            if self.projectile_weight > 0.0 && !matches!(self.objective, Objective::Projectile) {
                value + self.projectile_weight * p_value()?
            } else {
                value
            };
        Ok(Score {
            value,
            projectile: p,
        })
    }

    /// The objective (T, W, P or their weighted sum) of one case at `x` (physical values).
    pub fn case_t(&self, k: usize, x: &[f64]) -> Result<f64> {
        Ok(self.case_score(k, x)?.value)
    }

    /// The mean objective over the cases at `x` (physical values), and the mean P when
    /// compared.
    pub fn evaluate(&self, x: &[f64]) -> Result<Score> {
        let mut sum = 0.0;
        let mut p_sum = self.compares_projectile().then_some(0.0);
        for k in 0..self.cases.len() {
            let s = self
                .case_score(k, x)
                .map_err(|e| prefix(e, &self.cases[k].name))?;
            sum += s.value;
            p_sum = p_sum.zip(s.projectile).map(|(a, b)| a + b);
        }
        let n = self.cases.len() as f64;
        Ok(Score {
            value: sum / n,
            projectile: p_sum.map(|p| p / n),
        })
    }

    /// Mean T over the cases at `x` (physical values).
    pub fn objective(&self, x: &[f64]) -> Result<f64> {
        Ok(self.evaluate(x)?.value)
    }
    fn values(&self, z: &[f64]) -> Vec<f64> {
        self.params
            .iter()
            .zip(z)
            .map(|(p, &z)| p.value(z))
            .collect()
    }
}

/// An objective's value at one point, and the projectile mismatch P in it (mean over the
/// cases; `None` when P is not compared).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Score {
    pub value: f64,
    pub projectile: Option<f64>,
}

/// A candidate's run as a case compares it.
struct Candidate {
    series: Series,
    pairs: Pairing,
    projectile: Option<VelocityHistory>,
}

/// The candidate's values paired onto the reference's nodes: one entry per reference
/// node (at its position), the weighted sums of `pairs`.
pub fn aligned(candidate: &Series, pairs: &Pairing, reference: &Series) -> Series {
    Series {
        t: candidate.t.clone(),
        node_id: pairs
            .iter()
            .map(|w| {
                candidate.node_id[w
                    .iter()
                    .fold((0usize, f64::NEG_INFINITY), |b, &(c, x)| {
                        if x > b.1 {
                            (c, x)
                        } else {
                            b
                        }
                    })
                    .0]
            })
            .collect(),
        x0: reference.x0.clone(),
        values: candidate
            .values
            .iter()
            .map(|v| {
                pairs
                    .iter()
                    .map(|w| std::array::from_fn(|q| w.iter().map(|&(c, x)| x * v[c][q]).sum()))
                    .collect()
            })
            .collect(),
    }
}

fn prefix(e: WeftError, case: &str) -> WeftError {
    match e {
        WeftError::Input {
            what,
            at,
            expected,
            hint,
        } => WeftError::Input {
            what: format!("case `{case}`: {what}"),
            at,
            expected,
            hint,
        },
        e => e,
    }
}

/// One objective evaluation.
#[derive(Debug, Clone)]
pub struct Evaluation {
    pub start: usize,
    /// Index within its start.
    pub index: usize,
    /// Parameter values (physical units).
    pub x: Vec<f64>,
    pub t: f64,
    /// The projectile mismatch P in it, mean over the cases (`None`: not compared, or
    /// the solve failed).
    pub projectile: Option<f64>,
    pub seconds: f64,
    pub error: Option<String>,
}

/// Outcome of one local search.
#[derive(Debug, Clone)]
pub struct StartResult {
    pub start: usize,
    pub x0: Vec<f64>,
    pub x: Vec<f64>,
    pub t: f64,
    pub evaluations: usize,
    pub status: String,
}

/// Outcome of a fit.
#[derive(Debug, Clone)]
pub struct FitResult {
    pub x: Vec<f64>,
    pub t: f64,
    pub t_initial: f64,
    pub starts: Vec<StartResult>,
    /// Every evaluation, ordered by start, then index.
    pub evaluations: Vec<Evaluation>,
}

/// Halton sequence point `i` (i ≥ 1) in [0, 1]ⁿ: deterministic, well spread starts.
pub fn halton(i: usize, n: usize) -> Vec<f64> {
    const PRIMES: [usize; 16] = [2, 3, 5, 7, 11, 13, 17, 19, 23, 29, 31, 37, 41, 43, 47, 53];
    (0..n)
        .map(|d| {
            let b = PRIMES[d % PRIMES.len()];
            let (mut f, mut r, mut k) = (1.0, 0.0, i);
            while k > 0 {
                f /= b as f64;
                r += f * (k % b) as f64;
                k /= b;
            }
            r
        })
        .collect()
}

/// Evaluations of one local search, with the caller's callback.
struct Evaluator<'a> {
    problem: &'a Problem,
    start: usize,
    log: Mutex<Vec<Evaluation>>,
    on_eval: &'a (dyn Fn(&Evaluation) + Sync),
}

impl Unit for Evaluator<'_> {
    /// T at unit-box points, evaluated in parallel, logged in the given order.
    fn eval_many(&self, zs: &[Vec<f64>]) -> Vec<f64> {
        let out: Vec<Evaluation> = zs
            .par_iter()
            .map(|z| {
                let x = self.problem.values(z);
                let t0 = Instant::now();
                let (t, projectile, error) = match self.problem.evaluate(&x) {
                    Ok(s) if s.value.is_finite() => (s.value, s.projectile, None),
                    Ok(s) => (FAILED_T, None, Some(format!("T = {}", s.value))),
                    Err(e) => (FAILED_T, None, Some(e.to_string())),
                };
                Evaluation {
                    start: self.start,
                    index: 0,
                    x,
                    t,
                    projectile,
                    seconds: t0.elapsed().as_secs_f64(),
                    error,
                }
            })
            .collect();
        let mut log = self.log.lock().expect("log");
        out.into_iter()
            .map(|mut e| {
                e.index = log.len();
                let t = e.t;
                (self.on_eval)(&e);
                log.push(e);
                t
            })
            .collect()
    }
    fn eval(&self, z: &[f64]) -> f64 {
        self.eval_many(&[z.to_vec()])[0]
    }
    fn count(&self) -> usize {
        self.log.lock().expect("log").len()
    }
}

/// Minimise the problem's T. `on_eval` sees every evaluation as it completes (progress).
pub fn fit(
    problem: &Problem,
    opts: &Options,
    on_eval: &(dyn Fn(&Evaluation) + Sync),
) -> Result<FitResult> {
    problem.check()?;
    let n = problem.params.len();
    let z_init: Vec<f64> = problem.params.iter().map(|p| p.unit(p.initial)).collect();
    let starts: Vec<Vec<f64>> = (0..opts.starts.max(1))
        .map(|s| if s == 0 { z_init.clone() } else { halton(s, n) })
        .collect();
    let runs: Vec<(StartResult, Vec<Evaluation>)> = starts
        .par_iter()
        .enumerate()
        .map(|(s, z0)| {
            let ev = Evaluator {
                problem,
                start: s,
                log: Mutex::new(vec![]),
                on_eval,
            };
            let (z, t, status) = match opts.method {
                Method::Cobyla => cobyla_search(&ev, z0, opts),
                Method::Gradient => gradient_search(&ev, z0, opts),
            };
            let r = StartResult {
                start: s,
                x0: problem.values(z0),
                x: problem.values(&z),
                t,
                evaluations: ev.count(),
                status,
            };
            (r, ev.log.into_inner().expect("log"))
        })
        .collect();
    let t_initial = runs[0].1.first().map(|e| e.t).unwrap_or(f64::NAN);
    let mut starts_out = vec![];
    let mut evaluations = vec![];
    for (r, log) in runs {
        starts_out.push(r);
        evaluations.extend(log);
    }
    // The best evaluation overall (the first one on ties, in trace order).
    let best = evaluations
        .iter()
        .min_by(|a, b| a.t.total_cmp(&b.t))
        .expect("at least one evaluation");
    if best.t >= FAILED_T {
        return Err(WeftError::input(format!(
            "every one of {} evaluations failed; the first: {}",
            evaluations.len(),
            evaluations[0].error.as_deref().unwrap_or("?")
        ))
        .expected("parameter bounds within which the model runs")
        .hint("narrow the bounds to values the model can run with"));
    }
    Ok(FitResult {
        x: best.x.clone(),
        t: best.t,
        t_initial,
        starts: starts_out,
        evaluations,
    })
}
