//! What a mechanism looks like, for a viewer that animates a run: each
//! body as the points of it that elements attach to (in its own frame, so
//! drawn to scale), which coordinates place it, and each element as the
//! body points it connects. A frame is drawn from the coordinates `q` alone.

use super::body::BodyId;
use super::element::Element;
use super::mechanism::Mechanism;

/// A point of a body, in the body's frame relative to its centre of mass,
/// or a point of the ground, in world axes.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct Anchor {
    /// The body (its index in [`Drawing::bodies`]); `None` for the ground.
    pub body: Option<usize>,
    /// The point.
    pub point: [f64; 2],
}

/// One body: where its coordinates are in `q` and the points to draw.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct Shape {
    /// The body's name.
    pub name: String,
    /// Index of the centre of mass's x in `q` (y follows it).
    pub x: usize,
    /// Index of the angle in `q`; `None` for a point mass.
    pub angle: Option<usize>,
    /// The points elements attach to, body frame, without the centre of mass.
    pub points: Vec<[f64; 2]>,
}

/// One element: its kind as scenario files name it, and the points it acts at.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct Link {
    /// `revolute`, `spring`, `relative_angle`, … ([`Element::kind`]).
    pub kind: &'static str,
    /// The points it connects: two for joints, springs and dampers between
    /// points; one (a body's centre, or the point pushed) for elements on
    /// an angle or a single body, where one side is the ground.
    pub ends: Vec<Anchor>,
    /// A prismatic joint's line direction, in the frame of its first end's body.
    pub axis: Option<[f64; 2]>,
}

/// A mechanism as a viewer draws it.
#[derive(Debug, Clone, PartialEq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct Drawing {
    /// The bodies, in coordinate order.
    pub bodies: Vec<Shape>,
    /// The elements, in the mechanism's order.
    pub links: Vec<Link>,
}

impl Mechanism {
    /// The drawing of this mechanism. Coordinates are laid out as
    /// [`Mechanism::build`] lays them out; elements naming a body that does
    /// not exist are left out (`build` refuses them).
    pub fn drawing(&self) -> Drawing {
        let mut bodies = Vec::with_capacity(self.bodies.len());
        let mut at = 0;
        for b in &self.bodies {
            let angle = b.inertia.map(|_| at + 2);
            bodies.push(Shape { name: b.name.clone(), x: at, angle, points: Vec::new() });
            at += if angle.is_some() { 3 } else { 2 };
        }
        let mut links = Vec::new();
        for e in &self.elements {
            let (ends, axis) = ends(e);
            let ends: Option<Vec<Anchor>> = ends
                .into_iter()
                .map(|(id, point)| match id {
                    BodyId::Ground => Some(Anchor { body: None, point }),
                    BodyId::Body(i) if i < bodies.len() => Some(Anchor { body: Some(i), point }),
                    // An element on a body that does not exist: not drawn.
                    BodyId::Body(_) => None,
                })
                .collect();
            let Some(ends) = ends else { continue };
            for end in &ends {
                if let Some(i) = end.body
                    && end.point != [0.0, 0.0]
                    && !bodies[i].points.contains(&end.point)
                {
                    bodies[i].points.push(end.point);
                }
            }
            links.push(Link { kind: e.kind(), ends, axis });
        }
        Drawing { bodies, links }
    }
}

impl Drawing {
    /// Where `anchor` is, world axes, when the coordinates are `q`:
    /// `x + R(θ) p` for a body's point, `p` itself for the ground's.
    pub fn place(&self, anchor: Anchor, q: &[f64]) -> [f64; 2] {
        let Some(b) = anchor.body.and_then(|i| self.bodies.get(i)) else { return anchor.point };
        let angle = b.angle.map_or(0.0, |i| q[i]);
        let (s, c) = angle.sin_cos();
        let [px, py] = anchor.point;
        [q[b.x] + c * px - s * py, q[b.x + 1] + s * px + c * py]
    }
}

/// A point of a body (or the ground), as an element gives it.
type BodyPoint = (BodyId, [f64; 2]);

