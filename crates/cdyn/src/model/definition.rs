//! What a system is: coordinates with a mass matrix (constant and
//! diagonal, or from kinetic-energy elements: see [`crate::linalg::mass`]),
//! holonomic constraint elements, potentials and non-conservative forces.

use crate::error::{Error, Part, Problem, Result};
use crate::linalg::mass::{BlockMass, DenseMass, DiagonalMass, MassMatrix};
use crate::model::angular::Generator;
use crate::model::constraint::{ConstraintBlock, ConstraintValues};
use crate::model::force::{ForceBlock, PotentialBlock};
use crate::model::input::Inputs;
use crate::model::invariant::Declared;
use crate::model::kinetic::KineticBlock;
use crate::model::unit_vector::UnitVector;

/// The sparsity of `Φ_q`, as [`Model::pattern`] returns it (defined with the
/// other sparse structures in `sparse.rs`).
pub use crate::linalg::sparse::Pattern;

/// Where one constraint block's values lie: its rows `[start, end)` and
/// its Jacobian entries `[start, end)`, fixed when the model is built.
#[derive(Clone, Copy)]
pub(super) struct BlockSpan {
    pub rows: (usize, usize),
    pub entries: (usize, usize),
}

/// A constrained mechanical system, ready to simulate.
///
/// Built with [`Model::builder`] from the coordinates' masses and elements
/// written once for any scalar, as here a point on the unit circle:
///
/// ```
/// use cdyn::{Constraint, Model, Scalar};
///
/// /// `Φ = x² + y² − 1`
/// struct Circle;
/// impl Constraint<2, 1> for Circle {
///     fn eval<D: Scalar>(&self, [x, y]: [D; 2], _t: D) -> [D; 1] {
///         [x * x + y * y - 1.0]
///     }
/// }
///
/// let model = Model::builder(vec![2.0, 2.0]).constrain(Circle, [0, 1]).build()?;
/// assert_eq!((model.n(), model.m()), (2, 1));
/// let mut phi = [0.0];
/// model.constraint_values(&[0.6, 0.8], 0.0, &mut phi);
/// assert!(phi[0].abs() < 1e-15);
/// # Ok::<(), cdyn::Error>(())
/// ```
pub struct Model {
    pub(super) inertia: Inertia,
    pub(super) constraints: Vec<Box<dyn ConstraintBlock>>,
    pub(super) potentials: Vec<Box<dyn PotentialBlock>>,
    pub(super) forces: Vec<Box<dyn ForceBlock>>,
    pub(super) pattern: Pattern,
    /// The rows and Jacobian entries of each constraint block.
    pub(super) offsets: Vec<BlockSpan>,
    pub(super) unit_vectors: Vec<UnitVector>,
    pub(super) momenta: Vec<Direction>,
    pub(super) rotations: Vec<Generator>,
    pub(super) invariants: Vec<Declared>,
    pub(super) names: Option<Vec<String>>,
    pub(super) inputs: Inputs,
}

/// Where the kinetic energy comes from, decided when the model is built.
pub(super) enum Inertia {
    /// `T = ½ vᵀ M v` with a constant diagonal `M`: the fast path.
    Constant(DiagonalMass),
    /// `T = ½ Σ m_i v_i² + Σ T_e`: `M(q)` evaluated at every state.
    General {
        /// The diagonal part (zero where the elements give all the inertia).
        diagonal: Vec<f64>,
        kinetic: Vec<Box<dyn KineticBlock>>,
        /// Each element's coordinates, when `M(q)` is block-diagonal (see
        /// [`Model::mass_blocks`]); `None` when it must be factored densely.
        blocks: Option<Vec<Vec<u32>>>,
    },
}

/// A direction along which a model may keep its momentum: added by a
/// mechanism builder (rigid translations) or declared by the user.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct Direction {
    /// What its momentum is called ("linear momentum x").
    pub name: String,
    /// Its non-zero entries: coordinate and weight.
    pub entries: Vec<(u32, f64)>,
    /// Declared by the user: reported when the model does not keep it.
    pub declared: bool,
}

