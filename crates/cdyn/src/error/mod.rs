//! The library's one error type. Every variant says where (step, time,
//! constraint row, the part of a model) and what, as data, so a caller can
//! print a one-line message or name the entry of its own input at fault.
//! The parts of a model ([`Part`]), their problems ([`Problem`]) and the
//! method-key combinations refused ([`KeyProblem`]) have files of their own.
//!
//! May import: nothing of the crate.

use thiserror::Error;

mod keys;
mod part;
mod problem;

pub use keys::KeyProblem;
pub use part::Part;
pub use problem::Problem;

/// Everything that can go wrong while building a model or simulating it.
#[derive(Debug, Clone, PartialEq, Error)]
#[non_exhaustive]
pub enum Error {
    /// A setting or parameter outside its domain.
    #[error("invalid {name} = {value}: {reason}")]
    InvalidParameter {
        /// The parameter's name as the caller wrote it (`h`, `rod_length`).
        name: &'static str,
        /// The refused value.
        value: f64,
        /// Why it was refused, e.g. "must be finite and positive".
        reason: &'static str,
    },
    /// A model that cannot be simulated as described.
    #[error("invalid model: {at}{problem}")]
    InvalidModel {
        /// The part of the model at fault.
        at: Part,
        /// What is wrong with it.
        problem: Problem,
    },
    /// The initial state is off the constraints by more than the tolerance.
    #[error(
        "initial state violates the constraints: max |Φ| = {phi:.3e}, max |Φ̇| = {phi_dot:.3e} (tolerance {tolerance:.1e})"
    )]
    InconsistentInitialState {
        /// Largest constraint violation.
        phi: f64,
        /// Largest velocity-constraint violation.
        phi_dot: f64,
        /// The tolerance it exceeds.
        tolerance: f64,
    },
    /// `Φ_q M⁻¹ Φ_qᵀ` is singular: the constraints are redundant or degenerate here.
    #[error(
        "singular constraint matrix at step {step}, t = {}: constraint row {row} is linearly dependent on the others (if the constraints are redundant, set dependent_rows = \"tolerate\")", Time(*t)
    )]
    SingularConstraints {
        /// Steps taken before the failure.
        step: u64,
        /// Time of the failure.
        t: f64,
        /// The dependent constraint row.
        row: usize,
    },
    /// The mass matrix `M(q)` of kinetic-energy elements is not positive definite at the state.
    #[error(
        "mass matrix M(q) not positive definite at step {step}, t = {}: coordinate {coordinate} has no inertia there", Time(*t)
    )]
    MassNotPositive {
        /// Steps taken before the failure.
        step: u64,
        /// Time of the failure.
        t: f64,
        /// The coordinate whose pivot failed.
        coordinate: usize,
    },
    /// The state stopped being finite.
    #[error("simulation diverged at step {step}, t = {}: the state is no longer finite", Time(*t))]
    Diverged {
        /// Steps taken before the failure.
        step: u64,
        /// Time of the failure.
        t: f64,
    },
    /// The constraint violation grew past the configured limit.
    #[error(
        "simulation diverged at step {step}, t = {}: max |Φ| = {phi:.3e} exceeds the limit {limit:.1e}",
        Time(*t)
    )]
    ViolationLimit {
        /// Steps taken before the failure.
        step: u64,
        /// Time of the failure.
        t: f64,
        /// The violation reached.
        phi: f64,
        /// The configured limit.
        limit: f64,
    },
    /// The exact projection (the `projection` method) did not converge.
    #[error(
        "projection did not converge at step {step}, t = {}: {invariant} = {residual:.3e}{} after {iterations} Newton iterations (raise max_iterations or tolerance, or set on_failure = \"continue\")",
        Time(*t),
        row.map_or(String::new(), |r| format!(" in constraint row {r}"))
    )]
    ProjectionFailed {
        /// Steps taken, including the one whose result could not be projected.
        step: u64,
        /// Time of the state that could not be projected.
        t: f64,
        /// `|Φ|` or `|Ψ|`.
        invariant: &'static str,
        /// The worst violation left.
        residual: f64,
        /// The worst constraint row, for `|Φ|`.
        row: Option<usize>,
        /// Newton iterations taken.
        iterations: u32,
    },
    /// RATTLE's position step did not bring the constraints back to `Φ = 0`.
    #[error(
        "RATTLE's position step did not converge at step {step}, t = {}: |Φ| = {residual:.3e} in constraint row {row} after {iterations} iterations (take a smaller h)",
        Time(*t)
    )]
    RattleFailed {
        /// Steps taken, including the one that failed.
        step: u64,
        /// Time the step was to reach.
        t: f64,
        /// The worst violation left.
        residual: f64,
        /// The worst constraint row.
        row: usize,
        /// Iterations taken.
        iterations: u32,
    },
    /// Generalized-α's Newton iteration did not converge.
    #[error(
        "generalized-α's Newton iteration did not converge at step {step}, t = {}: relative |Δq̈| = {correction:.3e} after {iterations} corrections (take a smaller h, or allow more newton iterations)",
        Time(*t)
    )]
    NewtonFailed {
        /// Steps taken, including the one that failed.
        step: u64,
        /// Time the step was to reach.
        t: f64,
        /// `|Δq̈|∞` of the correction that would come next, over the largest
        /// acceleration.
        correction: f64,
        /// Corrections taken.
        iterations: u32,
    },
    /// Generalized-α's Newton matrix is singular at independent constraint
    /// rows (a dependent row is [`Error::SingularConstraints`], or dropped
    /// with `dependent_rows = "tolerate"`).
    #[error(
        "generalized-α's Newton matrix is singular at step {step}, t = {} (after {iterations} corrections) with independent constraint rows: the step's mass, damping and stiffness, M + c_v C + c_q K, have no inverse on the constraints, as where a negative stiffness cancels the inertia (take a smaller h)",
        Time(*t)
    )]
    NewtonSingular {
        /// Steps taken, including the one that failed.
        step: u64,
        /// Time the step was to reach.
        t: f64,
        /// Corrections taken before.
        iterations: u32,
    },
    /// An input that does not exist, or a value it cannot take
    /// ([`crate::model::input`]).
    #[error("input {name:?}: {reason}")]
    Input {
        /// The input's name (`#3` for a position that has none).
        name: String,
        /// What is wrong.
        reason: String,
    },
    /// Method keys that do not describe one method.
    #[error("{0}")]
    Method(#[from] KeyProblem),
    /// A combination of settings this kind of simulation does not offer.
    #[error("{0}")]
    Unsupported(&'static str),
    /// The pendulum's energy lies within a relative 1e-10 of the upright
    /// energy: the period diverges and the elliptic closed form of the
    /// reference solution degenerates.
    #[error("pendulum energy lies on the separatrix (just reaches the top); no elliptic closed form")]
    Separatrix,
}

impl Error {
    /// The constraint row a simulation error is about, if any.
    pub fn row(&self) -> Option<usize> {
        match self {
            Error::SingularConstraints { row, .. } => Some(*row),
            Error::InvalidModel { problem: Problem::SingularAssembly { row, .. }, .. } => Some(*row),
            Error::ProjectionFailed { row, .. } => *row,
            Error::RattleFailed { row, .. } => Some(*row),
            _ => None,
        }
    }

    /// The same error, said of `part`: a refused parameter becomes an
    /// [`Error::InvalidModel`] at `part`; an invalid model error of the whole
    /// model is moved to `part`; other errors are kept.
    pub fn at(self, part: Part) -> Error {
        match self {
            Error::InvalidParameter { name, value, reason } => {
                Error::InvalidModel { at: part, problem: Problem::Parameter { name, value, reason } }
            }
            Error::InvalidModel { at: Part::Model, problem } => Error::InvalidModel { at: part, problem },
            other => other,
        }
    }
}

impl From<Problem> for Error {
    /// A problem of the whole model.
    fn from(problem: Problem) -> Self {
        Error::InvalidModel { at: Part::Model, problem }
    }
}

/// A time as people write it: `step · h` rounded to 12 significant digits
/// (`0.3`, not the `0.30000000000000004` of `3 × 0.1`), far below any step.
pub fn tidy_time(t: f64) -> f64 {
    // Written on the stack, not into a `String`: a co-simulation step reads
    // its outputs (`t` among them) without allocating. 32 bytes hold the
    // longest, `-1.23456789012e-308`.
    use std::io::Write;
    let mut text = [0_u8; 32];
    let mut cursor = std::io::Cursor::new(&mut text[..]);
    if write!(cursor, "{t:.11e}").is_err() {
        return t;
    }
    let len = cursor.position() as usize;
    std::str::from_utf8(&text[..len]).ok().and_then(|s| s.parse().ok()).unwrap_or(t)
}

/// A time in a message: [`tidy_time`], in plain decimals between 1e-4 and
/// 1e9 and with an exponent outside (not 309 digits for 1e308).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Time(pub f64);

impl std::fmt::Display for Time {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let t = tidy_time(self.0);
        if t == 0.0 || (1e-4..1e9).contains(&t.abs()) { write!(f, "{t}") } else { write!(f, "{t:e}") }
    }
}

