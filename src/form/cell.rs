//! The periodic cell of a plain weave: forming a patch of any size by forming one cell.
//!
//! A plain weave whose yarn centre lines lie at x = x₀ + ip and y = x₀ + jp is
//! mirror-symmetric about every plane x = x₀ + ip and y = x₀ + jp: warp j follows
//! ±(−1)^j a cos(π(x − x₀)/p), which x → 2(x₀ + ip) − x leaves unchanged, and the wefts
//! are mapped onto wefts of the same sign. Under a uniform residual tension the formed
//! weave keeps these symmetries about the same planes, each moved by the mean stretch:
//! plane i by i·δ_x. The whole interior of a formed patch is therefore the fundamental
//! cell [x₀, x₀ + p]² — four half yarns (the halves of the bands towards the cell), four
//! quarter crossings — reflected over and over, and a yarn end at a patch edge is a cut
//! through that periodic state, where the formed patch holds it.
//!
//! So the cell is formed alone, with symmetry planes on its four sides: the planes
//! x = x₀ and y = x₀ stay, the planes x = x₀ + p and y = x₀ + p are moved by δ_x, δ_y (an
//! initial displacement that their symmetry condition keeps), and δ is found (secant
//! with a bracket, each family on its own) so that the force across each moved plane —
//! the reaction Σ −(f_int + f_contact) of its nodes, the stress resultant that the cut
//! yarns carry — equals the residual tension times the layers. Each evaluation is a
//! dynamic relaxation of the cell ([`crate::solver::relax`]) from the last one, shifted
//! affinely by the change of δ. One node per layer, the warp's centre line at mid-span
//! x₀ + p/2, is held in z: the cell's rigid z translation is otherwise free, and that
//! point lies on the cell's two-fold axis (x, z) → (2x₀ + p − x, −z) about its layer's
//! mid-plane, so the symmetric equilibrium needs no force there.
//!
//! The patch's displacement is then the cell's, reflected: with k = ⌊(x − x₀)/p⌋ and
//! r = x − x₀ − kp, a node takes the cell's node at r (k even) or p − r (k odd), the
//! displacement along x sign-flipped for odd k, plus (K + x₀/p)·δ_x with K = k (even) or
//! k + 1 (odd) — the planes passed counted from the patch's centre x = 0, which stays;
//! likewise along y; u_z unchanged. Cost: the 60 × 60 quarter's 85 562 nodes take
//! the state of a cell of 40, instead of a relaxation whose slow drum mode did not settle
//! in 18 min on 2 cores.

use crate::error::{Result, WeftError};
use crate::model::contacts::{InitialPenetration, Slave};
use crate::model::{ElementKind, Model, Part, SymmetryPlane};
use crate::solver::relax::{RelaxOptions, RelaxStats};
use crate::solver::Solver;

use super::params::Params;
use super::weave::{family, yarn_elements};

/// Largest number of relaxations of the cell while its planes are moved to the tension.
const ROUNDS: usize = 40;

/// The fundamental cell of a woven patch, as a model of its own.
#[derive(Debug, Clone)]
pub struct Cell {
    /// The cell: the yarn quads within [x₀, x₀ + p]², symmetry planes on its four sides,
    /// its contacts, one node per layer held in z.
    pub model: Model,
    /// The patch's node of each cell node.
    pub patch_node: Vec<usize>,
    /// The patch's part of each cell part.
    pub patch_part: Vec<usize>,
    /// Yarn spacing p and the first yarn centre line x₀ (0 for a quarter patch) [m].
    pub spacing: f64,
    pub origin: f64,
    /// Cell nodes on the moved planes x = x₀ + p (0) and y = x₀ + p (1), and on the
    /// fixed planes x = x₀, y = x₀.
    pub planes: [Vec<usize>; 2],
    pub fixed_planes: [Vec<usize>; 2],
    /// The nodes held in z (one per layer, on the two-fold axis).
    pub axis_nodes: Vec<usize>,
    pub layers: usize,
}

