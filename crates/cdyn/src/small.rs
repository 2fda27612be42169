//! Small systems whose size is known at compile time: `N` coordinates and
//! `M` constraint rows written as one function each, simulated in
//! fixed-size arrays.
//!
//! A general [`Model`] reads its elements through dynamic dispatch and its
//! buffers through run-time lengths. That costs a few nanoseconds per call
//! — nothing for a chain of a thousand bodies, most of the step for a
//! pendulum. Here every call is resolved and every length known at compile
//! time, so a step compiles to about what one would write by hand. The
//! physics, the control laws and the integrator are the general ones; only
//! the storage differs. [`to_model`] turns the same system into a general
//! model, and the tests hold both to the same trajectories.

use crate::ad::scalar::Scalar;
use crate::control::evaluation::Evaluation;
use crate::control::gains::Operators;
use crate::control::projection::{Failure, Projection};
use crate::control::{Control, Workspace};
use crate::dynamics::diagnostics::Measures;
use crate::dynamics::energy;
use crate::error::{Error, Result};
use crate::integrate::{Buffer, Rhs};
use crate::linalg::mass::{DiagonalMass, MassMatrix};
use crate::linalg::{Breakdown, DependentRows, inverse_pivot};
use crate::model::constraint::{Constraint, local};
use crate::model::force::{Force, Potential, energy_and_gradient};
use crate::model::{Model, check_rows};
use crate::simulate::system::{EvalError, System};
use crate::simulate::{Settings, Stepper, check_initial_state};
use num_dual::Dual64;
use std::sync::Arc;

/// A whole system of `N` coordinates with a constant diagonal mass matrix
/// and `M` holonomic constraints, written once for every scalar type.
pub trait SmallSystem<const N: usize, const M: usize>: Send + Sync + 'static {
    /// The diagonal of the mass matrix.
    fn mass(&self) -> [f64; N];
    /// `Φ(q, t)`.
    fn constraints<D: Scalar>(&self, q: [D; N], t: D) -> [D; M];
    /// The potential energy `V(q)`; none unless given.
    fn potential<D: Scalar>(&self, q: [D; N]) -> D {
        let _ = q;
        D::from(0.0)
    }
    /// The non-conservative generalized force; none unless given.
    fn force<D: Scalar>(&self, q: [D; N], v: [D; N], t: D) -> [D; N] {
        let _ = (q, v, t);
        [D::from(0.0); N]
    }
}

/// A small system seen as one constraint, potential and force element.
struct Whole<S, const N: usize, const M: usize>(Arc<S>);

impl<S: SmallSystem<N, M>, const N: usize, const M: usize> Constraint<N, M> for Whole<S, N, M> {
    #[inline(always)]
    fn eval<D: Scalar>(&self, q: [D; N], t: D) -> [D; M] {
        self.0.constraints(q, t)
    }
}

impl<S: SmallSystem<N, M>, const N: usize, const M: usize> Potential<N> for Whole<S, N, M> {
    #[inline(always)]
    fn energy<D: Scalar>(&self, q: [D; N]) -> D {
        self.0.potential(q)
    }
}

impl<S: SmallSystem<N, M>, const N: usize, const M: usize> Force<N> for Whole<S, N, M> {
    #[inline(always)]
    fn force<D: Scalar>(&self, q: [D; N], v: [D; N], t: D) -> [D; N] {
        self.0.force(q, v, t)
    }
}

/// The same system as a general [`Model`], one element of each kind over all coordinates.
pub fn to_model<S: SmallSystem<N, M>, const N: usize, const M: usize>(system: S) -> Result<Model> {
    let system = Arc::new(system);
    let all: [usize; N] = std::array::from_fn(|i| i);
    let mut builder = Model::builder(system.mass().to_vec());
    if M > 0 {
        builder = builder.constrain(Whole::<S, N, M>(system.clone()), all);
    }
    builder.potential(Whole::<S, N, M>(system.clone()), all).force(Whole::<S, N, M>(system), all).build()
}

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
            d: SmallDynamics::new(mass, settings.dependent_rows),
            rows: [[0.0; M]; 5],
            w: [0.0; N],
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
    d: SmallDynamics<N, M>,
    /// Work space of the control laws, kept so no evaluation initializes it.
    rows: [[f64; M]; 5],
    w: [f64; N],
}

