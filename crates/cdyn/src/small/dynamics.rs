//! One evaluation of the dynamics of a small system in arrays — `Φ`, `Φ_q`,
//! `λ`, the accelerations and the energy's gradients — as the control laws
//! read it.

use super::{SmallSystem, Whole};
use crate::control::evaluation::Evaluation;
use crate::error::Result;
use crate::linalg::mass::{DiagonalMass, MassMatrix};
use crate::linalg::{Breakdown, DependentRows, inverse_pivot};
use crate::model::constraint::local;
use crate::model::force::{Force, energy_and_gradient};

/// One evaluation of the dynamics of a small system (as `Dynamics`, in arrays).
pub(super) struct SmallDynamics<const N: usize, const M: usize> {
    pub(super) mass: DiagonalMass<[f64; N]>,
    pub(super) phi: [f64; M],
    pub(super) phi_dot: [f64; M],
    pub(super) phi_t: [f64; M],
    pub(super) jac: [[f64; N]; M],
    pub(super) grad_potential: [f64; N],
    pub(super) potential: f64,
    pub(super) force_power: f64,
    pub(super) lambda: [f64; M],
    pub(super) acc: [f64; N],
    /// `S = Φ_q M⁻¹ Φ_qᵀ = L D Lᵀ`: the strictly lower part of `L`, `D` and `1/D`.
    pub(super) lower: [[f64; M]; M],
    pub(super) d: [f64; M],
    pub(super) inv_d: [f64; M],
    /// Whether a dependent row is an error or dropped, and the most rows a
    /// factorization dropped since the last [`System::take_dependent_rows`]
    /// (kept here, and written only when a row was dropped: a step of a
    /// small system is some tens of instructions).
    pub(super) dependent: DependentRows,
    pub(super) dropped: usize,
    /// `dependent.tolerance()`, read once per factorization.
    pub(super) tolerance: f64,
}

impl<const N: usize, const M: usize> SmallDynamics<N, M> {
    /// The coordinates of a row of `Φ_q`: all of them.
    pub(super) const COLUMNS: [u32; N] = {
        let mut all = [0; N];
        let mut i = 0;
        while i < N {
            all[i] = i as u32;
            i += 1;
        }
        all
    };

    pub(super) fn new(mass: DiagonalMass<[f64; N]>, dependent: DependentRows) -> Self {
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
    pub(super) fn evaluate<S: SmallSystem<N, M>>(
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
    pub(super) fn factor(&mut self) -> Result<(), Breakdown> {
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
    pub(super) fn s(&self, i: usize, j: usize) -> f64 {
        let weight = self.mass.inverse();
        (0..N).map(|c| self.jac[i][c] * self.jac[j][c] * weight[c]).sum()
    }

    /// Solves `S x = b` in place with the current factorization.
    #[inline(always)]
    pub(super) fn solve(&self, b: &mut [f64; M]) {
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
    pub(super) fn subtract_weighted_jt(&self, y: &[f64; M], out: &mut [f64]) {
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
