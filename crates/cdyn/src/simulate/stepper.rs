//! The simulation loop: a model, a control law and a scheme stepped from
//! a consistent initial state, with observers called every `k` steps. A
//! step that leaves the state non-finite, or the violation past a limit,
//! stops the run with an error naming the step and time; observers have
//! seen every step before it.

use crate::control::gains::{Operators, Tuning, resolve};
use crate::control::projection::{Failure, OnFailure};
use crate::dynamics::DependentRows;
use crate::dynamics::diagnostics::Measures;
use crate::dynamics::momentum::Symmetries;
use crate::error::{Error, Result};
use crate::integrate::{Buffer, Integrator, Scheme};
use crate::simulate::settings::{Settings, steps_to};
use crate::simulate::system::{AlphaFailure, EvalError, RattleFailure, System};

/// A running simulation of any controlled [`System`]: the general
/// [`Simulation`](crate::simulate::Simulation) of a [`Model`](crate::model::Model), or a [`SmallSimulation`](crate::small::SmallSimulation).
///
/// A clone is a snapshot: the state, the scheme's history, the gains and
/// every buffer a step reads, so that stepping the clone repeats the run
/// bit for bit (the model, with the values of its inputs, is shared: see
/// [`Simulation::snapshot`](crate::simulate::Simulation::snapshot)).
#[derive(Clone)]
pub struct Stepper<S: System> {
    pub(super) system: S,
    pub(super) integrator: Integrator<S::State>,
    settings: Settings,
    tuning: Tuning,
    pub(super) x: S::State,
    step: u64,
    /// The time of step 0: 0 but for a part step within one of another
    /// run ([`crate::stops`] steps to an impact inside a step).
    start_time: f64,
    /// Newton iterations of the projection so far, and steps it failed.
    projection_iterations: u64,
    projection_failures: u64,
    /// Steps with dependent constraint rows, if any.
    rank_loss: Option<RankLoss>,
    /// Iterations of RATTLE's position step so far.
    rattle_iterations: u64,
    /// Generalized-α's Newton corrections so far, and the largest one it left.
    newton_iterations: u64,
    newton_correction: f64,
}

/// When the constraints lost rank during a run with
/// [`DependentRows::Tolerate`]: steps in which an evaluation of the
/// right-hand side dropped dependent rows.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct RankLoss {
    /// The most rows one evaluation dropped.
    pub max: usize,
    /// Steps with at least one dropped row.
    pub steps: u64,
    /// Start time of the first such step.
    pub first_time: f64,
    /// Start time of the last such step.
    pub last_time: f64,
}

