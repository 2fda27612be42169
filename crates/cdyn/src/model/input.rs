//! Inputs: named scalars that the world outside a simulation sets between
//! steps — a controller's torque, a drive's target, a spring's rest length —
//! without rebuilding the model.
//!
//! An [`Input`] is a cheap handle (a shared cell holding an `f64`'s bits).
//! The model owns the bank of its inputs ([`Inputs`], declared with
//! [`ModelBuilder::input`](crate::model::ModelBuilder::input)); each element
//! that depends on one holds a clone of its handle and reads its current
//! value as a plain constant while it is evaluated: no derivative is taken
//! with respect to an input, and within one step it does not change.
//! Values are set through [`Simulation::set_input`](crate::Simulation::set_input),
//! which also keeps the energy balance and the multistep history right.
//!
//! The cell is an atomic, so a [`Model`](crate::Model) stays `Send + Sync`;
//! but the value lives in the model: simulations that share one model share
//! its inputs. Give each simulation that is driven on its own a model of its
//! own (the C API and an FMU's instances build one per instance).

use crate::error::{Error, Result};
use std::sync::Arc;
use std::sync::atomic::{AtomicU64, Ordering};

/// A handle on one input: its name, its start value and its current value.
/// Clones share the value.
#[derive(Clone)]
pub struct Input(Arc<Cell>);

struct Cell {
    name: String,
    start: f64,
    bits: AtomicU64,
}

impl Input {
    /// An input called `name` with the value `start` until it is set.
    pub fn new(name: &str, start: f64) -> Self {
        Input(Arc::new(Cell { name: name.to_string(), start, bits: AtomicU64::new(start.to_bits()) }))
    }

    /// Its name.
    pub fn name(&self) -> &str {
        &self.0.name
    }

    /// The value it was declared with.
    pub fn start(&self) -> f64 {
        self.0.start
    }

    /// Its current value.
    #[inline(always)]
    pub fn value(&self) -> f64 {
        // Relaxed: a value is set between steps by the thread that steps.
        f64::from_bits(self.0.bits.load(Ordering::Relaxed))
    }

    /// Sets its value; only a simulation does this (see the module head).
    pub(crate) fn set(&self, value: f64) {
        self.0.bits.store(value.to_bits(), Ordering::Relaxed);
    }
}

impl PartialEq for Input {
    /// The same input (one cell), not merely the same value.
    fn eq(&self, other: &Self) -> bool {
        Arc::ptr_eq(&self.0, &other.0)
    }
}

impl std::fmt::Debug for Input {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "Input({:?} = {})", self.name(), self.value())
    }
}

/// A constant of an element that an input may set instead: a spring's
/// rest length, say. Read as a plain `f64` while the element is evaluated.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub enum Parameter {
    /// This value, always.
    Fixed(f64),
    /// The input's current value.
    Input(Input),
}

impl Parameter {
    /// Its current value.
    #[inline(always)]
    pub fn value(&self) -> f64 {
        match self {
            Parameter::Fixed(x) => *x,
            Parameter::Input(u) => u.value(),
        }
    }
}

impl From<f64> for Parameter {
    fn from(x: f64) -> Self {
        Parameter::Fixed(x)
    }
}

/// The inputs of a model, in the order they were declared.
#[derive(Debug, Clone, Default)]
pub struct Inputs {
    list: Vec<Input>,
}

impl Inputs {
    /// Adds `input`, checked: a name not empty and not declared before, a finite start.
    pub(crate) fn declare(&mut self, input: Input) -> Result<()> {
        let name = input.name();
        let refuse = |reason: String| Err(Error::Input { name: name.to_string(), reason });
        if name.is_empty() {
            return refuse("an input needs a name".into());
        }
        if !input.start().is_finite() {
            return refuse(format!("start = {}: must be finite", input.start()));
        }
        if self.index_of(name).is_some() {
            return refuse("declared twice".into());
        }
        self.list.push(input);
        Ok(())
    }

    /// How many there are.
    pub fn len(&self) -> usize {
        self.list.len()
    }

    /// Whether there are none.
    pub fn is_empty(&self) -> bool {
        self.list.is_empty()
    }

    /// The input at `index`, in declaration order.
    pub fn get(&self, index: usize) -> Option<&Input> {
        self.list.get(index)
    }

    /// All of them, in declaration order.
    pub fn iter(&self) -> impl Iterator<Item = &Input> {
        self.list.iter()
    }

    /// The position of the input called `name`.
    pub fn index_of(&self, name: &str) -> Option<usize> {
        self.list.iter().position(|i| i.name() == name)
    }

    /// The input at `index`, or an error that lists the inputs there are.
    pub fn at(&self, index: usize) -> Result<&Input> {
        self.list.get(index).ok_or_else(|| Error::Input {
            name: format!("#{index}"),
            reason: format!("no such input; {}", self.listing()),
        })
    }

    /// The input called `name`, or an error that lists the inputs there are.
    pub fn named(&self, name: &str) -> Result<usize> {
        self.index_of(name).ok_or_else(|| Error::Input {
            name: name.to_string(),
            reason: format!("no such input; {}", self.listing()),
        })
    }

    /// "the model has the inputs a, b" (or none), for messages.
    fn listing(&self) -> String {
        if self.list.is_empty() {
            return "the model has no inputs".into();
        }
        let names: Vec<&str> = self.list.iter().map(Input::name).collect();
        format!("the model has the inputs {}", names.join(", "))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_handle_shares_its_value_with_its_clones_and_is_equal_to_them_only() {
        let a = Input::new("tau", 1.5);
        let b = a.clone();
        a.set(-2.0);
        assert_eq!((b.value(), b.start()), (-2.0, 1.5));
        assert_eq!(a, b);
        assert_ne!(a, Input::new("tau", 1.5));
    }

    #[test]
    fn declarations_are_checked_and_lookups_name_what_exists() {
        let mut inputs = Inputs::default();
        inputs.declare(Input::new("tau", 0.0)).unwrap();
        let twice = inputs.declare(Input::new("tau", 1.0)).unwrap_err();
        assert_eq!(twice.to_string(), "input \"tau\": declared twice");
        let nan = inputs.declare(Input::new("f", f64::NAN)).unwrap_err();
        assert_eq!(nan.to_string(), "input \"f\": start = NaN: must be finite");
        assert_eq!(inputs.named("tau").unwrap(), 0);
        let unknown = inputs.named("tao").unwrap_err();
        assert_eq!(unknown.to_string(), "input \"tao\": no such input; the model has the inputs tau");
        assert_eq!(inputs.at(3).unwrap_err().to_string(), "input \"#3\": no such input; the model has the inputs tau");
    }
}
