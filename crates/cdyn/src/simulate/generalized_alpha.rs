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

use crate::dynamics::{Breakdown, DependentRows, Dynamics};
use crate::error::{Error, Result};
use crate::linalg::mass::MassMatrix;
use crate::linalg::sparse_lu::SparseLu;
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
    /// `ρ∞ = 0.9`, Newton to 1e-10 within 20 corrections.
    pub fn new() -> Self {
        Self { rho_inf: 0.9, newton: Newton::converge(1e-10, 20) }
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
    lu: SparseLu,
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
    /// The sizes of the residual's terms, `n` (see `settled`).
    terms: Vec<f64>,
}

impl Work {
    /// For `model`, with the mass matrix as `d` holds it, what a dependent
    /// constraint row does (as `d` is set to), and whether a projection
    /// follows every step.
    pub(crate) fn new(
        model: &Model,
        d: &Dynamics,
        settings: GeneralizedAlpha,
        dependent: DependentRows,
        projected: bool,
    ) -> Self {
        let (n, m) = (model.n(), model.m());
        let mut entries = Vec::new();
        d.mass(model).entries(&mut entries);
        let mass_entries = entries.len();
        model.iteration_entries(&mut entries);
        let force_entries = entries.len() - mass_entries;
        model.curvature_entries(&mut entries);
        let element_entries = entries.len() - mass_entries;
        let pattern = model.pattern();
        for r in 0..m {
            for j in pattern.row(r) {
                entries.push(((n + r) as u32, pattern.cols[j]));
            }
        }
        for r in 0..m {
            for j in pattern.row(r) {
                entries.push((pattern.cols[j], (n + r) as u32));
            }
        }
        // The zero block's diagonal, listed for the pivoting's sake.
        entries.extend((n..n + m).map(|i| (i as u32, i as u32)));
        Self {
            settings,
            holonomic: model.holonomic_rows(),
            tolerate: dependent == DependentRows::Tolerate,
            dropped: vec![false; m],
            any_dropped: false,
            probe: vec![0.0; m],
            mass_entries,
            force_entries,
            element_entries,
            values: vec![0.0; entries.len()],
            lu: SparseLu::new(n + m, &entries),
            acc: vec![0.0; n],
            aux: vec![0.0; n],
            lambda: vec![0.0; m],
            started: false,
            power: 0.0,
            projected,
            acc_new: vec![0.0; n],
            aux_new: vec![0.0; n],
            lambda_new: vec![0.0; m],
            q0: vec![0.0; n],
            v0: vec![0.0; n],
            rhs: vec![0.0; n + m],
            terms: vec![0.0; n],
        }
    }
}

/// A Newton correction larger than this fraction of the one before makes
/// the next iterate refactor the matrix.
const SLOW_CONTRACTION: f64 = 0.5;

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

impl Work {
    fn scaling(&self, h: f64) -> Scaling {
        let [alpha_m, alpha_f, gamma, beta] = self.settings.coefficients();
        let beta_prime = (1.0 - alpha_m) / (h * h * beta * (1.0 - alpha_f));
        let gamma_prime = gamma / (h * beta);
        Scaling { beta_prime, gamma_prime, c_q: 1.0 / beta_prime, c_v: gamma_prime / beta_prime }
    }

    /// Consistent accelerations and multipliers at `(q, v, t)`, `a_0 =
    /// q̈_0`; and one factorization of the Newton matrix there, which sizes
    /// the factors' storage for the pivoting of the steps to come.
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn start(
        &mut self,
        model: &Model,
        d: &mut Dynamics,
        q: &[f64],
        v: &[f64],
        t: f64,
        h: f64,
        evaluations: &mut u64,
    ) -> std::result::Result<(), Failure> {
        self.restart(model, d, q, v, t, evaluations)?;
        let Scaling { c_q, c_v, .. } = self.scaling(h);
        newton_matrix(model, d, q, v, t, c_q, c_v, self);
        self.lu.reserve(&self.values);
        Ok(())
    }

