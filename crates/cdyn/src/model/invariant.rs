//! First integrals a user declares: a scalar `I(q, v)` of a few
//! coordinates that the model keeps, written once generic over the scalar
//! like a constraint; its gradients `∂I/∂q` and `∂I/∂v` come from
//! automatic differentiation. A run checks that the uncontrolled motion
//! keeps it (`dI/dt = ∂I/∂q·v + ∂I/∂v·v̇ = 0` at sample states,
//! [`crate::dynamics::momentum::detect`]), reports it when it does not, and holds it
//! beside the energy and the angular momenta where the control does
//! ([`crate::control::held`]).

use crate::ad::scalar::Scalar;
use crate::model::constraint::seeded;
use num_dual::Dual64;

/// A first integral `I(x, ẋ)` of `K` coordinates.
pub trait Invariant<const K: usize>: Send + Sync + 'static {
    /// `I(x, ẋ)`, for any scalar type (dual numbers give its gradients).
    fn value<D: Scalar>(&self, x: [D; K], xd: [D; K]) -> D;
}

/// A declared invariant on the model's coordinates, type-erased.
pub(crate) trait InvariantBlock: Send + Sync {
    fn value(&self, q: &[f64], v: &[f64]) -> f64;
    /// `I`, with `∂I/∂q` and `∂I/∂v` added into `grad_q` and `grad_v`.
    fn gradients(&self, q: &[f64], v: &[f64], grad_q: &mut [f64], grad_v: &mut [f64]) -> f64;
}

struct Placed<I, const K: usize> {
    invariant: I,
    at: [usize; K],
}

impl<I: Invariant<K>, const K: usize> InvariantBlock for Placed<I, K> {
    fn value(&self, q: &[f64], v: &[f64]) -> f64 {
        self.invariant.value(self.at.map(|i| q[i]), self.at.map(|i| v[i]))
    }

    fn gradients(&self, q: &[f64], v: &[f64], grad_q: &mut [f64], grad_v: &mut [f64]) -> f64 {
        let (x, xd) = (self.at.map(|i| q[i]), self.at.map(|i| v[i]));
        let plain = |x: [f64; K]| x.map(Dual64::from);
        let mut value = self.invariant.value(x, xd);
        for j in 0..K {
            let along_x = self.invariant.value(seeded(&x, j), plain(xd));
            let along_v = self.invariant.value(plain(x), seeded(&xd, j));
            grad_q[self.at[j]] += along_x.eps;
            grad_v[self.at[j]] += along_v.eps;
            value = along_x.re;
        }
        value
    }
}

/// An invariant declared on a model ([`ModelBuilder::invariant`](crate::model::ModelBuilder::invariant)).
pub struct Declared {
    /// What it is called in the output.
    pub name: String,
    pub(crate) block: Box<dyn InvariantBlock>,
}

impl Declared {
    pub(crate) fn new<I: Invariant<K>, const K: usize>(name: &str, invariant: I, at: [usize; K]) -> Self {
        Self { name: name.to_string(), block: Box::new(Placed { invariant, at }) }
    }

    /// `I(q, v)` on the model's coordinates.
    pub fn value(&self, q: &[f64], v: &[f64]) -> f64 {
        self.block.value(q, v)
    }
}

impl std::fmt::Debug for Declared {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Declared").field("name", &self.name).finish_non_exhaustive()
    }
}