/// A formed cell.
#[derive(Debug, Clone)]
pub struct CellForm {
    /// Displacement of each cell node from its reference position [m].
    pub u: Vec<[f64; 3]>,
    /// The planes' displacement δ_x, δ_y [m] (the mean stretch times p).
    pub stretch: [f64; 2],
    /// Force across the moved planes per yarn and layer, warp and weft [N] ...
    pub tension: [f64; 2],
    /// ... across the fixed planes (the cell's balance: the same) ...
    pub fixed_tension: [f64; 2],
    /// ... and the largest force the z-held nodes on the two-fold axes need (0 by
    /// symmetry) [N].
    pub axis_reaction: f64,
    /// Relaxations of the cell and their steps (summed), the energy they removed and the
    /// last one's statistics.
    pub rounds: usize,
    pub steps: u64,
    pub work: f64,
    pub last: RelaxStats,
}

/// Whether `c` is within `tol` of a multiple of `p` from `x0` in [x0, x0 + p].
fn in_cell(c: f64, x0: f64, p: f64, tol: f64) -> bool {
    c >= x0 - tol && c <= x0 + p + tol
}

/// Where the patch's nodes and parts went in the cell.
struct CellIndex {
    /// The patch node of each cell node.
    patch_node: Vec<usize>,
    /// The cell part of each patch part (`usize::MAX` if none) ...
    part: Vec<usize>,
    /// ... and the patch part of each cell part.
    patch_part: Vec<usize>,
}

/// The cell of the woven patch `m` (from `weft-weave woven`, a quarter or a full patch
/// of at least two yarns per side beyond its first centre line).
pub fn extract(m: &Model, spacing: f64) -> Result<Cell> {
    let p = spacing;
    let tol = 1e-6 * p;
    if yarn_elements(m).next().is_none() {
        return Err(WeftError::input(
            "the model has no yarns (quads or trusses of parts named `warp…` or `weft…`): no yarns to form",
        )
        .hint("form a model from `weft-weave woven`"));
    }
    let x0 = cell_origin(m, p, tol)?;
    let keep = nodes_in_cell(m, x0, p, tol);
    let mut cell = Model {
        analysis: m.analysis.clone(),
        ..Default::default()
    };
    cell.analysis.history_sets.clear();
    let index = copy_yarns(m, &keep, x0, p, tol, &mut cell);
    check_every_node_in_an_element(&cell)?;
    copy_contacts(m, &index.part, &mut cell);
    for normal in [0, 1] {
        for position in [x0, x0 + p] {
            cell.symmetry.push(SymmetryPlane {
                normal,
                position,
                tolerance: tol,
            });
        }
    }
    let on = |d: usize, at: f64| {
        (0..cell.num_nodes())
            .filter(|&n| (cell.coords[n][d] - at).abs() <= tol)
            .collect::<Vec<_>>()
    };
    let planes = [0, 1].map(|d| on(d, x0 + p));
    let fixed_planes = [0, 1].map(|d| on(d, x0));
    // Warp parts are named warp_<layer>.
    let layers = index
        .patch_part
        .iter()
        .filter(|&&pi| family(m, pi) == Some(0))
        .count();
    let axis_nodes = hold_axis_nodes(m, &index.patch_part, x0, p, &mut cell);
    if layers == 0 || cell.contacts.is_empty() {
        return Err(WeftError::input(
            "the periodic cell holds no warp band or no contact between its yarns",
        )
        .hint("form a model from `weft-weave woven`"));
    }
    cell.validate()?;
    Ok(Cell {
        model: cell,
        patch_node: index.patch_node,
        patch_part: index.patch_part,
        spacing: p,
        origin: x0,
        planes,
        fixed_planes,
        axis_nodes,
        layers,
    })
}

