//! What a model is made of: its parts, element blocks, loads with their time laws,
//! projectiles, symmetry planes, ties and analysis settings, and the [`Model`] that holds
//! them, with the `add_*` methods generators build it with and the queries the rest of
//! the crate reads it by.

use std::collections::{BTreeMap, HashMap};
use std::sync::Arc;

use super::contacts::ContactDef;
use super::kinds::ElementKind;
use super::props::PartProps;

/// A part (`parts.parquet`): a named group of elements of one kind that share their
/// properties.
#[derive(Debug, Clone, PartialEq)]
pub struct Part {
    pub id: i64,
    pub name: String,
    pub kind: ElementKind,
    pub props: PartProps,
}

impl Part {
    /// The material of a solid part: E, ν, ρ, the law its `material` column names or
    /// its columns select, and its erosion ([`Material::of_part`]); an error names the
    /// part.
    pub fn material(&self) -> crate::error::Result<crate::material::Material> {
        crate::material::Material::of_part(&self.name, self.props.material.as_deref(), &self.props)
    }

    /// Whether a solid part's hexahedra are selective-reduced (its `solid_formulation`:
    /// null or `one_point`: no; `selective_reduced`: yes); another name is an error
    /// naming the part and the column.
    pub fn selective_reduced(&self) -> crate::error::Result<bool> {
        match self.props.solid_formulation.as_deref() {
            None | Some("one_point") => Ok(false),
            Some("selective_reduced") => Ok(true),
            Some(other) => Err(crate::error::WeftError::input(format!(
                "part `{}` (hex): solid_formulation `{other}`",
                self.name
            ))
            .in_file("parts.parquet")
            .in_column("solid_formulation")
            .expected("`one_point` or `selective_reduced`")
            .hint("see docs/tables.md, parts.parquet")),
        }
    }
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
    /// Elements that can fail: the factor on their part's failure strain (or force, or
    /// opening) [-], one per element (statistical strengths drawn by a generator);
    /// empty when every element has its part's.
    pub failure_factor: Vec<f64>,
    /// The layer of a fabric each element belongs to (1 = the strike face), one per
    /// element (null: none); empty when the table has no `layer` column.
    pub layer: Vec<Option<i64>>,
    /// The yarn each element belongs to within its part, one per element (null: none);
    /// empty when the table has no `yarn` column.
    pub yarn: Vec<Option<i64>>,
}

impl ElementBlock {
    pub fn len(&self) -> usize {
        self.id.len()
    }
    pub fn is_empty(&self) -> bool {
        self.id.is_empty()
    }
    /// The factor on element `e`'s failure strain (1 when the block has none).
    pub fn failure_factor(&self, e: usize) -> f64 {
        self.failure_factor.get(e).copied().unwrap_or(1.0)
    }
    /// The layer of element `e`, when the block has one for it.
    pub fn layer_of(&self, e: usize) -> Option<i64> {
        self.layer.get(e).copied().flatten()
    }
    /// The yarn of element `e` within its part, when the block has one for it.
    pub fn yarn_of(&self, e: usize) -> Option<i64> {
        self.yarn.get(e).copied().flatten()
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
    /// A rigid plane through the tip, normal to the axis, without bounds: the half-space
    /// behind it is inside (the Taylor test's wall: prescribed, at rest).
    Wall,
}

impl ProjectileShape {
    pub fn name(self) -> &'static str {
        match self {
            ProjectileShape::Sphere => "sphere",
            ProjectileShape::Flat => "flat",
            ProjectileShape::Round => "round",
            ProjectileShape::Wall => "wall",
        }
    }
    pub fn parse(s: &str) -> Option<Self> {
        [
            ProjectileShape::Sphere,
            ProjectileShape::Flat,
            ProjectileShape::Round,
            ProjectileShape::Wall,
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
    /// Normal viscous damping of the penalty contact, as a fraction ζ of the critical
    /// damping 2√(k m) of each node's contact spring (LS-DYNA's VDC; 0: none).
    pub contact_damping: f64,
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
    /// End the run once the projectile's outcome is decided (arrested, or perforated and
    /// free of the fabric), at that output sample, instead of at `end_time`: what a
    /// ballistic-limit sweep needs (docs/theory.md, "Failure, perforation and the
    /// ballistic limit"). Default false: the run goes to its end time.
    pub stop_on_outcome: bool,
    /// Let the step follow the solids as they are crushed (LS-DYNA's default for solids):
    /// each step the hexahedra's stable rows are taken at their current shape and the
    /// step is lowered to keep the same margin as the first (it never grows back). The
    /// contact penalties keep the first step's stiffness (so their ωΔt only falls).
    /// Default false: one step for the whole run, and a crushed solid stops it, named.
    pub variable_time_step: bool,
    /// Subcycle the solids whose stable step is many times the step (docs/theory.md,
    /// "Subcycling"): they are updated every `ratio` steps, their forces the impulse of
    /// that slow step (a clay block under a yarn-level pack: its cells' step is hundreds
    /// of the yarns'). Default false: every element every step.
    pub subcycle: bool,
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
            stop_on_outcome: false,
            variable_time_step: false,
            subcycle: false,
        }
    }
}

/// A whole model in memory: elements refer to nodes and parts by index.
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
    pub contacts: Vec<ContactDef>,
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
        if !b.failure_factor.is_empty() {
            b.failure_factor.push(1.0);
        }
        if !b.layer.is_empty() {
            b.layer.push(None);
        }
        if !b.yarn.is_empty() {
            b.yarn.push(None);
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
