//! The double pendulum: two point masses on massless rods, chaotic in general.

use std::f64::consts::FRAC_PI_2;

use super::Example;
use super::parts::{add, dir, example, hanging, point_body};
use crate::error::{Result, finite, non_negative, positive};
use crate::planar::{BodyId, Element, Mechanism};

/// A double pendulum: two point masses on massless rods, the first rod
/// pinned at the origin. Angles are counter-clockwise from the downward
/// vertical; `theta2` is the second rod's absolute angle.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields, default))]
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
