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
pub mod types;
pub mod validate;
pub mod yarn;

pub use kinds::ElementKind;
pub use props::PartProps;
pub use types::{
    Analysis, Curve, ElementBlock, Load, Model, Part, ProjectileShape, ProjectileSpec,
    SymmetryPlane, Tie, TimeLaw,
};
pub use validate::validate_part;
pub use yarn::YarnWindow;
