//! A URDF robot as a spatial [`Mechanism`], in redundant coordinates.
//!
//! Every link with a mass becomes a body, named after the link, with its
//! centre of mass, body axes and inertia from its `<inertial>`, at the pose
//! where every joint is at 0. The root link is the ground (a fixed base).
//! Joints become joints at their origin: `revolute` and `continuous` →
//! revolute, `prismatic` → prismatic, `fixed` → fixed (a weld), `floating`
//! → none (a free body). A massless link is allowed only behind `fixed`
//! joints (a frame: what hangs on it hangs on its nearest massive
//! ancestor). A revolute joint's `<dynamics damping>` becomes a rotary
//! damper. A link's `<visual>` boxes, cylinders and spheres are what its
//! body looks like in 3-D views (meshes are not read: a body without
//! primitive visuals is drawn as the box of its inertia).
//!
//! Refused, with the element named: `planar` and `spherical` URDF joints,
//! `<mimic>`, Coulomb `friction`, damping on a prismatic joint, a massless
//! link moved by a joint, and several root links. Not modelled (documented,
//! not refused, since nearly every robot file has them): joint limits,
//! effort and velocity bounds, safety controllers and calibration — cdyn
//! simulates the free dynamics; loop closures, drives and limits are for
//! the scenario to add.

use super::body::Body;
use super::joint::{Joint, JointKind};
use super::load::Load;
use super::mechanism::Mechanism;
use super::rotation::{about, compose, rotate};
use super::visual::{Shape, Visual};
use crate::error::{Error, Part, Problem, Result};
use std::collections::HashMap;

/// A pose: position and unit quaternion.
type Pose = ([f64; 3], [f64; 4]);

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
pub struct UrdfRobot {
    /// The mechanism.
    pub mechanism: Mechanism,
    /// The URDF joint behind each of the mechanism's joints.
    pub joint_names: Vec<String>,
    /// The URDF joint whose damping each of the mechanism's loads is.
    pub load_names: Vec<String>,
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
    let mut pose: Vec<Option<Pose>> = vec![None; robot.links.len()];
    pose[root] = Some(([0.0; 3], [1.0, 0.0, 0.0, 0.0]));
    let mut order = vec![root];
    let mut next = 0;
    while next < order.len() {
        let link = order[next];
        next += 1;
        for j in robot.joints.iter().filter(|j| link_index[j.parent.link.as_str()] == link) {
            let child = link_index[j.child.link.as_str()];
            pose[child] = pose[link].map(|p| then(p, &j.origin));
            order.push(child);
        }
    }
    if order.len() < robot.links.len() {
        return Err(Problem::Urdf {
            reason: "some links are not connected to the root (the joints form a loop)".into(),
        }
        .into());
    }
    // Bodies: the massive links but the root.
    let mut body_of: Vec<Option<usize>> = vec![None; robot.links.len()];
    let mut bodies = Vec::new();
    for &l in &order[1..] {
        let link = &robot.links[l];
        let inertial = &link.inertial;
        if inertial.mass.value == 0.0 {
            continue;
        }
        let (r, p) = then(pose[l].expect("every link reached"), &inertial.origin);
        let i = &inertial.inertia;
        body_of[l] = Some(bodies.len());
        bodies.push(Body {
            inertia: [[i.ixx, i.ixy, i.ixz], [i.ixy, i.iyy, i.iyz], [i.ixz, i.iyz, i.izz]],
            position: r,
            orientation: p,
            ..Body::new(&link.name, inertial.mass.value, [1.0; 3])
        });
    }
    // What carries a link: itself if massive, else its parent's carrier through a fixed joint.
    let mut carrier: Vec<Option<usize>> = vec![None; robot.links.len()];
    let (mut joints, mut loads) = (Vec::new(), Vec::new());
    let (mut joint_names, mut load_names) = (Vec::new(), Vec::new());
    for &l in &order[1..] {
        let j = &robot.joints[parent_joint[l].expect("not the root")];
        let parent = carrier[link_index[j.parent.link.as_str()]];
        let (origin, frame) = pose[l].expect("every link reached");
        let axis = rotate(frame, j.axis.xyz.0);
        let moves = !matches!(j.joint_type, urdf_rs::JointType::Fixed | urdf_rs::JointType::Floating);
        let length = j.axis.xyz.0.iter().map(|x| x * x).sum::<f64>().sqrt();
        if moves && !(length > 0.0 && length.is_finite()) {
            return Err(refused("joint", &j.name, format!("axis {:?} has zero length", j.axis.xyz.0)));
        }
        if j.mimic.is_some() {
            return Err(refused("joint", &j.name, "<mimic> is not supported".into()));
        }
        let (damping, friction) = j.dynamics.as_ref().map_or((0.0, 0.0), |d| (d.damping, d.friction));
        if friction != 0.0 {
            return Err(refused("joint", &j.name, format!("friction = {friction}: Coulomb friction is not supported")));
        }
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
        if damping != 0.0 && kind != Some(JointKind::Revolute) {
            return Err(refused("joint", &j.name, format!("damping = {damping} is supported on revolute joints only")));
        }
        let Some(child) = body_of[l] else {
            if kind == Some(JointKind::Fixed) {
                carrier[l] = parent;
                continue;
            }
            return Err(refused(
                "link",
                &robot.links[l].name,
                format!("has no mass but joint {:?} moves it: give it an <inertial>", j.name),
            ));
        };
        carrier[l] = Some(child);
        if let Some(kind) = kind {
            let joint = Joint::new(kind, child, parent, origin);
            joints.push(if kind == JointKind::Spherical { joint } else { joint.with_axis(axis) });
            joint_names.push(j.name.clone());
        }
        if damping != 0.0 {
            loads.push(Load::RotaryDamper { a: child, b: parent, axis, damping });
            load_names.push(j.name.clone());
        }
    }
    for &l in &order[1..] {
        if let (Some(b), Some(at)) = (carrier[l], pose[l]) {
            let body = (bodies[b].position, bodies[b].orientation);
            bodies[b].visuals.extend(visuals(&robot.links[l]).map(|(v, origin)| v.into_body(then(at, origin), body)));
        }
    }
    Ok(UrdfRobot { mechanism: Mechanism { bodies, joints, gravity, loads }, joint_names, load_names })
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
