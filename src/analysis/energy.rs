//! Energy per region over time, and the reflection fraction of a pulse at an interface
//! (the `energy` stage behind `weft-energy measure`; issue 12: "reflection at the
//! interface", what coupling two zones means physically), plus the pulse itself
//! ([`launch_pulse`], `weft-energy pulse`): an initial velocity on a strip of nodes
//! instead of a projectile.
//!
//! Regions are groups of parts (by name), node sets, or the nodes in a box of reference
//! coordinates (treated as a node set). At each output time of a history
//! written with every node (`weft-simulate --all-nodes`):
//! - **kinetic** [J]: Σᵢ ½ mᵢᴿ |vᵢ|², with mᵢᴿ node i's lumped mass from the region's own
//!   elements, by the solver's lumping ([`crate::solver::Families`]: half a truss's mass to
//!   each end, a membrane's mass in equal shares to its nodes, point masses), *before*
//!   ties move a tied node's mass onto its masters; vᵢ is the history's velocity (a tied
//!   node's is its masters' interpolated one). A node shared by regions (the two parts
//!   meeting at a common node) is so counted once overall: each part takes the share of
//!   its kinetic energy that its elements' mass contributes. A node-set region takes the
//!   whole lumped mass of its nodes (every part's elements).
//! - **elastic** [J]: the stored energy of the region's elements as `elements.parquet`
//!   computes it ([`crate::element_results`], the solver's kernels): a part region sums
//!   its elements; a node-set region takes, of every element, the fraction of its nodes
//!   that are in the set. Beams (their bending needs the rotations) and links with a
//!   friction slider count 0; contact penalties, hourglass control and the projectile
//!   belong to no region.
//!
//! Disjoint part regions (or node sets that partition the nodes) so add up to the
//! model's total, with no node counted twice.
//!
//! Reflection: a pulse launched in a source region carries E_launch there; once it has
//! passed the interface, and before anything returns from the model's outer boundary,
//! the energy left in the source is the reflected part: R = E_left / E_launch. E_launch
//! is the source's total at `launch` (linearly interpolated; default: at the sample
//! where the source's total is largest), E_left the mean of its samples in the window
//! [start, end] (default: the single sample, after the launch, where it is smallest; a
//! rule for a clean experiment only, where nothing comes back before the run ends).

use std::collections::{BTreeMap, HashMap};
use std::path::{Path, PathBuf};

use serde::Serialize;

use crate::element_results::ElementResults;
use crate::error::{Result, WeftError};
use crate::model::io::read_model;
use crate::model::{ElementKind, Model};
use crate::solver::beam::Rotations;
use crate::solver::family::Build;
use crate::solver::Families;
use crate::table::history::History;
use crate::table::{batch, write_table, Col, Provenance};

/// What a region holds.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub enum RegionSpec {
    /// The elements (and their share of the nodal masses) of these parts.
    Parts(Vec<String>),
    /// The nodes of a node set (whole nodal masses, shares of the elements).
    Set(String),
    /// The nodes whose reference coordinates lie in a box, [min, max] along x, y, z
    /// (as a node set).
    Box([[f64; 2]; 3]),
}

/// A named region.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Region {
    pub name: String,
    pub spec: RegionSpec,
}

