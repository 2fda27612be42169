//! The bodies of a planar mechanism: what a body is, how elements refer to
//! one, and the checks a body must pass before it is turned into
//! coordinates.

use crate::error::{Part, Problem, Result, finite, positive};
use std::collections::HashSet;

/// A body of a [`Mechanism`](super::Mechanism), or the ground. Exhaustive on
/// purpose (not `#[non_exhaustive]`): there is nothing else an element can
/// be attached to, so a `match` needs no wildcard arm.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum BodyId {
    /// The fixed world frame; it has no coordinates.
    Ground,
    /// The body at this position (from 0) in the mechanism's body list.
    Body(usize),
}

/// The name scenario files use for the ground, which no body may take.
pub const GROUND: &str = "ground";

/// One body's description and initial state. In a scenario file it is a
/// `[[bodies]]` entry with these keys; `angle`, `velocity` and
/// `angular_velocity` default to zero and `inertia` is omitted for a point
/// mass.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Deserialize), serde(deny_unknown_fields))]
#[non_exhaustive]
pub struct Body {
    /// How elements and coordinate names (`crank.x`) refer to the body; unique, not `ground`.
    pub name: String,
    /// Mass, finite and positive.
    pub mass: f64,
    /// Moment of inertia about the centre of mass; `None` for a point mass.
    pub inertia: Option<f64>,
    /// Initial position of the centre of mass, world axes.
    pub position: [f64; 2],
    /// Initial angle; a point mass has none, so it must stay 0.
    #[cfg_attr(feature = "serde", serde(default))]
    pub angle: f64,
    /// Initial velocity of the centre of mass, world axes.
    #[cfg_attr(feature = "serde", serde(default))]
    pub velocity: [f64; 2],
    /// Initial angular velocity; 0 for a point mass.
    #[cfg_attr(feature = "serde", serde(default))]
    pub angular_velocity: f64,
}

crate::setters!(Body {
    /// With `mass`: mass, finite and positive.
    with_mass => mass: f64,
    /// With `inertia`: moment of inertia about the centre of mass, making the body rigid.
    with_inertia => inertia(Some): f64,
    /// With `position`: initial position of the centre of mass, world axes.
    with_position => position: [f64; 2],
    /// With `angle`: initial angle; a point mass has none, so it must stay 0.
    with_angle => angle: f64,
    /// With `velocity`: initial velocity of the centre of mass, world axes.
    with_velocity => velocity: [f64; 2],
    /// With `angular_velocity`: initial angular velocity; 0 for a point mass.
    with_angular_velocity => angular_velocity: f64,
});

impl Body {
    /// A rigid body at `position` with angle `angle`, at rest.
    pub fn rigid(name: &str, mass: f64, inertia: f64, position: [f64; 2], angle: f64) -> Self {
        Self { inertia: Some(inertia), angle, ..Self::point(name, mass, position) }
    }

    /// A point mass at `position`, at rest.
    pub fn point(name: &str, mass: f64, position: [f64; 2]) -> Self {
        Self { name: name.into(), mass, inertia: None, position, angle: 0.0, velocity: [0.0; 2], angular_velocity: 0.0 }
    }

    /// Checks the body at `index` of a mechanism whose earlier bodies have
    /// the names `earlier` (a set, so that checking N bodies costs O(N)): a
    /// free, unique name, positive mass and inertia, a finite initial state,
    /// and no rotation of a point mass. Adds its name to `earlier`.
    pub(super) fn check<'a>(&'a self, index: usize, earlier: &mut HashSet<&'a str>) -> Result<()> {
        let at = || Part::Body { index, name: self.name.clone() };
        if self.name.is_empty() || self.name == GROUND {
            return Err(Problem::ReservedName { name: self.name.clone() }.at(at()));
        }
        if !earlier.insert(&self.name) {
            return Err(Problem::DuplicateName.at(at()));
        }
        positive("mass", self.mass).map_err(|e| e.at(at()))?;
        if let Some(inertia) = self.inertia {
            positive("inertia", inertia).map_err(|e| e.at(at()))?;
        }
        let [x, y] = self.position;
        let [vx, vy] = self.velocity;
        for (name, value) in [
            ("position[0]", x),
            ("position[1]", y),
            ("angle", self.angle),
            ("velocity[0]", vx),
            ("velocity[1]", vy),
            ("angular_velocity", self.angular_velocity),
        ] {
            finite(name, value).map_err(|e| e.at(at()))?;
        }
        if self.inertia.is_none() && (self.angle != 0.0 || self.angular_velocity != 0.0) {
            return Err(Problem::PointMassRotation.at(at()));
        }
        Ok(())
    }
}
