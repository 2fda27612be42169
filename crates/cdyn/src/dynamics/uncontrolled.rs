//! What the system does, uncontrolled: `Φ`, `Φ_q`, `γ`, the multipliers
//! `λ` and the accelerations `A` (Eqs. 4–8), at one state.

use crate::dynamics::energy;
use crate::dynamics::solver::{BLOCKS_FROM, Blocks, General, Solver};
use crate::linalg::mass::{DenseMass, MassAt, MassMatrix};
pub use crate::linalg::{Breakdown, DependentRows, LinearSolver, SPARSE_FROM};
use crate::linalg::{DenseLdl, Schur};
use crate::model::Model;
use crate::model::constraint::ConstraintBuffers;

/// Workspace holding one evaluation of the dynamics. Allocated once per
/// model; `evaluate` never allocates. The results are read through the
/// accessors below, so only [`evaluate`](Self::evaluate) writes them.
#[derive(Clone)]
pub struct Dynamics {
    /// Φ, Φ̇, Φ_t, γ and Φ_q of the last pass.
    pub(super) constraints: ConstraintBuffers,
    force: Vec<f64>,
    grad_potential: Vec<f64>,
    potential: f64,
    /// `T` of the last evaluation where `M` depends on `q` (its pass sums
    /// it with `M`); unused with a constant `M`.
    kinetic: f64,
    force_power: f64,
    lambda: Vec<f64>,
    acc: Vec<f64>,
    pub(super) solver: Solver,
    /// With a constant `M`, `S` depends on `(q, t)` alone: the positions and
    /// time of its latest factorization, so that an evaluation at the same
    /// ones (the next step's first, at the state the projection left)
    /// solves with it instead of factoring again; the results are the same
    /// to the bit. Kept only when asked ([`Dynamics::reuse_factorization`]):
    /// copying `q` costs 2–3 % of a chain's step where nothing repeats.
    reuse: bool,
    factored_at: Option<f64>,
    /// The positions of that factorization (allocated once).
    factored_q: Vec<f64>,
    /// `Φ_q M⁻¹∇V` of the last evaluation, read off its right-hand side
    /// `Φ_q M⁻¹G − γ` where `G = −∇V` (constant `M`, no non-conservative
    /// force): the projected energy law needs it, and forming it again
    /// cost a pass over `Φ_q` (1.7 µs of a 1 000-body chain's 45 µs step).
    /// Empty unless asked for ([`Dynamics::keep_potential_rate`]).
    potential_rate: Vec<f64>,
    potential_rate_valid: bool,
}

/// Lagrange's velocity terms join `G`: `M q̈ = G + ∂T/∂q − Ṁ q̇` (see
/// `kinetic.rs`); `∂T/∂q` becomes `Ψ_q = ∇V + ∂T/∂q`.
fn lagrange_terms(force: &mut [f64], psi_q: &mut [f64], mdot_v: &[f64], grad_potential: &[f64]) {
    for (((f, dt), mv), gv) in force.iter_mut().zip(psi_q).zip(mdot_v).zip(grad_potential) {
        *f += *dt - mv;
        *dt += gv;
    }
}

impl Dynamics {
    /// A workspace for `model`, factoring `Φ_q M⁻¹ Φ_qᵀ` dense or sparse by its size.
    pub fn new(model: &Model) -> Self {
        Self::with_solver(model, LinearSolver::Auto)
    }

