//! A square system with a fixed pattern that fills much of it, factored
//! densely by LU: the Newton matrix of an implicit step on a model of a
//! few bodies or a few hundred unknowns (which pattern goes here:
//! [`super::lu`]). It is first eliminated without row exchanges, in an
//! order that keeps its factors sparse (`positions`: the coordinates in
//! order, each multiplier right after the last coordinate its row reads),
//! along the pattern of the factors (found once, `Elimination`): `M`
//! dominates the coordinates' block, so their pivots need no exchange, and
//! a multiplier's pivot is its entry of `Φ_q M⁻¹ Φ_qᵀ`, which the
//! elimination of its coordinates fills in. Where a pivot is too small for
//! that (a singular or indefinite matrix), the matrix is factored again
//! with partial pivoting.

use super::sparse_lu::Singular;

/// The entries are given as `(row, column)` positions, repeats allowed
/// (they add), and their values in the same order, as for
/// [`SparseLu`](super::sparse_lu::SparseLu).
#[derive(Clone)]
pub(crate) struct DenseLu {
    dim: usize,
    /// Where each listed entry lands in the row-major matrix.
    at: Vec<usize>,
    /// The matrix, then its factors: `U` on and above the diagonal, unit
    /// lower `L` below it after partial pivoting (in `l_columns` after an
    /// elimination in order).
    a: Vec<f64>,
    /// Row `j` was swapped with row `pivot[j] ≥ j` at elimination step `j`
    /// (with partial pivoting, `pivoted`).
    pivot: Vec<usize>,
    pivoted: bool,
    /// The elimination in order, where it saves at least half the products
    /// of a dense one (not in a pattern that fills up, as a flyball
    /// governor's of springs and dampers between every body does: 39 k
    /// products of the dense 46 k, slower along their runs than the
    /// pivoting kernel's skipped rows).
    order: Option<Elimination>,
    /// Where each unknown is eliminated (its row and column in `a`), and a
    /// right-hand side in that order.
    position: Vec<usize>,
    permuted: Vec<f64>,
    /// `L`'s entries of an elimination in order, column after column as
    /// `Elimination::below` lists their rows: the forward substitution
    /// reads them in sequence (from the dense matrix, by computed index,
    /// it was UR5's most frequent line of a generalized-α step).
    l_columns: Vec<f64>,
    factored: bool,
}

/// The non-zeros of the factors when the matrix is eliminated in its own
/// order, fill included: per pivot `k`, the rows below it with an entry in
/// column `k` (`L`) and the columns right of it with an entry in row `k`
/// (`U`), as runs of consecutive columns.
#[derive(Clone)]
struct Elimination {
    below: Vec<u32>,
    below_at: Vec<usize>,
    right: Vec<(u32, u32)>,
    right_at: Vec<usize>,
}

/// A pivot of the elimination in order is taken if the entries it divides
/// are at most this many times larger: a badly scaled but regular pivot
/// (an Euler parameter's `4J′` against its joints' lever arms) passes, a
/// vanishing one (a singular or indefinite matrix) falls back to partial
/// pivoting.
const GROWTH: f64 = 1e8;

impl Elimination {
    /// Simulates the elimination of the pattern `entries` (and the diagonal).
    fn new(dim: usize, entries: &[(u32, u32)]) -> Self {
        let mut filled = vec![false; dim * dim];
        for &(r, c) in entries {
            filled[r as usize * dim + c as usize] = true;
        }
        let (mut below, mut below_at, mut right, mut right_at) = (Vec::new(), vec![0], Vec::new(), vec![0]);
        for k in 0..dim {
            let rows: Vec<usize> = (k + 1..dim).filter(|&i| filled[i * dim + k]).collect();
            let cols: Vec<usize> = (k + 1..dim).filter(|&j| filled[k * dim + j]).collect();
            for &i in &rows {
                for &j in &cols {
                    filled[i * dim + j] = true;
                }
            }
            below.extend(rows.iter().map(|&i| i as u32));
            below_at.push(below.len());
            for j in cols {
                let runs = right.len() - right_at[k];
                match right.last_mut() {
                    Some((_, end)) if runs > 0 && *end as usize == j => *end += 1,
                    _ => right.push((j as u32, j as u32 + 1)),
                }
            }
            right_at.push(right.len());
        }
        Self { below, below_at, right, right_at }
    }