impl<S: System> Stepper<S> {
    /// Starts `system` at `t = 0` from a checked `(q0, v0)` with valid `settings`.
    pub(crate) fn start(mut system: S, settings: Settings, q0: &[f64], v0: &[f64]) -> Result<Self> {
        match settings.scheme {
            Scheme::Rattle | Scheme::GeneralizedAlpha if !system.offers_model_schemes() => {
                return Err(Error::Unsupported(
                    "schemes rattle and generalized_alpha step a general model (Simulation), not a SmallSimulation",
                ));
            }
            Scheme::Rattle if settings.control.is_active() => {
                return Err(Error::Unsupported(
                    "scheme rattle holds Φ = 0 and Φ̇ = 0 itself: use no control law (method none), or projection to hold the energy as well",
                ));
            }
            Scheme::GeneralizedAlpha if settings.control.is_active() => {
                return Err(Error::Unsupported(
                    "scheme generalized_alpha holds Φ = 0 itself: use no control law (method none), or projection to hold Φ̇ and the energy as well",
                ));
            }
            Scheme::GeneralizedAlpha => {
                system.prepare_generalized_alpha(settings.generalized_alpha, q0, v0, settings.h)
            }
            _ => {}
        }
        let n = q0.len();
        let mut x = system.zero_state();
        x.as_mut_slice()[..n].copy_from_slice(q0);
        x.as_mut_slice()[n..2 * n].copy_from_slice(v0);
        if let Some(tolerance) = settings.consistency_tolerance {
            let m = system.measure(x.as_slice(), 0.0);
            if m.phi.abs() > tolerance || m.phi_dot > tolerance {
                return Err(Error::InconsistentInitialState { phi: m.phi.abs(), phi_dot: m.phi_dot, tolerance });
            }
        }
        // Automatic gains, and the rate × h every control term runs at.
        // A state the dynamics cannot evaluate fails the first step, which
        // reports it with the run's record; the gains are then moot.
        // The projection reads the damping's rate (whether to project `Ψ`);
        // an explicit scheme's run reports the damping's and the springs'
        // rates against its step (a hint where they are stiff).
        let operators = if settings.scheme != Scheme::GeneralizedAlpha || settings.control.projection.is_some() {
            system.operators(x.as_slice(), 0.0).unwrap_or(Operators { coupling: 1.0, ..Operators::default() })
        } else {
            Operators::default()
        };
        let (control, tuning) = resolve(settings.control, settings.scheme, settings.h, operators);
        system.set_control(control);
        let settings = Settings { control, ..settings };
        let integrator = Integrator::with_zero(settings.scheme, settings.control.application, system.zero_state());
        // The gains' evaluation is not a step.
        system.take_dependent_rows();
        Ok(Self {
            system,
            integrator,
            settings,
            tuning,
            x,
            step: 0,
            start_time: 0.0,
            projection_iterations: 0,
            projection_failures: 0,
            rank_loss: None,
            rattle_iterations: 0,
            newton_iterations: 0,
            newton_correction: 0.0,
        })
    }

    /// What the automatic gains were chosen from, and the largest rate × h
    /// of the control terms ([`crate::control::gains`]).
    pub fn tuning(&self) -> &Tuning {
        &self.tuning
    }
    /// Newton iterations of the projection so far (the `projection` method).
    pub fn projection_iterations(&self) -> u64 {
        self.projection_iterations
    }
    /// Steps whose projection did not converge (with `on_failure = continue`).
    pub fn projection_failures(&self) -> u64 {
        self.projection_failures
    }
    /// Iterations of RATTLE's position step so far ([`Scheme::Rattle`]).
    pub fn rattle_iterations(&self) -> u64 {
        self.rattle_iterations
    }
    /// Generalized-α's Newton corrections so far ([`Scheme::GeneralizedAlpha`]).
    pub fn newton_iterations(&self) -> u64 {
        self.newton_iterations
    }
    /// The largest `|Δq|∞` a generalized-α step left uncorrected so far:
    /// below the tolerance when Newton converges, what a fixed number of
    /// corrections reached otherwise.
    pub fn newton_correction(&self) -> f64 {
        self.newton_correction
    }
    /// Steps in which the constraints lost rank so far; `None` if none did.
    pub fn rank_loss(&self) -> Option<&RankLoss> {
        self.rank_loss.as_ref()
    }

    /// The settings it runs with, its control with the automatic gains chosen.
    pub fn settings(&self) -> &Settings {
        &self.settings
    }
    /// Steps taken.
    pub fn steps(&self) -> u64 {
        self.step
    }
    /// Counts on from `previous`, the run this one continues with another
    /// model from `previous`'s end ([`crate::stops`]): its steps (so that
    /// `t` goes on), and the iterations and rank losses of its method, so
    /// that a run's totals cover all of it.
    pub(crate) fn continue_counts<T: System>(&mut self, previous: &Stepper<T>) {
        self.step = previous.step;
        self.projection_iterations += previous.projection_iterations;
        self.projection_failures += previous.projection_failures;
        self.rattle_iterations += previous.rattle_iterations;
        self.newton_iterations += previous.newton_iterations;
        self.newton_correction = self.newton_correction.max(previous.newton_correction);
        self.rank_loss = match (previous.rank_loss, self.rank_loss) {
            (Some(a), Some(b)) => Some(RankLoss {
                max: a.max.max(b.max),
                steps: a.steps + b.steps,
                first_time: a.first_time,
                last_time: b.last_time,
            }),
            (a, b) => a.or(b),
        };
    }
    /// Current time, `step · h` (not accumulated, so it does not drift).
    pub fn t(&self) -> f64 {
        self.start_time + self.step as f64 * self.settings.h
    }

