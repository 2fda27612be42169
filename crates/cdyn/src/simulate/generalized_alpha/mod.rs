//! Generalized-α (Chung & Hulbert 1993) for the index-3 equations of
//! motion, in the form Arnold & Brüls (2007) analyse for multibody
//! systems: `Φ(q, t) = 0` holds at every step to the Newton tolerance.
//!
//! From `(q_n, v_n)`, the accelerations `q̈_n` and the auxiliary
//! accelerations `a_n` (`a_0 = q̈_0`):
//!
//! ```text
//! q_{n+1} = q_n + h v_n + h² (½ − β) a_n + h² β a_{n+1}
//! v_{n+1} = v_n + h (1 − γ) a_n + h γ a_{n+1}
//! (1 − α_m) a_{n+1} + α_m a_n = (1 − α_f) q̈_{n+1} + α_f q̈_n
//! M q̈_{n+1} + Φ_qᵀ λ_{n+1} = G(q_{n+1}, v_{n+1}, t_{n+1})
//! Φ(q_{n+1}, t_{n+1}) = 0        (nonholonomic rows: A v_{n+1} + b = 0)
//! ```
//!
//! with `α_m = (2ρ∞ − 1)/(ρ∞ + 1)`, `α_f = ρ∞/(ρ∞ + 1)`,
//! `γ = ½ + α_f − α_m`, `β = ¼ (γ + ½)²`: second order, unconditionally
//! stable on linear problems, and damping the modes far above `1/h` to
//! the spectral radius `ρ∞` per step (1: none, 0: at once) while those
//! well below it keep their amplitude to `O(h³)` per step.
//!
//! Newton iterates on `q̈_{n+1}` and `λ_{n+1}`. Its unknowns are the
//! position change `Δq = Δq̈ / β′` and `Δμ = Δλ / β′`, `β′ = (1 − α_m) /
//! (h² β (1 − α_f))`, which make every block of the matrix of order one:
//!
//! ```text
//! [ M + c_v C + c_q K   Φ_qᵀ ] [Δq]   [ −c_q (M q̈ + Φ_qᵀ λ − G) ]
//! [ Φ_q                 0    ] [Δμ] = [ −Φ   (−(A v + b)/γ′)     ]
//! ```
//!
//! `c_q = 1/β′`, `c_v = γ′/β′`, `γ′ = γ/(h β)`; `K = −∂G/∂q + Σ λ_r ∇²Φ_r`
//! and `C = −∂G/∂v`: the potentials' Hessians, the forces' Jacobians
//! (springs, dampers) and the holonomic constraints' curvatures weighted
//! by the multipliers (their geometric stiffness), each element's by dual
//! numbers. Left out, so that the matrix keeps the sparsity of `M` and the
//! elements: the derivatives of `M(q) q̈` in `q`, of Lagrange's velocity
//! terms and of the nonholonomic rows' `Aᵀλ`, which are `O(h²)` against
//! `M`. The iteration is then quasi-Newton: the matrix is factored at the
//! step's first iterate (sparse LU, its ordering analysed once per model)
//! and again at any iterate whose correction is more than half the one
//! before (with a fixed count of corrections, only at the first). Without
//! the curvatures and the refactoring, Andrews' squeezer (multipliers of
//! 100 N on links of 2–4 cm) did not converge at h = 7.5e-4; with them it
//! runs there, and stops at 1e-3.
//!
//! With [`DependentRows::Tolerate`] each new Newton matrix comes with a
//! factorization of `Φ_q M⁻¹ Φ_qᵀ` at its iterate (a full evaluation), and
//! the rows it drops get `Δμ_r = 0` and `λ_r = 0`: the explicit schemes'
//! basic solution (Bricard's mechanism, the N four-bar's flat position).

//!
//! Here the settings and the state between steps with its buffers; in
//! `start` its allocation and the first consistent accelerations, in
//! `step` the Newton iteration of one step, in `newton` its right-hand
//! side and matrix.
//!
//! May import: `error`, `dynamics`, `linalg`, `model`.

mod newton;
mod start;
mod step;

