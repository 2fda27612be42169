//! What a scheme steps: a state equation split into the part the scheme
//! integrates and the control term, and the storage of a state.

/// A state equation `ẋ = f(x, t) + U(x, t)`.
pub trait Rhs {
    /// Why an evaluation can fail.
    type Error;
    /// Length of the state `x`.
    fn state_len(&self) -> usize;
    /// Whether `U` can be non-zero.
    fn has_control(&self) -> bool;
    /// Writes `f(x, t)` and, when `u` is given, `U(x, t)`.
    fn eval(&mut self, x: &[f64], t: f64, f: &mut [f64], u: Option<&mut [f64]>) -> Result<(), Self::Error>;
}

/// Storage of a state or of a derivative: a vector, or a fixed-size
/// array when the size is known at compile time (so that a small system's
/// step keeps its numbers in registers).
pub trait Buffer: Clone {
    /// The numbers.
    fn as_slice(&self) -> &[f64];
    /// The numbers, to write.
    fn as_mut_slice(&mut self) -> &mut [f64];
}

impl Buffer for Vec<f64> {
    #[inline(always)]
    fn as_slice(&self) -> &[f64] {
        self
    }
    #[inline(always)]
    fn as_mut_slice(&mut self) -> &mut [f64] {
        self
    }
}
