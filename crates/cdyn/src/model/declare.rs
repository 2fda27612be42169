//! Declarations on a built model: the momenta, angular momenta and first
//! integrals a user says it keeps (as the builder's
//! [`momentum`](crate::model::ModelBuilder::momentum),
//! [`angular_momentum`](crate::model::ModelBuilder::angular_momentum) and
//! [`invariant`](crate::model::ModelBuilder::invariant) do before it is built).

use crate::error::{Part, Problem, Result};
use crate::model::Model;
use crate::model::angular::Generator;
use crate::model::definition::checked_direction;
use crate::model::invariant::{Declared, Invariant};

impl Model {
    /// Declares, on a built model, that it keeps the momentum along
    /// `direction` (as [`ModelBuilder::momentum`](crate::model::ModelBuilder::momentum)).
    pub fn declare_momentum(&mut self, name: &str, direction: &[(usize, f64)]) -> Result<()> {
        self.momenta.push(checked_direction(name, direction, true, self.n())?);
        Ok(())
    }

    /// Declares, on a built model, that it keeps the momentum of the
    /// rotation `generator` (as [`ModelBuilder::angular_momentum`](crate::model::ModelBuilder::angular_momentum)).
    pub fn declare_angular_momentum(&mut self, generator: Generator) -> Result<()> {
        generator
            .check(self.n())
            .map_err(|reason| Problem::Rotation(reason).at(Part::Block { what: "an angular momentum" }))?;
        self.rotations.push(Generator { declared: true, ..generator });
        Ok(())
    }

    /// Declares, on a built model, that it keeps `I(q, v)` of the
    /// coordinates `at` (as [`ModelBuilder::invariant`](crate::model::ModelBuilder::invariant)).
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
}