/// x₀: the first warp centre line at y ≥ its smallest coordinate: a quarter patch's
/// warp 0 lies on y = 0, a full patch's first on (−N/2 + ½)p. The crossing nodes of
/// `axis_x` give the wefts' centre lines (x); the warps' are the same by symmetry. An
/// error when the yarns do not reach one spacing beyond it.
fn cell_origin(m: &Model, p: f64, tol: f64) -> Result<f64> {
    let mut lo = f64::INFINITY;
    let mut hi = f64::NEG_INFINITY;
    for (b, npe, e) in yarn_elements(m) {
        for &n in &b.nodes[npe * e..npe * (e + 1)] {
            lo = lo.min(m.coords[n][0]);
            hi = hi.max(m.coords[n][0]);
        }
    }
    let axis = m.node_sets.get("axis_x").cloned().unwrap_or_default();
    let x0 = axis
        .iter()
        .map(|&n| m.coords[n][0])
        .filter(|&x| x >= lo - tol)
        .fold(f64::INFINITY, f64::min);
    if !x0.is_finite() || hi < x0 + p - tol {
        return Err(WeftError::input(format!(
            "the patch's yarns reach x = {hi:e} m from their first centre line x₀ = {x0:e} m"
        ))
        .expected(format!(
            "at least one spacing p = {p:e} m beyond x₀: the periodic cell [x₀, x₀ + p]² must lie inside the patch"
        ))
        .hint("form patches of at least 2 yarns per side with the cell, or use --start geometry"));
    }
    Ok(x0)
}

/// Cell nodes: of yarn quads, within the cell [x₀, x₀ + p]².
fn nodes_in_cell(m: &Model, x0: f64, p: f64, tol: f64) -> Vec<bool> {
    let mut keep = vec![false; m.num_nodes()];
    for (b, npe, e) in yarn_elements(m) {
        for &n in &b.nodes[npe * e..npe * (e + 1)] {
            let c = m.coords[n];
            if in_cell(c[0], x0, p, tol) && in_cell(c[1], x0, p, tol) {
                keep[n] = true;
            }
        }
    }
    keep
}

/// Copy into `cell` the nodes `keep` of `m` and the yarn elements all of whose nodes it
/// keeps, with their parts.
fn copy_yarns(m: &Model, keep: &[bool], x0: f64, p: f64, tol: f64, cell: &mut Model) -> CellIndex {
    let mut index = vec![usize::MAX; m.num_nodes()];
    let mut patch_node = vec![];
    for n in (0..m.num_nodes()).filter(|&n| keep[n]) {
        index[n] = cell.add_node(m.node_id[n], m.coords[n]);
        patch_node.push(n);
    }
    let mut part_index = vec![usize::MAX; m.parts.len()];
    let mut patch_part = vec![];
    for (b, npe, e) in yarn_elements(m) {
        let ns = &b.nodes[npe * e..npe * (e + 1)];
        if !ns.iter().all(|&n| keep[n]) {
            continue;
        }
        let pi = b.part[e];
        if part_index[pi] == usize::MAX {
            let Part {
                id,
                name,
                kind,
                props,
            } = m.parts[pi].clone();
            part_index[pi] = cell.add_part(id, &name, kind, props);
            patch_part.push(pi);
        }
        let local: Vec<usize> = ns.iter().map(|&n| index[n]).collect();
        if npe == 2 {
            // A chain on one of the cell's planes is half in the cell: half the full
            // yarn's section (the patch's own yarn on a symmetry plane is half already).
            let [a, c] = [ns[0], ns[1]];
            let on_plane = [0, 1].into_iter().any(|d| {
                [x0, x0 + p].into_iter().any(|at| {
                    (m.coords[a][d] - at).abs() <= tol && (m.coords[c][d] - at).abs() <= tol
                })
            });
            let full = m.parts[pi].props.area.unwrap_or(0.0);
            let area = if on_plane {
                0.5 * full
            } else {
                b.truss_area(&m.parts, e)
            };
            cell.add_truss_with_area(b.id[e], part_index[pi], [local[0], local[1]], area);
        } else if b.thickness.is_empty() {
            cell.add_element(b.id[e], part_index[pi], &local);
        } else {
            cell.add_element_with_thickness(
                b.id[e],
                part_index[pi],
                &local,
                &b.thickness[npe * e..npe * (e + 1)],
            );
        }
    }
    CellIndex {
        patch_node,
        part: part_index,
        patch_part,
    }
}

