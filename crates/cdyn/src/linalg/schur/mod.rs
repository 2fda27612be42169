//! The `m × m` system `S = Φ_q M⁻¹ Φ_qᵀ`: its assembly from the sparse
//! Jacobian and its `L D Lᵀ` factorization.
//!
//! Everything structural is done once: the list of products `J_a J_b / m_c`
//! that make `S` (one per pair of rows sharing a coordinate, so forming `S`
//! costs the same as reading the Jacobian for chains and trees), the
//! ordering, and the pattern of `L`. A step then only refills values,
//! eliminates along the known pattern and solves — in buffers allocated
//! here, never per step.
//!
//! Dense and sparse share the kernel and differ in the pattern of `L`:
//! dense takes the full lower triangle in the natural order; small systems
//! the pattern the natural order fills; sparse the pattern faer's symbolic
//! Cholesky finds (`sparse.rs`), with an AMD ordering when it fills less
//! than the natural one.
//!
//! Here the structure and the settings; the numeric factorization in
//! `factor`, the substitutions with it in `solve`.
//!
//! May import: `linalg`'s other files.

mod factor;
mod solve;

use crate::linalg::ldl::{Breakdown, DependentRows, inverse_pivot};
use crate::linalg::mass::DiagonalMass;
use crate::linalg::sparse::{Pattern, Structure};

/// How to factor `Φ_q M⁻¹ Φ_qᵀ`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[non_exhaustive]
pub enum LinearSolver {
    /// Sparse from [`SPARSE_FROM`] constraint rows; below, the pattern `L`
    /// takes in the rows' own order (the full triangle where that fills it),
    /// except that with a block-diagonal `M(q)` (spatial bodies) a
    /// reordered sparse pattern is taken where it has fewer entries.
    #[default]
    Auto,
    /// The full triangle of `S`: for few constraint rows.
    Dense,
    /// The pattern of `S`, ordered for little fill: for many rows.
    Sparse,
}

/// Constraint rows from which `Auto` factors sparse (below it, see
/// [`LinearSolver::Auto`]).
pub const SPARSE_FROM: usize = 48;

/// For every pair of rows `(a ≥ b)` sharing a coordinate, the products
/// that make `S_ab`, as `(a, b, ja, jb, col)`; `col` selects the weight
/// `(M⁻¹)_col,col` of the product.
pub(crate) fn products(pattern: &Pattern, n: usize) -> Vec<(usize, usize, usize, usize, usize)> {
    let m = pattern.start.len() - 1;
    // For every coordinate, the Jacobian entries that touch it (that can be non-zero).
    let mut by_col: Vec<Vec<(usize, usize)>> = vec![Vec::new(); n];
    for r in 0..m {
        for j in pattern.row(r).filter(|&j| pattern.read[j]) {
            by_col[pattern.cols[j] as usize].push((r, j));
        }
    }
    let mut out = Vec::new();
    for (col, entries) in by_col.iter().enumerate() {
        for &(ra, ja) in entries {
            for &(rb, jb) in entries {
                if rb <= ra {
                    out.push((ra, rb, ja, jb, col));
                }
            }
        }
    }
    out
}

