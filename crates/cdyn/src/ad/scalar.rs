//! The scalar type users write physics with.

use num_dual::DualNum;

/// A real number or a dual number over `f64`.
///
/// Constraints, potentials and forces are written once, generic over
/// `D: Scalar`; the library evaluates them with `f64` for values and with
/// dual numbers for exact derivatives (`Φ_q`, `γ`, `∇V`).
pub trait Scalar: DualNum<Primitive = f64> + Copy {}

impl<T: DualNum<Primitive = f64> + Copy> Scalar for T {}
