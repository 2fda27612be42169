//! What a system is: coordinates with a mass matrix (constant and
//! diagonal, or from kinetic-energy elements: see [`crate::linalg::mass`]),
//! holonomic constraint elements, potentials and non-conservative forces.

use crate::error::{Error, Part, Problem, Result};
use crate::linalg::mass::{BlockMass, DenseMass, DiagonalMass, MAX_BLOCK, MassMatrix};
use crate::model::angular::Generator;
use crate::model::constraint::{Constraint, ConstraintBlock, ConstraintGroup, ConstraintValues};
use crate::model::force::{Force, ForceBlock, ForceGroup, Potential, PotentialBlock, PotentialGroup};
use crate::model::invariant::{Declared, Invariant};
use crate::model::kinetic::{ByMap, Kinetic, KineticBlock, KineticElement, KineticGroup, VelocityMap};
use crate::model::nonholonomic::{Nonholonomic, NonholonomicGroup};
use crate::model::unit_vector::{UnitNorm, UnitVector};

/// The sparsity of `Φ_q`, as [`Model::pattern`] returns it (defined with the
/// other sparse structures in `sparse.rs`).
pub use crate::linalg::sparse::Pattern;

/// A constrained mechanical system, ready to simulate.
pub struct Model {
    inertia: Inertia,
    constraints: Vec<Box<dyn ConstraintBlock>>,
    potentials: Vec<Box<dyn PotentialBlock>>,
    forces: Vec<Box<dyn ForceBlock>>,
    pattern: Pattern,
    /// First row and first Jacobian entry of each constraint block.
    offsets: Vec<(usize, usize)>,
    unit_vectors: Vec<UnitVector>,
    momenta: Vec<Direction>,
    rotations: Vec<Generator>,
    invariants: Vec<Declared>,
    names: Option<Vec<String>>,
}

/// Where the kinetic energy comes from, decided when the model is built.
enum Inertia {
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

/// Builds a [`Model`] element by element.
pub struct ModelBuilder {
    mass: Vec<f64>,
    kinetic: Vec<Box<dyn KineticBlock>>,
    constraints: Vec<Box<dyn ConstraintBlock>>,
    potentials: Vec<Box<dyn PotentialBlock>>,
    forces: Vec<Box<dyn ForceBlock>>,
    unit_vectors: Vec<UnitVector>,
    momenta: Vec<Direction>,
    rotations: Vec<Generator>,
    invariants: Vec<Declared>,
    names: Option<Vec<String>>,
    error: Option<Error>,
}

impl ModelBuilder {
    fn check_indices<const K: usize>(&mut self, what: &'static str, at: &[usize; K]) -> bool {
        if self.error.is_some() {
            return false;
        }
        let n = self.mass.len();
        for (j, &i) in at.iter().enumerate() {
            if i >= n {
                self.error = Some(Problem::NoSuchCoordinate { index: i, n }.at(Part::Block { what }));
                return false;
            }
            if at[..j].contains(&i) {
                self.error = Some(Problem::CoordinateTwice { index: i }.at(Part::Block { what }));
                return false;
            }
        }
        true
    }

    /// Adds `R` constraint rows reading the coordinates `at`.
    pub fn constrain<C: Constraint<K, R>, const K: usize, const R: usize>(mut self, c: C, at: [usize; K]) -> Self {
        if self.check_indices("a constraint", &at) {
            let item = (c, at);
            match self.constraints.last_mut().and_then(|b| b.as_any_mut().downcast_mut::<ConstraintGroup<C, K, R>>()) {
                Some(g) => g.items.push(item),
                None => self.constraints.push(Box::new(ConstraintGroup { items: vec![item] })),
            }
        }
        self
    }

    /// Adds the row `|x|² − 1 = 0` on the coordinates `at` and makes them a
    /// unit vector, of which only the direction is physical (a spatial
    /// body's Euler parameters): cdyn's corrections of the positions carry
    /// its velocities along (see [`crate::model::unit_vector`]).
    pub fn unit_vector<const K: usize>(mut self, at: [usize; K]) -> Self {
        let row = self.rows();
        self = self.constrain(UnitNorm, at);
        if self.error.is_none() {
            self.unit_vectors.push(UnitVector { row, coordinates: at.map(|c| c as u32).to_vec() });
        }
        self
    }

    /// Names the coordinates (`body.x`, …), one per coordinate, for what a
    /// run reports of them (a cyclic coordinate's momentum).
    pub fn coordinate_names(mut self, names: Vec<String>) -> Self {
        if self.error.is_none() && names.len() != self.mass.len() {
            self.error = Some(Error::InvalidParameter {
                name: "coordinate names",
                value: names.len() as f64,
                reason: "must name every coordinate once",
            });
        }
        self.names = Some(names);
        self
    }