/// A node within the cell that no cell element holds (a band edge beyond a cut) would
/// carry no mass: an error naming it.
fn check_every_node_in_an_element(cell: &Model) -> Result<()> {
    let mut held = vec![false; cell.num_nodes()];
    for b in cell.elements.values() {
        for &n in &b.nodes {
            held[n] = true;
        }
    }
    if let Some(n) = (0..cell.num_nodes()).find(|&n| !held[n]) {
        let c = cell.coords[n];
        return Err(WeftError::input(format!(
            "node `{}` at ({:e}, {:e}, {:e}) m lies in the periodic cell but in none of its quads",
            cell.node_id[n], c[0], c[1], c[2]
        ))
        .expected("yarn bands whose quads end on the cell's planes (an even number of quads across and per spacing)")
        .hint("generate the patch with `weft-weave woven`, or use --start geometry"));
    }
    Ok(())
}

/// Copy into `cell` the contacts of `m` between parts it holds (`part_index`: the cell
/// part of each patch part), acting on the full depth of any initial overlap.
fn copy_contacts(m: &Model, part_index: &[usize], cell: &mut Model) {
    for d in &m.contacts {
        let slave = match d.slave {
            Slave::Part(s) if part_index[s] != usize::MAX => Slave::Part(part_index[s]),
            _ => continue,
        };
        if part_index[d.master] == usize::MAX {
            continue;
        }
        let mut c = d.clone();
        c.slave = slave;
        c.master = part_index[d.master];
        c.initial_penetration = InitialPenetration::Keep;
        cell.contacts.push(c);
    }
}

/// Hold one node per layer of `cell` in z: the warp's centre line at mid-span (on the
/// cell's two-fold axis). Those nodes.
fn hold_axis_nodes(
    m: &Model,
    patch_part: &[usize],
    x0: f64,
    p: f64,
    cell: &mut Model,
) -> Vec<usize> {
    let mut axis_nodes = vec![];
    for (ci, &pi) in patch_part.iter().enumerate() {
        if family(m, pi) != Some(0) {
            continue;
        }
        let kind = cell.parts[ci].kind;
        let (b, npe) = (&cell.elements[&kind], kind.nodes_per_element());
        let pick = (0..b.len())
            .filter(|&e| b.part[e] == ci)
            .flat_map(|e| b.nodes[npe * e..npe * (e + 1)].to_vec())
            .min_by(|&a, &b| {
                let da =
                    (cell.coords[a][0] - (x0 + 0.5 * p)).abs() + (cell.coords[a][1] - x0).abs();
                let db =
                    (cell.coords[b][0] - (x0 + 0.5 * p)).abs() + (cell.coords[b][1] - x0).abs();
                da.total_cmp(&db).then(a.cmp(&b))
            });
        if let Some(n) = pick {
            cell.constraints.push((n, [false, false, true]));
            axis_nodes.push(n);
        }
    }
    axis_nodes
}

/// The cell's balance at a state: the forces its symmetry planes and its axis nodes
/// take.
#[derive(Debug, Clone, Copy)]
struct Balance {
    /// Force across the moved planes, per yarn and layer, warp and weft [N] ...
    moved: [f64; 2],
    /// ... and across the fixed ones [N].
    fixed: [f64; 2],
    /// The largest z force on the nodes held on the two-fold axes [N].
    axis: f64,
}

/// The cell's balance at the solver's state (its contacts evaluated there): the force
/// across the moved planes and across the fixed ones, per yarn and layer — Σ −(f_int +
/// f_contact) along the normal over the moved plane's nodes, Σ (f_int + f_contact) over
/// the fixed plane's (the reactions its symmetry condition supplies) [N] — and the
/// largest z force on the nodes held on the two-fold axes [N].
fn balance(cell: &Cell, solver: &mut Solver) -> Balance {
    let fi = solver.internal_forces();
    let fc = &solver.operator().fcon;
    let has_fc = solver.operator().has_fcon();
    let f = |n: usize, d: usize| fi[n][d] + if has_fc { fc[n][d] } else { 0.0 };
    let per = cell.layers as f64;
    let moved = [0, 1].map(|d| -cell.planes[d].iter().map(|&n| f(n, d)).sum::<f64>() / per);
    let fixed = [0, 1].map(|d| cell.fixed_planes[d].iter().map(|&n| f(n, d)).sum::<f64>() / per);
    let axis = cell
        .axis_nodes
        .iter()
        .map(|&n| f(n, 2).abs())
        .fold(0.0, f64::max);
    Balance { moved, fixed, axis }
}

