//! One evaluation of the dynamics of a system of `N` coordinates with a
//! constant diagonal mass and `M` constraint rows, in fixed-size arrays —
//! `Φ`, `Φ_q`, `λ`, the accelerations and the energy's gradients — as the
//! control laws read it, and the controlled right-hand side formed from it.
//! A [`SmallSystem`](crate::small::SmallSystem) fills it by its own dual
//! passes (`small`), a general model of that size by its elements'
//! ([`evaluate_model`](ArrayDynamics::evaluate_model)).

use super::EvalError;
use crate::control::evaluation::Evaluation;
use crate::control::{Control, Workspace};
use crate::dynamics::energy;
use crate::linalg::mass::{DiagonalMass, MassMatrix};
use crate::linalg::{Breakdown, DependentRows, inverse_pivot};
use crate::model::Model;
use crate::model::constraint::ConstraintValues;

/// One evaluation of the dynamics of a small system (as `Dynamics`, in arrays).
#[derive(Clone)]
pub(crate) struct ArrayDynamics<const N: usize, const M: usize> {
    pub(crate) mass: DiagonalMass<[f64; N]>,
    pub(crate) phi: [f64; M],
    pub(crate) phi_dot: [f64; M],
    pub(crate) phi_t: [f64; M],
    pub(crate) jac: [[f64; N]; M],
    pub(crate) grad_potential: [f64; N],
    pub(crate) potential: f64,
    pub(crate) force_power: f64,
    pub(crate) lambda: [f64; M],
    pub(crate) acc: [f64; N],
    /// `S = Φ_q M⁻¹ Φ_qᵀ = L D Lᵀ`: the strictly lower part of `L`, `D` and `1/D`.
    pub(crate) lower: [[f64; M]; M],
    pub(crate) d: [f64; M],
    pub(crate) inv_d: [f64; M],
    /// Whether a dependent row is an error or dropped, and the most rows a
    /// factorization dropped since the last [`System::take_dependent_rows`]
    /// (kept here, and written only when a row was dropped: a step of a
    /// small system is some tens of instructions).
    pub(crate) dependent: DependentRows,
    pub(crate) dropped: usize,
    /// `dependent.tolerance()`, read once per factorization.
    pub(crate) tolerance: f64,
}

impl<const N: usize, const M: usize> ArrayDynamics<N, M> {
    /// The coordinates of a row of `Φ_q`: all of them.
    pub(crate) const COLUMNS: [u32; N] = {
        let mut all = [0; N];
        let mut i = 0;
        while i < N {
            all[i] = i as u32;
            i += 1;
        }
        all
    };