    /// Declares that the model keeps the generalized momentum `eᵀ ∂T/∂v`
    /// along the constant direction `e` given by its non-zero entries
    /// (coordinate, weight). A run checks it like the directions it finds
    /// itself ([`crate::dynamics::momentum::detect`]) and reports it when the model
    /// breaks it, instead of holding it.
    pub fn momentum(self, name: &str, direction: &[(usize, f64)]) -> Self {
        self.momentum_direction(name, direction, true)
    }

    /// A direction a mechanism builder proposes (a rigid translation):
    /// kept where the model turns out symmetric along it, else dropped silently.
    pub(crate) fn momentum_candidate(self, name: &str, direction: &[(usize, f64)]) -> Self {
        self.momentum_direction(name, direction, false)
    }

    /// Declares that the model keeps the momentum `L = ξ(q)ᵀ M v` of the
    /// rigid rotation `generator` (see [`crate::model::angular`];
    /// [`Generator::rotation`] makes one from a mechanism's coordinate
    /// names). A run checks it like those it finds, holds it where the
    /// control does, and reports it when the model breaks it.
    pub fn angular_momentum(self, generator: Generator) -> Self {
        self.rotation(Generator { declared: true, ..generator })
    }

    /// Declares that the model keeps `I(q, v)` of the coordinates `at`, a
    /// function written once generic over the scalar (its gradients by AD).
    /// A run checks it at sample states, holds it beside the energy where
    /// the control does (`robust`, `projection`), and reports it, with its
    /// drift, when the motion changes it.
    pub fn invariant<I: Invariant<K>, const K: usize>(mut self, name: &str, invariant: I, at: [usize; K]) -> Self {
        if self.check_indices("an invariant", &at) {
            self.invariants.push(Declared::new(name, invariant, at));
        }
        self
    }

    /// A rotation a mechanism builder proposes: kept where the model turns
    /// out symmetric under it, else dropped silently.
    pub(crate) fn rotation_candidate(self, generator: Generator) -> Self {
        self.rotation(Generator { declared: false, ..generator })
    }

    fn rotation(mut self, generator: Generator) -> Self {
        if self.error.is_none() {
            match generator.check(self.mass.len()) {
                Ok(()) => self.rotations.push(generator),
                Err(reason) => {
                    self.error = Some(Problem::Rotation(reason).at(Part::Block { what: "an angular momentum" }))
                }
            }
        }
        self
    }

    fn momentum_direction(mut self, name: &str, direction: &[(usize, f64)], declared: bool) -> Self {
        if self.error.is_none() {
            match checked_direction(name, direction, declared, self.mass.len()) {
                Ok(d) => self.momenta.push(d),
                Err(e) => self.error = Some(e),
            }
        }
        self
    }

    /// Adds `R` nonholonomic rows `A(q, t) v + b(q, t) = 0` reading the
    /// coordinates `at` (see [`crate::model::nonholonomic`] for how every part of
    /// the library treats them).
    pub fn nonholonomic<C: Nonholonomic<K, R>, const K: usize, const R: usize>(mut self, c: C, at: [usize; K]) -> Self {
        if self.check_indices("a nonholonomic constraint", &at) {
            let item = (c, at);
            match self.constraints.last_mut().and_then(|b| b.as_any_mut().downcast_mut::<NonholonomicGroup<C, K, R>>())
            {
                Some(g) => g.items.push(item),
                None => self.constraints.push(Box::new(NonholonomicGroup { items: vec![item] })),
            }
        }
        self
    }

    /// Adds a potential energy term reading the coordinates `at`.
    pub fn potential<P: Potential<K>, const K: usize>(mut self, p: P, at: [usize; K]) -> Self {
        if self.check_indices("a potential", &at) {
            let item = (p, at);
            match self.potentials.last_mut().and_then(|b| b.as_any_mut().downcast_mut::<PotentialGroup<P, K>>()) {
                Some(g) => g.items.push(item),
                None => self.potentials.push(Box::new(PotentialGroup { items: vec![item] })),
            }
        }
        self
    }

    /// Adds a non-conservative force acting on the coordinates `at`.
    pub fn force<F: Force<K>, const K: usize>(mut self, f: F, at: [usize; K]) -> Self {
        if self.check_indices("a force", &at) {
            let item = (f, at);
            match self.forces.last_mut().and_then(|b| b.as_any_mut().downcast_mut::<ForceGroup<F, K>>()) {
                Some(g) => g.items.push(item),
                None => self.forces.push(Box::new(ForceGroup { items: vec![item] })),
            }
        }
        self
    }

