//! The `m × m` system `S = Φ_q M⁻¹ Φ_qᵀ`: its assembly from the sparse
//! Jacobian and its factorization.
//!
//! Assembly is a precomputed list of products `J_a J_b / m_c` (one per pair
//! of rows sharing a coordinate), so forming `S` costs the same as reading
//! the Jacobian for chains and trees, and never allocates.

use crate::model::Pattern;

/// Why `S` could not be factored.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Breakdown {
    /// This row is linearly dependent on the rows before it.
    Singular(usize),
    /// `S` has non-finite entries: the state has blown up.
    NonFinite,
}

/// One contribution `J[ja] J[jb] / m[col]` to entry `s` of `S`.
#[derive(Debug, Clone, Copy)]
struct Term {
    s: usize,
    ja: usize,
    jb: usize,
    col: usize,
}

/// Dense Cholesky factorization of `S`, stored lower-triangular row-major.
pub(crate) struct DenseSchur {
    m: usize,
    terms: Vec<Term>,
    a: Vec<f64>,
    diag: Vec<f64>,
}

/// Pivots below this fraction of the assembled diagonal mean the row
/// depends on the rows before it.
pub(crate) const PIVOT_TOLERANCE: f64 = 1e-12;

/// For every pair of rows `(a ≥ b)` sharing a coordinate, the products
/// that make `S_ab`, as `(a, b, ja, jb, col)`.
pub(crate) fn products(pattern: &Pattern, n: usize) -> Vec<(usize, usize, usize, usize, usize)> {
    let m = pattern.start.len() - 1;
    // For every coordinate, the Jacobian entries that touch it.
    let mut by_col: Vec<Vec<(usize, usize)>> = vec![Vec::new(); n];
    for r in 0..m {
        for j in pattern.row(r) {
            by_col[pattern.cols[j]].push((r, j));
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

impl DenseSchur {
    pub fn new(pattern: &Pattern, n: usize) -> Self {
        let m = pattern.start.len() - 1;
        let mut terms: Vec<Term> = products(pattern, n)
            .into_iter()
            .map(|(ra, rb, ja, jb, col)| Term { s: ra * m + rb, ja, jb, col })
            .collect();
        terms.sort_by_key(|t| t.s);
        Self { m, terms, a: vec![0.0; m * m], diag: vec![0.0; m] }
    }

    /// Assembles `S` from the Jacobian values and factors it.
    pub fn factor(&mut self, jac: &[f64], inv_mass: &[f64]) -> Result<(), Breakdown> {
        let m = self.m;
        self.a.fill(0.0);
        for t in &self.terms {
            self.a[t.s] += jac[t.ja] * jac[t.jb] * inv_mass[t.col];
        }
        for r in 0..m {
            self.diag[r] = self.a[r * m + r];
        }
        for j in 0..m {
            let mut d = self.a[j * m + j];
            for k in 0..j {
                d -= self.a[j * m + k] * self.a[j * m + k];
            }
            if !d.is_finite() {
                return Err(Breakdown::NonFinite);
            }
            if d.is_nan() || d <= PIVOT_TOLERANCE * self.diag[j] {
                return Err(Breakdown::Singular(j));
            }
            let d = d.sqrt();
            self.a[j * m + j] = d;
            for i in j + 1..m {
                let mut s = self.a[i * m + j];
                for k in 0..j {
                    s -= self.a[i * m + k] * self.a[j * m + k];
                }
                self.a[i * m + j] = s / d;
            }
        }
        Ok(())
    }

    /// Solves `S x = b` in place with the current factorization.
    pub fn solve(&self, b: &mut [f64]) {
        let m = self.m;
        for i in 0..m {
            let mut s = b[i];
            for k in 0..i {
                s -= self.a[i * m + k] * b[k];
            }
            b[i] = s / self.a[i * m + i];
        }
        for i in (0..m).rev() {
            let mut s = b[i];
            for k in i + 1..m {
                s -= self.a[k * m + i] * b[k];
            }
            b[i] = s / self.a[i * m + i];
        }
    }
}

/// How to factor `Φ_q M⁻¹ Φ_qᵀ`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum LinearSolver {
    /// Dense below [`SPARSE_FROM`] constraint rows, sparse from there on.
    #[default]
    Auto,
    Dense,
    Sparse,
}

/// Constraint rows from which `Auto` factors sparse: below it a dense
/// Cholesky of `S` is cheaper than the sparse machinery.
pub const SPARSE_FROM: usize = 48;

/// `S` with the chosen factorization.
pub(crate) enum Schur {
    Dense(DenseSchur),
    Sparse(Box<crate::sparse::SparseSchur>),
}

impl Schur {
    pub fn new(pattern: &Pattern, n: usize, solver: LinearSolver) -> Self {
        let m = pattern.start.len() - 1;
        let sparse = match solver {
            LinearSolver::Auto => m >= SPARSE_FROM,
            LinearSolver::Dense => false,
            LinearSolver::Sparse => m > 0,
        };
        if sparse {
            Schur::Sparse(Box::new(crate::sparse::SparseSchur::new(pattern, n)))
        } else {
            Schur::Dense(DenseSchur::new(pattern, n))
        }
    }

    pub fn factor(&mut self, jac: &[f64], inv_mass: &[f64]) -> Result<(), Breakdown> {
        match self {
            Schur::Dense(d) => d.factor(jac, inv_mass),
            Schur::Sparse(s) => s.factor(jac, inv_mass),
        }
    }

    pub fn solve(&self, b: &mut [f64]) {
        match self {
            Schur::Dense(d) => d.solve(b),
            Schur::Sparse(s) => s.solve(b),
        }
    }
}
