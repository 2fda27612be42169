//! The bodies of a planar mechanism: what a body is, how elements refer to
//! one, and the checks a body must pass before it is turned into
//! coordinates.

use crate::error::{Part, Problem, Result, finite, positive};
use std::collections::HashSet;

/// A body of a [`Mechanism`](super::Mechanism), or the ground.
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

impl Body {
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