    /// Adds a kinetic-energy term `T_e(x, ẋ)` of the coordinates `at`
    /// (see [`crate::model::kinetic`]): the model's `M` then depends on `q`, and the
    /// diagonal masses given to [`Model::builder`] may be zero for
    /// coordinates whose inertia comes from such terms. `M(q)` must be
    /// positive definite wherever the motion goes; where it is not, the
    /// evaluation fails with [`Breakdown::Mass`](crate::dynamics::Breakdown::Mass).
    pub fn kinetic<T: Kinetic<K>, const K: usize>(self, t: T, at: [usize; K]) -> Self {
        self.kinetic_element(t, at)
    }

    /// Adds a kinetic energy given by its velocity map `w = B(x) ẋ` and
    /// inertia `J` (see [`VelocityMap`]): the same as [`kinetic`](Self::kinetic)
    /// with `T = ½ wᵀ J w`, differentiated by cheaper passes.
    pub fn kinetic_map<T: VelocityMap<K, V>, const K: usize, const V: usize>(self, t: T, at: [usize; K]) -> Self {
        self.kinetic_element(ByMap::<T, V>(t), at)
    }

    fn kinetic_element<E: KineticElement<K>, const K: usize>(mut self, e: E, at: [usize; K]) -> Self {
        if self.check_indices("a kinetic energy", &at) {
            let item = (e, at);
            match self.kinetic.last_mut().and_then(|b| b.as_any_mut().downcast_mut::<KineticGroup<E, K>>()) {
                Some(g) => g.items.push(item),
                None => self.kinetic.push(Box::new(KineticGroup { items: vec![item] })),
            }
        }
        self
    }

    /// Constraint rows added so far.
    pub fn rows(&self) -> usize {
        self.constraints.iter().map(|b| b.rows()).sum()
    }

