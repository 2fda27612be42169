//! Functions of time for drives and applied loads, written once for every
//! scalar type so that `Φ_t`, `Φ_tt` come from the same dual passes as
//! everything else.

use crate::scalar::Scalar;

/// `f(t) = Σ_k c_k t^k + Σ_j a_j sin(ω_j t + φ_j)`.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct TimeFn {
    /// Polynomial coefficients `c_0, c_1, …`.
    pub polynomial: Vec<f64>,
    /// Sine terms `(amplitude, angular frequency, phase)`.
    pub sines: Vec<[f64; 3]>,
}

impl TimeFn {
    pub fn constant(c: f64) -> Self {
        Self { polynomial: vec![c], sines: Vec::new() }
    }

    /// `c0 + c1 t`.
    pub fn linear(c0: f64, c1: f64) -> Self {
        Self { polynomial: vec![c0, c1], sines: Vec::new() }
    }

    pub fn eval<D: Scalar>(&self, t: D) -> D {
        // Horner for the polynomial.
        let mut p = D::from(0.0);
        for &c in self.polynomial.iter().rev() {
            p = p * t + c;
        }
        for &[a, w, phase] in &self.sines {
            p += (t * w + phase).sin() * a;
        }
        p
    }

    /// Whether every coefficient is finite.
    pub fn is_finite(&self) -> bool {
        self.polynomial.iter().chain(self.sines.iter().flatten()).all(|c| c.is_finite())
    }
}
