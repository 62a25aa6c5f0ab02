//! Element results at the output times (`weft-simulate --element-results PART`):
//! `elements.parquet`, one row per output time and selected element, computed from the
//! nodal positions and velocities of the history sample with the solver's own kernels;
//! a hexahedron's row instead from the solver's own state (below).
//!
//! Glossary: X reference (stress-free) positions, u₀ a formed model's initial
//! displacement, u(t), v(t) the history's displacement and velocity, so the current
//! position is x = X + u₀ + u. Per element kind:
//! - truss: L₀ = |X₂ − X₁|/(1 + ε₀) (ε₀ the prestrain), axial strain ε = (L − L₀)/L₀,
//!   axial force N = E·A·ε (0 in compression when tension-only), energy ½(E·A/L₀)(L − L₀)²
//!   ([`crate::solver::truss`]);
//! - beam: the axial part only, L₀ = |X₂ − X₁|, ε and N = E·b·h·ε (bending needs the nodal
//!   rotations, which the history does not hold);
//! - link: relative displacement d = (x₂ − x₁) − (X₂ − X₁) and, for a link without a
//!   friction slider, the force it carries k∘d + c∘ḋ (the force on node 1; node 2 gets
//!   the opposite) and its spring energy ½ d·k∘d (a slider's slip is solver state the
//!   history does not hold: null there);
//! - tri, quad: Green strain [E₁₁, E₂₂, 2E₁₂] in material axes, second Piola–Kirchhoff
//!   stress S = D E + S₀ (tension field applied), membrane strain energy A₀ s (½E·DE + S₀·E)
//!   without the hourglass part ([`crate::solver::membrane`]);
//! - hex: the integration point's state, which depends on the path and not on the
//!   positions alone, handed over by the solver at its sample steps
//!   ([`crate::solver::Sink::element_states`], of the elements the simulate stage chooses
//!   with [`crate::solver::Solver::sample_states_of`]: [`ElementResults::hex_elements`];
//!   the hex nodes need no history):
//!   `plastic_strain` the equivalent plastic strain ε_p = ∫√(⅔ ε̇ᵖ:ε̇ᵖ) dt,
//!   `temperature` T [K] (Johnson–Cook: from the part's `room_temperature` up by the
//!   adiabatic heating; J2 and elastic parts: 293.15 K throughout), `pressure` p = −tr σ/3 [Pa] (compression
//!   positive; the Cauchy stress alone, without the bulk viscosity q that the element
//!   adds to it in its forces), `von_mises_stress` σ̄ = √(3/2 s:s) [Pa], s the deviator.
//!   The other quantity columns are null (`energy` too: the element's internal work in
//!   the ledger holds the plastic work, which is no stored energy). An eroded hexahedron
//!   keeps its row: `plastic_strain` and `temperature` as it eroded, `pressure` and
//!   `von_mises_stress` 0 (its forces are zero from then on; at an output time between
//!   the step before its erosion and the erosion step they are interpolated like any
//!   other value). The static solve has no solid stiffness: it writes no hex rows;
//! - point masses have no row.
//!
//! `energy` [J]: the element's stored elastic energy as above (truss, link without a
//! slider, membranes; null for beams, whose bending energy needs the rotations, and for
//! hexahedra).
//!
//! Between solver steps the history is interpolated linearly; the element quantities
//! here are those of the interpolated positions (the same at the steps themselves). A
//! hexahedron's σ, ε_p and T are interpolated linearly between the two steps around the
//! output time, and p and σ̄ taken of the interpolated σ.

use std::path::Path;

use crate::error::{Result, WeftError};
use crate::material;
use crate::model::{ElementBlock, ElementKind, Model};
use crate::solver::membrane::{self, Material, Reference};
use crate::solver::output::StateValues;
use crate::solver::{truss, Energies, Sink};
use crate::table::{batch, write_table, Col, Provenance};

/// One selected element with what its quantities need.
enum Item {
    Truss {
        nodes: [usize; 2],
        k: f64,
        l0: f64,
        tension_only: bool,
    },
    Beam {
        nodes: [usize; 2],
        l0: f64,
        ea: f64,
    },
    Link {
        nodes: [usize; 2],
        d0: [f64; 3],
        k: [f64; 3],
        c: [f64; 3],
        slider: bool,
    },
    Tri(Box<Membrane<3>>),
    Quad(Box<Membrane<4>>),
}