/// A momentum direction on `n` coordinates, checked: coordinates that
/// exist, finite weights, not all zero.
pub(super) fn checked_direction(name: &str, direction: &[(usize, f64)], declared: bool, n: usize) -> Result<Direction> {
    if let Some(&(index, _)) = direction.iter().find(|(i, _)| *i >= n) {
        return Err(Problem::NoSuchCoordinate { index, n }.at(Part::Block { what: "a momentum" }));
    }
    let bad = |value, reason| Err(Error::InvalidParameter { name: "momentum direction", value, reason });
    if let Some(&(_, w)) = direction.iter().find(|(_, w)| !w.is_finite()) {
        return bad(w, "must be finite");
    }
    if direction.iter().all(|(_, w)| *w == 0.0) {
        return bad(0.0, "must have a non-zero entry");
    }
    let entries = direction.iter().map(|&(i, w)| (i as u32, w)).collect();
    Ok(Direction { name: name.to_string(), entries, declared })
}

/// Checks there are no more constraint rows `m` than coordinates `n`
/// (`m = n` is allowed: a fully driven, kinematic mechanism).
pub(crate) fn check_rows(m: usize, n: usize) -> Result<()> {
    if m > n {
        return Err(Problem::TooManyConstraints { m, n }.into());
    }
    Ok(())
}

impl Model {
    /// The rotations declared or proposed by a mechanism builder, whose
    /// angular momenta a run checks ([`crate::dynamics::momentum::detect`]).
    pub fn rotations(&self) -> &[Generator] {
        &self.rotations
    }

    /// The invariants declared with [`ModelBuilder::invariant`](crate::model::ModelBuilder::invariant).
    pub fn declared_invariants(&self) -> &[Declared] {
        &self.invariants
    }

    /// The inputs declared with [`ModelBuilder::input`](crate::model::ModelBuilder::input)
    /// (see [`crate::model::input`]); their values are set through a simulation.
    pub fn inputs(&self) -> &Inputs {
        &self.inputs
    }

    /// The coordinates' names, where the builder gave them.
    pub fn coordinate_names(&self) -> Option<&[String]> {
        self.names.as_deref()
    }

    /// The momentum directions declared or proposed by a mechanism
    /// builder ([`ModelBuilder::momentum`](crate::model::ModelBuilder::momentum)); which of them, and which cyclic
    /// coordinates, the model keeps is found when a run starts.
    pub fn momentum_directions(&self) -> &[Direction] {
        &self.momenta
    }

    /// The unit vectors among the coordinates ([`ModelBuilder::unit_vector`](crate::model::ModelBuilder::unit_vector)).
    pub fn unit_vectors(&self) -> &[UnitVector] {
        &self.unit_vectors
    }

    /// Number of coordinates `n`.
    pub fn n(&self) -> usize {
        match &self.inertia {
            Inertia::Constant(mass) => mass.n(),
            Inertia::General { diagonal, .. } => diagonal.len(),
        }
    }
    /// Number of constraint rows `m`.
    pub fn m(&self) -> usize {
        self.pattern.start.len() - 1
    }
    /// The mass matrix `M` when it is constant and diagonal; `None` when it
    /// depends on `q` (kinetic-energy elements), see [`Model::mass_at`].
    #[inline(always)]
    pub fn mass(&self) -> Option<&DiagonalMass> {
        match &self.inertia {
            Inertia::Constant(mass) => Some(mass),
            Inertia::General { .. } => None,
        }
    }

    /// Evaluates `M(q)` into `mass` and factors it; adds `∂T/∂q` into
    /// `grad_q` and `Ṁ q̇` into `mdot_v` (both zero for a constant `M`).
    /// Returns `T`, or the coordinate whose pivot shows `M` is not
    /// positive definite at `q`.
    pub fn mass_at(
        &self,
        q: &[f64],
        v: &[f64],
        mass: &mut DenseMass,
        grad_q: &mut [f64],
        mdot_v: &mut [f64],
    ) -> std::result::Result<f64, usize> {
        let n = self.n();
        let m = mass.matrix_mut();
        m.fill(0.0);
        let mut energy = 0.0;
        match &self.inertia {
            Inertia::Constant(d) => {
                for (i, &mi) in d.diagonal().iter().enumerate() {
                    m[i * n + i] = mi;
                }
                energy = d.kinetic(v);
            }
            Inertia::General { diagonal, kinetic, .. } => {
                for (i, &mi) in diagonal.iter().enumerate() {
                    m[i * n + i] = mi;
                    energy += 0.5 * mi * v[i] * v[i];
                }
                for b in kinetic {
                    energy += b.add_all(q, v, m, grad_q, mdot_v);
                }
            }
        }
        mass.factor()?;
        Ok(energy)
    }
    /// The diagonal masses given to [`Model::builder`] (for a constant `M`, its diagonal).
    pub fn diagonal_mass(&self) -> &[f64] {
        match &self.inertia {
            Inertia::Constant(mass) => mass.diagonal(),
            Inertia::General { diagonal, .. } => diagonal,
        }
    }