/// The largest yarn thickness of the cell's model: its quads' nodal thickness, or its
/// contacts' thickness [m].
fn largest_thickness(model: &Model) -> f64 {
    model
        .elements
        .get(&ElementKind::Quad)
        .map(|b| b.thickness.iter().cloned().fold(0.0, f64::max))
        .unwrap_or(0.0)
        .max(
            model
                .contacts
                .iter()
                .flat_map(|c| [c.slave_thickness, c.master_thickness])
                .flatten()
                .fold(0.0, f64::max),
        )
}

/// The first guess of the plane displacement δ along `d` (0 x, 1 y): the cell
/// stretched so that the centre line of the yarn along `d`, of the generated path
/// length, runs straight between crossings at ±a (a the generated amplitude):
/// δ = p (L/L_straight − 1).
fn first_stretch(model: &Model, cell: &Cell, d: usize) -> f64 {
    let pp = cell.spacing;
    let fam_line: Vec<usize> = {
        let mut v: Vec<usize> = (0..model.num_nodes())
            .filter(|&n| (model.coords[n][1 - d] - cell.origin).abs() <= 1e-6 * pp)
            .filter(|&n| {
                yarn_elements(model).any(|(b, npe, e)| {
                    family(model, b.part[e]) == Some(d)
                        && b.nodes[npe * e..npe * (e + 1)].contains(&n)
                })
            })
            .collect();
        v.sort_by(|&a, &b| model.coords[a][d].total_cmp(&model.coords[b][d]));
        v
    };
    if fam_line.len() < 2 {
        return 1e-3 * pp;
    }
    let x = &model.coords;
    let len: f64 = fam_line
        .windows(2)
        .map(|w| {
            let e = [0, 1, 2].map(|k| x[w[1]][k] - x[w[0]][k]);
            (e[0] * e[0] + e[1] * e[1] + e[2] * e[2]).sqrt()
        })
        .sum();
    let z: Vec<f64> = fam_line.iter().map(|&n| x[n][2]).collect();
    let a = 0.5
        * (z.iter().cloned().fold(f64::NEG_INFINITY, f64::max)
            - z.iter().cloned().fold(f64::INFINITY, f64::min));
    let straight = pp * (1.0 + (2.0 * a / pp).powi(2)).sqrt();
    (pp * (len / straight - 1.0)).max(0.0)
}

/// One evaluation of a family's plane: its displacement δ [m] and the force across it
/// per yarn [N].
#[derive(Debug, Clone, Copy)]
struct Evaluation {
    stretch: f64,
    force: f64,
}

/// The search for one family's plane displacement δ: the bracket (δ with force below,
/// δ with force above) and the last evaluation, for the secant.
#[derive(Debug, Clone, Copy, Default)]
struct PlaneSearch {
    below: Option<Evaluation>,
    above: Option<Evaluation>,
    last: Option<Evaluation>,
}