/// One evaluation of the dynamics of a small system (as `Dynamics`, in arrays).
struct SmallDynamics<const N: usize, const M: usize> {
    mass: DiagonalMass<[f64; N]>,
    phi: [f64; M],
    phi_dot: [f64; M],
    phi_t: [f64; M],
    jac: [[f64; N]; M],
    grad_potential: [f64; N],
    potential: f64,
    force_power: f64,
    lambda: [f64; M],
    acc: [f64; N],
    /// `S = Φ_q M⁻¹ Φ_qᵀ = L D Lᵀ`: the strictly lower part of `L`, `D` and `1/D`.
    lower: [[f64; M]; M],
    d: [f64; M],
    inv_d: [f64; M],
    /// Whether a dependent row is an error or dropped, and the most rows a
    /// factorization dropped since the last [`System::take_dependent_rows`]
    /// (kept here, and written only when a row was dropped: a step of a
    /// small system is some tens of instructions).
    dependent: DependentRows,
    dropped: usize,
    /// `dependent.tolerance()`, read once per factorization.
    tolerance: f64,
}

impl<const N: usize, const M: usize> SmallDynamics<N, M> {
    /// The coordinates of a row of `Φ_q`: all of them.
    const COLUMNS: [u32; N] = {
        let mut all = [0; N];
        let mut i = 0;
        while i < N {
            all[i] = i as u32;
            i += 1;
        }
        all
    };

    fn new(mass: DiagonalMass<[f64; N]>, dependent: DependentRows) -> Self {
        Self {
            mass,
            phi: [0.0; M],
            phi_dot: [0.0; M],
            phi_t: [0.0; M],
            jac: [[0.0; N]; M],
            grad_potential: [0.0; N],
            potential: 0.0,
            force_power: 0.0,
            lambda: [0.0; M],
            acc: [0.0; N],
            lower: [[0.0; M]; M],
            d: [0.0; M],
            inv_d: [0.0; M],
            dependent,
            dropped: 0,
            tolerance: dependent.tolerance(),
        }
    }

    /// As [`Dynamics::evaluate`](crate::dynamics::Dynamics::evaluate).
    #[inline(always)]
    fn evaluate<S: SmallSystem<N, M>>(
        &mut self,
        system: &Whole<S, N, M>,
        q: [f64; N],
        v: [f64; N],
        t: f64,
    ) -> Result<(), Breakdown> {
        let (potential, grad) = energy_and_gradient(system, q);
        let force = system.force(q, v, t);
        self.potential = potential;
        self.grad_potential = grad;
        self.force_power = (0..N).map(|i| force[i] * v[i]).sum();
        let applied: [f64; N] = std::array::from_fn(|i| force[i] - grad[i]);
        let mut acc = [0.0; N];
        self.mass.solve(&applied, &mut acc);
        let l = local(system, q, v, acc, t);
        (self.phi, self.phi_dot, self.phi_t, self.jac) = (l.phi, l.phi_dot, l.phi_t, l.jac);
        self.factor()?;
        // (Φ_q M⁻¹ Φ_qᵀ) λ = Φ_q M⁻¹ G − γ   (Eqs. 6–7)
        let mut lambda = l.rhs;
        self.solve(&mut lambda);
        // A = M⁻¹ (G − Φ_qᵀ λ)   (Eq. 8)
        self.subtract_weighted_jt(&lambda, &mut acc);
        (self.lambda, self.acc) = (lambda, acc);
        Ok(())
    }

    /// Factors `S = Φ_q M⁻¹ Φ_qᵀ` as `L D Lᵀ`, with the pivot test and the
    /// dropping of dependent rows of the general kernel.
    ///
    /// A second copy of the factorization on purpose: `linalg::Schur` reads
    /// every entry through index arrays, and stepping a small system through
    /// it was measured at 42.6 instead of 32.8 ns per step of Example 1 (best
    /// of 8 interleaved `cdyn bench` runs, 1.65× hand-written instead of
    /// 1.24×); it would also change the rounding of `d_j` for `M ≥ 2`. What
    /// both must agree on, the pivot test, is shared.
    #[inline(always)]
    fn factor(&mut self) -> Result<(), Breakdown> {
        let (dependent, tolerance) = (self.dependent, self.tolerance);
        let mut count = 0;
        for j in 0..M {
            let s_jj = self.s(j, j);
            let d = s_jj - (0..j).map(|k| self.lower[j][k] * self.lower[j][k] * self.d[k]).sum::<f64>();
            // A dropped row's 1/d is 0, so its column of L is too: no later row subtracts it.
            let inv = inverse_pivot(d, s_jj, tolerance, self.jac.as_flattened(), dependent, &mut count, || j)?;
            self.d[j] = d;
            self.inv_d[j] = inv;
            for i in j + 1..M {
                let update: f64 = (0..j).map(|k| self.lower[i][k] * self.lower[j][k] * self.d[k]).sum();
                self.lower[i][j] = (self.s(i, j) - update) * self.inv_d[j];
            }
        }
        if count > 0 {
            self.dropped = self.dropped.max(count);
        }
        Ok(())
    }

