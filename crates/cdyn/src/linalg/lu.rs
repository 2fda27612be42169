//! The Newton matrix's LU: dense where the pattern fills a sixth of the
//! matrix or more, sparse otherwise. A sparse LU's analysis and index
//! bookkeeping cost more than the arithmetic of the zeros it skips until
//! the pattern is thin: generalized-α without control, µs per step, faer's
//! sparse LU against [`DenseLu`] (best of 5 runs of 2 000 steps):
//!
//! | model | unknowns | pattern's share | sparse | dense |
//! |---|---|---|---|---|
//! | planar chain, 10 links | 30 | 0.22 | 7.2 | 4.4 |
//! | planar chain, 13 links | 39 | 0.17 | 6.3 | 6.6 |
//! | planar chain, 16 links | 48 | 0.14 | 11.6 | 13.2 |
//! | spatial chain, 6 bodies | 66 | 0.30 | 36.8 | 21.5 |
//! | spatial chain, 10 bodies | 110 | 0.19 | 59.4 | 57.3 |
//! | spatial chain, 12 bodies | 132 | 0.16 | 74.7 | 83.2 |
//!
//! Both kinds cross over near a share of 0.18, where the rule sits.

use super::dense_lu::DenseLu;
use super::sparse_lu::{Singular, SparseLu};

/// The share of a pattern's entries from which it is factored densely.
const DENSE_FROM: f64 = 0.18;

/// A square system with a fixed pattern, factored many times.
#[derive(Clone)]
pub(crate) enum Lu {
    Dense(DenseLu),
    /// Boxed: its analysis is some hundreds of bytes, the dense kernel's a few vectors.
    Sparse(Box<SparseLu>),
}

impl Lu {
    /// The `dim × dim` pattern with these entries (repeats add; list every
    /// diagonal entry, even a structural zero, for the sparse pivoting).
    pub(crate) fn new(dim: usize, entries: &[(u32, u32)]) -> Self {
        let mut distinct = entries.to_vec();
        distinct.sort_unstable();
        distinct.dedup();
        if distinct.len() as f64 >= DENSE_FROM * (dim * dim) as f64 {
            Self::Dense(DenseLu::new(dim, entries))
        } else {
            Self::Sparse(Box::new(SparseLu::new(dim, entries)))
        }
    }

    /// Sizes the sparse factors' storage by factoring `values` once (see [`SparseLu::reserve`]).
    pub(crate) fn reserve(&mut self, values: &[f64]) {
        if let Self::Sparse(lu) = self {
            lu.reserve(values);
        }
    }

    /// Factors the matrix whose listed entries have `values`.
    pub(crate) fn factor(&mut self, values: &[f64]) -> Result<(), Singular> {
        match self {
            Self::Dense(lu) => lu.factor(values),
            Self::Sparse(lu) => lu.factor(values),
        }
    }

    /// Solves in place with the last factorization.
    pub(crate) fn solve(&mut self, rhs: &mut [f64]) {
        match self {
            Self::Dense(lu) => lu.solve(rhs),
            Self::Sparse(lu) => lu.solve(rhs),
        }
    }
}
