//! The double pendulum: two point masses on massless rods, chaotic in
//! general; in Cartesian coordinates (constant mass, two distance
//! constraints) and in its two angles (kinetic energy `T(θ, θ̇)`, `M(θ)`
//! by automatic differentiation, no constraints).

use std::f64::consts::FRAC_PI_2;

use super::Example;
use super::parts::{add, dir, example, hanging, point_body};
use crate::error::{Result, finite, non_negative, positive};
use crate::model::kinetic::Kinetic;
use crate::planar::{BodyId, Element, Mechanism};
use crate::{Model, Potential, Scalar};

/// A double pendulum: two point masses on massless rods, the first rod
/// pinned at the origin. Angles are counter-clockwise from the downward
/// vertical; `theta2` is the second rod's absolute angle.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields, default))]
#[non_exhaustive]
pub struct DoublePendulumParams {
    /// Mass of the first bob.
    pub m1: f64,
    /// Mass of the second bob.
    pub m2: f64,
    /// Length of the first rod (pivot to first bob).
    pub l1: f64,
    /// Length of the second rod (first bob to second).
    pub l2: f64,
    /// Gravitational acceleration, along −Y.
    pub gravity: f64,
    /// Initial angle of the first rod from the downward vertical.
    pub theta1: f64,
    /// Initial angle of the second rod from the downward vertical.
    pub theta2: f64,
    /// Initial angular velocity of the first rod.
    pub omega1: f64,
    /// Initial angular velocity of the second rod.
    pub omega2: f64,
}

crate::setters!(DoublePendulumParams {
    /// With `m1`: mass of the first bob.
    with_m1 => m1: f64,
    /// With `m2`: mass of the second bob.
    with_m2 => m2: f64,
    /// With `l1`: length of the first rod (pivot to first bob).
    with_l1 => l1: f64,
    /// With `l2`: length of the second rod (first bob to second).
    with_l2 => l2: f64,
    /// With `gravity`: gravitational acceleration, along −Y.
    with_gravity => gravity: f64,
    /// With `theta1`: initial angle of the first rod from the downward vertical.
    with_theta1 => theta1: f64,
    /// With `theta2`: initial angle of the second rod from the downward vertical.
    with_theta2 => theta2: f64,
    /// With `omega1`: initial angular velocity of the first rod.
    with_omega1 => omega1: f64,
    /// With `omega2`: initial angular velocity of the second rod.
    with_omega2 => omega2: f64,
});

impl Default for DoublePendulumParams {
    /// Unit masses and rods, both released at rest from the horizontal: the
    /// classic chaotic demonstration.
    fn default() -> Self {
        Self {
            m1: 1.0,
            m2: 1.0,
            l1: 1.0,
            l2: 1.0,
            gravity: 9.81,
            theta1: FRAC_PI_2,
            theta2: FRAC_PI_2,
            omega1: 0.0,
            omega2: 0.0,
        }
    }
}

impl DoublePendulumParams {
    fn validate(&self) -> Result<()> {
        positive("m1", self.m1)?;
        positive("m2", self.m2)?;
        positive("l1", self.l1)?;
        positive("l2", self.l2)?;
        non_negative("gravity", self.gravity)?;
        finite("theta1", self.theta1)?;
        finite("theta2", self.theta2)?;
        finite("omega1", self.omega1)?;
        finite("omega2", self.omega2)?;
        Ok(())
    }
}

/// The double pendulum in Cartesian coordinates
/// `q = (bob1.x, bob1.y, bob2.x, bob2.y)`.
///
/// Observables: `bob2.x`, `bob2.y` (the tip), `theta1`, `theta2` (from the
/// downward vertical, in (−π, π]), then the coordinates. No reference: the
/// motion is chaotic in general.
pub fn double_pendulum(p: DoublePendulumParams) -> Result<Example> {
    p.validate()?;
    let p1 = add([0.0, 0.0], p.l1, hanging(p.theta1));
    let p2 = add(p1, p.l2, hanging(p.theta2));
    let v1 = add([0.0, 0.0], p.l1 * p.omega1, dir(p.theta1));
    let v2 = add(v1, p.l2 * p.omega2, dir(p.theta2));
    let mut m = Mechanism::new([0.0, -p.gravity]);
    let b1 = m.push(point_body("bob1", p.m1, p1, v1));
    let b2 = m.push(point_body("bob2", p.m2, p2, v2));
    m.add(Element::Distance { a: BodyId::Ground, pa: [0.0, 0.0], b: b1, pb: [0.0, 0.0], length: p.l1 });
    m.add(Element::Distance { a: b1, pa: [0.0, 0.0], b: b2, pb: [0.0, 0.0], length: p.l2 });
    let built = m.build()?;
    Ok(example(
        built,
        &["bob2.x", "bob2.y", "theta1", "theta2"],
        |q, _v, out| {
            out[0] = q[2];
            out[1] = q[3];
            out[2] = q[0].atan2(-q[1]);
            out[3] = (q[2] - q[0]).atan2(q[1] - q[3]);
        },
        None,
    ))
}

