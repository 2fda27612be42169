//! `S` assembled from the Jacobian's values and factored, with the
//! forward substitution of one right-hand side joined to it.

use super::*;

impl Schur {
    /// Assembles `S` from the Jacobian values, factors it and solves
    /// `S x = b` in place. The forward substitution and the diagonal
    /// scaling join the factorization (column `j` of `L` is final when it is
    /// applied), which saves two passes over `L` and `b`.
    pub fn factor_and_solve(&mut self, jac: &[f64], b: &mut [f64]) -> Result<(), Breakdown> {
        assert!(jac.len() == self.nnz && b.len() == self.m, "Jacobian or right-hand side of the wrong length");
        // SAFETY: `new` checked (`check`) that every index in the structure
        // is in bounds of the array it indexes; `jac` and `b` have the
        // lengths the terms and rows assume. Unchecked: this loop is bound by
        // branch throughput, and its bounds checks (some twenty per row of a
        // chain) cost 18% of the factorization (chain N=10000: 106 → 87 µs).
        unsafe { self.factor(jac, b)? };
        self.backward([b.as_mut_ptr()]);
        Ok(())
    }

    /// Assembles `S` and factors it, column by column (left-looking: column
    /// `j` from the finished columns `k < j`), and applies `L⁻¹` then `D⁻¹` to `b`.
    ///
    /// # Safety
    /// `jac.len() == self.nnz` and `b.len() == self.m`.
    unsafe fn factor(&mut self, jac: &[f64], b: &mut [f64]) -> Result<(), Breakdown> {
        let m = self.m;
        let Self {
            order,
            col_ptr,
            row_idx,
            row_ptr,
            row_entries,
            sum_ptr,
            terms,
            lower,
            scaled,
            inv_d,
            work,
            dependent,
            dropped,
            tolerance,
            ..
        } = self;
        let (dependent, tolerance) = (*dependent, *tolerance);
        // Counted in a local, which stays in a register; stored once at the end.
        let mut count = 0;
        *dropped = 0;
        // Entry `slot` of `S` (see `sum_ptr`), summed in a register.
        let entry = |slot: usize| -> f64 {
            // SAFETY (here and below): indices from the checked structure.
            unsafe {
                let terms = terms.get_unchecked(span_unchecked(sum_ptr, slot));
                terms.iter().map(|&(a, b, w)| jac.get_unchecked(a as usize) * jac.get_unchecked(b as usize) * w).sum()
            }
        };
        // A diagonal entry's products are squares (`ja = jb`): one index read, not two.
        let diagonal = |slot: usize| -> f64 {
            unsafe {
                let terms = terms.get_unchecked(span_unchecked(sum_ptr, slot));
                terms
                    .iter()
                    .map(|&(a, _, w)| {
                        let x = *jac.get_unchecked(a as usize);
                        x * x * w
                    })
                    .sum()
            }
        };
        for j in 0..m {
            let s_jj = diagonal(j);
            let own = unsafe { span_unchecked(col_ptr, j) };
            for p in own.clone() {
                unsafe { *work.get_unchecked_mut(*row_idx.get_unchecked(p) as usize) = entry(m + p) };
            }
            let mut d = s_jj;
            for &(k, at) in unsafe { row_entries.get_unchecked(span_unchecked(row_ptr, j)) } {
                let (k, at) = (k as usize, at as usize);
                // (L D)_jk is known before 1/d_k: the pivot waits on one
                // multiplication after the division, not two.
                unsafe {
                    let u = *scaled.get_unchecked(at);
                    d -= u * u * inv_d.get_unchecked(k);
                    for p in at + 1..*col_ptr.get_unchecked(k + 1) as usize {
                        *work.get_unchecked_mut(*row_idx.get_unchecked(p) as usize) -= lower.get_unchecked(p) * u;
                    }
                }
            }
            let inv = inverse_pivot(d, s_jj, tolerance, jac, dependent, &mut count, || order[j] as usize)?;
            unsafe {
                *inv_d.get_unchecked_mut(j) = inv;
                let row = *order.get_unchecked(j) as usize;
                let y = *b.get_unchecked(row);
                for p in own {
                    let i = *row_idx.get_unchecked(p) as usize;
                    let u = *work.get_unchecked(i);
                    *scaled.get_unchecked_mut(p) = u;
                    let l = u * inv;
                    *lower.get_unchecked_mut(p) = l;
                    *b.get_unchecked_mut(i) -= l * y;
                }
                *b.get_unchecked_mut(row) = y * inv;
            }
        }
        *dropped = count;
        Ok(())
    }
}
