//! The controlled state equation `ẋ = f(x, t) + U(x, t)` of a model, with
//! the state laid out as `x = (q, v, e)`, `e = ∫Ė dτ`.
//!
//! Here the interface a [`Stepper`](crate::simulate::Stepper) steps — the
//! [`System`] trait, its evaluation errors and the failures of the schemes
//! that step a model — and the state's layout; `controlled` is the
//! [`ControlledSystem`] of a general [`Model`](crate::model::Model),
//! `evaluated` what the control laws read of its evaluations, `arrays` an
//! evaluation in fixed-size arrays and `in_arrays` a small model stepped
//! through it.
//!
//! May import: `control`, `dynamics`, `integrate`, `linalg`, `model` (and
//! `rattle`, `generalized_alpha` beside it).

mod arrays;
mod controlled;
mod evaluated;
mod in_arrays;

pub(crate) use arrays::{ArrayDynamics, ArrayWork};
pub use controlled::ControlledSystem;

use crate::control::Control;
use crate::control::gains::Operators;
use crate::control::projection::{Failure, Projection};
use crate::dynamics::Breakdown;
use crate::dynamics::diagnostics::Measures;
use crate::dynamics::momentum::Symmetries;
use crate::integrate::{Buffer, Rhs};
use crate::simulate::generalized_alpha::{GeneralizedAlpha, StepReport};

/// A failed evaluation of the right-hand side.
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub enum EvalError {
    /// `Φ_q M⁻¹ Φ_qᵀ` is singular at a finite state.
    Singular {
        /// Time of the evaluation.
        t: f64,
        /// The dependent constraint row.
        row: usize,
    },
    /// The state handed in was not finite.
    NonFinite {
        /// Time of the evaluation.
        t: f64,
    },
    /// `M(q)` is not positive definite at the state.
    Mass {
        /// Time of the evaluation.
        t: f64,
        /// The coordinate whose pivot failed.
        coordinate: usize,
    },
}

impl EvalError {
    pub(crate) fn at(b: Breakdown, t: f64) -> Self {
        match b {
            Breakdown::Singular(row) => EvalError::Singular { t, row },
            Breakdown::NonFinite => EvalError::NonFinite { t },
            Breakdown::Mass(coordinate) => EvalError::Mass { t, coordinate },
        }
    }
}