    /// The multiply-adds of an elimination along the pattern.
    fn products(&self) -> usize {
        let width = |k: usize| self.right(k).iter().map(|&(s, e)| (e - s) as usize).sum::<usize>();
        (0..self.below_at.len() - 1).map(|k| self.below(k).len() * width(k)).sum()
    }

    /// Zeros the entries of the factors (the diagonal, `L` and `U`) in the
    /// row-major `n × n` matrix `a`.
    fn clear(&self, a: &mut [f64], n: usize) {
        for k in 0..n {
            a[k * n + k] = 0.0;
            self.below(k).iter().for_each(|&i| a[i as usize * n + k] = 0.0);
            self.right(k).iter().for_each(|&(s, e)| a[k * n + s as usize..k * n + e as usize].fill(0.0));
        }
    }

    fn below(&self, k: usize) -> &[u32] {
        &self.below[self.below_at[k]..self.below_at[k + 1]]
    }

    fn right(&self, k: usize) -> &[(u32, u32)] {
        &self.right[self.right_at[k]..self.right_at[k + 1]]
    }
}

/// The order of elimination: the `leading` unknowns (a positive definite
/// block's: the coordinates) in their order, each other one (a multiplier)
/// right after the last leading unknown its row reads, where its pivot has
/// gathered the terms of every coordinate it reads and its row has filled
/// in little beyond that coordinate's. Putting every multiplier last
/// instead fills the factors of a tree of bodies almost densely (UR5: 65 k
/// of the dense 155 k products, against 21.9 k in this order).
fn positions(dim: usize, leading: usize, entries: &[(u32, u32)]) -> Vec<usize> {
    let mut last = vec![0; dim];
    for &(r, c) in entries {
        let (r, c) = (r as usize, c as usize);
        if r >= leading && c < leading {
            last[r] = last[r].max(c + 1);
        }
    }
    let mut order: Vec<usize> = (0..dim).collect();
    order.sort_by_key(|&i| if i < leading { (i, 0, i) } else { (last[i].max(1) - 1, 1, i) });
    let mut position = vec![0; dim];
    for (at, i) in order.into_iter().enumerate() {
        position[i] = at;
    }
    position
}

impl DenseLu {
    /// The `dim × dim` pattern of `entries`, whose first `leading` unknowns
    /// are those of a positive definite block (see [`positions`]).
    pub(crate) fn new(dim: usize, leading: usize, entries: &[(u32, u32)]) -> Self {
        let position = positions(dim, leading, entries);
        let moved: Vec<(u32, u32)> =
            entries.iter().map(|&(r, c)| (position[r as usize] as u32, position[c as usize] as u32)).collect();
        let at = moved.iter().map(|&(r, c)| r as usize * dim + c as usize).collect();
        let order = Elimination::new(dim, &moved);
        let dense: usize = (1..dim).map(|k| k * k).sum();
        let order = (2 * order.products() <= dense).then_some(order);
        let entries_of_l = order.as_ref().map_or(0, |o| o.below.len());
        Self {
            dim,
            at,
            a: vec![0.0; dim * dim],
            pivot: vec![0; dim],
            pivoted: false,
            order,
            position,
            permuted: vec![0.0; dim],
            l_columns: vec![0.0; entries_of_l],
            factored: false,
        }
    }

    /// Factors the matrix whose listed entries have `values`.
    pub(crate) fn factor(&mut self, values: &[f64]) -> Result<(), Singular> {
        self.factored = false;
        if values.iter().any(|x| !x.is_finite()) {
            return Err(Singular);
        }
        let in_order = self.order.is_some();
        self.scatter(values, in_order);
        if !(in_order && self.eliminate_in_order()) {
            if in_order {
                self.scatter(values, false);
            }
            self.eliminate_with_pivoting()?;
        }
        self.factored = true;
        Ok(())
    }