    /// A copy of this run moved to `(q, v)` at time `t0` and stepped once
    /// by `dt`: a part of a step ([`crate::stops`] steps to an impact
    /// within one), with this run's model, gains and symmetries, not the
    /// set-up of a new run (two thirds of it finding the symmetries). Its
    /// `∫Ė` is `e`, the run's own there; without one, the part starts from
    /// an impact and holds the energy and momenta at their values there
    /// ([`System::hold_from`]). The scheme starts afresh, a multistep one
    /// by its start-up scheme, as after any restart.
    pub(crate) fn part_step(&self, q: &[f64], v: &[f64], e: Option<f64>, t0: f64, dt: f64) -> Result<Self>
    where
        S: Clone,
    {
        let mut part = self.clone();
        (part.settings.h, part.step, part.start_time) = (dt, 0, t0);
        if part.settings.scheme == Scheme::GeneralizedAlpha {
            part.system.prepare_generalized_alpha(part.settings.generalized_alpha, q, v, dt);
        }
        let n = q.len();
        let x = part.x.as_mut_slice();
        x[..n].copy_from_slice(q);
        x[n..2 * n].copy_from_slice(v);
        match e {
            Some(e) => x[2 * n] = e,
            None => part.system.hold_from(x),
        }
        part.integrator.restart();
        part.system.restart(part.x.as_slice(), t0);
        part.step()?;
        Ok(part)
    }
    /// Current positions.
    pub fn q(&self) -> &[f64] {
        &self.x.as_slice()[..self.system.n()]
    }
    /// Current velocities.
    pub fn v(&self) -> &[f64] {
        let n = self.system.n();
        &self.x.as_slice()[n..2 * n]
    }
    /// `∫Ė dτ` so far.
    pub fn energy_input(&self) -> f64 {
        self.x.as_slice()[2 * self.system.n()]
    }
    /// `E₀ = T₀ + V₀`.
    pub fn initial_energy(&self) -> f64 {
        self.system.e0()
    }
    /// Right-hand-side evaluations so far.
    pub fn evaluations(&self) -> u64 {
        self.system.evaluations()
    }

    /// The momenta the system keeps, found at the start, and the declared
    /// ones it breaks ([`crate::dynamics::momentum::detect`]).
    pub fn symmetries(&self) -> &Symmetries {
        self.system.symmetries()
    }

    /// The value `eᵀ M v` of momentum `j` at the current state: the kept
    /// ones, then the declared ones the model breaks ([`Symmetries::direction`]).
    pub fn momentum(&mut self, j: usize) -> f64 {
        self.system.momentum(j, self.x.as_slice())
    }

    /// Violations at the current state.
    pub fn measure(&mut self) -> Measures {
        let t = self.t();
        self.system.measure(self.x.as_slice(), t)
    }

