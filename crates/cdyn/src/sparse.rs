//! Sparse Cholesky of `S = Φ_q M⁻¹ Φ_qᵀ` for large systems (faer): the
//! pattern of `S` and its fill-reducing (AMD) symbolic factorization are
//! computed once; each step only refills the values, refactors numerically
//! and solves, in buffers allocated here.

use crate::linalg::{Breakdown, PIVOT_TOLERANCE, products};
use crate::model::Pattern;
use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::cholesky::llt::factor::LltRegularization;
use faer::linalg::solvers::LltError;
use faer::sparse::linalg::SupernodalThreshold;
use faer::sparse::linalg::cholesky::{
    CholeskySymbolicParams, SymbolicCholesky, SymbolicCholeskyRaw, SymmetricOrdering, factorize_symbolic_cholesky,
};
use faer::sparse::{SparseColMatRef, SymbolicSparseColMatRef};
use faer::{Conj, MatMut, Par, Side};
use std::cell::RefCell;

pub(crate) struct SparseSchur {
    m: usize,
    /// Upper triangle of `S` in compressed columns.
    col_ptr: Vec<usize>,
    row_idx: Vec<usize>,
    values: Vec<f64>,
    /// `(slot in values, ja, jb, col)` for every product `J_a J_b / m_col`.
    terms: Vec<(usize, usize, usize, usize)>,
    diag_slot: Vec<usize>,
    symbolic: SymbolicCholesky<usize>,
    /// Position of `L_jj` in the factor's values, per column `j`.
    l_diag: Vec<usize>,
    l_values: Vec<f64>,
    stack: RefCell<MemBuffer>,
}

impl SparseSchur {
    pub fn new(pattern: &Pattern, n: usize) -> Self {
        let m = pattern.start.len() - 1;
        let mut products = products(pattern, n);
        // Upper triangle by columns (entry (b, a), b ≤ a, in column a): the
        // layout faer's simplicial factorization works in, so an unpermuted
        // factorization reads it as it is.
        products.sort_by_key(|&(a, b, ..)| (a, b));
        let (mut col_ptr, mut row_idx, mut terms) = (vec![0; m + 1], Vec::new(), Vec::new());
        let mut last = None;
        for &(a, b, ja, jb, col) in &products {
            if last != Some((a, b)) {
                row_idx.push(b);
                col_ptr[a + 1] += 1;
                last = Some((a, b));
            }
            terms.push((row_idx.len() - 1, ja, jb, col));
        }
        for j in 0..m {
            col_ptr[j + 1] += col_ptr[j];
        }
        let diag_slot = (0..m).map(|j| col_ptr[j + 1] - 1).collect::<Vec<_>>();
        let structure = SymbolicSparseColMatRef::new_checked(m, m, &col_ptr, None, &row_idx);
        let params = CholeskySymbolicParams {
            // Simplicial: chains and trees have narrow fronts, and its factor's layout is plain CSC.
            supernodal_flop_ratio_threshold: SupernodalThreshold::FORCE_SIMPLICIAL,
            ..Default::default()
        };
        // AMD, unless the natural order fills no more: chains and trees are
        // often already ordered, and then the per-step permutation is saved.
        let analyse = |ordering| {
            factorize_symbolic_cholesky(structure, Side::Upper, ordering, params)
                .expect("symbolic Cholesky of a valid pattern")
        };
        let amd = analyse(SymmetricOrdering::Amd);
        let natural = analyse(SymmetricOrdering::Identity);
        let symbolic = if natural.len_val() <= amd.len_val() { natural } else { amd };
        let l_diag = match symbolic.raw() {
            SymbolicCholeskyRaw::Simplicial(s) => (0..m)
                .map(|j| {
                    let (a, b) = (s.col_ptr()[j], s.col_ptr()[j + 1]);
                    a + s.row_idx()[a..b].iter().position(|&r| r == j).expect("diagonal in the factor")
                })
                .collect(),
            SymbolicCholeskyRaw::Supernodal(_) => unreachable!("simplicial forced"),
        };
        let scratch = symbolic
            .factorize_numeric_llt_scratch::<f64>(Par::Seq, Default::default())
            .or(symbolic.solve_in_place_scratch::<f64>(1, Par::Seq));
        Self {
            m,
            l_values: vec![0.0; symbolic.len_val()],
            values: vec![0.0; row_idx.len()],
            col_ptr,
            row_idx,
            terms,
            diag_slot,
            symbolic,
            l_diag,
            stack: RefCell::new(MemBuffer::new(scratch)),
        }
    }

    pub fn factor(&mut self, jac: &[f64], inv_mass: &[f64]) -> Result<(), Breakdown> {
        self.values.fill(0.0);
        for &(slot, ja, jb, col) in &self.terms {
            self.values[slot] += jac[ja] * jac[jb] * inv_mass[col];
        }
        if self.values.iter().any(|v| !v.is_finite()) {
            return Err(Breakdown::NonFinite);
        }
        let s = SparseColMatRef::new(
            SymbolicSparseColMatRef::new_checked(self.m, self.m, &self.col_ptr, None, &self.row_idx),
            &self.values,
        );
        let stack = &mut *self.stack.borrow_mut();
        let perm = self.symbolic.perm().map(|p| p.arrays().0);
        let original = |j: usize| perm.map_or(j, |p| p[j]);
        match self.symbolic.factorize_numeric_llt(
            &mut self.l_values,
            s,
            Side::Upper,
            LltRegularization::default(),
            Par::Seq,
            MemStack::new(stack),
            Default::default(),
        ) {
            Ok(_) => {}
            // faer counts the pivot from 1.
            Err(LltError::NonPositivePivot { index }) => return Err(Breakdown::Singular(original(index - 1))),
        }
        // faer only refuses non-positive pivots; a dependent row leaves a
        // round-off-sized one. Apply the dense solver's relative test.
        for (j, &at) in self.l_diag.iter().enumerate() {
            let row = original(j);
            let pivot = self.l_values[at] * self.l_values[at];
            if pivot.is_nan() || pivot <= PIVOT_TOLERANCE * self.values[self.diag_slot[row]] {
                return Err(Breakdown::Singular(row));
            }
        }
        Ok(())
    }

    pub fn solve(&self, b: &mut [f64]) {
        let llt = faer::sparse::linalg::cholesky::LltRef::new(&self.symbolic, &self.l_values);
        let stack = &mut *self.stack.borrow_mut();
        llt.solve_in_place_with_conj(
            Conj::No,
            MatMut::from_column_major_slice_mut(b, self.m, 1),
            Par::Seq,
            MemStack::new(stack),
        );
    }
}
