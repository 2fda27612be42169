//! Joint limits, planar and spatial: the range of a revolute or prismatic
//! joint's coordinate `θ` ([`JointLimit`]), each finite side a one-sided
//! stop ([`Stop`]) with its gap `g = θ − lower` or `upper − θ` (`g ≥ 0`
//! allowed, [`JointLimit::gap`]), and the row `g = 0` that holds a joint at
//! a stop while it pushes into it.
//!
//! A mechanism says where its stops are
//! ([`crate::spatial::Mechanism::stops`], [`crate::planar::Mechanism::stops`])
//! and builds its model with a given set of them held (`build_holding`: the
//! row is the gap, written once on the joint's coordinate and
//! differentiated like any other row); when a stop is hit, held and
//! released is the run's business ([`crate::stops`]), as it changes which
//! rows the model has.
//!
//! What `θ` is depends on the mechanism: a spatial joint's angle (read in
//! `(−π, π]`: a range shorter than a turn is told apart from it wherever
//! its bounds lie, Panda's joint 6 going to 3.75 rad; in a range of a turn
//! or more, URDF's ±2π of a multi-turn joint or TIAGo's fingers' −2.62 …
//! 6.28, a state alone cannot tell the turns apart, and a run's stops
//! follow them from step to step, [`crate::stops`]) or displacement from
//! the initial pose; a planar joint's relative angle `φ_b − φ_a` (not
//! wrapped) or the displacement of `point_b` from `point_a` along the axis.
//!
//! May import: `error`.

use crate::error::{Problem, Result};
use std::f64::consts::TAU;

/// The range of a revolute or prismatic joint's coordinate: an angle in
/// rad, a displacement in length units (for a spatial joint from the
/// initial pose, see [`crate::spatial::Mechanism::joint_coordinates`]; for
/// a planar one see [`crate::planar::Element::Revolute`] and
/// [`crate::planar::Element::Prismatic`]). In a scenario file a joint's
/// `limit = { lower = -1.0, upper = 1.0 }`; from URDF, `<limit>`.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Deserialize), serde(deny_unknown_fields))]
#[non_exhaustive]
pub struct JointLimit {
    /// The lowest coordinate (`−∞`: none).
    #[cfg_attr(feature = "serde", serde(default = "minus_infinity"))]
    pub lower: f64,
    /// The highest coordinate (`+∞`: none).
    #[cfg_attr(feature = "serde", serde(default = "infinity"))]
    pub upper: f64,
    /// Newton's coefficient of restitution at a stop: the joint's rate
    /// after an impact is `−e` times the rate before; 0 (the default)
    /// stops it there and holds it while it pushes.
    #[cfg_attr(feature = "serde", serde(default))]
    pub restitution: f64,
    /// The largest `|θ̇|` (`+∞`: none): reported where exceeded, not enforced.
    #[cfg_attr(feature = "serde", serde(default = "infinity"))]
    pub velocity: f64,
    /// The largest actuator torque (force) at the joint (`+∞`: none): a
    /// spatial joint's [`Actuator`](crate::spatial::Actuator) is clamped to
    /// `±effort`. A planar joint has no actuator, and refuses a finite one.
    #[cfg_attr(feature = "serde", serde(default = "infinity"))]
    pub effort: f64,
}

#[cfg(feature = "serde")]
fn infinity() -> f64 {
    f64::INFINITY
}

#[cfg(feature = "serde")]
fn minus_infinity() -> f64 {
    f64::NEG_INFINITY
}

impl JointLimit {
    /// Whether a revolute joint's angle, measured in `(−π, π]`, tells
    /// which side of this range it is on: a range shorter than a turn,
    /// whose bounds may lie beyond ±π (Panda's joint 6: −0.0175 to 3.7525).
    pub(crate) fn within_a_turn(&self) -> bool {
        self.upper - self.lower < TAU
    }

    /// A revolute joint's angle measured in `(−π, π]` as an angle of a range
    /// [`within_a_turn`](Self::within_a_turn): in `[lower, upper]` when
    /// inside it, else past the nearer bound. Measured as it is, Panda's
    /// joint 6 turning through π within its range read as far past its
    /// lower bound, and a stop took it there.
    pub(crate) fn unwrap_angle(&self, angle: f64) -> f64 {
        let theta = self.lower + (angle - self.lower).rem_euclid(TAU);
        if theta - self.upper > self.lower + TAU - theta { theta - TAU } else { theta }
    }

    /// A revolute joint's angle `θ` as the angle `θ + 2πk` of a range of a
    /// turn or more (not [`within_a_turn`](Self::within_a_turn), which
    /// always holds one) nearest `reference`. A bound is in the range to
    /// [`AT_BOUND`]: a joint resting at a bound of 0 at `−1e-17` is read at
    /// it, not a turn away at the other bound.
    pub(crate) fn turn_nearest(&self, angle: f64, reference: f64) -> f64 {
        let lowest = ((self.lower - AT_BOUND - angle) / TAU).ceil();
        let highest = ((self.upper + AT_BOUND - angle) / TAU).floor();
        // Ties (θ = π from 0) keep θ; `max`/`min`, unlike `clamp`, do not
        // panic should round-off leave the range without a whole turn.
        let turns = ((reference - angle) / TAU).round_ties_even().max(lowest).min(highest);
        angle + TAU * turns
    }