    /// The model, or the first error met while adding elements.
    pub fn build(self) -> Result<Model> {
        if let Some(e) = self.error {
            return Err(e);
        }
        if self.mass.is_empty() {
            return Err(Problem::NoCoordinates.into());
        }
        let n = self.mass.len();
        let nnz: usize = self.constraints.iter().map(|b| b.rows() * b.width()).sum();
        if u32::try_from(n.max(nnz)).is_err() {
            return Err(Problem::TooLarge { n, nnz }.into());
        }
        let mut pattern = Pattern { start: vec![0], cols: Vec::with_capacity(nnz), read: Vec::with_capacity(nnz) };
        let mut offsets = Vec::with_capacity(self.constraints.len());
        for b in &self.constraints {
            offsets.push((pattern.start.len() - 1, pattern.cols.len()));
            b.columns(&mut pattern.cols);
            b.reads(&mut pattern.read);
            for _ in 0..b.rows() {
                let last = *pattern.start.last().unwrap();
                pattern.start.push(last + b.width() as u32);
            }
        }
        let inertia = if self.kinetic.is_empty() {
            Inertia::Constant(DiagonalMass::new(self.mass)?)
        } else {
            for &m in &self.mass {
                crate::error::non_negative("mass", m)?;
            }
            let blocks = block_layout(&self.mass, &self.kinetic, &pattern);
            Inertia::General { diagonal: self.mass, kinetic: self.kinetic, blocks }
        };
        check_rows(pattern.start.len() - 1, n)?;
        Ok(Model {
            inertia,
            constraints: self.constraints,
            potentials: self.potentials,
            forces: self.forces,
            pattern,
            offsets,
            unit_vectors: self.unit_vectors,
            momenta: self.momenta,
            rotations: self.rotations,
            invariants: self.invariants,
            names: self.names,
        })
    }
}

/// The kinetic elements' coordinates when `M(q)` is block-diagonal in a
/// way the sparse solver can use: the elements read disjoint sets of at
/// most [`MAX_BLOCK`] coordinates, every other coordinate has a positive
/// mass of its own, and a constraint row that reads a coordinate of a
/// block reads all of them (so `M⁻¹ Φ_qᵀ` keeps the pattern of `Φ_qᵀ`). A
/// spatial body's Euler parameters are such a block. `None` otherwise.
fn block_layout(mass: &[f64], kinetic: &[Box<dyn KineticBlock>], pattern: &Pattern) -> Option<Vec<Vec<u32>>> {
    let blocks: Vec<Vec<u32>> = kinetic.iter().flat_map(|b| b.coordinates()).collect();
    let mut owner = vec![u32::MAX; mass.len()];
    for (b, coords) in blocks.iter().enumerate() {
        if coords.len() > MAX_BLOCK {
            return None;
        }
        for &c in coords {
            if owner[c as usize] != u32::MAX {
                return None;
            }
            owner[c as usize] = b as u32;
        }
    }
    if owner.iter().zip(mass).any(|(&o, &m)| o == u32::MAX && m <= 0.0) {
        return None;
    }
    let mut seen = vec![0usize; blocks.len()];
    for r in 0..pattern.start.len() - 1 {
        let cols = &pattern.cols[pattern.row(r)];
        for &c in cols {
            if let Some(b) = owner.get(c as usize).filter(|&&o| o != u32::MAX) {
                seen[*b as usize] += 1;
            }
        }
        for &c in cols {
            if let Some(&b) = owner.get(c as usize).filter(|&&o| o != u32::MAX)
                && !std::mem::take(&mut seen[b as usize]).is_multiple_of(blocks[b as usize].len())
            {
                return None;
            }
        }
    }
    Some(blocks)
}

/// A direction along which a model may keep its momentum: added by a
/// mechanism builder (rigid translations) or declared by the user.
#[derive(Debug, Clone, PartialEq)]
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
fn checked_direction(name: &str, direction: &[(usize, f64)], declared: bool, n: usize) -> Result<Direction> {
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
    /// Starts a model whose coordinates have these (diagonal) masses.
    pub fn builder(mass: Vec<f64>) -> ModelBuilder {
        ModelBuilder {
            mass,
            kinetic: Vec::new(),
            constraints: Vec::new(),
            potentials: Vec::new(),
            forces: Vec::new(),
            unit_vectors: Vec::new(),
            momenta: Vec::new(),
            rotations: Vec::new(),
            invariants: Vec::new(),
            names: None,
            error: None,
        }
    }

    /// Declares, on a built model, that it keeps the momentum along
    /// `direction` (as [`ModelBuilder::momentum`]).
    pub fn declare_momentum(&mut self, name: &str, direction: &[(usize, f64)]) -> Result<()> {
        self.momenta.push(checked_direction(name, direction, true, self.n())?);
        Ok(())
    }

    /// Declares, on a built model, that it keeps the momentum of the
    /// rotation `generator` (as [`ModelBuilder::angular_momentum`]).
    pub fn declare_angular_momentum(&mut self, generator: Generator) -> Result<()> {
        generator
            .check(self.n())
            .map_err(|reason| Problem::Rotation(reason).at(Part::Block { what: "an angular momentum" }))?;
        self.rotations.push(Generator { declared: true, ..generator });
        Ok(())
    }

    /// The rotations declared or proposed by a mechanism builder, whose
    /// angular momenta a run checks ([`crate::dynamics::momentum::detect`]).
    pub fn rotations(&self) -> &[Generator] {
        &self.rotations
    }

    /// Declares, on a built model, that it keeps `I(q, v)` of the
    /// coordinates `at` (as [`ModelBuilder::invariant`]).
    pub fn declare_invariant<I: Invariant<K>, const K: usize>(
        &mut self,
        name: &str,
        invariant: I,
        at: [usize; K],
    ) -> Result<()> {
        let n = self.n();
        for (j, &index) in at.iter().enumerate() {
            let what = Part::Block { what: "an invariant" };
            if index >= n {
                return Err(Problem::NoSuchCoordinate { index, n }.at(what));
            }
            if at[..j].contains(&index) {
                return Err(Problem::CoordinateTwice { index }.at(what));
            }
        }
        self.invariants.push(Declared::new(name, invariant, at));
        Ok(())
    }

    /// The invariants declared with [`ModelBuilder::invariant`].
    pub fn declared_invariants(&self) -> &[Declared] {
        &self.invariants
    }

    /// The coordinates' names, where the builder gave them.
    pub fn coordinate_names(&self) -> Option<&[String]> {
        self.names.as_deref()
    }

    /// The momentum directions declared or proposed by a mechanism
    /// builder ([`ModelBuilder::momentum`]); which of them, and which cyclic
    /// coordinates, the model keeps is found when a run starts.
    pub fn momentum_directions(&self) -> &[Direction] {
        &self.momenta
    }

    /// The unit vectors among the coordinates ([`ModelBuilder::unit_vector`]).
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
        for (b, &(r0, j0)) in self.constraints.iter().zip(&self.offsets) {
            let (r1, j1) = (r0 + b.rows(), j0 + b.rows() * b.width());
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
        for (b, &(r0, _)) in self.constraints.iter().zip(&self.offsets) {
            b.values(q, t, &mut phi[r0..r0 + b.rows()]);
        }
    }

    /// Potential energy; adds `∇V` into `grad` when given.
    pub fn potential(&self, q: &[f64], grad: Option<&mut [f64]>) -> f64 {
        match grad {
            Some(g) => self.potentials.iter().map(|p| p.energy_and_gradient(q, g)).sum(),
            None => self.potentials.iter().map(|p| p.energy(q)).sum(),
        }
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
