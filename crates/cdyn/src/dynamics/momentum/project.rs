//! Corrections made M-orthogonal to the kept momentum directions.

use crate::linalg::dot;
use crate::linalg::mass::MassMatrix;

use super::*;

/// The kept momentum directions at run time: `E`, `M E` at the latest
/// evaluation and the inverse of `EᵀME`, so that a correction is made
/// M-orthogonal to them with `k` dot products and `k` updates.
#[derive(Debug, Clone, Default)]
pub(crate) struct Momenta {
    /// `k × n`: the directions, row by row.
    e: Vec<f64>,
    /// `k × n`: `M e_j`.
    mass_e: Vec<f64>,
    /// `k × k`: `(EᵀME)⁻¹`.
    gram_inverse: Vec<f64>,
    /// `M e` is the same at every state: set once.
    constant: bool,
    /// `M E` has been formed.
    ready: bool,
    /// Number of directions, `k`.
    k: usize,
    n: usize,
}

impl Momenta {
    /// No directions: every operation is a no-op.
    pub(crate) const NONE: Momenta = Momenta {
        e: Vec::new(),
        mass_e: Vec::new(),
        gram_inverse: Vec::new(),
        constant: true,
        ready: true,
        k: 0,
        n: 0,
    };

    /// The constant directions of `kept` (not the rotations), for a model of `n` coordinates; `M e` is
    /// set by [`update`](Self::update).
    pub(crate) fn new(kept: &[Momentum], n: usize, constant: bool) -> Self {
        let constant_directions = || kept.iter().filter(|m| m.kind == Kind::Constant);
        let k = constant_directions().count();
        Self {
            e: constant_directions().flat_map(|m| m.direction.iter().copied()).collect(),
            mass_e: vec![0.0; k * n],
            gram_inverse: vec![0.0; k * k],
            constant,
            ready: k == 0,
            k,
            n,
        }
    }

    /// Number of directions.
    #[inline(always)]
    pub(crate) fn len(&self) -> usize {
        self.k
    }

    /// Whether there are none.
    #[inline(always)]
    pub(crate) fn is_empty(&self) -> bool {
        self.k == 0
    }

    /// Whether `M E` must be formed (again) at the current state.
    #[inline(always)]
    pub(crate) fn stale(&self) -> bool {
        !self.is_empty() && (!self.ready || !self.constant)
    }

    /// `M E` and `(EᵀME)⁻¹` from the mass matrix at the current state.
    pub(crate) fn update(&mut self, mass: &impl MassMatrix) {
        let (k, n) = (self.len(), self.n);
        for j in 0..k {
            mass.mul(&self.e[j * n..(j + 1) * n], &mut self.mass_e[j * n..(j + 1) * n]);
        }
        let mut gram = [0.0; MAX_MOMENTA * MAX_MOMENTA];
        for a in 0..k {
            for b in 0..k {
                gram[a * k + b] = dot(&self.e[a * n..(a + 1) * n], &self.mass_e[b * n..(b + 1) * n]);
            }
        }
        invert(&mut gram[..k * k], k, &mut self.gram_inverse);
        self.ready = true;
    }

    /// `a = (EᵀME)⁻¹ Eᵀ M x`: the coefficients of `x`'s part along the
    /// momentum directions.
    #[inline]
    pub(crate) fn coefficients(&self, x: &[f64]) -> [f64; MAX_MOMENTA] {
        let (k, n) = (self.len(), self.n);
        let mut p = [0.0; MAX_MOMENTA];
        for j in 0..k {
            p[j] = dot(&self.mass_e[j * n..(j + 1) * n], x);
        }
        let mut a = [0.0; MAX_MOMENTA];
        for i in 0..k {
            a[i] = (0..k).map(|j| self.gram_inverse[i * k + j] * p[j]).sum();
        }
        a
    }

    /// `out += scale · E a`.
    #[inline(always)]
    pub(crate) fn add_directions(&self, a: &[f64; MAX_MOMENTA], scale: f64, out: &mut [f64]) {
        let n = self.n;
        for (j, &aj) in a.iter().enumerate().take(self.len()) {
            let s = scale * aj;
            out.iter_mut().zip(&self.e[j * n..(j + 1) * n]).for_each(|(o, e)| *o += s * e);
        }
    }

    /// `x ← P_E x = x − E (EᵀME)⁻¹ EᵀM x`: no part left along any momentum
    /// direction in the metric `M`.
    #[inline]
    pub(crate) fn project(&self, x: &mut [f64]) {
        if self.is_empty() {
            return;
        }
        let a = self.coefficients(x);
        self.add_directions(&a, -1.0, x);
    }

    /// `x`'s coefficients `a` along the momentum directions and the part
    /// of `|x|²_M` along them, `(EᵀMx)ᵀ (EᵀME)⁻¹ (EᵀMx) = aᵀ EᵀMx`.
    #[inline(always)]
    pub(crate) fn split(&self, x: &[f64]) -> ([f64; MAX_MOMENTA], f64) {
        if self.is_empty() {
            return ([0.0; MAX_MOMENTA], 0.0);
        }
        let a = self.coefficients(x);
        let n = self.n;
        (a, (0..self.len()).map(|j| a[j] * dot(&self.mass_e[j * n..(j + 1) * n], x)).sum())
    }
}

/// `out = a⁻¹` for a symmetric positive definite `k × k` matrix `a`
/// (overwritten), by Gauss–Jordan elimination; `k` is small.
pub(super) fn invert(a: &mut [f64], k: usize, out: &mut [f64]) {
    out.fill(0.0);
    for i in 0..k {
        out[i * k + i] = 1.0;
    }
    for c in 0..k {
        let pivot = a[c * k + c];
        for j in 0..k {
            a[c * k + j] /= pivot;
            out[c * k + j] /= pivot;
        }
        for r in (0..k).filter(|&r| r != c) {
            let f = a[r * k + c];
            if f != 0.0 {
                for j in 0..k {
                    a[r * k + j] -= f * a[c * k + j];
                    out[r * k + j] -= f * out[c * k + j];
                }
            }
        }
    }
}