impl Region {
    /// Parse `NAME=PART[,PART…]` (a group of parts), `set:SET` (a node set, named after
    /// it), `NAME=box:XMIN,XMAX,YMIN,YMAX,ZMIN,ZMAX` (the nodes in a box of reference
    /// coordinates [m], as a node set) or `PART` (one part, named after it).
    pub fn parse(s: &str) -> Result<Region> {
        let s = s.trim();
        let bad = || {
            WeftError::input(format!("--region `{s}`"))
                .expected("`NAME=PART[,PART…]`, `set:SET`, `NAME=box:XMIN,XMAX,YMIN,YMAX,ZMIN,ZMAX` or `PART`")
        };
        if let Some(set) = s.strip_prefix("set:") {
            if set.is_empty() {
                return Err(bad());
            }
            return Ok(Region {
                name: set.to_string(),
                spec: RegionSpec::Set(set.to_string()),
            });
        }
        if let Some((name, b)) = s.split_once("=box:") {
            let v: Vec<f64> = b
                .split(',')
                .map(|x| x.trim().parse::<f64>())
                .collect::<std::result::Result<_, _>>()
                .map_err(|_| bad())?;
            if name.trim().is_empty()
                || v.len() != 6
                || v.iter().any(|x| x.is_nan())
                || (0..3).any(|d| v[2 * d] > v[2 * d + 1])
            {
                return Err(bad().hint("six numbers, min ≤ max along each axis (inf allowed)"));
            }
            return Ok(Region {
                name: name.trim().to_string(),
                spec: RegionSpec::Box(std::array::from_fn(|d| [v[2 * d], v[2 * d + 1]])),
            });
        }
        if let Some((name, parts)) = s.split_once('=') {
            let parts: Vec<String> = parts.split(',').map(|p| p.trim().to_string()).collect();
            if name.trim().is_empty() || parts.iter().any(|p| p.is_empty()) {
                return Err(bad());
            }
            return Ok(Region {
                name: name.trim().to_string(),
                spec: RegionSpec::Parts(parts),
            });
        }
        if s.is_empty() {
            return Err(bad());
        }
        Ok(Region {
            name: s.to_string(),
            spec: RegionSpec::Parts(vec![s.to_string()]),
        })
    }
}

/// One region per part of the model, named after it.
pub fn part_regions(m: &Model) -> Vec<Region> {
    m.parts
        .iter()
        .map(|p| Region {
            name: p.name.clone(),
            spec: RegionSpec::Parts(vec![p.name.clone()]),
        })
        .collect()
}

pub(crate) fn part_list(m: &Model) -> String {
    m.parts
        .iter()
        .map(|p| format!("`{}`", p.name))
        .collect::<Vec<_>>()
        .join(", ")
}

/// Lumped nodal masses [kg] from the elements of the parts with `keep[p]` (the
/// solver's own lumping, before ties and mass scaling).
pub fn lumped_masses(m: &Model, keep: &[bool]) -> Result<Vec<f64>> {
    let mut mm = m.clone();
    // A solid's material refuses a zero density: the hexahedra of the parts left out
    // are removed instead (their block keeps the rest, in order).
    if let Some(b) = mm.elements.get_mut(&ElementKind::Hex) {
        let kept: Vec<usize> = (0..b.len()).filter(|&e| keep[b.part[e]]).collect();
        if kept.len() < b.len() {
            let pick = |v: &[Option<i64>]| -> Vec<Option<i64>> {
                if v.is_empty() {
                    vec![]
                } else {
                    kept.iter().map(|&e| v[e]).collect()
                }
            };
            b.layer = pick(&b.layer);
            b.yarn = pick(&b.yarn);
            if !b.failure_factor.is_empty() {
                b.failure_factor = kept.iter().map(|&e| b.failure_factor[e]).collect();
            }
            b.nodes = kept
                .iter()
                .flat_map(|&e| b.nodes[8 * e..8 * e + 8].to_vec())
                .collect();
            b.id = kept.iter().map(|&e| b.id[e]).collect();
            b.part = kept.iter().map(|&e| b.part[e]).collect();
        }
    }
    for (p, part) in mm.parts.iter_mut().enumerate() {
        if !keep[p] && part.kind != ElementKind::Hex {
            if part.props.density.is_some() {
                part.props.density = Some(0.0);
            }
            if part.props.mass.is_some() {
                part.props.mass = Some(0.0);
            }
        }
    }
    let n = mm.num_nodes();
    let mut mass = vec![0.0; n];
    let mut rot = Rotations::new(n);
    Families::build(&mut Build {
        model: &mm,
        mass: &mut mass,
        rot: &mut rot,
    })?;
    Ok(mass)
}

/// Energies of the regions over time: `kinetic[r][k]`, `elastic[r][k]` of region r at
/// time `t[k]` [J].
#[derive(Debug, Clone)]
pub struct RegionEnergies {
    pub names: Vec<String>,
    pub t: Vec<f64>,
    pub kinetic: Vec<Vec<f64>>,
    pub elastic: Vec<Vec<f64>>,
}