pub(crate) use step::step;

use crate::dynamics::{Breakdown, DependentRows, Dynamics};
use crate::error::{Error, Result};
use crate::linalg::lu::Lu;
use crate::linalg::mass::MassMatrix;
use crate::model::Model;

/// How generalized-α iterates its implicit equations
/// ([`Scheme::GeneralizedAlpha`](crate::Scheme::GeneralizedAlpha)):
/// [`GeneralizedAlpha::new`] and the `with_*` setters.
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub struct GeneralizedAlpha {
    /// The spectral radius at infinite frequency, `ρ∞ ∈ [0, 1]`.
    pub rho_inf: f64,
    /// When the Newton iteration stops.
    pub newton: Newton,
}

/// When the Newton iteration of an implicit step stops.
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub enum Newton {
    /// When the next correction of the accelerations is below
    /// `tolerance` × the largest acceleration of the last step (at least
    /// 1), or the position correction it makes is at the round-off of
    /// the positions (100 ε × the largest coordinate, at least 1; at
    /// small steps that is the accelerations' own round-off); more than
    /// `max_iterations` stop the run. The accelerations, not the
    /// positions, are judged: an error `δ` left in `q̈` at every step
    /// moves the positions by about `δ t²/2` over a run, while the same
    /// iterate's position correction is only `h² β δ`. Also when the
    /// corrections stop shrinking at an iterate whose residual is already
    /// within `tolerance` of the equations' terms (and `Φ` at round-off):
    /// near a singular position the matrix magnifies round-off into
    /// corrections no iteration removes ([`StepReport::correction`] then
    /// reports the one left).
    Converge {
        /// The correction's bound, relative to the largest acceleration.
        tolerance: f64,
        /// Corrections allowed per step.
        max_iterations: u32,
    },
    /// After exactly this many corrections, whatever they reach: every
    /// step costs the same (`iterations + 1` evaluations and one
    /// factorization), for real-time runs. The run reports the largest
    /// correction left ([`StepReport::correction`]).
    Fixed {
        /// Corrections per step (at least 1).
        iterations: u32,
    },
}

impl Newton {
    /// Converging to `tolerance`, within `max_iterations`.
    pub fn converge(tolerance: f64, max_iterations: u32) -> Self {
        Self::Converge { tolerance, max_iterations }
    }
    /// Exactly `iterations` corrections a step.
    pub fn fixed(iterations: u32) -> Self {
        Self::Fixed { iterations }
    }
}

crate::setters!(GeneralizedAlpha {
    /// With this `ρ∞`.
    with_rho_inf => rho_inf: f64,
    /// With this Newton iteration.
    with_newton => newton: Newton,
});

impl Default for GeneralizedAlpha {
    fn default() -> Self {
        Self::new()
    }
}

impl GeneralizedAlpha {
    /// `ρ∞ = 0.9`, Newton to 1e-10 within 50 corrections: room for the
    /// damping, whose halvings (to 1/256) and return to the last accepted
    /// iterate take up to 9 evaluations each time the residual grows.
    pub fn new() -> Self {
        Self { rho_inf: 0.9, newton: Newton::converge(1e-10, 50) }
    }

    /// Checks `ρ∞` and the iteration's bounds.
    pub fn validate(&self) -> Result<()> {
        let bad = |name, value, reason| Err(Error::InvalidParameter { name, value, reason });
        if !(0.0..=1.0).contains(&self.rho_inf) {
            return bad("rho_inf", self.rho_inf, "must lie in [0, 1]");
        }
        match self.newton {
            Newton::Converge { tolerance, .. } if !(tolerance > 0.0 && tolerance.is_finite()) => {
                bad("newton tolerance", tolerance, "must be positive")
            }
            Newton::Converge { max_iterations: 0, .. } => bad("newton max_iterations", 0.0, "must be at least 1"),
            Newton::Fixed { iterations: 0 } => bad("newton iterations", 0.0, "must be at least 1"),
            _ => Ok(()),
        }
    }

