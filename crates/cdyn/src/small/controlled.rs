//! A small system with a control law: its state in a fixed-size array,
//! the right-hand side the integrator steps, and the simulation of it.

use super::{SmallSystem, Whole};
use crate::control::Control;
use crate::control::gains::Operators;
use crate::control::projection::{Failure, Projection};
use crate::dynamics::diagnostics::Measures;
use crate::dynamics::energy;
use crate::error::{Error, Result};
use crate::integrate::{Buffer, Rhs};
use crate::linalg::mass::{DiagonalMass, MassMatrix};
use crate::model::check_rows;
use crate::model::constraint::local;
use crate::model::force::{Force, Potential};
use crate::simulate::system::{ArrayDynamics, ArrayWork, EvalError, System};
use crate::simulate::{Settings, Stepper, check_initial_state};
use num_dual::Dual64;
use std::sync::Arc;

/// A running simulation of a [`SmallSystem`].
pub type SmallSimulation<S, const N: usize, const M: usize> = Stepper<SmallControlled<S, N, M>>;

impl<S: SmallSystem<N, M>, const N: usize, const M: usize> SmallSimulation<S, N, M> {
    /// Starts at `t = 0` from `(q0, v0)`, checking the settings, the masses
    /// and, unless disabled, that the initial state satisfies the constraints.
    pub fn new(system: S, settings: Settings, q0: [f64; N], v0: [f64; N]) -> Result<Self> {
        settings.validate()?;
        if settings.control.projection.is_some() {
            return Err(Error::Unsupported(
                "the projection method runs on a general Model (small::to_model), not on a SmallSystem",
            ));
        }
        check_initial_state(N, &q0, &v0)?;
        let mass = DiagonalMass::new(system.mass())?;
        check_rows(M, N)?;
        let system = Whole(Arc::new(system));
        let e0 = mass.kinetic(&v0) + system.energy(q0);
        let controlled = SmallControlled {
            system,
            control: settings.control,
            e0,
            evaluations: 0,
            d: ArrayDynamics::new(mass, settings.dependent_rows),
            work: ArrayWork::default(),
        };
        Self::start(controlled, settings, &q0, &v0)
    }
}

/// The state `x = (q, v, e)` of a small system, in place.
#[derive(Debug, Clone, Copy)]
#[repr(C)]
pub struct SmallState<const N: usize> {
    q: [f64; N],
    v: [f64; N],
    e: f64,
}

impl<const N: usize> Buffer for SmallState<N> {
    #[inline(always)]
    fn as_slice(&self) -> &[f64] {
        // SAFETY: `repr(C)` lays out `2N + 1` consecutive `f64`s with no
        // padding (every field has the alignment and size of `f64` units),
        // and any bit pattern is a valid `f64`.
        unsafe { std::slice::from_raw_parts((self as *const Self).cast::<f64>(), 2 * N + 1) }
    }
    #[inline(always)]
    fn as_mut_slice(&mut self) -> &mut [f64] {
        // SAFETY: as in `as_slice`; the borrow of `self` is exclusive.
        unsafe { std::slice::from_raw_parts_mut((self as *mut Self).cast::<f64>(), 2 * N + 1) }
    }
}

/// `(q, v, e)` of a state of length `2N + 1`.
#[inline(always)]
fn split<const N: usize>(x: &[f64]) -> ([f64; N], [f64; N], f64) {
    (std::array::from_fn(|i| x[i]), std::array::from_fn(|i| x[N + i]), x[2 * N])
}

/// A small system with a control law: the right-hand side the integrator steps.
pub struct SmallControlled<S, const N: usize, const M: usize> {
    system: Whole<S, N, M>,
    control: Control,
    e0: f64,
    evaluations: u64,
    d: ArrayDynamics<N, M>,
    work: ArrayWork<N, M>,
}

impl<S: SmallSystem<N, M>, const N: usize, const M: usize> Rhs for SmallControlled<S, N, M> {
    type Error = EvalError;

    fn state_len(&self) -> usize {
        2 * N + 1
    }

    fn has_control(&self) -> bool {
        self.control.is_active()
    }

    #[inline(always)]
    fn eval(&mut self, x: &[f64], t: f64, f: &mut [f64], u: Option<&mut [f64]>) -> Result<(), EvalError> {
        self.evaluations += 1;
        let system = &self.system;
        self.d
            .controlled_rhs(&self.control, self.e0, &mut self.work, (x, t), f, u, |d, q, v| d.evaluate(system, q, v, t))
    }
}

impl<S: SmallSystem<N, M>, const N: usize, const M: usize> System for SmallControlled<S, N, M> {
    type State = SmallState<N>;
    fn zero_state(&self) -> SmallState<N> {
        SmallState { q: [0.0; N], v: [0.0; N], e: 0.0 }
    }
    fn n(&self) -> usize {
        N
    }
    fn e0(&self) -> f64 {
        self.e0
    }
    fn evaluations(&self) -> u64 {
        self.evaluations
    }
    fn take_dependent_rows(&mut self) -> usize {
        std::mem::take(&mut self.d.dropped)
    }
    fn last_violation(&self) -> f64 {
        self.d.max_violation()
    }
    fn measure(&mut self, x: &[f64], t: f64) -> Measures {
        let (q, v, e) = split(x);
        let l = local(&self.system, q, v, [0.0; N], t);
        let (potential, grad) = self.system.energy_and_gradient(q);
        let psi = energy::psi(&self.d.mass, &v, potential, e, self.e0);
        let columns = &ArrayDynamics::<N, M>::COLUMNS;
        Measures::of(psi, &grad, &l.phi, &l.phi_dot, |r| (l.jac[r].as_slice(), columns.as_slice()))
    }
    fn operators(&mut self, x: &[f64], t: f64) -> Result<Operators, EvalError> {
        let (q, v, _) = split(x);
        self.d.evaluate(&self.system, q, v, t).map_err(|b| EvalError::at(b, t))?;
        let rows = self.d.jac.iter().map(|row| row.iter().map(|j| j * j).sum::<f64>());
        let system = &self.system;
        // −∂Q/∂v · w, one directional dual pass.
        let damping = |w: &[f64], out: &mut [f64]| {
            let along: [Dual64; N] = std::array::from_fn(|i| Dual64::new(v[i], w[i]));
            let f = system.force(q.map(Dual64::from), along, Dual64::from(t));
            out.iter_mut().zip(f).for_each(|(o, f)| *o = -f.eps);
        };
        Ok(Operators {
            coupling: crate::control::gains::coupling(&self.d, N),
            max_row_norm2: rows.fold(0.0, f64::max),
            dissipation: crate::control::gains::dissipation_rate(&self.d, N, damping),
            // Not estimated for the small systems (no stiffness hint).
            frequency: 0.0,
            dissipating: None,
        })
    }
    fn set_control(&mut self, control: Control) {
        self.control = control;
    }
    /// Not reached: [`SmallSimulation::new`] refuses a projection.
    fn project(&mut self, _: &mut [f64], _: f64, _: f64, _: &Projection) -> Result<u32, Failure> {
        Err(Failure::Energy { residual: f64::NAN })
    }
}