struct Membrane<const N: usize> {
    nodes: [usize; N],
    reference: Reference<N>,
    material: Material,
    thickness: f64,
}

/// The element-results calculator: which elements, and the table being collected.
pub struct ElementResults {
    id: Vec<i64>,
    part_id: Vec<i64>,
    kind: Vec<&'static str>,
    items: Vec<Item>,
    /// Initial positions X + u₀.
    x0: Vec<[f64; 3]>,
    /// Model node index → position in the history's node list.
    slot: Vec<usize>,
    /// The selected hexahedra: rows of the model's hex table, their ids and part ids.
    hex: Vec<u32>,
    hex_id: Vec<i64>,
    hex_part_id: Vec<i64>,
    rows: Rows,
}

#[derive(Default)]
struct Rows {
    t: Vec<f64>,
    id: Vec<i64>,
    part_id: Vec<i64>,
    kind: Vec<String>,
    /// Nullable quantity columns, in [`COLUMNS`] order.
    q: [Vec<Option<f64>>; 19],
}

/// The quantity columns computed from the history (all but the hexahedra's).
const HISTORY_COLUMNS: usize = 15;

/// The quantity columns of `elements.parquet`, in order.
pub const COLUMNS: [&str; 19] = [
    "axial_strain",
    "axial_force",
    "relative_displacement_x",
    "relative_displacement_y",
    "relative_displacement_z",
    "force_x",
    "force_y",
    "force_z",
    "strain_11",
    "strain_22",
    "strain_12",
    "stress_11",
    "stress_22",
    "stress_12",
    "energy",
    "plastic_strain",
    "temperature",
    "pressure",
    "von_mises_stress",
];

/// Whether each part of `m` is among `parts` (`all`: every one); an unknown name is
/// refused with the model's part names.
fn chosen_parts(m: &Model, parts: &[String]) -> Result<Vec<bool>> {
    let mut chosen = vec![false; m.parts.len()];
    for name in parts {
        if name == "all" {
            chosen.iter_mut().for_each(|c| *c = true);
            continue;
        }
        let i = m.part_index(name).ok_or_else(|| {
            WeftError::input(format!("--element-results: no part `{name}`")).expected(format!(
                "`all` or a part of the model: {}",
                m.parts
                    .iter()
                    .map(|p| format!("`{}`", p.name))
                    .collect::<Vec<_>>()
                    .join(", ")
            ))
        })?;
        chosen[i] = true;
    }
    Ok(chosen)
}