    /// The coordinates of each block of a block-diagonal `M(q)` (one per
    /// kinetic element), or `None` when `M` is constant or must be
    /// factored densely (see [`BlockMass`]).
    pub fn mass_blocks(&self) -> Option<&[Vec<u32>]> {
        match &self.inertia {
            Inertia::General { blocks, .. } => blocks.as_deref(),
            Inertia::Constant(_) => None,
        }
    }

    /// As [`mass_at`](Self::mass_at), into the blocks of a
    /// [`BlockMass`] laid out by [`mass_blocks`](Self::mass_blocks).
    pub fn block_mass_at(
        &self,
        q: &[f64],
        v: &[f64],
        mass: &mut BlockMass,
        grad_q: &mut [f64],
        mdot_v: &mut [f64],
    ) -> std::result::Result<f64, usize> {
        let Inertia::General { diagonal, kinetic, blocks: Some(_) } = &self.inertia else {
            panic!("block_mass_at on a model without a block-diagonal M(q)");
        };
        let mut energy = 0.5 * diagonal.iter().zip(v).map(|(m, v)| m * v * v).sum::<f64>();
        let mut rest = mass.matrices_mut();
        for b in kinetic {
            let k = b.width();
            let (mine, others) = std::mem::take(&mut rest).split_at_mut(b.items() * k * k);
            energy += b.add_blocks(q, v, mine, grad_q, mdot_v);
            rest = others;
        }
        // A coordinate's own mass joins its block's diagonal.
        for b in 0..mass.blocks() {
            let k = mass.coordinates(b).len();
            for i in 0..k {
                let c = mass.coordinates(b)[i] as usize;
                if diagonal[c] != 0.0 {
                    mass.add_to_diagonal(b, i, diagonal[c]);
                }
            }
        }
        mass.factor()?;
        Ok(energy)
    }

    /// Which coordinates each constraint row of `Φ_q` reads.
    pub fn pattern(&self) -> &Pattern {
        &self.pattern
    }
    /// `Φ`, `Φ̇`, `Φ_t`, `γ`, the Jacobian values (in [`Pattern`] order) and `Φ_q a − γ`.
    pub(crate) fn constraints(&self, q: &[f64], v: &[f64], t: f64, out: ConstraintValues<'_>) {
        // One block spans every row: `out` as it is (slicing seven buffers
        // per call was a third of a pendulum's constraint pass).
        if let [block] = &self.constraints[..] {
            return block.evaluate(q, v, t, out);
        }
        // The spans are read, not recomputed: a block's `rows` and `width`
        // are calls through its vtable (three a block, each step).
        for (b, &BlockSpan { rows: (r0, r1), entries: (j0, j1) }) in self.constraints.iter().zip(&self.offsets) {
            b.evaluate(
                q,
                v,
                t,
                ConstraintValues {
                    free_acc: out.free_acc,
                    rhs: &mut out.rhs[r0..r1],
                    phi: &mut out.phi[r0..r1],
                    phi_dot: &mut out.phi_dot[r0..r1],
                    phi_t: &mut out.phi_t[r0..r1],
                    gamma: &mut out.gamma[r0..r1],
                    jac: &mut out.jac[j0..j1],
                },
            );
        }
    }

    /// `Φ(q, t)` alone (zero on nonholonomic rows, which have no position-level value).
    pub fn constraint_values(&self, q: &[f64], t: f64, phi: &mut [f64]) {
        for (b, &BlockSpan { rows: (r0, r1), .. }) in self.constraints.iter().zip(&self.offsets) {
            b.values(q, t, &mut phi[r0..r1]);
        }
    }

    /// Potential energy; adds `∇V` into `grad` when given.
    pub fn potential(&self, q: &[f64], grad: Option<&mut [f64]>) -> f64 {
        match grad {
            Some(g) => self.potentials.iter().map(|p| p.energy_and_gradient(q, g)).sum(),
            None => self.potentials.iter().map(|p| p.energy(q)).sum(),
        }
    }

