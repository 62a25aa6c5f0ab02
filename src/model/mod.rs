//! The model: nodes, parts, elements by kind, node sets, constraints, loads with time
//! laws, initial velocities and analysis settings, all in SI units.
//!
//! A model lives on disk as a folder of Parquet tables (see [`io`] and
//! `docs/tables.md`); in memory, elements refer to nodes and parts by index. Generators
//! build models with [`Model`]'s `add_*` methods; [`Model::validate`] checks every
//! property and reference and names the offending part, element, node or row.

pub mod contacts;
pub mod io;
pub mod kinds;
pub mod props;

pub use kinds::ElementKind;
pub use props::PartProps;

use std::collections::{BTreeMap, HashMap};
use std::sync::Arc;

use crate::error::{Result, WeftError};

/// A part (`parts.parquet`): a named group of elements of one kind that share their
/// properties.
#[derive(Debug, Clone, PartialEq)]
pub struct Part {
    pub id: i64,
    pub name: String,
    pub kind: ElementKind,
    pub props: PartProps,
}

/// Elements of one kind, struct-of-arrays; `nodes` holds `nodes_per_element` node
/// indices per element.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct ElementBlock {
    pub id: Vec<i64>,
    /// Index into [`Model::parts`].
    pub part: Vec<usize>,
    /// Node indices, `nodes_per_element` consecutive entries per element.
    pub nodes: Vec<usize>,
    /// Membranes: thickness at each element node [m], `nodes_per_element` entries per
    /// element (LS-DYNA's shell nodal thickness); empty when every element has its
    /// part's thickness.
    pub thickness: Vec<f64>,
    /// Trusses: cross-section area of each element [m²] (a yarn on a symmetry plane
    /// carries half its section); empty when every truss has its part's area.
    pub area: Vec<f64>,
    /// Membranes: initial stress [S₁₁, S₂₂, S₁₂] [Pa] in material axes, one per element
    /// (a formed, pre-stressed state); empty when every element starts unstressed.
    pub stress0: Vec<[f64; 3]>,
    /// Links: the frame nodes (f1, f2, f3, f4) of each link, whose local frame has
    /// e₁ along x_f2 − x_f1 and its normal n along e₁ × (x_f4 − x_f3) (the crossing's two
    /// yarn directions); empty when no link carries them. Read only by links whose part
    /// has `local_frame`.
    pub frame: Vec<[usize; 4]>,
}

impl ElementBlock {
    pub fn len(&self) -> usize {
        self.id.len()
    }
    pub fn is_empty(&self) -> bool {
        self.id.is_empty()
    }
    /// Trusses: the cross-section area of element `e` [m²], its own or its part's.
    pub fn truss_area(&self, parts: &[Part], e: usize) -> f64 {
        match self.area.get(e) {
            Some(&a) => a,
            None => parts[self.part[e]].props.area.unwrap_or(0.0),
        }
    }
}

/// A tabulated function of time g(t), linearly interpolated, held constant beyond its
/// first and last points.
#[derive(Debug, Clone, PartialEq)]
pub struct Curve {
    pub t: Vec<f64>,
    pub value: Vec<f64>,
}

impl Curve {
    pub fn eval(&self, t: f64) -> f64 {
        let n = self.t.len();
        if t <= self.t[0] {
            return self.value[0];
        }
        if t >= self.t[n - 1] {
            return self.value[n - 1];
        }
        let i = self.t.partition_point(|&ti| ti <= t) - 1;
        let w = (t - self.t[i]) / (self.t[i + 1] - self.t[i]);
        self.value[i] + w * (self.value[i + 1] - self.value[i])
    }
}

/// Time law g(t) of a load: the applied force is F(t) = F·g(t).
#[derive(Debug, Clone, PartialEq)]
pub enum TimeLaw {
    /// g = sin(π (t − t0)/T_F) for t0 ≤ t ≤ t0 + T_F, 0 otherwise.
    SinePulse { start: f64, duration: f64 },
    /// g = 0 before t0, 1 from t0 on.
    Step { start: f64 },
    /// g = 0 before t0, rising linearly to 1 at t0 + T, 1 after.
    Ramp { start: f64, duration: f64 },
    /// g = the named curve of `curves.parquet`, evaluated at t.
    Tabulated { name: String, curve: Arc<Curve> },
}

impl TimeLaw {
    pub fn name(&self) -> &'static str {
        match self {
            TimeLaw::SinePulse { .. } => "sine_pulse",
            TimeLaw::Step { .. } => "step",
            TimeLaw::Ramp { .. } => "ramp",
            TimeLaw::Tabulated { .. } => "tabulated",
        }
    }
    pub fn eval(&self, t: f64) -> f64 {
        match self {
            TimeLaw::SinePulse { start, duration } => {
                let s = t - start;
                if (0.0..=*duration).contains(&s) {
                    (std::f64::consts::PI * s / duration).sin()
                } else {
                    0.0
                }
            }
            TimeLaw::Step { start } => {
                if t >= *start {
                    1.0
                } else {
                    0.0
                }
            }
            TimeLaw::Ramp { start, duration } => ((t - start) / duration).clamp(0.0, 1.0),
            TimeLaw::Tabulated { curve, .. } => curve.eval(t),
        }
    }
}

/// A nodal force F·g(t).
#[derive(Debug, Clone, PartialEq)]
pub struct Load {
    pub id: i64,
    pub node: usize,
    /// Force vector amplitude [N].
    pub force: [f64; 3],
    pub law: TimeLaw,
}