    /// With a chosen factorization of `Φ_q M⁻¹ Φ_qᵀ`. A block-diagonal
    /// `M(q)` (see [`Model::mass_blocks`]) is factored by blocks with
    /// [`LinearSolver::Sparse`], and with [`LinearSolver::Auto`] from
    /// [`BLOCKS_FROM`] coordinates; any other `M(q)` is dense.
    pub fn with_solver(model: &Model, solver: LinearSolver) -> Self {
        let (n, m) = (model.n(), model.m());
        let solver = match (model.mass(), model.mass_blocks()) {
            (Some(mass), _) => Solver::Constant(Schur::new(model.pattern(), mass, solver)),
            (None, Some(blocks))
                if solver == LinearSolver::Sparse || solver == LinearSolver::Auto && n >= BLOCKS_FROM =>
            {
                Solver::Blocks(Box::new(Blocks::new(model, blocks, solver)))
            }
            (None, _) => Solver::General(Box::new(General {
                mass: DenseMass::new(n),
                psi_q: vec![0.0; n],
                mdot_v: vec![0.0; n],
                jac: vec![0.0; m * n],
                weighted: vec![0.0; m * n],
                schur: DenseLdl::new(m),
            })),
        };
        Self {
            constraints: ConstraintBuffers::new(m, model.pattern().nnz()),
            force: vec![0.0; n],
            grad_potential: vec![0.0; n],
            potential: 0.0,
            kinetic: 0.0,
            force_power: 0.0,
            lambda: vec![0.0; m],
            acc: vec![0.0; n],
            solver,
            reuse: false,
            factored_at: None,
            factored_q: vec![0.0; n],
            potential_rate: Vec::new(),
            potential_rate_valid: false,
        }
    }

    /// Whether the evaluations keep `Φ_q M⁻¹∇V` where the right-hand side
    /// gives it for free (see [`potential_rate`](Self::potential_rate)).
    pub fn keep_potential_rate(&mut self, model: &Model, on: bool) {
        self.potential_rate = if on { vec![0.0; model.m()] } else { Vec::new() };
        self.potential_rate_valid = false;
    }

    /// `Φ_q M⁻¹∇V` of the last evaluation, where it was kept and the applied
    /// force is `−∇V` alone; `None` otherwise.
    pub fn potential_rate(&self) -> Option<&[f64]> {
        self.potential_rate_valid.then_some(&self.potential_rate[..])
    }

    /// Whether an evaluation at the positions and time of the latest
    /// factorization of `S` reuses it (constant `M` only): worth it where
    /// states repeat, as after a projection.
    pub fn reuse_factorization(&mut self, on: bool) {
        self.reuse = on;
        self.factored_at = None;
    }

    /// Sets what a dependent constraint row does in the next evaluations
    /// (default: [`DependentRows::Error`]).
    pub fn set_dependent_rows(&mut self, dependent: DependentRows) {
        self.factored_at = None;
        match &mut self.solver {
            Solver::Constant(schur) => schur.set_dependent_rows(dependent),
            Solver::General(g) => g.schur.set_dependent_rows(dependent),
            Solver::Blocks(b) => b.set_dependent_rows(dependent),
        }
    }

    /// Whether `Φ_q M⁻¹ Φ_qᵀ` is factored along a sparse pattern (fewer
    /// entries of `L` than the full triangle), as [`LinearSolver::Auto`]
    /// finds for chains and trees.
    pub fn sparse_factor(&self) -> bool {
        match &self.solver {
            Solver::Constant(schur) => schur.is_sparse(),
            Solver::General(_) => false,
            Solver::Blocks(b) => b.schur.is_sparse(),
        }
    }

    /// Constraint rows the last evaluation dropped as dependent (0 unless tolerated).
    pub fn dependent_rows(&self) -> usize {
        match &self.solver {
            Solver::Constant(schur) => schur.dependent_rows(),
            Solver::General(g) => g.schur.dependent_rows(),
            Solver::Blocks(b) => b.schur.dependent_rows(),
        }
    }

    /// Evaluates everything at `(q, v, t)`: constraints, forces, the
    /// factorization of `Φ_q M⁻¹ Φ_qᵀ`, `λ` and `A`.
    pub fn evaluate(&mut self, model: &Model, q: &[f64], v: &[f64], t: f64) -> Result<(), Breakdown> {
        self.evaluate_but_reaction(model, q, v, t)?;
        self.take_acc(|d, acc| d.subtract_reaction(model, acc));
        Ok(())
    }

