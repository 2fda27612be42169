//! Building a [`Model`] element by element: each element's type, its
//! coordinates and its rows, checked as they are added, then laid out once
//! (the pattern of `Φ_q`, the blocks of `M(q)`).

use crate::error::{Error, Part, Problem, Result};
use crate::linalg::mass::{DiagonalMass, MAX_BLOCK};
use crate::model::angular::Generator;
use crate::model::constraint::{Constraint, ConstraintBlock, ConstraintGroup};
use crate::model::force::{Force, ForceBlock, ForceGroup, Potential, PotentialBlock, PotentialGroup};
use crate::model::input::{Input, Inputs};
use crate::model::invariant::{Declared, Invariant};
use crate::model::kinetic::{ByMap, Kinetic, KineticBlock, KineticElement, KineticGroup, VelocityMap};
use crate::model::nonholonomic::{Nonholonomic, NonholonomicGroup};
use crate::model::unit_vector::{UnitNorm, UnitVector};

use crate::linalg::sparse::Pattern;
/// The sparsity of `Φ_q`, as [`Model::pattern`] returns it (defined with the
/// other sparse structures in `sparse.rs`).
use crate::model::definition::{BlockSpan, Direction, Inertia, Model, check_rows, checked_direction};

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
            inputs: Inputs::default(),
            error: None,
        }
    }
}

/// Builds a [`Model`] element by element.
///
/// Each element names the coordinates it reads; its derivatives come by
/// automatic differentiation. A spring `V = ½ k x²` on the first of two
/// coordinates:
///
/// ```
/// use cdyn::{Model, Potential, Scalar};
///
/// struct Spring(f64);
/// impl Potential<1> for Spring {
///     fn energy<D: Scalar>(&self, [x]: [D; 1]) -> D {
///         x * x * (0.5 * self.0)
///     }
/// }
///
/// let model = Model::builder(vec![1.0, 1.0])
///     .potential(Spring(4.0), [0])
///     .coordinate_names(vec!["x".into(), "y".into()])
///     .build()?;
/// let mut grad = [0.0; 2];
/// assert_eq!(model.potential(&[0.5, 3.0], Some(&mut grad)), 0.5);
/// assert_eq!(grad, [2.0, 0.0]); // ∇V = (k x, 0)
/// # Ok::<(), cdyn::Error>(())
/// ```
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
    inputs: Inputs,
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

    /// Declares `input` (made with [`Input::new`], a name and a start
    /// value) as one of the model's inputs, which a simulation sets by
    /// name or position; the elements that read it hold clones of it. A
    /// name declared twice or a start that is not finite fails the build.
    pub fn input(mut self, input: &Input) -> Self {
        if self.error.is_none()
            && let Err(e) = self.inputs.declare(input.clone())
        {
            self.error = Some(e);
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

    /// A kinetic energy and a potential given whole, in closed form, over
    /// the first coordinates (a tree of bodies in joint coordinates).
    pub(crate) fn whole(mut self, kinetic: Box<dyn KineticBlock>, potential: Option<Box<dyn PotentialBlock>>) -> Self {
        self.kinetic.push(kinetic);
        self.potentials.extend(potential);
        self
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

    /// Force elements added so far (the order [`Model::most_dissipating`] counts them in).
    pub fn force_elements(&self) -> usize {
        self.forces.iter().map(|b| b.elements().0).sum()
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
            let (r0, j0) = (pattern.start.len() - 1, pattern.cols.len());
            offsets.push(BlockSpan { rows: (r0, r0 + b.rows()), entries: (j0, j0 + b.rows() * b.width()) });
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
            inputs: self.inputs,
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