/// Shape of a rigid projectile's nose.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, clap::ValueEnum)]
#[serde(rename_all = "lowercase")]
pub enum ProjectileShape {
    Sphere,
    /// Flat-nosed cylinder.
    Flat,
    /// Round-nosed cylinder (hemispherical nose).
    Round,
}

impl ProjectileShape {
    pub fn name(self) -> &'static str {
        match self {
            ProjectileShape::Sphere => "sphere",
            ProjectileShape::Flat => "flat",
            ProjectileShape::Round => "round",
        }
    }
    pub fn parse(s: &str) -> Option<Self> {
        [
            ProjectileShape::Sphere,
            ProjectileShape::Flat,
            ProjectileShape::Round,
        ]
        .into_iter()
        .find(|k| k.name() == s)
    }
}

/// A rigid projectile (`projectile.parquet`): translation only, contact with nodes.
#[derive(Debug, Clone, PartialEq)]
pub struct ProjectileSpec {
    pub id: i64,
    pub shape: ProjectileShape,
    /// Radius [m].
    pub radius: f64,
    /// Body length behind the nose tip [m] (cylinders).
    pub length: f64,
    /// Mass [kg].
    pub mass: f64,
    /// Nose tip position [m].
    pub tip: [f64; 3],
    /// Axis, pointing from the body to the tip (normalised on use).
    pub axis: [f64; 3],
    /// Initial velocity [m/s].
    pub velocity: [f64; 3],
    /// Moves at its initial velocity whatever the contact force.
    pub prescribed_velocity: bool,
    /// Penalty stiffness per node [N/m]; `None`: 0.1·m_node/Δt².
    pub contact_stiffness: Option<f64>,
    /// Coulomb friction coefficient μ.
    pub friction: f64,
    /// Also contact the membrane faces (sample points at face centroids and edge
    /// midpoints), so that a projectile smaller than an element cannot pass between
    /// nodes. Default true.
    pub segment_contact: bool,
}

/// A symmetry plane (`symmetry.parquet`): nodes on it keep their displacement normal to
/// it at zero (quarter models: x = 0 and y = 0).
#[derive(Debug, Clone, PartialEq)]
pub struct SymmetryPlane {
    /// Normal axis: 0 = x, 1 = y, 2 = z.
    pub normal: usize,
    /// Plane position along the normal [m].
    pub position: f64,
    /// Nodes within this distance lie on the plane [m].
    pub tolerance: f64,
}

/// A tied node (`ties.parquet`): the slave follows the master edge (2 nodes) or face
/// (3 or 4 nodes) it lies on; its mass and forces go to the masters with the same weights.
#[derive(Debug, Clone, PartialEq)]
pub struct Tie {
    pub slave: usize,
    pub masters: Vec<usize>,
}

/// Analysis settings (`analysis.parquet`); command-line flags of `weft-simulate`
/// override them.
#[derive(Debug, Clone, PartialEq)]
pub struct Analysis {
    /// Simulated time [s].
    pub end_time: f64,
    /// Spacing of the output time grid [s]; outputs at k·Δt_out, k = 0..=round(end/Δt_out).
    pub output_interval: f64,
    /// Safety factor on the stable time step (0 < f ≤ 1). Default 0.9: the usual
    /// explicit-code margin for the step estimate's neglect of element coupling.
    pub dt_safety: f64,
    /// Mass-proportional damping coefficient α [1/s]: f_d = −α m v.
    pub mass_damping: f64,
    /// Fixed time step [s]; must not exceed the stable step. `None`: the stable step.
    pub time_step: Option<f64>,
    /// Target time step for mass scaling [s]: elements whose stable step is below it get
    /// added nodal mass. `None`: no mass scaling.
    pub target_time_step: Option<f64>,
    /// Node sets written to `history.parquet`; empty = all nodes.
    pub history_sets: Vec<String>,
    /// Stop when |energy balance error| exceeds this fraction of the reference energy.
    /// Default 0.1: far above the O(Δt²) drift of a stable run, far below the energy
    /// growth of an instability, which is exponential.
    pub max_energy_error: f64,
}

impl Default for Analysis {
    fn default() -> Self {
        Analysis {
            end_time: 1e-4,
            output_interval: 1e-6,
            dt_safety: 0.9,
            mass_damping: 0.0,
            time_step: None,
            target_time_step: None,
            history_sets: Vec::new(),
            max_energy_error: 0.1,
        }
    }
}

#[derive(Debug, Clone, Default, PartialEq)]
pub struct Model {
    pub node_id: Vec<i64>,
    /// Reference coordinates [m]: the stress-free geometry of the elements.
    pub coords: Vec<[f64; 3]>,
    /// Initial displacement from the reference [m], one per node, or empty (none): a
    /// formed state (`weft-form`) starts at coords + u₀ with the strains, contact
    /// penetrations and hourglass forces of that state; displacements in the outputs are
    /// measured from coords + u₀.
    pub initial_displacement: Vec<[f64; 3]>,
    pub parts: Vec<Part>,
    /// Element blocks by kind.
    pub elements: BTreeMap<ElementKind, ElementBlock>,
    /// Named ordered node sets (node indices).
    pub node_sets: BTreeMap<String, Vec<usize>>,
    /// Fixed degrees of freedom per constrained node: (node index, [x, y, z] fixed).
    pub constraints: Vec<(usize, [bool; 3])>,
    /// Fixed rotations about x, y, z (nodes with beams): (node index, [rx, ry, rz]).
    pub rot_constraints: Vec<(usize, [bool; 3])>,
    pub loads: Vec<Load>,
    /// Tabulated curves by name.
    pub curves: BTreeMap<String, Arc<Curve>>,
    /// Initial velocities [m/s]: (node index, v).
    pub initial_velocities: Vec<(usize, [f64; 3])>,
    pub projectiles: Vec<ProjectileSpec>,
    pub symmetry: Vec<SymmetryPlane>,
    pub ties: Vec<Tie>,
    /// Contact definitions (`contacts.parquet`).
    pub contacts: Vec<contacts::ContactDef>,
    pub analysis: Analysis,
}

