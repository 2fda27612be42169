//! A general model with a control law: the right-hand side an integrator
//! steps, and the steps of RATTLE and generalized-α on its model.

use super::evaluated::Evaluated;
use super::in_arrays::{InArrays, in_arrays};
use super::{AlphaFailure, EvalError, RattleFailure, System, split_state, split_state_mut};
use crate::control::evaluation::Evaluation;
use crate::control::gains::Operators;
use crate::control::held::Held;
use crate::control::projection::{self, Failure, Projection};
use crate::control::{Control, Energy, Workspace};
use crate::dynamics::diagnostics::{Measures, Probe};
use crate::dynamics::energy;
use crate::dynamics::momentum::{self, Kind, Momenta, Symmetries};
use crate::dynamics::{DependentRows, Dynamics, LinearSolver};
use crate::integrate::Rhs;
use crate::linalg::mass::MassAt;
use crate::model::Model;
use crate::simulate::generalized_alpha::{self, GeneralizedAlpha, StepReport};
use crate::simulate::rattle;
use std::cell::Cell;

mod between;

/// A model with a control law: the right-hand side an [`Integrator`](crate::integrate::Integrator) steps.
#[derive(Clone)]
pub struct ControlledSystem<'m> {
    model: &'m Model,
    control: Control,
    /// The dynamics of the latest evaluation.
    dynamics: Dynamics,
    /// `E₀ = T₀ + V₀`
    e0: f64,
    /// Work space of the control laws: five vectors of `m` values, one of `n`.
    rows: [Vec<f64>; 5],
    work: Vec<f64>,
    probe: Probe,
    projection: crate::dynamics::manifold::Work,
    /// Right-hand-side evaluations so far.
    evaluations: u64,
    /// Most rows an evaluation dropped as dependent since the last [`System::take_dependent_rows`].
    dependent: usize,
    /// What a dependent row does (as the dynamics are set to).
    dependent_rows: DependentRows,
    /// The momenta the model keeps ([`crate::dynamics::momentum::detect`]).
    symmetries: Symmetries,
    /// Those the corrections keep (none with [`Invariants::Free`](crate::control::Invariants::Free)).
    momenta: Momenta,
    /// The angular momenta and declared invariants `robust` and `projection` hold beside the energy (none with `Free`).
    held: Held,
    /// A rotation's field `ξ(q)`, for [`System::momentum`].
    turned: Vec<f64>,
    /// RATTLE's buffers (allocated here, so that no step allocates).
    rattle: rattle::Work,
    /// Generalized-α's state and buffers, made before its first step.
    alpha: Option<generalized_alpha::Work>,
    /// Whether it may be evaluated in arrays ([`Self::allow_arrays`]), and that evaluation.
    arrays_allowed: bool,
    arrays: Option<Box<dyn InArrays>>,
}

impl<'m> ControlledSystem<'m> {
    /// A controlled `model` with initial energy `e0`, factoring `Φ_q M⁻¹ Φ_qᵀ` dense or sparse by its size.
    pub fn new(model: &'m Model, control: Control, e0: f64) -> Self {
        Self::with_solver(model, control, e0, LinearSolver::Auto)
    }

    /// With a chosen factorization of `Φ_q M⁻¹ Φ_qᵀ`.
    pub fn with_solver(model: &'m Model, control: Control, e0: f64, solver: LinearSolver) -> Self {
        let mut dynamics = Dynamics::with_solver(model, solver);
        dynamics.reuse_factorization(control.projection.is_some());
        dynamics.keep_potential_rate(model, control.reads_potential_rate());
        Self {
            model,
            control,
            dynamics,
            e0,
            rows: std::array::from_fn(|_| vec![0.0; model.m()]),
            work: vec![0.0; model.n()],
            probe: Probe::new(model),
            projection: crate::dynamics::manifold::Work::new(model),
            evaluations: 0,
            dependent: 0,
            dependent_rows: DependentRows::Error,
            symmetries: Symmetries::default(),
            momenta: Momenta::NONE,
            held: Held::default(),
            turned: vec![0.0; model.n()],
            rattle: rattle::Work::new(model),
            alpha: None,
            arrays_allowed: false,
            arrays: None,
        }
    }

    /// Lets a small model run in arrays ([`in_arrays`]); [`Self::dynamics`] then hold its last general evaluation.
    pub(crate) fn allow_arrays(&mut self) {
        self.arrays_allowed = true;
        self.choose_arrays();
    }

