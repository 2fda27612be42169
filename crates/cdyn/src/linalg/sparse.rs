//! Symbolic analysis of a sparse `S = Φ_q M⁻¹ Φ_qᵀ`: the elimination
//! order and the pattern of its Cholesky factor. Done once per model; the
//! numeric factorization in `linalg.rs` follows the pattern found here at
//! every step.
//!
//! Chains and trees (more generally, chordal patterns) are eliminated
//! without fill by peeling, round after round, every row whose neighbours
//! are already coupled to each other. Rows of one round are independent,
//! so their eliminations overlap in the processor instead of waiting on
//! one another: a chain peeled from both ends has half the dependent
//! divisions of one eliminated from the top. Other patterns get faer's
//! AMD ordering, or the natural order when that fills no more.
//!
//! Also here, as the other sparse structure: the [`Pattern`] of `Φ_q` itself.

use faer::Side;
use faer::sparse::SymbolicSparseColMatRef;
use faer::sparse::linalg::SupernodalThreshold;
use faer::sparse::linalg::cholesky::{
    CholeskySymbolicParams, SymbolicCholeskyRaw, SymmetricOrdering, factorize_symbolic_cholesky,
};
use std::collections::BTreeSet;

/// Sparsity of `Φ_q`: row `r` has entries at `cols[start[r]..start[r + 1]]`.
///
/// Indices are `u32`: the pattern is read in every step, and for large
/// models (a 10 000-body chain) half the bytes is a measurable share of the
/// memory traffic. [`ModelBuilder::build`](crate::model::ModelBuilder::build) checks that they fit.
#[derive(Debug, Clone, Default)]
pub struct Pattern {
    /// Where each row's entries start in `cols` (`m + 1` entries).
    pub start: Vec<u32>,
    /// The coordinate of each entry, row after row.
    pub cols: Vec<u32>,
    /// Whether each entry can be non-zero ([`Constraint::reads`](crate::Constraint::reads)).
    pub read: Vec<bool>,
}

impl Pattern {
    /// The positions in `cols` (and in the Jacobian values) of row `r`'s entries.
    pub fn row(&self, r: usize) -> std::ops::Range<usize> {
        self.start[r] as usize..self.start[r + 1] as usize
    }
    /// Number of entries of `Φ_q`.
    pub fn nnz(&self) -> usize {
        self.cols.len()
    }
}

/// A symmetric elimination order and the pattern of the strictly lower
/// triangle of `L` in it, by columns with rows ascending.
pub(crate) struct Structure {
    /// `perm[i]` is the original row eliminated `i`-th; `None` for the natural order.
    pub perm: Option<Vec<usize>>,
    /// Start of each column of `L` in `row_idx` (`m + 1` entries).
    pub col_ptr: Vec<usize>,
    /// Row (in elimination positions) of each strictly-lower entry of `L`.
    pub row_idx: Vec<usize>,
}

impl Structure {
    /// The full lower triangle in the natural order.
    pub(crate) fn dense(m: usize) -> Self {
        let col_ptr = (0..=m).map(|j| j * m - j * (j + 1) / 2).collect();
        let row_idx = (0..m).flat_map(|j| j + 1..m).collect();
        Self { perm: None, col_ptr, row_idx }
    }
}

/// The pattern of `L` for the `m × m` symmetric pattern with entries
/// `(a, b)` in the natural order: no fill-reducing permutation, so that
/// the rows are eliminated, and dependent ones dropped, in their own order.
/// Its entries are a subset of the full triangle's, and the elimination
/// along it does the same arithmetic less the products of structural zeros.
pub(crate) fn natural(m: usize, entries: impl Iterator<Item = (usize, usize)>) -> Structure {
    let mut below: Vec<BTreeSet<usize>> = vec![BTreeSet::new(); m];
    for (a, b) in entries {
        if a != b {
            below[a.min(b)].insert(a.max(b));
        }
    }
    let (mut col_ptr, mut row_idx) = (vec![0], Vec::new());
    for j in 0..m {
        let column = std::mem::take(&mut below[j]);
        // Eliminating row j couples its rows below it with each other; the
        // first of them (its parent in the elimination tree) takes the rest.
        let mut rows = column.iter().copied();
        if let Some(parent) = rows.next() {
            below[parent].extend(rows);
        }
        row_idx.extend(column);
        col_ptr.push(row_idx.len());
    }
    Structure { perm: None, col_ptr, row_idx }
}