impl Model {
    pub fn num_nodes(&self) -> usize {
        self.node_id.len()
    }

    /// The model's node set names, each in backticks, comma-separated (for messages that
    /// say which sets there are).
    pub fn node_set_names(&self) -> String {
        self.node_sets
            .keys()
            .map(|k| format!("`{k}`"))
            .collect::<Vec<_>>()
            .join(", ")
    }

    /// Add a node; returns its index.
    pub fn add_node(&mut self, id: i64, x: [f64; 3]) -> usize {
        self.node_id.push(id);
        self.coords.push(x);
        self.node_id.len() - 1
    }

    /// Add a part; returns its index.
    pub fn add_part(&mut self, id: i64, name: &str, kind: ElementKind, props: PartProps) -> usize {
        self.parts.push(Part {
            id,
            name: name.to_string(),
            kind,
            props,
        });
        self.parts.len() - 1
    }

    /// Add an element of the part's kind on the given node indices.
    pub fn add_element(&mut self, id: i64, part: usize, nodes: &[usize]) {
        let kind = self.parts[part].kind;
        assert_eq!(
            nodes.len(),
            kind.nodes_per_element(),
            "node count of a {}",
            kind.name()
        );
        let t = self.parts[part].props.thickness.unwrap_or(0.0);
        let a = self.parts[part].props.area.unwrap_or(0.0);
        let b = self.elements.entry(kind).or_default();
        b.id.push(id);
        b.part.push(part);
        b.nodes.extend_from_slice(nodes);
        if !b.thickness.is_empty() {
            b.thickness.extend(std::iter::repeat_n(t, nodes.len()));
        }
        if !b.area.is_empty() {
            b.area.push(a);
        }
        if !b.stress0.is_empty() {
            b.stress0.push([0.0; 3]);
        }
        if !b.frame.is_empty() {
            // A link without frame nodes of its own: the link's nodes twice (a frame
            // that `validate` refuses if its part asks for a local frame).
            b.frame.push([nodes[0], nodes[1], nodes[0], nodes[1]]);
        }
    }

    /// Add a link with its frame nodes (f1, f2, f3, f4): e₁ along x_f2 − x_f1, the normal
    /// along e₁ × (x_f4 − x_f3) (see [`ElementBlock::frame`]).
    pub fn add_link_with_frame(
        &mut self,
        id: i64,
        part: usize,
        nodes: &[usize],
        frame: [usize; 4],
    ) {
        let b = self.elements.entry(ElementKind::Link).or_default();
        if b.frame.is_empty() && !b.is_empty() {
            b.frame = (0..b.len())
                .map(|e| {
                    let (a, c) = (b.nodes[2 * e], b.nodes[2 * e + 1]);
                    [a, c, a, c]
                })
                .collect();
        }
        self.add_element(id, part, nodes);
        let b = self
            .elements
            .get_mut(&ElementKind::Link)
            .expect("just added");
        if b.frame.len() < b.len() {
            b.frame.push(frame);
        } else {
            *b.frame.last_mut().expect("one per link") = frame;
        }
    }

    /// Add a membrane element with a thickness at each of its nodes [m].
    pub fn add_element_with_thickness(
        &mut self,
        id: i64,
        part: usize,
        nodes: &[usize],
        thickness: &[f64],
    ) {
        assert_eq!(nodes.len(), thickness.len(), "one thickness per node");
        let kind = self.parts[part].kind;
        let parts = &self.parts;
        let b = self.elements.entry(kind).or_default();
        if b.thickness.is_empty() && !b.is_empty() {
            // Earlier elements have their part's thickness.
            let npe = kind.nodes_per_element();
            b.thickness = b
                .part
                .iter()
                .flat_map(|&p| std::iter::repeat_n(parts[p].props.thickness.unwrap_or(0.0), npe))
                .collect();
        }
        self.add_element(id, part, nodes);
        let b = self.elements.get_mut(&kind).expect("just added");
        if b.thickness.is_empty() {
            b.thickness.extend_from_slice(thickness);
        } else {
            let n = b.thickness.len();
            b.thickness[n - thickness.len()..].copy_from_slice(thickness);
        }
    }

    /// Add a truss with a cross-section area of its own [m²] (not its part's).
    pub fn add_truss_with_area(&mut self, id: i64, part: usize, nodes: [usize; 2], area: f64) {
        let parts = &self.parts;
        let b = self.elements.entry(ElementKind::Truss).or_default();
        if b.area.is_empty() && !b.is_empty() {
            // Earlier trusses have their part's area.
            b.area = b
                .part
                .iter()
                .map(|&p| parts[p].props.area.unwrap_or(0.0))
                .collect();
        }
        let fresh = b.area.is_empty();
        self.add_element(id, part, &nodes);
        let b = self
            .elements
            .get_mut(&ElementKind::Truss)
            .expect("just added");
        if fresh {
            b.area.push(area);
        } else {
            *b.area.last_mut().expect("one per truss") = area;
        }
    }

    pub fn block(&self, kind: ElementKind) -> Option<&ElementBlock> {
        self.elements.get(&kind).filter(|b| !b.is_empty())
    }

    pub fn num_elements(&self) -> usize {
        self.elements.values().map(|b| b.len()).sum()
    }

