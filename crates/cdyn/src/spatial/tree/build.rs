//! A mechanism's tree and its model in joint coordinates, with what the
//! formulation does not model yet refused by name.

use super::dynamics::TreeKinetic;
use super::elements::{Actuated, Bound, Coupled, Driven};
use super::gravity::TreeGravity;
use super::loads::{BodyTorque, LineDamper, Path, PointForce, RotaryDamper, SpringEnergy, Step};
use super::motion::{Inertia, M3};
use super::{BodyPoses, Node, Shared, Tree};
use crate::error::{Error, Part, Problem, Result};
use crate::limit::Stop;
use crate::model::force::PotentialBlock;
use crate::model::timefn::TimeFn;
use crate::model::{Model, ModelBuilder};
use crate::spatial::actuator::Law;
use crate::spatial::joint::{Joint, JointKind};
use crate::spatial::load::Load;
use crate::spatial::mechanism::Mechanism;
use crate::spatial::placing::{checked_load, joint_law};
use crate::spatial::posing::line;
use crate::spatial::rotation::rotate;
use std::sync::Arc;

/// A mechanism in joint coordinates ([`Mechanism::in_joint_coordinates`]):
/// its model, the initial state, and the joint behind each coordinate.
#[non_exhaustive]
pub struct InJoints {
    /// The model: coordinate `k` is joint `joints[k]`'s angle (displacement).
    pub model: Model,
    /// The pose the mechanism is defined in, all coordinates 0 but a driven
    /// joint's, at its drive's `f(0)`.
    pub q0: Vec<f64>,
    /// All rates 0 but a driven joint's, `ḟ(0)`.
    pub v0: Vec<f64>,
    /// The mechanism's joint of each coordinate, in joint order.
    pub joints: Vec<usize>,
    /// The reader of the bodies' poses at joint coordinates.
    pub poses: BodyPoses,
    /// The reader of the actuators' torques.
    pub torques: CoordinateTorques,
    /// The part behind each constraint row (drives, couplings, held stops).
    pub rows: Vec<Part>,
    /// The part behind each force element (joints' damping and friction, actuators).
    pub forces: Vec<Part>,
}

/// The torque (force) each actuator of a tree applies, read from its joint coordinates.
#[derive(Debug, Clone)]
pub struct CoordinateTorques(Vec<(usize, Law)>);

impl CoordinateTorques {
    /// The torque actuator `i` applies at `(θ, θ̇)` and time `t`.
    pub fn at(&self, i: usize, q: &[f64], v: &[f64], t: f64) -> f64 {
        let (c, law) = &self.0[i];
        law.torque(t, |target| q[*c] - target, || v[*c])
    }
}

impl InJoints {
    /// The bodies' positions and velocities in the mechanism's own
    /// coordinates (seven per body, as [`Mechanism::build`] has them) at
    /// joint coordinates `theta` and rates `rate`.
    pub fn bodies(&self, mechanism: &Mechanism, theta: &[f64], rate: &[f64]) -> Result<(Vec<f64>, Vec<f64>)> {
        let pairs = |x: &[f64]| self.joints.iter().copied().zip(x.iter().copied()).collect::<Vec<_>>();
        mechanism.state_at_joints(&pairs(theta), &pairs(rate))
    }
}

/// Runs `$body` with the const `$k` the number of coordinates `$at` (1 to [`LOAD_REACH`]).
macro_rules! by_reach {
    ($at:expr, $k:ident, $body:expr) => {
        crate::with_const!($at.len(), $k, [1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12], $body)
    };
}

fn refuse(part: Part, reason: impl Into<String>) -> Error {
    Problem::JointCoordinates { reason: reason.into() }.at(part)
}

impl Mechanism {
    /// The mechanism in joint coordinates: one per revolute and prismatic
    /// joint, in joint order, counted from the pose it is defined in.
    /// Its joints must form a tree on the ground (each body held to the
    /// ground by one path of joints); bodies welded by fixed joints ride
    /// with their parent, and those welded to the ground are ground. The
    /// joints' damping and friction and `<mimic>` couplings (one row
    /// each), drives (a row `θ − f(t)` each, the joint started at `f(0)`,
    /// `ḟ(0)`), actuators (a torque on the coordinate; a servo's error is
    /// `θ − θ_ref` itself, turns counted), loads (on the coordinates of
    /// their bodies' paths) and limits as stops
    /// ([`TreeStops`](crate::stops::TreeStops)); bodies' own initial
    /// velocities are refused, by name.
    pub fn in_joint_coordinates(&self) -> Result<InJoints> {
        self.in_joint_coordinates_holding(&[])
    }

