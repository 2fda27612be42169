//! A spatial mechanism — bodies, joints and gravity — turned into a
//! [`Model`] and its initial state.

use super::actuator::Actuator;
use super::body::{Body, Rotation, SpatialBody, coordinate_names};
use super::coordinate::{JointCoordinate, JointSpace, Mimic, StopRow};
use super::joint::{Joint, JointKind};
use super::load::Load;
use super::placing::{add_joint, add_load, joint_frames};
use super::rotation::rate_from_body;
use super::visual::Visual;
use crate::ad::scalar::Scalar;
use crate::error::{Part, Problem, Result};
use crate::limit::Stop;
use crate::model::angular::Generator;
use crate::model::force::Potential;
use crate::model::{Model, ModelBuilder};

/// Bodies, joints and uniform gravity.
///
/// A rod hanging from a spherical joint at the origin, started off the
/// vertical: seven coordinates, the joint's three rows and the Euler
/// parameters' normalization:
///
/// ```
/// use cdyn::spatial::{Body, Joint, JointKind, Mechanism};
/// use cdyn::{Control, Scheme, Settings, Simulation};
///
/// let rod = Body::new("rod", 1.0, [0.08, 0.08, 0.01]).with_position([0.3, 0.0, -0.4]);
/// let pivot = Joint::new(JointKind::Spherical, 0, None, [0.0; 3]);
/// let built = Mechanism::new([0.0, 0.0, -9.81]).with_bodies(vec![rod]).with_joints(vec![pivot]).build()?;
/// assert_eq!((built.model.n(), built.model.m()), (7, 4));
/// let settings = Settings::new(Scheme::RungeKutta4, 1e-3, Control::robust());
/// let mut sim = Simulation::new(&built.model, settings, &built.q0, &built.v0)?;
/// sim.run::<cdyn::Error>(0.05, 10, |_| Ok(()))?;
/// assert!(sim.measure().phi.abs() < 1e-9 && sim.q()[0] < 0.3); // swinging back towards the vertical
/// # Ok::<(), cdyn::Error>(())
/// ```
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
    /// Joints whose coordinates are tied (URDF's `<mimic>`).
    pub couplings: Vec<Coupling>,
    /// Torques (forces) on revolute (prismatic) joints.
    pub actuators: Vec<Actuator>,
    /// What the ground looks like in 3-D views: shapes placed in space (a
    /// robot's base, welded to the ground, is part of it).
    pub ground: Vec<Visual>,
}

/// A `<mimic>` coupling, one constraint row: joint `follower`'s coordinate
/// kept at `multiplier ×` joint `leader`'s `+ offset` (both revolute or
/// prismatic; coordinates as in [`Mechanism::joint_coordinates`]).
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub struct Coupling {
    /// The joint that follows (an index into [`Mechanism::joints`]).
    pub follower: usize,
    /// The joint it follows.
    pub leader: usize,
    /// `m`
    pub multiplier: f64,
    /// `o`
    pub offset: f64,
}

