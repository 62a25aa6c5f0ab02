//! Contact definitions (`contacts.parquet`): which nodes meet which surface, with what
//! friction and penalty. One row per definition; see `docs/tables.md`.
//!
//! A definition pairs slave nodes — the nodes of a part (`slave_part`) or a node set
//! (`slave_set`) — with the master surface of a part (`master_part`): the faces of a
//! membrane part (triangles, quads) offset by ± half the nodal thickness, the
//! segments of a truss or beam part with a radius, or the boundary faces of a
//! hexahedron part (one-sided: a node behind one is pushed back out of the solid; a
//! solid's slaves are its boundary nodes). `two_way` also checks the master part's nodes
//! against the slave part's surface; a part against itself is self-contact (a node never
//! meets the faces it belongs to), except for a solid, which is refused.
//!
//! The table's codec is `io::contacts`; its checks are part of [`super::Model::validate`].

use super::kinds::ElementKind;

/// What to do with a slave node that starts inside the surface.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum InitialPenetration {
    /// Remember the depth and push only beyond it (the offset shrinks as the node leaves;
    /// LS-DYNA's IGNORE = 1): the node is reported, not launched.
    Track,
    /// Stop with an error naming the node.
    Error,
    /// The penalty acts from the start with the full depth: a formed state whose contact
    /// forces are part of its equilibrium (`weft-form` writes this).
    Keep,
}

impl InitialPenetration {
    pub fn name(self) -> &'static str {
        match self {
            InitialPenetration::Track => "track",
            InitialPenetration::Error => "error",
            InitialPenetration::Keep => "keep",
        }
    }
}

/// The slave side of a contact.
#[derive(Debug, Clone, PartialEq)]
pub enum Slave {
    /// The nodes of a part's elements (index into `Model::parts`).
    Part(usize),
    /// A node set.
    Set(String),
}

/// One contact definition.
#[derive(Debug, Clone, PartialEq)]
pub struct ContactDef {
    pub id: i64,
    pub slave: Slave,
    /// Part whose faces or segments form the surface (index into `Model::parts`).
    pub master: usize,
    /// Static and dynamic Coulomb coefficients μ_s, μ_d (≥ 0).
    pub static_friction: f64,
    pub dynamic_friction: f64,
    /// Exponential decay coefficient d_c [s/m]: μ = μ_d + (μ_s − μ_d) e^{−d_c |v_t|}.
    pub friction_decay: f64,
    /// Multiplies the penalty factor κ_c = 0.1 of k = κ_c m*/Δt².
    pub penalty_scale: f64,
    /// Contact thickness of the slave nodes [m] (None: from their elements).
    pub slave_thickness: Option<f64>,
    /// Contact thickness of the surface [m] (None: from its elements).
    pub master_thickness: Option<f64>,
    /// Also the master part's nodes against the slave part's surface.
    pub two_way: bool,
    pub initial_penetration: InitialPenetration,
}

impl ContactDef {
    /// A one-way, frictionless definition with the default penalty.
    pub fn new(id: i64, slave: Slave, master: usize) -> ContactDef {
        ContactDef {
            id,
            slave,
            master,
            static_friction: 0.0,
            dynamic_friction: 0.0,
            friction_decay: 0.0,
            penalty_scale: 1.0,
            slave_thickness: None,
            master_thickness: None,
            two_way: false,
            initial_penetration: InitialPenetration::Track,
        }
    }
    /// Coulomb friction with one coefficient.
    pub fn with_friction(mut self, mu: f64) -> ContactDef {
        self.static_friction = mu;
        self.dynamic_friction = mu;
        self
    }
}

/// Part kinds that can form a contact surface (a hexahedron part by its boundary faces).
pub fn is_surface_kind(k: ElementKind) -> bool {
    matches!(
        k,
        ElementKind::Tri
            | ElementKind::Quad
            | ElementKind::Truss
            | ElementKind::Beam
            | ElementKind::Hex
    )
}

/// Names, each in backticks, comma-separated (for messages that list the choices).
pub(super) fn names<'a>(it: impl Iterator<Item = &'a String>) -> String {
    it.map(|k| format!("`{k}`")).collect::<Vec<_>>().join(", ")
}
