//! A square system with a fixed pattern that fills much of it, factored
//! densely by LU with partial pivoting: the Newton matrix of an implicit
//! step on a model of a few bodies (which pattern goes here: [`super::lu`]).

use super::sparse_lu::Singular;

/// The entries are given as `(row, column)` positions, repeats allowed
/// (they add), and their values in the same order, as for
/// [`SparseLu`](super::sparse_lu::SparseLu).
#[derive(Clone)]
pub(crate) struct DenseLu {
    dim: usize,
    /// Where each listed entry lands in the row-major matrix.
    at: Vec<usize>,
    /// The matrix, then its factors: unit lower `L` below the diagonal, `U` on and above.
    a: Vec<f64>,
    /// Row `j` was swapped with row `pivot[j] ≥ j` at elimination step `j`.
    pivot: Vec<usize>,
    factored: bool,
}

impl DenseLu {
    pub(crate) fn new(dim: usize, entries: &[(u32, u32)]) -> Self {
        let at = entries.iter().map(|&(r, c)| r as usize * dim + c as usize).collect();
        Self { dim, at, a: vec![0.0; dim * dim], pivot: vec![0; dim], factored: false }
    }

    /// Factors the matrix whose listed entries have `values`.
    pub(crate) fn factor(&mut self, values: &[f64]) -> Result<(), Singular> {
        let (n, a) = (self.dim, &mut self.a);
        a.fill(0.0);
        for (&at, &x) in self.at.iter().zip(values) {
            a[at] += x;
        }
        self.factored = false;
        if a.iter().any(|x| !x.is_finite()) {
            return Err(Singular);
        }
        for j in 0..n {
            let p = (j..n).max_by(|&x, &y| a[x * n + j].abs().total_cmp(&a[y * n + j].abs())).unwrap_or(j);
            if a[p * n + j] == 0.0 {
                return Err(Singular);
            }
            if p != j {
                for c in 0..n {
                    a.swap(p * n + c, j * n + c);
                }
            }
            self.pivot[j] = p;
            let inv = 1.0 / a[j * n + j];
            let (upper, lower) = a.split_at_mut((j + 1) * n);
            let pivot_row = &upper[j * n + j + 1..];
            for row in lower.chunks_exact_mut(n) {
                let l = row[j] * inv;
                row[j] = l;
                // The Newton matrix is mostly zeros: skip the rows with nothing to eliminate.
                if l != 0.0 {
                    row[j + 1..].iter_mut().zip(pivot_row).for_each(|(x, u)| *x -= l * u);
                }
            }
        }
        self.factored = true;
        Ok(())
    }

    /// Solves in place with the last factorization.
    pub(crate) fn solve(&self, b: &mut [f64]) {
        assert!(self.factored, "solve before a successful factorization");
        let (n, a) = (self.dim, &self.a);
        for j in 0..n {
            b.swap(j, self.pivot[j]);
        }
        for i in 0..n {
            let row = &a[i * n..i * n + i];
            b[i] -= row.iter().zip(&b[..i]).map(|(l, x)| l * x).sum::<f64>();
        }
        for i in (0..n).rev() {
            let row = &a[i * n + i + 1..(i + 1) * n];
            let s = row.iter().zip(&b[i + 1..]).map(|(u, x)| u * x).sum::<f64>();
            b[i] = (b[i] - s) / a[i * n + i];
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::linalg::sparse_lu::SparseLu;
    use crate::random::Lcg;

    /// A saddle-point matrix like the Newton matrix, `[A, Bᵀ; B, 0]`, with
    /// repeated entries and a zero diagonal block that needs pivoting:
    /// dense and sparse solve it alike, to a small residual.
    #[test]
    fn dense_and_sparse_lu_solve_a_saddle_point_system_alike() {
        let (n, m) = (7, 3);
        let mut entries = Vec::new();
        for i in 0..n + m {
            entries.push((i as u32, i as u32));
            for j in 0..n {
                if i < n && (i + j) % 3 == 0 {
                    entries.push((i as u32, j as u32));
                }
            }
        }
        for r in 0..m {
            for c in [r, r + 2, r + 4] {
                entries.extend([((n + r) as u32, c as u32), (c as u32, (n + r) as u32)]);
            }
        }
        // Twice each entry of A's diagonal (repeats add), zero on the multipliers' diagonal.
        entries.extend((0..n as u32).map(|i| (i, i)));
        let mut random = Lcg(7);
        let values: Vec<f64> =
            entries.iter().map(|&(r, c)| if r == c && r as usize >= n { 0.0 } else { 4.0 * random.next() }).collect();
        let b: Vec<f64> = (0..n + m).map(|_| random.next()).collect();
        let mut a = vec![0.0; (n + m) * (n + m)];
        entries.iter().zip(&values).for_each(|(&(r, c), v)| a[r as usize * (n + m) + c as usize] += v);
        let mut dense = DenseLu::new(n + m, &entries);
        dense.factor(&values).unwrap();
        let mut y = b.clone();
        dense.solve(&mut y);
        let residual = (0..n + m)
            .map(|i| (b[i] - (0..n + m).map(|j| a[i * (n + m) + j] * y[j]).sum::<f64>()).abs())
            .fold(0.0, f64::max);
        assert!(residual < 1e-13, "{residual:e}");
        let mut sparse = SparseLu::new(n + m, &entries);
        sparse.factor(&values).unwrap();
        let mut z = b.clone();
        sparse.solve(&mut z);
        assert!(y.iter().zip(&z).all(|(y, z)| (y - z).abs() < 1e-12 * (1.0 + z.abs())), "{y:?} vs {z:?}");
    }

    /// A zero column and a non-finite entry are refused, not solved.
    #[test]
    fn dense_lu_refuses_a_singular_or_non_finite_matrix() {
        let entries = [(0, 0), (0, 1), (1, 0), (1, 1)];
        let mut lu = DenseLu::new(2, &entries);
        assert_eq!(lu.factor(&[1.0, 0.0, 2.0, 0.0]), Err(Singular));
        assert_eq!(lu.factor(&[1.0, f64::NAN, 2.0, 1.0]), Err(Singular));
        assert!(lu.factor(&[0.0, 1.0, 2.0, 0.0]).is_ok(), "a zero pivot that a row swap fixes");
        let mut b = [3.0, 4.0];
        lu.solve(&mut b);
        assert_eq!(b, [2.0, 3.0]);
    }
}
