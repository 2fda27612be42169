//! A sparse square system with a fixed pattern, factored by LU with
//! partial pivoting and solved many times: the Newton matrix
//! `[M + c_v C + c_q K, Φ_qᵀ; Φ_q, 0]` of an implicit step, which is
//! indefinite (no Cholesky) and whose pattern never changes. The pattern
//! and its fill-reducing ordering are analysed once, and the factors'
//! storage is sized by a first factorization of a matrix like the ones
//! to come ([`SparseLu::reserve`]), so steps do not allocate.

use faer::Par;
use faer::dyn_stack::{MemBuffer, MemStack, StackReq};
use faer::sparse::linalg::LuError;
use faer::sparse::linalg::lu::{LuRef, LuSymbolicParams, NumericLu, SymbolicLu, factorize_symbolic_lu};
use faer::sparse::{SparseColMatRef, SymbolicSparseColMatRef};

/// The matrix entries are given as a list of `(row, column)` positions,
/// repeats allowed (they add), and their values in the same order.
pub(crate) struct SparseLu {
    dim: usize,
    col_ptr: Vec<usize>,
    row_idx: Vec<usize>,
    /// Where each listed entry lands among the compressed values.
    slot: Vec<usize>,
    values: Vec<f64>,
    symbolic: SymbolicLu<usize>,
    numeric: NumericLu<usize, f64>,
    factored: bool,
    memory: MemBuffer,
}

impl Clone for SparseLu {
    /// The same pattern and factors, with scratch memory of its own.
    fn clone(&self) -> Self {
        Self {
            dim: self.dim,
            col_ptr: self.col_ptr.clone(),
            row_idx: self.row_idx.clone(),
            slot: self.slot.clone(),
            values: self.values.clone(),
            symbolic: self.symbolic.clone(),
            numeric: self.numeric.clone(),
            factored: self.factored,
            memory: MemBuffer::new(StackReq::new_aligned::<u8>(self.memory.len(), 64)),
        }
    }
}

/// The factorization found the matrix singular.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Singular;

impl SparseLu {
    /// The `dim × dim` pattern with these entries (each diagonal entry
    /// should be listed, even where it is structurally zero, so that the
    /// pivoting has the freedom partial pivoting needs).
    pub(crate) fn new(dim: usize, entries: &[(u32, u32)]) -> Self {
        let mut order: Vec<usize> = (0..entries.len()).collect();
        order.sort_unstable_by_key(|&k| (entries[k].1, entries[k].0));
        let mut col_ptr = vec![0; dim + 1];
        let mut row_idx = Vec::new();
        let mut slot = vec![0; entries.len()];
        let mut last = None;
        for k in order {
            let (r, c) = entries[k];
            if last != Some((r, c)) {
                row_idx.push(r as usize);
                col_ptr[c as usize + 1] = row_idx.len();
                last = Some((r, c));
            }
            slot[k] = row_idx.len() - 1;
        }
        for c in 0..dim {
            col_ptr[c + 1] = col_ptr[c + 1].max(col_ptr[c]);
        }
        let pattern = SymbolicSparseColMatRef::new_checked(dim, dim, &col_ptr, None, &row_idx);
        let symbolic =
            factorize_symbolic_lu(pattern, LuSymbolicParams::default()).expect("symbolic LU of a valid pattern");
        let scratch = StackReq::or(
            symbolic.factorize_numeric_lu_scratch::<f64>(Par::Seq, Default::default()),
            symbolic.solve_in_place_scratch::<f64>(1, Par::Seq),
        );
        Self {
            dim,
            values: vec![0.0; row_idx.len()],
            col_ptr,
            row_idx,
            slot,
            symbolic,
            numeric: NumericLu::new(),
            factored: false,
            memory: MemBuffer::new(scratch),
        }
    }

    /// Factors `values` to size the factors' storage, and forgets the
    /// factorization: a matrix with the pivoting of the real ones leaves
    /// room for their fill. A singular one does nothing (the real
    /// factorization says so, if it is).
    pub(crate) fn reserve(&mut self, values: &[f64]) {
        let _ = self.factor(values);
        self.factored = false;
    }

    /// Factors the matrix whose listed entries have `values` (in the order of [`new`](Self::new)'s).
    pub(crate) fn factor(&mut self, values: &[f64]) -> Result<(), Singular> {
        self.values.fill(0.0);
        for (&s, &x) in self.slot.iter().zip(values) {
            self.values[s] += x;
        }
        self.factored = false;
        if self.values.iter().any(|x| !x.is_finite()) {
            return Err(Singular);
        }
        let pattern = SymbolicSparseColMatRef::new_checked(self.dim, self.dim, &self.col_ptr, None, &self.row_idx);
        let matrix = SparseColMatRef::new(pattern, &self.values);
        let stack = MemStack::new(&mut self.memory);
        match self.symbolic.factorize_numeric_lu(&mut self.numeric, matrix, Par::Seq, stack, Default::default()) {
            Ok(_) => {
                self.factored = true;
                Ok(())
            }
            Err(LuError::SymbolicSingular { .. } | LuError::Generic(_)) => Err(Singular),
        }
    }

    /// Solves in place with the last factorization.
    pub(crate) fn solve(&mut self, rhs: &mut [f64]) {
        assert!(self.factored, "solve before a successful factorization");
        let lu = LuRef::new_unchecked(&self.symbolic, &self.numeric);
        let rhs = faer::MatMut::from_column_major_slice_mut(rhs, self.dim, 1);
        let stack = MemStack::new(&mut self.memory);
        lu.solve_in_place_with_conj(faer::Conj::No, rhs, Par::Seq, stack);
    }
}
