//! A planar joint's limit ([`JointLimit`], shared with spatial joints) on
//! the joint's coordinate `θ` (`coordinate`: the relative angle of a
//! revolute joint's bodies, not wrapped, or a prismatic joint's
//! displacement along its axis): the row `g = s (θ − bound)` that holds
//! the joint at a stop (`StopRow`) gets its Jacobian and `γ` by dual
//! numbers like every other row, and a gap's rate `ġ` is one dual pass
//! along the velocities. When a stop is hit, held and released is the
//! run's business ([`crate::stops`]).

use super::coordinate::{JointCoordinate, coordinate};
use super::element::Element;
use super::ends::{idx_array, with_k};
use super::layout::Layout;
use super::mechanism::Mechanism;
use crate::ad::scalar::Scalar;
use crate::error::{Problem, Result};
use crate::limit::{JointLimit, Stop};
use crate::model::ModelBuilder;
use crate::model::constraint::Constraint;

/// The row holding a joint at a stop: `g = s (θ − bound)`, `s = 1` at a
/// lower bound and `−1` at an upper one.
struct StopRow {
    coordinate: JointCoordinate,
    bound: f64,
    sign: f64,
}

impl<const K: usize> Constraint<K, 1> for StopRow {
    #[inline(always)]
    fn eval<D: Scalar>(&self, x: [D; K], _t: D) -> [D; 1] {
        [(self.coordinate.at(&x) - self.bound) * self.sign]
    }
}

impl<B> Element<B> {
    /// The joint's limit: a revolute or prismatic joint's, if it has one.
    pub fn limit(&self) -> Option<JointLimit> {
        match *self {
            Element::Revolute { limit, .. } | Element::Prismatic { limit, .. } => limit,
            _ => None,
        }
    }
}

/// Refuses a bad limit of `e`: bounds (see [`JointLimit::check`]), an
/// effort bound (a planar joint has no actuator to clamp), a joint whose
/// coordinate cannot be read.
pub(super) fn check_limit(layout: &Layout, e: &Element) -> Result<()> {
    let Some(limit) = e.limit() else { return Ok(()) };
    limit.check()?;
    if limit.effort != f64::INFINITY {
        let reason = format!("limit effort = {}: a planar joint has no actuator to clamp", limit.effort);
        return Err(Problem::Stop { reason }.into());
    }
    coordinate(layout, e).map(|_| ())
}

/// Adds the row holding joint `e` at the side `stop` of its limit.
pub(super) fn stop_row(layout: &Layout, builder: ModelBuilder, e: &Element, stop: Stop) -> Result<ModelBuilder> {
    let limit = e.limit().ok_or_else(|| Problem::Stop { reason: format!("a {} without a limit", e.kind()) })?;
    let (coordinate, idx) = coordinate(layout, e)?;
    let (bound, sign) = limit.side(stop.upper);
    Ok(with_k!(idx, K, builder.constrain(StopRow { coordinate, bound, sign }, idx_array::<K>(&idx))))
}

impl Mechanism {
    /// Every finite side of every joint's limit, lower before upper,
    /// elements in order.
    pub fn stops(&self) -> Vec<Stop> {
        let limits = self.elements.iter().enumerate().filter_map(|(joint, e)| Some((joint, e.limit()?)));
        limits.flat_map(|(joint, l)| l.finite_sides().map(move |upper| Stop { joint, upper })).collect()
    }

    /// The stop's bound, its sign `s` (1 lower, −1 upper) and its joint's restitution.
    /// Panics if the stop's element has no limit.
    pub fn stop_bound(&self, stop: Stop) -> (f64, f64, f64) {
        let l = self.elements[stop.joint].limit().expect("a stop's joint has a limit");
        let (bound, sign) = l.side(stop.upper);
        (bound, sign, l.restitution)
    }

    /// The gap `g = s (θ − bound)` and its rate `ġ` of each stop at `(q, v)`.
    pub fn gaps(&self, stops: &[Stop], q: &[f64], v: &[f64]) -> Result<Vec<[f64; 2]>> {
        let gap = |s: Stop| {
            let [theta, rate] = self.joint_coordinate(s.joint, q, v)?;
            Ok(self.elements[s.joint].limit().expect("a stop's joint has a limit").gap(s.upper, theta, rate))
        };
        stops.iter().map(|&s| gap(s)).collect()
    }
}