    /// [`evaluate`](Self::evaluate) but for the constraint forces in `A`:
    /// [`acc`](Self::acc) is `M⁻¹G` until the caller subtracts `M⁻¹Φ_qᵀλ`
    /// (with [`take_acc`](Self::take_acc)) — in the same pass over the
    /// Jacobian as the control terms' own products, which saves one.
    pub(crate) fn evaluate_but_reaction(
        &mut self,
        model: &Model,
        q: &[f64],
        v: &[f64],
        t: f64,
    ) -> Result<(), Breakdown> {
        self.evaluate_forces(model, q, v, t)?;
        if model.m() == 0 {
            return Ok(());
        }
        self.potential_rate_valid =
            !self.potential_rate.is_empty() && matches!(self.solver, Solver::Constant(_)) && !model.has_forces();
        if self.potential_rate_valid {
            // λ holds Φ_q M⁻¹G − γ with G = −∇V.
            let gamma = &self.constraints.gamma;
            for ((p, l), g) in self.potential_rate.iter_mut().zip(&self.lambda).zip(gamma) {
                *p = -(l + g);
            }
        }
        match &mut self.solver {
            Solver::Constant(schur) => {
                if self.reuse && self.factored_at == Some(t) && self.factored_q == q {
                    schur.solve(&mut self.lambda);
                } else {
                    self.factored_at = None;
                    schur.factor_and_solve(&self.constraints.jac, &mut self.lambda)?;
                    if self.reuse {
                        self.factored_q.copy_from_slice(q);
                        self.factored_at = Some(t);
                    }
                }
            }
            Solver::General(g) => g.factor_and_solve(model, &self.constraints.jac, &mut self.lambda)?,
            Solver::Blocks(b) => b.factor_and_solve(&self.constraints.jac, &mut self.lambda)?,
        }
        Ok(())
    }

    /// Lends `A` (as [`evaluate_but_reaction`](Self::evaluate_but_reaction)
    /// left it) to `f`, which finishes it.
    pub(crate) fn take_acc(&mut self, f: impl FnOnce(&Self, &mut [f64])) {
        let mut acc = std::mem::take(&mut self.acc);
        f(self, &mut acc);
        self.acc = acc;
    }

    /// `acc −= M⁻¹ Φ_qᵀ λ`: `A`'s constraint forces (Eq. 8, `A = M⁻¹ (G − Φ_qᵀ λ)`).
    pub(crate) fn subtract_reaction(&self, model: &Model, acc: &mut [f64]) {
        self.add_weighted_jt(model, &self.lambda, -1.0, acc);
    }

    /// The first half of [`evaluate`](Self::evaluate): `V`, `G`, `M(q)`
    /// and the constraints (`Φ`, `Φ̇`, `Φ_t`, `γ`, `Φ_q`) at `(q, v, t)`,
    /// without the multipliers: what an implicit scheme's Newton residual
    /// reads. [`lambda`](Self::lambda) and [`acc`](Self::acc) are then not
    /// the multipliers and accelerations of this state.
    #[inline(always)]
    pub fn evaluate_forces(&mut self, model: &Model, q: &[f64], v: &[f64], t: f64) -> Result<(), Breakdown> {
        self.grad_potential.fill(0.0);
        self.potential = model.potential(q, Some(&mut self.grad_potential));
        for (f, g) in self.force.iter_mut().zip(&self.grad_potential) {
            *f = -g;
        }
        self.force_power = model.add_forces(q, v, t, &mut self.force);
        // The unconstrained acceleration M⁻¹ G, which the constraint pass needs for `Φ_q M⁻¹ G − γ`.
        match (&mut self.solver, model.mass()) {
            (Solver::Constant(_), Some(mass)) => mass.solve(&self.force, &mut self.acc),
            (Solver::General(g), _) => {
                g.psi_q.fill(0.0);
                g.mdot_v.fill(0.0);
                self.kinetic =
                    model.mass_at(q, v, &mut g.mass, &mut g.psi_q, &mut g.mdot_v).map_err(Breakdown::Mass)?;
                lagrange_terms(&mut self.force, &mut g.psi_q, &g.mdot_v, &self.grad_potential);
                g.mass.solve(&self.force, &mut self.acc);
            }
            (Solver::Blocks(b), _) => {
                b.psi_q.fill(0.0);
                b.mdot_v.fill(0.0);
                self.kinetic =
                    model.block_mass_at(q, v, &mut b.mass, &mut b.psi_q, &mut b.mdot_v).map_err(Breakdown::Mass)?;
                lagrange_terms(&mut self.force, &mut b.psi_q, &b.mdot_v, &self.grad_potential);
                b.mass.solve(&self.force, &mut self.acc);
            }
            (Solver::Constant(_), None) => unreachable!("a workspace built for another model"),
        }
        // λ starts as the right-hand side of (Φ_q M⁻¹ Φ_qᵀ) λ = Φ_q M⁻¹ G − γ   (Eqs. 6–7)
        model.constraints(q, v, t, self.constraints.pass(&self.acc, &mut self.lambda));
        Ok(())
    }

