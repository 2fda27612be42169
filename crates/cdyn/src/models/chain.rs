//! The N-link pendulum chain, with a reference for rigid rotation and for one link.

use std::f64::consts::FRAC_PI_2;

use super::parts::{dir, example, hanging, point_body};
use super::{Example, PendulumParams, Reference};
use crate::error::{Error, Result};
use crate::planar::{BodyId, Element, Mechanism};
use crate::reference::PendulumExact;

/// An N-link pendulum chain: N equal point masses joined by equal massless
/// rods, the first rod pinned at the origin. It starts straight, at angle
/// `theta0` from the downward vertical, rotating rigidly at `omega0` about
/// the pivot (`v_i = ω × r_i`; at rest when `omega0 = 0`).
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields, default))]
#[non_exhaustive]
pub struct ChainParams {
    /// Number of links (and of masses), from 1 to 1 000 000.
    #[cfg_attr(feature = "serde", serde(deserialize_with = "whole_number"))]
    pub n: usize,
    /// Mass of each point mass.
    pub mass: f64,
    /// Length of each link.
    pub length: f64,
    /// Gravitational acceleration, along −Y.
    pub gravity: f64,
    /// Angle of the straight chain from the downward vertical.
    pub theta0: f64,
    /// Initial rigid angular velocity about the pivot.
    pub omega0: f64,
}

crate::setters!(ChainParams {
    /// With `n`: number of links (and of masses), from 1 to 1 000 000.
    with_n => n: usize,
    /// With `mass`: mass of each point mass.
    with_mass => mass: f64,
    /// With `length`: length of each link.
    with_length => length: f64,
    /// With `gravity`: gravitational acceleration, along −Y.
    with_gravity => gravity: f64,
    /// With `theta0`: angle of the straight chain from the downward vertical.
    with_theta0 => theta0: f64,
    /// With `omega0`: initial rigid angular velocity about the pivot.
    with_omega0 => omega0: f64,
});

impl Default for ChainParams {
    /// Five unit links released at rest from the horizontal.
    fn default() -> Self {
        Self { n: 5, mass: 1.0, length: 1.0, gravity: 9.81, theta0: FRAC_PI_2, omega0: 0.0 }
    }
}

impl ChainParams {
    fn validate(&self) -> Result<()> {
        if self.n == 0 {
            return Err(Error::InvalidParameter { name: "n", value: 0.0, reason: "a chain needs at least one link" });
        }
        // A bound well above any chain worth simulating, so that a slip of the
        // keyboard is refused instead of exhausting the memory.
        if self.n > MAX_LINKS {
            return Err(Error::InvalidParameter {
                name: "n",
                value: self.n as f64,
                reason: "a chain has at most 1000000 links",
            });
        }
        // Each link is the paper's pendulum, with its parameters' domains.
        let (mass, length, gravity, theta0, omega0) = (self.mass, self.length, self.gravity, self.theta0, self.omega0);
        PendulumParams { mass, length, gravity, theta0, omega0 }.validate()
    }
}

/// The most links [`chain`] accepts.
const MAX_LINKS: usize = 1_000_000;

/// The number of links as scenario files write it: an integer, or a number
/// without a fractional part (`n = 20.0` has always been accepted).
#[cfg(feature = "serde")]
fn whole_number<'de, D: serde::Deserializer<'de>>(deserializer: D) -> Result<usize, D::Error> {
    use serde::Deserialize;
    use serde::de::{Error as _, Unexpected};
    let x = f64::deserialize(deserializer)?;
    if x.fract() == 0.0 && (0.0..=usize::MAX as f64).contains(&x) {
        Ok(x as usize)
    } else {
        Err(D::Error::invalid_value(Unexpected::Float(x), &"a whole number of links"))
    }
}

/// `(q, v)` of a straight chain at angle `theta` (from the downward
/// vertical) rotating rigidly at `omega`.
fn straight_chain(n: usize, length: f64, theta: f64, omega: f64, q: &mut [f64], v: &mut [f64]) {
    let (r, t) = (hanging(theta), dir(theta));
    for i in 0..n {
        let k = (i + 1) as f64 * length;
        q[2 * i] = k * r[0];
        q[2 * i + 1] = k * r[1];
        v[2 * i] = k * omega * t[0];
        v[2 * i + 1] = k * omega * t[1];
    }
}

/// The chain in Cartesian coordinates `q = (bob1.x, bob1.y, …, bobN.y)`.
///
/// Observables: `tip.x`, `tip.y` (the last mass), then the coordinates.
/// Reference: without gravity the straight chain keeps rotating rigidly,
/// `θ = θ0 + ω0 t` (exact); with gravity and one link it is the exact
/// pendulum ([`PendulumExact`]); otherwise none.
pub fn chain(p: ChainParams) -> Result<Example> {
    p.validate()?;
    let n = p.n;
    let (mut q0, mut v0) = (vec![0.0; 2 * n], vec![0.0; 2 * n]);
    straight_chain(n, p.length, p.theta0, p.omega0, &mut q0, &mut v0);
    let mut m = Mechanism::new([0.0, -p.gravity]);
    let mut prev = BodyId::Ground;
    for i in 0..n {
        let bob = m.push(point_body(
            &format!("bob{}", i + 1),
            p.mass,
            [q0[2 * i], q0[2 * i + 1]],
            [v0[2 * i], v0[2 * i + 1]],
        ));
        m.add(Element::Distance { a: prev, pa: [0.0, 0.0], b: bob, pb: [0.0, 0.0], length: p.length });
        prev = bob;
    }
    let built = m.build()?;
    let reference: Option<Reference> = if p.gravity == 0.0 {
        Some(Box::new(move |t, q, v| {
            straight_chain(n, p.length, p.theta0 + p.omega0 * t, p.omega0, q, v);
        }))
    } else if n == 1 {
        PendulumExact::new(p.gravity / p.length, p.theta0 - FRAC_PI_2, p.omega0).ok().map(|exact| -> Reference {
            Box::new(move |t, q, v| {
                let (theta, omega) = exact.angle(t);
                straight_chain(1, p.length, theta + FRAC_PI_2, omega, q, v);
            })
        })
    } else {
        None
    };
    Ok(example(
        built,
        &["tip.x", "tip.y"],
        move |q, _v, out| {
            out[0] = q[2 * n - 2];
            out[1] = q[2 * n - 1];
        },
        reference,
    ))
}
