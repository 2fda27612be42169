//! A planar joint's limit ([`JointLimit`], shared with spatial joints).
//! The joint's coordinate `θ` is the relative angle `φ_b − φ_a` of a
//! revolute joint's bodies (the ground's angle is 0; not wrapped), or the
//! displacement `(p_b − p_a) · u` of a prismatic joint's point `pb` from
//! its point `pa` along the unit axis `u` (which turns with `a`). It is
//! written once, generic over the scalar: the row `g = s (θ − bound)` that
//! holds the joint at a stop (`StopRow`) gets its Jacobian and `γ` by dual
//! numbers like every other row, and a gap's rate `ġ` is one dual pass
//! along the velocities. When a stop is hit, held and released is the
//! run's business ([`crate::stops`]).

use super::element::Element;
use super::ends::{End, angle_of, idx_array, with_k};
use super::layout::{Layout, offsets};
use super::mechanism::Mechanism;
use crate::ad::scalar::Scalar;
use crate::error::{Problem, Result, positive};
use crate::limit::{JointLimit, Stop};
use crate::model::ModelBuilder;
use crate::model::constraint::Constraint;
use num_dual::Dual64;

/// A revolute or prismatic joint's coordinate in the coordinates it reads.
#[derive(Debug, Clone, Copy, PartialEq)]
enum JointCoordinate {
    /// `φ_b − φ_a`, each angle's place among the coordinates read (`None`: the ground).
    Angle { a: Option<usize>, b: Option<usize> },
    /// `(p_b − p_a) · R(φ_a) u`, `u` of unit length in `a`'s frame.
    Slide { a: End, b: End, axis: [f64; 2] },
}

impl JointCoordinate {
    #[inline(always)]
    fn at<D: Scalar, const K: usize>(&self, x: &[D; K]) -> D {
        match *self {
            JointCoordinate::Angle { a, b } => angle_of(b, x) - angle_of(a, x),
            JointCoordinate::Slide { a, b, axis: [ux, uy] } => {
                let (pa, pb) = (a.position(x), b.position(x));
                let phi = a.angle(x);
                let (s, c) = (phi.sin(), phi.cos());
                (pb[0] - pa[0]) * (c * ux - s * uy) + (pb[1] - pa[1]) * (s * ux + c * uy)
            }
        }
    }
}

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