impl PlaneSearch {
    /// The next δ after the evaluation `now`, for the force `tension`: secant through the
    /// last two evaluations, kept inside the bracket once there is one (bisection when it
    /// leaves it); before a bracket, steps of p/1000 (`pp` the spacing p; the
    /// de-crimping compliance: 0.5 N moves a plane ~1 µm).
    fn next(&mut self, now: Evaluation, tension: f64, pp: f64) -> f64 {
        let (d, r) = (now.stretch, now.force);
        if r < tension {
            self.below = Some(now);
        } else {
            self.above = Some(now);
        }
        let mut cand = match self.last {
            Some(Evaluation {
                stretch: d1,
                force: r1,
            }) if (r - r1).abs() > 1e-12 * tension && d != d1 => {
                d + (tension - r) * (d - d1) / (r - r1)
            }
            _ => {
                if r < tension {
                    d + 1e-3 * pp
                } else {
                    d - 1e-3 * pp
                }
            }
        };
        if let (Some(lo), Some(hi)) = (self.below, self.above) {
            let (dl, dh) = (lo.stretch, hi.stretch);
            let (a, b) = (dl.min(dh), dl.max(dh));
            if !(cand > a && cand < b) {
                cand = 0.5 * (a + b);
            }
        }
        self.last = Some(now);
        cand
    }
}

/// Form the cell: relax it with its planes moved until the force across each is the
/// residual tension (to `tolerance`, relative).
pub fn form(
    cell: &Cell,
    p: &Params,
    tolerance: f64,
    progress: &mut dyn FnMut(&RelaxStats),
) -> Result<CellForm> {
    let tension = p.tension();
    if tension.iter().any(|&t| !(t > 0.0)) {
        return Err(WeftError::input(format!(
            "a residual tension of {} / {} N per warp / weft yarn with the periodic cell",
            tension[0], tension[1]
        ))
        .expected("tensions > 0: the cell's planes are moved until the yarns carry them")
        .hint("use --start geometry for a weave without tension"));
    }
    let pp = cell.spacing;
    let mut model = cell.model.clone();
    for c in &mut model.contacts {
        if !p.friction {
            c.static_friction = 0.0;
            c.dynamic_friction = 0.0;
        }
    }
    let t_max = largest_thickness(&model);
    let mut delta = [
        first_stretch(&model, cell, 0),
        first_stretch(&model, cell, 1),
    ];
    let mut u: Vec<[f64; 3]> = model
        .coords
        .iter()
        .map(|c| {
            [
                delta[0] * (c[0] - cell.origin) / pp,
                delta[1] * (c[1] - cell.origin) / pp,
                0.0,
            ]
        })
        .collect();
    let mut search = [PlaneSearch::default(); 2];
    let (mut steps, mut work) = (0u64, 0.0f64);
    let mut forces = [f64::NAN; 2];
    for round in 1..=ROUNDS {
        model.initial_displacement = u.clone();
        let mut solver = Solver::new(&model)?;
        let opts = RelaxOptions {
            work_offset: work,
            ..p.relax_options(solver.time_step().dt, tension[0].max(tension[1]), t_max)
        };
        let st = solver.relax(&opts, progress)?;
        steps += st.steps;
        work += st.removed;
        if !st.converged {
            return Err(WeftError::input(format!(
                "the periodic cell did not reach equilibrium in {} steps (round {round}, planes moved {:.4e} / {:.4e} m): kinetic energy {:.2e} J, largest residual force {:.3e} N on node `{}` against contact forces up to {:.3e} N",
                st.steps, delta[0], delta[1], st.kinetic, st.residual, model.node_id[st.residual_node], st.contact_force
            ))
            .hint("raise --max-steps, or loosen --kinetic-tolerance / --force-tolerance"));
        }
        let balance = balance(cell, &mut solver);
        forces = balance.moved;
        u = solver
            .state()
            .x
            .iter()
            .zip(&model.coords)
            .map(|(a, b)| [a[0] - b[0], a[1] - b[1], a[2] - b[2]])
            .collect();
        let off = (0..2)
            .map(|f| (forces[f] / tension[f] - 1.0).abs())
            .fold(0.0, f64::max);
        if off <= tolerance {
            return Ok(CellForm {
                u,
                stretch: delta,
                tension: forces,
                fixed_tension: balance.fixed,
                axis_reaction: balance.axis,
                rounds: round,
                steps,
                work,
                last: st,
            });
        }
        // Next δ per family (a family already at its tension stays).
        let mut next = delta;
        for f in 0..2 {
            if (forces[f] / tension[f] - 1.0).abs() > tolerance {
                let now = Evaluation {
                    stretch: delta[f],
                    force: forces[f],
                };
                next[f] = search[f].next(now, tension[f], pp);
            }
        }
        for (n, c) in model.coords.iter().enumerate() {
            for f in 0..2 {
                u[n][f] += (next[f] - delta[f]) * (c[f] - cell.origin) / pp;
            }
        }
        delta = next;
    }
    Err(WeftError::input(format!(
        "the periodic cell's planes, moved {:.4e} / {:.4e} m, give {:.4} / {:.4} N per warp / weft yarn after {ROUNDS} relaxations",
        delta[0], delta[1], forces[0], forces[1]
    ))
    .expected(format!(
        "the residual tension {} / {} N to {:.1e}",
        tension[0], tension[1], tolerance
    ))
    .hint("use --start geometry"))
}