impl RegionEnergies {
    /// Total (kinetic + elastic) of region `r` over time.
    pub fn total(&self, r: usize) -> Vec<f64> {
        self.kinetic[r]
            .iter()
            .zip(&self.elastic[r])
            .map(|(a, b)| a + b)
            .collect()
    }
    /// Index of the region named `name`.
    pub fn index(&self, name: &str) -> Result<usize> {
        self.names.iter().position(|n| n == name).ok_or_else(|| {
            WeftError::input(format!("--source `{name}` is not one of the regions"))
                .expected(format!(
                    "one of {}",
                    self.names
                        .iter()
                        .map(|n| format!("`{n}`"))
                        .collect::<Vec<_>>()
                        .join(", ")
                ))
                .hint("name a --region, or a part when no --region is given")
        })
    }
}

/// The energies of `regions` at the samples of a history: `u[k][i]`, `v[k][i]` of model
/// node i at time `t[k]` (NaN where the history lacks the node); `history` names the
/// file in errors.
pub fn region_energies(
    m: &Model,
    regions: &[Region],
    t: &[f64],
    u: &[Vec<[f64; 3]>],
    v: &[Vec<[f64; 3]>],
    history: &Path,
) -> Result<RegionEnergies> {
    let sel = Selections::resolve(m, regions)?;
    // Nodes the history holds (finite values at the first sample).
    let present: Vec<usize> = (0..m.num_nodes())
        .filter(|&i| u[0][i].iter().chain(&v[0][i]).all(|x| x.is_finite()))
        .collect();
    let parts: Vec<String> = m
        .parts
        .iter()
        .enumerate()
        .filter(|(i, p)| sel.needed_parts[*i] && p.kind != ElementKind::PointMass)
        .map(|(_, p)| p.name.clone())
        .collect();
    let er = ElementResults::new(m, &parts, &present).map_err(|e| {
        e.in_file(history)
            .context("cannot compute the regions' elastic energy")
    })?;
    let weights = region_weights(m, regions, &sel, &er, &present, history)?;
    let (kinetic, elastic) = energies_over_time(
        regions,
        Nodal {
            t,
            u,
            v,
            present: &present,
            path: history,
        },
        &er,
        &weights,
    )?;
    Ok(RegionEnergies {
        names: regions.iter().map(|r| r.name.clone()).collect(),
        t: t.to_vec(),
        kinetic,
        elastic,
    })
}

/// What one region takes.
enum Selection {
    /// The elements (and their share of the nodal masses) of the parts p with `keep[p]`.
    Parts(Vec<bool>),
    /// The nodes i with `nodes[i]` (whole nodal masses, shares of the elements).
    Nodes(Vec<bool>),
}

/// The regions resolved against the model.
struct Selections {
    /// Per region, in order.
    of: Vec<Selection>,
    /// Some region is a node set (or a box): every part's masses are needed.
    any_set: bool,
    /// The parts whose elements some region takes (all of them when `any_set`).
    needed_parts: Vec<bool>,
}

impl Selections {
    /// Find each region's parts or nodes in the model.
    fn resolve(m: &Model, regions: &[Region]) -> Result<Selections> {
        let nn = m.num_nodes();
        let mut of = vec![];
        let mut any_set = false;
        let mut needed_parts = vec![false; m.parts.len()];
        for r in regions {
            match &r.spec {
                RegionSpec::Parts(ps) => {
                    let mut keep = vec![false; m.parts.len()];
                    for p in ps {
                        let i = m.part_index(p).ok_or_else(|| {
                            WeftError::input(format!("region `{}`: no part `{p}`", r.name))
                                .expected(format!("a part of the model: {}", part_list(m)))
                        })?;
                        keep[i] = true;
                        needed_parts[i] = true;
                    }
                    of.push(Selection::Parts(keep));
                }
                RegionSpec::Set(s) => {
                    let nodes = m.node_sets.get(s).ok_or_else(|| {
                        WeftError::input(format!("region `{}`: no node set `{s}`", r.name))
                            .expected(format!("a node set of the model: {}", m.node_set_names()))
                    })?;
                    let mut sel = vec![false; nn];
                    for &i in nodes {
                        sel[i] = true;
                    }
                    any_set = true;
                    of.push(Selection::Nodes(sel));
                }
                RegionSpec::Box(b) => {
                    let sel: Vec<bool> = m
                        .coords
                        .iter()
                        .map(|x| (0..3).all(|d| x[d] >= b[d][0] && x[d] <= b[d][1]))
                        .collect();
                    if !sel.contains(&true) {
                        return Err(WeftError::input(format!(
                            "region `{}`: no node in the box {b:?}",
                            r.name
                        ))
                        .expected("a box [min, max] along x, y, z holding some nodes")
                        .hint("check it against the model's coordinates (nodes.parquet)"));
                    }
                    any_set = true;
                    of.push(Selection::Nodes(sel));
                }
            }
        }
        if any_set {
            needed_parts.iter_mut().for_each(|x| *x = true);
        }
        Ok(Selections {
            of,
            any_set,
            needed_parts,
        })
    }
}