/// The kinetic energy of the two bobs in the rods' absolute angles from the
/// downward vertical, written through the bobs' Cartesian velocities:
/// `T = ½ m₁|ṗ₁|² + ½ m₂|ṗ₂|²`, `p₁ = l₁(sin θ₁, −cos θ₁)`, `p₂ = p₁ + l₂(sin θ₂, −cos θ₂)`.
/// Its mass matrix is `[[(m₁+m₂)l₁², m₂l₁l₂cos(θ₁−θ₂)], [·, m₂l₂²]]`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DoublePendulumKinetic {
    /// Mass of the first bob.
    pub m1: f64,
    /// Mass of the second bob.
    pub m2: f64,
    /// Length of the first rod.
    pub l1: f64,
    /// Length of the second rod.
    pub l2: f64,
}

impl Kinetic<2> for DoublePendulumKinetic {
    fn energy<D: Scalar>(&self, [t1, t2]: [D; 2], [w1, w2]: [D; 2]) -> D {
        // ṗ = l θ̇ (cos θ, sin θ) for each rod.
        let (v1x, v1y) = (t1.cos() * w1 * self.l1, t1.sin() * w1 * self.l1);
        let (v2x, v2y) = (v1x + t2.cos() * w2 * self.l2, v1y + t2.sin() * w2 * self.l2);
        (v1x * v1x + v1y * v1y) * (0.5 * self.m1) + (v2x * v2x + v2y * v2y) * (0.5 * self.m2)
    }
}

/// Gravity on the two bobs, in the angles: `V = g (m₁ y₁ + m₂ y₂)`.
struct DoublePendulumWeight {
    m1: f64,
    m2: f64,
    l1: f64,
    l2: f64,
    gravity: f64,
}

impl Potential<2> for DoublePendulumWeight {
    fn energy<D: Scalar>(&self, [t1, t2]: [D; 2]) -> D {
        let y1 = -t1.cos() * self.l1;
        let y2 = y1 - t2.cos() * self.l2;
        (y1 * self.m1 + y2 * self.m2) * self.gravity
    }
}

/// The double pendulum in its angles `q = (θ₁, θ₂)` (absolute, from the
/// downward vertical), with the same parameters as [`double_pendulum`]: two
/// coordinates, no constraints, and a configuration-dependent mass matrix
/// from the kinetic energy [`DoublePendulumKinetic`].
///
/// Observables as for [`double_pendulum`]: `bob2.x`, `bob2.y`, `theta1`,
/// `theta2` (in (−π, π]), then the angles as integrated.
pub fn double_pendulum_angles(p: DoublePendulumParams) -> Result<Example> {
    p.validate()?;
    let (m1, m2, l1, l2) = (p.m1, p.m2, p.l1, p.l2);
    let model = Model::builder(vec![0.0, 0.0])
        .kinetic(DoublePendulumKinetic { m1, m2, l1, l2 }, [0, 1])
        .potential(DoublePendulumWeight { m1, m2, l1, l2, gravity: p.gravity }, [0, 1])
        .build()?;
    let wrap = |a: f64| a.sin().atan2(a.cos());
    Ok(Example {
        model,
        q0: vec![p.theta1, p.theta2],
        v0: vec![p.omega1, p.omega2],
        observables: ["bob2.x", "bob2.y", "theta1", "theta2", "q0", "q1"].map(String::from).to_vec(),
        observe: Box::new(move |_t, q, _v, out| {
            let tip = add(add([0.0, 0.0], l1, hanging(q[0])), l2, hanging(q[1]));
            out.copy_from_slice(&[tip[0], tip[1], wrap(q[0]), wrap(q[1]), q[0], q[1]]);
        }),
        reference: None,
        drawing: None,
        sketch: None,
    })
}
