//! What a system is: coordinates with a mass matrix, and the small local
//! elements physics is written in — holonomic constraints, nonholonomic
//! constraints, potentials and forces, kinetic energies, unit vectors,
//! functions of time, inputs set from outside, and the invariants a user declares (momenta, angular
//! momenta, first integrals) — gathered into a [`Model`] by its builder.
//!
//! May import: `error`, `ad`, `linalg`.

pub mod angular;
mod builder;
pub mod constraint;
mod declare;
mod definition;
mod dissipation;
pub mod force;
pub mod input;
pub mod invariant;
pub mod kinetic;
pub mod nonholonomic;
pub mod timefn;
pub mod unit_vector;

pub use builder::*;
pub use definition::*;