    pub fn part_index(&self, name: &str) -> Option<usize> {
        self.parts.iter().position(|p| p.name == name)
    }

    /// Index of a node by id.
    pub fn node_index_map(&self) -> HashMap<i64, usize> {
        self.node_id
            .iter()
            .enumerate()
            .map(|(i, &id)| (id, i))
            .collect()
    }

    /// Check ids, references and properties. Errors name the part, element or node and
    /// the value (rows refer to the tables' row order).
    pub fn validate(&self) -> Result<()> {
        let mut seen = HashMap::new();
        for (row, id) in self.node_id.iter().enumerate() {
            if let Some(first) = seen.insert(*id, row) {
                return Err(WeftError::input(format!(
                    "duplicate node id `{id}` (first at row {first})"
                ))
                .in_file("nodes.parquet")
                .in_column("node_id")
                .at_row(row)
                .expected("unique node ids")
                .hint("renumber the nodes or merge coincident ones"));
            }
        }
        if !self.initial_displacement.is_empty()
            && self.initial_displacement.len() != self.coords.len()
        {
            return Err(WeftError::input(format!(
                "{} initial displacements for {} nodes",
                self.initial_displacement.len(),
                self.coords.len()
            ))
            .in_file("nodes.parquet")
            .expected("columns ux0, uy0, uz0 on every row, or none"));
        }
        for (row, u) in self.initial_displacement.iter().enumerate() {
            for (c, v) in ["ux0", "uy0", "uz0"].iter().zip(u) {
                if !v.is_finite() {
                    return Err(WeftError::input(format!(
                        "node `{}` has non-finite initial displacement `{v}`",
                        self.node_id[row]
                    ))
                    .in_file("nodes.parquet")
                    .in_column(*c)
                    .at_row(row)
                    .expected("a finite displacement in m, or null for 0"));
                }
            }
        }
        for (row, x) in self.coords.iter().enumerate() {
            for (c, v) in ["x", "y", "z"].iter().zip(x) {
                if !v.is_finite() {
                    return Err(WeftError::input(format!(
                        "node `{}` has non-finite coordinate `{v}`",
                        self.node_id[row]
                    ))
                    .in_file("nodes.parquet")
                    .in_column(*c)
                    .at_row(row)
                    .expected("a finite coordinate in m"));
                }
            }
        }
        let mut part_ids = HashMap::new();
        for (row, p) in self.parts.iter().enumerate() {
            if let Some(first) = part_ids.insert(p.id, row) {
                return Err(WeftError::input(format!(
                    "duplicate part id `{}` (first at row {first})",
                    p.id
                ))
                .in_file("parts.parquet")
                .in_column("part_id")
                .at_row(row)
                .expected("unique part ids"));
            }
            validate_part(p).map_err(|e| e.in_file("parts.parquet").at_row(row))?;
        }
        let mut elem_ids: HashMap<i64, ElementKind> = HashMap::new();
        for (kind, b) in &self.elements {
            let file = format!("elements_{}.parquet", kind.name());
            let npe = kind.nodes_per_element();
            for (row, id) in b.id.iter().enumerate() {
                if let Some(k) = elem_ids.insert(*id, *kind) {
                    return Err(WeftError::input(format!(
                        "duplicate element id `{id}` (also a {} element)",
                        k.name()
                    ))
                    .in_file(&file)
                    .in_column("element_id")
                    .at_row(row)
                    .expected("element ids unique across all element tables"));
                }
                let p = &self.parts[b.part[row]];
                if p.kind != *kind {
                    return Err(WeftError::input(format!(
                        "element `{id}` refers to part `{}` of kind `{}`",
                        p.id,
                        p.kind.name()
                    ))
                    .in_file(&file)
                    .in_column("part_id")
                    .at_row(row)
                    .expected(format!("a part of kind `{}`", kind.name())));
                }
                let ns = &b.nodes[row * npe..(row + 1) * npe];
                if npe == 2 && ns[0] == ns[1] {
                    return Err(WeftError::input(format!(
                        "element `{id}` joins node `{}` to itself",
                        self.node_id[ns[0]]
                    ))
                    .in_file(&file)
                    .in_column("n2")
                    .at_row(row)
                    .expected("two distinct nodes"));
                }
                if *kind == ElementKind::Truss {
                    let (a, c) = (self.coords[ns[0]], self.coords[ns[1]]);
                    let l = ((c[0] - a[0]).powi(2) + (c[1] - a[1]).powi(2) + (c[2] - a[2]).powi(2))
                        .sqrt();
                    if l <= 0.0 {
                        return Err(WeftError::input(format!(
                            "truss `{id}` has zero length: nodes `{}` and `{}` coincide",
                            self.node_id[ns[0]], self.node_id[ns[1]]
                        ))
                        .in_file(&file)
                        .at_row(row)
                        .expected("a truss between distinct positions")
                        .hint("use a link between coincident nodes"));
                    }
                }
            }
        }
        for (name, set) in &self.node_sets {
            if set.is_empty() {
                return Err(WeftError::input(format!("node set `{name}` is empty"))
                    .in_file("node_sets.parquet")
                    .expected("at least one node per set"));
            }
        }
        for l in &self.loads {
            let ok = match &l.law {
                TimeLaw::SinePulse { start, duration } | TimeLaw::Ramp { start, duration } => {
                    start.is_finite() && *duration > 0.0
                }
                TimeLaw::Step { start } => start.is_finite(),
                TimeLaw::Tabulated { .. } => true,
            };
            if !ok {
                return Err(WeftError::input(format!(
                    "load `{}` ({}) has a non-positive duration",
                    l.id,
                    l.law.name()
                ))
                .in_file("loads.parquet")
                .in_column("duration")
                .expected("duration > 0 s for sine_pulse and ramp"));
            }
        }
        // A node both fixed and given an initial velocity in that direction is a
        // contradiction, not something to resolve silently.
        let mut fixed = vec![[false; 3]; self.num_nodes()];
        for (n, f) in &self.constraints {
            for d in 0..3 {
                fixed[*n][d] |= f[d];
            }
        }
        for (row, (n, v)) in self.initial_velocities.iter().enumerate() {
            for d in 0..3 {
                if fixed[*n][d] && v[d] != 0.0 {
                    return Err(WeftError::input(format!(
                        "node `{}` has fixed {} but initial velocity {} = {}",
                        self.node_id[*n],
                        ["x", "y", "z"][d],
                        ["vx", "vy", "vz"][d],
                        v[d]
                    ))
                    .in_file("initial_velocities.parquet")
                    .at_row(row)
                    .expected("zero initial velocity along fixed directions")
                    .hint("remove the constraint or the velocity"));
                }
            }
        }
        for (row, p) in self.projectiles.iter().enumerate() {
            let bad = |col: &str, v: f64, exp: &str| {
                Err(
                    WeftError::input(format!("projectile `{}` has {col} = `{v}`", p.id))
                        .in_file("projectile.parquet")
                        .in_column(col)
                        .at_row(row)
                        .expected(exp.to_string()),
                )
            };
            if !(p.radius > 0.0 && p.radius.is_finite()) {
                return bad("radius", p.radius, "a radius > 0 in m");
            }
            if !(p.mass > 0.0 && p.mass.is_finite()) {
                return bad("mass", p.mass, "a mass > 0 in kg");
            }
            if !(p.length >= 0.0 && p.length.is_finite()) {
                return bad("length", p.length, "a length ≥ 0 in m");
            }
            if !(p.friction >= 0.0 && p.friction.is_finite()) {
                return bad("friction", p.friction, "μ ≥ 0");
            }
            if let Some(k) = p.contact_stiffness {
                if !(k > 0.0 && k.is_finite()) {
                    return bad(
                        "contact_stiffness",
                        k,
                        "a stiffness > 0 in N/m, or null for the automatic one",
                    );
                }
            }
            let n = (p.axis[0].powi(2) + p.axis[1].powi(2) + p.axis[2].powi(2)).sqrt();
            if !(n > 0.0 && n.is_finite()) {
                return bad(
                    "axis_x",
                    n,
                    "a non-zero axis vector (axis_x, axis_y, axis_z)",
                );
            }
        }
        let mut slave_of = vec![false; self.num_nodes()];
        for t in &self.ties {
            slave_of[t.slave] = true;
        }
        let mut seen_slave = vec![false; self.num_nodes()];
        for (row, t) in self.ties.iter().enumerate() {
            let err = |what: String, exp: &str| {
                Err(WeftError::input(what)
                    .in_file("ties.parquet")
                    .at_row(row)
                    .expected(exp.to_string()))
            };
            let sid = self.node_id[t.slave];
            if !(2..=4).contains(&t.masters.len()) {
                return err(
                    format!("tie of node `{sid}` has {} masters", t.masters.len()),
                    "2 (an edge), 3 or 4 (a face) master nodes",
                );
            }
            if seen_slave[t.slave] {
                return err(
                    format!("node `{sid}` is tied twice"),
                    "each slave node in one tie",
                );
            }
            seen_slave[t.slave] = true;
            for (k, &mn) in t.masters.iter().enumerate() {
                if mn == t.slave || t.masters[..k].contains(&mn) {
                    return err(
                        format!("tie of node `{sid}` repeats node `{}`", self.node_id[mn]),
                        "distinct master nodes, none of them the slave",
                    );
                }
                if slave_of[mn] {
                    return err(
                        format!(
                            "master `{}` of the tie of node `{sid}` is itself tied",
                            self.node_id[mn]
                        ),
                        "masters that are not slaves of other ties (no chains)",
                    );
                }
            }
        }
        for (row, s) in self.symmetry.iter().enumerate() {
            if !(s.tolerance >= 0.0 && s.position.is_finite()) {
                return Err(WeftError::input(format!(
                    "symmetry plane has position {} and tolerance {}",
                    s.position, s.tolerance
                ))
                .in_file("symmetry.parquet")
                .at_row(row)
                .expected("a finite position and a tolerance ≥ 0 in m"));
            }
        }
        self.validate_nodal_thickness()?;
        self.validate_link_frames()?;
        self.validate_sliding_links()?;
        contacts::validate(self)?;
        validate_analysis(&self.analysis)
    }

