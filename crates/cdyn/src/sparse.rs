//! Symbolic analysis of a sparse `S = Φ_q M⁻¹ Φ_qᵀ` with faer: the
//! elimination order (AMD, or the natural order when it fills no more —
//! chains and trees often come ordered) and the pattern of its Cholesky
//! factor. Done once per model; the numeric factorization in `linalg.rs`
//! follows the pattern found here at every step.

use crate::linalg::Structure;
use faer::Side;
use faer::sparse::SymbolicSparseColMatRef;
use faer::sparse::linalg::SupernodalThreshold;
use faer::sparse::linalg::cholesky::{
    CholeskySymbolicParams, SymbolicCholeskyRaw, SymmetricOrdering, factorize_symbolic_cholesky,
};

/// Analyses the `m × m` symmetric pattern with entries `(a, b)`, `a ≥ b`
/// (repeats allowed).
pub(crate) fn analyse(m: usize, entries: impl Iterator<Item = (usize, usize)>) -> Structure {
    // Upper triangle by columns: entry (b, a), b ≤ a, in column a.
    let mut columns: Vec<Vec<usize>> = vec![Vec::new(); m];
    for (a, b) in entries {
        columns[a].push(b);
    }
    let mut col_ptr = vec![0];
    let mut row_idx = Vec::new();
    for (a, rows) in columns.iter_mut().enumerate() {
        rows.push(a);
        rows.sort_unstable();
        rows.dedup();
        row_idx.extend_from_slice(rows);
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
