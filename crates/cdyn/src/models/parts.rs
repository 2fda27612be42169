//! Pieces the built-in planar mechanisms share: parameter checks, plane
//! vectors, body constructors, the load pendulum the driven mechanisms
//! carry, and the assembly of an [`Example`] from a built mechanism.
//!
//! A rigid link is a body whose centre of mass is the link's midpoint and
//! whose own x-axis points along the link, from its first joint to its
//! second; its angle coordinate is the link's angle from +X.

use super::{Example, Observe, Reference};
use crate::error::{Result, finite, non_negative, positive};
use crate::planar::{Body, BodyId, Element, Mechanism};
use crate::reference::fine_ode::FineOde;

/// `(cos a, sin a)`
pub(super) fn dir(a: f64) -> [f64; 2] {
    let (s, c) = a.sin_cos();
    [c, s]
}

/// `(−sin a, cos a)`, the direction rotated a quarter turn counter-clockwise.
pub(super) fn perp(a: f64) -> [f64; 2] {
    let (s, c) = a.sin_cos();
    [-s, c]
}

/// `(sin a, −cos a)`: the unit vector at angle `a` from the downward vertical.
pub(super) fn hanging(a: f64) -> [f64; 2] {
    let (s, c) = a.sin_cos();
    [s, -c]
}

pub(super) fn add(p: [f64; 2], k: f64, d: [f64; 2]) -> [f64; 2] {
    [p[0] + k * d[0], p[1] + k * d[1]]
}

pub(super) fn point_body(name: &str, mass: f64, position: [f64; 2], velocity: [f64; 2]) -> Body {
    Body::point(name, mass, position).with_velocity(velocity)
}

pub(super) fn rigid_body(
    name: &str,
    mass: f64,
    inertia: f64,
    position: [f64; 2],
    angle: f64,
    velocity: [f64; 2],
    angular_velocity: f64,
) -> Body {
    Body::rigid(name, mass, inertia, position, angle).with_velocity(velocity).with_angular_velocity(angular_velocity)
}

/// An example whose observables are `first` (computed by `observe_first`)
/// followed by every coordinate.
pub(super) fn example(
    built: crate::planar::Built,
    first: &[&str],
    observe_first: impl Fn(&[f64], &[f64], &mut [f64]) + Send + Sync + 'static,
    reference: Option<Reference>,
) -> Example {
    let k = first.len();
    let n = built.model.n();
    let mut observables: Vec<String> = first.iter().map(|s| s.to_string()).collect();
    observables.extend(built.names);
    let observe: Observe = Box::new(move |_t, q, v, out| {
        observe_first(q, v, &mut out[..k]);
        out[k..k + n].copy_from_slice(&q[..n]);
    });
    let drawing = Some(built.drawing);
    Example { model: built.model, q0: built.q0, v0: built.v0, observables, observe, reference, drawing, sketch: None }
}

// ---------------------------------------------------------------------------
// Load pendulum (the free degree of freedom of the driven mechanisms)
// ---------------------------------------------------------------------------

/// A point mass on a massless rod hanging from a driven point of a
/// mechanism. The angle is counter-clockwise from the downward vertical.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields, default))]
#[non_exhaustive]
pub struct LoadPendulum {
    /// Mass of the bob.
    pub mass: f64,
    /// Length of the rod.
    pub length: f64,
    /// Initial angle of the rod from the downward vertical.
    pub angle: f64,
    /// Initial angular velocity of the rod.
    pub omega: f64,
}

crate::setters!(LoadPendulum {
    /// With `mass`: mass of the bob.
    with_mass => mass: f64,
    /// With `length`: length of the rod.
    with_length => length: f64,
    /// With `angle`: initial angle of the rod from the downward vertical.
    with_angle => angle: f64,
    /// With `omega`: initial angular velocity of the rod.
    with_omega => omega: f64,
});

