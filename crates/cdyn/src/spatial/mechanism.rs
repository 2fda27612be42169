//! A spatial mechanism — bodies, joints and gravity — turned into a
//! [`Model`] and its initial state.

use super::body::{Body, Rotation};
use super::joint::{BodyToBody, BodyToGround, Frame, Joint, JointKind, JointRows};
use super::load::{BodyRotaryDamper, BodyTorque, GroundRotaryDamper, LineDamper, Load, PointForce, SpringEnergy};
use super::rotation::{cross, rate_from_body, unrotate};
use crate::ad::scalar::Scalar;
use crate::error::{Error, Part, Problem, Result};
use crate::model::angular::Generator;
use crate::model::force::Potential;
use crate::model::{Model, ModelBuilder};
use std::collections::HashMap;

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

/// Where a body's coordinates are: `r` at `first .. first + 3`, `p` at
/// `first + 3 .. first + 7`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
pub struct SpatialBody {
    /// Its first coordinate.
    pub first: usize,
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

impl SpatialBody {
    /// Body `index` of a [`Mechanism`].
    pub fn of(index: usize) -> Self {
        Self { first: 7 * index }
    }
    /// Its centre of mass in `q`.
    pub fn position(&self, q: &[f64]) -> [f64; 3] {
        std::array::from_fn(|i| q[self.first + i])
    }
    /// Its Euler parameters in `q`.
    pub fn orientation(&self, q: &[f64]) -> [f64; 4] {
        std::array::from_fn(|i| q[self.first + 3 + i])
    }
    /// The coordinates of its Euler parameters.
    pub fn euler_parameters(&self) -> [usize; 4] {
        std::array::from_fn(|i| self.first + 3 + i)
    }
    /// All seven coordinates.
    pub fn coordinates(&self) -> [usize; 7] {
        std::array::from_fn(|i| self.first + i)
    }
}

/// How many ground joints' points the builder proposes rotations about.
const MAX_PIVOTS: usize = 4;

/// The names of a body's coordinates: `name.x`, `name.y`, `name.z`, `name.e0` … `name.e3`.
pub fn coordinate_names(name: &str) -> [String; 7] {
    ["x", "y", "z", "e0", "e1", "e2", "e3"].map(|c| format!("{name}.{c}"))
}

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

fn unit(name: &'static str, x: [f64; 3]) -> Result<[f64; 3]> {
    let norm = x.iter().map(|x| x * x).sum::<f64>().sqrt();
    if !(norm.is_finite() && norm > 0.0) {
        return Err(Problem::ZeroAxis { name }.into());
    }
    Ok(x.map(|x| x / norm))
}

/// A right-handed frame `(f, g, h)` with axis `h`.
fn frame_about(h: [f64; 3]) -> [[f64; 3]; 3] {
    // Start from the space axis least aligned with h.
    let k = (0..3).min_by(|&i, &j| h[i].abs().total_cmp(&h[j].abs())).unwrap_or(0);
    let e: [f64; 3] = std::array::from_fn(|i| if i == k { 1.0 } else { 0.0 });
    let f = cross(cross(h, e), h);
    let norm = f.iter().map(|x| x * x).sum::<f64>().sqrt();
    let f = f.map(|x| x / norm);
    [f, cross(h, f), h]
}

impl Mechanism {
    /// An empty mechanism under `gravity`; bodies, joints and loads are
    /// added with [`Mechanism::with_bodies`], [`Mechanism::with_joints`],
    /// [`Mechanism::with_loads`].
    pub fn new(gravity: [f64; 3]) -> Self {
        Self { gravity, ..Self::default() }
    }

