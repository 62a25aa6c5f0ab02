//! Solid elements: the eight-node hexahedron with one-point integration and
//! Flanagan–Belytschko hourglass control.
//!
//! - [`hex`]: the element family (the solver's phases, energies, stable step);
//! - [`kernel`]: velocity gradient, objective rotation of the stress, hourglass shape
//!   vectors and forces, bulk viscosity; the geometry (exact volume, the mean-strain
//!   gradient operator) is the shape's, [`crate::shape::hex8`];
//! - [`selective`]: the selective-reduced (B̄, eight-point) element, hourglass-free,
//!   for parts whose `solid_formulation` is `selective_reduced`;
//! - [`slow`]: the slow elements of a subcycled run ([`crate::solver::subcycle`]);
//! - the material laws the element carries are [`crate::material`]'s.

pub mod hex;
pub mod kernel;
pub mod selective;
pub mod slow;
