//! A planar joint's own coordinate `θ`: the relative angle `φ_b − φ_a` of
//! a revolute joint's bodies (the ground's angle is 0; not wrapped), or the
//! displacement `(p_b − p_a) · u` of a prismatic joint's point `pb` from
//! its point `pa` along the unit axis `u` (which turns with `a`). Written
//! once, generic over the scalar: what a joint limit's stop row holds
//! (`limit`), and, read with dual numbers along the velocities, `θ` and
//! its rate `θ̇` at a state ([`Mechanism::joint_coordinate`], and
//! [`JointSpace`] for reading them at every step without allocating).

use super::element::Element;
use super::ends::{End, angle_of, with_k};
use super::layout::{Layout, offsets};
use super::mechanism::Mechanism;
use crate::ad::scalar::Scalar;
use crate::error::{Problem, Result, positive};
use num_dual::Dual64;

/// A revolute or prismatic joint's coordinate in the coordinates it reads.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) enum JointCoordinate {
    /// `φ_b − φ_a`, each angle's place among the coordinates read (`None`: the ground).
    Angle { a: Option<usize>, b: Option<usize> },
    /// `(p_b − p_a) · R(φ_a) u`, `u` of unit length in `a`'s frame.
    Slide { a: End, b: End, axis: [f64; 2] },
}

impl JointCoordinate {
    #[inline(always)]
    pub(super) fn at<D: Scalar, const K: usize>(&self, x: &[D; K]) -> D {
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

/// The coordinate of joint `e` and the coordinates it reads.
pub(super) fn coordinate(layout: &Layout, e: &Element) -> Result<(JointCoordinate, Vec<usize>)> {
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

/// The coordinates of a planar mechanism's revolute and prismatic joints,
/// read from a state without allocating (the stops of its limits read them
/// after every step): built once by [`Mechanism::joint_space`].
#[derive(Debug, Clone, PartialEq, Default)]
pub struct JointSpace {
    read: Vec<Readable>,
}

/// One joint that has a coordinate: its element's index, its coordinate
/// and the coordinates it reads.
#[derive(Debug, Clone, PartialEq)]
struct Readable {
    element: usize,
    coordinate: JointCoordinate,
    idx: Vec<usize>,
}

impl JointSpace {
    /// The index in [`Mechanism::elements`] of each joint read, in order.
    pub fn joints(&self) -> impl ExactSizeIterator<Item = usize> + '_ {
        self.read.iter().map(|r| r.element)
    }

    /// `(θ, θ̇)` of the `i`-th joint read at the state `(q, v)` (see
    /// [`Mechanism::joint_coordinate`]). Panics if `i` is not below
    /// [`JointSpace::joints`]' count or a slice is shorter than the mechanism's coordinates.
    pub fn at(&self, i: usize, q: &[f64], v: &[f64]) -> [f64; 2] {
        let Readable { coordinate, idx, .. } = &self.read[i];
        let theta = with_k!(idx, K, {
            let x: [Dual64; K] = std::array::from_fn(|i| Dual64::new(q[idx[i]], v[idx[i]]));
            coordinate.at(&x)
        });
        [theta.re, theta.eps]
    }
}

impl Mechanism {
    /// The reader of every revolute and prismatic joint's coordinate that
    /// has one (a revolute joint's on rigid bodies, see
    /// [`Mechanism::joint_coordinate`]), for reading them at many states.
    pub fn joint_space(&self) -> JointSpace {
        let offsets = offsets(&self.bodies);
        let layout = Layout { bodies: &self.bodies, offsets: &offsets };
        let read = self.elements.iter().enumerate().filter_map(|(element, e)| {
            let (coordinate, idx) = coordinate(&layout, e).ok()?;
            Some(Readable { element, coordinate, idx })
        });
        JointSpace { read: read.collect() }
    }

    /// The coordinate `θ` of the revolute or prismatic joint `element` (its
    /// position in [`Mechanism::elements`]) and its rate `θ̇` at `(q, v)`:
    /// the relative angle `φ_b − φ_a`, or the displacement of `pb` from
    /// `pa` along the axis (see [`Element::Revolute`], [`Element::Prismatic`]).
    pub fn joint_coordinate(&self, element: usize, q: &[f64], v: &[f64]) -> Result<[f64; 2]> {
        self.check_state(q, v)?;
        let e = self.elements.get(element).ok_or(Problem::NoSuchJoint { index: element })?;
        let offsets = offsets(&self.bodies);
        let (coordinate, idx) = coordinate(&Layout { bodies: &self.bodies, offsets: &offsets }, e)?;
        let space = JointSpace { read: vec![Readable { element, coordinate, idx }] };
        Ok(space.at(0, q, v))
    }

    /// Refuses positions `q` or velocities `v` of other than the
    /// mechanism's coordinates (a reader indexes them).
    pub(crate) fn check_state(&self, q: &[f64], v: &[f64]) -> Result<()> {
        let n = self.bodies.iter().map(|b| if b.inertia.is_some() { 3 } else { 2 }).sum();
        if q.len() != n || v.len() != n {
            return Err(Problem::StateLength { positions: q.len(), velocities: v.len(), n }.into());
        }
        Ok(())
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
