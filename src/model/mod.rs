//! The model: nodes, parts, elements by kind, node sets, constraints, loads with time
//! laws, initial velocities and analysis settings, all in SI units.
//!
//! A model lives on disk as a folder of Parquet tables (see [`io`] and
//! `docs/tables.md`); in memory, elements refer to nodes and parts by index. Generators
//! build models with [`Model`]'s `add_*` methods; [`Model::validate`] checks every
//! property and reference and names the offending part, element, node or row.
//!
//! The modules: [`kinds`] (the element kinds), [`props`] (part properties, each defined
//! once), [`types`] (what a model is made of, and [`Model`] with its builders),
//! [`contacts`] (contact definitions), [`yarn`] (chains of trusses, the sliding links'
//! windows), [`validate`] (the checks) and [`io`] (one codec per table). This module only
//! declares them and re-exports their public items; none of them imports from it.

pub mod contacts;
pub mod io;
pub mod kinds;
pub mod props;
pub mod striker;
pub mod types;
pub mod validate;
mod validate_contacts;
mod validate_parts;
pub mod yarn;

pub use kinds::ElementKind;
pub use props::PartProps;
pub use types::{
    Analysis, Curve, ElementBlock, Load, Model, Part, ProjectileShape, ProjectileSpec,
    SymmetryPlane, Tie, TimeLaw,
};
pub use validate::ValidatedModel;
pub use validate_parts::validate_part;
pub use yarn::YarnWindow;
