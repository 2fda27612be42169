//! Built-in systems, each with its initial state and, where one exists,
//! its reference solution. Tests, benchmarks and the command line share them.

pub mod andrews;
mod mechanisms;
mod pendulum;

pub use andrews::andrews;
pub use mechanisms::*;
pub use pendulum::{PendulumParams, SmallPendulum, cartesian_pendulum, small_pendulum, theta_pendulum};

/// `(q, v)` of the exact solution at time `t`, in the model's coordinates.
pub type Reference = Box<dyn Fn(f64, &mut [f64], &mut [f64]) + Send + Sync>;

/// Maps a state `(q, v)` to named observable quantities.
pub type Observe = Box<dyn Fn(&[f64], &[f64], &mut [f64]) + Send + Sync>;

/// A built-in system ready to simulate.
pub struct Example {
    pub model: crate::Model,
    pub q0: Vec<f64>,
    pub v0: Vec<f64>,
    /// Names of the observables, e.g. `X, Y, VX, VY`; errors against the
    /// reference are reported for the first of them.
    pub observables: Vec<String>,
    pub observe: Observe,
    pub reference: Option<Reference>,
}

impl Example {
    /// A mechanism as an example whose observables are its coordinates.
    pub fn from_mechanism(built: crate::planar::Built, reference: Option<Reference>) -> Self {
        let n = built.model.n();
        Example {
            model: built.model,
            q0: built.q0,
            v0: built.v0,
            observables: built.names,
            observe: Box::new(move |q, _v, out| out.copy_from_slice(&q[..n])),
            reference,
        }
    }

    /// The observables of the state `(q, v)`.
    pub fn observe(&self, q: &[f64], v: &[f64]) -> Vec<f64> {
        let mut out = vec![0.0; self.observables.len()];
        (self.observe)(q, v, &mut out);
        out
    }

    /// Error of the first observable against the reference at time `t`.
    pub fn error(&self, q: &[f64], v: &[f64], t: f64) -> Option<f64> {
        let reference = self.reference.as_ref()?;
        let n = self.model.n();
        let (mut qr, mut vr) = (vec![0.0; n], vec![0.0; n]);
        reference(t, &mut qr, &mut vr);
        Some(self.observe(q, v)[0] - self.observe(&qr, &vr)[0])
    }
}