/// The body points an element acts at, and a prismatic joint's axis or a
/// knife edge's blade (in the frame of the element's first body). An
/// element on an angle is drawn at the centres of its bodies other than the ground.
fn ends(e: &Element) -> (Vec<BodyPoint>, Option<[f64; 2]>) {
    let centres = |ids: &[BodyId]| ids.iter().filter(|id| **id != BodyId::Ground).map(|&id| (id, [0.0, 0.0])).collect();
    match *e {
        Element::Revolute { a, pa, b, pb, .. }
        | Element::Distance { a, pa, b, pb, .. }
        | Element::Spring { a, pa, b, pb, .. }
        | Element::Damper { a, pa, b, pb, .. } => (vec![(a, pa), (b, pb)], None),
        Element::Prismatic { a, pa, b, pb, axis, .. } => (vec![(a, pa), (b, pb)], Some(axis)),
        Element::KnifeEdge { body, point, blade } => (vec![(body, point)], Some(blade)),
        Element::FixedAngle { a, b, .. }
        | Element::DriveAngle { a, b, .. }
        | Element::TorsionSpring { a, b, .. }
        | Element::RotaryDamper { a, b, .. } => (centres(&[a, b]), None),
        Element::DriveCoordinate { body, .. } | Element::AppliedTorque { body, .. } => (centres(&[body]), None),
        Element::AppliedForce { body, point, .. } => (vec![(body, point)], None),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::timefn::TimeFn;

    /// A crank (rigid) pinned to the ground, driven, with a point mass on a spring.
    #[test]
    fn coordinates_points_and_ends() {
        let mut m = Mechanism::new([0.0, -9.81]);
        let crank = m.rigid("crank", 1.0, 0.1, [0.5, 0.0], 0.0);
        let bob = m.point("bob", 1.0, [2.0, 0.0]);
        m.add(Element::Revolute { a: BodyId::Ground, pa: [0.0, 0.0], b: crank, pb: [-0.5, 0.0], limit: None });
        m.add(Element::DriveAngle { a: BodyId::Ground, b: crank, f: TimeFn::constant(0.0) });
        m.add(Element::Spring { a: crank, pa: [0.5, 0.0], b: bob, pb: [0.0, 0.0], stiffness: 1.0, rest_length: 1.0 });
        m.add(Element::Revolute { a: crank, pa: [-0.5, 0.0], b: BodyId::Body(7), pb: [0.0, 0.0], limit: None });
        let d = m.drawing();
        assert_eq!(d.bodies.len(), 2);
        assert_eq!((d.bodies[0].x, d.bodies[0].angle), (0, Some(2)));
        assert_eq!((d.bodies[1].x, d.bodies[1].angle), (3, None));
        assert_eq!(d.bodies[0].points, vec![[-0.5, 0.0], [0.5, 0.0]]);
        assert!(d.bodies[1].points.is_empty());
        // The element on a missing body is left out.
        let kinds: Vec<_> = d.links.iter().map(|l| l.kind).collect();
        assert_eq!(kinds, ["revolute", "relative_angle", "spring"]);
        assert_eq!(d.links[0].ends[0], Anchor { body: None, point: [0.0, 0.0] });
        assert_eq!(d.links[1].ends, vec![Anchor { body: Some(0), point: [0.0, 0.0] }]);
        assert_eq!(d.links[2].ends[1], Anchor { body: Some(1), point: [0.0, 0.0] });
        // The crank's free end at a quarter turn, the bob where its coordinates say, the ground fixed.
        let q = [0.0, 0.5, std::f64::consts::FRAC_PI_2, 3.0, -1.0];
        let end = d.place(Anchor { body: Some(0), point: [0.5, 0.0] }, &q);
        assert!((end[0] - 0.0).abs() < 1e-15 && (end[1] - 1.0).abs() < 1e-15, "{end:?}");
        assert_eq!(d.place(Anchor { body: Some(1), point: [0.0, 0.0] }, &q), [3.0, -1.0]);
        assert_eq!(d.place(Anchor { body: None, point: [2.0, 7.0] }, &q), [2.0, 7.0]);
    }
}
