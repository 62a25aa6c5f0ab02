//! Solid elements: the eight-node hexahedron with one-point integration and
//! Flanagan–Belytschko hourglass control, and the metal materials it carries.
//!
//! - [`hex`]: the element family (the solver's phases, energies, stable step);
//! - [`kernel`]: geometry (exact volume, the mean-strain gradient operator), velocity
//!   gradient, objective rotation of the stress, hourglass shape vectors and forces,
//!   bulk viscosity;
//! - [`material`]: isotropic elasticity, J2 plasticity with isotropic hardening
//!   (bilinear or tabulated) by radial return, Johnson–Cook with adiabatic heating.

pub mod hex;
pub mod kernel;
pub mod material;
