//! Solves with a finished factorization: `L⁻¹`, `D⁻¹` and `L⁻ᵀ` on up to
//! [`MAX_RIGHT_HAND_SIDES`] vectors at once.

use super::*;

impl Schur {
    pub fn solve(&self, b: &mut [f64]) {
        self.solve_many(&mut [b]);
    }

    /// Solves `S x = b` in place for up to [`MAX_RIGHT_HAND_SIDES`] vectors
    /// in one pass over `L`: the control laws solve several right-hand sides
    /// per evaluation, and the pass (index loads) costs more than the
    /// arithmetic. Each vector sees exactly the operations of a lone solve.
    pub fn solve_many(&self, bs: &mut [&mut [f64]]) {
        assert!(bs.iter().all(|b| b.len() == self.m), "right-hand side of the wrong length");
        match bs {
            [] => {}
            [a] => self.forward_backward([&mut **a]),
            [a, b] => self.forward_backward([&mut **a, &mut **b]),
            [a, b, c] => self.forward_backward([&mut **a, &mut **b, &mut **c]),
            [a, b, c, d] => self.forward_backward([&mut **a, &mut **b, &mut **c, &mut **d]),
            _ => panic!("at most {MAX_RIGHT_HAND_SIDES} right-hand sides"),
        }
    }

    /// `L⁻¹`, `D⁻¹`, then `L⁻ᵀ`, on `K` vectors of length `m` at once.
    #[inline(always)]
    fn forward_backward<const K: usize>(&self, mut bs: [&mut [f64]; K]) {
        let b: [*mut f64; K] = bs.each_mut().map(|b| b.as_mut_ptr());
        self.forward(b);
        self.backward(b);
    }

    /// Applies `L⁻¹` then `D⁻¹` to `K` vectors of length `m` at once.
    ///
    /// SAFETY (of the callers): every pointer is to `m` values, and no two
    /// overlap. `new` checked (`check`) that `order` and `row_idx` hold rows
    /// < m and that `col_ptr` indexes `lower`.
    #[inline(always)]
    fn forward<const K: usize>(&self, b: [*mut f64; K]) {
        // SAFETY: see above; `solve_many` checked the lengths and takes
        // distinct borrows.
        unsafe {
            for j in 0..self.m {
                let row = *self.order.get_unchecked(j) as usize;
                let y: [f64; K] = std::array::from_fn(|k| *b[k].add(row));
                for p in span_unchecked(&self.col_ptr, j) {
                    let (i, l) = (*self.row_idx.get_unchecked(p) as usize, *self.lower.get_unchecked(p));
                    for k in 0..K {
                        *b[k].add(i) -= l * y[k];
                    }
                }
                let inv = *self.inv_d.get_unchecked(j);
                for k in 0..K {
                    *b[k].add(row) = y[k] * inv;
                }
            }
        }
    }

    /// Applies `L⁻ᵀ` to `K` vectors at once; the callers' contract is `forward`'s.
    #[inline(always)]
    pub(super) fn backward<const K: usize>(&self, b: [*mut f64; K]) {
        // SAFETY: see `forward`.
        unsafe {
            for j in (0..self.m).rev() {
                let row = *self.order.get_unchecked(j) as usize;
                let mut y: [f64; K] = std::array::from_fn(|k| *b[k].add(row));
                for p in span_unchecked(&self.col_ptr, j) {
                    let (i, l) = (*self.row_idx.get_unchecked(p) as usize, *self.lower.get_unchecked(p));
                    for k in 0..K {
                        y[k] -= l * *b[k].add(i);
                    }
                }
                for k in 0..K {
                    *b[k].add(row) = y[k];
                }
            }
        }
    }
}