    /// [`Mechanism::in_joint_coordinates`] with the stops `held` as rows
    /// `g = s (θ − bound) = 0` after all others, in that order.
    pub fn in_joint_coordinates_holding(&self, held: &[Stop]) -> Result<InJoints> {
        if self.bodies.is_empty() {
            return Err(Problem::NoBodies.into());
        }
        let poses = self.poses()?;
        self.refuse_what_is_not_modelled()?;
        let edges = self.spanning_tree();
        let mut joined = vec![false; self.bodies.len()];
        for e in &edges {
            joined[e.beyond] = true;
        }
        if let Some(k) = joined.iter().position(|&j| !j) {
            let part = Part::Body { index: k, name: self.bodies[k].name.clone() };
            return Err(refuse(part, "the body is not joined to the ground (the tree needs a fixed base)"));
        }
        if let Some(index) = (0..self.joints.len()).find(|&k| !edges.iter().any(|e| e.joint == k)) {
            let part = Part::Element { index, kind: self.joints[index].kind.name() };
            return Err(refuse(part, "the joint closes a loop (the bodies' joints must form a tree)"));
        }
        let moving = |k: usize| matches!(self.joints[k].kind, JointKind::Revolute | JointKind::Prismatic);
        let joints: Vec<usize> = (0..self.joints.len()).filter(|&k| moving(k)).collect();
        if joints.is_empty() {
            return Err(refuse(Part::Model, "no revolute or prismatic joint: nothing moves"));
        }
        // The node carrying each body, parents first.
        let mut carrier: Vec<Option<usize>> = vec![None; self.bodies.len()];
        let mut nodes: Vec<Node> = Vec::with_capacity(joints.len());
        for e in &edges {
            let parent = e.before.and_then(|b| carrier[b]);
            if !moving(e.joint) {
                carrier[e.beyond] = parent;
                continue;
            }
            let joint = &self.joints[e.joint];
            if joint.axis.is_none_or(|a| a == [0.0; 3] || a.iter().any(|x| !x.is_finite())) {
                return Err(
                    Problem::ZeroAxis { name: "axis" }.at(Part::Element { index: e.joint, kind: joint.kind.name() })
                );
            }
            let (point, axis) = line(joint);
            nodes.push(Node {
                parent,
                coordinate: joints.iter().position(|&k| k == e.joint).expect("a moving joint"),
                rotary: joint.kind == JointKind::Revolute,
                axis: axis.map(|x| e.sign * x),
                point,
                inertia: Inertia::default(),
            });
            carrier[e.beyond] = Some(nodes.len() - 1);
        }
        for (k, body) in self.bodies.iter().enumerate() {
            if let Some(t) = carrier[k] {
                let p = poses[k].1;
                // R J′ Rᵀ, with R's columns the body axes in space.
                let columns: [[f64; 3]; 3] =
                    std::array::from_fn(|j| rotate(p, std::array::from_fn(|i| f64::from(u8::from(i == j)))));
                let rj: M3 = std::array::from_fn(|i| {
                    std::array::from_fn(|l| (0..3).map(|m| columns[m][i] * body.inertia[m][l]).sum())
                });
                let world: M3 =
                    std::array::from_fn(|i| std::array::from_fn(|l| (0..3).map(|m| rj[i][m] * columns[m][l]).sum()));
                nodes[t].inertia = nodes[t].inertia.plus(&Inertia::of_body(body.mass, body.position, world));
            }
        }
        let n = joints.len();
        let bodies = self.bodies.iter().zip(&carrier).zip(&poses).map(|((_, &c), &(r, p))| (c, r, p)).collect();
        let shared = Arc::new(Shared::new(Tree { nodes, n, bodies }));
        let gravity = (self.gravity != [0.0; 3]).then(|| {
            Box::new(TreeGravity { shared: shared.clone(), gravity: self.gravity }) as Box<dyn PotentialBlock>
        });
        let names = joints.iter().map(|k| format!("joint {k}")).collect();
        let mut builder =
            Model::builder(vec![0.0; n]).coordinate_names(names).whole(Box::new(TreeKinetic(shared.clone())), gravity);
        let (mut q0, mut v0) = (vec![0.0; n], vec![0.0; n]);
        let (mut rows, mut forces) = (Vec::new(), Vec::new());
        for (c, &k) in joints.iter().enumerate() {
            let at = Part::Element { index: k, kind: self.joints[k].kind.name() };
            if let Some(law) = joint_law(&self.joints[k]).map_err(|e| e.at(at.clone()))? {
                builder = builder.force(law, [c]);
                forces.push(at.clone());
            }
            if let Some(f) = drive(&self.joints[k]).map_err(|e| e.at(at))? {
                // Started where the drive has it: the row holds from t = 0.
                (q0[c], v0[c]) = (f.eval(0.0), f.derivative().eval(0.0));
                builder = builder.constrain(Driven(f.clone()), [c]);
                rows.push(Part::Element { index: k, kind: self.joints[k].kind.name() });
            }
        }
        builder = self.declare_inputs(builder);
        let mut actuators = Vec::with_capacity(self.actuators.len());
        for (k, actuator) in self.actuators.iter().enumerate() {
            let at = self.actuator_part(k);
            let joint = self.joints.get(actuator.joint).ok_or(Problem::NoSuchJoint { index: actuator.joint });
            let joint = joint.map_err(|e| Error::from(e).at(at.clone()))?;
            let Some(c) = joints.iter().position(|&j| j == actuator.joint) else {
                let kind = joint.kind.name();
                return Err(Error::from(Problem::NoCoordinate { index: actuator.joint, kind }).at(at));
            };
            let law = actuator.law(joint.limit.map_or(f64::INFINITY, |l| l.effort)).map_err(|e| e.at(at))?;
            builder = builder.force(Actuated(law.clone()), [c]);
            forces.push(self.actuator_part(k));
            actuators.push((c, law));
        }
        for (k, load) in self.loads.iter().enumerate() {
            let at = Part::Element { index: self.joints.len() + k, kind: load.kind() };
            let before = builder.force_elements();
            builder = add_load(
                builder,
                &checked_load(load, &poses).map_err(|e| e.at(at.clone()))?,
                &shared.tree.nodes,
                &carrier,
            )
            .map_err(|e| e.at(at.clone()))?;
            forces.extend(std::iter::repeat_n(at, builder.force_elements() - before));
        }
        for (k, coupling) in self.couplings.iter().enumerate() {
            let at = Part::Element { index: self.joints.len() + self.loads.len() + k, kind: "mimic" };
            let coordinate = |joint: usize| {
                joints.iter().position(|&j| j == joint).ok_or_else(|| {
                    let kind = self.joints.get(joint).map_or("missing", |j| j.kind.name());
                    Error::from(Problem::NoCoordinate { index: joint, kind }).at(at.clone())
                })
            };
            let (f, l) = (coordinate(coupling.follower)?, coordinate(coupling.leader)?);
            for (name, value) in [("multiplier", coupling.multiplier), ("offset", coupling.offset)] {
                crate::error::finite(name, value).map_err(|e| e.at(at.clone()))?;
            }
            builder = builder.constrain(Coupled { multiplier: coupling.multiplier, offset: coupling.offset }, [f, l]);
            rows.push(at);
        }
        for &stop in held {
            let at = Part::Element { index: stop.joint, kind: "limit" };
            let Some(c) =
                joints.iter().position(|&j| j == stop.joint).filter(|_| self.joints[stop.joint].limit.is_some())
            else {
                return Err(Error::from(Problem::NoSuchJoint { index: stop.joint }).at(at));
            };
            let (bound, sign, _) = self.stop_bound(stop);
            builder = builder.constrain(Bound { bound, sign }, [c]);
            rows.push(at);
        }
        Ok(InJoints {
            model: builder.build()?,
            q0,
            v0,
            joints,
            poses: BodyPoses::new(&shared),
            torques: CoordinateTorques(actuators),
            rows,
            forces,
        })
    }