/// Analyses the `m × m` symmetric pattern with entries `(a, b)`, `a ≥ b`
/// (repeats allowed).
pub(crate) fn analyse(m: usize, entries: impl Iterator<Item = (usize, usize)>) -> Structure {
    let mut neighbours: Vec<BTreeSet<usize>> = vec![BTreeSet::new(); m];
    for (a, b) in entries {
        if a != b {
            neighbours[a].insert(b);
            neighbours[b].insert(a);
        }
    }
    if let Some(order) = peel(neighbours.clone()) {
        return without_fill(&order, &neighbours);
    }
    // Upper triangle by columns: rows b ≤ a in column a, ascending.
    let mut col_ptr = vec![0];
    let mut row_idx = Vec::new();
    for (a, rows) in neighbours.iter().enumerate() {
        row_idx.extend(rows.range(..a));
        row_idx.push(a);
        col_ptr.push(row_idx.len());
    }
    let structure = SymbolicSparseColMatRef::new_checked(m, m, &col_ptr, None, &row_idx);
    let params = CholeskySymbolicParams {
        // Simplicial: its factor's pattern is plain compressed columns.
        supernodal_flop_ratio_threshold: SupernodalThreshold::FORCE_SIMPLICIAL,
        ..Default::default()
    };
    let analyse = |ordering| {
        factorize_symbolic_cholesky(structure, Side::Upper, ordering, params)
            .expect("symbolic Cholesky of a valid pattern")
    };
    let amd = analyse(SymmetricOrdering::Amd);
    let natural = analyse(SymmetricOrdering::Identity);
    let symbolic = if natural.len_val() <= amd.len_val() { natural } else { amd };
    let SymbolicCholeskyRaw::Simplicial(factor) = symbolic.raw() else { unreachable!("simplicial forced") };
    // faer's columns include the diagonal; keep the strictly lower part, sorted.
    let mut col_ptr = vec![0];
    let mut row_idx = Vec::new();
    for j in 0..m {
        let start = row_idx.len();
        let rows = &factor.row_idx()[factor.col_ptr()[j]..factor.col_ptr()[j + 1]];
        row_idx.extend(rows.iter().copied().filter(|&i| i > j));
        row_idx[start..].sort_unstable();
        col_ptr.push(row_idx.len());
    }
    let perm = symbolic.perm().map(|p| p.arrays().0.to_vec());
    Structure { perm, col_ptr, row_idx }
}

/// Rows whose neighbours number more than this are not tested for being
/// simplicial (the test is quadratic in the degree).
const MAX_PEEL_DEGREE: usize = 32;

/// An elimination order without fill, by rounds of simplicial rows (whose
/// remaining neighbours are pairwise coupled); `None` if peeling gets stuck.
fn peel(mut neighbours: Vec<BTreeSet<usize>>) -> Option<Vec<usize>> {
    let m = neighbours.len();
    let simplicial = |nb: &[BTreeSet<usize>], u: usize| {
        nb[u].len() <= MAX_PEEL_DEGREE && nb[u].iter().all(|&a| nb[u].iter().all(|&b| a >= b || nb[a].contains(&b)))
    };
    let mut order = Vec::with_capacity(m);
    let mut done = vec![false; m];
    // Only rows whose neighbourhood shrank can have become simplicial.
    let mut candidates: Vec<usize> = (0..m).collect();
    let mut seen = vec![usize::MAX; m];
    for round in 0.. {
        if order.len() == m {
            return Some(order);
        }
        let peeled: Vec<usize> =
            candidates.iter().copied().filter(|&u| !done[u] && simplicial(&neighbours, u)).collect();
        if peeled.is_empty() {
            return None;
        }
        candidates.clear();
        for &u in &peeled {
            done[u] = true;
            order.push(u);
            for a in std::mem::take(&mut neighbours[u]) {
                neighbours[a].remove(&u);
                if !done[a] && seen[a] != round {
                    seen[a] = round;
                    candidates.push(a);
                }
            }
        }
    }
    unreachable!()
}

/// The structure of an elimination order without fill: `L`'s pattern is
/// `S`'s, renumbered.
fn without_fill(order: &[usize], neighbours: &[BTreeSet<usize>]) -> Structure {
    let mut position = vec![0; order.len()];
    for (new, &old) in order.iter().enumerate() {
        position[old] = new;
    }
    let mut col_ptr = vec![0];
    let mut row_idx = Vec::new();
    for (j, &old) in order.iter().enumerate() {
        let start = row_idx.len();
        row_idx.extend(neighbours[old].iter().map(|&a| position[a]).filter(|&i| i > j));
        row_idx[start..].sort_unstable();
        col_ptr.push(row_idx.len());
    }
    let natural = order.iter().enumerate().all(|(i, &o)| i == o);
    Structure { perm: (!natural).then(|| order.to_vec()), col_ptr, row_idx }
}
