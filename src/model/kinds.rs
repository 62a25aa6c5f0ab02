//! The element kinds: the families of elements the solver knows, by the names the
//! tables give them. A module of its own because every other part of the model, the
//! part properties included, names them.

/// Element families known to the solver. The string form is the `kind` column of
/// `parts.parquet` and the suffix of `elements_<kind>.parquet`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum ElementKind {
    /// Two-node corotational truss (rod), optionally tension-only.
    Truss,
    /// Two-node discrete link: spring and dashpot per global axis, optional friction
    /// slider in the global x–y plane.
    Link,
    /// One-node point mass.
    PointMass,
    /// Three-node constant-strain membrane triangle.
    Tri,
    /// Four-node one-point membrane quadrilateral with hourglass control.
    Quad,
    /// Two-node 3-D corotational beam with a rectangular section (rigid joints).
    Beam,
    /// Eight-node hexahedron (solid) with one-point integration and Flanagan–Belytschko
    /// hourglass control; isotropic elastic, J2 or Johnson–Cook material.
    Hex,
}

impl ElementKind {
    pub const ALL: [ElementKind; 7] = [
        ElementKind::Truss,
        ElementKind::Link,
        ElementKind::PointMass,
        ElementKind::Tri,
        ElementKind::Quad,
        ElementKind::Beam,
        ElementKind::Hex,
    ];
    pub fn name(self) -> &'static str {
        match self {
            ElementKind::Truss => "truss",
            ElementKind::Link => "link",
            ElementKind::PointMass => "point_mass",
            ElementKind::Tri => "tri",
            ElementKind::Quad => "quad",
            ElementKind::Beam => "beam",
            ElementKind::Hex => "hex",
        }
    }
    pub fn nodes_per_element(self) -> usize {
        match self {
            ElementKind::Truss | ElementKind::Link | ElementKind::Beam => 2,
            ElementKind::PointMass => 1,
            ElementKind::Tri => 3,
            ElementKind::Quad => 4,
            ElementKind::Hex => 8,
        }
    }
    pub fn parse(s: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|k| k.name() == s)
    }
}
