//! A constant diagonal `M`, kept with its inverse.

use super::MassMatrix;
use crate::error::{Result, positive};

/// A constant diagonal mass matrix, kept with its inverse, over storage `S`
/// (`Vec<f64>` or `[f64; N]`).
#[derive(Debug, Clone, PartialEq)]
pub struct DiagonalMass<S = Vec<f64>> {
    diagonal: S,
    inverse: S,
}

impl<S: AsRef<[f64]> + AsMut<[f64]> + Clone> DiagonalMass<S> {
    /// The mass matrix with this diagonal; every entry must be finite and positive.
    pub fn new(diagonal: S) -> Result<Self> {
        for &m in diagonal.as_ref() {
            positive("mass", m)?;
        }
        let mut inverse = diagonal.clone();
        for w in inverse.as_mut() {
            *w = 1.0 / *w;
        }
        Ok(Self { diagonal, inverse })
    }
}

impl<S: AsRef<[f64]>> DiagonalMass<S> {
    /// The diagonal of `M`.
    #[inline(always)]
    pub fn diagonal(&self) -> &S {
        &self.diagonal
    }

    /// The diagonal of `M⁻¹`: the weights `1/m_c` of the products
    /// `J_a J_b / m_c` that sum to the entries of `S = Φ_q M⁻¹ Φ_qᵀ`.
    #[inline(always)]
    pub fn inverse(&self) -> &S {
        &self.inverse
    }
}

// The arithmetic below is written term for term as it was before the mass
// matrix had a type (`(s · m) · v`, not `s · (m · v)`), so results stay
// bit-identical; change an association only on purpose.
impl<S: AsRef<[f64]>> MassMatrix for DiagonalMass<S> {
    #[inline(always)]
    fn n(&self) -> usize {
        self.diagonal.as_ref().len()
    }

    #[inline(always)]
    fn mul(&self, x: &[f64], out: &mut [f64]) {
        for ((o, m), x) in out.iter_mut().zip(self.diagonal.as_ref()).zip(x) {
            *o = m * x;
        }
    }

    #[inline(always)]
    fn solve(&self, x: &[f64], out: &mut [f64]) {
        for ((o, w), x) in out.iter_mut().zip(self.inverse.as_ref()).zip(x) {
            *o = x * w;
        }
    }

    #[inline(always)]
    fn kinetic(&self, v: &[f64]) -> f64 {
        0.5 * self.diagonal.as_ref().iter().zip(v).map(|(m, v)| m * v * v).sum::<f64>()
    }

    #[inline(always)]
    fn psi_v(&self, v: &[f64], out: &mut [f64]) -> f64 {
        // In one pass (Example 1: two loops where this was two fused ones).
        let mut sum = 0.0;
        for ((o, m), v) in out.iter_mut().zip(self.diagonal.as_ref()).zip(v) {
            *o = m * v;
            sum += *o * *o;
        }
        sum
    }

    #[inline(always)]
    fn psi_v_dot(&self, v: &[f64], x: impl Fn(usize) -> f64, extra: impl Fn(usize) -> f64, init: f64) -> f64 {
        let mut sum = init;
        for (i, (m, v)) in self.diagonal.as_ref().iter().zip(v).enumerate() {
            sum += m * v * x(i) + extra(i);
        }
        sum
    }

    #[inline(always)]
    fn add_inverse_psi_v(&self, v: &[f64], scale: f64, out: &mut [f64]) {
        for (o, v) in out.iter_mut().zip(v) {
            *o += scale * v;
        }
    }
}
