//! What a spatial mechanism looks like, for figures of a run: each body as
//! the points of it that joints attach to (in its own axes, so drawn to
//! scale) and its shapes, and each joint as the two points it connects. A
//! frame is drawn from the coordinates `q` alone.

use super::body::SpatialBody;
use super::mechanism::Mechanism;
use super::rotation::{rotate, unrotate};
use super::visual::Visual;

/// A point of a body (body axes, from its centre of mass) or of the ground (space).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Anchor {
    /// The body, by index; `None` for the ground.
    pub body: Option<usize>,
    /// The point.
    pub point: [f64; 3],
}

/// One body: its name, where its coordinates start, its points.
#[derive(Debug, Clone, PartialEq)]
pub struct Limb {
    /// The body's name.
    pub name: String,
    /// Its coordinates: `r` from here, then `p`.
    pub at: SpatialBody,
    /// The points joints attach to, body axes, from the centre of mass.
    pub points: Vec<[f64; 3]>,
    /// What it looks like: the body's visuals, or the box of its inertia.
    pub shapes: Vec<Visual>,
    /// Whether `shapes` are the body's own visuals (not its inertia's box).
    pub shaped: bool,
}

/// A spatial mechanism as a figure draws it.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Sketch {
    /// The bodies.
    pub bodies: Vec<Limb>,
    /// Each joint's two points (the same place for all but distance joints).
    pub joints: Vec<[Anchor; 2]>,
    /// The ground's shapes, in space ([`Mechanism::ground`]).
    pub ground: Vec<Visual>,
}

impl Sketch {
    /// Where `anchor` is at positions `q`, in space.
    pub fn place(&self, q: &[f64], anchor: &Anchor) -> [f64; 3] {
        match anchor.body {
            None => anchor.point,
            Some(b) => {
                let at = self.bodies[b].at;
                let (r, x) = (at.position(q), rotate(at.orientation(q), anchor.point));
                std::array::from_fn(|i| r[i] + x[i])
            }
        }
    }
}

impl Mechanism {
    /// The sketch of this mechanism, from the bodies' initial poses.
    pub fn sketch(&self) -> Sketch {
        let mut bodies: Vec<Limb> = self
            .bodies
            .iter()
            .enumerate()
            .map(|(i, b)| Limb {
                name: b.name.clone(),
                at: SpatialBody::of(i),
                points: Vec::new(),
                shapes: if b.visuals.is_empty() {
                    vec![Visual::of_inertia(b.mass, &b.inertia)]
                } else {
                    b.visuals.clone()
                },
                shaped: !b.visuals.is_empty(),
            })
            .collect();
        let mut anchor = |body: Option<usize>, point: [f64; 3]| match body.filter(|&b| b < self.bodies.len()) {
            None => Anchor { body: None, point },
            Some(b) => {
                let body = &self.bodies[b];
                let norm = body.orientation.iter().map(|x| x * x).sum::<f64>().sqrt();
                let s =
                    unrotate(body.orientation.map(|x| x / norm), std::array::from_fn(|i| point[i] - body.position[i]));
                bodies[b].points.push(s);
                Anchor { body: Some(b), point: s }
            }
        };
        let joints = self
            .joints
            .iter()
            .map(|j| [anchor(Some(j.a), j.point), anchor(j.b, j.point_b.unwrap_or(j.point))])
            .collect();
        Sketch { bodies, joints, ground: self.ground.clone() }
    }
}