    /// For a change `b` of the constraint right-hand side (`Φ_q q̈ = γ − b`),
    /// adds the resulting change of acceleration, `−M⁻¹ Φ_qᵀ S⁻¹ b`, to
    /// `out`. `b` is overwritten with the multiplier change `S⁻¹ b`.
    /// Uses the factorization of the last [`evaluate`](Self::evaluate).
    pub fn add_constraint_response(&self, model: &Model, b: &mut [f64], out: &mut [f64]) {
        match &self.solver {
            Solver::Constant(schur) => schur.solve(b),
            Solver::General(g) => g.schur.solve(b),
            Solver::Blocks(blocks) => blocks.schur.solve(b),
        }
        self.add_weighted_jt(model, b, -1.0, out);
    }

    /// The mass matrix at the state of the last [`evaluate`](Self::evaluate).
    #[inline(always)]
    pub fn mass<'a>(&'a self, model: &'a Model) -> MassAt<'a> {
        match (&self.solver, model.mass()) {
            (Solver::General(g), _) => MassAt::Dense(&g.mass),
            (Solver::Blocks(b), _) => MassAt::Blocks(&b.mass),
            (Solver::Constant(_), Some(mass)) => MassAt::Diagonal(mass),
            (Solver::Constant(_), None) => unreachable!("a workspace built for another model"),
        }
    }

    /// `Ψ_q = ∇V + ∂T/∂q` of the last evaluation (`∇V` when `M` is constant).
    pub fn psi_q(&self) -> &[f64] {
        match &self.solver {
            Solver::Constant(_) => &self.grad_potential,
            Solver::General(g) => &g.psi_q,
            Solver::Blocks(b) => &b.psi_q,
        }
    }

    /// The energy input `Ė = F·v + λᵀ Φ_t` of the last evaluation (see [`crate::dynamics::energy`]).
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
    /// Values of `Φ_q` in the model's [`Pattern`](crate::linalg::sparse::Pattern) order.
    pub fn jac(&self) -> &[f64] {
        &self.constraints.jac
    }
    /// Generalized applied force `G = −∇V + F`, with Lagrange's velocity
    /// terms `∂T/∂q − Ṁ q̇` when `M` depends on `q`.
    pub fn force(&self) -> &[f64] {
        &self.force
    }
    /// `∇V` (which is `Ψ_q` when `M` is constant; see [`psi_q`](Self::psi_q)).
    pub fn grad_potential(&self) -> &[f64] {
        &self.grad_potential
    }
    /// `V(q)`
    pub fn potential(&self) -> f64 {
        self.potential
    }
    /// Kinetic energy at the last evaluation, whose velocities `v` are:
    /// summed by the mass pass where `M` depends on `q`, `½ vᵀMv` otherwise.
    pub fn kinetic(&self, model: &Model, v: &[f64]) -> f64 {
        match (&self.solver, model.mass()) {
            (Solver::Constant(_), Some(mass)) => mass.kinetic(v),
            _ => self.kinetic,
        }
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