/// What a region's energies sum at each sample.
struct Weights {
    /// Kinetic: (node, its lumped mass in the region), nodes of mass > 0 only.
    masses: Vec<(usize, f64)>,
    /// Elastic: (element of the [`ElementResults`], the share of its energy).
    shares: Vec<(usize, f64)>,
}

/// Kinetic masses per region, and the element shares; every node of mass must be in the
/// history (`present`).
fn region_weights(
    m: &Model,
    regions: &[Region],
    sel: &Selections,
    er: &ElementResults,
    present: &[usize],
    history: &Path,
) -> Result<Vec<Weights>> {
    let nn = m.num_nodes();
    let mut slot = vec![usize::MAX; nn];
    for (j, &i) in present.iter().enumerate() {
        slot[i] = j;
    }
    let all_mass = if sel.any_set {
        lumped_masses(m, &vec![true; m.parts.len()])?
    } else {
        vec![]
    };
    let part_index: HashMap<i64, usize> =
        m.parts.iter().enumerate().map(|(i, p)| (p.id, i)).collect();
    let mut out = vec![];
    for (reg, selection) in regions.iter().zip(&sel.of) {
        let (mass, share) = match selection {
            Selection::Parts(keep) => {
                let mass = lumped_masses(m, keep)?;
                let share: Vec<(usize, f64)> = (0..er.len())
                    .filter(|&e| keep[part_index[&er.element_part_id(e)]])
                    .map(|e| (e, 1.0))
                    .collect();
                (mass, share)
            }
            Selection::Nodes(sel) => {
                let mass: Vec<f64> = (0..nn)
                    .map(|i| if sel[i] { all_mass[i] } else { 0.0 })
                    .collect();
                let share: Vec<(usize, f64)> = (0..er.len())
                    .filter_map(|e| {
                        let ns = er.element_nodes(e);
                        let k = ns.iter().filter(|&&i| sel[i]).count();
                        (k > 0).then(|| (e, k as f64 / ns.len() as f64))
                    })
                    .collect();
                (mass, share)
            }
        };
        let mut mv = vec![];
        for (i, &mi) in mass.iter().enumerate() {
            if mi > 0.0 {
                if slot[i] == usize::MAX {
                    return Err(WeftError::input(format!(
                        "region `{}` needs the velocity of node `{}`, which the history does not hold",
                        reg.name, m.node_id[i]
                    ))
                    .in_file(history)
                    .expected("every node of the region's elements at every output time")
                    .hint("write every node: weft-simulate --all-nodes"));
                }
                mv.push((i, mi));
            }
        }
        out.push(Weights {
            masses: mv,
            shares: share,
        });
    }
    Ok(out)
}

/// A history by model node, as [`read_history`] gives it, with the nodes it holds.
struct Nodal<'a> {
    t: &'a [f64],
    /// `u[k][i]`, `v[k][i]`: model node i at time `t[k]` (NaN where the history lacks it).
    u: &'a [Vec<[f64; 3]>],
    v: &'a [Vec<[f64; 3]>],
    /// The nodes the history holds, in model order.
    present: &'a [usize],
    /// The file, named in errors.
    path: &'a Path,
}

