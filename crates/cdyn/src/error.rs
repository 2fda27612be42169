//! The library's one error type. Every variant says where (step, time,
//! constraint row) and what, so a caller can print a one-line message.

use thiserror::Error;

/// Everything that can go wrong while building a model or simulating it.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum Error {
    /// A setting or parameter outside its domain.
    #[error("invalid {name} = {value}: {reason}")]
    InvalidParameter { name: &'static str, value: f64, reason: &'static str },
    /// A model that cannot be simulated as described.
    #[error("invalid model: {0}")]
    InvalidModel(String),
    /// The initial state is off the constraints by more than the tolerance.
    #[error(
        "initial state violates the constraints: max |Φ| = {phi:.3e}, max |Φ̇| = {phi_dot:.3e} (tolerance {tolerance:.1e})"
    )]
    InconsistentInitialState { phi: f64, phi_dot: f64, tolerance: f64 },
    /// `Φ_q M⁻¹ Φ_qᵀ` is singular: the constraints are redundant or degenerate here.
    #[error(
        "singular constraint matrix at step {step}, t = {t}: constraint row {row} is linearly dependent on the others"
    )]
    SingularConstraints { step: u64, t: f64, row: usize },
    /// The state stopped being finite.
    #[error("simulation diverged at step {step}, t = {t}: the state is no longer finite")]
    Diverged { step: u64, t: f64 },
    /// The constraint violation grew past the configured limit.
    #[error("simulation diverged at step {step}, t = {t}: max |Φ| = {phi:.3e} exceeds the limit {limit:.1e}")]
    ViolationLimit { step: u64, t: f64, phi: f64, limit: f64 },
}

pub type Result<T, E = Error> = std::result::Result<T, E>;

/// Checks that `value` is finite and positive; names it otherwise.
pub(crate) fn positive(name: &'static str, value: f64) -> Result<f64> {
    if value.is_finite() && value > 0.0 {
        Ok(value)
    } else {
        Err(Error::InvalidParameter { name, value, reason: "must be finite and positive" })
    }
}

/// Checks that `value` is finite and not negative; names it otherwise.
pub(crate) fn non_negative(name: &'static str, value: f64) -> Result<f64> {
    if value.is_finite() && value >= 0.0 {
        Ok(value)
    } else {
        Err(Error::InvalidParameter { name, value, reason: "must be finite and not negative" })
    }
}
