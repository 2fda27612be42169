//! What the system does, uncontrolled, at one state: `Φ`, `Φ_q`, `γ`, the
//! multipliers `λ` and the accelerations `A` ([`Dynamics`]) with the
//! products and solves that reuse them, the energy
//! constraint `Ψ` ([`energy`]), the violations a sample reports
//! ([`diagnostics`]), the momenta it keeps ([`momentum`]), and the Newton
//! projections onto the constraint manifold shared by assembly
//! ([`assemble`]) and the exact projection.
//!
//! May import: `error`, `ad`, `linalg`, `model`, `random`.

pub mod assemble;
pub mod diagnostics;
pub mod energy;
pub(crate) mod manifold;
pub mod momentum;
mod products;
mod solver;
mod uncontrolled;

pub use solver::BLOCKS_FROM;
pub use uncontrolled::*;