/// The library's result type.
pub type Result<T, E = Error> = std::result::Result<T, E>;

/// Checks that `value` is finite; names it otherwise.
pub fn finite(name: &'static str, value: f64) -> Result<f64> {
    if value.is_finite() { Ok(value) } else { Err(Error::InvalidParameter { name, value, reason: "must be finite" }) }
}

/// Checks that `value` is finite and positive; names it otherwise.
pub fn positive(name: &'static str, value: f64) -> Result<f64> {
    if value.is_finite() && value > 0.0 {
        Ok(value)
    } else {
        Err(Error::InvalidParameter { name, value, reason: "must be finite and positive" })
    }
}

/// Checks that `value` is finite and not negative; names it otherwise.
pub fn non_negative(name: &'static str, value: f64) -> Result<f64> {
    if value.is_finite() && value >= 0.0 {
        Ok(value)
    } else {
        Err(Error::InvalidParameter { name, value, reason: "must be finite and not negative" })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn times_print_as_written() {
        assert_eq!(Time(3.0 * 0.1).to_string(), "0.3");
        assert_eq!(Time(1e308).to_string(), "1e308");
        assert_eq!(Time(2.5e-6).to_string(), "2.5e-6");
        assert_eq!(Time(0.0).to_string(), "0");
        assert_eq!(Time(4766.0 * 0.001).to_string(), "4.766");
    }

    /// The stack-written rounding equals the `String` one it replaced, at the extremes too.
    #[test]
    fn tidy_time_rounds_as_through_a_string() {
        for t in
            [3.0 * 0.1, -f64::MAX, -f64::MIN_POSITIVE, 5e-324, 0.0, -0.0, f64::INFINITY, f64::NAN, 1234.5678901234567]
        {
            let through_string: f64 = format!("{t:.11e}").parse().unwrap();
            assert_eq!(tidy_time(t).to_bits(), through_string.to_bits(), "{t}");
        }
    }
}