    /// Whether the model has non-conservative forces (the applied force is `−∇V` without them).
    pub fn has_forces(&self) -> bool {
        !self.forces.is_empty()
    }

    /// Adds the non-conservative forces into `f`; returns their power.
    pub fn add_forces(&self, q: &[f64], v: &[f64], t: f64, f: &mut [f64]) -> f64 {
        self.forces.iter().map(|b| b.add_forces(q, v, t, f)).sum()
    }

    /// Adds `C w = −∂Q/∂v · w`, the damping of the non-conservative forces
    /// along `w`, into `out` (by one directional dual pass of each force).
    pub fn add_damping(&self, q: &[f64], v: &[f64], w: &[f64], t: f64, out: &mut [f64]) {
        self.forces.iter().for_each(|b| b.add_damping(q, v, w, t, out));
    }

    /// The `(row, column)` of the entries [`iteration_values`](Self::iteration_values)
    /// writes: each potential's Hessian block, then each force's Jacobian block.
    pub(crate) fn iteration_entries(&self, out: &mut Vec<(u32, u32)>) {
        self.potentials.iter().for_each(|p| p.hessian_entries(out));
        self.forces.iter().for_each(|f| f.jacobian_entries(out));
    }

    /// `c_q K + c_v C` of an implicit step's Newton matrix, entry by entry
    /// in the order of [`iteration_entries`](Self::iteration_entries):
    /// `K = ∇²V − ∂F/∂q` and `C = −∂F/∂v` of the potentials and forces.
    pub(crate) fn iteration_values(&self, q: &[f64], v: &[f64], t: f64, c_q: f64, c_v: f64, out: &mut [f64]) {
        let mut at = 0;
        for p in &self.potentials {
            at += p.hessians(q, c_q, &mut out[at..]);
        }
        for f in &self.forces {
            at += f.jacobians(q, v, t, c_q, c_v, &mut out[at..]);
        }
    }

    /// The `(row, column)` of the entries [`curvature_values`](Self::curvature_values)
    /// writes: each holonomic constraint element's block.
    pub(crate) fn curvature_entries(&self, out: &mut Vec<(u32, u32)>) {
        self.constraints.iter().for_each(|b| b.curvature_entries(out));
    }

    /// `scale · Σ_r λ_r ∇²Φ_r`, the derivative of `Φ_qᵀ λ` in `q` (the
    /// constraints' geometric stiffness), entry by entry in the order of
    /// [`curvature_entries`](Self::curvature_entries).
    pub(crate) fn curvature_values(&self, q: &[f64], t: f64, lambda: &[f64], scale: f64, out: &mut [f64]) {
        let mut at = 0;
        for (b, &BlockSpan { rows: (r0, r1), .. }) in self.constraints.iter().zip(&self.offsets) {
            at += b.curvatures(q, t, &lambda[r0..r1], scale, &mut out[at..]);
        }
    }

    /// For each constraint row, whether it is holonomic (a position-level
    /// `Φ`) rather than nonholonomic (velocity-level only).
    pub(crate) fn holonomic_rows(&self) -> Vec<bool> {
        self.constraints.iter().flat_map(|b| std::iter::repeat_n(b.holonomic(), b.rows())).collect()
    }

    /// Kinetic energy `T(q, v) = ½ vᵀ M(q) v`.
    pub fn kinetic(&self, q: &[f64], v: &[f64]) -> f64 {
        self.kinetic_and_gradient(q, v, None)
    }

    /// `T(q, v)`, adding `∂T/∂q` into `grad_q` when given (nothing for a
    /// constant `M`). `∇V + ∂T/∂q` is the energy constraint's `Ψ_q`.
    pub fn kinetic_and_gradient(&self, q: &[f64], v: &[f64], mut grad_q: Option<&mut [f64]>) -> f64 {
        match &self.inertia {
            Inertia::Constant(mass) => mass.kinetic(v),
            Inertia::General { diagonal, kinetic, .. } => {
                let own = 0.5 * diagonal.iter().zip(v).map(|(m, v)| m * v * v).sum::<f64>();
                own + kinetic.iter().map(|b| b.energy(q, v, grad_q.as_deref_mut())).sum::<f64>()
            }
        }
    }
}