    /// An entry of `S`, weighted by the mass matrix as in the general kernel.
    #[inline(always)]
    fn s(&self, i: usize, j: usize) -> f64 {
        let weight = self.mass.inverse();
        (0..N).map(|c| self.jac[i][c] * self.jac[j][c] * weight[c]).sum()
    }

    /// Solves `S x = b` in place with the current factorization.
    #[inline(always)]
    fn solve(&self, b: &mut [f64; M]) {
        for i in 0..M {
            for k in 0..i {
                b[i] -= self.lower[i][k] * b[k];
            }
        }
        for i in 0..M {
            b[i] *= self.inv_d[i];
        }
        for i in (0..M).rev() {
            for k in i + 1..M {
                b[i] -= self.lower[k][i] * b[k];
            }
        }
    }

    /// `out −= M⁻¹ Φ_qᵀ y`
    #[inline(always)]
    fn subtract_weighted_jt(&self, y: &[f64; M], out: &mut [f64]) {
        let weight = self.mass.inverse();
        for r in 0..M {
            for c in 0..N {
                out[c] -= weight[c] * self.jac[r][c] * y[r];
            }
        }
    }
}

impl<const N: usize, const M: usize> Evaluation for SmallDynamics<N, M> {
    type Mass = DiagonalMass<[f64; N]>;
    fn mass(&self) -> &DiagonalMass<[f64; N]> {
        &self.mass
    }
    fn phi(&self) -> &[f64] {
        &self.phi
    }
    fn phi_dot(&self) -> &[f64] {
        &self.phi_dot
    }
    fn grad_potential(&self) -> &[f64] {
        &self.grad_potential
    }
    fn acc(&self) -> &[f64] {
        &self.acc
    }
    fn row(&self, r: usize) -> (&[f64], &[u32]) {
        (&self.jac[r], &Self::COLUMNS)
    }
    fn add_constraint_response(&self, b: &mut [f64], out: &mut [f64]) {
        let b: &mut [f64; M] = b.try_into().expect("one value per constraint row");
        self.solve(b);
        self.subtract_weighted_jt(b, out);
    }
    fn solve_many(&self, bs: &mut [&mut [f64]]) {
        for b in bs.iter_mut() {
            self.solve((&mut **b).try_into().expect("one value per constraint row"));
        }
    }
    fn add_weighted_jt(&self, y: &[f64], scale: f64, out: &mut [f64]) {
        let weight = self.mass.inverse();
        for r in 0..M {
            for c in 0..N {
                out[c] += scale * (weight[c] * self.jac[r][c] * y[r]);
            }
        }
    }
    fn phi_t(&self) -> &[f64] {
        &self.phi_t
    }
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
        let (q, v, e) = split(x);
        self.evaluations += 1;
        let d = &mut self.d;
        d.evaluate(&self.system, q, v, t).map_err(|b| EvalError::at(b, t))?;
        let e_dot = energy::power(d.force_power, &d.lambda, &d.phi_t);
        f[..N].copy_from_slice(&v);
        f[N..2 * N].copy_from_slice(&d.acc);
        f[2 * N] = e_dot;
        if let Some(u) = u {
            let psi = energy::psi(&d.mass, &v, d.potential, e, self.e0);
            let (u_q, rest) = u.split_at_mut(N);
            let (u_v, u_e) = rest.split_at_mut(N);
            u_e[0] = 0.0;
            let [r0, r1, r2, r3, r4] = &mut self.rows;
            let work = Workspace { rows: [r0, r1, r2, r3, r4], w: &mut self.w, held: None };
            self.control.terms(&*d, &v, psi, e_dot, u_q, u_v, work);
        }
        Ok(())
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
        self.d.phi.iter().fold(0.0_f64, |a, p| a.max(p.abs()))
    }
    fn measure(&mut self, x: &[f64], t: f64) -> Measures {
        let (q, v, e) = split(x);
        let l = local(&self.system, q, v, [0.0; N], t);
        let (potential, grad) = energy_and_gradient(&self.system, q);
        let psi = energy::psi(&self.d.mass, &v, potential, e, self.e0);
        let columns = &SmallDynamics::<N, M>::COLUMNS;
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