/// `kinetic[r][k]`, `elastic[r][k]` of each region at each sample; a non-finite one is
/// refused.
fn energies_over_time(
    regions: &[Region],
    h: Nodal,
    er: &ElementResults,
    weights: &[Weights],
) -> Result<(Vec<Vec<f64>>, Vec<Vec<f64>>)> {
    let (t, u, v, present) = (h.t, h.u, h.v, h.present);
    // The history restricted to the present nodes, sample by sample.
    let mut kinetic = vec![vec![0.0; t.len()]; regions.len()];
    let mut elastic = vec![vec![0.0; t.len()]; regions.len()];
    let mut us = vec![[0.0; 3]; present.len()];
    let mut vs = vec![[0.0; 3]; present.len()];
    let mut ee = vec![0.0; er.len()];
    for k in 0..t.len() {
        for (j, &i) in present.iter().enumerate() {
            us[j] = u[k][i];
            vs[j] = v[k][i];
        }
        for (e, x) in ee.iter_mut().enumerate() {
            *x = er.energy(e, &us, &vs).unwrap_or(0.0);
        }
        for r in 0..regions.len() {
            kinetic[r][k] = weights[r]
                .masses
                .iter()
                .map(|&(i, mi)| 0.5 * mi * v[k][i].iter().map(|c| c * c).sum::<f64>())
                .sum();
            elastic[r][k] = weights[r].shares.iter().map(|&(e, w)| w * ee[e]).sum();
        }
        for r in 0..regions.len() {
            let (a, b) = (kinetic[r][k], elastic[r][k]);
            if !(a.is_finite() && b.is_finite()) {
                return Err(WeftError::input(format!(
                    "region `{}` has a non-finite energy at t = {:e} s (kinetic {a:e} J, elastic {b:e} J)",
                    regions[r].name, t[k]
                ))
                .in_file(h.path)
                .expected("finite displacements and velocities of the region's nodes")
                .hint("a node the history lacks at this time, or a run that broke down"));
            }
        }
    }
    Ok((kinetic, elastic))
}

/// The reflection fraction of a pulse in one region.
#[derive(Debug, Clone, Serialize)]
pub struct Reflection {
    pub source: String,
    pub launch_time: f64,
    pub energy_launched: f64,
    pub window_start: f64,
    pub window_end: f64,
    pub window_samples: usize,
    pub energy_left: f64,
    pub reflection: f64,
    /// How the times were chosen: "given" or the default rule's name.
    pub launch_rule: String,
    pub window_rule: String,
}