    /// Starts again at `(q, v, t)` from the accelerations there, as after
    /// an input changed the forces: `q̈`, `a`, `λ` and `Ė` of one evaluation.
    pub(crate) fn restart(
        &mut self,
        model: &Model,
        d: &mut Dynamics,
        q: &[f64],
        v: &[f64],
        t: f64,
        evaluations: &mut u64,
    ) -> std::result::Result<(), Failure> {
        *evaluations += 1;
        d.evaluate(model, q, v, t).map_err(|b| Failure::Breakdown(b, t))?;
        self.find_dropped(d);
        self.acc.copy_from_slice(d.acc());
        self.aux.copy_from_slice(d.acc());
        self.lambda.copy_from_slice(d.lambda());
        self.lambda_new.copy_from_slice(d.lambda());
        self.power = d.energy_input();
        self.started = true;
        Ok(())
    }

    /// After a full evaluation with [`DependentRows::Tolerate`], marks the
    /// rows it dropped: their multipliers are exactly 0 in every solve with
    /// its factorization (see `linalg::schur`), so a solve of a right-hand
    /// side with no zero entry finds them. Their multipliers are set to 0.
    fn find_dropped(&mut self, d: &Dynamics) {
        if !self.tolerate || (d.dependent_rows() == 0 && !self.any_dropped) {
            return;
        }
        self.any_dropped = d.dependent_rows() > 0;
        if self.any_dropped {
            // Generic values, none zero, so that no independent row's solution is 0 by chance.
            for (r, p) in self.probe.iter_mut().enumerate() {
                *p = 1.0 + (r as f64 * 0.618_033_988_749_895).fract();
            }
            d.solve_many(&mut [&mut self.probe]);
        }
        for ((dropped, p), l) in self.dropped.iter_mut().zip(&self.probe).zip(&mut self.lambda_new) {
            *dropped = self.any_dropped && *p == 0.0;
            if *dropped {
                *l = 0.0;
            }
        }
    }
}