    fn choose_arrays(&mut self) {
        let (model, control, symmetries, rows) = (self.model, &self.control, &self.symmetries, self.dependent_rows);
        self.arrays = self.arrays_allowed.then(|| in_arrays(model, control, symmetries, rows)).flatten();
    }

    /// The momenta the model keeps; corrections are M-orthogonal to them (unless `Invariants::Free`).
    pub fn set_symmetries(&mut self, symmetries: Symmetries) {
        self.momenta = match self.control.invariants {
            crate::control::Invariants::Keep => {
                let constant = self.model.mass().is_some()
                    || symmetries.kept.iter().filter(|m| m.kind == Kind::Constant).all(|m| m.linear);
                Momenta::new(&symmetries.kept, self.model.n(), constant)
            }
            crate::control::Invariants::Free => Momenta::NONE,
        };
        let held = symmetries.kept.iter().filter(|m| m.kind != Kind::Constant).map(|m| (m.kind.clone(), m.initial));
        let (kinds, targets) = held.filter(|_| self.control.invariants == crate::control::Invariants::Keep).unzip();
        self.held = Held::new(kinds, targets, self.model.n(), self.model.m());
        self.symmetries = symmetries;
        self.choose_arrays();
    }

    /// Sets what a dependent constraint row does (default: an error).
    pub fn set_dependent_rows(&mut self, dependent: DependentRows) {
        self.dynamics.set_dependent_rows(dependent);
        self.dependent_rows = dependent;
        self.choose_arrays();
    }

    /// Counts `n` evaluations made before it (by the run it continues).
    pub(crate) fn add_evaluations(&mut self, n: u64) {
        self.evaluations += n;
    }

    /// The model it evaluates.
    pub fn model(&self) -> &'m Model {
        self.model
    }

    /// The control law it adds.
    pub fn control(&self) -> &Control {
        &self.control
    }

    /// The dynamics of the latest general evaluation (of every evaluation, unless a small model runs in arrays).
    pub fn dynamics(&self) -> &Dynamics {
        &self.dynamics
    }

    /// [`Rhs::eval`] by the general kernels (apart: a small model's call into its arrays skips its set-up).
    #[inline(never)]
    fn eval_general(&mut self, x: &[f64], t: f64, f: &mut [f64], u: Option<&mut [f64]>) -> Result<(), EvalError> {
        let n = self.model.n();
        let (q, v, e) = split_state(x, n);
        // The projected energy law (robust's) takes its products with
        // M⁻¹Φ_qᵀ in a pass over the Jacobian, which also subtracts A's
        // constraint forces (one pass fewer); no law of that kind reads A.
        let fused = u.is_some() && matches!(self.control.energy, Energy::Projected { .. });
        let evaluated = if fused {
            self.dynamics.evaluate_but_reaction(self.model, q, v, t)
        } else {
            self.dynamics.evaluate(self.model, q, v, t)
        };
        evaluated.map_err(|b| EvalError::at(b, t))?;
        self.dependent = self.dependent.max(self.dynamics.dependent_rows());
        let e_dot = self.dynamics.energy_input();
        f[..n].copy_from_slice(v);
        f[2 * n] = e_dot;
        if let Some(u) = u {
            let kinetic = self.dynamics.kinetic(self.model, v);
            let psi = energy::psi_from(kinetic, self.dynamics.potential(), e, self.e0);
            let (u_q, u_v, u_e) = split_state_mut(u, n);
            *u_e = 0.0;
            let [r0, r1, r2, r3, r4] = &mut self.rows;
            if self.momenta.stale() {
                self.momenta.update(&self.dynamics.mass(self.model));
            }
            let holds = self.control.holds_invariants();
            let held = if holds && !self.held.is_empty() {
                self.held.update(self.model, &self.dynamics, &self.momenta, q, v, true);
                Some(&mut self.held)
            } else {
                None
            };
            let work = Workspace { rows: [r0, r1, r2, r3, r4], w: &mut self.work, held };
            let (model, control, momenta) = (self.model, &self.control, &self.momenta);
            let run = |dynamics: &Dynamics, reaction: Option<&mut [f64]>| {
                let reaction = Cell::new(reaction);
                // The laws are compiled once per kind of mass, so that a constant
                // diagonal `M` runs its loops without a match per product
                // (Example 1 took 6.6 % more instructions per step with one).
                macro_rules! terms {
                    ($mass:expr) => {{
                        let e = Evaluated { model, dynamics, mass: $mass, momenta, reaction };
                        control.terms(&e, v, [psi, kinetic, e_dot], u_q, u_v, work);
                        e.reaction.into_inner()
                    }};
                }
                let left = match dynamics.mass(model) {
                    MassAt::Diagonal(mass) => terms!(mass),
                    MassAt::Dense(mass) => terms!(mass),
                    MassAt::Blocks(mass) => terms!(mass),
                };
                // No pair of products took them (no law called for one).
                if let Some(acc) = left {
                    dynamics.subtract_reaction(model, acc);
                }
            };
            if fused {
                self.dynamics.take_acc(|dynamics, acc| run(dynamics, Some(acc)));
            } else {
                run(&self.dynamics, None);
            }
        }
        f[n..2 * n].copy_from_slice(self.dynamics.acc());
        Ok(())
    }
}

