//! A dense `M(q)` evaluated at one state, with its Cholesky factor.

use super::MassMatrix;

/// A symmetric positive definite `M`, evaluated at one state and kept
/// with its Cholesky factor `M = L Lᵀ`; storage allocated once.
#[derive(Debug, Clone, PartialEq)]
pub struct DenseMass {
    n: usize,
    /// `M`, row-major.
    matrix: Vec<f64>,
    /// `L`, row-major lower triangle.
    factor: Vec<f64>,
}

impl DenseMass {
    /// Storage for an `n × n` matrix, zero.
    pub fn new(n: usize) -> Self {
        Self { n, matrix: vec![0.0; n * n], factor: vec![0.0; n * n] }
    }

    /// `M`, row-major, to be filled before [`factor`](Self::factor).
    pub fn matrix_mut(&mut self) -> &mut [f64] {
        &mut self.matrix
    }

    /// `M`, row-major.
    pub fn matrix(&self) -> &[f64] {
        &self.matrix
    }

    /// Factors `M = L Lᵀ`. `Err(k)` names the first coordinate whose pivot
    /// is not positive (or not finite): `M` is not positive definite there.
    pub fn factor(&mut self) -> std::result::Result<(), usize> {
        let n = self.n;
        let (a, l) = (&self.matrix, &mut self.factor);
        for j in 0..n {
            let mut d = a[j * n + j];
            for k in 0..j {
                d -= l[j * n + k] * l[j * n + k];
            }
            // Relative to the diagonal entry: a pivot lost to round-off is singular.
            if d.is_nan() || d <= 1e-14 * a[j * n + j].abs() || !d.is_finite() {
                return Err(j);
            }
            let d = d.sqrt();
            l[j * n + j] = d;
            for i in j + 1..n {
                let mut s = a[i * n + j];
                for k in 0..j {
                    s -= l[i * n + k] * l[j * n + k];
                }
                l[i * n + j] = s / d;
            }
        }
        Ok(())
    }

    /// `(M v)_i`
    #[inline(always)]
    fn row_dot(&self, i: usize, v: &[f64]) -> f64 {
        self.matrix[i * self.n..(i + 1) * self.n].iter().zip(v).map(|(m, v)| m * v).sum()
    }
}

impl MassMatrix for DenseMass {
    fn n(&self) -> usize {
        self.n
    }

    fn mul(&self, x: &[f64], out: &mut [f64]) {
        for (i, o) in out.iter_mut().enumerate() {
            *o = self.row_dot(i, x);
        }
    }

    /// With the factor of the last [`factor`](DenseMass::factor): `L y = x`, then `Lᵀ out = y`, in `out`.
    fn solve(&self, x: &[f64], out: &mut [f64]) {
        let (n, l) = (self.n, &self.factor);
        for i in 0..n {
            let s: f64 = (0..i).map(|k| l[i * n + k] * out[k]).sum();
            out[i] = (x[i] - s) / l[i * n + i];
        }
        for i in (0..n).rev() {
            let s: f64 = (i + 1..n).map(|k| l[k * n + i] * out[k]).sum();
            out[i] = (out[i] - s) / l[i * n + i];
        }
    }

    fn kinetic(&self, v: &[f64]) -> f64 {
        0.5 * (0..self.n).map(|i| v[i] * self.row_dot(i, v)).sum::<f64>()
    }

    fn psi_v_dot(&self, v: &[f64], x: impl Fn(usize) -> f64, extra: impl Fn(usize) -> f64, init: f64) -> f64 {
        let mut sum = init;
        for i in 0..self.n {
            sum += self.row_dot(i, v) * x(i) + extra(i);
        }
        sum
    }

    fn add_inverse_psi_v(&self, v: &[f64], scale: f64, out: &mut [f64]) {
        for (o, v) in out.iter_mut().zip(v) {
            *o += scale * v;
        }
    }
}
