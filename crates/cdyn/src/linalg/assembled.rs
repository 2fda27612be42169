//! `S = Φ_q M⁻¹ Φ_qᵀ` assembled by its caller (block masses: spatial
//! bodies) and factored in a [`Band`] or by the column kernel of
//! [`Schur`], whichever the pattern and the handling of dependent rows
//! call for.
//!
//! May import: `linalg`'s other files.

use super::band::{Band, MAX_WIDTH};
use super::ldl::{Breakdown, DependentRows};
use super::schur::{LinearSolver, Schur, below_triangle, products};
use super::sparse::Pattern;

/// How `S` of a block mass is factored: in a [`Band`] where `Auto` finds
/// one at most [`MAX_WIDTH`] wide and with at most [`BAND_WIDER`] times
/// the entries of the sparse factor (chains, arms: every entry costs less
/// there), else by the column kernel of [`Schur`]. With dependent rows
/// tolerated the column kernel factors, so that the same rows are dropped
/// as without a band (the band's order is another: the Bricard mechanism
/// then dropped a row whose loss made the projection's position step move
/// `Ψ` by 5e-6). Both are kept; `S` is assembled in the slots of the one
/// that factors, and [`set_dependent_rows`](Self::set_dependent_rows)
/// says how to move the assembly's slots when that changes.
#[derive(Clone)]
pub(crate) struct AssembledSchur {
    columns: Schur,
    /// The band, and the band's slot of each of the column kernel's.
    band: Option<(Band, Vec<u32>)>,
    /// Whether the band factors (it exists and no dependent row is tolerated).
    banded: bool,
}

/// How many times the sparse factor's entries a band may hold and still be
/// chosen. Panda's tree has a band of 16 with 2.1 times: there the band
/// took 176.8 k instructions an AB-3 step against the column kernel's 140.1 k.
const BAND_WIDER: usize = 2;

impl AssembledSchur {
    pub(crate) fn new(pattern: &Pattern, n: usize, solver: LinearSolver) -> Self {
        let columns = Schur::assembled_by_caller(pattern, n, solver);
        let m = pattern.start.len() - 1;
        let pairs = || products(pattern, n).into_iter().map(|(a, b, ..)| (a, b));
        let band = (solver == LinearSolver::Auto && m > 0)
            .then(|| Band::new(m, pairs()))
            .filter(|band| band.width() <= MAX_WIDTH && band.entries() <= BAND_WIDER * (columns.slots() - m));
        let band = band.map(|band| {
            // Every entry of `S` the caller assembles, in both layouts; the
            // column kernel's fill is never assembled.
            let mut to_band = vec![0; columns.slots()];
            let (to, from) = (band.slot_finder(), columns.slot_finder());
            for (a, b) in (0..m).map(|r| (r, r)).chain(pairs()) {
                to_band[from(a, b)] = to(a, b) as u32;
            }
            drop((to, from));
            (band, to_band)
        });
        Self { banded: band.is_some(), columns, band }
    }

    /// Whether the band factors.
    #[cfg(test)]
    pub(crate) fn banded(&self) -> bool {
        self.banded
    }

    /// Entries of `S` the factorization reads, by slot.
    pub(crate) fn slots(&self) -> usize {
        match &self.band {
            Some((band, _)) if self.banded => band.slots(),
            _ => self.columns.slots(),
        }
    }

    /// The slot of `S`'s entry `(a, b)` (original rows).
    pub(crate) fn slot_finder(&self) -> Box<dyn Fn(usize, usize) -> usize + '_> {
        match &self.band {
            Some((band, _)) if self.banded => Box::new(band.slot_finder()),
            _ => Box::new(self.columns.slot_finder()),
        }
    }

    pub(crate) fn factor_and_solve_assembled(&mut self, entries: &[f64], b: &mut [f64]) -> Result<(), Breakdown> {
        match &mut self.band {
            Some((band, _)) if self.banded => band.factor_and_solve_assembled(entries, b),
            _ => self.columns.factor_and_solve_assembled(entries, b),
        }
    }

    pub(crate) fn solve(&self, b: &mut [f64]) {
        self.solve_many(&mut [b]);
    }

    pub(crate) fn solve_many(&self, bs: &mut [&mut [f64]]) {
        match &self.band {
            Some((band, _)) if self.banded => band.solve_many(bs),
            _ => self.columns.solve_many(bs),
        }
    }

    /// Sets what a dependent row does in the next factorizations. Where
    /// that changes which kernel factors, returns the new slot of each old
    /// one the caller assembles (others map to 0), to be applied before the
    /// next factorization, with [`slots`](Self::slots) entries from then on.
    #[must_use]
    pub(crate) fn set_dependent_rows(&mut self, dependent: DependentRows) -> Option<Vec<u32>> {
        self.columns.set_dependent_rows(dependent);
        let Some((band, to_band)) = &mut self.band else { return None };
        band.set_dependent_rows(dependent);
        let banded = dependent == DependentRows::Error;
        if banded == self.banded {
            return None;
        }
        self.banded = banded;
        Some(if banded {
            to_band.clone()
        } else {
            let mut to_columns = vec![0; band.slots()];
            to_band.iter().enumerate().for_each(|(column, &slot)| to_columns[slot as usize] = column as u32);
            to_columns
        })
    }

    pub(crate) fn dependent_rows(&self) -> usize {
        match &self.band {
            Some((band, _)) if self.banded => band.dependent_rows(),
            _ => self.columns.dependent_rows(),
        }
    }

    /// Whether `L` has fewer entries than the full triangle.
    pub(crate) fn is_sparse(&self) -> bool {
        match &self.band {
            Some((band, _)) if self.banded => below_triangle(band.entries(), band.slots() - band.entries()),
            _ => self.columns.is_sparse(),
        }
    }
}
