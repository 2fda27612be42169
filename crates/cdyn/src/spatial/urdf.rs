//! A URDF robot as a spatial [`Mechanism`], in redundant coordinates.
//!
//! Every link with a mass becomes a body, named after the link, with its
//! centre of mass, body axes and inertia from its `<inertial>`, at the pose
//! where every joint is at 0. The root link is the ground (a fixed base).
//! Joints become joints at their origin: `revolute` and `continuous` →
//! revolute, `prismatic` → prismatic, `fixed` → fixed (a weld), `floating`
//! → none (a free body); their `<dynamics damping friction>` become the
//! joint's viscous damping and (regularized) Coulomb friction, and a
//! `<mimic>` a [`Coupling`] of the two joints' coordinates. A link's
//! `<visual>` boxes, cylinders and spheres are what its body looks like in
//! 3-D views (meshes are not read: a body without primitive visuals is
//! drawn as the box of its inertia).
//!
//! A link welded by a `fixed` joint to a link that moves is merged into
//! that link's body (its mass, centre of mass and inertia added to the
//! body's): one rigid body, not two held together by six rows (Kinova's
//! fingers, Panda's hand). A link welded to the root (a base link) is part
//! of the ground, as Pinocchio and MuJoCo take it; its visuals, or the box
//! of its inertia if it has none but meshes, are drawn on the ground
//! ([`Mechanism::ground`]). Joints and loads of a scenario may name a
//! merged link ([`UrdfRobot::merged`]). Refused, with the element named: a moved
//! link that has no mass or no usable inertia even then, `planar` and
//! `spherical` joints, a `<mimic>` of a joint that is not revolute or
//! prismatic, a zero axis on a moving joint, and several root links.
//!
//! A revolute or prismatic joint's `<limit>` becomes its [`JointLimit`]
//! (checked: NaN or inverted bounds are refused, naming the joint), held
//! by a run with stops ([`crate::stops`], as `cdyn run` runs it).
//!
//! Not modelled, and listed in [`UrdfRobot::notes`] (a run prints them on
//! one line): collision and contact, transmissions, Gazebo extensions,
//! safety controllers, calibration. A limit's effort bound clamps the
//! joint's actuator where the scenario gives it one ([`super::Actuator`]).

use super::body::Body;
use super::joint::{Joint, JointKind};
use super::mechanism::{Coupling, Mechanism};
use super::named::MergedLink;
use super::rotation::{about, compose, rotate, unrotate};
use super::visual::{Shape, Visual};
use crate::error::{Error, Part, Problem, Result};
use crate::limit::JointLimit;
use std::collections::HashMap;

/// A pose: position and unit quaternion.
type Pose = ([f64; 3], [f64; 4]);

/// Space's own axes, as a pose.
const SPACE: Pose = ([0.0; 3], [1.0, 0.0, 0.0, 0.0]);

/// `R = Rz(yaw) Ry(pitch) Rx(roll)`, URDF's convention, as a quaternion.
fn rpy([roll, pitch, yaw]: [f64; 3]) -> [f64; 4] {
    compose(about([0.0, 0.0, 1.0], yaw), compose(about([0.0, 1.0, 0.0], pitch), about([1.0, 0.0, 0.0], roll)))
}

/// `parent ∘ local`
fn then((r, p): Pose, local: &urdf_rs::Pose) -> Pose {
    let x = rotate(p, local.xyz.0);
    (std::array::from_fn(|i| r[i] + x[i]), compose(p, rpy(local.rpy.0)))
}

fn refused(what: &str, name: &str, reason: String) -> Error {
    Problem::Urdf { reason }.at(Part::Urdf { element: format!("{what} {name:?}") })
}

/// The mechanism of the URDF `text` under `gravity`.
pub fn from_urdf(text: &str, gravity: [f64; 3]) -> Result<Mechanism> {
    read_urdf(text, gravity).map(|robot| robot.mechanism)
}