/// R = E_left / E_launch of a source region's total energy `e` at times `t` (see the
/// module docs for the default launch time and window).
pub fn reflection(
    source: &str,
    t: &[f64],
    e: &[f64],
    launch: Option<f64>,
    window: Option<(f64, f64)>,
) -> Result<Reflection> {
    let (t0, t1) = (t[0], *t.last().expect("a non-empty history"));
    let inside = |flag: &str, x: f64| -> Result<()> {
        if !(x >= t0 && x <= t1) {
            return Err(WeftError::input(format!("{flag} = `{x:e}` s"))
                .expected(format!("a time within the run, {t0:e} s to {t1:e} s"))
                .hint("the history's output times: see its column t"));
        }
        Ok(())
    };
    let (launch_time, energy_launched, launch_rule) = match launch {
        Some(tl) => {
            inside("--launch", tl)?;
            let k = t.partition_point(|&x| x <= tl).clamp(1, t.len().max(2) - 1);
            let el = if t.len() == 1 {
                e[0]
            } else {
                let w = ((tl - t[k - 1]) / (t[k] - t[k - 1])).clamp(0.0, 1.0);
                e[k - 1] + w * (e[k] - e[k - 1])
            };
            (tl, el, "given".to_string())
        }
        None => {
            let k = (0..t.len())
                .max_by(|&a, &b| e[a].total_cmp(&e[b]).then(b.cmp(&a)))
                .expect("a non-empty history");
            (t[k], e[k], "maximum".to_string())
        }
    };
    if energy_launched.is_nan() || energy_launched <= 0.0 {
        return Err(WeftError::input(format!(
            "region `{source}` holds no energy at the launch time {launch_time:e} s (--launch, or the default: its largest): {energy_launched:e} J"
        ))
        .expected("a pulse launched in the source region")
        .hint("--source names the region the pulse starts in (weft-energy pulse puts it on a strip of a part's nodes)"));
    }
    let (ws, we, window_rule) = match window {
        Some((a, b)) => {
            inside("--window-start", a)?;
            inside("--window-end", b)?;
            if !(a <= b && a >= launch_time) {
                return Err(WeftError::input(format!(
                    "window {a:e} s to {b:e} s with the launch at {launch_time:e} s"
                ))
                .expected("launch ≤ --window-start ≤ --window-end"));
            }
            (a, b, "given".to_string())
        }
        None => {
            let k = (0..t.len())
                .filter(|&k| t[k] >= launch_time)
                .min_by(|&a, &b| e[a].total_cmp(&e[b]).then(a.cmp(&b)))
                .expect("the launch is a sample time");
            (t[k], t[k], "minimum".to_string())
        }
    };
    let inw: Vec<f64> = (0..t.len())
        .filter(|&k| t[k] >= ws && t[k] <= we)
        .map(|k| e[k])
        .collect();
    if inw.is_empty() {
        return Err(WeftError::input(format!(
            "the window {ws:e} s to {we:e} s holds no output time"
        ))
        .expected("at least one output time of the history in the window")
        .hint(
            "widen the window, or write the history more often (weft-simulate --output-interval)",
        ));
    }
    let energy_left = inw.iter().sum::<f64>() / inw.len() as f64;
    Ok(Reflection {
        source: source.to_string(),
        launch_time,
        energy_launched,
        window_start: ws,
        window_end: we,
        window_samples: inw.len(),
        energy_left,
        reflection: energy_left / energy_launched,
        launch_rule,
        window_rule,
    })
}

/// Read a history table with every node's displacement and velocity: times, and
/// `u[k][i]`, `v[k][i]` per model node (NaN where the history lacks a node).
#[allow(clippy::type_complexity)]
pub fn read_history(
    m: &Model,
    history: &Path,
) -> Result<(Vec<f64>, Vec<Vec<[f64; 3]>>, Vec<Vec<[f64; 3]>>)> {
    let h = History::read(history)?;
    // Energies sum squares: a value whose square overflows would give inf, named nowhere;
    // NaN marks a node the history lacks below, so none may come from the file (the
    // table layer refuses non-finite values).
    h.refuse_overflowing_squares("a finite value, |value| < 1e150 (its square must not overflow)")?;
    let index: HashMap<i64, usize> = m
        .node_id
        .iter()
        .enumerate()
        .map(|(i, &id)| (id, i))
        .collect();
    let nn = m.num_nodes();
    let mut u: Vec<Vec<[f64; 3]>> = vec![];
    let mut v: Vec<Vec<[f64; 3]>> = vec![];
    let times = h.by_time(|k, r| {
        if k == u.len() {
            u.push(vec![[f64::NAN; 3]; nn]);
            v.push(vec![[f64::NAN; 3]; nn]);
        }
        let i = *index.get(&h.node_id[r]).ok_or_else(|| {
            h.value_error("node_id", r, format!("node `{}`", h.node_id[r]))
                .expected("a node of the model (nodes.parquet)")
                .hint("is this the history of a run of this model?")
        })?;
        let c = h.row(r);
        u[k][i] = [c[0], c[1], c[2]];
        v[k][i] = [c[3], c[4], c[5]];
        Ok(())
    })?;
    // A node must be there at every time or never.
    for (i, id) in m.node_id.iter().enumerate() {
        let first = u[0][i][0].is_finite();
        if let Some(k) = (1..times.len()).find(|&k| u[k][i][0].is_finite() != first) {
            return Err(WeftError::input(format!(
                "node `{id}` is in the history at some output times only (not at t = {:e} s)",
                if first { times[k] } else { times[0] }
            ))
            .in_file(history)
            .in_column("node_id")
            .expected("the same nodes at every output time"));
        }
    }
    Ok((times, u, v))
}