    /// One step of size `h`.
    pub fn step(&mut self) -> Result<()> {
        let t = self.t();
        let step = self.step;
        let h = self.settings.h;
        if self.settings.scheme == Scheme::Rattle {
            match self.system.rattle(self.x.as_mut_slice(), t, h) {
                Ok(iterations) => self.rattle_iterations += u64::from(iterations),
                Err(RattleFailure::Eval(e)) => return Err(eval_error(e, step, t + h)),
                Err(RattleFailure::Positions { row, residual, iterations }) => {
                    return Err(Error::RattleFailed { step: step + 1, t: t + h, residual, row, iterations });
                }
            }
        } else if self.settings.scheme == Scheme::GeneralizedAlpha {
            let (step, t) = (step + 1, t + h);
            match self.system.generalized_alpha(self.x.as_mut_slice(), t - h, h) {
                Ok(r) => {
                    self.newton_iterations += u64::from(r.iterations);
                    self.newton_correction = self.newton_correction.max(r.correction);
                }
                Err(AlphaFailure::Eval(e)) => return Err(eval_error(e, step - 1, t)),
                Err(AlphaFailure::Singular { iterations }) => {
                    return Err(Error::NewtonSingular { step, t, iterations });
                }
                Err(AlphaFailure::NotConverged { correction, iterations }) => {
                    return Err(Error::NewtonFailed { step, t, correction, iterations });
                }
            }
        } else {
            self.integrator
                .step(&mut self.system, self.x.as_mut_slice(), t, h)
                .map_err(|e| eval_error(e, step, t + h))?;
        }
        self.step += 1;
        let dropped = match self.settings.dependent_rows {
            DependentRows::Error => 0,
            DependentRows::Tolerate => self.system.take_dependent_rows(),
        };
        if dropped > 0 {
            let r = self.rank_loss.get_or_insert(RankLoss { max: 0, steps: 0, first_time: t, last_time: t });
            (r.max, r.steps, r.last_time) = (r.max.max(dropped), r.steps + 1, t);
        }
        if !all_finite(self.x.as_slice()) {
            return Err(Error::Diverged { step: self.step, t: self.t() });
        }
        if let Some(p) = self.settings.control.projection {
            let t = self.t();
            match self.system.project(self.x.as_mut_slice(), t, self.settings.h, &p) {
                Ok(iterations) => self.projection_iterations += u64::from(iterations),
                Err(f) => {
                    let (invariant, residual, row, iterations) = match f {
                        Failure::Breakdown(b, _) => return Err(eval_error(EvalError::at(b, t), self.step, t)),
                        Failure::Positions { row, residual, iterations } => ("|Φ|", residual, Some(row), iterations),
                        Failure::Energy { residual } => ("|Ψ|", residual, None, p.max_iterations),
                    };
                    if p.on_failure == OnFailure::Stop {
                        return Err(Error::ProjectionFailed {
                            step: self.step,
                            t,
                            invariant,
                            residual,
                            row,
                            iterations,
                        });
                    }
                    self.projection_failures += 1;
                }
            }
        }
        // Φ(x_k) was evaluated at the start of this step: checking it costs nothing.
        if self.settings.violation_limit.is_finite() {
            let phi = self.system.last_violation();
            if phi > self.settings.violation_limit {
                return Err(Error::ViolationLimit { step, t, phi, limit: self.settings.violation_limit });
            }
        }
        Ok(())
    }

    /// Steps until `t_end`, which must be a whole number of steps (see
    /// [`steps_to`]), calling `observe` at the start and after every
    /// `every`-th step and the last.
    pub fn run<E: From<Error>>(
        &mut self,
        t_end: f64,
        every: u64,
        mut observe: impl FnMut(&mut Self) -> Result<(), E>,
    ) -> Result<(), E> {
        let steps = steps_to(t_end, self.settings.h)?;
        let every = every.max(1);
        observe(self)?;
        while self.step < steps {
            self.step()?;
            if self.step.is_multiple_of(every) || self.step == steps {
                observe(self)?;
            }
        }
        Ok(())
    }
}

/// The error of a failed evaluation during step `step` (steps taken before
/// it), at time `t_next` for a state that stopped being finite.
fn eval_error(e: EvalError, step: u64, t_next: f64) -> Error {
    match e {
        EvalError::Singular { t, row } => Error::SingularConstraints { step, t, row },
        EvalError::NonFinite { .. } => Error::Diverged { step: step + 1, t: t_next },
        EvalError::Mass { t, coordinate } => Error::MassNotPositive { step, t, coordinate },
    }
}

/// Whether every value is finite; without early exit inside a chunk, so
/// that the test vectorizes.
#[inline(always)]
fn all_finite(x: &[f64]) -> bool {
    x.chunks(64).all(|c| c.iter().fold(true, |ok, x| ok & x.is_finite()))
}
