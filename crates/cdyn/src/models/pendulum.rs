//! Example 1 of the paper: a pendulum as a point mass in Cartesian
//! coordinates `(X, Y)` on a rod (Eqs. 60–63), and the same pendulum in the
//! independent angle `θ` (Eq. 68). Gravity acts along −Y; `θ` is measured
//! counter-clockwise from +X.

use super::Example;
use crate::error::{Result, finite, non_negative, positive};
use crate::planar::{Anchor, Drawing, Link, Shape};
use crate::reference::PendulumExact;
use crate::small::SmallSystem;
use crate::{Constraint, Model, Potential, Scalar};

/// Parameters of the pendulum; the default is the paper's Example 1.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields, default))]
#[non_exhaustive]
pub struct PendulumParams {
    /// Mass of the bob.
    pub mass: f64,
    /// Length of the rod.
    pub length: f64,
    /// Gravitational acceleration, along −Y.
    pub gravity: f64,
    /// Initial angle from +X, counter-clockwise.
    pub theta0: f64,
    /// Initial angular velocity.
    pub omega0: f64,
}

crate::setters!(PendulumParams {
    /// With `mass`: mass of the bob.
    with_mass => mass: f64,
    /// With `length`: length of the rod.
    with_length => length: f64,
    /// With `gravity`: gravitational acceleration, along −Y.
    with_gravity => gravity: f64,
    /// With `theta0`: initial angle from +X, counter-clockwise.
    with_theta0 => theta0: f64,
    /// With `omega0`: initial angular velocity.
    with_omega0 => omega0: f64,
});

impl Default for PendulumParams {
    fn default() -> Self {
        // X(0) = 1, Y(0) = 0, V_X(0) = 0, V_Y(0) = 2 (Eq. 63).
        Self { mass: 1.0, length: 1.0, gravity: 1.0, theta0: 0.0, omega0: 2.0 }
    }
}

impl PendulumParams {
    pub(super) fn validate(&self) -> Result<()> {
        positive("mass", self.mass)?;
        positive("length", self.length)?;
        non_negative("gravity", self.gravity)?;
        finite("theta0", self.theta0)?;
        finite("omega0", self.omega0)?;
        Ok(())
    }

    /// The exact motion `θ(t)`, when gravity is on and the motion is not the separatrix.
    fn exact(&self) -> Option<PendulumExact> {
        PendulumExact::new(self.gravity / self.length, self.theta0, self.omega0).ok()
    }
}

/// `Φ = ½ (X² + Y² − L²)` (Eq. 61).
struct Rod {
    length: f64,
}

impl Constraint<2, 1> for Rod {
    fn eval<D: Scalar>(&self, [x, y]: [D; 2], _t: D) -> [D; 1] {
        [(x * x + y * y - self.length * self.length) * 0.5]
    }
}

/// `V = w · height`.
pub(crate) struct Weight {
    pub w: f64,
}

impl Potential<1> for Weight {
    fn energy<D: Scalar>(&self, [height]: [D; 1]) -> D {
        height * self.w
    }
}

/// `V = m g L sin θ`.
struct ThetaWeight {
    mgl: f64,
}

impl Potential<1> for ThetaWeight {
    fn energy<D: Scalar>(&self, [theta]: [D; 1]) -> D {
        theta.sin() * self.mgl
    }
}

fn tip(length: f64, theta: f64, omega: f64) -> [f64; 4] {
    let (s, c) = theta.sin_cos();
    [length * c, length * s, -length * s * omega, length * c * omega]
}

fn names() -> Vec<String> {
    ["X", "Y", "VX", "VY"].map(String::from).to_vec()
}

/// The pendulum in Cartesian coordinates `q = (X, Y)`.
pub fn cartesian_pendulum(p: PendulumParams) -> Result<Example> {
    p.validate()?;
    let model = Model::builder(vec![p.mass, p.mass])
        .constrain(Rod { length: p.length }, [0, 1])
        .potential(Weight { w: p.mass * p.gravity }, [1])
        .build()?;
    let [x, y, vx, vy] = tip(p.length, p.theta0, p.omega0);
    let reference = p.exact().map(|exact| -> super::Reference {
        Box::new(move |t, q, v| {
            let (theta, omega) = exact.angle(t);
            let [x, y, vx, vy] = tip(p.length, theta, omega);
            q.copy_from_slice(&[x, y]);
            v.copy_from_slice(&[vx, vy]);
        })
    });
    Ok(Example {
        model,
        q0: vec![x, y],
        v0: vec![vx, vy],
        observables: names(),
        observe: Box::new(|_t, q, v, out| out.copy_from_slice(&[q[0], q[1], v[0], v[1]])),
        reference,
        drawing: Some(bob_on_a_rod()),
        sketch: None,
    })
}

/// The Cartesian pendulum as a viewer draws it: the bob, a point mass at
/// `q = (x, y)`, on a rod from the pivot at the origin.
fn bob_on_a_rod() -> Drawing {
    let bob = Shape { name: "bob".into(), x: 0, angle: None, points: Vec::new() };
    let ends = vec![Anchor { body: None, point: [0.0, 0.0] }, Anchor { body: Some(0), point: [0.0, 0.0] }];
    Drawing { bodies: vec![bob], links: vec![Link { kind: "distance", ends, axis: None }] }
}

/// The pendulum in Cartesian coordinates as a [`SmallSystem`]: the same
/// equations as [`cartesian_pendulum`], in fixed-size arrays.
#[derive(Debug, Clone, Copy)]
pub struct SmallPendulum {
    rod: f64,
    mass: f64,
    weight: f64,
}

impl SmallSystem<2, 1> for SmallPendulum {
    fn mass(&self) -> [f64; 2] {
        [self.mass; 2]
    }
    fn constraints<D: Scalar>(&self, q: [D; 2], t: D) -> [D; 1] {
        Rod { length: self.rod }.eval(q, t)
    }
    fn potential<D: Scalar>(&self, [_, y]: [D; 2]) -> D {
        Weight { w: self.weight }.energy([y])
    }
}

/// The Cartesian pendulum as a [`SmallSystem`], with its initial `(q, v)`.
pub fn small_pendulum(p: PendulumParams) -> Result<(SmallPendulum, [f64; 2], [f64; 2])> {
    p.validate()?;
    let [x, y, vx, vy] = tip(p.length, p.theta0, p.omega0);
    Ok((SmallPendulum { rod: p.length, mass: p.mass, weight: p.mass * p.gravity }, [x, y], [vx, vy]))
}

/// The pendulum in the independent angle `q = (θ)`, `m L² θ̈ + m g L cos θ = 0`.
pub fn theta_pendulum(p: PendulumParams) -> Result<Example> {
    p.validate()?;
    let model = Model::builder(vec![p.mass * p.length * p.length])
        .potential(ThetaWeight { mgl: p.mass * p.gravity * p.length }, [0])
        .build()?;
    let reference = p.exact().map(|exact| -> super::Reference {
        Box::new(move |t, q, v| {
            let (theta, omega) = exact.angle(t);
            q[0] = theta;
            v[0] = omega;
        })
    });
    let length = p.length;
    Ok(Example {
        model,
        q0: vec![p.theta0],
        v0: vec![p.omega0],
        observables: names(),
        observe: Box::new(move |_t, q, v, out| out.copy_from_slice(&tip(length, q[0], v[0]))),
        reference,
        drawing: None,
        sketch: None,
    })
}
