//! The pivot test shared by every `L D Lᵀ` of `S` (dense, sparse, and the
//! small systems' in `small/`), what it does with a dependent row
//! ([`DependentRows`]), why a factorization fails ([`Breakdown`]), and the
//! dense factorization of a small `S`.

/// Why `S` could not be factored.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
pub enum Breakdown {
    /// This row is linearly dependent on the rows before it.
    Singular(usize),
    /// `S` has non-finite entries: the state has blown up.
    NonFinite,
    /// The configuration-dependent mass matrix `M(q)` is not positive
    /// definite at this state (its pivot of this coordinate): the kinetic
    /// energy elements leave a coordinate without inertia there.
    Mass(usize),
}

/// Pivots below this fraction of the assembled diagonal mean the row
/// depends on the rows before it: an error (the strict default).
///
/// `d_j / S_jj` is the squared sine of the angle (in the metric `M⁻¹`)
/// between row `j` of `Φ_q` and the span of the rows eliminated before it,
/// so the test does not depend on the units or scale of a row. An exactly
/// dependent row leaves round-off, `d_j / S_jj` of order `ε ≈ 1e-16` times
/// a small growth factor; 1e-12 flags it with a margin of 10⁴.
const PIVOT_TOLERANCE: f64 = 1e-12;

/// Pivots below this fraction of the assembled diagonal are dropped with
/// [`DependentRows::Tolerate`]: rows within 1e-4 rad of the span of the
/// others.
///
/// Larger than [`PIVOT_TOLERANCE`] because redundant constraints are
/// dependent only *on* the constraint manifold: at a drift `|Φ| ~ δ` their
/// rows differ by `O(δ)`, so `d_j / S_jj ~ δ²`, and a row kept with such a
/// pivot enforces a second, slightly different constraint — its multiplier
/// grows like the right-hand side's `O(δ)` inconsistency over `δ²`. Measured
/// on the parallelogram with a redundant crank under energy-only control:
/// at 1e-12 the row came back once `|Φ|` drifted past 1e-7 and the run
/// diverged within 0.5 s; at 1e-8 drifts to about 1e-5 are absorbed. A
/// legitimately near-singular row (a mechanism within 1e-4 rad of a flat
/// position) is dropped instead of solved with a pivot 1e-8 of its scale,
/// where its equation is nearly implied by the others.
const DROP_TOLERANCE: f64 = 1e-8;

/// What to do with a constraint row that depends on the rows eliminated
/// before it (a pivot of `Φ_q M⁻¹ Φ_qᵀ` small relative to its diagonal
/// entry): redundant constraints, or a mechanism passing through a
/// singular position.
///
/// In scenario files: `[integrator] dependent_rows = "error"` or `"tolerate"`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "snake_case"))]
#[non_exhaustive]
pub enum DependentRows {
    /// Stop with an error naming the row. The default: a dependent row is
    /// far more often a modelling mistake (a joint entered twice) than an
    /// intended redundancy, and redundant constraints are opted into.
    #[default]
    Error,
    /// Solve without the row: its multiplier is 0 and the rows before it
    /// carry the whole reaction (a *basic* solution of the singular
    /// system, not the minimum-norm one). The accelerations are the unique
    /// ones whenever the constraint equations are consistent. Rows are
    /// dropped below 1e-8 of their diagonal entry (not 1e-12: redundant
    /// rows are dependent only on the constraint manifold, and a drift
    /// makes them independent by its square).
    Tolerate,
}

impl DependentRows {
    /// The fraction of its diagonal entry a pivot must exceed for its row
    /// to count as independent.
    #[inline(always)]
    pub(crate) fn tolerance(self) -> f64 {
        match self {
            DependentRows::Error => PIVOT_TOLERANCE,
            DependentRows::Tolerate => DROP_TOLERANCE,
        }
    }
}

/// The pivot test of every `L D Lᵀ` of `S` (this module's and the small
/// systems' one in `small/`): pivot `d` of the row `row()` whose assembled
/// diagonal entry is `s_jj`, for the Jacobian values `jac`. Returns `1/d`
/// for a pivot above `tolerance · s_jj` (`dependent.tolerance()`, chosen
/// once per factorization). One below means a dependent row — unless the
/// state has blown up, which is told apart so that it is not reported as
/// singular: the [`Breakdown`], or 0 and one more `dropped` row when
/// `dependent` tolerates it — which removes the row from the solve: its
/// column of `L` becomes `S_ij · 0 = 0` and its entry of `D⁻¹` is 0. A
/// passing pivot costs what the strict test alone did.
#[inline(always)]
pub(crate) fn inverse_pivot(
    d: f64,
    s_jj: f64,
    tolerance: f64,
    jac: &[f64],
    dependent: DependentRows,
    dropped: &mut usize,
    row: impl FnOnce() -> usize,
) -> Result<f64, Breakdown> {
    if d.is_nan() || d <= tolerance * s_jj {
        return dependent_pivot(d, jac, dependent, dropped, row);
    }
    Ok(1.0 / d)
}

