//! Linear algebra: the mass matrix `M` and every product with it
//! ([`mass`]), the `m × m` system `S = Φ_q M⁻¹ Φ_qᵀ` with its `L D Lᵀ`
//! factorization (`schur`; its pivot test and the dense factorization in
//! `ldl`; in a band, `band`; the choice between them for an `S` its caller
//! assembles, `assembled`), and the symbolic analysis of a sparse `S`
//! (`sparse`, done once per model); the LU of an implicit step's Newton
//! matrix (`lu`: in dense storage along its factors' pattern, `dense_lu`,
//! or by faer's sparse LU, `sparse_lu`).
//!
//! May import: `error`.

mod assembled;
mod band;
mod dense_lu;
mod ldl;
pub(crate) mod lu;
pub mod mass;
mod schur;
pub(crate) mod sparse;
pub(crate) mod sparse_lu;

pub(crate) use assembled::AssembledSchur;
pub use ldl::{Breakdown, DependentRows};
pub(crate) use ldl::{DenseLdl, inverse_pivot};
pub use schur::{LinearSolver, SPARSE_FROM};
pub(crate) use schur::{Schur, dot, norm, products};
