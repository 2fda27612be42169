//! What the system does, uncontrolled: `Φ`, `Φ_q`, `γ`, the multipliers
//! `λ` and the accelerations `A` (Eqs. 4–8), at one state.

use crate::constraint::ConstraintBuffers;
use crate::energy;
use crate::linalg::Schur;
pub use crate::linalg::{Breakdown, DependentRows, LinearSolver, SPARSE_FROM};
use crate::mass::MassMatrix;
use crate::model::Model;

/// Workspace holding one evaluation of the dynamics. Allocated once per
/// model; `evaluate` never allocates. The results are read through the
/// accessors below, so only [`evaluate`](Self::evaluate) writes them.
pub struct Dynamics {
    /// Φ, Φ̇, Φ_t, γ and Φ_q of the last pass.
    constraints: ConstraintBuffers,
    force: Vec<f64>,
    grad_potential: Vec<f64>,
    potential: f64,
    force_power: f64,
    lambda: Vec<f64>,
    acc: Vec<f64>,
    schur: Schur,
}

impl Dynamics {
    /// A workspace for `model`, factoring `Φ_q M⁻¹ Φ_qᵀ` dense or sparse by its size.
    pub fn new(model: &Model) -> Self {
        Self::with_solver(model, LinearSolver::Auto)
    }

    /// With a chosen factorization of `Φ_q M⁻¹ Φ_qᵀ`.
    pub fn with_solver(model: &Model, solver: LinearSolver) -> Self {
        let (n, m) = (model.n(), model.m());
        Self {
            constraints: ConstraintBuffers::new(m, model.pattern().nnz()),
            force: vec![0.0; n],
            grad_potential: vec![0.0; n],
            potential: 0.0,
            force_power: 0.0,
            lambda: vec![0.0; m],
            acc: vec![0.0; n],
            schur: Schur::new(model.pattern(), model.mass(), solver),
        }
    }

    /// Sets what a dependent constraint row does in the next evaluations
    /// (default: [`DependentRows::Error`]).
    pub fn set_dependent_rows(&mut self, dependent: DependentRows) {
        self.schur.set_dependent_rows(dependent);
    }

    /// Constraint rows the last evaluation dropped as dependent (0 unless tolerated).
    pub fn dependent_rows(&self) -> usize {
        self.schur.dependent_rows()
    }

    /// Evaluates everything at `(q, v, t)`: constraints, forces, the
    /// factorization of `Φ_q M⁻¹ Φ_qᵀ`, `λ` and `A`.
    pub fn evaluate(&mut self, model: &Model, q: &[f64], v: &[f64], t: f64) -> Result<(), Breakdown> {
        self.grad_potential.fill(0.0);
        self.potential = model.potential(q, Some(&mut self.grad_potential));
        for (f, g) in self.force.iter_mut().zip(&self.grad_potential) {
            *f = -g;
        }
        self.force_power = model.add_forces(q, v, t, &mut self.force);
        // The unconstrained acceleration M⁻¹ G, which the constraint pass needs for `Φ_q M⁻¹ G − γ`.
        model.mass().solve(&self.force, &mut self.acc);
        // λ starts as the right-hand side of (Φ_q M⁻¹ Φ_qᵀ) λ = Φ_q M⁻¹ G − γ   (Eqs. 6–7)
        model.constraints(q, v, t, self.constraints.pass(&self.acc, &mut self.lambda));
        if model.m() == 0 {
            return Ok(());
        }
        self.schur.factor_and_solve(&self.constraints.jac, &mut self.lambda)?;
        // A = M⁻¹ (G − Φ_qᵀ λ)   (Eq. 8)
        let mut acc = std::mem::take(&mut self.acc);
        self.add_weighted_jt(model, &self.lambda, -1.0, &mut acc);
        self.acc = acc;
        Ok(())
    }

    /// For a change `b` of the constraint right-hand side (`Φ_q q̈ = γ − b`),
    /// adds the resulting change of acceleration, `−M⁻¹ Φ_qᵀ S⁻¹ b`, to
    /// `out`. `b` is overwritten with the multiplier change `S⁻¹ b`.
    /// Uses the factorization of the last [`evaluate`](Self::evaluate).
    pub fn add_constraint_response(&self, model: &Model, b: &mut [f64], out: &mut [f64]) {
        self.schur.solve(b);
        self.add_weighted_jt(model, b, -1.0, out);
    }

    /// `out += scale · M⁻¹ Φ_qᵀ y` with the Jacobian of the last
    /// [`evaluate`](Self::evaluate), without bounds checks: the control laws
    /// take up to three such products per evaluation, and the checks were
    /// half their cost on a chain of 1 000 bodies.
    pub fn add_weighted_jt(&self, model: &Model, y: &[f64], scale: f64, out: &mut [f64]) {
        let (pattern, weight, jac) = (model.pattern(), model.mass().inverse(), &self.constraints.jac);
        assert!(y.len() == model.m() && out.len() == model.n(), "vectors of the wrong length");
        assert!(jac.len() == pattern.cols.len(), "a Jacobian of another model");
        // SAFETY: a model's pattern is built by `ModelBuilder::build` from
        // checked coordinates (< n) with `start` rising from 0 to
        // `cols.len()`, and it cannot be changed afterwards; `weight` has n
        // entries, `jac` as many as `cols`, `y` and `start` m (+ 1).
        unsafe {
            for (r, &yr) in y.iter().enumerate() {
                let s = scale * yr;
                let (a, b) = (*pattern.start.get_unchecked(r) as usize, *pattern.start.get_unchecked(r + 1) as usize);
                for j in a..b {
                    let c = *pattern.cols.get_unchecked(j) as usize;
                    *out.get_unchecked_mut(c) += s * weight.get_unchecked(c) * jac.get_unchecked(j);
                }
            }
        }
    }