/// `S` assembled and factored as `L D Lᵀ` (unit lower `L`), in the
/// elimination order of its [`Structure`].
///
/// Rank-revealing: a row whose pivot fails [`inverse_pivot`] is an error,
/// or, with [`DependentRows::Tolerate`], a row whose pivot is below
/// [`DROP_TOLERANCE`] of its diagonal entry is dropped — `D⁻¹` and its
/// column of `L` are 0 — so that `S x = b` is solved on the other rows and
/// the dropped rows' `x` is 0. For a consistent `b` (in the range of `S`,
/// as `Φ_q M⁻¹ G − γ` is when the constraints are compatible) this is an
/// exact solution, the *basic* one, and `Φ_qᵀ x` — hence the acceleration —
/// is the same for every solution. Not the minimum-norm multipliers: that
/// needs a second solve on the dependent set, and the basic solution is
/// what the rows' order already defines, costs nothing per step and keeps
/// a dependent row's multiplier exactly 0. For an inconsistent `b` (a
/// control law's `Φ` off the manifold) the dropped rows' equations are
/// simply not enforced; nothing is divided by a vanishing pivot.
///
/// Everything the numeric passes read per row is addressed by original row
/// number (`order` maps elimination positions to rows), so a right-hand side
/// is solved in place, without a permuted copy. Indices are `u32`: the
/// structure is read at every step, and half the bytes is half the memory
/// traffic once it outgrows the caches.
#[derive(Clone)]
pub(crate) struct Schur {
    m: usize,
    /// `order[i]` is the original row eliminated `i`-th.
    order: Vec<u32>,
    /// Columns of the strictly lower `L` (by elimination position).
    col_ptr: Vec<u32>,
    /// The original row of each entry of `L`, by columns.
    row_idx: Vec<u32>,
    /// For each position `j`, the columns `k < j` with `L_jk ≠ 0` and the slot of `L_jk`.
    row_ptr: Vec<u32>,
    row_entries: Vec<(u32, u32)>,
    /// The products `J[ja] J[jb] / m` that sum to each entry of `S`: the
    /// diagonal entries (in elimination order) first, then the entries in
    /// `L`'s slots (zero sums for fill).
    sum_ptr: Vec<u32>,
    terms: Vec<(u32, u32, f64)>,
    /// `L` and `L D` below the diagonal, and `D⁻¹` (by position).
    lower: Vec<f64>,
    scaled: Vec<f64>,
    inv_d: Vec<f64>,
    /// Column being eliminated, by original row.
    work: Vec<f64>,
    /// Length of the Jacobian the terms index.
    nnz: usize,
    /// Whether `terms` sum `S`'s entries; if not, the caller passes them
    /// assembled (`factor_and_solve_assembled`).
    summed: bool,
    /// Whether a dependent row is an error or dropped.
    dependent: DependentRows,
    /// Rows dropped by the last factorization.
    dropped: usize,
    /// `dependent.tolerance()`.
    tolerance: f64,
}

/// Entries `slot` of `col_ptr`, `row_ptr` or `sum_ptr` to the next, as a
/// range, without bounds checks.
///
/// # Safety
/// `slot + 1 < ptr.len()`.
#[inline(always)]
unsafe fn span_unchecked(ptr: &[u32], slot: usize) -> std::ops::Range<usize> {
    unsafe { *ptr.get_unchecked(slot) as usize..*ptr.get_unchecked(slot + 1) as usize }
}

/// An index into one of the structure arrays; they are stored as `u32`.
fn index(i: usize) -> u32 {
    u32::try_from(i).expect("the constraint system has fewer than 2³² entries")
}

impl Schur {
    /// The structure of `S = Φ_q M⁻¹ Φ_qᵀ` for this Jacobian pattern, with
    /// the weights of its products taken from the (constant) mass matrix.
    pub fn new(pattern: &Pattern, mass: &DiagonalMass, solver: LinearSolver) -> Self {
        Self::with_rule(pattern, Some(mass), mass.inverse().len(), solver)
    }

    /// The structure of `S` for `n` coordinates, whose entries the caller
    /// assembles and passes by slot ([`slot_finder`](Self::slot_finder),
    /// [`factor_and_solve_assembled`](Self::factor_and_solve_assembled)):
    /// for block masses (spatial bodies), whose products on a block are
    /// dense. Below [`SPARSE_FROM`] rows `Auto` takes the reordered sparse
    /// pattern where it has fewer entries than the full triangle: a robot
    /// arm's tree of 43 rows (UR5) stepped in 18.3 µs with the full
    /// triangle and 10.7 µs with its own pattern (the kernel is the same
    /// for both, so fewer entries cost less). A constant mass (planar
    /// models) keeps the rows' own order below `SPARSE_FROM`, which fixes
    /// which of redundant rows are dropped (the later ones, docs/rank.md),
    /// and eliminates along the pattern that order fills: the full
    /// triangle's arithmetic less the products of structural zeros (a
    /// planar chain of 10: 45 entries of `L` → 9).
    pub fn assembled_by_caller(pattern: &Pattern, n: usize, solver: LinearSolver) -> Self {
        Self::with_rule(pattern, None, n, solver)
    }