impl Default for LoadPendulum {
    /// Half a kilogram on a 1 m rod, released at rest 0.2 rad from the bottom.
    fn default() -> Self {
        Self { mass: 0.5, length: 1.0, angle: 0.2, omega: 0.0 }
    }
}

impl LoadPendulum {
    pub(super) fn validate(&self) -> Result<()> {
        positive("load mass", self.mass)?;
        positive("load length", self.length)?;
        finite("load angle", self.angle)?;
        finite("load omega", self.omega)?;
        Ok(())
    }

    /// Adds the bob hanging from `point` (local) of `support`, whose world
    /// position and velocity are `s`, `sd`.
    pub(super) fn attach(&self, m: &mut Mechanism, support: BodyId, point: [f64; 2], s: [f64; 2], sd: [f64; 2]) {
        let bob = m.push(point_body(
            "load",
            self.mass,
            add(s, self.length, hanging(self.angle)),
            add(sd, self.length * self.omega, dir(self.angle)),
        ));
        m.add(Element::Distance { a: support, pa: point, b: bob, pb: [0.0, 0.0], length: self.length });
    }

    /// The load's angle `φ(t)` and rate, for a support moving with
    /// acceleration `acc(t)`: `L φ̈ = −g sin φ − a_x cos φ − a_y sin φ`
    /// (the tangential component of `m p̈ = m g + tension`), by fine RK-4.
    pub(super) fn motion(
        &self,
        gravity: f64,
        rate: f64,
        acc: impl Fn(f64) -> [f64; 2] + Send + Sync + 'static,
        horizon_acc: f64,
    ) -> FineOde<2> {
        let l = self.length;
        let scale = self.omega.abs() + ((gravity + horizon_acc) / l).sqrt() + 4.0 * rate.abs() + 1e-3;
        FineOde::new(1e-3 / scale, [self.angle, self.omega], move |t, [phi, w]| {
            let [ax, ay] = acc(t);
            let (s, c) = phi.sin_cos();
            [w, -(gravity * s + ax * c + ay * s) / l]
        })
    }
}

/// Writes the load's `(q, v)` at `at` given the support's position and velocity.
pub(super) fn load_state(
    load: &LoadPendulum,
    phi: [f64; 2],
    s: [f64; 2],
    sd: [f64; 2],
    at: usize,
    q: &mut [f64],
    v: &mut [f64],
) {
    let p = add(s, load.length, hanging(phi[0]));
    let pv = add(sd, load.length * phi[1], dir(phi[0]));
    q[at..at + 2].copy_from_slice(&p);
    v[at..at + 2].copy_from_slice(&pv);
}

/// Largest magnitude of `acc` over `[0, period]` (64 samples), to size the
/// reference step.
pub(super) fn max_acc(acc: impl Fn(f64) -> [f64; 2], period: f64) -> f64 {
    (0..64)
        .map(|i| {
            let [x, y] = acc(period * f64::from(i) / 64.0);
            x.hypot(y)
        })
        .fold(0.0, f64::max)
}

/// Checks shared by the crank-driven mechanisms: drive speed, initial
/// crank angle, gravity and the optional load pendulum.
pub(super) fn validate_drive(omega: f64, theta0: f64, gravity: f64, load: Option<&LoadPendulum>) -> Result<()> {
    finite("omega", omega)?;
    finite("theta0", theta0)?;
    non_negative("gravity", gravity)?;
    load.map_or(Ok(()), LoadPendulum::validate)
}

/// Test helpers the models' unit tests share.
#[cfg(test)]
pub(super) mod testing {
    /// Asserts `|a − b| ≤ tol`.
    pub(crate) fn close(a: f64, b: f64, tol: f64, what: &str) {
        assert!((a - b).abs() <= tol, "{what}: {a} vs {b} (diff {:e})", a - b);
    }

    /// Central differences of `f` at `t`.
    pub(crate) fn diff(f: impl Fn(f64) -> f64, t: f64) -> f64 {
        let h = 1e-5;
        (f(t + h) - f(t - h)) / (2.0 * h)
    }
}