    /// `out[k] −= M⁻¹ Φ_qᵀ y[k]` for two pairs in one pass over the Jacobian
    /// (the coupled control terms' two products), each with the arithmetic of
    /// [`add_weighted_jt`](Self::add_weighted_jt) at scale −1.
    pub fn add_weighted_jt_pair(&self, model: &Model, [y0, y1]: [&[f64]; 2], [out0, out1]: [&mut [f64]; 2]) {
        let (pattern, weight, jac) = (model.pattern(), model.mass().inverse(), &self.constraints.jac);
        assert!(y0.len() == model.m() && y1.len() == model.m(), "vectors of the wrong length");
        assert!(out0.len() == model.n() && out1.len() == model.n(), "vectors of the wrong length");
        assert!(jac.len() == pattern.cols.len(), "a Jacobian of another model");
        // SAFETY: as in `add_weighted_jt`.
        unsafe {
            for r in 0..y0.len() {
                let (s0, s1) = (-*y0.get_unchecked(r), -*y1.get_unchecked(r));
                let (a, b) = (*pattern.start.get_unchecked(r) as usize, *pattern.start.get_unchecked(r + 1) as usize);
                for j in a..b {
                    let c = *pattern.cols.get_unchecked(j) as usize;
                    let (wc, jv) = (*weight.get_unchecked(c), *jac.get_unchecked(j));
                    *out0.get_unchecked_mut(c) += s0 * wc * jv;
                    *out1.get_unchecked_mut(c) += s1 * wc * jv;
                }
            }
        }
    }

    /// `out = Φ_q x` with the Jacobian of the last [`evaluate`](Self::evaluate),
    /// without bounds checks (see [`add_weighted_jt`](Self::add_weighted_jt)).
    pub fn jac_mul(&self, model: &Model, x: &[f64], out: &mut [f64]) {
        let (pattern, jac) = (model.pattern(), &self.constraints.jac);
        assert!(x.len() == model.n() && out.len() == model.m(), "vectors of the wrong length");
        assert!(jac.len() == pattern.cols.len(), "a Jacobian of another model");
        // SAFETY: as in `add_weighted_jt`.
        unsafe {
            for (r, o) in out.iter_mut().enumerate() {
                let (a, b) = (*pattern.start.get_unchecked(r) as usize, *pattern.start.get_unchecked(r + 1) as usize);
                *o = (a..b)
                    .map(|j| jac.get_unchecked(j) * x.get_unchecked(*pattern.cols.get_unchecked(j) as usize))
                    .sum();
            }
        }
    }

    /// Solves `(Φ_q M⁻¹ Φ_qᵀ) x = b` in place for up to four vectors at
    /// once, with the factorization of the last [`evaluate`](Self::evaluate).
    pub fn solve_many(&self, bs: &mut [&mut [f64]]) {
        self.schur.solve_many(bs);
    }

    /// The energy input `Ė = F·v + λᵀ Φ_t` of the last evaluation (see [`crate::energy`]).
    pub fn energy_input(&self) -> f64 {
        energy::power(self.force_power, &self.lambda, &self.constraints.phi_t)
    }

    /// `Φ(q, t)`
    pub fn phi(&self) -> &[f64] {
        &self.constraints.phi
    }
    /// `Φ̇ = Φ_q v + Φ_t`
    pub fn phi_dot(&self) -> &[f64] {
        &self.constraints.phi_dot
    }
    /// `Φ_t`, as `Φ̇ − Φ_q v` (zero up to round-off without drives).
    pub fn phi_t(&self) -> &[f64] {
        &self.constraints.phi_t
    }
    /// `γ` of Eq. 5
    pub fn gamma(&self) -> &[f64] {
        &self.constraints.gamma
    }
    /// Values of `Φ_q` in the model's [`Pattern`] order.
    pub fn jac(&self) -> &[f64] {
        &self.constraints.jac
    }
    /// Generalized applied force `G = −∇V + F`.
    pub fn force(&self) -> &[f64] {
        &self.force
    }
    /// `∇V`, which is also `Ψ_q`.
    pub fn grad_potential(&self) -> &[f64] {
        &self.grad_potential
    }
    /// `V(q)`
    pub fn potential(&self) -> f64 {
        self.potential
    }
    /// Power of the non-conservative forces, `F·v`.
    pub fn force_power(&self) -> f64 {
        self.force_power
    }
    /// `λ` of Eq. 7.
    pub fn lambda(&self) -> &[f64] {
        &self.lambda
    }
    /// `A = M⁻¹ (G − Φ_qᵀ λ)` of Eq. 8.
    pub fn acc(&self) -> &[f64] {
        &self.acc
    }
}