    /// `mass` weighs the products that sum `S`'s entries; without it the
    /// caller (a block mass) assembles them, and `Auto` takes the fewest
    /// entries below `SPARSE_FROM`.
    fn with_rule(pattern: &Pattern, mass: Option<&DiagonalMass>, n: usize, solver: LinearSolver) -> Self {
        let m = pattern.start.len() - 1;
        let fewest_below = mass.is_none();
        let products = products(pattern, n);
        let pairs = || products.iter().map(|&(a, b, ..)| (a, b));
        let analyse = || crate::linalg::sparse::analyse(m, pairs());
        let natural = || crate::linalg::sparse::natural(m, pairs());
        let structure = match solver {
            _ if m == 0 => Structure::dense(0),
            LinearSolver::Dense => Structure::dense(m),
            LinearSolver::Sparse => analyse(),
            LinearSolver::Auto if m >= SPARSE_FROM => analyse(),
            LinearSolver::Auto if fewest_below => {
                let sparse = analyse();
                if below_triangle(sparse.row_idx.len(), m) { sparse } else { Structure::dense(m) }
            }
            LinearSolver::Auto => natural(),
        };
        let Structure { perm, col_ptr, row_idx } = structure;
        let order = perm.unwrap_or_else(|| (0..m).collect());
        let mut position = vec![0; m];
        order.iter().enumerate().for_each(|(new, &old)| position[old] = new);
        // The products that sum S's entries: none where the caller assembles them.
        let (summed, inv_mass): (&[_], &[f64]) = match mass {
            Some(mass) => (&products, mass.inverse()),
            None => (&[], &[]),
        };
        let mut by_slot: Vec<(usize, (u32, u32, f64))> = summed
            .iter()
            .map(|&(a, b, ja, jb, col)| {
                let (i, j) = (position[a].max(position[b]), position[a].min(position[b]));
                let slot = if i == j {
                    j
                } else {
                    let column = &row_idx[col_ptr[j]..col_ptr[j + 1]];
                    m + col_ptr[j] + column.binary_search(&i).expect("S's pattern lies inside L's")
                };
                (slot, (index(ja), index(jb), inv_mass[col]))
            })
            .collect();
        by_slot.sort_by_key(|&(slot, _)| slot);
        let mut sum_ptr = vec![0; m + row_idx.len() + 1];
        for &(slot, _) in &by_slot {
            sum_ptr[slot + 1] += 1;
        }
        for i in 0..sum_ptr.len() - 1 {
            sum_ptr[i + 1] += sum_ptr[i];
        }
        // Row patterns of L, by walking its columns in order.
        let mut row_ptr = vec![0; m + 1];
        for &i in &row_idx {
            row_ptr[i + 1] += 1;
        }
        for i in 0..m {
            row_ptr[i + 1] += row_ptr[i];
        }
        let mut fill = row_ptr.clone();
        let mut row_entries = vec![(0, 0); row_idx.len()];
        for k in 0..m {
            for p in col_ptr[k]..col_ptr[k + 1] {
                let i = row_idx[p];
                row_entries[fill[i]] = (index(k), index(p));
                fill[i] += 1;
            }
        }
        let indices = |v: Vec<usize>| v.into_iter().map(index).collect::<Vec<u32>>();
        let schur = Self {
            m,
            lower: vec![0.0; row_idx.len()],
            scaled: vec![0.0; row_idx.len()],
            row_idx: row_idx.iter().map(|&i| index(order[i])).collect(),
            order: indices(order),
            col_ptr: indices(col_ptr),
            row_ptr: indices(row_ptr),
            row_entries,
            sum_ptr: indices(sum_ptr),
            terms: by_slot.into_iter().map(|(_, t)| t).collect(),
            inv_d: vec![0.0; m],
            work: vec![0.0; m],
            nnz: pattern.nnz(),
            summed: mass.is_some(),
            dependent: DependentRows::Error,
            dropped: 0,
            tolerance: DependentRows::Error.tolerance(),
        };
        schur.check();
        schur
    }