    /// `(α_m, α_f, γ, β)` of `ρ∞`.
    pub fn coefficients(&self) -> [f64; 4] {
        let rho = self.rho_inf;
        let alpha_m = (2.0 * rho - 1.0) / (rho + 1.0);
        let alpha_f = rho / (rho + 1.0);
        let gamma = 0.5 + alpha_f - alpha_m;
        [alpha_m, alpha_f, gamma, 0.25 * (gamma + 0.5) * (gamma + 0.5)]
    }
}

/// What one step's Newton iteration did.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StepReport {
    /// Corrections applied.
    pub iterations: u32,
    /// `|Δq̈|∞` of the next correction, not applied, over the largest
    /// acceleration of the last step (at least 1): the error left in the accelerations.
    pub correction: f64,
}

/// Why a generalized-α step failed.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum Failure {
    /// The dynamics could not be evaluated at an iterate (at time `t`).
    Breakdown(Breakdown, f64),
    /// The Newton matrix is singular, or its solution not finite, at
    /// independent constraint rows (dependent ones are the dynamics'
    /// [`Breakdown::Singular`], or dropped), after these corrections.
    Singular { iterations: u32 },
    /// No convergence within the allowed corrections.
    NotConverged { correction: f64, iterations: u32 },
}

/// The scheme's state between steps and its buffers, allocated once per model.
#[derive(Clone)]
pub(crate) struct Work {
    settings: GeneralizedAlpha,
    /// Per constraint row: holonomic (its value is `Φ`) or not (`A v + b`).
    holonomic: Vec<bool>,
    /// With [`DependentRows::Tolerate`]: the rows the factorization of
    /// `Φ_q M⁻¹ Φ_qᵀ` at the iterate of the last Newton matrix dropped as
    /// dependent, and the probe that finds them.
    tolerate: bool,
    dropped: Vec<bool>,
    any_dropped: bool,
    probe: Vec<f64>,
    /// Entries of the Newton matrix: `M`, then the elements', `Φ_q`, `Φ_qᵀ`.
    mass_entries: usize,
    /// Of them, the potentials' and forces' (the rest are the constraints' curvatures).
    force_entries: usize,
    element_entries: usize,
    values: Vec<f64>,
    lu: Lu,
    /// `q̈_n`, `a_n`, `λ_n`, and whether they are known (after the first step).
    acc: Vec<f64>,
    aux: Vec<f64>,
    lambda: Vec<f64>,
    started: bool,
    /// `Ė` at the end of the last step.
    power: f64,
    /// Whether a projection follows every step, so that `Ė` takes the
    /// multipliers of a full evaluation (see `step`).
    projected: bool,
    /// The iterate: `q̈`, `a`, `λ`; the step's start `(q_n, v_n)`.
    acc_new: Vec<f64>,
    aux_new: Vec<f64>,
    lambda_new: Vec<f64>,
    q0: Vec<f64>,
    v0: Vec<f64>,
    /// The Newton right-hand side and solution, `n + m`.
    rhs: Vec<f64>,
    /// The last accepted iterate (`q̈`, then `λ`) and the full correction
    /// taken from it, `n + m`: where a damped iterate steps back to.
    base: Vec<f64>,
    along: Vec<f64>,
    /// The sizes of the residual's terms, `n` (see `settled`).
    terms: Vec<f64>,
}

/// A Newton correction larger than this fraction of the one before makes
/// the next iterate refactor the matrix.
const SLOW_CONTRACTION: f64 = 0.5;

/// The shortest share of a correction a damped Newton iterate takes
/// (halved from 1 while the residual does not shrink): past it the
/// iteration goes on from there, to converge or run out of iterations.
const MIN_DAMPING: f64 = 1.0 / 256.0;

/// A position correction this small (relative to the largest coordinate)
/// is round-off: Newton stops there whatever its tolerance.
const POSITION_ROUND_OFF: f64 = 100.0 * f64::EPSILON;

/// The Newton system's scaling at step `h` (see the module's notes).
struct Scaling {
    beta_prime: f64,
    gamma_prime: f64,
    c_q: f64,
    c_v: f64,
}