impl Item {
    /// What the quantities of element `e` of block `b` (kind `kind`, nodes `nodes`) need
    /// (module docs); not for point masses and hexahedra, which take no history.
    fn of(
        m: &Model,
        kind: ElementKind,
        b: &ElementBlock,
        e: usize,
        nodes: &[usize],
    ) -> Result<Item> {
        let p = &m.parts[b.part[e]].props;
        let sub = |a: usize, b: usize| -> [f64; 3] {
            std::array::from_fn(|d| m.coords[b][d] - m.coords[a][d])
        };
        let norm = |v: [f64; 3]| (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
        Ok(match kind {
            ElementKind::Truss => {
                let l = norm(sub(nodes[0], nodes[1]));
                let l0 = l / (1.0 + p.prestrain.unwrap_or(0.0));
                let ea = p.youngs_modulus.unwrap_or(0.0) * b.truss_area(&m.parts, e);
                Item::Truss {
                    nodes: [nodes[0], nodes[1]],
                    k: ea / l0,
                    l0,
                    tension_only: p.tension_only.unwrap_or(false),
                }
            }
            ElementKind::Beam => Item::Beam {
                nodes: [nodes[0], nodes[1]],
                l0: norm(sub(nodes[0], nodes[1])),
                ea: p.youngs_modulus.unwrap_or(0.0)
                    * p.width.unwrap_or(0.0)
                    * p.height.unwrap_or(0.0),
            },
            ElementKind::Link => Item::Link {
                nodes: [nodes[0], nodes[1]],
                d0: sub(nodes[0], nodes[1]),
                k: [p.kx, p.ky, p.kz].map(|v| v.unwrap_or(0.0)),
                c: [p.cx, p.cy, p.cz].map(|v| v.unwrap_or(0.0)),
                slider: p.slip_force.is_some() || p.sliding == Some(true),
            },
            ElementKind::Tri => Item::Tri(Box::new(membrane_item(m, b, e, nodes)?)),
            ElementKind::Quad => Item::Quad(Box::new(membrane_item(m, b, e, nodes)?)),
            ElementKind::PointMass | ElementKind::Hex => unreachable!("no history for {kind:?}"),
        })
    }
}

impl ElementResults {
    /// Select the elements of the named parts (`all`: every part) of a validated model;
    /// `output_nodes` are the history's nodes, which must hold every node of those
    /// elements.
    pub fn new(m: &Model, parts: &[String], output_nodes: &[usize]) -> Result<ElementResults> {
        let chosen = chosen_parts(m, parts)?;
        let mut slot = vec![usize::MAX; m.num_nodes()];
        for (j, &i) in output_nodes.iter().enumerate() {
            slot[i] = j;
        }
        let x0: Vec<[f64; 3]> = (0..m.num_nodes())
            .map(|i| {
                let u0 = m.initial_displacement.get(i).copied().unwrap_or([0.0; 3]);
                std::array::from_fn(|d| m.coords[i][d] + u0[d])
            })
            .collect();
        let mut r = ElementResults {
            id: vec![],
            part_id: vec![],
            kind: vec![],
            items: vec![],
            x0,
            slot,
            hex: vec![],
            hex_id: vec![],
            hex_part_id: vec![],
            rows: Rows::default(),
        };
        for (&kind, b) in &m.elements {
            let npe = kind.nodes_per_element();
            for e in 0..b.len() {
                let part = &m.parts[b.part[e]];
                // Point masses carry no result; a hex's stress, plastic strain and temperature
                // depend on the path, not on the history's positions alone: the solver hands
                // them over ([`ElementResults::sample_solids`]), its nodes need no history.
                if !chosen[b.part[e]] || kind == ElementKind::PointMass {
                    continue;
                }
                if kind == ElementKind::Hex {
                    r.hex.push(e as u32);
                    r.hex_id.push(b.id[e]);
                    r.hex_part_id.push(part.id);
                    continue;
                }
                let nodes = &b.nodes[npe * e..npe * (e + 1)];
                if let Some(&n) = nodes.iter().find(|&&n| r.slot[n] == usize::MAX) {
                    return Err(WeftError::input(format!(
                        "element results of part `{}` need the history of its nodes; node `{}` (element `{}`) is not in the history's node sets",
                        part.name, m.node_id[n], b.id[e]
                    ))
                    .hint("write every node: weft-simulate --all-nodes (or add the part's nodes to a --history-set)"));
                }
                let item = Item::of(m, kind, b, e, nodes)?;
                r.id.push(b.id[e]);
                r.part_id.push(part.id);
                r.kind.push(kind.name());
                r.items.push(item);
            }
        }
        Ok(r)
    }

    /// Number of selected elements whose quantities come from the history (all but the
    /// hexahedra).
    pub fn len(&self) -> usize {
        self.items.len()
    }

    pub fn is_empty(&self) -> bool {
        self.items.is_empty()
    }

    /// The selected hexahedra, as rows of the model's hex table (the indices of the
    /// solver's hex family): what [`crate::solver::Solver::sample_states_of`] must
    /// hold for the run to hand over their states.
    pub fn hex_elements(&self) -> &[u32] {
        &self.hex
    }