    /// Checks that every index the structure holds is in bounds of the
    /// array it indexes, which the unchecked factorization relies on.
    fn check(&self) {
        let (m, nl) = (self.m, self.lower.len());
        let ptr_ok = |ptr: &[u32], len: usize, end: usize| {
            ptr.len() == len && ptr[0] == 0 && ptr.windows(2).all(|w| w[0] <= w[1]) && ptr[len - 1] as usize == end
        };
        let ok = self.order.len() == m
            && self.order.iter().all(|&i| (i as usize) < m)
            && ptr_ok(&self.col_ptr, m + 1, nl)
            && self.row_idx.len() == nl
            && self.row_idx.iter().all(|&i| (i as usize) < m)
            && ptr_ok(&self.row_ptr, m + 1, self.row_entries.len())
            && self.row_entries.iter().all(|&(k, at)| (k as usize) < m && at < self.col_ptr[k as usize + 1])
            && ptr_ok(&self.sum_ptr, m + nl + 1, self.terms.len())
            && self.terms.iter().all(|&(a, b, _)| (a as usize) < self.nnz && (b as usize) < self.nnz)
            && self.scaled.len() == nl
            && self.inv_d.len() == m
            && self.work.len() == m;
        assert!(ok, "inconsistent structure of S");
        // A row reads each coordinate once, so its diagonal products are squares.
        let squares = self.terms[..self.sum_ptr[m] as usize].iter().all(|&(a, b, _)| a == b);
        assert!(squares, "a constraint row reads a coordinate twice");
    }

    /// Entries of `S` the factorization reads: `m` diagonal ones, then one
    /// per entry of `L` (zero for fill).
    pub fn slots(&self) -> usize {
        self.m + self.lower.len()
    }

    /// The slot of `S`'s entry `(a, b)` (original rows), for
    /// [`factor_and_solve_assembled`](Self::factor_and_solve_assembled):
    /// diagonal entries at their elimination position, the others at their
    /// entry of `L`. Panics if the entry is not in `L`'s pattern.
    pub fn slot_finder(&self) -> impl Fn(usize, usize) -> usize + '_ {
        let mut position = vec![0; self.m];
        self.order.iter().enumerate().for_each(|(new, &old)| position[old as usize] = new);
        move |a, b| {
            let (i, j) = (position[a].max(position[b]), position[a].min(position[b]));
            if i == j {
                return j;
            }
            // A column's rows are in elimination order.
            let column = &self.row_idx[self.col_ptr[j] as usize..self.col_ptr[j + 1] as usize];
            let at = column.binary_search_by_key(&i, |&r| position[r as usize]).expect("S's pattern lies inside L's");
            self.m + self.col_ptr[j] as usize + at
        }
    }

    /// Sets what a dependent row does in the next factorizations.
    pub fn set_dependent_rows(&mut self, dependent: DependentRows) {
        (self.dependent, self.tolerance) = (dependent, dependent.tolerance());
    }

    /// Rows the last factorization dropped as dependent (0 unless tolerated).
    pub fn dependent_rows(&self) -> usize {
        self.dropped
    }

    /// Whether `L`'s pattern has fewer entries than the full triangle.
    pub fn is_sparse(&self) -> bool {
        below_triangle(self.lower.len(), self.m)
    }
}

/// Whether `entries` strictly-lower entries of `L` are fewer than the full
/// triangle of `m` rows has.
pub(crate) fn below_triangle(entries: usize, m: usize) -> bool {
    entries < m * m.saturating_sub(1) / 2
}

/// The most right-hand sides [`Schur::solve_many`] takes at once.
pub(crate) const MAX_RIGHT_HAND_SIDES: usize = 4;

/// `a · b`, for the small dense products of the momentum code.
pub(crate) fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(a, b)| a * b).sum()
}