/// One step of `(q, v, e)` from `t` to `t + h`, counting the evaluations
/// of the dynamics in `evaluations`.
#[allow(clippy::too_many_arguments)]
pub(crate) fn step(
    model: &Model,
    d: &mut Dynamics,
    q: &mut [f64],
    v: &mut [f64],
    e: &mut f64,
    t: f64,
    h: f64,
    w: &mut Work,
    evaluations: &mut u64,
) -> std::result::Result<StepReport, Failure> {
    let n = model.n();
    if !w.started {
        w.start(model, d, q, v, t, h, evaluations)?;
    }
    let Scaling { beta_prime, gamma_prime, c_q, c_v } = w.scaling(h);
    let [alpha_m, alpha_f, gamma, beta] = w.settings.coefficients();
    w.q0.copy_from_slice(q);
    w.v0.copy_from_slice(v);
    // The predictor: the accelerations and multipliers of the last step.
    w.acc_new.copy_from_slice(&w.acc);
    w.lambda_new.copy_from_slice(&w.lambda);
    let states = |w: &mut Work, q: &mut [f64], v: &mut [f64]| {
        for i in 0..n {
            let aux = ((1.0 - alpha_f) * w.acc_new[i] + alpha_f * w.acc[i] - alpha_m * w.aux[i]) / (1.0 - alpha_m);
            w.aux_new[i] = aux;
            q[i] = w.q0[i] + h * w.v0[i] + h * h * ((0.5 - beta) * w.aux[i] + beta * aux);
            v[i] = w.v0[i] + h * ((1.0 - gamma) * w.aux[i] + gamma * aux);
        }
    };
    states(w, q, v);
    let scale = w.acc.iter().fold(1.0_f64, |a, x| a.max(x.abs()));
    // The accelerations' round-off: that of the positions, over h² β.
    let round_off = POSITION_ROUND_OFF * beta_prime * w.q0.iter().fold(1.0_f64, |a, x| a.max(x.abs())) / scale;
    let t1 = t + h;
    let (mut iterations, mut last) = (0, f64::INFINITY);
    let mut refactor = true;
    let correction = loop {
        *evaluations += 1;
        // A fresh Newton matrix with tolerated dependent rows: the full
        // evaluation factors `Φ_q M⁻¹ Φ_qᵀ` at the iterate, which finds them.
        let rank_revealed = refactor && w.tolerate;
        let evaluated = if rank_revealed { d.evaluate(model, q, v, t1) } else { d.evaluate_forces(model, q, v, t1) };
        evaluated.map_err(|b| Failure::Breakdown(b, t1))?;
        if rank_revealed {
            w.find_dropped(d);
        }
        residual(model, d, w, c_q, gamma_prime);
        // The last correction did not halve the one before. Where the
        // iterate already solves the equations (its residual), the
        // corrections are round-off magnified by a near-singular matrix (a
        // mechanism near a singular position), and no iteration improves
        // on it: the step ends, reporting the correction it could not make.
        if let Newton::Converge { tolerance, .. } = w.settings.newton
            && refactor
            && iterations > 0
            && settled(model, d, w, q, v, c_q, gamma_prime, tolerance)
        {
            break last;
        }
        if refactor {
            newton_matrix(model, d, q, v, t1, c_q, c_v, w);
            if w.lu.factor(&w.values).is_err() {
                return Err(singular(model, d, q, v, t1, iterations));
            }
        }
        w.lu.solve(&mut w.rhs);
        let correction = beta_prime * w.rhs[..n].iter().fold(0.0_f64, |a, x| a.max(x.abs())) / scale;
        // Converging slower than halving a correction: the matrix of the
        // step's start is too far from the iterate's (the multipliers and
        // the configuration moved), so the next correction gets a fresh
        // one. A fixed count keeps one factorization a step.
        refactor = matches!(w.settings.newton, Newton::Converge { .. }) && correction > SLOW_CONTRACTION * last;
        last = correction;
        if !correction.is_finite() || w.rhs[n..].iter().any(|x| !x.is_finite()) {
            return Err(singular(model, d, q, v, t1, iterations));
        }
        match w.settings.newton {
            Newton::Converge { tolerance, .. } if correction <= tolerance + round_off => break correction,
            Newton::Converge { max_iterations, .. } if iterations == max_iterations => {
                return Err(Failure::NotConverged { correction, iterations });
            }
            Newton::Fixed { iterations: fixed } if iterations == fixed => break correction,
            _ => {}
        }
        for (a, dq) in w.acc_new.iter_mut().zip(&w.rhs[..n]) {
            *a += beta_prime * dq;
        }
        for (l, dmu) in w.lambda_new.iter_mut().zip(&w.rhs[n..]) {
            *l += beta_prime * dmu;
        }
        states(w, q, v);
        iterations += 1;
    };
    std::mem::swap(&mut w.acc, &mut w.acc_new);
    std::mem::swap(&mut w.aux, &mut w.aux_new);
    std::mem::swap(&mut w.lambda, &mut w.lambda_new);
    // Ė = F·v + λᵀΦ_t at the last evaluated iterate, with its λ. After a
    // projection of the velocities (by O(h²) across the constraints) the
    // next step's positions move by O(h³) across them, which the index-3
    // equations answer with an O(h) change of λ: the drives' work λᵀΦ_t
    // would then be integrated to O(h) only (measured: the driven
    // slider-crank's |Ψ| 2.5e-2 at h = 1e-3 and 1.3e-2 at 5e-4, the moving
    // support pendulum 40× farther from the truth than without). With a
    // projection Ė takes the multipliers of a full evaluation at the new
    // state, which the projection's own first evaluation then reuses.
    let power = if w.projected {
        *evaluations += 1;
        d.evaluate(model, q, v, t1).map_err(|b| Failure::Breakdown(b, t1))?;
        d.energy_input()
    } else {
        crate::dynamics::energy::power(d.force_power(), &w.lambda, d.phi_t())
    };
    *e += 0.5 * h * (w.power + power);
    w.power = power;
    Ok(StepReport { iterations, correction })
}

/// Why the Newton matrix at `(q, v, t)` is singular: a dependent
/// constraint row (the dynamics' [`Breakdown::Singular`](crate::dynamics::Breakdown::Singular),
/// unless tolerated, where the rows were dropped), or else the rest of the
/// matrix.
fn singular(model: &Model, d: &mut Dynamics, q: &[f64], v: &[f64], t: f64, iterations: u32) -> Failure {
    match d.evaluate(model, q, v, t) {
        Err(b) => Failure::Breakdown(b, t),
        Ok(()) => Failure::Singular { iterations },
    }
}

