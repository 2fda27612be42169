//! The mass matrix `M`: every product with `M` or `M⁻¹` the library forms
//! goes through here, so that the rest of the crate never assumes its shape.
//!
//! In redundant (Cartesian) coordinates every body's mass matrix is constant
//! and diagonal — `(m, m, I)` for a planar body, `m` per axis for a point
//! mass — which is what makes the formulation cheap: `M⁻¹` is free and
//! `S = Φ_q M⁻¹ Φ_qᵀ` inherits the sparsity of the constraints. That is the
//! one kind today ([`DiagonalMass`]). Block and configuration-dependent
//! kinds (`M(q)`) will implement [`MassMatrix`] too; the control laws and
//! the energy already ask it, not the diagonal, for what they need.
//!
//! The diagonal kind is generic over its storage: a `Vec` for a general
//! model, an array for a small system, whose loops then keep their
//! compile-time lengths.

use crate::error::{Result, positive};

/// What the dynamics, the energy and the control laws need of a mass matrix.
///
/// The vectors have one entry per coordinate. `Ψ_v` is the velocity gradient
/// of the energy constraint, `Ψ_v = ∂T/∂v = (M v)ᵀ` (Eq. 14 ff.).
pub trait MassMatrix {
    /// Number of coordinates `n`.
    fn n(&self) -> usize;
    /// `out = M x`.
    fn mul(&self, x: &[f64], out: &mut [f64]);
    /// `out = M⁻¹ x`.
    fn solve(&self, x: &[f64], out: &mut [f64]);
    /// The kinetic energy `½ vᵀ M v`.
    fn kinetic(&self, v: &[f64]) -> f64;
    /// `|Ψ_v|² = |M v|²`, which sets the gain of the gradient energy control (Eq. 27).
    fn psi_v_norm2(&self, v: &[f64]) -> f64;
    /// `Ψ_v x = (M v) · x`, summed in coordinate order after `init`, with
    /// `extra(i)` added to the `i`-th term before it joins the sum (the
    /// Baumgarte-type energy control sums `Ψ_v A + Ψ_q v` in one pass).
    fn psi_v_dot(&self, v: &[f64], x: impl Fn(usize) -> f64, extra: impl Fn(usize) -> f64, init: f64) -> f64;
    /// `out += scale · Ψ_vᵀ = scale · M v`.
    fn add_psi_v(&self, v: &[f64], scale: f64, out: &mut [f64]);
    /// `out += scale · M⁻¹ Ψ_vᵀ`. Since `Ψ_vᵀ = M v`, this is `scale · v`
    /// for every kind of `M`, formed without the round trip through `M`.
    fn add_inverse_psi_v(&self, v: &[f64], scale: f64, out: &mut [f64]);
}

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
    fn psi_v_norm2(&self, v: &[f64]) -> f64 {
        self.diagonal.as_ref().iter().zip(v).map(|(m, v)| (m * v) * (m * v)).sum()
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
    fn add_psi_v(&self, v: &[f64], scale: f64, out: &mut [f64]) {
        for ((o, m), v) in out.iter_mut().zip(self.diagonal.as_ref()).zip(v) {
            *o += scale * m * v;
        }
    }

    #[inline(always)]
    fn add_inverse_psi_v(&self, v: &[f64], scale: f64, out: &mut [f64]) {
        for (o, v) in out.iter_mut().zip(v) {
            *o += scale * v;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn diagonal_products_agree_with_their_definitions() {
        let mass = DiagonalMass::new(vec![2.0, 0.5, 4.0]).unwrap();
        let v = [1.0, -2.0, 0.25];
        let mut mv = [0.0; 3];
        mass.mul(&v, &mut mv);
        assert_eq!(mv, [2.0, -1.0, 1.0]);
        let mut back = [0.0; 3];
        mass.solve(&mv, &mut back);
        assert_eq!(back, v);
        assert_eq!(mass.kinetic(&v), 0.5 * (2.0 + 2.0 + 0.25));
        assert_eq!(mass.psi_v_norm2(&v), 4.0 + 1.0 + 1.0);
        assert_eq!(mass.psi_v_dot(&v, |_| 1.0, |_| 0.0, 0.5), 0.5 + 2.0);
        let mut out = [1.0; 3];
        mass.add_psi_v(&v, -1.0, &mut out);
        assert_eq!(out, [-1.0, 2.0, 0.0]);
        // M⁻¹ Ψ_vᵀ = v.
        let mut out = [0.0; 3];
        mass.add_inverse_psi_v(&v, 2.0, &mut out);
        assert_eq!(out, [2.0, -4.0, 0.5]);
        // Array storage behaves the same.
        let small = DiagonalMass::new([2.0, 0.5, 4.0]).unwrap();
        assert_eq!(small.kinetic(&v), mass.kinetic(&v));
        assert_eq!(small.inverse(), &[0.5, 2.0, 0.25]);
    }

    #[test]
    fn a_mass_that_is_not_positive_is_an_error() {
        for bad in [0.0, -1.0, f64::NAN, f64::INFINITY] {
            let err = DiagonalMass::new(vec![1.0, bad]).unwrap_err();
            assert!(err.to_string().contains("mass"), "{err}");
        }
    }
}
