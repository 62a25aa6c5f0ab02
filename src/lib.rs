//! weft: finite-element models of woven fabrics under impact, at two resolutions,
//! coupled; an explicit solver, model generators, and stages that pass Parquet tables.
//!
//! Layout: [`model`] (the model and its folder of tables), [`solver`] (explicit central
//! difference, element kernels, output sinks), [`simulate`] (the stage behind
//! `weft-simulate`), [`generate`] (canonical models behind `weft-weave`), [`plot`]
//! (the figures behind `weft-plot`), [`vtk`] (ParaView time series behind `weft-vtk`), [`export`] (CalculiX and LS-DYNA decks behind `weft-export`), [`surrogate`] (regression and network surrogates behind `weft-surrogate`), [`table`]
//! (validated Parquet I/O with provenance), [`error`] (typed errors), [`cli`] (what the
//! stage binaries share: `main`, error printing, progress).

pub mod analysis;
pub mod ballistic;
pub mod cli;
pub mod element_results;
pub mod error;
pub mod export;
pub mod fit;
pub mod form;
pub mod generate;
pub mod material;
pub mod model;
pub mod pipeline;
pub mod plot;
pub mod random;
pub mod shape;
pub mod simulate;
pub mod solver;
pub mod surrogate;
pub mod table;
pub mod vec3;
pub mod vtk;

pub use error::{Result, WeftError};