impl Rhs for ControlledSystem<'_> {
    type Error = EvalError;

    fn state_len(&self) -> usize {
        2 * self.model.n() + 1
    }

    fn has_control(&self) -> bool {
        self.control.is_active()
    }

    #[inline]
    fn eval(&mut self, x: &[f64], t: f64, f: &mut [f64], u: Option<&mut [f64]>) -> Result<(), EvalError> {
        self.evaluations += 1;
        match &mut self.arrays {
            Some(arrays) => arrays.eval(self.model, &self.control, self.e0, x, t, f, u),
            None => self.eval_general(x, t, f, u),
        }
    }
}

impl System for ControlledSystem<'_> {
    type State = Vec<f64>;
    fn zero_state(&self) -> Vec<f64> {
        vec![0.0; self.state_len()]
    }
    fn n(&self) -> usize {
        self.model.n()
    }
    fn e0(&self) -> f64 {
        self.e0
    }
    fn evaluations(&self) -> u64 {
        self.evaluations
    }
    fn take_dependent_rows(&mut self) -> usize {
        std::mem::take(&mut self.dependent).max(self.arrays.as_mut().map_or(0, |a| a.take_dropped()))
    }
    fn last_violation(&self) -> f64 {
        let general = || self.dynamics.phi().iter().fold(0.0_f64, |a, p| a.max(p.abs()));
        self.arrays.as_ref().map_or_else(general, |a| a.last_violation())
    }
    fn measure(&mut self, x: &[f64], t: f64) -> Measures {
        let (q, v, e) = split_state(x, self.model.n());
        self.probe.measure(self.model, q, v, e, t, self.e0)
    }
    fn operators(&mut self, x: &[f64], t: f64) -> Result<Operators, EvalError> {
        let (q, v, _) = split_state(x, self.model.n());
        let (model, n) = (self.model, self.model.n());
        self.dynamics.evaluate(model, q, v, t).map_err(|b| EvalError::at(b, t))?;
        let mass = self.dynamics.mass(model);
        let d = Evaluated::new(model, &self.dynamics, &mass, &self.momenta);
        let rows = (0..model.m()).map(|r| d.row(r).0.iter().map(|j| j * j).sum::<f64>());
        let damping = |w: &[f64], out: &mut [f64]| {
            out.fill(0.0);
            model.add_damping(q, v, w, t, out);
        };
        // K of generalized-α's Newton matrix: the potentials' and forces'
        // stiffness, and the constraints' curvatures weighted by λ.
        let mut entries = Vec::new();
        model.iteration_entries(&mut entries);
        let forces = entries.len();
        model.curvature_entries(&mut entries);
        let mut values = vec![0.0; entries.len()];
        model.iteration_values(q, v, t, 1.0, 0.0, &mut values[..forces]);
        model.curvature_values(q, t, self.dynamics.lambda(), 1.0, &mut values[forces..]);
        let stiffness = |w: &[f64], out: &mut [f64]| {
            out.fill(0.0);
            for (&(r, c), k) in entries.iter().zip(&values) {
                out[r as usize] += k * w[c as usize];
            }
        };
        let (dissipation, mode) = crate::control::gains::dissipation_mode(&d, n, damping);
        Ok(Operators {
            coupling: crate::control::gains::coupling(&d, n),
            max_row_norm2: rows.fold(0.0, f64::max),
            dissipation,
            frequency: crate::control::gains::oscillation_frequency(&d, n, stiffness),
            dissipating: (dissipation > 0.0).then(|| model.most_dissipating(q, v, &mode, t)).flatten(),
        })
    }
    fn set_control(&mut self, control: Control) {
        self.dynamics.reuse_factorization(control.projection.is_some());
        self.dynamics.keep_potential_rate(self.model, control.reads_potential_rate());
        self.control = control;
        self.choose_arrays();
    }
    fn symmetries(&self) -> &Symmetries {
        &self.symmetries
    }
    fn hold_from(&mut self, x: &mut [f64]) {
        self.hold_at(x);
    }
    fn momentum(&mut self, j: usize, x: &[f64]) -> f64 {
        let (q, v, _) = split_state(x, self.model.n());
        let direction = match self.symmetries.direction(j) {
            (_, Kind::Declared(i)) => return self.model.declared_invariants()[*i].value(q, v),
            (_, Kind::Rotation(g)) => {
                g.at(q, &mut self.turned);
                &self.turned
            }
            (e, Kind::Constant) => e,
        };
        momentum::value(self.model, q, v, direction, &mut self.work)
    }
    fn offers_model_schemes(&self) -> bool {
        true
    }
    fn prepare_generalized_alpha(&mut self, settings: GeneralizedAlpha, q0: &[f64], v0: &[f64], h: f64) {
        let mut work = generalized_alpha::Work::new(
            self.model,
            &self.dynamics,
            settings,
            self.dependent_rows,
            self.control.projection.is_some(),
        );
        // A state the dynamics cannot evaluate leaves it unstarted: the first step says why.
        let _ = work.start(self.model, &mut self.dynamics, q0, v0, 0.0, h, &mut self.evaluations);
        self.alpha = Some(work);
    }
    fn generalized_alpha(&mut self, x: &mut [f64], t: f64, h: f64) -> Result<StepReport, AlphaFailure> {
        let (q, v, e) = split_state_mut(x, self.model.n());
        let work = self.alpha.as_mut().expect("prepare_generalized_alpha before the first step");
        let d = &mut self.dynamics;
        let taken = generalized_alpha::step(self.model, d, q, v, e, t, h, work, &mut self.evaluations);
        self.dependent = self.dependent.max(self.dynamics.dependent_rows());
        taken.map_err(|f| match f {
            generalized_alpha::Failure::Breakdown(b, t) => AlphaFailure::Eval(EvalError::at(b, t)),
            generalized_alpha::Failure::Singular { iterations } => AlphaFailure::Singular { iterations },
            generalized_alpha::Failure::NotConverged { correction, iterations } => {
                AlphaFailure::NotConverged { correction, iterations }
            }
        })
    }
    fn rattle(&mut self, x: &mut [f64], t: f64, h: f64) -> Result<u32, RattleFailure> {
        let (q, v, e) = split_state_mut(x, self.model.n());
        let work = &mut self.rattle;
        let taken = rattle::step(self.model, &mut self.dynamics, q, v, e, t, h, work, &mut self.evaluations);
        self.dependent = self.dependent.max(self.dynamics.dependent_rows());
        taken.map_err(|f| match f {
            rattle::Failure::Breakdown(b, t) => RattleFailure::Eval(EvalError::at(b, t)),
            rattle::Failure::Positions { row, residual, iterations } => {
                RattleFailure::Positions { row, residual, iterations }
            }
        })
    }
    fn restart(&mut self, x: &[f64], t: f64) {
        self.rattle.forget();
        if let Some(work) = &mut self.alpha {
            let (q, v, _) = split_state(x, self.model.n());
            // A state the dynamics cannot evaluate fails the next step, which says why.
            let _ = work.restart(self.model, &mut self.dynamics, q, v, t, &mut self.evaluations);
        }
    }
    fn project(&mut self, x: &mut [f64], t: f64, h: f64, settings: &Projection) -> Result<u32, Failure> {
        self.rattle.forget();
        let (q, v, e) = split_state_mut(x, self.model.n());
        let target = self.e0 + *e;
        let (model, d) = (self.model, &mut self.dynamics);
        let (momenta, held) = (&mut self.momenta, &mut self.held);
        projection::invariants(model, d, momenta, held, q, v, t, target, h, settings, &mut self.projection)
    }
}