    pub(crate) fn new(mass: DiagonalMass<[f64; N]>, dependent: DependentRows) -> Self {
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

    /// As [`Dynamics::evaluate`](crate::dynamics::Dynamics::evaluate), for
    /// a `model` of this size with a constant diagonal mass: its elements
    /// write `Φ_q` in the order of its pattern, which `places` puts in rows
    /// and columns (`None`: already row by row over every coordinate).
    #[inline(always)]
    pub(crate) fn evaluate_model(
        &mut self,
        model: &Model,
        places: Option<&[(u32, u32)]>,
        q: [f64; N],
        v: [f64; N],
        t: f64,
    ) -> Result<(), Breakdown> {
        // Every output an element writes is read back value by value (`read_each`).
        let mut grad = [0.0; N];
        self.potential = model.potential(&q, Some(&mut grad));
        let grad = read_each(&grad);
        let mut force = grad.map(|g| -g);
        self.force_power = model.add_forces(&q, &v, t, &mut force);
        let force = read_each(&force);
        self.grad_potential = grad;
        let mut acc = [0.0; N];
        self.mass.solve(&force, &mut acc);
        let (mut rhs, mut gamma, mut values) = ([0.0; M], [0.0; M], [[0.0; N]; M]);
        let (mut phi, mut phi_dot, mut phi_t) = ([0.0; M], [0.0; M], [0.0; M]);
        let jac = values.as_flattened_mut();
        let out = ConstraintValues {
            free_acc: &acc,
            rhs: &mut rhs,
            phi: &mut phi,
            phi_dot: &mut phi_dot,
            phi_t: &mut phi_t,
            gamma: &mut gamma,
            jac: match places {
                Some(places) => &mut jac[..places.len()],
                None => jac,
            },
        };
        model.constraints(&q, &v, t, out);
        (self.phi, self.phi_dot, self.phi_t) = (read_each(&phi), read_each(&phi_dot), read_each(&phi_t));
        let rhs = read_each(&rhs);
        self.jac = match places {
            None => values.map(|row| read_each(&row)),
            Some(places) => {
                let mut rows = [[0.0; N]; M];
                for (&(r, c), x) in places.iter().zip(values.as_flattened()) {
                    rows[r as usize][c as usize] += x;
                }
                rows.map(|row| read_each(&row))
            }
        };
        self.finish(rhs, acc)
    }

    /// With `Φ`, `Φ_q`, the forces and `M⁻¹G` (`acc`) in place: `S`
    /// factored, `λ` from `rhs = Φ_q M⁻¹ G − γ` and `A`.
    #[inline(always)]
    pub(crate) fn finish(&mut self, rhs: [f64; M], mut acc: [f64; N]) -> Result<(), Breakdown> {
        self.factor()?;
        // (Φ_q M⁻¹ Φ_qᵀ) λ = Φ_q M⁻¹ G − γ   (Eqs. 6–7)
        let mut lambda = rhs;
        self.solve(&mut lambda);
        // A = M⁻¹ (G − Φ_qᵀ λ)   (Eq. 8)
        self.add_weighted_jt(&lambda, -1.0, &mut acc);
        (self.lambda, self.acc) = (lambda, acc);
        Ok(())
    }

    /// The right-hand side `f` at `x = (q, v, e)` and, when asked, the
    /// control term `U` of `control`, with `evaluate` evaluating the
    /// dynamics at `(q, v, t)`.
    #[inline(always)]
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn controlled_rhs(
        &mut self,
        control: &Control,
        e0: f64,
        work: &mut ArrayWork<N, M>,
        (x, t): (&[f64], f64),
        f: &mut [f64],
        u: Option<&mut [f64]>,
        evaluate: impl FnOnce(&mut Self, [f64; N], [f64; N]) -> Result<(), Breakdown>,
    ) -> Result<(), EvalError> {
        let q: [f64; N] = x[..N].try_into().expect("a state of 2N + 1 values");
        let v: [f64; N] = x[N..2 * N].try_into().expect("a state of 2N + 1 values");
        let e = x[2 * N];
        evaluate(self, q, v).map_err(|b| EvalError::at(b, t))?;
        let e_dot = energy::power(self.force_power, &self.lambda, &self.phi_t);
        f[..N].copy_from_slice(&v);
        f[N..2 * N].copy_from_slice(&self.acc);
        f[2 * N] = e_dot;
        if let Some(u) = u {
            let kinetic = self.mass.kinetic(&v);
            let psi = energy::psi_from(kinetic, self.potential, e, e0);
            let (u_q, rest) = u.split_at_mut(N);
            let (u_v, u_e) = rest.split_at_mut(N);
            u_e[0] = 0.0;
            let [r0, r1, r2, r3, r4] = &mut work.rows;
            let work = Workspace { rows: [r0, r1, r2, r3, r4], w: &mut work.w, held: None };
            control.terms(&*self, &v, [psi, kinetic, e_dot], u_q, u_v, work);
        }
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
    pub(crate) fn factor(&mut self) -> Result<(), Breakdown> {
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
    pub(crate) fn s(&self, i: usize, j: usize) -> f64 {
        let weight = self.mass.inverse();
        (0..N).map(|c| self.jac[i][c] * self.jac[j][c] * weight[c]).sum()
    }

    /// Solves `S x = b` in place with the current factorization.
    #[inline(always)]
    pub(crate) fn solve(&self, b: &mut [f64; M]) {
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

    /// The largest `|Φ|` of the last evaluation.
    pub(crate) fn max_violation(&self) -> f64 {
        self.phi.iter().fold(0.0_f64, |a, p| a.max(p.abs()))
    }
}

impl<const N: usize, const M: usize> Evaluation for ArrayDynamics<N, M> {
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
        self.add_weighted_jt(b, -1.0, out);
    }
    fn solve_many(&self, bs: &mut [&mut [f64]]) {
        for b in bs.iter_mut() {
            self.solve((&mut **b).try_into().expect("one value per constraint row"));
        }
    }
    #[inline(always)]
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

/// `a`, read value by value. A model's element writes its outputs a value
/// at a time, through a call the compiler cannot see into; read as vectors
/// right after, two such writes still on their way to the cache cannot be
/// forwarded to one load, which then waits for both to reach the cache
/// (the general step of Example 1 took 71 ns instead of 56, the double
/// pendulum's 170 ns instead of 117).
#[inline(always)]
fn read_each<const K: usize>(a: &[f64; K]) -> [f64; K] {
    // SAFETY: each pointer is to an initialized `f64` of the borrowed array.
    std::array::from_fn(|i| unsafe { std::ptr::read_volatile(&a[i]) })
}

/// The work space of the control laws on arrays, kept so that no
/// evaluation initializes it.
#[derive(Clone, Copy)]
pub(crate) struct ArrayWork<const N: usize, const M: usize> {
    rows: [[f64; M]; 5],
    w: [f64; N],
}

impl<const N: usize, const M: usize> Default for ArrayWork<N, M> {
    fn default() -> Self {
        Self { rows: [[0.0; M]; 5], w: [0.0; N] }
    }
}
