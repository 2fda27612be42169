//! The mass matrix `M`: every product with `M` or `M⁻¹` the library forms
//! goes through here, so that the rest of the crate never assumes its shape.
//!
//! In redundant (Cartesian) coordinates every body's mass matrix is constant
//! and diagonal — `(m, m, I)` for a planar body, `m` per axis for a point
//! mass — which is what makes the formulation cheap: `M⁻¹` is free and
//! `S = Φ_q M⁻¹ Φ_qᵀ` inherits the sparsity of the constraints. That is the
//! common kind ([`DiagonalMass`]). Coordinates such as angles have a
//! configuration-dependent `M(q)` ([`crate::model::kinetic`]): it is evaluated at
//! every state into a [`DenseMass`] and factored once per evaluation.
//! [`MassAt`] is either, as the control laws and the energy see it: they
//! ask it, not the diagonal, for what they need.
//!
//! The diagonal kind is generic over its storage: a `Vec` for a general
//! model, an array for a small system, whose loops then keep their
//! compile-time lengths.
//!
//! May import: `error`.

mod at;
mod block;
mod dense;
mod diagonal;

pub use at::MassAt;
pub(crate) use block::WidthFn;
pub use block::{BlockMass, MAX_BLOCK};
pub use dense::DenseMass;
pub use diagonal::DiagonalMass;

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
    /// `out = Ψ_vᵀ = M v`; returns `|Ψ_v|²`, which sets the gain of the
    /// gradient energy control (Eq. 27).
    fn psi_v(&self, v: &[f64], out: &mut [f64]) -> f64 {
        self.mul(v, out);
        out.iter().map(|w| w * w).sum()
    }
    /// `Ψ_v x = (M v) · x`, summed in coordinate order after `init`, with
    /// `extra(i)` added to the `i`-th term before it joins the sum (the
    /// Baumgarte-type energy control sums `Ψ_v A + Ψ_q v` in one pass).
    fn psi_v_dot(&self, v: &[f64], x: impl Fn(usize) -> f64, extra: impl Fn(usize) -> f64, init: f64) -> f64;
    /// `out += scale · M⁻¹ Ψ_vᵀ`. Since `Ψ_vᵀ = M v`, this is `scale · v`
    /// for every kind of `M`, formed without the round trip through `M`.
    fn add_inverse_psi_v(&self, v: &[f64], scale: f64, out: &mut [f64]);
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
        assert_eq!(mass.psi_v(&v, &mut mv), 4.0 + 1.0 + 1.0);
        assert_eq!(mv, [2.0, -1.0, 1.0]);
        assert_eq!(mass.psi_v_dot(&v, |_| 1.0, |_| 0.0, 0.5), 0.5 + 2.0);
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
    fn dense_products_agree_with_their_definitions() {
        let mut mass = DenseMass::new(3);
        mass.matrix_mut().copy_from_slice(&[4.0, 1.0, 0.5, 1.0, 3.0, -1.0, 0.5, -1.0, 2.0]);
        mass.factor().unwrap();
        let v = [1.0, -2.0, 0.25];
        let mut mv = [0.0; 3];
        mass.mul(&v, &mut mv);
        assert_eq!(mv, [4.0 - 2.0 + 0.125, 1.0 - 6.0 - 0.25, 0.5 + 2.0 + 0.5]);
        let mut back = [0.0; 3];
        mass.solve(&mv, &mut back);
        for (b, v) in back.iter().zip(&v) {
            assert!((b - v).abs() < 1e-14, "{back:?}");
        }
        let vmv: f64 = mv.iter().zip(&v).map(|(a, b)| a * b).sum();
        assert_eq!(mass.kinetic(&v), 0.5 * vmv);
        let mut again = [0.0; 3];
        assert_eq!(mass.psi_v(&v, &mut again), mv.iter().map(|x| x * x).sum::<f64>());
        assert_eq!(again, mv);
        // Not positive definite: the pivot of coordinate 1 is 1 − 4 < 0.
        mass.matrix_mut().copy_from_slice(&[1.0, 2.0, 0.0, 2.0, 1.0, 0.0, 0.0, 0.0, 1.0]);
        assert_eq!(mass.factor(), Err(1));
    }

    #[test]
    fn a_mass_that_is_not_positive_is_an_error() {
        for bad in [0.0, -1.0, f64::NAN, f64::INFINITY] {
            let err = DiagonalMass::new(vec![1.0, bad]).unwrap_err();
            assert!(err.to_string().contains("mass"), "{err}");
        }
    }
}
