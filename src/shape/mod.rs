//! Element shapes: node order, faces and exact geometry, one file per shape, below both
//! the model (whose checks refuse inverted elements) and the solver (whose element
//! families and contact surfaces are built on them).
//!
//! - [`hex8`]: the eight-node trilinear hexahedron.

pub mod hex8;
