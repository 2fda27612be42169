//! How to simulate — the scheme, the step, the control law and the checks
//! ([`Settings`]) — and the time grid a run steps on: a whole number of
//! fixed steps to the end time ([`steps_to`]).

use crate::control::Control;
use crate::dynamics::{DependentRows, LinearSolver};
use crate::error::{Error, Result, positive};
use crate::integrate::Scheme;
use crate::simulate::generalized_alpha::GeneralizedAlpha;

/// How to simulate: [`Settings::new`] and the `with_*` setters.
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub struct Settings {
    /// The fixed-step scheme.
    pub scheme: Scheme,
    /// The step size.
    pub h: f64,
    /// The stabilization method.
    pub control: Control,
    /// The initial state must satisfy `|Φ|, |Φ̇| ≤` this, unless `None`.
    pub consistency_tolerance: Option<f64>,
    /// Stop when `max |Φ|` exceeds this.
    pub violation_limit: f64,
    /// Dense or sparse factorization of `Φ_q M⁻¹ Φ_qᵀ` (default: by size).
    pub solver: LinearSolver,
    /// Whether a dependent constraint row stops the run (the default) or
    /// is solved around (redundant constraints, singular positions).
    pub dependent_rows: DependentRows,
    /// `ρ∞` and the Newton iteration of [`Scheme::GeneralizedAlpha`] (unused by the other schemes).
    pub generalized_alpha: GeneralizedAlpha,
}

crate::setters!(Settings {
    /// With this scheme.
    with_scheme => scheme: Scheme,
    /// With this step size.
    with_h => h: f64,
    /// With this stabilization method.
    with_control => control: Control,
    /// With the initial state checked to this `|Φ|, |Φ̇|`, or not checked (`None`).
    with_consistency_tolerance => consistency_tolerance: Option<f64>,
    /// Stopping when `max |Φ|` exceeds this.
    with_violation_limit => violation_limit: f64,
    /// With this factorization of `Φ_q M⁻¹ Φ_qᵀ`.
    with_solver => solver: LinearSolver,
    /// With dependent constraint rows an error or solved around.
    with_dependent_rows => dependent_rows: DependentRows,
    /// With this `ρ∞` and Newton iteration for generalized-α.
    with_generalized_alpha => generalized_alpha: GeneralizedAlpha,
});

impl Settings {
    /// These choices, a consistency tolerance of 1e-9, no violation limit
    /// and the solver chosen by size.
    pub fn new(scheme: Scheme, h: f64, control: Control) -> Self {
        Self {
            scheme,
            h,
            control,
            consistency_tolerance: Some(1e-9),
            violation_limit: f64::INFINITY,
            solver: LinearSolver::Auto,
            dependent_rows: DependentRows::Error,
            generalized_alpha: GeneralizedAlpha::new(),
        }
    }

    /// Checks `h`, the gains and the tolerances.
    pub fn validate(&self) -> Result<()> {
        positive("h", self.h)?;
        self.control.validate()?;
        self.generalized_alpha.validate()?;
        if let Some(tol) = self.consistency_tolerance {
            positive("consistency tolerance", tol)?;
        }
        if self.violation_limit.is_nan() || self.violation_limit <= 0.0 {
            return Err(Error::InvalidParameter {
                name: "violation limit",
                value: self.violation_limit,
                reason: "must be positive",
            });
        }
        Ok(())
    }
}

/// Relative tolerance of "a whole number of steps": absorbs the round-off
/// of decimal inputs (`20.0 / 0.01` is `1999.9999999999998`), far below any
/// step a user means.
const WHOLE_STEPS_TOLERANCE: f64 = 1e-9;

/// Number of steps of size `h` that end exactly at `t_end`.
///
/// The rule: `t_end` must be a whole number of steps (to a relative 1e-9).
/// The last step is never shortened or stretched — a shortened step would
/// break the fixed step every scheme and the multistep history assume — and
/// a run never overshoots `t_end`. `h > t_end` and any other `t_end` are an
/// [`Error::InvalidParameter`] naming `h` or `t_end`; [`nearest_valid_t_end`]
/// is the end time to suggest instead.
///
/// ```
/// use cdyn::simulate::{nearest_valid_t_end, steps_to};
/// assert_eq!(steps_to(20.0, 0.01)?, 2000);
/// assert!(steps_to(0.105, 0.01).is_err());
/// assert!(steps_to(0.1, 0.5).is_err());
/// assert!((nearest_valid_t_end(0.1049, 0.01) - 0.1).abs() < 1e-12);
/// # Ok::<(), cdyn::Error>(())
/// ```
pub fn steps_to(t_end: f64, h: f64) -> Result<u64> {
    positive("t_end", t_end)?;
    positive("h", h)?;
    let ratio = t_end / h;
    if ratio > 1e12 {
        return Err(Error::InvalidParameter { name: "t_end / h", value: ratio, reason: "more than 1e12 steps" });
    }
    let steps = ratio.round();
    if steps >= 1.0 && (ratio - steps).abs() <= WHOLE_STEPS_TOLERANCE * ratio {
        Ok(steps as u64)
    } else if ratio < 1.0 {
        Err(Error::InvalidParameter { name: "h", value: h, reason: "must not exceed t_end" })
    } else {
        Err(Error::InvalidParameter { name: "t_end", value: t_end, reason: "must be a whole number of steps h" })
    }
}

/// The end time nearest to `t_end` that [`steps_to`] accepts for `h`: a
/// whole number of steps, at least one. It is rounded to 12 significant
/// digits so that it prints as a user would write it (`0.11`, not
/// `0.10999999999999999`); that moves it far less than the tolerance.
pub fn nearest_valid_t_end(t_end: f64, h: f64) -> f64 {
    crate::error::tidy_time((t_end / h).round().max(1.0) * h)
}
