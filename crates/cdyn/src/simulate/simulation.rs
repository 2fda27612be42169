//! [`Simulation`]: the [`Stepper`] of a general [`Model`], started from a
//! checked initial state, with its state and inputs changed between steps.

use crate::control::projection::Failure;
use crate::dynamics::momentum;
use crate::error::{Part, Problem, Result};
use crate::linalg::LinearSolver;
use crate::model::Model;
use crate::simulate::settings::Settings;
use crate::simulate::stepper::Stepper;
use crate::simulate::system::{ControlledSystem, System};

/// A running simulation of a [`Model`].
///
/// A harmonic oscillator `ẍ = −x` by RK-4, against `cos t`:
///
/// ```
/// use cdyn::{Control, Model, Potential, Scalar, Scheme, Settings, Simulation};
///
/// struct Spring;
/// impl Potential<1> for Spring {
///     fn energy<D: Scalar>(&self, [x]: [D; 1]) -> D {
///         x * x * 0.5
///     }
/// }
///
/// let model = Model::builder(vec![1.0]).potential(Spring, [0]).build()?;
/// let settings = Settings::new(Scheme::RungeKutta4, 0.01, Control::none());
/// let mut sim = Simulation::new(&model, settings, &[1.0], &[0.0])?;
/// sim.run::<cdyn::Error>(1.0, 10, |_| Ok(()))?;
/// assert_eq!(sim.steps(), 100);
/// assert!((sim.q()[0] - 1f64.cos()).abs() < 1e-9);
/// # Ok::<(), cdyn::Error>(())
/// ```
pub type Simulation<'m> = Stepper<ControlledSystem<'m>>;

impl<'m> Simulation<'m> {
    /// Starts at `t = 0` from `(q0, v0)`, checking the settings and, unless
    /// disabled, that the initial state satisfies the constraints.
    pub fn new(model: &'m Model, settings: Settings, q0: &[f64], v0: &[f64]) -> Result<Self> {
        settings.validate()?;
        check_initial_state(model.n(), q0, v0)?;
        let e0 = model.kinetic(q0, v0) + model.potential(q0, None);
        let mut system = ControlledSystem::with_solver(model, settings.control, e0, settings.solver);
        system.set_dependent_rows(settings.dependent_rows);
        system.set_symmetries(momentum::detect(model, q0, v0));
        // RATTLE and generalized-α step the model, not its right-hand side.
        if settings.solver == LinearSolver::Auto && !settings.scheme.steps_model() {
            system.allow_arrays();
        }
        Self::start(system, settings, q0, v0)
    }

    /// The model simulated.
    pub fn model(&self) -> &'m Model {
        self.system.model()
    }

    /// Continues `previous`, a run of another model ending where this one
    /// starts ([`crate::stops`]): its counts, and its evaluations.
    pub(crate) fn continue_from(&mut self, previous: &Simulation<'_>) {
        self.continue_counts(previous);
        self.system.add_evaluations(previous.evaluations());
    }

    /// Counts `n` evaluations made for this run by copies of it (the part
    /// steps of [`crate::stops`] to an impact).
    pub(crate) fn count_evaluations(&mut self, n: u64) {
        self.system.add_evaluations(n);
    }

    /// Writes `(q, v, e)` into the state and restarts the scheme (see [`Simulation::set_state`]).
    pub(super) fn replace_state(&mut self, q: &[f64], v: &[f64], e: f64) {
        let (t, n) = (self.t(), self.system.n());
        let x = self.x.as_mut_slice();
        x[..n].copy_from_slice(q);
        x[n..2 * n].copy_from_slice(v);
        x[2 * n] = e;
        self.integrator.restart();
        self.system.restart(self.x.as_slice(), t);
    }

    /// Changes an input by `set` between steps, keeping `Ψ` and restarting
    /// the scheme (see [`Simulation::set_input`]).
    pub(super) fn change_input(&mut self, set: impl FnOnce()) -> std::result::Result<(), Failure> {
        let (t, n) = (self.t(), self.system.n());
        let shift = self.system.change_input(self.x.as_mut_slice(), t, set)?;
        self.x.as_mut_slice()[2 * n] += shift;
        self.integrator.restart();
        self.system.restart(self.x.as_slice(), t);
        Ok(())
    }
}

/// Checks an initial state has `n` finite positions and velocities.
pub(crate) fn check_initial_state(n: usize, q0: &[f64], v0: &[f64]) -> Result<()> {
    if q0.len() != n || v0.len() != n {
        let (positions, velocities) = (q0.len(), v0.len());
        return Err(Problem::StateLength { positions, velocities, n }.at(Part::InitialState));
    }
    if let Some((i, &x)) = q0.iter().chain(v0).enumerate().find(|(_, x)| !x.is_finite()) {
        return Err(Problem::NonFiniteState { index: i, value: x }.at(Part::InitialState));
    }
    Ok(())
}