/// `|x|`.
pub(crate) fn norm(x: &[f64]) -> f64 {
    dot(x, x).sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Rows of a star: a hub row on coordinates 0..2 and `arms` chains of
    /// `len` rows, each row coupling two consecutive coordinate pairs;
    /// numbered level by level so that the natural order fills in.
    fn star(arms: usize, len: usize) -> (Pattern, usize) {
        let mut rows: Vec<Vec<usize>> = vec![vec![0, 1]];
        let pair = |arm: usize, level: usize| 2 + 2 * (level * arms + arm);
        for level in 0..len {
            for arm in 0..arms {
                let inner = if level == 0 { 0 } else { pair(arm, level - 1) };
                let outer = pair(arm, level);
                rows.push(vec![inner, inner + 1, outer, outer + 1]);
            }
        }
        let mut pattern = Pattern { start: vec![0], cols: Vec::new(), read: Vec::new() };
        for r in rows {
            pattern.cols.extend(r.iter().map(|&c| c as u32));
            pattern.read.extend(r.iter().map(|_| true));
            pattern.start.push(pattern.cols.len() as u32);
        }
        (pattern, 2 + 2 * arms * len)
    }

    /// A `w × w` lattice of coordinate pairs with a row on every edge
    /// (a net of rods), rows numbered with a stride: a pattern without a
    /// fill-free order, in a numbering that fills more than AMD's.
    fn net(w: usize, stride: usize) -> (Pattern, usize) {
        let pair = |x: usize, y: usize| 2 * (y * w + x);
        let mut edges = Vec::new();
        for y in 0..w {
            for x in 0..w {
                if x + 1 < w {
                    edges.push((pair(x, y), pair(x + 1, y)));
                }
                if y + 1 < w {
                    edges.push((pair(x, y), pair(x, y + 1)));
                }
            }
        }
        let mut pattern = Pattern { start: vec![0], cols: Vec::new(), read: Vec::new() };
        for r in 0..edges.len() {
            let (a, b) = edges[(r * stride) % edges.len()];
            pattern.cols.extend([a, a + 1, b, b + 1].map(|c| c as u32));
            pattern.read.extend([true; 4]);
            pattern.start.push(pattern.cols.len() as u32);
        }
        (pattern, 2 * w * w)
    }

    fn values(len: usize, seed: f64) -> Vec<f64> {
        (0..len).map(|i| (seed + 1.7 * i as f64).sin() + 0.2 * (i % 3) as f64).collect()
    }

    /// `‖S x − b‖ / ‖b‖` with `S = J M⁻¹ Jᵀ` formed densely.
    fn residual(pattern: &Pattern, jac: &[f64], inv_mass: &[f64], x: &[f64], b: &[f64]) -> f64 {
        let m = pattern.start.len() - 1;
        let mut jt_x = vec![0.0; inv_mass.len()];
        for r in 0..m {
            for j in pattern.row(r) {
                let c = pattern.cols[j] as usize;
                jt_x[c] += jac[j] * x[r] * inv_mass[c];
            }
        }
        let mut worst = 0.0_f64;
        for r in 0..m {
            let s_x: f64 = pattern.row(r).map(|j| jac[j] * jt_x[pattern.cols[j] as usize]).sum();
            worst = worst.max((s_x - b[r]).abs());
        }
        worst / b.iter().fold(0.0_f64, |a, b| a.max(b.abs()))
    }

    #[test]
    fn dense_and_reordered_sparse_factors_solve_s() {
        for (name, (pattern, n)) in [("star", star(5, 12)), ("net", net(8, 17))] {
            let m = pattern.start.len() - 1;
            let jac = values(pattern.nnz(), 0.3);
            let mass = DiagonalMass::new(values(n, 1.1).iter().map(|x| 1.5 + x).collect()).unwrap();
            let inv_mass = mass.inverse();
            for solver in [LinearSolver::Dense, LinearSolver::Sparse] {
                let mut s = Schur::new(&pattern, &mass, solver);
                // The sparse analysis must have reordered (the natural order fills).
                let natural = s.order.iter().enumerate().all(|(i, &o)| i == o as usize);
                assert_eq!(!natural, solver == LinearSolver::Sparse, "{name}");
                if solver == LinearSolver::Sparse {
                    let off_diagonal_of_s = products(&pattern, n)
                        .iter()
                        .filter(|&&(a, b, ..)| a != b)
                        .map(|&(a, b, ..)| (a, b))
                        .collect::<std::collections::BTreeSet<_>>()
                        .len();
                    let fill = s.row_idx.len() - off_diagonal_of_s;
                    // The star is chordal: peeled without fill. The net is not.
                    assert_eq!(fill == 0, name == "star", "{name}: fill {fill}");
                }
                // Solved along with the factorization, and again with it.
                for seed in [2.0, 2.5] {
                    let b = values(m, seed);
                    let mut x = b.clone();
                    if seed == 2.0 {
                        s.factor_and_solve(&jac, &mut x).unwrap();
                    } else {
                        s.solve(&mut x);
                    }
                    let r = residual(&pattern, &jac, inv_mass, &x, &b);
                    assert!(r < 1e-12, "{name} {solver:?}: relative residual {r:e}");
                }
            }
        }
    }

    /// `m` rows in a chain, row `r` coupling coordinate pairs `r` and `r + 1`: `S` is tridiagonal.
    fn chain(m: usize) -> (Pattern, usize) {
        let mut pattern = Pattern { start: vec![0], cols: Vec::new(), read: Vec::new() };
        for r in 0..m {
            pattern.cols.extend([2 * r, 2 * r + 1, 2 * r + 2, 2 * r + 3].map(|c| c as u32));
            pattern.read.extend([true; 4]);
            pattern.start.push(pattern.cols.len() as u32);
        }
        (pattern, 2 * m + 2)
    }

    /// A chain, the star and net given, and a pattern with a dependent
    /// row: each with its Jacobian values and a diagonal mass.
    fn cases(
        star: (Pattern, usize),
        net: (Pattern, usize),
    ) -> Vec<(&'static str, Pattern, usize, Vec<f64>, DiagonalMass)> {
        let (with_dependent, n_dependent, jac_dependent) = repeated_row(1.0);
        let shapes = [
            ("chain", chain(20), None),
            ("star", star, None),
            ("net", net, None),
            ("dependent", (with_dependent, n_dependent), Some(jac_dependent)),
        ];
        shapes
            .into_iter()
            .map(|(name, (pattern, n), jac)| {
                let jac = jac.unwrap_or_else(|| values(pattern.nnz(), 0.3));
                let mass = DiagonalMass::new(values(n, 1.1).iter().map(|x| 1.5 + x).collect()).unwrap();
                (name, pattern, n, jac, mass)
            })
            .collect()
    }

    #[test]
    fn below_sparse_from_auto_takes_the_natural_pattern_and_gives_the_full_triangles_answers_to_the_bit() {
        for (name, pattern, _, jac, mass) in cases(star(3, 4), net(4, 3)) {
            let m = pattern.start.len() - 1;
            assert!(m < SPARSE_FROM, "{name}");
            let (mut auto, mut dense) =
                (Schur::new(&pattern, &mass, LinearSolver::Auto), Schur::new(&pattern, &mass, LinearSolver::Dense));
            // The rows' own order, so that the same dependent rows are dropped.
            assert!(auto.order.iter().enumerate().all(|(i, &o)| i == o as usize), "{name}");
            assert!(auto.row_idx.len() <= dense.row_idx.len(), "{name}");
            if name == "chain" {
                assert_eq!(auto.row_idx.len(), m - 1, "a tridiagonal S fills nothing in its own order");
            }
            for rows in [DependentRows::Error, DependentRows::Tolerate] {
                auto.set_dependent_rows(rows);
                dense.set_dependent_rows(rows);
                let b = values(m, 2.0);
                let (mut x_auto, mut x_dense) = (b.clone(), b.clone());
                let outcome = auto.factor_and_solve(&jac, &mut x_auto);
                assert_eq!(outcome, dense.factor_and_solve(&jac, &mut x_dense), "{name} {rows:?}");
                if outcome.is_ok() {
                    // Equal as numbers: the bits, but for the sign of a dropped row's zero.
                    assert_eq!(x_auto, x_dense, "{name} {rows:?}");
                    let (mut y_auto, mut y_dense) = (values(m, 5.0), values(m, 5.0));
                    auto.solve(&mut y_auto);
                    dense.solve(&mut y_dense);
                    assert_eq!(y_auto, y_dense, "{name} {rows:?}");
                    let bits = |x: &[f64]| x.iter().filter(|v| **v != 0.0).map(|v| v.to_bits()).collect::<Vec<_>>();
                    assert_eq!(bits(&x_auto), bits(&x_dense), "{name} {rows:?}");
                }
            }
        }
    }

    #[test]
    fn entries_assembled_by_the_caller_by_slot_factor_as_the_summed_ones() {
        for (name, pattern, n, jac, mass) in cases(star(5, 12), net(8, 17)) {
            let m = pattern.start.len() - 1;
            for solver in [LinearSolver::Dense, LinearSolver::Sparse] {
                let mut summed = Schur::new(&pattern, &mass, solver);
                let mut assembled = Schur::assembled_by_caller(&pattern, n, solver);
                assert_eq!(assembled.order, summed.order, "{name} {solver:?}");
                // Each entry summed in the order of the summed structure's terms.
                let mut entries = vec![0.0; assembled.slots()];
                let slot = assembled.slot_finder();
                for (a, b, ja, jb, col) in products(&pattern, n) {
                    entries[slot(a, b)] += jac[ja] * jac[jb] * mass.inverse()[col];
                }
                drop(slot);
                for rows in [DependentRows::Error, DependentRows::Tolerate] {
                    summed.set_dependent_rows(rows);
                    assembled.set_dependent_rows(rows);
                    let b = values(m, 2.0);
                    let (mut x_summed, mut x_assembled) = (b.clone(), b.clone());
                    let outcome = summed.factor_and_solve(&jac, &mut x_summed);
                    let assembled_outcome = assembled.factor_and_solve_assembled(&entries, &mut x_assembled);
                    assert_eq!(outcome, assembled_outcome, "{name} {solver:?} {rows:?}");
                    if outcome.is_ok() {
                        // The same sums in the same order: equal as numbers.
                        assert_eq!(x_summed, x_assembled, "{name} {solver:?} {rows:?}");
                        assert_eq!(summed.dependent_rows(), assembled.dependent_rows(), "{name}");
                    }
                }
            }
        }
    }

    #[test]
    fn several_right_hand_sides_are_solved_exactly_as_one_at_a_time() {
        let (pattern, n) = net(8, 17);
        let m = pattern.start.len() - 1;
        let jac = values(pattern.nnz(), 0.3);
        let mass = DiagonalMass::new(values(n, 1.1).iter().map(|x| 1.5 + x).collect()).unwrap();
        for solver in [LinearSolver::Dense, LinearSolver::Sparse] {
            let mut s = Schur::new(&pattern, &mass, solver);
            s.factor_and_solve(&jac, &mut vec![1.0; m]).unwrap();
            let rhs: Vec<Vec<f64>> = (0..4).map(|k| values(m, 3.0 + k as f64)).collect();
            let alone: Vec<Vec<f64>> = rhs
                .iter()
                .map(|b| {
                    let mut x = b.clone();
                    s.solve_many(&mut [&mut x]);
                    x
                })
                .collect();
            for k in 1..=4 {
                let mut together = rhs[..k].to_vec();
                let mut refs: Vec<&mut [f64]> = together.iter_mut().map(|b| b.as_mut_slice()).collect();
                s.solve_many(&mut refs);
                assert_eq!(together, alone[..k], "{solver:?}, {k} at once");
                assert!(residual(&pattern, &jac, mass.inverse(), &together[0], &rhs[0]) < 1e-12);
            }
        }
    }

    #[test]
    fn a_dependent_row_is_named_and_a_blown_up_jacobian_is_not_called_singular() {
        let (pattern, n, jac) = repeated_row(1.0);
        let mass = DiagonalMass::new(vec![1.0; n]).unwrap();
        let m = pattern.start.len() - 1;
        for solver in [LinearSolver::Dense, LinearSolver::Sparse] {
            let mut s = Schur::new(&pattern, &mass, solver);
            let err = s.factor_and_solve(&jac, &mut vec![1.0; m]).unwrap_err();
            assert!(matches!(err, Breakdown::Singular(r) if r == m - 1 || r == m - 2), "{solver:?}: {err:?}");
            let mut bad = values(pattern.nnz(), 0.7);
            bad[3] = f64::INFINITY;
            assert_eq!(s.factor_and_solve(&bad, &mut vec![1.0; m]), Err(Breakdown::NonFinite), "{solver:?}");
            // Tolerated, the blown-up Jacobian is still not called singular.
            s.set_dependent_rows(DependentRows::Tolerate);
            assert_eq!(s.factor_and_solve(&bad, &mut vec![1.0; m]), Err(Breakdown::NonFinite), "{solver:?}");
        }
    }

    /// A star pattern whose last row repeats the row before it, `scale` times.
    fn repeated_row(scale: f64) -> (Pattern, usize, Vec<f64>) {
        let (mut pattern, n) = star(3, 4);
        let last = pattern.row(pattern.start.len() - 2);
        let repeated: Vec<u32> = pattern.cols[last.clone()].to_vec();
        pattern.cols.extend(&repeated);
        pattern.read.extend(repeated.iter().map(|_| true));
        pattern.start.push(pattern.cols.len() as u32);
        let mut jac = values(pattern.nnz(), 0.7);
        let k = repeated.len();
        let tail = jac.len() - k;
        let copy = jac[tail - k..tail].to_vec();
        jac[tail..].iter_mut().zip(&copy).for_each(|(j, c)| *j = scale * c);
        (pattern, n, jac)
    }

    /// `M⁻¹ Φ_qᵀ x`.
    fn weighted_jt(pattern: &Pattern, jac: &[f64], inv_mass: &[f64], x: &[f64]) -> Vec<f64> {
        let mut out = vec![0.0; inv_mass.len()];
        for (r, &xr) in x.iter().enumerate() {
            for j in pattern.row(r) {
                let c = pattern.cols[j] as usize;
                out[c] += inv_mass[c] * jac[j] * xr;
            }
        }
        out
    }

    #[test]
    fn a_tolerated_dependent_row_is_dropped_with_a_zero_multiplier_and_the_same_response() {
        // Twice the row before: dependent, and not of the same scale.
        let (pattern, n, jac) = repeated_row(2.0);
        let m = pattern.start.len() - 1;
        let mass: DiagonalMass = DiagonalMass::new(values(n, 1.1).iter().map(|x| 1.5 + x).collect()).unwrap();
        let inv_mass = mass.inverse();
        // b = S y = Φ_q M⁻¹ Φ_qᵀ y: in the range of S.
        let y = values(m, 4.0);
        let w = weighted_jt(&pattern, &jac, inv_mass, &y);
        let b: Vec<f64> = (0..m).map(|r| pattern.row(r).map(|j| jac[j] * w[pattern.cols[j] as usize]).sum()).collect();
        for solver in [LinearSolver::Dense, LinearSolver::Sparse] {
            let mut s = Schur::new(&pattern, &mass, solver);
            s.set_dependent_rows(DependentRows::Tolerate);
            let mut x = b.clone();
            s.factor_and_solve(&jac, &mut x).unwrap();
            assert_eq!(s.dependent_rows(), 1, "{solver:?}");
            let dropped: Vec<usize> = (0..m).filter(|&r| x[r] == 0.0).collect();
            assert!(dropped == [m - 1] || dropped == [m - 2], "{solver:?}: zero multipliers {dropped:?}");
            let r = residual(&pattern, &jac, inv_mass, &x, &b);
            assert!(r < 1e-12, "{solver:?}: relative residual {r:e}");
            // The response M⁻¹ Φ_qᵀ x is the unique one, though x is not y.
            let (got, want) = (weighted_jt(&pattern, &jac, inv_mass, &x), &w);
            let err = got.iter().zip(want).fold(0.0_f64, |a, (g, w)| a.max((g - w).abs()));
            assert!(err < 1e-12, "{solver:?}: response off by {err:e}");
            // Further solves with the factorization drop the same row.
            let mut again = b.clone();
            s.solve(&mut again);
            assert_eq!(again, x, "{solver:?}");
            // An independent system afterwards counts no dropped row.
            let (indep, _) = star(3, 4);
            let mut t = Schur::new(&indep, &mass, solver);
            t.set_dependent_rows(DependentRows::Tolerate);
            t.factor_and_solve(&values(indep.nnz(), 0.7), &mut vec![1.0; m - 1]).unwrap();
            assert_eq!(t.dependent_rows(), 0, "{solver:?}");
        }
    }
}