/// The patch's displacement from the formed cell (see the module docs): the cell
/// reflected over the patch, plus the planes' stretch. Nodes that are not in a yarn
/// (a membrane around the patch) get none.
pub fn tile(m: &Model, cell: &Cell, f: &CellForm) -> Result<Vec<[f64; 3]>> {
    let p = cell.spacing;
    let q = 1e-6 * p;
    let key = |part: usize, x: f64, y: f64| (part, (x / q).round() as i64, (y / q).round() as i64);
    let mut index: std::collections::HashMap<(usize, i64, i64), usize> = Default::default();
    let cm = &cell.model;
    for (b, npe, e) in yarn_elements(cm) {
        for &n in &b.nodes[npe * e..npe * (e + 1)] {
            let c = cm.coords[n];
            index.insert(key(cell.patch_part[b.part[e]], c[0], c[1]), n);
        }
    }
    // Fold a coordinate into the cell: (folded, sign of the displacement, planes passed).
    let fold = |c: f64| -> (f64, f64, f64) {
        let s = (c - cell.origin) / p;
        let k = (s + 1e-9).floor();
        let r = ((s - k) * p).max(0.0);
        if (k as i64).rem_euclid(2) == 0 {
            (cell.origin + r, 1.0, k)
        } else {
            (cell.origin + p - r, -1.0, k + 1.0)
        }
    };
    let mut u = vec![[0.0; 3]; m.num_nodes()];
    let mut done = vec![false; m.num_nodes()];
    for (b, npe, e) in yarn_elements(m) {
        for &n in &b.nodes[npe * e..npe * (e + 1)] {
            if done[n] {
                continue;
            }
            let c = m.coords[n];
            let (x, sx, kx) = fold(c[0]);
            let (y, sy, ky) = fold(c[1]);
            let Some(&k) = index.get(&key(b.part[e], x, y)) else {
                return Err(WeftError::input(format!(
                    "node `{}` ({}, at x = {:e}, y = {:e} m) has no counterpart at x = {x:e}, y = {y:e} m in the periodic cell",
                    m.node_id[n], m.parts[b.part[e]].name, c[0], c[1]
                ))
                .expected("a plain weave whose mesh repeats at every yarn (as `weft-weave woven` builds it)")
                .hint("use --start geometry"));
            };
            if (cm.coords[k][2] - c[2]).abs() > 1e-6 * p {
                return Err(WeftError::input(format!(
                    "node `{}` ({}, at z = {:e} m) reflects onto cell node `{}` at z = {:e} m",
                    m.node_id[n], m.parts[b.part[e]].name, c[2], cm.node_id[k], cm.coords[k][2]
                ))
                .expected("a plain weave symmetric about every yarn's centre line")
                .hint("use --start geometry"));
            }
            // Planes passed, counted from the patch's centre x = y = 0 rather than from
            // x₀ (the same for a quarter patch; a full patch, x₀ = −(N − 1)p/2, keeps its
            // centre where it is).
            let uc = f.u[k];
            let from_centre = cell.origin / p;
            u[n] = [
                sx * uc[0] + (kx + from_centre) * f.stretch[0],
                sy * uc[1] + (ky + from_centre) * f.stretch[1],
                uc[2],
            ];
            done[n] = true;
        }
    }
    Ok(u)
}
