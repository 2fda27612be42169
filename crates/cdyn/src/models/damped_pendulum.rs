//! The rigid pendulum with a rotary damper.

use super::parts::{dir, example, perp, rigid_body};
use super::{Example, Reference};
use crate::error::{Result, finite, non_negative, positive};
use crate::planar::{BodyId, Element, Mechanism};
use crate::reference::PendulumExact;
use crate::reference::fine_ode::FineOde;

/// A rigid pendulum pinned at one end, with a rotary damper (torque
/// `−c ω`) between it and the ground. The angle of the pivot→centre line is
/// counter-clockwise from +X, as in [`super::PendulumParams`].
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields, default))]
#[non_exhaustive]
pub struct DampedPendulumParams {
    /// Mass of the bar.
    pub mass: f64,
    /// Moment of inertia about the centre of mass.
    pub inertia: f64,
    /// Distance from the pivot to the centre of mass.
    pub length: f64,
    /// Gravitational acceleration, along −Y.
    pub gravity: f64,
    /// Rotary damping coefficient `c ≥ 0`.
    pub damping: f64,
    /// Initial angle from +X.
    pub theta0: f64,
    /// Initial angular velocity.
    pub omega0: f64,
}

crate::setters!(DampedPendulumParams {
    /// With `mass`: mass of the bar.
    with_mass => mass: f64,
    /// With `inertia`: moment of inertia about the centre of mass.
    with_inertia => inertia: f64,
    /// With `length`: distance from the pivot to the centre of mass.
    with_length => length: f64,
    /// With `gravity`: gravitational acceleration, along −Y.
    with_gravity => gravity: f64,
    /// With `damping`: rotary damping coefficient `c ≥ 0`.
    with_damping => damping: f64,
    /// With `theta0`: initial angle from +X.
    with_theta0 => theta0: f64,
    /// With `omega0`: initial angular velocity.
    with_omega0 => omega0: f64,
});

impl Default for DampedPendulumParams {
    /// A uniform 1 kg, 1 m bar pinned at one end (`l_c = 0.5`, `I = 1/12`),
    /// `c = 0.1`, released at rest from the horizontal: the energy decays
    /// roughly as `e^{−(c/I_pivot) t} = e^{−0.3 t}`.
    fn default() -> Self {
        Self { mass: 1.0, inertia: 1.0 / 12.0, length: 0.5, gravity: 9.81, damping: 0.1, theta0: 0.0, omega0: 0.0 }
    }
}

impl DampedPendulumParams {
    fn validate(&self) -> Result<()> {
        positive("mass", self.mass)?;
        positive("inertia", self.inertia)?;
        positive("length", self.length)?;
        non_negative("gravity", self.gravity)?;
        non_negative("damping", self.damping)?;
        finite("theta0", self.theta0)?;
        finite("omega0", self.omega0)?;
        Ok(())
    }

    /// Moment of inertia about the pivot.
    pub fn pivot_inertia(&self) -> f64 {
        self.inertia + self.mass * self.length * self.length
    }
}

/// The damped pendulum, coordinates `bar.(x, y, angle)`.
///
/// Observables: `theta` (the body angle, continuous), `omega`, then the
/// coordinates. Reference: `I_pivot θ̈ = −m g l_c cos θ − c θ̇` — for `c = 0`
/// the exact pendulum, otherwise a fine RK-4 (error about 1e-13).
pub fn damped_pendulum(p: DampedPendulumParams) -> Result<Example> {
    p.validate()?;
    let (lc, th0, om0) = (p.length, p.theta0, p.omega0);
    let state = move |theta: f64, omega: f64, q: &mut [f64], v: &mut [f64]| {
        let (c, n) = (dir(theta), perp(theta));
        q[..3].copy_from_slice(&[lc * c[0], lc * c[1], theta]);
        v[..3].copy_from_slice(&[lc * omega * n[0], lc * omega * n[1], omega]);
    };
    let (mut q0, mut v0) = ([0.0; 3], [0.0; 3]);
    state(th0, om0, &mut q0, &mut v0);
    let mut m = Mechanism::new([0.0, -p.gravity]);
    let bar = m.push(rigid_body("bar", p.mass, p.inertia, [q0[0], q0[1]], q0[2], [v0[0], v0[1]], v0[2]));
    m.add(Element::Revolute { a: BodyId::Ground, pa: [0.0, 0.0], b: bar, pb: [-lc, 0.0], limit: None });
    m.add(Element::RotaryDamper { a: BodyId::Ground, b: bar, damping: p.damping });
    let built = m.build()?;

    let ip = p.pivot_inertia();
    let w2 = p.mass * p.gravity * lc / ip;
    let cd = p.damping / ip;
    let exact = (cd == 0.0).then(|| PendulumExact::new(w2, th0, om0).ok()).flatten();
    let reference: Reference = match exact {
        Some(e) => Box::new(move |t, q, v| {
            let (th, om) = e.angle(t);
            state(th, om, q, v);
        }),
        None => {
            let scale = (om0 * om0 + 4.0 * w2).sqrt() + cd + 1e-3;
            let ode = FineOde::new(1e-3 / scale, [th0, om0], move |_t, [th, w]| [w, -w2 * th.cos() - cd * w]);
            Box::new(move |t, q, v| {
                let [th, om] = ode.at(t);
                state(th, om, q, v);
            })
        }
    };
    Ok(example(
        built,
        &["theta", "omega"],
        |q, v, out| {
            out[0] = q[2];
            out[1] = v[2];
        },
        Some(reference),
    ))
}
