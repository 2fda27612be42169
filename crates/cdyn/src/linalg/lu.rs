//! The Newton matrix's LU: in dense storage up to `DENSE_UP_TO` unknowns
//! (or where the pattern fills a sixth of the matrix or more), by faer's
//! sparse LU beyond. The dense kernel eliminates along the pattern of its
//! factors, in an order that keeps them sparse ([`DenseLu`]), so it skips
//! what a sparse LU skips without that LU's analysis and index
//! bookkeeping; its dense matrix holds `dim²` values (2.9 MB at 600
//! unknowns), which the cap bounds. Generalized-α without control, h =
//! 1e-3, µs per step (best of 5 runs of 2 000 steps, 2026-12-07, while the
//! dense kernel still cleared the whole matrix at every factorization; it
//! now clears the factors' pattern only: the planar chain of 200 links
//! 61 µs):
//!
//! | model | unknowns | dense | sparse |
//! |---|---|---|---|
//! | planar chain, 10 links | 30 | 4.2 | 7.3 |
//! | planar chain, 50 links | 150 | 15.3 | 25.6 |
//! | planar chain, 100 links | 300 | 35.4 | 51.0 |
//! | planar chain, 200 links | 600 | 86.3 | 155.3 |
//! | planar chain, 300 links | 900 | 178.8 | 164.0 |
//! | spatial chain, 6 bodies | 66 | 20.0 | 37.8 |
//! | spatial chain, 50 bodies | 550 | 148.1 | 326.9 |
//! | spatial chain, 100 bodies | 1 100 | 404.0 | 680.3 |
//!
//! (Before the dense kernel eliminated along the pattern, with partial
//! pivoting over whole rows, the two crossed over near a share of 0.18:
//! the spatial chain of 12 bodies, 132 unknowns, 83.2 against 74.7 µs.)

use super::dense_lu::DenseLu;
use super::sparse_lu::{Singular, SparseLu};

/// The most unknowns factored in dense storage, whatever the pattern.
const DENSE_UP_TO: usize = 600;

/// The share of a pattern's entries from which it is factored densely.
const DENSE_FROM: f64 = 0.18;

/// A square system with a fixed pattern, factored many times.
#[derive(Clone)]
pub(crate) enum Lu {
    /// Both boxed: each holds some hundreds of bytes besides its buffers.
    Dense(Box<DenseLu>),
    Sparse(Box<SparseLu>),
}

impl Lu {
    /// The `dim × dim` pattern with these entries (repeats add; list every
    /// diagonal entry, even a structural zero, for the sparse pivoting).
    /// The first `leading` unknowns are those of a positive definite block
    /// (the coordinates', see [`DenseLu::new`]).
    pub(crate) fn new(dim: usize, leading: usize, entries: &[(u32, u32)]) -> Self {
        let share = || {
            let mut distinct = entries.to_vec();
            distinct.sort_unstable();
            distinct.dedup();
            distinct.len() as f64 / (dim * dim) as f64
        };
        if dim <= DENSE_UP_TO || share() >= DENSE_FROM {
            Self::Dense(Box::new(DenseLu::new(dim, leading, entries)))
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
