//! Small systems whose size is known at compile time: `N` coordinates and
//! `M` constraint rows written as one function each, simulated in
//! fixed-size arrays.
//!
//! A general [`Model`] reads its elements through dynamic dispatch and its
//! buffers through run-time lengths. That costs a few nanoseconds per call
//! — nothing for a chain of a thousand bodies, most of the step for a
//! pendulum. Here every call is resolved and every length known at compile
//! time, so a step compiles to about what one would write by hand. The
//! physics, the control laws and the integrator are the general ones; only
//! the storage differs. [`to_model`] turns the same system into a general
//! model, and the tests hold both to the same trajectories.
//!
//! - here: [`SmallSystem`], the system as the user writes it, and
//!   [`to_model`];
//! - `dynamics`: its evaluation of the dynamics in arrays (`ArrayDynamics`,
//!   which a general model of a few coordinates is also stepped through);
//! - `controlled`: the system with a control law, stepped as a
//!   [`SmallSimulation`].
//!
//! May import: `error`, `ad`, `linalg`, `model`, `dynamics`, `integrate`,
//! `control`, `simulate`.

mod controlled;
mod dynamics;

pub use controlled::{SmallControlled, SmallSimulation, SmallState};

use crate::ad::scalar::Scalar;
use crate::error::Result;
use crate::model::Model;
use crate::model::constraint::Constraint;
use crate::model::force::{Force, Potential};
use std::sync::Arc;

/// A whole system of `N` coordinates with a constant diagonal mass matrix
/// and `M` holonomic constraints, written once for every scalar type.
pub trait SmallSystem<const N: usize, const M: usize>: Send + Sync + 'static {
    /// The diagonal of the mass matrix.
    fn mass(&self) -> [f64; N];
    /// `Φ(q, t)`.
    fn constraints<D: Scalar>(&self, q: [D; N], t: D) -> [D; M];
    /// The potential energy `V(q)`; none unless given.
    fn potential<D: Scalar>(&self, q: [D; N]) -> D {
        let _ = q;
        D::from(0.0)
    }
    /// The non-conservative generalized force; none unless given.
    fn force<D: Scalar>(&self, q: [D; N], v: [D; N], t: D) -> [D; N] {
        let _ = (q, v, t);
        [D::from(0.0); N]
    }
}

/// A small system seen as one constraint, potential and force element.
struct Whole<S, const N: usize, const M: usize>(Arc<S>);

impl<S: SmallSystem<N, M>, const N: usize, const M: usize> Constraint<N, M> for Whole<S, N, M> {
    #[inline(always)]
    fn eval<D: Scalar>(&self, q: [D; N], t: D) -> [D; M] {
        self.0.constraints(q, t)
    }
}

impl<S: SmallSystem<N, M>, const N: usize, const M: usize> Potential<N> for Whole<S, N, M> {
    #[inline(always)]
    fn energy<D: Scalar>(&self, q: [D; N]) -> D {
        self.0.potential(q)
    }
}

impl<S: SmallSystem<N, M>, const N: usize, const M: usize> Force<N> for Whole<S, N, M> {
    #[inline(always)]
    fn force<D: Scalar>(&self, q: [D; N], v: [D; N], t: D) -> [D; N] {
        self.0.force(q, v, t)
    }
}

/// The same system as a general [`Model`], one element of each kind over all coordinates.
pub fn to_model<S: SmallSystem<N, M>, const N: usize, const M: usize>(system: S) -> Result<Model> {
    let system = Arc::new(system);
    let all: [usize; N] = std::array::from_fn(|i| i);
    let mut builder = Model::builder(system.mass().to_vec());
    if M > 0 {
        builder = builder.constrain(Whole::<S, N, M>(system.clone()), all);
    }
    builder.potential(Whole::<S, N, M>(system.clone()), all).force(Whole::<S, N, M>(system), all).build()
}
