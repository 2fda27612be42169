//! `S = Φ_q M⁻¹ Φ_qᵀ` assembled by its caller (block masses: spatial
//! bodies) and factored in a [`Band`] or by the column kernel of
//! [`Schur`], whichever the pattern and the handling of dependent rows
//! call for.
//!
//! May import: `linalg`'s other files.

use super::band::{Band, MAX_WIDTH};
use super::ldl::{Breakdown, DependentRows};
use super::schur::{LinearSolver, Schur, products};
use super::sparse::Pattern;

/// How `S` of a block mass is factored: in a [`Band`] where `Auto` finds
/// one at most [`MAX_WIDTH`] wide and with at most [`BAND_WIDER`] times
/// the entries of the sparse factor (chains, arms: every entry costs less
/// there), else by the column kernel of [`Schur`]. Both are kept: `S` is
/// assembled in the column kernel's slots (and one zero after them), which
/// the band reads through `map`, and with dependent rows tolerated the
/// column kernel factors, so that the same rows are dropped as without a
/// band (its order is another: the Bricard mechanism then dropped a row
/// whose loss made the projection's position step move `Ψ` by 5e-6).
#[derive(Clone)]
pub(crate) struct AssembledSchur {
    columns: Schur,
    band: Option<(Band, Vec<u32>)>,
    /// Whether the band factors (it exists and no dependent row is tolerated).
    banded: bool,
}

/// How many times the sparse factor's entries a band may hold and still be chosen.
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
            // Every band slot reads the column kernel's slot of its entry,
            // or the zero after them.
            let zero = columns.slots() as u32;
            let mut map = vec![zero; band.slots()];
            let (to, from) = (band.slot_finder(), columns.slot_finder());
            for r in 0..m {
                map[to(r, r)] = from(r, r) as u32;
            }
            for (a, b) in pairs().filter(|(a, b)| a != b) {
                map[to(a, b)] = from(a, b) as u32;
            }
            drop((to, from));
            (band, map)
        });
        Self { banded: band.is_some(), columns, band }
    }

    /// Whether the band factors.
    #[cfg(test)]
    pub(crate) fn banded(&self) -> bool {
        self.banded
    }

    /// `S`'s entries by slot, and one zero after them.
    pub(crate) fn slots(&self) -> usize {
        self.columns.slots() + 1
    }

    pub(crate) fn slot_finder(&self) -> impl Fn(usize, usize) -> usize + '_ {
        self.columns.slot_finder()
    }

    pub(crate) fn factor_and_solve_assembled(&mut self, entries: &[f64], b: &mut [f64]) -> Result<(), Breakdown> {
        match &mut self.band {
            Some((band, map)) if self.banded => band.factor_and_solve_mapped(entries, map, b),
            _ => self.columns.factor_and_solve_assembled(&entries[..self.columns.slots()], b),
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

    pub(crate) fn set_dependent_rows(&mut self, dependent: DependentRows) {
        self.columns.set_dependent_rows(dependent);
        if let Some((band, _)) = &mut self.band {
            band.set_dependent_rows(dependent);
        }
        self.banded = self.band.is_some() && dependent == DependentRows::Error;
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
            Some((band, _)) if self.banded => {
                let m = band.slots() - band.entries();
                band.entries() < m * m.saturating_sub(1) / 2
            }
            _ => self.columns.is_sparse(),
        }
    }
}
