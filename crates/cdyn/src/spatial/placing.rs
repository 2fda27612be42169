//! Joints and loads placed at the initial pose: their points and axes
//! carried into each body's frame there, and added to the model as
//! constraint rows, potentials and forces.

use super::body::{Body, SpatialBody};
use super::joint::{Joint, JointKind};
use super::joint_element::{BodyToBody, BodyToGround};
use super::joint_rows::{Frame, JointRows};
use super::load::{
    BodyRotaryDamper, BodyTorque, GroundRotaryDamper, Law, LineDamper, Load, PointForce, Slide, SpringEnergy,
};
use super::rotation::{cross, unrotate};
use crate::error::{Error, Problem, Result};
use crate::model::ModelBuilder;

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

/// The frames of one joint on its two sides, its points and axes carried
/// into the bodies' axes at their initial `poses` (in space on the
/// ground), checked: the keys its kind takes, finite points and drives,
/// perpendicular axes of a universal joint.
pub(super) fn joint_frames(joint: &Joint, bodies: &[Body], poses: &[([f64; 3], [f64; 4])]) -> Result<(Frame, Frame)> {
    let pose = |i: usize| poses.get(i).copied().ok_or(Error::from(Problem::NoSuchBody { index: i }));
    let (ra, pa) = pose(joint.a)?;
    if joint.b == Some(joint.a) {
        return Err(Problem::SameBody { body: bodies[joint.a].name.clone() }.into());
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
    for (key, allowed, drive) in [("angle", drives[0], &joint.angle), ("displacement", drives[1], &joint.displacement)]
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
    let in_body = |(r, p): ([f64; 3], [f64; 4]), point: [f64; 3], axes: [[f64; 3]; 3]| Frame {
        s: unrotate(p, std::array::from_fn(|i| point[i] - r[i])),
        axes: axes.map(|x| unrotate(p, x)),
    };
    let fa = in_body((ra, pa), joint.point, axes_a);
    let fb = match b {
        Some(pose) => in_body(pose, point_b, axes_b),
        None => Frame { s: point_b, axes: axes_b },
    };
    Ok((fa, fb))
}

/// Adds the rows of one joint, and its damping and friction, its points
/// and axes carried into the bodies' frames at their initial `poses`.
pub(super) fn add_joint(
    builder: ModelBuilder,
    joint: &Joint,
    bodies: &[Body],
    poses: &[([f64; 3], [f64; 4])],
) -> Result<ModelBuilder> {
    let (fa, fb) = joint_frames(joint, bodies, poses)?;
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
    let builder = match joint.rows() {
        1 => add!(1),
        3 => add!(3),
        4 => add!(4),
        5 => add!(5),
        _ => add!(6),
    };
    add_joint_law(builder, joint, fa, fb)
}

/// A joint's damping and friction, checked: `None` without either, an
/// error on a joint that has no coordinate for them to resist.
pub(super) fn joint_law(joint: &Joint) -> Result<Option<Law>> {
    let law = Law {
        damping: crate::error::non_negative("damping", joint.damping)?,
        friction: crate::error::non_negative("friction", joint.friction)?,
    };
    if law.damping == 0.0 && law.friction == 0.0 {
        return Ok(None);
    }
    if !matches!(joint.kind, JointKind::Revolute | JointKind::Prismatic) {
        let key = if law.damping != 0.0 { "damping" } else { "friction" };
        return Err(Problem::JointKey { key, kind: joint.kind.name(), wanted: false }.into());
    }
    Ok(Some(law))
}

/// A revolute or prismatic joint's damping and friction, as a torque about
/// (a force along) its axis, carried by `a`, between its bodies.
fn add_joint_law(builder: ModelBuilder, joint: &Joint, fa: Frame, fb: Frame) -> Result<ModelBuilder> {
    let Some(law) = joint_law(joint)? else {
        return Ok(builder);
    };
    let (a_at, b_at) = (SpatialBody::of(joint.a), joint.b.map(SpatialBody::of));
    Ok(match (joint.kind, b_at) {
        (JointKind::Revolute, Some(b)) => {
            let (pa, pb) = (a_at.euler_parameters(), b.euler_parameters());
            let at: [usize; 8] = std::array::from_fn(|i| if i < 4 { pa[i] } else { pb[i - 4] });
            builder.force(BodyRotaryDamper { axis: fa.axes[2], law }, at)
        }
        (JointKind::Revolute, None) => {
            builder.force(GroundRotaryDamper { axis: fb.axes[2], law }, a_at.euler_parameters())
        }
        (JointKind::Prismatic, Some(b)) => {
            let (ca, cb) = (a_at.coordinates(), b.coordinates());
            let at: [usize; 14] = std::array::from_fn(|i| if i < 7 { ca[i] } else { cb[i - 7] });
            builder.force(Slide { sa: fa.s, sb: fb.s, axis: fa.axes[2], ground: false, law }, at)
        }
        (JointKind::Prismatic, None) => {
            builder.force(Slide { sa: fa.s, sb: fb.s, axis: fa.axes[2], ground: true, law }, a_at.coordinates())
        }
        (kind, _) => unreachable!("joint_law gives a law to revolute and prismatic joints only, not {kind:?}"),
    })
}

/// A body point given in space at the initial pose, in the body's axes.
fn in_body((r, p): ([f64; 3], [f64; 4]), point: [f64; 3]) -> [f64; 3] {
    unrotate(p, std::array::from_fn(|i| point[i] - r[i]))
}

/// A load checked, as both coordinate systems read it: its numbers finite
/// (and non-negative where they must be), a spring's rest length resolved
/// (the initial distance unless given), a damper's axis of unit length, a
/// force's point resolved (the body's centre of mass unless given).
pub(super) fn checked_load(load: &Load, poses: &[([f64; 3], [f64; 4])]) -> Result<Load> {
    let pose = |i: usize| poses.get(i).copied().ok_or(Error::from(Problem::NoSuchBody { index: i }));
    let finite = |name: &'static str, x: &[f64]| match x.iter().find(|x| !x.is_finite()) {
        Some(&value) => Err(Error::from(Problem::Parameter { name, value, reason: "must be finite" })),
        None => Ok(()),
    };
    let mut load = load.clone();
    match &mut load {
        Load::Spring { a, b, point, point_b, stiffness, damping, length } => {
            crate::error::non_negative("stiffness", *stiffness)?;
            crate::error::non_negative("damping", *damping)?;
            finite("point", point)?;
            finite("point_b", point_b)?;
            let initial = (0..3).map(|i| (point_b[i] - point[i]).powi(2)).sum::<f64>().sqrt();
            *length = Some(match *length {
                Some(l) => crate::error::non_negative("length", l)?,
                None => initial,
            });
            if initial == 0.0 {
                let reason = "must differ from point: a spring needs a line";
                return Err(Problem::Parameter { name: "point_b", value: 0.0, reason }.into());
            }
            pose(*a)?;
            b.map(pose).transpose()?;
        }
        Load::RotaryDamper { a, b, axis, damping } => {
            crate::error::non_negative("damping", *damping)?;
            *axis = unit("axis", *axis)?;
            pose(*a)?;
            b.map(pose).transpose()?;
        }
        Load::Force { body, force, point } => {
            finite("force", force)?;
            let at = point.unwrap_or(pose(*body)?.0);
            finite("point", &at)?;
            *point = Some(at);
        }
        Load::Torque { body, torque } => {
            finite("torque", torque)?;
            pose(*body)?;
        }
    }
    Ok(load)
}