/// The coordinate of joint `e` and the coordinates it reads.
fn coordinate(layout: &Layout, e: &Element) -> Result<(JointCoordinate, Vec<usize>)> {
    match *e {
        Element::Revolute { a, b, .. } => {
            for body in [a, b].into_iter().filter_map(|id| layout.body(id)) {
                if body.inertia.is_none() {
                    let reason = format!(
                        "limit: body {} is a point mass: a revolute joint's limit bounds the relative angle of rigid bodies (or of one and the ground)",
                        body.name
                    );
                    return Err(Problem::Stop { reason }.into());
                }
            }
            let (a, b, idx) = layout.two_angles(a, b)?;
            Ok((JointCoordinate::Angle { a, b }, idx))
        }
        Element::Prismatic { a, pa, b, pb, axis, .. } => {
            let norm = positive("|axis|", axis[0].hypot(axis[1]))?;
            let (a, b, idx) = layout.two_points(a, pa, b, pb)?;
            Ok((JointCoordinate::Slide { a, b, axis: [axis[0] / norm, axis[1] / norm] }, idx))
        }
        ref other => {
            let reason = format!("a {} has no coordinate to limit (revolute and prismatic joints have)", other.kind());
            Err(Problem::Stop { reason }.into())
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
        let offsets = offsets(&self.bodies);
        stops
            .iter()
            .map(|&s| {
                let [theta, rate] = self.coordinate_at(&offsets, s.joint, q, v)?;
                let limit = self.elements[s.joint].limit().expect("a stop's joint has a limit");
                Ok(limit.gap(s.upper, theta, rate))
            })
            .collect()
    }

    /// The coordinate `θ` of the revolute or prismatic joint `element` (its
    /// position in [`Mechanism::elements`]) and its rate `θ̇` at `(q, v)`:
    /// the relative angle `φ_b − φ_a`, or the displacement of `pb` from
    /// `pa` along the axis (see [`Element::Revolute`], [`Element::Prismatic`]).
    pub fn joint_coordinate(&self, element: usize, q: &[f64], v: &[f64]) -> Result<[f64; 2]> {
        self.coordinate_at(&offsets(&self.bodies), element, q, v)
    }

    fn coordinate_at(&self, offsets: &[usize], element: usize, q: &[f64], v: &[f64]) -> Result<[f64; 2]> {
        let n = self.bodies.iter().map(|b| if b.inertia.is_some() { 3 } else { 2 }).sum();
        if q.len() != n || v.len() != n {
            return Err(Problem::StateLength { positions: q.len(), velocities: v.len(), n }.into());
        }
        let e = self.elements.get(element).ok_or(Problem::NoSuchJoint { index: element })?;
        let (coordinate, idx) = coordinate(&Layout { bodies: &self.bodies, offsets }, e)?;
        let theta = with_k!(idx, K, {
            let x: [Dual64; K] = std::array::from_fn(|i| Dual64::new(q[idx[i]], v[idx[i]]));
            coordinate.at(&x)
        });
        Ok([theta.re, theta.eps])
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::planar::BodyId;

    /// The coordinates by hand: a rigid crank at angle 0.7 and a rigid
    /// slider at angle −0.2 on a line through the crank's point
    /// `[0.3, 0.1]` along the crank's local axis `[3, 4]`; the rates by the
    /// derivative of the hand formula along `v`, by central differences.
    #[test]
    fn the_coordinates_are_the_relative_angle_and_the_displacement_along_the_axis() {
        let mut m = Mechanism::new([0.0, -9.81]);
        let crank = m.rigid("crank", 1.0, 0.1, [0.2, -0.4], 0.7);
        let slider = m.rigid("slider", 1.0, 0.1, [1.1, 0.6], -0.2);
        let (pa, pb, axis) = ([0.3, 0.1], [-0.05, 0.02], [3.0, 4.0]);
        m.add(Element::Revolute { a: crank, pa: [0.0; 2], b: slider, pb: [0.0; 2], limit: None });
        m.add(Element::Prismatic { a: crank, pa, b: slider, pb, axis, limit: None });
        m.add(Element::Revolute { a: BodyId::Ground, pa: [0.0; 2], b: slider, pb: [0.0; 2], limit: None });
        let q = [0.2, -0.4, 0.7, 1.1, 0.6, -0.2];
        let v = [0.3, -1.2, 0.8, -0.5, 0.9, 2.1];
        let rotate = |phi: f64, [x, y]: [f64; 2]| [phi.cos() * x - phi.sin() * y, phi.sin() * x + phi.cos() * y];
        let slide = |q: &[f64]| {
            let (wa, wb) = (rotate(q[2], pa), rotate(q[5], pb));
            let u = rotate(q[2], [0.6, 0.8]);
            (q[3] + wb[0] - q[0] - wa[0]) * u[0] + (q[4] + wb[1] - q[1] - wa[1]) * u[1]
        };
        let by_hand = |k: usize, q: &[f64]| match k {
            0 => q[5] - q[2],
            1 => slide(q),
            _ => q[5],
        };
        for k in 0..3 {
            let theta = |q: &[f64]| by_hand(k, q);
            let [x, rate] = m.joint_coordinate(k, &q, &v).unwrap();
            assert!((x - theta(&q)).abs() < 1e-15, "element {k}: {x} against {}", theta(&q));
            let eps = 1e-6;
            let shifted = |s: f64| theta(&std::array::from_fn::<_, 6, _>(|i| q[i] + s * v[i]));
            let fd = (shifted(eps) - shifted(-eps)) / (2.0 * eps);
            assert!((rate - fd).abs() < 1e-8, "element {k}: {rate} against {fd}");
        }
    }
}