/// The Newton right-hand side at the iterate, into `w.rhs`; the dropped
/// rows' equations are `Δμ_r = 0`.
fn residual(model: &Model, d: &Dynamics, w: &mut Work, c_q: f64, gamma_prime: f64) {
    let n = model.n();
    let (top, rows) = w.rhs.split_at_mut(n);
    d.mass(model).mul(&w.acc_new, top);
    d.add_jt(model, &w.lambda_new, top);
    for (x, g) in top.iter_mut().zip(d.force()) {
        *x = -c_q * (*x - g);
    }
    for (r, x) in rows.iter_mut().enumerate() {
        *x = if w.dropped[r] {
            0.0
        } else if w.holonomic[r] {
            -d.phi()[r]
        } else {
            -d.phi_dot()[r] / gamma_prime
        };
    }
}

/// Whether the iterate solves the step's equations as well as they can
/// be solved, judged by its residual in `w.rhs` (not by the correction
/// that residual would make): each constraint row at the round-off of
/// evaluating it, `100 ε` of `|Φ_q| |q|` (holonomic, in the row's own
/// units) or of `|A| |v|` (nonholonomic); the equations of motion within
/// `tolerance` of the size of their terms, `|M q̈| + |Φ_q|ᵀ|λ| + |G|`, the
/// largest residual against the largest term (a backward error of the
/// accelerations, where the correction is their forward error).
#[allow(clippy::too_many_arguments)]
fn settled(
    model: &Model,
    d: &Dynamics,
    w: &mut Work,
    q: &[f64],
    v: &[f64],
    c_q: f64,
    gamma_prime: f64,
    tolerance: f64,
) -> bool {
    let n = model.n();
    let (pattern, jac) = (model.pattern(), d.jac());
    let terms = &mut w.terms;
    d.mass(model).mul(&w.acc_new, terms);
    for (x, g) in terms.iter_mut().zip(d.force()) {
        *x = x.abs() + g.abs();
    }
    for (r, l) in w.lambda_new.iter().enumerate() {
        for j in pattern.row(r) {
            terms[pattern.cols[j] as usize] += (jac[j] * l).abs();
        }
    }
    let (top, rows) = w.rhs.split_at(n);
    let largest = |x: &[f64]| x.iter().fold(0.0_f64, |a, x| a.max(x.abs()));
    largest(top) <= c_q * tolerance * largest(terms)
        && rows.iter().enumerate().all(|(r, x)| {
            let (values, over) = if w.holonomic[r] { (q, 1.0) } else { (v, gamma_prime) };
            let size: f64 = pattern.row(r).map(|j| (jac[j] * values[pattern.cols[j] as usize]).abs()).sum();
            x.abs() <= POSITION_ROUND_OFF * size / over
        })
}

/// The Newton matrix's values at the iterate, into `w.values`.
#[allow(clippy::too_many_arguments)]
fn newton_matrix(model: &Model, d: &Dynamics, q: &[f64], v: &[f64], t: f64, c_q: f64, c_v: f64, w: &mut Work) {
    let (mass, rest) = w.values.split_at_mut(w.mass_entries);
    d.mass(model).entry_values(mass);
    let (elements, rest) = rest.split_at_mut(w.element_entries);
    let (forces, curvatures) = elements.split_at_mut(w.force_entries);
    model.iteration_values(q, v, t, c_q, c_v, forces);
    model.curvature_values(q, t, &w.lambda_new, c_q, curvatures);
    let nnz = model.pattern().nnz();
    let (jac, rest) = rest.split_at_mut(nnz);
    let (jac_t, zeros) = rest.split_at_mut(nnz);
    jac.copy_from_slice(d.jac());
    jac_t.copy_from_slice(d.jac());
    zeros.fill(0.0);
    // A dropped row: `Δμ_r = 0`, and no reaction `Φ_qᵀ` from it.
    if w.any_dropped {
        let pattern = model.pattern();
        for (r, _) in w.dropped.iter().enumerate().filter(|(_, d)| **d) {
            jac[pattern.row(r)].fill(0.0);
            jac_t[pattern.row(r)].fill(0.0);
            zeros[r] = 1.0;
        }
    }
}