    /// Nodal thickness: one finite value > 0 per element node, membranes only; initial
    /// stress: finite, one per membrane element.
    fn validate_nodal_thickness(&self) -> Result<()> {
        for (kind, b) in &self.elements {
            if !b.stress0.is_empty() {
                let file = format!("elements_{}.parquet", kind.name());
                if !matches!(kind, ElementKind::Tri | ElementKind::Quad)
                    || b.stress0.len() != b.len()
                {
                    return Err(WeftError::input(format!(
                        "{} elements carry {} initial stresses for {} elements",
                        kind.name(),
                        b.stress0.len(),
                        b.len()
                    ))
                    .in_file(file)
                    .expected(
                        "initial stress columns s0_11, s0_22, s0_12 on tri and quad tables only",
                    ));
                }
                for (e, s) in b.stress0.iter().enumerate() {
                    for (c, v) in ["s0_11", "s0_22", "s0_12"].iter().zip(s) {
                        if !v.is_finite() {
                            return Err(WeftError::input(format!(
                                "{} `{}` has initial stress {c} = `{v}`",
                                kind.name(),
                                b.id[e]
                            ))
                            .in_file(file.clone())
                            .in_column(*c)
                            .at_row(e)
                            .expected("a finite stress in Pa, or null for 0"));
                        }
                    }
                }
            }
            if !b.area.is_empty() {
                let file = format!("elements_{}.parquet", kind.name());
                if *kind != ElementKind::Truss || b.area.len() != b.len() {
                    return Err(WeftError::input(format!(
                        "{} elements carry {} cross-section areas for {} elements",
                        kind.name(),
                        b.area.len(),
                        b.len()
                    ))
                    .in_file(file)
                    .expected("an area column on the truss table only, one per element"));
                }
                for (e, &a) in b.area.iter().enumerate() {
                    if !(a.is_finite() && a > 0.0) {
                        return Err(WeftError::input(format!(
                            "truss `{}` has cross-section area `{a}`",
                            b.id[e]
                        ))
                        .in_file(file)
                        .in_column("area")
                        .at_row(e)
                        .expected("an area > 0 in m², or null for the part's area"));
                    }
                }
            }
            if b.thickness.is_empty() {
                continue;
            }
            let npe = kind.nodes_per_element();
            let file = format!("elements_{}.parquet", kind.name());
            if !matches!(kind, ElementKind::Tri | ElementKind::Quad)
                || b.thickness.len() != npe * b.len()
            {
                return Err(WeftError::input(format!(
                    "{} elements carry {} nodal thicknesses for {} elements",
                    kind.name(),
                    b.thickness.len(),
                    b.len()
                ))
                .in_file(file)
                .expected(
                    "nodal thickness columns t1… on tri and quad tables only, one per element node",
                ));
            }
            for (k, &t) in b.thickness.iter().enumerate() {
                if !(t.is_finite() && t >= 0.0) {
                    return Err(WeftError::input(format!(
                        "{} `{}` has nodal thickness `{t}` at its node {}",
                        kind.name(),
                        b.id[k / npe],
                        k % npe + 1
                    ))
                    .in_file(file)
                    .in_column(format!("t{}", k % npe + 1))
                    .at_row(k / npe)
                    .expected("a thickness ≥ 0 in m (the element's mean > 0), or null for the part's thickness"));
                }
            }
        }
        Ok(())
    }
}

