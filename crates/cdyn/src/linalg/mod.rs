//! Linear algebra: the mass matrix `M` and every product with it
//! ([`mass`]), the `m × m` system `S = Φ_q M⁻¹ Φ_qᵀ` with its `L D Lᵀ`
//! factorization (`schur`), and the symbolic analysis of a sparse `S`
//! (`sparse`, done once per model).
//!
//! May import: `error`.

pub mod mass;
mod schur;
pub(crate) mod sparse;

pub use schur::{Breakdown, DependentRows, LinearSolver, SPARSE_FROM};
pub(crate) use schur::{DenseLdl, Schur, dot, inverse_pivot, norm};