    /// `lower ≤ θ ≤ upper`, stopped without rebound, no velocity or effort bound.
    pub fn new(lower: f64, upper: f64) -> Self {
        Self { lower, upper, restitution: 0.0, velocity: f64::INFINITY, effort: f64::INFINITY }
    }

    /// Refuses bounds that are NaN or in the wrong order, and a restitution
    /// outside `[0, 1]` or velocity and effort bounds that are not positive.
    pub fn check(&self) -> Result<()> {
        let reason = if self.lower.is_nan() || self.upper.is_nan() {
            Some("a bound is not a number")
        } else if self.lower > self.upper {
            Some("lower is above upper")
        } else if self.lower == f64::INFINITY || self.upper == f64::NEG_INFINITY {
            Some("the range is empty")
        } else {
            None
        };
        if let Some(reason) = reason {
            return Err(Problem::BadLimit { lower: self.lower, upper: self.upper, reason }.into());
        }
        if !(0.0..=1.0).contains(&self.restitution) {
            let value = self.restitution;
            return Err(Problem::Parameter { name: "restitution", value, reason: "must be in [0, 1]" }.into());
        }
        crate::error::positive("velocity limit", self.velocity).or_else(|e| infinite_is_none(e, self.velocity))?;
        crate::error::positive("effort limit", self.effort).or_else(|e| infinite_is_none(e, self.effort))?;
        Ok(())
    }
}

/// How far past a bound a coordinate is still at it: round-off of a pose
/// placed there (see [`crate::stops::START_SLACK`], which it is).
pub(crate) const AT_BOUND: f64 = 1e-12;

/// `+∞` is no bound, not an error.
fn infinite_is_none(e: crate::Error, value: f64) -> Result<f64> {
    if value == f64::INFINITY { Ok(value) } else { Err(e) }
}

crate::setters!(JointLimit {
    /// With Newton's coefficient of restitution `e`.
    with_restitution => restitution: f64,
    /// With a velocity bound (reported where exceeded).
    with_velocity => velocity: f64,
    /// With an effort bound (which clamps the joint's actuator).
    with_effort => effort: f64,
});

/// One side of a joint's limit.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Stop {
    /// The joint: an index into [`crate::spatial::Mechanism::joints`], or
    /// into [`crate::planar::Mechanism::elements`].
    pub joint: usize,
    /// The upper bound (else the lower).
    pub upper: bool,
}

impl JointLimit {
    /// The bound of one side and its sign `s` (1 lower, −1 upper): the gap
    /// there is `g = s (θ − bound)`.
    pub fn side(&self, upper: bool) -> (f64, f64) {
        if upper { (self.upper, -1.0) } else { (self.lower, 1.0) }
    }

    /// The gap `g` of one side and its rate `ġ`, at the coordinate `θ` moving at `θ̇`.
    pub fn gap(&self, upper: bool, theta: f64, rate: f64) -> [f64; 2] {
        let (bound, sign) = self.side(upper);
        [sign * (theta - bound), sign * rate]
    }

    /// The finite sides, lower before upper: the joint's stops.
    pub fn finite_sides(self) -> impl Iterator<Item = bool> {
        [false, true].into_iter().filter(move |&upper| self.side(upper).0.is_finite())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;

    #[test]
    fn an_angle_in_a_range_of_a_turn_or_more_is_the_one_nearest_the_reference() {
        let finger = JointLimit::new(-2.62, 6.2);
        // In range and nearest 0: kept; below −2.62, a turn up.
        assert_eq!(finger.turn_nearest(2.0, 0.0), 2.0);
        assert_eq!(finger.turn_nearest(-3.0, 0.0), -3.0 + TAU);
        // Nearest the start 5.0: a turn up, where that is in range.
        assert_eq!(finger.turn_nearest(5.0 - TAU, 5.0), 5.0 - TAU + TAU);
        assert_eq!(finger.turn_nearest(-1.0, 9.0), -1.0 + TAU);
        // π from 0 (a tie with −π) stays π.
        assert_eq!(JointLimit::new(-TAU, TAU).turn_nearest(PI, 0.0), PI);
        // A joint resting at its bound 0 by round-off is at it, not a turn away.
        assert_eq!(JointLimit::new(0.0, TAU).turn_nearest(-1e-17, 0.0), -1e-17);
        assert_eq!(JointLimit::new(0.0, TAU).turn_nearest(-1e-9, 0.0), -1e-9 + TAU);
        // One bound only: the nearest angle on its side.
        assert_eq!(JointLimit::new(f64::NEG_INFINITY, 1.0).turn_nearest(2.0, 0.0), 2.0 - TAU);
    }
}