    /// A mechanism whose joints name their bodies (`"ground"`, or `b`
    /// omitted, for the ground), as scenario files do.
    pub fn named(
        bodies: Vec<Body>,
        joints: Vec<Joint<String>>,
        loads: Vec<Load<String>>,
        gravity: [f64; 3],
    ) -> Result<Self> {
        let mut index = HashMap::new();
        for (i, body) in bodies.iter().enumerate() {
            let at = || Part::Body { index: i, name: body.name.clone() };
            if body.name.is_empty() || body.name == crate::planar::GROUND {
                return Err(Problem::ReservedName { name: body.name.clone() }.at(at()));
            }
            if index.insert(body.name.as_str(), i).is_some() {
                return Err(Problem::DuplicateName.at(at()));
            }
        }
        let resolve = |key: &'static str, name: &str| match index.get(name) {
            Some(&i) => Ok(Some(i)),
            None if name == crate::planar::GROUND => Ok(None),
            None => Err(Error::from(Problem::UnknownBody { key, name: name.to_string() })),
        };
        let joints = joints
            .into_iter()
            .enumerate()
            .map(|(k, j)| {
                let at = Part::Element { index: k, kind: j.kind.name() };
                let a = resolve("a", &j.a).map_err(|e| e.at(at.clone()))?;
                let b = match &j.b {
                    Some(name) => resolve("b", name).map_err(|e| e.at(at.clone()))?,
                    None => None,
                };
                let Joint { kind, point, axis, axis_b, point_b, angle, displacement, .. } = j;
                match (a, b) {
                    (Some(a), b) => Ok(Joint { kind, a, b, point, axis, axis_b, point_b, angle, displacement }),
                    // `a = "ground"`: the same joint seen from `b`, each
                    // side's point and axis going with its body, and the
                    // drives turned round.
                    (None, Some(b)) => Ok(Joint {
                        kind,
                        a: b,
                        b: None,
                        point: point_b.unwrap_or(point),
                        axis: axis_b.or(axis),
                        axis_b: axis_b.and(axis),
                        point_b: point_b.and(Some(point)),
                        angle: angle.map(negated),
                        displacement: displacement.map(negated),
                    }),
                    (None, None) => Err(Problem::SameBody { body: crate::planar::GROUND.to_string() }.at(at)),
                }
            })
            .collect::<Result<Vec<_>>>()?;
        let ground = || Problem::SameBody { body: crate::planar::GROUND.to_string() };
        let loads = loads
            .into_iter()
            .enumerate()
            .map(|(k, load)| {
                let at = Part::Element { index: joints.len() + k, kind: load.kind() };
                let body = |key, name: &str| resolve(key, name).map_err(|e| e.at(at.clone()));
                let pair = |a: &str, b: &Option<String>| -> Result<(Option<usize>, Option<usize>)> {
                    Ok((body("a", a)?, b.as_deref().map(|b| body("b", b)).transpose()?.flatten()))
                };
                let one = |name: &str| body("body", name)?.ok_or_else(|| Problem::OnGround("loaded").at(at.clone()));
                Ok(match load {
                    Load::Spring { a, b, point, point_b, stiffness, damping, length } => match pair(&a, &b)? {
                        (Some(a), b) => Load::Spring { a, b, point, point_b, stiffness, damping, length },
                        (None, Some(b)) => {
                            Load::Spring { a: b, b: None, point: point_b, point_b: point, stiffness, damping, length }
                        }
                        (None, None) => return Err(ground().at(at)),
                    },
                    Load::RotaryDamper { a, b, axis, damping } => match pair(&a, &b)? {
                        (Some(a), b) => Load::RotaryDamper { a, b, axis, damping },
                        (None, Some(b)) => Load::RotaryDamper { a: b, b: None, axis, damping },
                        (None, None) => return Err(ground().at(at)),
                    },
                    Load::Force { body, force, point } => Load::Force { body: one(&body)?, force, point },
                    Load::Torque { body, torque } => Load::Torque { body: one(&body)?, torque },
                })
            })
            .collect::<Result<Vec<_>>>()?;
        Ok(Self { bodies, joints, gravity, loads })
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
            builder = self.add_joint(builder, joint, &poses).map_err(|e| e.at(at.clone()))?;
            rows.extend(std::iter::repeat_n(at, joint.rows()));
        }
        for (k, load) in self.loads.iter().enumerate() {
            let at = Part::Element { index: self.joints.len() + k, kind: load.kind() };
            builder = add_load(builder, load, &poses).map_err(|e| e.at(at))?;
        }
        Ok(Built { model: builder.build()?, q0, v0, rows })
    }

    fn add_joint(&self, builder: ModelBuilder, joint: &Joint, poses: &[([f64; 3], [f64; 4])]) -> Result<ModelBuilder> {
        let pose = |i: usize| poses.get(i).copied().ok_or(Error::from(Problem::NoSuchBody { index: i }));
        let (ra, pa) = pose(joint.a)?;
        if joint.b == Some(joint.a) {
            return Err(Problem::SameBody { body: self.bodies[joint.a].name.clone() }.into());
        }
        let b = joint.b.map(pose).transpose()?;
        let [wants_axis, wants_axis_b, wants_point_b] = joint.kind.keys();
        let kind = joint.kind.name();
        for (key, wanted, given) in [
            ("axis", wants_axis, joint.axis.is_some()),
            ("axis_b", wants_axis_b, joint.axis_b.is_some()),
            ("point_b", wants_point_b, joint.point_b.is_some()),
        ] {
            if wanted != given {
                return Err(Problem::JointKey { key, kind, wanted }.into());
            }
        }
        let drives = match joint.kind {
            JointKind::Revolute => [true, false],
            JointKind::Prismatic => [false, true],
            JointKind::Cylindrical => [true, true],
            _ => [false, false],
        };
        for (key, allowed, drive) in
            [("angle", drives[0], &joint.angle), ("displacement", drives[1], &joint.displacement)]
        {
            match drive {
                Some(_) if !allowed => return Err(Problem::JointKey { key, kind, wanted: false }.into()),
                Some(f) if !f.is_finite() => return Err(Problem::NonFiniteFunction.into()),
                _ => {}
            }
        }
        let given = joint.point.iter().chain(joint.point_b.iter().flatten());
        if given.clone().any(|x| !x.is_finite()) {
            let value = given.copied().find(|x| !x.is_finite()).unwrap_or(f64::NAN);
            return Err(Problem::Parameter { name: "point", value, reason: "must be finite" }.into());
        }
        let z = frame_about([0.0, 0.0, 1.0]);
        let axes_a = joint.axis.map(|a| unit("axis", a)).transpose()?;
        let axes_b = joint.axis_b.map(|a| unit("axis_b", a)).transpose()?;
        let (axes_a, axes_b) = match (axes_a, axes_b) {
            (Some(ha), Some(hb)) => {
                let c = ha[0] * hb[0] + ha[1] * hb[1] + ha[2] * hb[2];
                if c.abs() > 1e-9 {
                    return Err(Problem::Parameter {
                        name: "axis · axis_b",
                        value: c,
                        reason: "must be 0: a universal joint's axes are perpendicular",
                    }
                    .into());
                }
                (frame_about(ha), frame_about(hb))
            }
            (Some(h), None) => (frame_about(h), frame_about(h)),
            _ => (z, z),
        };
        let point_b = joint.point_b.unwrap_or(joint.point);
        let d: [f64; 3] = std::array::from_fn(|i| point_b[i] - joint.point[i]);
        let length2 = d.iter().map(|x| x * x).sum::<f64>();
        if joint.kind == JointKind::Distance && length2 == 0.0 {
            return Err(Problem::Parameter {
                name: "length",
                value: 0.0,
                reason: "must be positive: point_b must differ from point",
            }
            .into());
        }
        let in_body = |(r, p): ([f64; 3], [f64; 4]), point: [f64; 3], axes: [[f64; 3]; 3]| Frame {
            s: unrotate(p, std::array::from_fn(|i| point[i] - r[i])),
            axes: axes.map(|x| unrotate(p, x)),
        };
        let fa = in_body((ra, pa), joint.point, axes_a);
        let fb = match b {
            Some(pose) => in_body(pose, point_b, axes_b),
            None => Frame { s: point_b, axes: axes_b },
        };
        let a_at = SpatialBody::of(joint.a).coordinates();
        macro_rules! add {
            ($r:literal) => {{
                let rows = JointRows::<$r> {
                    kind: joint.kind,
                    a: fa,
                    b: fb,
                    length2,
                    angle: joint.angle.clone(),
                    displacement: joint.displacement.clone(),
                };
                match joint.b {
                    Some(jb) => {
                        let b_at = SpatialBody::of(jb).coordinates();
                        let at: [usize; 14] = std::array::from_fn(|i| if i < 7 { a_at[i] } else { b_at[i - 7] });
                        builder.constrain(BodyToBody(rows), at)
                    }
                    None => builder.constrain(BodyToGround(rows), a_at),
                }
            }};
        }
        Ok(match joint.rows() {
            1 => add!(1),
            3 => add!(3),
            4 => add!(4),
            5 => add!(5),
            _ => add!(6),
        })
    }
}

