//! What a system is: coordinates with a mass matrix (see [`crate::mass`]
//! for why it is constant and diagonal), holonomic constraint elements,
//! potentials and non-conservative forces.

use crate::constraint::{Constraint, ConstraintBlock, ConstraintGroup, ConstraintValues};
use crate::error::{Error, Part, Problem, Result};
use crate::force::{Force, ForceBlock, ForceGroup, Potential, PotentialBlock, PotentialGroup};
use crate::mass::{DiagonalMass, MassMatrix};
use crate::nonholonomic::{Nonholonomic, NonholonomicGroup};
/// The sparsity of `Φ_q`, as [`Model::pattern`] returns it (defined with the
/// other sparse structures in `sparse.rs`).
pub use crate::sparse::Pattern;

/// A constrained mechanical system, ready to simulate.
pub struct Model {
    mass: DiagonalMass,
    constraints: Vec<Box<dyn ConstraintBlock>>,
    potentials: Vec<Box<dyn PotentialBlock>>,
    forces: Vec<Box<dyn ForceBlock>>,
    pattern: Pattern,
    /// First row and first Jacobian entry of each constraint block.
    offsets: Vec<(usize, usize)>,
}

/// Builds a [`Model`] element by element.
pub struct ModelBuilder {
    mass: Vec<f64>,
    constraints: Vec<Box<dyn ConstraintBlock>>,
    potentials: Vec<Box<dyn PotentialBlock>>,
    forces: Vec<Box<dyn ForceBlock>>,
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

    /// Adds `R` nonholonomic rows `A(q, t) v + b(q, t) = 0` reading the
    /// coordinates `at` (see [`crate::nonholonomic`] for how every part of
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
        let mut pattern = Pattern { start: vec![0], cols: Vec::with_capacity(nnz) };
        let mut offsets = Vec::with_capacity(self.constraints.len());
        for b in &self.constraints {
            offsets.push((pattern.start.len() - 1, pattern.cols.len()));
            b.columns(&mut pattern.cols);
            for _ in 0..b.rows() {
                let last = *pattern.start.last().unwrap();
                pattern.start.push(last + b.width() as u32);
            }
        }
        let mass = DiagonalMass::new(self.mass)?;
        check_rows(pattern.start.len() - 1, n)?;
        Ok(Model {
            mass,
            constraints: self.constraints,
            potentials: self.potentials,
            forces: self.forces,
            pattern,
            offsets,
        })
    }
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
        ModelBuilder { mass, constraints: Vec::new(), potentials: Vec::new(), forces: Vec::new(), error: None }
    }

    /// Number of coordinates `n`.
    pub fn n(&self) -> usize {
        self.mass.n()
    }
    /// Number of constraint rows `m`.
    pub fn m(&self) -> usize {
        self.pattern.start.len() - 1
    }
    /// The mass matrix `M`.
    pub fn mass(&self) -> &DiagonalMass {
        &self.mass
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

    /// Kinetic energy `½ vᵀ M v`.
    pub fn kinetic(&self, v: &[f64]) -> f64 {
        self.mass.kinetic(v)
    }
}