/// A URDF robot as a mechanism, with the URDF's names of its parts (the
/// bodies carry their links' names themselves).
#[derive(Debug, Clone)]
#[non_exhaustive]
pub struct UrdfRobot {
    /// The mechanism.
    pub mechanism: Mechanism,
    /// The URDF joint behind each of the mechanism's joints.
    pub joint_names: Vec<String>,
    /// What the file holds that cdyn does not model, one phrase each
    /// (`"collision (12 elements)"`), for a run to print.
    pub notes: Vec<String>,
    /// The links merged into other links' bodies or the ground, for
    /// [`Mechanism::named_with_links`].
    pub merged: Vec<MergedLink>,
}

/// The elements of a URDF file that cdyn reads past without modelling them.
const NOT_MODELLED: [(&str, &str); 6] = [
    ("collision", "collision (no contact)"),
    ("transmission", "transmission"),
    ("gazebo", "gazebo"),
    ("safety_controller", "safety_controller"),
    ("calibration", "calibration"),
    ("sensor", "sensor"),
];

/// How many elements `<tag …>` the text holds.
fn count_elements(text: &str, tag: &str) -> usize {
    let open = format!("<{tag}");
    text.match_indices(&open)
        .filter(|(at, _)| text[at + open.len()..].starts_with(|c: char| c.is_whitespace() || c == '>' || c == '/'))
        .count()
}

/// A link's own body, if it has a mass: centre of mass, axes and inertia from its `<inertial>`.
fn own_body(link: &urdf_rs::Link, pose: Pose) -> Option<Body> {
    let inertial = &link.inertial;
    if inertial.mass.value == 0.0 {
        return None;
    }
    let (r, p) = then(pose, &inertial.origin);
    let i = &inertial.inertia;
    Some(Body {
        inertia: [[i.ixx, i.ixy, i.ixz], [i.ixy, i.iyy, i.iyz], [i.ixz, i.iyz, i.izz]],
        position: r,
        orientation: p,
        ..Body::new(&link.name, inertial.mass.value, [1.0; 3])
    })
}

/// The rigid body of several links' bodies, in the axes `axes`: total
/// mass, centre of mass, and inertia about it (parallel-axis theorem).
fn merged(name: &str, parts: &[Body], axes: [f64; 4]) -> Option<Body> {
    let mass: f64 = parts.iter().map(|b| b.mass).sum();
    if mass == 0.0 {
        return None;
    }
    let c: [f64; 3] = std::array::from_fn(|k| parts.iter().map(|b| b.mass * b.position[k]).sum::<f64>() / mass);
    let mut inertia = [[0.0; 3]; 3];
    for b in parts {
        // The part's inertia in `axes`: R Jᵢ Rᵀ with R from its axes to `axes`.
        let columns: [[f64; 3]; 3] = std::array::from_fn(|k| {
            let e = std::array::from_fn(|i| f64::from(u8::from(i == k)));
            unrotate(axes, rotate(b.orientation, e))
        });
        let d = unrotate(axes, std::array::from_fn(|k| b.position[k] - c[k]));
        let d2 = d.iter().map(|x| x * x).sum::<f64>();
        for (i, row) in inertia.iter_mut().enumerate() {
            for (j, x) in row.iter_mut().enumerate() {
                let turned: f64 = (0..3)
                    .flat_map(|k| (0..3).map(move |l| (k, l)))
                    .map(|(k, l)| columns[k][i] * b.inertia[k][l] * columns[l][j])
                    .sum();
                *x += turned + b.mass * (if i == j { d2 } else { 0.0 } - d[i] * d[j]);
            }
        }
    }
    Some(Body { inertia, position: c, orientation: axes, ..Body::new(name, mass, [1.0; 3]) })
}