    /// The matrix of `values`: cleared only on the factors' pattern, which
    /// is all the elimination in order and its solves read (the rest of the
    /// dense matrix, clear at 600 unknowns, was most of such a step: the
    /// planar chain of 200 links), or cleared whole for partial pivoting.
    fn scatter(&mut self, values: &[f64], on_pattern: bool) {
        let (n, a) = (self.dim, &mut self.a);
        match (&self.order, on_pattern) {
            (Some(order), true) => order.clear(a, n),
            _ => a.fill(0.0),
        }
        for (&at, &x) in self.at.iter().zip(values) {
            a[at] += x;
        }
    }

    /// Eliminates in the matrix's order along the factors' pattern; false
    /// where it does not (a pivot too small, or no such order kept).
    fn eliminate_in_order(&mut self) -> bool {
        let (n, a) = (self.dim, &mut self.a);
        let Some(order) = &self.order else { return false };
        self.pivoted = false;
        for k in 0..n {
            let (upper, lower) = a.split_at_mut((k + 1) * n);
            let pivot_row = &upper[k * n..];
            let p = pivot_row[k];
            if p == 0.0 || !p.is_finite() {
                return false;
            }
            let (inv, bound) = (1.0 / p, p.abs() * GROWTH);
            let column = &mut self.l_columns[order.below_at[k]..order.below_at[k + 1]];
            for (&i, kept) in order.below(k).iter().zip(column) {
                let row = &mut lower[(i as usize - k - 1) * n..(i as usize - k) * n];
                // Checked as each entry is divided: the factorization
                // falls back before anything it wrote is read.
                if row[k].abs() >= bound {
                    return false;
                }
                // `L` is read from `l_columns` only: its place in `a` is left as it is.
                let l = row[k] * inv;
                *kept = l;
                if l == 0.0 {
                    continue;
                }
                for &(s, e) in order.right(k) {
                    let (s, e) = (s as usize, e as usize);
                    row[s..e].iter_mut().zip(&pivot_row[s..e]).for_each(|(x, u)| *x -= l * u);
                }
            }
        }
        true
    }

    /// LU with partial pivoting over the whole matrix.
    fn eliminate_with_pivoting(&mut self) -> Result<(), Singular> {
        let (n, a) = (self.dim, &mut self.a);
        self.pivoted = true;
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
        Ok(())
    }

    /// Solves in place with the last factorization.
    pub(crate) fn solve(&mut self, b: &mut [f64]) {
        assert!(self.factored, "solve before a successful factorization");
        let mut permuted = std::mem::take(&mut self.permuted);
        self.position.iter().zip(b.iter()).for_each(|(&at, &x)| permuted[at] = x);
        self.solve_in_order(&mut permuted);
        self.position.iter().zip(b.iter_mut()).for_each(|(&at, x)| *x = permuted[at]);
        self.permuted = permuted;
    }

