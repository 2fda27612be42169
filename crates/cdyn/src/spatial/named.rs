//! A spatial mechanism as scenario files write it: joints and loads that
//! name their bodies, a joint or load on the ground seen from its other
//! body.

use super::body::Body;
use super::joint::Joint;
use super::load::Load;
use super::mechanism::Mechanism;
use crate::error::{Error, Part, Problem, Result};
use crate::limit::JointLimit;
use std::collections::HashMap;

/// A part of a body that joints and loads may name as if it were a body:
/// a URDF link welded to another link's body (`UrdfRobot::merged`, feature `urdf`).
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct MergedLink {
    /// Its name.
    pub name: String,
    /// The name of the body it is part of (`"ground"`: the ground's).
    pub body: String,
    /// Its own centre of mass, in space at the initial pose, where a force
    /// on it without a `point` acts (`None`: massless, the body's).
    pub centre: Option<[f64; 3]>,
}

impl Mechanism {
    /// A mechanism whose joints name their bodies (`"ground"`, or `b`
    /// omitted, for the ground), as scenario files do.
    pub fn named(
        bodies: Vec<Body>,
        joints: Vec<Joint<String>>,
        loads: Vec<Load<String>>,
        gravity: [f64; 3],
    ) -> Result<Self> {
        Self::named_with_links(bodies, joints, loads, gravity, &[])
    }

    /// [`Mechanism::named`], where joints and loads may also name the
    /// `merged` links, each standing for its body (a force on one without a
    /// `point` acting at the link's own centre of mass).
    pub fn named_with_links(
        bodies: Vec<Body>,
        joints: Vec<Joint<String>>,
        loads: Vec<Load<String>>,
        gravity: [f64; 3],
        merged: &[MergedLink],
    ) -> Result<Self> {
        let mut index = HashMap::new();
        for (i, body) in bodies.iter().enumerate() {
            let at = || Part::Body { index: i, name: body.name.clone() };
            if body.name.is_empty() || body.name == crate::planar::GROUND {
                return Err(Problem::ReservedName { name: body.name.clone() }.at(at()));
            }
            if index.insert(body.name.as_str(), i).is_some() || merged.iter().any(|l| l.name == body.name) {
                return Err(Problem::DuplicateName.at(at()));
            }
        }
        let link = |name: &str| merged.iter().find(|l| l.name == name);
        let resolve = |key: &'static str, given: &str| {
            let name = link(given).map_or(given, |l| l.body.as_str());
            match index.get(name) {
                Some(&i) => Ok(Some(i)),
                None if name == crate::planar::GROUND => Ok(None),
                None => Err(Error::from(Problem::UnknownBody { key, name: given.to_string() })),
            }
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
                let Joint { kind, point, axis, axis_b, point_b, angle, displacement, damping, friction, limit, .. } = j;
                match (a, b) {
                    (Some(a), b) => Ok(Joint {
                        kind,
                        a,
                        b,
                        point,
                        axis,
                        axis_b,
                        point_b,
                        angle,
                        displacement,
                        damping,
                        friction,
                        limit,
                    }),
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
                        angle: angle.map(|f| f.negated()),
                        displacement: displacement.map(|f| f.negated()),
                        damping,
                        friction,
                        limit: limit.map(|l| JointLimit { lower: -l.upper, upper: -l.lower, ..l }),
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
                    Load::Force { body, force, point } => {
                        let point = point.or_else(|| link(&body).and_then(|l| l.centre));
                        Load::Force { body: one(&body)?, force, point }
                    }
                    Load::Torque { body, torque } => Load::Torque { body: one(&body)?, torque },
                })
            })
            .collect::<Result<Vec<_>>>()?;
        Ok(Self { bodies, joints, loads, ..Self::new(gravity) })
    }
}