/// A stretch of the yarn through a node: the chain of trusses through it, up to `half`
/// nodes on each side (a sliding link's reach, [`crate::solver::sliding_link`]).
#[derive(Debug, Clone, PartialEq)]
pub struct YarnWindow {
    /// Node indices in chain order.
    pub nodes: Vec<usize>,
    /// The node's position in `nodes`.
    pub home: usize,
    /// Whether the first and the last node of the window end the yarn (rather than the
    /// window's reach).
    pub ends: [bool; 2],
}

impl Model {
    /// The truss neighbours of every node, in truss table order.
    pub fn truss_neighbours(&self) -> Vec<Vec<usize>> {
        let mut nb = vec![vec![]; self.coords.len()];
        if let Some(b) = self.block(ElementKind::Truss) {
            for e in 0..b.len() {
                let (a, c) = (b.nodes[2 * e], b.nodes[2 * e + 1]);
                nb[a].push(c);
                nb[c].push(a);
            }
        }
        nb
    }

    /// The window of the yarn through `node` (see [`YarnWindow`]), walking the truss
    /// neighbours `nb` ([`Model::truss_neighbours`]); why there is none otherwise: a node
    /// on no truss, a node where the trusses branch (more than two neighbours), a yarn
    /// that closes on itself within the window.
    pub fn yarn_window(
        &self,
        nb: &[Vec<usize>],
        node: usize,
        half: usize,
    ) -> std::result::Result<YarnWindow, String> {
        let id = |n: usize| self.node_id[n];
        match nb[node].len() {
            0 => return Err(format!("node `{}` is on no truss", id(node))),
            1 | 2 => {}
            k => {
                return Err(format!(
                    "node `{}` joins {k} trusses (a yarn is a chain: one or two)",
                    id(node)
                ))
            }
        }
        let mut sides = [vec![], vec![]];
        let mut ends = [true, true];
        for (side, &first) in nb[node].iter().enumerate() {
            let (mut prev, mut cur) = (node, first);
            loop {
                if cur == node || sides[side].contains(&cur) {
                    return Err(format!(
                        "the yarn through node `{}` closes on itself",
                        id(node)
                    ));
                }
                sides[side].push(cur);
                if nb[cur].len() > 2 {
                    return Err(format!(
                        "node `{}` on the yarn through node `{}` joins {} trusses (a yarn is a chain: one or two)",
                        id(cur),
                        id(node),
                        nb[cur].len()
                    ));
                }
                let next = nb[cur].iter().copied().find(|&n| n != prev);
                match next {
                    Some(n) if sides[side].len() < half => (prev, cur) = (cur, n),
                    Some(_) => {
                        ends[side] = false;
                        break;
                    }
                    None => break,
                }
            }
        }
        let [back, fwd] = sides;
        let home = back.len();
        let nodes: Vec<usize> = back
            .into_iter()
            .rev()
            .chain(std::iter::once(node))
            .chain(fwd)
            .collect();
        // A node with one neighbour ends the yarn: its side's walk never started, and
        // its `ends` entry stays true.
        Ok(YarnWindow { nodes, home, ends })
    }