impl Coupling {
    /// Joint `follower` kept at `multiplier ×` joint `leader`'s coordinate `+ offset`.
    pub fn new(follower: usize, leader: usize, multiplier: f64, offset: f64) -> Self {
        Self { follower, leader, multiplier, offset }
    }
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
    /// The part behind each force element, in the order the model counts
    /// them ([`Model::most_dissipating`]): a joint's damping and friction,
    /// a load.
    pub forces: Vec<Part>,
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
    /// With these couplings of joint coordinates.
    with_couplings => couplings: Vec<Coupling>,
    /// With these joint actuators.
    with_actuators => actuators: Vec<Actuator>,
    /// With these shapes drawn on the ground (in space).
    with_ground => ground: Vec<Visual>,
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
        self.build_holding(&[])
    }

    /// [`Mechanism::build`] with the stops `held` as rows `g = 0` after all
    /// others, in that order (see [`Mechanism::stops`]).
    pub fn build_holding(&self, held: &[Stop]) -> Result<Built> {
        if self.bodies.is_empty() {
            return Err(Problem::NoBodies.into());
        }
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
        let (mut rows, mut forces) = (Vec::new(), Vec::new());
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
            if let Some(limit) = &joint.limit {
                limit.check().map_err(|e| e.at(at.clone()))?;
                self.coordinate(index, &poses).map_err(|e| e.at(at.clone()))?;
            }
            let before = builder.force_elements();
            builder = add_joint(builder, joint, &self.bodies, &poses).map_err(|e| e.at(at.clone()))?;
            forces.extend(std::iter::repeat_n(at.clone(), builder.force_elements() - before));
            rows.extend(std::iter::repeat_n(at, joint.rows()));
        }
        for (k, load) in self.loads.iter().enumerate() {
            let at = Part::Element { index: self.joints.len() + k, kind: load.kind() };
            let before = builder.force_elements();
            builder = add_load(builder, load, &poses).map_err(|e| e.at(at.clone()))?;
            forces.extend(std::iter::repeat_n(at, builder.force_elements() - before));
        }
        for (k, coupling) in self.couplings.iter().enumerate() {
            let at = Part::Element { index: self.joints.len() + self.loads.len() + k, kind: "mimic" };
            builder = self.add_coupling(builder, coupling, &poses).map_err(|e| e.at(at.clone()))?;
            rows.push(at);
        }
        builder = self.add_actuators(builder, &poses, &mut forces)?;
        for &stop in held {
            let at = Part::Element { index: stop.joint, kind: "limit" };
            builder = self.add_stop(builder, stop, &poses).map_err(|e| e.at(at.clone()))?;
            rows.push(at);
        }
        Ok(Built { model: builder.build()?, q0, v0, rows, forces })
    }

    /// Joint `index`'s coordinate and its sides, for a revolute or prismatic joint.
    pub(super) fn coordinate(&self, index: usize, poses: &[Pose]) -> Result<JointCoordinate> {
        let joint = self.joints.get(index).ok_or(Problem::NoSuchJoint { index })?;
        let rotary = match joint.kind {
            JointKind::Revolute => true,
            JointKind::Prismatic => false,
            other => return Err(Problem::NoCoordinate { index, kind: other.name() }.into()),
        };
        let (a, b) = joint_frames(joint, &self.bodies, poses)?;
        Ok(JointCoordinate { rotary, a, b })
    }

    fn add_stop(&self, builder: ModelBuilder, stop: Stop, poses: &[Pose]) -> Result<ModelBuilder> {
        let coordinate = self.coordinate(stop.joint, poses)?;
        let (bound, sign, _) = self.stop_bound(stop);
        let row = StopRow { coordinate, bound, sign };
        Ok(match reads(&self.joints[stop.joint]) {
            Reads::Ground(at) => builder.constrain(row, at),
            Reads::Bodies(at) => builder.constrain(row, at),
        })
    }

    fn add_coupling(&self, builder: ModelBuilder, c: &Coupling, poses: &[Pose]) -> Result<ModelBuilder> {
        for (name, value) in [("multiplier", c.multiplier), ("offset", c.offset)] {
            crate::error::finite(name, value)?;
        }
        let (follower, leader) = (self.coordinate(c.follower, poses)?, self.coordinate(c.leader, poses)?);
        // The distinct bodies of both joints, and each side's slot among them.
        let mut bodies: Vec<usize> = Vec::with_capacity(4);
        let mut slot = |body: Option<usize>| {
            body.map(|i| {
                bodies.iter().position(|&b| b == i).unwrap_or_else(|| {
                    bodies.push(i);
                    bodies.len() - 1
                })
            })
        };
        let sides = |j: &Joint, slot: &mut dyn FnMut(Option<usize>) -> Option<usize>| [slot(Some(j.a)), slot(j.b)];
        let (fj, lj) = (&self.joints[c.follower], &self.joints[c.leader]);
        let follower = (follower, sides(fj, &mut slot));
        let leader = (leader, sides(lj, &mut slot));
        let mimic = Mimic { follower, leader, multiplier: c.multiplier, offset: c.offset };
        let coordinates: Vec<usize> = bodies.iter().flat_map(|&b| SpatialBody::of(b).coordinates()).collect();
        Ok(crate::with_const!(coordinates.len(), K, [7, 14, 21, 28], {
            builder.constrain(mimic, <[usize; K]>::try_from(coordinates.as_slice()).expect("K coordinates"))
        }))
    }

    /// The coordinate `θ` of every revolute and prismatic joint (`None` for
    /// the others) at the state `(q, v)` with accelerations `a`: `(θ, θ̇, θ̈)`,
    /// the angle of `a` relative to `b` about the axis or the displacement
    /// along it, from the initial pose, as URDF counts them. An angle is
    /// in `(−π, π]`, but for a joint whose limit is shorter than a turn,
    /// in that range (or past its nearer bound: `[lower, lower + 2π)`
    /// split halfway between the bounds; Panda's joint 6 turns from −0.0175
    /// to 3.75 rad), as its stops read it (a range of a turn or more's stops
    /// follow the joint's turns: [`crate::stops`]). One place for joint-space output
    /// (the CSV, `summary.json`, the C API, the FMU, Python), for the stops
    /// and for tests against joint-space dynamics.
    pub fn joint_coordinates(&self, q: &[f64], v: &[f64], a: &[f64]) -> Result<Vec<Option<[f64; 3]>>> {
        let n = 7 * self.bodies.len();
        if q.len() != n || v.len() != n || a.len() != n {
            let (positions, velocities) = (q.len(), v.len());
            return Err(Problem::StateLength { positions, velocities, n }.into());
        }
        let space = self.joint_space()?;
        let mut out = vec![None; self.joints.len()];
        for (i, joint) in space.joints().enumerate() {
            out[joint] = Some(space.at(i, q, v, a));
        }
        Ok(out)
    }

    /// The reader of every revolute and prismatic joint's coordinate (see
    /// [`Mechanism::joint_coordinates`]), for reading them at many states.
    pub fn joint_space(&self) -> Result<JointSpace> {
        let poses = self.poses()?;
        let read = (0..self.joints.len()).filter_map(|k| {
            let c = self.coordinate(k, &poses).ok()?;
            Some((k, c, self.joints[k].a, self.joints[k].b, self.joints[k].limit))
        });
        Ok(JointSpace::new(read))
    }

    /// Each body's initial pose, its orientation checked.
    pub(super) fn poses(&self) -> Result<Vec<Pose>> {
        self.bodies
            .iter()
            .enumerate()
            .map(|(i, body)| {
                let p = body.check().map_err(|e| e.at(Part::Body { index: i, name: body.name.clone() }))?;
                Ok((body.position, p))
            })
            .collect()
    }
}

/// The coordinates an element on one joint reads: its body `a`'s, or `a`'s then `b`'s.
pub(super) enum Reads {
    Ground([usize; 7]),
    Bodies([usize; 14]),
}

pub(super) fn reads(j: &Joint) -> Reads {
    let a = SpatialBody::of(j.a).coordinates();
    match j.b {
        None => Reads::Ground(a),
        Some(b) => {
            let b = SpatialBody::of(b).coordinates();
            Reads::Bodies(std::array::from_fn(|i| if i < 7 { a[i] } else { b[i - 7] }))
        }
    }
}

/// A body's position and unit orientation.
pub(super) type Pose = ([f64; 3], [f64; 4]);