/// Adds the elements of one load.
pub(super) fn add_load(builder: ModelBuilder, load: &Load, poses: &[([f64; 3], [f64; 4])]) -> Result<ModelBuilder> {
    let pose = |i: usize| poses[i];
    Ok(match checked_load(load, poses)? {
        Load::Spring { a, b, point, point_b, stiffness, damping, length } => {
            let length = length.unwrap_or_default();
            let sa = in_body(pose(a), point);
            let a_at = SpatialBody::of(a).coordinates();
            match b {
                Some(b) => {
                    let sb = in_body(pose(b), point_b);
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
            let (_, pa) = pose(a);
            let a_at = SpatialBody::of(a).euler_parameters();
            match b {
                Some(b) => {
                    let b_at = SpatialBody::of(b).euler_parameters();
                    let at: [usize; 8] = std::array::from_fn(|i| if i < 4 { a_at[i] } else { b_at[i - 4] });
                    builder.force(BodyRotaryDamper { axis: unrotate(pa, axis), law: Law::damper(damping) }, at)
                }
                None => builder.force(GroundRotaryDamper { axis, law: Law::damper(damping) }, a_at),
            }
        }
        Load::Force { body, force, point } => {
            let s = in_body(pose(body), point.unwrap_or_default());
            builder.force(PointForce { s, f: force }, SpatialBody::of(body).coordinates())
        }
        Load::Torque { body, torque } => {
            builder.force(BodyTorque { n: torque }, SpatialBody::of(body).euler_parameters())
        }
    })
}
