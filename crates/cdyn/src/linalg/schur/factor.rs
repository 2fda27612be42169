//! `S` assembled from the Jacobian's values (or passed assembled) and
//! factored, with the forward substitution of one right-hand side joined
//! to it.

use super::*;

/// Where the factorization reads `S`'s entries, by slot (see `sum_ptr`).
trait Entries {
    /// Entry `slot`, on the diagonal.
    ///
    /// # Safety
    /// `slot` is a slot of the checked structure.
    unsafe fn diagonal(&self, slot: usize) -> f64;
    /// Entry `slot`, below it; the same safety contract.
    unsafe fn below(&self, slot: usize) -> f64;
    /// The values the entries are made of, for the pivot test to tell a
    /// blown-up state from a dependent row.
    fn values(&self) -> &[f64];
}

/// `S`'s entries as the sums of their products `J_a J_b w`, in registers.
struct Summed<'a> {
    sum_ptr: &'a [u32],
    terms: &'a [(u32, u32, f64)],
    jac: &'a [f64],
}

impl Entries for Summed<'_> {
    // SAFETY (both): `check` bounds every term's indices by the Jacobian's
    // length and `sum_ptr` by the terms'.
    #[inline(always)]
    unsafe fn diagonal(&self, slot: usize) -> f64 {
        // A diagonal entry's products are squares (`ja = jb`): one index read, not two.
        unsafe {
            let terms = self.terms.get_unchecked(span_unchecked(self.sum_ptr, slot));
            terms
                .iter()
                .map(|&(a, _, w)| {
                    let x = *self.jac.get_unchecked(a as usize);
                    x * x * w
                })
                .sum()
        }
    }

    #[inline(always)]
    unsafe fn below(&self, slot: usize) -> f64 {
        unsafe {
            let terms = self.terms.get_unchecked(span_unchecked(self.sum_ptr, slot));
            let jac = self.jac;
            terms.iter().map(|&(a, b, w)| jac.get_unchecked(a as usize) * jac.get_unchecked(b as usize) * w).sum()
        }
    }

    fn values(&self) -> &[f64] {
        self.jac
    }
}

/// `S`'s entries assembled by the caller, one per slot.
struct Assembled<'a>(&'a [f64]);

impl Entries for Assembled<'_> {
    // SAFETY (both): the caller checked the length (`slots()`).
    #[inline(always)]
    unsafe fn diagonal(&self, slot: usize) -> f64 {
        unsafe { *self.0.get_unchecked(slot) }
    }

    #[inline(always)]
    unsafe fn below(&self, slot: usize) -> f64 {
        unsafe { *self.0.get_unchecked(slot) }
    }

    fn values(&self) -> &[f64] {
        self.0
    }
}

impl Schur {
    /// Assembles `S` from the Jacobian values, factors it and solves
    /// `S x = b` in place. The forward substitution and the diagonal
    /// scaling join the factorization (column `j` of `L` is final when it is
    /// applied), which saves two passes over `L` and `b`.
    pub fn factor_and_solve(&mut self, jac: &[f64], b: &mut [f64]) -> Result<(), Breakdown> {
        assert!(self.summed, "this S is assembled by its caller (factor_and_solve_assembled)");
        assert!(jac.len() == self.nnz && b.len() == self.m, "Jacobian or right-hand side of the wrong length");
        // SAFETY: `new` checked (`check`) that every index in the structure
        // is in bounds of the array it indexes; `jac` and `b` have the
        // lengths the terms and rows assume. Unchecked: this loop is bound by
        // branch throughput, and its bounds checks (some twenty per row of a
        // chain) cost 18% of the factorization (chain N=10000: 106 → 87 µs).
        unsafe { self.factor(|sum_ptr, terms| Summed { sum_ptr, terms, jac }, b)? };
        self.backward([b.as_mut_ptr()]);
        Ok(())
    }

    /// As [`factor_and_solve`](Self::factor_and_solve), with `S`'s entries
    /// given by slot ([`slot_finder`](Self::slot_finder)), for a caller that
    /// assembles them in its own order.
    pub fn factor_and_solve_assembled(&mut self, entries: &[f64], b: &mut [f64]) -> Result<(), Breakdown> {
        assert!(entries.len() == self.slots() && b.len() == self.m, "entries or right-hand side of the wrong length");
        // SAFETY: as in `factor_and_solve`; the entries' length is checked.
        unsafe { self.factor(|_, _| Assembled(entries), b)? };
        self.backward([b.as_mut_ptr()]);
        Ok(())
    }

    /// Factors `S`, whose entries `entries` reads from the structure's sums
    /// (`sum_ptr`, `terms`), column by column (left-looking: column `j` from
    /// the finished columns `k < j`), and applies `L⁻¹` then `D⁻¹` to `b`.
    ///
    /// # Safety
    /// The entries read in bounds for every slot, and `b.len() == self.m`.
    #[inline(always)]
    unsafe fn factor<'s, E: Entries>(
        &'s mut self,
        entries: impl FnOnce(&'s [u32], &'s [(u32, u32, f64)]) -> E,
        b: &mut [f64],
    ) -> Result<(), Breakdown> {
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
        let entries = entries(sum_ptr, terms);
        // SAFETY (here and below): indices from the checked structure.
        let entry = |slot: usize| unsafe { entries.below(slot) };
        let diagonal = |slot: usize| unsafe { entries.diagonal(slot) };
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
            let inv = inverse_pivot(d, s_jj, tolerance, entries.values(), dependent, &mut count, || order[j] as usize)?;
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