    /// Sliding links: not in a frame of frame nodes as well, and each end on a yarn
    /// (a chain of trusses) other than the other end's.
    fn validate_sliding_links(&self) -> Result<()> {
        let Some(b) = self.block(ElementKind::Link) else {
            return Ok(());
        };
        let file = "elements_link.parquet";
        let mut nb = None;
        for e in 0..b.len() {
            let part = &self.parts[b.part[e]];
            if part.props.sliding != Some(true) {
                continue;
            }
            let nb = nb.get_or_insert_with(|| self.truss_neighbours());
            let (n1, n2) = (b.nodes[2 * e], b.nodes[2 * e + 1]);
            let mut windows = vec![];
            for (col, n) in [("n1", n1), ("n2", n2)] {
                match self.yarn_window(nb, n, crate::solver::sliding_link::HALF) {
                    Ok(w) => windows.push(w),
                    Err(why) => {
                        return Err(WeftError::input(format!(
                            "sliding link `{}` of part `{}`: {why}",
                            b.id[e], part.name
                        ))
                        .in_file(file)
                        .in_column(col)
                        .at_row(e)
                        .expected("each end of a sliding link on a yarn: a chain of trusses through the node")
                        .hint(format!("join the node to its yarn's trusses, or set `sliding` of part `{}` to null", part.name)));
                    }
                }
            }
            if windows[0].nodes.contains(&n2) {
                return Err(WeftError::input(format!(
                    "sliding link `{}` of part `{}` joins nodes `{}` and `{}` of the same yarn",
                    b.id[e], part.name, self.node_id[n1], self.node_id[n2]
                ))
                .in_file(file)
                .in_column("n2")
                .at_row(e)
                .expected("the two ends on two yarns that cross"));
            }
        }
        Ok(())
    }