    /// Solves in place, `b` in the order of elimination.
    fn solve_in_order(&self, b: &mut [f64]) {
        let (n, a) = (self.dim, &self.a);
        if let (false, Some(order)) = (self.pivoted, &self.order) {
            assert!(b.len() == n, "a right-hand side of the wrong length");
            for k in 0..n {
                let x = b[k];
                let column = &self.l_columns[order.below_at[k]..order.below_at[k + 1]];
                for (&i, l) in order.below(k).iter().zip(column) {
                    // SAFETY: `Elimination::new` lists rows `k < i < n` below pivot `k`, and `b` has `n` entries.
                    unsafe { *b.get_unchecked_mut(i as usize) -= l * x };
                }
            }
            for k in (0..n).rev() {
                let row = &a[k * n..(k + 1) * n];
                let mut s = 0.0;
                for &(start, end) in order.right(k) {
                    let (start, end) = (start as usize, end as usize);
                    s += row[start..end].iter().zip(&b[start..end]).map(|(u, x)| u * x).sum::<f64>();
                }
                b[k] = (b[k] - s) / row[k];
            }
            return;
        }
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
        let mut dense = DenseLu::new(n + m, n, &entries);
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

    /// A chain's saddle-point matrix: a positive definite block per body on
    /// the diagonal, coupled to the next body's, and joint rows that read
    /// two neighbouring bodies. It is eliminated in order (each multiplier
    /// after its joint's last coordinate, no row exchanged) along a pattern
    /// far from dense, and solves as the sparse LU does; a body with a zero
    /// or a vanishing pivot in that order falls back to partial pivoting
    /// and still solves, and the next matrix is eliminated in order again.
    #[test]
    fn a_chains_newton_matrix_is_eliminated_in_order_or_else_with_pivoting() {
        let (bodies, size) = (8, 3);
        let (n, m) = (bodies * size, bodies - 1);
        let mut random = Lcg(11);
        let (mut entries, mut values) = (Vec::new(), Vec::new());
        let mut put = |r: usize, c: usize, x: f64| {
            entries.push((r as u32, c as u32));
            values.push(x);
        };
        for b in 0..bodies {
            for i in 0..size {
                for j in 0..size {
                    let diagonal = if i == j { 4.0 } else { 0.0 };
                    put(b * size + i, b * size + j, diagonal + 0.3 * random.next());
                    if b + 1 < bodies {
                        put(b * size + i, (b + 1) * size + j, 0.1 * random.next());
                        put((b + 1) * size + j, b * size + i, 0.1 * random.next());
                    }
                }
            }
        }
        for r in 0..m {
            for c in r * size..(r + 2) * size {
                let x = random.next();
                put(n + r, c, x);
                put(c, n + r, x);
            }
            put(n + r, n + r, 0.0);
        }
        let b: Vec<f64> = (0..n + m).map(|_| random.next()).collect();
        let mut dense = DenseLu::new(n + m, n, &entries);
        let order = dense.order.as_ref().expect("an order that saves products");
        assert!(4 * order.products() < (1..n + m).map(|k| k * k).sum::<usize>());
        let mut solve = |values: &[f64], pivoted: bool| {
            dense.factor(values).unwrap();
            assert_eq!(dense.pivoted, pivoted);
            let mut x = b.clone();
            dense.solve(&mut x);
            let mut sparse = SparseLu::new(n + m, &entries);
            sparse.factor(values).unwrap();
            let mut y = b.clone();
            sparse.solve(&mut y);
            let mut residual = b.clone();
            entries.iter().zip(values).for_each(|(&(r, c), v)| residual[r as usize] -= v * x[c as usize]);
            let residual = residual.iter().fold(0.0_f64, |a, r| a.max(r.abs()));
            assert!(residual < 1e-12, "{residual:e}");
            assert!(x.iter().zip(&y).all(|(x, y)| (x - y).abs() < 1e-10 * (1.0 + y.abs())), "{x:?} vs {y:?}");
        };
        solve(&values, false);
        // The first coordinate's own entry (the first listed) cancelled:
        // its in-order pivot is 0 while its column below is not.
        let regular = values.clone();
        values[0] = 0.0;
        solve(&values, true);
        // A pivot small against the entries it divides (1e-10 against
        // about 0.1): the elimination in order stops part-way and pivots.
        values[0] = 1e-10;
        solve(&values, true);
        // In order again, after the pivoting filled the matrix off the
        // factors' pattern (which the elimination in order does not clear).
        solve(&regular, false);
    }

    /// A zero column and a non-finite entry are refused, not solved.
    #[test]
    fn dense_lu_refuses_a_singular_or_non_finite_matrix() {
        let entries = [(0, 0), (0, 1), (1, 0), (1, 1)];
        let mut lu = DenseLu::new(2, 2, &entries);
        assert_eq!(lu.factor(&[1.0, 0.0, 2.0, 0.0]), Err(Singular));
        assert_eq!(lu.factor(&[1.0, f64::NAN, 2.0, 1.0]), Err(Singular));
        assert!(lu.factor(&[0.0, 1.0, 2.0, 0.0]).is_ok(), "a zero pivot that a row swap fixes");
        let mut b = [3.0, 4.0];
        lu.solve(&mut b);
        assert_eq!(b, [2.0, 3.0]);
    }
}
