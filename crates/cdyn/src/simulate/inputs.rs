//! Setting a simulation's inputs between steps ([`crate::model::input`]):
//! by position or name, checked, with the energy balance and the scheme's
//! history kept right.
//!
//! - **Energy.** `Ψ = T + V − E₀ − ∫Ė` is held at zero. An input in a
//!   force does work `F·v` that `Ė` already counts. An input in a potential
//!   (a spring's rest length) makes `V` jump at fixed `q`: `∫Ė` is moved by
//!   the same jump, so that `Ψ` is unchanged and no energy law fights the
//!   change.
//! - **Constraints.** An input in a constraint (a drive's target, held
//!   piecewise constant: `Φ_t = 0` between changes) would make `Φ` jump.
//!   The jump is applied at once instead: `(q, v)` are projected onto the
//!   constraints at the new value (Newton, minimum correction in the
//!   kinetic-energy metric, as the initial state is assembled) and `∫Ė`
//!   moves by the change of `T + V`, the work of the drive. Left to the
//!   stabilization, the jump would be removed over a few steps by the
//!   geometric law, and the energy it took would stay in `Ψ` for the energy
//!   law to fight (`tests/inputs.rs` shows both). A target that cannot be
//!   reached is an error.
//! - **History.** Past evaluations were made with the old value, so the
//!   scheme starts again from the current state: AB-3 and ABM-4 take their
//!   RK-4 start-up steps again, RATTLE evaluates again, generalized-α takes
//!   its accelerations from the new forces. Kept, the multistep history
//!   would extrapolate the old forces across the jump, an error of order
//!   `h Δu` in each step after a change instead of the start-up's `h⁵`
//!   (`tests/inputs.rs` measures both against a fine reference).
//!   A value set equal to the current one changes nothing.

use crate::error::{Error, Result};
use crate::simulate::Simulation;

impl Simulation<'_> {
    /// Sets input `index` (declaration order, [`Model::inputs`](crate::Model::inputs))
    /// to `value`, which must be finite. Takes effect from the next step.
    pub fn set_input(&mut self, index: usize, value: f64) -> Result<()> {
        let model = self.model();
        let input = model.inputs().at(index)?;
        if !value.is_finite() {
            return Err(Error::Input { name: input.name().into(), reason: format!("{value}: must be finite") });
        }
        if input.value().to_bits() == value.to_bits() {
            return Ok(());
        }
        let name = input.name();
        self.change_input(|| input.set(value)).map_err(|failure| Error::Input {
            name: name.into(),
            reason: format!("{value}: the constraints cannot be met at this value ({failure:?})"),
        })
    }

    /// Sets the input called `name` (see [`set_input`](Self::set_input)).
    pub fn set_input_named(&mut self, name: &str, value: f64) -> Result<()> {
        let index = self.model().inputs().named(name)?;
        self.set_input(index, value)
    }

    /// The current value of input `index`.
    pub fn input(&self, index: usize) -> Result<f64> {
        self.model().inputs().at(index).map(|u| u.value())
    }
}