/// `−f(t)`: a drive seen from the other body.
fn negated(f: crate::model::timefn::TimeFn) -> crate::model::timefn::TimeFn {
    crate::model::timefn::TimeFn {
        polynomial: f.polynomial.iter().map(|c| -c).collect(),
        sines: f.sines.iter().map(|&[a, w, phase]| [-a, w, phase]).collect(),
    }
}

/// A body point given in space at the initial pose, in the body's axes.
fn in_body((r, p): ([f64; 3], [f64; 4]), point: [f64; 3]) -> [f64; 3] {
    unrotate(p, std::array::from_fn(|i| point[i] - r[i]))
}

/// Adds the elements of one load.
fn add_load(builder: ModelBuilder, load: &Load, poses: &[([f64; 3], [f64; 4])]) -> Result<ModelBuilder> {
    let pose = |i: usize| poses.get(i).copied().ok_or(Error::from(Problem::NoSuchBody { index: i }));
    let finite = |name: &'static str, x: &[f64]| match x.iter().find(|x| !x.is_finite()) {
        Some(&value) => Err(Error::from(Problem::Parameter { name, value, reason: "must be finite" })),
        None => Ok(()),
    };
    Ok(match *load {
        Load::Spring { a, b, point, point_b, stiffness, damping, length } => {
            crate::error::non_negative("stiffness", stiffness)?;
            crate::error::non_negative("damping", damping)?;
            finite("point", &point)?;
            finite("point_b", &point_b)?;
            let initial = (0..3).map(|i| (point_b[i] - point[i]).powi(2)).sum::<f64>().sqrt();
            let length = match length {
                Some(l) => crate::error::non_negative("length", l)?,
                None => initial,
            };
            if initial == 0.0 {
                let reason = "must differ from point: a spring needs a line";
                return Err(Problem::Parameter { name: "point_b", value: 0.0, reason }.into());
            }
            let sa = in_body(pose(a)?, point);
            let a_at = SpatialBody::of(a).coordinates();
            match b {
                Some(b) => {
                    let sb = in_body(pose(b)?, point_b);
                    let b_at = SpatialBody::of(b).coordinates();
                    let at: [usize; 14] = std::array::from_fn(|i| if i < 7 { a_at[i] } else { b_at[i - 7] });
                    let builder = builder.potential(SpringEnergy { sa, sb, ground: false, k: stiffness, length }, at);
                    if damping > 0.0 {
                        builder.force(LineDamper { sa, sb, ground: false, c: damping }, at)
                    } else {
                        builder
                    }
                }
                None => {
                    let spring = SpringEnergy { sa, sb: point_b, ground: true, k: stiffness, length };
                    let builder = builder.potential(spring, a_at);
                    if damping > 0.0 {
                        builder.force(LineDamper { sa, sb: point_b, ground: true, c: damping }, a_at)
                    } else {
                        builder
                    }
                }
            }
        }
        Load::RotaryDamper { a, b, axis, damping } => {
            crate::error::non_negative("damping", damping)?;
            let axis = unit("axis", axis)?;
            let (_, pa) = pose(a)?;
            let a_at = SpatialBody::of(a).euler_parameters();
            match b {
                Some(b) => {
                    pose(b)?;
                    let b_at = SpatialBody::of(b).euler_parameters();
                    let at: [usize; 8] = std::array::from_fn(|i| if i < 4 { a_at[i] } else { b_at[i - 4] });
                    builder.force(BodyRotaryDamper { axis: unrotate(pa, axis), c: damping }, at)
                }
                None => builder.force(GroundRotaryDamper { axis, c: damping }, a_at),
            }
        }
        Load::Force { body, force, point } => {
            finite("force", &force)?;
            let (r, p) = pose(body)?;
            let point = point.unwrap_or(r);
            finite("point", &point)?;
            builder.force(PointForce { s: in_body((r, p), point), f: force }, SpatialBody::of(body).coordinates())
        }
        Load::Torque { body, torque } => {
            finite("torque", &torque)?;
            pose(body)?;
            builder.force(BodyTorque { n: torque }, SpatialBody::of(body).euler_parameters())
        }
    })
}