    /// Link frame nodes: on link tables only, one set per link; every link whose part
    /// asks for `local_frame` has frame nodes that span a plane at the reference
    /// coordinates (e₁ = x_f2 − x_f1 ≠ 0, not parallel to x_f4 − x_f3).
    fn validate_link_frames(&self) -> Result<()> {
        for (kind, b) in &self.elements {
            let file = format!("elements_{}.parquet", kind.name());
            if !b.frame.is_empty() && (*kind != ElementKind::Link || b.frame.len() != b.len()) {
                return Err(WeftError::input(format!(
                    "{} elements carry {} frame-node sets for {} elements",
                    kind.name(),
                    b.frame.len(),
                    b.len()
                ))
                .in_file(file)
                .expected(
                    "frame node columns f1, f2, f3, f4 on the link table only, one set per link",
                ));
            }
        }
        let Some(b) = self.block(ElementKind::Link) else {
            return Ok(());
        };
        let file = "elements_link.parquet";
        for e in 0..b.len() {
            let part = &self.parts[b.part[e]];
            if part.props.local_frame != Some(true) {
                continue;
            }
            let Some(f) = b.frame.get(e) else {
                return Err(WeftError::input(format!(
                    "link `{}` of part `{}` asks for a local frame but the link table has no frame nodes",
                    b.id[e], part.name
                ))
                .in_file(file)
                .in_column("f1")
                .at_row(e)
                .expected("columns f1, f2, f3, f4: the nodes whose directions f2 − f1 and f4 − f3 span the crossing's plane")
                .hint("give the frame nodes, or set `local_frame` of the part to null (global axes)"));
            };
            let x = |k: usize| self.coords[f[k]];
            let sub = |a: [f64; 3], c: [f64; 3]| [c[0] - a[0], c[1] - a[1], c[2] - a[2]];
            let (u, w) = (sub(x(0), x(1)), sub(x(2), x(3)));
            let cr = [
                u[1] * w[2] - u[2] * w[1],
                u[2] * w[0] - u[0] * w[2],
                u[0] * w[1] - u[1] * w[0],
            ];
            let norm = |v: [f64; 3]| (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
            let (nu, nw, nc) = (norm(u), norm(w), norm(cr));
            if !(nu > 0.0 && nw > 0.0 && nc > 1e-6 * nu * nw) {
                return Err(WeftError::input(format!(
                    "link `{}` has frame nodes `{}`, `{}`, `{}`, `{}` whose directions f2 − f1 and f4 − f3 do not span a plane (sine of their angle {:.1e})",
                    b.id[e],
                    self.node_id[f[0]],
                    self.node_id[f[1]],
                    self.node_id[f[2]],
                    self.node_id[f[3]],
                    if nu > 0.0 && nw > 0.0 { nc / (nu * nw) } else { 0.0 }
                ))
                .in_file(file)
                .in_column("f1")
                .at_row(e)
                .expected("two non-zero, non-parallel directions (the crossing's warp and weft)"));
            }
        }
        Ok(())
    }
}

/// A value > 0 that one property needs because of another (a friction slider's
/// tangential stiffness).
fn require_pos(p: &Part, col: &str, v: Option<f64>, unit: &str) -> Result<()> {
    match v {
        Some(x) if x > 0.0 && x.is_finite() => Ok(()),
        Some(x) => Err(WeftError::input(format!(
            "part `{}` ({}) has {col} = `{x}`",
            p.name,
            p.kind.name()
        ))
        .in_column(col)
        .expected(format!("a value > 0 {unit}"))),
        None => Err(WeftError::input(format!(
            "part `{}` ({}) has no {col}",
            p.name,
            p.kind.name()
        ))
        .in_column(col)
        .expected(format!("a value > 0 {unit}"))
        .hint(format!("every {} part needs `{col}`", p.kind.name()))),
    }
}

/// Check the properties a part's kind needs: each against its rule in
/// [`props::PROPERTIES`], in table order, then the checks that involve two properties.
pub fn validate_part(p: &Part) -> Result<()> {
    for prop in props::PROPERTIES {
        prop.check(&p.name, p.kind, &p.props)?;
    }
    let q = &p.props;
    match p.kind {
        ElementKind::Link => {
            if let (Some(f), Some(mu)) = (q.slip_force, q.friction) {
                return Err(WeftError::input(format!(
                    "part `{}` (link) has both slip_force = `{f}` and friction = `{mu}`",
                    p.name
                ))
                .in_column("friction")
                .expected("one slip law: a constant slip force or Coulomb friction μ")
                .hint("leave `slip_force` null to slip at μ·N, or `friction` null to slip at a constant force"));
            }
            if q.slip_force.is_some() || q.friction.is_some() {
                for (c, v) in [("kx", q.kx), ("ky", q.ky)] {
                    require_pos(
                        p,
                        c,
                        v,
                        "in N/m (a friction slider needs tangential stiffness)",
                    )?;
                }
            }
            if q.friction.is_some() {
                require_pos(
                    p,
                    "kz",
                    q.kz,
                    "in N/m (Coulomb friction takes its normal force N from the normal spring)",
                )?;
            }
            if q.sliding == Some(true) && q.local_frame == Some(true) {
                return Err(WeftError::input(format!(
                    "part `{}` (link) has both sliding and local_frame",
                    p.name
                ))
                .in_column("sliding")
                .expected("one frame: a sliding link's own (its yarns' tangents where its ends are), or the frame nodes' of `local_frame`")
                .hint("leave `local_frame` null for sliding links"));
            }
            if q.unilateral == Some(true) && q.kz.is_none() && q.cz.is_none() {
                return Err(WeftError::input(format!(
                    "part `{}` (link) is unilateral but has no kz or cz",
                    p.name
                ))
                .in_column("unilateral")
                .expected("a normal spring `kz` (or dashpot `cz`) for the unilateral law to act on")
                .hint("give `kz`, or leave `unilateral` null"));
            }
        }
        ElementKind::Tri | ElementKind::Quad => {
            let nu = q.poisson_ratio_12.unwrap_or(0.0);
            // Both moduli are required, hence checked > 0 above.
            let (e1, e2) = (q.youngs_modulus_1.unwrap(), q.youngs_modulus_2.unwrap());
            if !(nu.is_finite() && nu * nu * e2 / e1 < 1.0 && nu > -1.0) {
                return Err(WeftError::input(format!(
                    "part `{}` has poisson_ratio_12 = `{nu}`",
                    p.name
                ))
                .in_column("poisson_ratio_12")
                .expected(format!(
                    "−1 < ν₁₂ and ν₁₂² E₂/E₁ < 1 (here E₂/E₁ = {})",
                    e2 / e1
                )));
            }
        }
        _ => {}
    }
    Ok(())
}

fn validate_analysis(a: &Analysis) -> Result<()> {
    let err = |col: &str, v: f64, exp: &str| {
        Err(WeftError::input(format!("analysis setting {col} = `{v}`"))
            .in_file("analysis.parquet")
            .in_column(col)
            .expected(exp.to_string()))
    };
    if !(a.end_time > 0.0 && a.end_time.is_finite()) {
        return err("end_time", a.end_time, "a time > 0 s");
    }
    if !(a.output_interval > 0.0 && a.output_interval <= a.end_time) {
        return err(
            "output_interval",
            a.output_interval,
            "0 < output_interval ≤ end_time (s)",
        );
    }
    if a.end_time / a.output_interval > 1e7 {
        return Err(WeftError::input(format!(
            "analysis settings end_time = `{}` s and output_interval = `{}` s give {:.3e} output samples",
            a.end_time,
            a.output_interval,
            a.end_time / a.output_interval
        ))
        .in_file("analysis.parquet")
        .in_column("output_interval")
        .expected("at most 10⁷ output samples")
        .hint("lengthen output_interval, or check end_time"));
    }
    if !(a.dt_safety > 0.0 && a.dt_safety <= 1.0) {
        return err("dt_safety", a.dt_safety, "0 < dt_safety ≤ 1");
    }
    if !(a.mass_damping >= 0.0 && a.mass_damping.is_finite()) {
        return err("mass_damping", a.mass_damping, "α ≥ 0 in 1/s");
    }
    if let Some(dt) = a.time_step {
        if !(dt > 0.0 && dt.is_finite()) {
            return err("time_step", dt, "a step > 0 s, or null for the stable step");
        }
    }
    if let Some(dt) = a.target_time_step {
        if !(dt > 0.0 && dt.is_finite()) {
            return err(
                "target_time_step",
                dt,
                "a step > 0 s, or null for no mass scaling",
            );
        }
    }
    if !(a.max_energy_error > 0.0) {
        return err("max_energy_error", a.max_energy_error, "a fraction > 0");
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sine_pulse_law() {
        let law = TimeLaw::SinePulse {
            start: 1.0,
            duration: 2.0,
        };
        assert_eq!(law.eval(0.5), 0.0);
        assert!((law.eval(2.0) - 1.0).abs() < 1e-15);
        assert_eq!(law.eval(3.5), 0.0);
    }

    #[test]
    fn curve_interpolates_and_holds() {
        let c = Curve {
            t: vec![0.0, 1.0, 3.0],
            value: vec![0.0, 2.0, 0.0],
        };
        assert_eq!(c.eval(-1.0), 0.0);
        assert_eq!(c.eval(0.5), 1.0);
        assert_eq!(c.eval(2.0), 1.0);
        assert_eq!(c.eval(5.0), 0.0);
    }
}