    fn refuse_what_is_not_modelled(&self) -> Result<()> {
        for (index, body) in self.bodies.iter().enumerate() {
            if body.velocity != [0.0; 3] || body.angular_velocity != [0.0; 3] {
                let part = Part::Body { index, name: body.name.clone() };
                return Err(refuse(part, "a body's own velocity is not read: start the joints at their rates"));
            }
        }
        for (index, joint) in self.joints.iter().enumerate() {
            let part = Part::Element { index, kind: joint.kind.name() };
            let reason = match joint.kind {
                JointKind::Revolute | JointKind::Prismatic | JointKind::Fixed => None,
                kind => Some(format!("a {} joint has more or less than one coordinate", kind.name())),
            };
            if let Some(reason) = reason {
                return Err(refuse(part, reason));
            }
            if let Some(&value) = joint.point.iter().find(|x| !x.is_finite()) {
                return Err(Problem::Parameter { name: "point", value, reason: "must be finite" }.at(part));
            }
            if let Some(limit) = &joint.limit {
                limit.check().map_err(|e| e.at(part))?;
            }
        }
        Ok(())
    }
}

/// The most joint coordinates one load may reach (the union of its bodies' paths).
const LOAD_REACH: usize = 12;

/// Adds one checked load's elements on the coordinates of its bodies' paths
/// (`carrier`: each body's node; `nodes` the tree's, parents first).
fn add_load(builder: ModelBuilder, load: &Load, nodes: &[Node], carrier: &[Option<usize>]) -> Result<ModelBuilder> {
    let mut coordinates: Vec<usize> = Vec::new();
    let mut path = |body: Option<usize>| -> Path {
        let mut chain = Vec::new();
        let mut at = body.and_then(|b| carrier[b]);
        while let Some(t) = at {
            chain.push(t);
            at = nodes[t].parent;
        }
        chain
            .into_iter()
            .rev()
            .map(|t| {
                let node = &nodes[t];
                let slot = coordinates.iter().position(|&c| c == node.coordinate).unwrap_or_else(|| {
                    coordinates.push(node.coordinate);
                    coordinates.len() - 1
                });
                Step { rotary: node.rotary, axis: node.axis, point: node.point, slot }
            })
            .collect()
    };
    enum Element {
        Spring(SpringEnergy, Option<LineDamper>),
        Rotary(RotaryDamper),
        Force(PointForce),
        Torque(BodyTorque),
    }
    let element = match load.clone() {
        Load::Spring { a, b, point, point_b, stiffness, damping, length } => {
            let (pa, pb) = (path(Some(a)), path(b));
            let points = [point, point_b];
            let damper = (damping > 0.0).then(|| LineDamper { a: pa.clone(), b: pb.clone(), points, c: damping });
            Element::Spring(
                SpringEnergy { a: pa, b: pb, points, k: stiffness, length: length.unwrap_or_default() },
                damper,
            )
        }
        Load::RotaryDamper { a, b, axis, damping } => {
            Element::Rotary(RotaryDamper { a: path(Some(a)), b: path(b), axis, c: damping, ground: b.is_none() })
        }
        Load::Force { body, force, point } => {
            Element::Force(PointForce { body: path(Some(body)), point: point.unwrap_or_default(), force })
        }
        Load::Torque { body, torque } => Element::Torque(BodyTorque { body: path(Some(body)), torque }),
    };
    if coordinates.is_empty() {
        // Every body it acts on is welded to the ground: it does no work.
        return Ok(builder);
    }
    if coordinates.len() > LOAD_REACH {
        let reason = format!("a load on bodies {} joints from the ground (at most {LOAD_REACH})", coordinates.len());
        return Err(Problem::JointCoordinates { reason }.into());
    }
    let at = coordinates.as_slice();
    Ok(match element {
        Element::Spring(spring, damper) => {
            let builder = by_reach!(at, K, builder.potential(spring, at_k::<K>(at)));
            match damper {
                Some(d) => by_reach!(at, K, builder.force(d, at_k::<K>(at))),
                None => builder,
            }
        }
        Element::Rotary(e) => by_reach!(at, K, builder.force(e, at_k::<K>(at))),
        Element::Force(e) => by_reach!(at, K, builder.force(e, at_k::<K>(at))),
        Element::Torque(e) => by_reach!(at, K, builder.force(e, at_k::<K>(at))),
    })
}

fn at_k<const K: usize>(at: &[usize]) -> [usize; K] {
    std::array::from_fn(|i| at[i])
}

/// A joint's drive, checked: an angle on a revolute joint, a displacement
/// on a prismatic one, finite; none on a fixed one.
fn drive(joint: &Joint) -> Result<Option<&TimeFn>> {
    let kind = joint.kind.name();
    let (own, other, key) = match joint.kind {
        JointKind::Revolute => (&joint.angle, &joint.displacement, "displacement"),
        JointKind::Prismatic => (&joint.displacement, &joint.angle, "angle"),
        _ => (&None, &joint.angle, "angle"),
    };
    if other.is_some() {
        return Err(Problem::JointKey { key, kind, wanted: false }.into());
    }
    match own {
        Some(f) if !f.is_finite() => Err(Problem::NonFiniteFunction.into()),
        f => Ok(f.as_ref()),
    }
}