/// The `<limit>` of a revolute or prismatic joint (`continuous` has none):
/// its position range where `lower < upper` (URDF before 1.2 writes an
/// omitted bound as 0, so `lower = upper` is no range), its velocity and
/// effort bounds where positive (0 is URDF's "none").
fn urdf_limit(j: &urdf_rs::Joint) -> Option<JointLimit> {
    use urdf_rs::JointType as T;
    if !matches!(j.joint_type, T::Revolute | T::Prismatic) {
        return None;
    }
    let l = &j.limit;
    let (lower, upper) = if l.lower == l.upper { (f64::NEG_INFINITY, f64::INFINITY) } else { (l.lower, l.upper) };
    let bound = |x: f64| {
        if x > 0.0 {
            x
        } else if x == 0.0 {
            f64::INFINITY
        } else {
            x
        }
    };
    let limit = JointLimit::new(lower, upper).with_velocity(bound(l.velocity)).with_effort(bound(l.effort));
    let bounds = [limit.lower, limit.upper, limit.velocity, limit.effort];
    (bounds.iter().any(|x| x.is_finite()) || bounds.iter().any(|x| x.is_nan())).then_some(limit)
}

/// [`from_urdf`], keeping the URDF joints' names for messages.
pub fn read_urdf(text: &str, gravity: [f64; 3]) -> Result<UrdfRobot> {
    let robot = urdf_rs::read_from_string(text)
        .map_err(|e| Error::from(Problem::Urdf { reason: format!("not a valid URDF: {e}") }))?;
    let link_index: HashMap<&str, usize> = robot.links.iter().enumerate().map(|(i, l)| (l.name.as_str(), i)).collect();
    let mut parent_joint: Vec<Option<usize>> = vec![None; robot.links.len()];
    for (k, j) in robot.joints.iter().enumerate() {
        for end in [&j.parent.link, &j.child.link] {
            if !link_index.contains_key(end.as_str()) {
                return Err(refused("joint", &j.name, format!("link {end:?} does not exist")));
            }
        }
        let child = link_index[j.child.link.as_str()];
        if parent_joint[child].replace(k).is_some() {
            return Err(refused("link", &j.child.link, "is the child of two joints (URDF is a tree)".into()));
        }
    }
    let roots: Vec<usize> = (0..robot.links.len()).filter(|&i| parent_joint[i].is_none()).collect();
    let root = match roots.as_slice() {
        [root] => *root,
        [] => return Err(Problem::Urdf { reason: "no root link (the joints form a loop)".into() }.into()),
        many => {
            let names: Vec<&str> = many.iter().map(|&i| robot.links[i].name.as_str()).collect();
            return Err(Problem::Urdf {
                reason: format!("{} root links ({}): one is the fixed base", names.len(), names.join(", ")),
            }
            .into());
        }
    };
    // Link poses at zero joint positions, parents first.
    let mut pose: Vec<Pose> = vec![SPACE; robot.links.len()];
    let mut order = vec![root];
    let mut next = 0;
    while next < order.len() {
        let link = order[next];
        next += 1;
        for j in robot.joints.iter().filter(|j| link_index[j.parent.link.as_str()] == link) {
            let child = link_index[j.child.link.as_str()];
            pose[child] = then(pose[link], &j.origin);
            order.push(child);
        }
    }
    if order.len() < robot.links.len() {
        return Err(Problem::Urdf {
            reason: "some links are not connected to the root (the joints form a loop)".into(),
        }
        .into());
    }
    // Which link's body each link joins (`head`): its own, unless it is
    // fixed to its parent, whose head it joins; the root's is the ground.
    let own: Vec<Option<Body>> = robot.links.iter().zip(&pose).map(|(l, &p)| own_body(l, p)).collect();
    let mut head: Vec<usize> = (0..robot.links.len()).collect();
    for &l in &order[1..] {
        let j = &robot.joints[parent_joint[l].expect("not the root")];
        if j.joint_type == urdf_rs::JointType::Fixed {
            head[l] = head[link_index[j.parent.link.as_str()]];
        }
    }
    let mut bodies = Vec::new();
    let mut body_of: Vec<Option<usize>> = vec![None; robot.links.len()];
    let mut merges = Vec::new();
    for &h in order[1..].iter().filter(|&&l| head[l] == l) {
        let members: Vec<usize> = order.iter().copied().filter(|&l| head[l] == h).collect();
        let centre = |l: usize| own[l].as_ref().map(|b| b.position);
        merges.extend(members[1..].iter().map(|&l| (l, robot.links[h].name.clone(), centre(l))));
        let parts: Vec<Body> = members.iter().filter_map(|&l| own[l].clone()).collect();
        let name = &robot.links[h].name;
        let axes = own[h].as_ref().map_or(pose[h].1, |b| b.orientation);
        let joint = &robot.joints[parent_joint[h].expect("not the root")].name;
        let Some(body) = (if members.len() == 1 { own[h].clone() } else { merged(name, &parts, axes) }) else {
            return Err(refused(
                "link",
                name,
                format!(
                    "has no mass, nor has any link fixed to it, but joint {joint:?} moves it: give it an <inertial>"
                ),
            ));
        };
        if let Err(e) = body.check() {
            let e = match e {
                Error::InvalidModel { problem, .. } => problem.to_string(),
                Error::InvalidParameter { name, value, reason } => format!("{name} = {value}: {reason}"),
                other => other.to_string(),
            };
            let with = if parts.len() > 1 { " (with the links fixed to it)" } else { "" };
            return Err(refused("link", name, format!("{e}{with}, and joint {joint:?} moves it")));
        }
        body_of[h] = Some(bodies.len());
        bodies.push(body);
    }
    let mut notes: Vec<String> = NOT_MODELLED
        .iter()
        .filter_map(|&(tag, what)| match count_elements(text, tag) {
            0 => None,
            n => Some(format!("{what} ({n} element{})", if n == 1 { "" } else { "s" })),
        })
        .collect();
    if !merges.is_empty() {
        notes.push(format!("{} links merged into the bodies they are fixed to", merges.len()));
    }
    let grounded = order[1..].iter().filter(|&&l| head[l] == root);
    merges.extend(grounded.map(|&l| (l, crate::planar::GROUND.to_string(), None)));
    let merged_links = merges
        .into_iter()
        .map(|(l, body, centre)| MergedLink { name: robot.links[l].name.clone(), body, centre })
        .collect();
    let (mut joints, mut joint_names, mut mimics) = (Vec::new(), Vec::new(), Vec::new());
    let mut still = 0;
    for &l in &order[1..] {
        let j = &robot.joints[parent_joint[l].expect("not the root")];
        let (damping, friction) = j.dynamics.as_ref().map_or((0.0, 0.0), |d| (d.damping, d.friction));
        use urdf_rs::JointType as T;
        let kind = match j.joint_type {
            T::Revolute | T::Continuous => Some(JointKind::Revolute),
            T::Prismatic => Some(JointKind::Prismatic),
            T::Fixed => Some(JointKind::Fixed),
            T::Floating => None,
            T::Planar | T::Spherical => {
                return Err(refused(
                    "joint",
                    &j.name,
                    format!("type {:?} is not supported", j.joint_type).to_lowercase(),
                ));
            }
        };
        let moves = matches!(kind, Some(JointKind::Revolute | JointKind::Prismatic));
        still += usize::from(!moves && (damping != 0.0 || friction != 0.0 || j.mimic.is_some()));
        let length = j.axis.xyz.0.iter().map(|x| x * x).sum::<f64>().sqrt();
        if moves && !(length > 0.0 && length.is_finite()) {
            return Err(refused("joint", &j.name, format!("axis {:?} has zero length", j.axis.xyz.0)));
        }
        let Some(child) = body_of[l] else { continue }; // merged into its parent's body
        let parent = body_of[head[link_index[j.parent.link.as_str()]]];
        let Some(kind) = kind else { continue }; // floating: a free body
        let (origin, frame) = pose[l];
        // A weld's axis only orients its frame: any will do (URDF's may be zero).
        let axis = if moves { rotate(frame, j.axis.xyz.0) } else { [0.0, 0.0, 1.0] };
        let mut joint = Joint::new(kind, child, parent, origin).with_axis(axis);
        if moves {
            joint = joint.with_damping(damping).with_friction(friction);
        }
        if let Some(limit) = urdf_limit(j) {
            limit.check().map_err(|e| refused("joint", &j.name, e.to_string().replace("invalid model: ", "")))?;
            joint = joint.with_limit(limit);
        }
        if let Some(m) = j.mimic.as_ref().filter(|_| moves) {
            mimics.push((joints.len(), m.joint.clone(), m.multiplier.unwrap_or(1.0), m.offset.unwrap_or(0.0)));
        }
        joints.push(joint);
        joint_names.push(j.name.clone());
    }
    if still > 0 {
        notes.push(format!("<dynamics> or <mimic> of {still} fixed or floating joints (nothing to move)"));
    }
    let couplings = mimics
        .into_iter()
        .map(|(follower, leader, multiplier, offset)| {
            let at = joint_names.iter().position(|n| *n == leader);
            match at.filter(|&k| joints[k].kind != JointKind::Fixed) {
                Some(leader) => Ok(Coupling::new(follower, leader, multiplier, offset)),
                None => Err(refused(
                    "joint",
                    &joint_names[follower],
                    format!("<mimic joint={leader:?}>: no revolute or prismatic joint of that name"),
                )),
            }
        })
        .collect::<Result<Vec<_>>>()?;
    // What each link looks like, on the body it joins or on the ground (in
    // space; a base link drawn only by meshes as the box of its inertia).
    let mut ground = Vec::new();
    for &l in &order {
        let at = |(v, origin): (Visual, &urdf_rs::Pose), body| v.into_body(then(pose[l], origin), body);
        match body_of[head[l]] {
            Some(b) => {
                let body = (bodies[b].position, bodies[b].orientation);
                bodies[b].visuals.extend(visuals(&robot.links[l]).map(|v| at(v, body)));
            }
            None => {
                let before = ground.len();
                ground.extend(visuals(&robot.links[l]).map(|v| at(v, SPACE)));
                if let Some(b) = own[l].as_ref().filter(|b| ground.len() == before && b.check().is_ok()) {
                    ground.push(Visual::of_inertia(b.mass, &b.inertia).into_body((b.position, b.orientation), SPACE));
                }
            }
        }
    }
    let mechanism =
        Mechanism::new(gravity).with_bodies(bodies).with_joints(joints).with_couplings(couplings).with_ground(ground);
    Ok(UrdfRobot { mechanism, joint_names, notes, merged: merged_links })
}

/// A link's `<visual>` boxes, cylinders and spheres (a capsule as the
/// cylinder around it), each in its own `<origin>`; meshes are not read.
fn visuals(link: &urdf_rs::Link) -> impl Iterator<Item = (Visual, &urdf_rs::Pose)> {
    link.visual.iter().filter_map(|v| {
        let shape = match v.geometry {
            urdf_rs::Geometry::Box { size } => Shape::Box { size: size.0 },
            urdf_rs::Geometry::Cylinder { radius, length } => Shape::Cylinder { radius, length },
            urdf_rs::Geometry::Capsule { radius, length } => Shape::Cylinder { radius, length: length + 2.0 * radius },
            urdf_rs::Geometry::Sphere { radius } => Shape::Sphere { radius },
            urdf_rs::Geometry::Mesh { .. } => return None,
        };
        Some((Visual::new(shape, [0.0; 3], [1.0, 0.0, 0.0, 0.0]), &v.origin))
    })
}