/// What a [`Stepper`](crate::simulate::Stepper) steps: a controlled state
/// equation over `x = (q, v, e)` that can also report its violations.
pub trait System: Rhs<Error = EvalError> {
    /// Storage of a state.
    type State: Buffer;
    /// A zero state.
    fn zero_state(&self) -> Self::State;
    /// Number of coordinates `n`.
    fn n(&self) -> usize;
    /// `E₀ = T₀ + V₀`.
    fn e0(&self) -> f64;
    /// Right-hand-side evaluations so far.
    fn evaluations(&self) -> u64;
    /// The most constraint rows an evaluation dropped as dependent since
    /// the last call (0 unless [`DependentRows::Tolerate`](crate::dynamics::DependentRows)), and resets it.
    fn take_dependent_rows(&mut self) -> usize;
    /// `max |Φ|` at the state of the latest evaluation.
    fn last_violation(&self) -> f64;
    /// Violations at the state `x`, time `t`.
    fn measure(&mut self, x: &[f64], t: f64) -> Measures;
    /// At the state `x`, time `t`: the largest mode `μ_max` of the paper's
    /// CVSGF operator, the largest `|∇Φᵢ|²` and the fastest damping rate
    /// `λ_d`, for automatic gains ([`crate::control::gains`]). Not counted as an
    /// evaluation.
    fn operators(&mut self, x: &[f64], t: f64) -> Result<Operators, EvalError>;
    /// Replaces the control law (once its automatic gains are chosen).
    fn set_control(&mut self, control: Control);
    /// Projects the state `x` at time `t` onto the invariants (the
    /// `projection` method); returns the Newton iterations taken.
    fn project(&mut self, x: &mut [f64], t: f64, h: f64, settings: &Projection) -> Result<u32, Failure>;
    /// Whether it can be stepped by the schemes that step a model itself,
    /// [`Scheme::Rattle`](crate::Scheme::Rattle) and
    /// [`Scheme::GeneralizedAlpha`](crate::Scheme::GeneralizedAlpha) ([`Scheme::steps_model`](crate::Scheme::steps_model)).
    fn offers_model_schemes(&self) -> bool {
        false
    }
    /// One RATTLE step of the state `x` from `t` to `t + h`
    /// ([`crate::simulate::rattle`]); returns the iterations of its position
    /// step. Called only where [`offers_model_schemes`](Self::offers_model_schemes).
    fn rattle(&mut self, x: &mut [f64], t: f64, h: f64) -> Result<u32, RattleFailure> {
        let _ = (x, t, h);
        unreachable!("a system that does not offer RATTLE")
    }
    /// Makes generalized-α's buffers and Newton matrix pattern, and starts
    /// it at `(q0, v0)` with step `h`, before the first
    /// [`generalized_alpha`](Self::generalized_alpha) step.
    fn prepare_generalized_alpha(&mut self, settings: GeneralizedAlpha, q0: &[f64], v0: &[f64], h: f64) {
        let _ = (settings, q0, v0, h);
        unreachable!("a system that does not offer generalized-α")
    }
    /// One generalized-α step of the state `x` from `t` to `t + h`
    /// ([`crate::simulate::generalized_alpha`]). Called only where
    /// [`offers_model_schemes`](Self::offers_model_schemes), after
    /// [`prepare_generalized_alpha`](Self::prepare_generalized_alpha).
    fn generalized_alpha(&mut self, x: &mut [f64], t: f64, h: f64) -> Result<StepReport, AlphaFailure> {
        let _ = (x, t, h);
        unreachable!("a system that does not offer generalized-α")
    }
    /// Forgets what it kept of evaluations before the state `x` at time `t`
    /// (an input changed the forces): RATTLE's evaluation at the state,
    /// generalized-α's accelerations, which start again from `x`.
    fn restart(&mut self, x: &[f64], t: f64) {
        let _ = (x, t);
    }
    /// Holds, from the state `x` on, the energy and the momenta at their
    /// values there: sets `x`'s `∫Ė` so that `Ψ = 0`, and the kept
    /// momenta's targets. For a part step from an impact
    /// ([`crate::stops`]), which changed them and must not be undone.
    fn hold_from(&mut self, x: &mut [f64]) {
        let _ = x;
        unreachable!("a system without stops")
    }
    /// The momenta the system keeps ([`crate::dynamics::momentum`]); none unless it finds them.
    fn symmetries(&self) -> &Symmetries {
        &NO_SYMMETRIES
    }
    /// The value at the state `x` of momentum `j` of [`Symmetries::direction`].
    fn momentum(&mut self, j: usize, x: &[f64]) -> f64 {
        let _ = (j, x);
        0.0
    }
}

/// Why a RATTLE step failed.
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub enum RattleFailure {
    /// The dynamics could not be evaluated.
    Eval(EvalError),
    /// The position step did not reach `Φ = 0` within
    /// [`MAX_ITERATIONS`](crate::simulate::rattle::MAX_ITERATIONS).
    Positions {
        /// The worst constraint row.
        row: usize,
        /// Its `|Φ|`.
        residual: f64,
        /// Iterations taken.
        iterations: u32,
    },
}

/// Why a generalized-α step failed.
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub enum AlphaFailure {
    /// The dynamics could not be evaluated at an iterate.
    Eval(EvalError),
    /// The Newton matrix is singular (or its solution not finite) though
    /// the constraint rows are independent (or the dependent ones dropped).
    Singular {
        /// Corrections taken before.
        iterations: u32,
    },
    /// Newton did not converge within its allowed corrections.
    NotConverged {
        /// `|Δq|∞` of the correction that would come next.
        correction: f64,
        /// Corrections taken.
        iterations: u32,
    },
}

static NO_SYMMETRIES: Symmetries = Symmetries::NONE;

/// Splits a state into `(q, v, e)`.
pub fn split_state(x: &[f64], n: usize) -> (&[f64], &[f64], f64) {
    (&x[..n], &x[n..2 * n], x[2 * n])
}

/// Splits a state into `(q, v, e)`, each to be written.
fn split_state_mut(x: &mut [f64], n: usize) -> (&mut [f64], &mut [f64], &mut f64) {
    let (q, rest) = x.split_at_mut(n);
    let (v, e) = rest.split_at_mut(n);
    (q, v, &mut e[0])
}