    /// Add the hexahedra's rows of output time `t` from their states (in the order of
    /// [`ElementResults::hex_elements`]).
    pub fn sample_solids(&mut self, t: f64, states: &[StateValues]) -> Result<()> {
        if states.len() != self.hex.len() {
            return Err(WeftError::input(format!(
                "element results: the run handed over {} hexahedra at t = {t:e} s, {} were selected",
                states.len(),
                self.hex.len()
            ))
            .hint("choose the hexahedra with Solver::sample_states_of(ElementKind::Hex, ElementResults::hex_elements()) before the run"));
        }
        for (j, st) in states.iter().enumerate() {
            let s: [f64; 6] = std::array::from_fn(|c| st[c]);
            self.rows.t.push(t);
            self.rows.id.push(self.hex_id[j]);
            self.rows.part_id.push(self.hex_part_id[j]);
            self.rows.kind.push(ElementKind::Hex.name().to_string());
            for c in &mut self.rows.q[..HISTORY_COLUMNS] {
                c.push(None);
            }
            let new = [
                st[6],
                st[7],
                material::pressure(&s),
                material::von_mises(&s),
            ];
            for (c, v) in self.rows.q[HISTORY_COLUMNS..].iter_mut().zip(new) {
                c.push(Some(v));
            }
        }
        Ok(())
    }

    /// Add the rows of output time `t` from the history sample (u, v of the output
    /// nodes, in the history's order).
    pub fn sample(&mut self, t: f64, u: &[[f64; 3]], v: &[[f64; 3]]) {
        for e in 0..self.items.len() {
            let q = self.quantities(e, u, v);
            self.rows.t.push(t);
            self.rows.id.push(self.id[e]);
            self.rows.part_id.push(self.part_id[e]);
            self.rows.kind.push(self.kind[e].to_string());
            for (c, v) in q.into_iter().enumerate() {
                self.rows.q[c].push(v);
            }
            for c in &mut self.rows.q[HISTORY_COLUMNS..] {
                c.push(None);
            }
        }
    }

    /// The stored elastic energy [J] of selected element `e` (the `energy` column: None
    /// for beams and links with a slider) at the history sample u, v (of the output
    /// nodes, in the history's order). Used by [`crate::analysis::energy`].
    pub fn energy(&self, e: usize, u: &[[f64; 3]], v: &[[f64; 3]]) -> Option<f64> {
        self.quantities(e, u, v)[14]
    }

    /// Id of the part of selected element `e` (the `part_id` column).
    pub fn element_part_id(&self, e: usize) -> i64 {
        self.part_id[e]
    }

    /// Node indices of selected element `e`.
    pub fn element_nodes(&self, e: usize) -> &[usize] {
        match &self.items[e] {
            Item::Truss { nodes, .. } | Item::Beam { nodes, .. } | Item::Link { nodes, .. } => {
                nodes
            }
            Item::Tri(mb) => &mb.nodes,
            Item::Quad(mb) => &mb.nodes,
        }
    }

    /// The quantity columns of selected element `e` at a history sample.
    fn quantities(&self, e: usize, u: &[[f64; 3]], v: &[[f64; 3]]) -> [Option<f64>; 15] {
        let pos = |i: usize| -> [f64; 3] {
            let j = self.slot[i];
            std::array::from_fn(|d| self.x0[i][d] + u[j][d])
        };
        let vel = |i: usize| v[self.slot[i]];
        let mut q = [None; 15];
        match &self.items[e] {
            Item::Truss {
                nodes,
                k,
                l0,
                tension_only,
            } => {
                let (x1, x2) = (pos(nodes[0]), pos(nodes[1]));
                let l = dist(&x1, &x2);
                q[0] = Some((l - l0) / l0);
                q[1] = Some(truss::axial_force(&x1, &x2, *k, *l0, *tension_only));
                q[14] = Some(truss::energy(&x1, &x2, *k, *l0, *tension_only));
            }
            Item::Beam { nodes, l0, ea } => {
                let eps = (dist(&pos(nodes[0]), &pos(nodes[1])) - l0) / l0;
                q[0] = Some(eps);
                q[1] = Some(ea * eps);
            }
            Item::Link {
                nodes,
                d0,
                k,
                c,
                slider,
            } => {
                let (x1, x2) = (pos(nodes[0]), pos(nodes[1]));
                let (v1, v2) = (vel(nodes[0]), vel(nodes[1]));
                let mut w = 0.0;
                for d in 0..3 {
                    let dd = x2[d] - x1[d] - d0[d];
                    q[2 + d] = Some(dd);
                    w += 0.5 * k[d] * dd * dd;
                    if !slider {
                        q[5 + d] = Some(k[d] * dd + c[d] * (v2[d] - v1[d]));
                    }
                }
                if !slider {
                    q[14] = Some(w);
                }
            }
            Item::Tri(mb) => membrane_row(mb, &pos, &mut q),
            Item::Quad(mb) => membrane_row(mb, &pos, &mut q),
        }
        q
    }