/// The failing branch of [`inverse_pivot`], out of the factorization's loop.
#[cold]
#[inline(never)]
fn dependent_pivot(
    d: f64,
    jac: &[f64],
    dependent: DependentRows,
    dropped: &mut usize,
    row: impl FnOnce() -> usize,
) -> Result<f64, Breakdown> {
    if !d.is_finite() || jac.iter().any(|x| !x.is_finite()) {
        return Err(Breakdown::NonFinite);
    }
    match dependent {
        DependentRows::Error => Err(Breakdown::Singular(row())),
        DependentRows::Tolerate => {
            *dropped += 1;
            Ok(0.0)
        }
    }
}

/// `S = Φ_q M⁻¹ Φ_qᵀ` held dense and factored as `L D Lᵀ`, for a mass
/// matrix that changes with the state (`M(q)`): `S` is then formed anew at
/// every evaluation, densely, which is what small systems in angles need.
/// Same pivot test ([`inverse_pivot`]) and handling of dependent rows as
/// the sparse kernel.
#[derive(Clone)]
pub(crate) struct DenseLdl {
    m: usize,
    /// `S` on entry to [`factor`](Self::factor) (lower triangle read), then
    /// `L` below the diagonal, row-major.
    lower: Vec<f64>,
    /// `D` and `D⁻¹`.
    d: Vec<f64>,
    inv_d: Vec<f64>,
    /// Whether a dependent row is an error or dropped.
    dependent: DependentRows,
    /// Rows dropped by the last factorization.
    dropped: usize,
}

impl DenseLdl {
    /// Storage for `m` rows.
    pub fn new(m: usize) -> Self {
        Self {
            m,
            lower: vec![0.0; m * m],
            d: vec![0.0; m],
            inv_d: vec![0.0; m],
            dependent: DependentRows::Error,
            dropped: 0,
        }
    }

    /// Sets what a dependent row does in the next factorizations.
    pub fn set_dependent_rows(&mut self, dependent: DependentRows) {
        self.dependent = dependent;
    }

    /// Rows the last factorization dropped as dependent (0 unless tolerated).
    pub fn dependent_rows(&self) -> usize {
        self.dropped
    }

    /// `S`, row-major, to be filled (lower triangle) before [`factor`](Self::factor).
    pub fn matrix_mut(&mut self) -> &mut [f64] {
        &mut self.lower
    }

    /// Factors the `S` written through [`matrix_mut`](Self::matrix_mut);
    /// `jac` is the Jacobian it came from (for the pivot test).
    pub fn factor(&mut self, jac: &[f64]) -> Result<(), Breakdown> {
        let (m, a, dependent) = (self.m, &mut self.lower, self.dependent);
        let tolerance = dependent.tolerance();
        self.dropped = 0;
        let mut count = 0;
        for j in 0..m {
            let s_jj = a[j * m + j];
            let mut d = s_jj;
            for k in 0..j {
                d -= a[j * m + k] * a[j * m + k] * self.d[k];
            }
            // A dropped row has `D⁻¹ = 0`, so its column of `L` below is 0.
            self.inv_d[j] = inverse_pivot(d, s_jj, tolerance, jac, dependent, &mut count, || j)?;
            self.d[j] = d;
            for i in j + 1..m {
                let mut s = a[i * m + j];
                for k in 0..j {
                    s -= a[i * m + k] * a[j * m + k] * self.d[k];
                }
                a[i * m + j] = s * self.inv_d[j];
            }
        }
        self.dropped = count;
        Ok(())
    }

    /// Solves `S x = b` in place with the current factor.
    pub fn solve(&self, b: &mut [f64]) {
        let (m, l) = (self.m, &self.lower);
        for i in 0..m {
            b[i] -= (0..i).map(|k| l[i * m + k] * b[k]).sum::<f64>();
        }
        for (b, w) in b.iter_mut().zip(&self.inv_d) {
            *b *= w;
        }
        for i in (0..m).rev() {
            b[i] -= (i + 1..m).map(|k| l[k * m + i] * b[k]).sum::<f64>();
        }
    }
}