/// Settings of one measurement, as `weft-energy measure`'s flags give them (and as its
/// tables' provenance records them).
#[derive(Debug, Clone, Serialize)]
pub struct Config {
    pub model: PathBuf,
    pub history: PathBuf,
    /// Regions (see [`Region::parse`]); empty: one per part.
    pub regions: Vec<String>,
    /// The region a pulse starts in: the reflection fraction is measured there.
    pub source: Option<String>,
    pub launch: Option<f64>,
    pub window_start: Option<f64>,
    pub window_end: Option<f64>,
    /// Output folder: `region_energy.parquet`, and `reflection.parquet` with a source.
    pub out_dir: PathBuf,
}

/// What a measurement reports back to the binary.
#[derive(Debug, Clone)]
pub struct Report {
    pub energies: RegionEnergies,
    pub reflection: Option<Reflection>,
}

/// Run the stage.
pub fn run(c: &Config) -> Result<Report> {
    let m = read_model(&c.model)?;
    let regions: Vec<Region> = if c.regions.is_empty() {
        part_regions(&m)
    } else {
        c.regions
            .iter()
            .map(|s| Region::parse(s))
            .collect::<Result<_>>()?
    };
    let mut seen = BTreeMap::new();
    for r in &regions {
        if seen.insert(r.name.clone(), ()).is_some() {
            return Err(
                WeftError::input(format!("two regions are named `{}`", r.name))
                    .expected("distinct region names")
                    .hint("name a group of parts: --region NAME=PART,PART"),
            );
        }
    }
    let window = match (c.window_start, c.window_end) {
        (Some(a), Some(b)) => Some((a, b)),
        (None, None) => None,
        _ => {
            return Err(WeftError::input("one end of the window only")
                .expected("both --window-start and --window-end, or neither"))
        }
    };
    if c.source.is_none() && (window.is_some() || c.launch.is_some()) {
        return Err(WeftError::input("a launch time or window without --source")
            .expected("--source REGION with --launch / --window-start / --window-end"));
    }
    let (t, u, v) = read_history(&m, &c.history)?;
    let en = region_energies(&m, &regions, &t, &u, &v, &c.history)?;
    let refl = match &c.source {
        Some(s) => {
            let r = en.index(s)?;
            Some(reflection(s, &en.t, &en.total(r), c.launch, window)?)
        }
        None => None,
    };
    let prov = Provenance::new(
        "energy",
        serde_json::to_value(c).expect("config serialises"),
    )
    .with_input(&c.history)?;
    let (mut tt, mut name, mut ke, mut ie, mut tot) = (vec![], vec![], vec![], vec![], vec![]);
    for k in 0..en.t.len() {
        for r in 0..en.names.len() {
            tt.push(en.t[k]);
            name.push(en.names[r].clone());
            ke.push(en.kinetic[r][k]);
            ie.push(en.elastic[r][k]);
            tot.push(en.kinetic[r][k] + en.elastic[r][k]);
        }
    }
    write_table(
        &c.out_dir.join("region_energy.parquet"),
        &batch(vec![
            Col::F64("t", tt),
            Col::Str("region", name),
            Col::F64("kinetic", ke),
            Col::F64("elastic", ie),
            Col::F64("total", tot),
        ]),
        &prov,
    )?;
    if let Some(r) = &refl {
        write_table(
            &c.out_dir.join("reflection.parquet"),
            &batch(vec![
                Col::Str("source", vec![r.source.clone()]),
                Col::F64("launch_time", vec![r.launch_time]),
                Col::F64("energy_launched", vec![r.energy_launched]),
                Col::F64("window_start", vec![r.window_start]),
                Col::F64("window_end", vec![r.window_end]),
                Col::I64("window_samples", vec![r.window_samples as i64]),
                Col::F64("energy_left", vec![r.energy_left]),
                Col::F64("reflection", vec![r.reflection]),
                Col::Str("launch_rule", vec![r.launch_rule.clone()]),
                Col::Str("window_rule", vec![r.window_rule.clone()]),
            ]),
            &prov,
        )?;
    }
    Ok(Report {
        energies: en,
        reflection: refl,
    })
}
