//! Automatic differentiation: the scalar type users write physics in, and
//! the dual number that yields an element's whole Jacobian in one pass.
//! Jacobians, `γ`, mass matrices and energy gradients all come from here.
//!
//! May import: nothing of the crate.

pub(crate) mod jet;
pub mod scalar;
