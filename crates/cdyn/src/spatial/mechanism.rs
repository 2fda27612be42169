//! A spatial mechanism — bodies, joints and gravity — turned into a
//! [`Model`] and its initial state.

use super::body::{Body, Rotation, SpatialBody, coordinate_names};
use super::joint::{Joint, JointKind};
use super::load::Load;
use super::placing::{add_joint, add_load};
use super::rotation::rate_from_body;
use crate::ad::scalar::Scalar;
use crate::error::{Part, Result};
use crate::model::Model;
use crate::model::angular::Generator;
use crate::model::force::Potential;

/// Bodies, joints and uniform gravity.
#[derive(Debug, Clone, PartialEq, Default)]
#[non_exhaustive]
pub struct Mechanism {
    /// The bodies; body `i` has coordinates `7i .. 7i + 7` (see [`SpatialBody`]).
    pub bodies: Vec<Body>,
    /// The joints, placed at the bodies' initial poses.
    pub joints: Vec<Joint>,
    /// Gravitational acceleration, in space.
    pub gravity: [f64; 3],
    /// Springs, dampers, forces and torques, placed at the initial pose.
    pub loads: Vec<Load>,
}

/// A mechanism's model, its initial state (as given, not yet projected
/// onto the constraints: see [`crate::dynamics::assemble`]) and, for every
/// constraint row, the part it comes from: [`Part::Body`] for a body's
/// normalization, [`Part::Element`] for a joint.
pub struct Built {
    /// The equations of motion.
    pub model: Model,
    /// Initial positions.
    pub q0: Vec<f64>,
    /// Initial velocities.
    pub v0: Vec<f64>,
    /// The part behind each constraint row.
    pub rows: Vec<Part>,
}

/// How many ground joints' points the builder proposes rotations about.
const MAX_PIVOTS: usize = 4;

/// `−m g · r`
#[derive(Debug, Clone, Copy, PartialEq)]
struct Gravity {
    weight: [f64; 3],
}

impl Potential<3> for Gravity {
    fn energy<D: Scalar>(&self, r: [D; 3]) -> D {
        -(r[0] * self.weight[0] + r[1] * self.weight[1] + r[2] * self.weight[2])
    }
}

crate::setters!(Mechanism {
    /// With these bodies.
    with_bodies => bodies: Vec<Body>,
    /// With these joints.
    with_joints => joints: Vec<Joint>,
    /// With this gravitational acceleration.
    with_gravity => gravity: [f64; 3],
    /// With these springs, dampers, forces and torques.
    with_loads => loads: Vec<Load>,
});

impl Mechanism {
    /// An empty mechanism under `gravity`; bodies, joints and loads are
    /// added with [`Mechanism::with_bodies`], [`Mechanism::with_joints`],
    /// [`Mechanism::with_loads`].
    pub fn new(gravity: [f64; 3]) -> Self {
        Self { gravity, ..Self::default() }
    }

    /// The model, its initial state and the part behind each row.
    pub fn build(&self) -> Result<Built> {
        let n = 7 * self.bodies.len();
        let mut mass = vec![0.0; n];
        let (mut q0, mut v0) = (vec![0.0; n], vec![0.0; n]);
        let mut poses = Vec::with_capacity(self.bodies.len());
        for (i, body) in self.bodies.iter().enumerate() {
            let at = Part::Body { index: i, name: body.name.clone() };
            let p = body.check().map_err(|e| e.at(at.clone()))?;
            let b = SpatialBody::of(i);
            mass[b.first..b.first + 3].fill(body.mass);
            q0[b.first..b.first + 3].copy_from_slice(&body.position);
            q0[b.first + 3..b.first + 7].copy_from_slice(&p);
            v0[b.first..b.first + 3].copy_from_slice(&body.velocity);
            v0[b.first + 3..b.first + 7].copy_from_slice(&rate_from_body(p, body.angular_velocity));
            poses.push((body.position, p));
        }
        for g in self.gravity {
            crate::error::finite("gravity", g)?;
        }
        let mut rows = Vec::new();
        let names: Vec<String> = self.bodies.iter().flat_map(|b| coordinate_names(&b.name)).collect();
        let mut builder = Model::builder(mass).coordinate_names(names.clone());
        // The rigid translations: kept where nothing holds the mechanism in place.
        let axes = if self.bodies.is_empty() {
            &[][..]
        } else {
            &["linear momentum x", "linear momentum y", "linear momentum z"]
        };
        for (axis, name) in axes.iter().enumerate() {
            let direction: Vec<(usize, f64)> =
                (0..self.bodies.len()).map(|i| (SpatialBody::of(i).first + axis, 1.0)).collect();
            builder = builder.momentum_candidate(name, &direction);
        }
        // The rigid rotations about the axes through the origin, and through
        // the first few points where a joint holds the mechanism to the
        // ground (a pendulum keeps its momentum about its pivot).
        let mut points = vec![[0.0; 3]];
        for j in self.joints.iter().filter(|j| j.b.is_none()) {
            let point = if j.kind == JointKind::Distance { j.point_b.unwrap_or(j.point) } else { j.point };
            if points.len() < MAX_PIVOTS + 1 && point.iter().all(|x| x.is_finite()) && !points.contains(&point) {
                points.push(point);
            }
        }
        for point in points {
            for (axis, name) in axes.iter().enumerate() {
                let unit = std::array::from_fn(|i| f64::from(u8::from(i == axis)));
                let mut name = name.replace("linear", "angular");
                if point != [0.0; 3] {
                    name += &format!(" about {point:?}");
                }
                if let Ok(g) = Generator::rotation(&name, &names, unit, point, false) {
                    builder = builder.rotation_candidate(g);
                }
            }
        }
        for (i, body) in self.bodies.iter().enumerate() {
            let b = SpatialBody::of(i);
            builder = builder
                .kinetic_map(Rotation::new(body.inertia), b.euler_parameters())
                .unit_vector(b.euler_parameters());
            rows.push(Part::Body { index: i, name: body.name.clone() });
            if self.gravity != [0.0; 3] {
                let weight = self.gravity.map(|g| g * body.mass);
                builder = builder.potential(Gravity { weight }, [b.first, b.first + 1, b.first + 2]);
            }
        }
        for (index, joint) in self.joints.iter().enumerate() {
            let at = Part::Element { index, kind: joint.kind.name() };
            builder = add_joint(builder, joint, &self.bodies, &poses).map_err(|e| e.at(at.clone()))?;
            rows.extend(std::iter::repeat_n(at, joint.rows()));
        }
        for (k, load) in self.loads.iter().enumerate() {
            let at = Part::Element { index: self.joints.len() + k, kind: load.kind() };
            builder = add_load(builder, load, &poses).map_err(|e| e.at(at))?;
        }
        Ok(Built { model: builder.build()?, q0, v0, rows })
    }
}