    /// Write `elements.parquet` (atomically).
    pub fn write(self, path: &Path, prov: &Provenance) -> Result<()> {
        let r = self.rows;
        let mut cols = vec![
            Col::F64("t", r.t),
            Col::I64("element_id", r.id),
            Col::I64("part_id", r.part_id),
            Col::Str("kind", r.kind),
        ];
        for (name, v) in COLUMNS.iter().zip(r.q) {
            cols.push(Col::OptF64(name, v));
        }
        write_table(path, &batch(cols), prov)
    }
}

fn dist(a: &[f64; 3], b: &[f64; 3]) -> f64 {
    ((b[0] - a[0]).powi(2) + (b[1] - a[1]).powi(2) + (b[2] - a[2]).powi(2)).sqrt()
}

fn membrane_item<const N: usize>(
    m: &Model,
    b: &crate::model::ElementBlock,
    e: usize,
    nodes: &[usize],
) -> Result<Membrane<N>> {
    let p = &m.parts[b.part[e]].props;
    let x: [[f64; 3]; N] = std::array::from_fn(|a| m.coords[nodes[a]]);
    let reference = Reference::new(&x, p.material_angle.unwrap_or(0.0))
        .ok_or_else(|| WeftError::input(format!("membrane element `{}` is degenerate", b.id[e])))?;
    let mut material = Material::orthotropic(
        p.youngs_modulus_1.unwrap_or(0.0),
        p.youngs_modulus_2.unwrap_or(0.0),
        p.poisson_ratio_12.unwrap_or(0.0),
        p.shear_modulus_12.unwrap_or(0.0),
        p.no_compression.unwrap_or(false),
    )?;
    if !b.stress0.is_empty() {
        material.s0 = b.stress0[e];
    }
    let thickness = if b.thickness.is_empty() {
        p.thickness.unwrap_or(0.0)
    } else {
        b.thickness[N * e..N * (e + 1)].iter().sum::<f64>() / N as f64
    };
    Ok(Membrane {
        nodes: std::array::from_fn(|a| nodes[a]),
        reference,
        material,
        thickness,
    })
}

fn membrane_row<const N: usize>(
    mb: &Membrane<N>,
    pos: &dyn Fn(usize) -> [f64; 3],
    q: &mut [Option<f64>; 15],
) {
    let x: [[f64; 3]; N] = std::array::from_fn(|a| pos(mb.nodes[a]));
    let e = membrane::green_strain(&x, &mb.reference);
    let s = membrane::stress(&mb.material, &e);
    for k in 0..3 {
        q[8 + k] = Some(e[k]);
        q[11 + k] = Some(s[k]);
    }
    q[14] = Some(membrane::energy(&x, &mb.reference, &mb.material, mb.thickness, 0.0).0);
}

/// A sink that passes everything on to `inner` and samples the element results at
/// every history output.
pub struct WithElementResults<'a, S: Sink> {
    pub inner: S,
    pub results: &'a mut ElementResults,
}

impl<S: Sink> Sink for WithElementResults<'_, S> {
    fn history(&mut self, t: f64, nodes: &[usize], u: &[[f64; 3]], v: &[[f64; 3]]) -> Result<()> {
        self.results.sample(t, u, v);
        self.inner.history(t, nodes, u, v)
    }
    fn energy(&mut self, t: f64, e: &Energies) -> Result<()> {
        self.inner.energy(t, e)
    }
    fn projectile(&mut self, t: f64, id: i64, state: &[f64; 9]) -> Result<()> {
        self.inner.projectile(t, id, state)
    }
    fn layers(&mut self, t: f64, rows: &[crate::solver::watch::LayerValues]) -> Result<()> {
        self.inner.layers(t, rows)
    }
    fn element_states(&mut self, t: f64, rows: &[StateValues]) -> Result<()> {
        self.results.sample_solids(t, rows)?;
        self.inner.element_states(t, rows)
    }
    fn crater(&mut self, t: f64, rows: &[crate::solver::crater::CraterRow]) -> Result<()> {
        self.inner.crater(t, rows)
    }
}
