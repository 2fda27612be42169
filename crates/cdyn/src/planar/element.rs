//! The joints, drives and forces of a planar mechanism, as described — in
//! code with [`BodyId`]s, or in a scenario file with body names.

use super::body::BodyId;
use crate::limit::JointLimit;
use crate::model::timefn::TimeFn;

/// Which coordinate of a body a drive prescribes (`"x"`, `"y"`, `"angle"` in
/// files). Exhaustive on purpose (not `#[non_exhaustive]`): a planar body has
/// these three coordinates and no other.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(serde::Deserialize), serde(rename_all = "lowercase"))]
pub enum Coordinate {
    /// The centre of mass's x.
    X,
    /// The centre of mass's y.
    Y,
    /// The body's angle (rigid bodies only).
    Angle,
}

/// Declares [`Element`] with the four fields of an element between two
/// points written once: a variant declared `Name between B { … }` gets `a`,
/// `pa`, `b`, `pb` (in files `a`, `point_a`, `b`, `point_b`, the points
/// defaulting to `[0, 0]`). Not `#[serde(flatten)]` of a shared struct:
/// serde cannot combine it with `deny_unknown_fields`, and a misspelt key
/// must stay an error.
macro_rules! elements {
    (
        $(#[$meta:meta])*
        pub enum $name:ident<$b:ident = $default:ty> {
            $(
                $(#[$variant_meta:meta])*
                $variant:ident $(between $ends:ident)? { $($(#[$field_meta:meta])* $field:ident: $t:ty,)* }
            ),* $(,)?
        }
    ) => {
        $(#[$meta])*
        pub enum $name<$b = $default> {
            $(
                $(#[$variant_meta])*
                $variant {
                    $(
                        /// First body.
                        a: $ends,
                        /// Point on `a`.
                        #[cfg_attr(feature = "serde", serde(rename = "point_a", default))]
                        pa: [f64; 2],
                        /// Second body.
                        b: $ends,
                        /// Point on `b`.
                        #[cfg_attr(feature = "serde", serde(rename = "point_b", default))]
                        pb: [f64; 2],
                    )?
                    $($(#[$field_meta])* $field: $t,)*
                },
            )*
        }
    };
}

elements! {
/// An element of a mechanism, as described. `B` is how it refers to a body:
/// a [`BodyId`] in code, a name (`Element<String>`) as read from a scenario
/// file, where every element is a table tagged by its [`kind`](Self::kind)
/// with the field names below (`point_a` for `pa`, `function` for `f`, …);
/// [`Mechanism::add_named`](super::Mechanism::add_named) looks the names up.
///
/// Points are in the body's own frame, relative to its centre of mass (world
/// points for the ground) and default to `[0, 0]` in files, as do the rest
/// length and angles; loads not given are zero.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Deserialize),
    serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)
)]
#[non_exhaustive]
pub enum Element<B = BodyId> {
    /// Points `pa` on `a` and `pb` on `b` coincide.
    Revolute between B {
        /// The range of the relative angle `φ_b − φ_a` (the ground's angle
        /// is 0; not wrapped, so any finite bound is a stop), for two rigid
        /// bodies or a rigid body and the ground.
        #[cfg_attr(feature = "serde", serde(default))]
        limit: Option<JointLimit>,
    },
    /// Point `pb` on `b` slides along the line through `pa` on `a` with
    /// direction `axis` (in `a`'s frame); the relative angle stays fixed
    /// when both have one.
    Prismatic between B {
        /// The line's direction in `a`'s frame; any non-zero length.
        axis: [f64; 2],
        /// The range of the displacement `(p_b − p_a) · u` of `pb` from `pa`
        /// along the axis (`u` the unit axis, turning with `a`).
        #[cfg_attr(feature = "serde", serde(default))]
        limit: Option<JointLimit>,
    },
    /// A massless rod of this length between two points.
    Distance between B {
        /// The rod's length, positive.
        length: f64,
    },
    /// `φ_b − φ_a = angle`.
    FixedAngle {
        /// First body.
        a: B,
        /// Second body.
        b: B,
        /// The relative angle kept.
        #[cfg_attr(feature = "serde", serde(default))]
        angle: f64,
    },
    /// A knife edge or a wheel's contact: the point `point` of a rigid body
    /// moves along `blade` (a direction fixed in the body) and not across
    /// it — a nonholonomic constraint on the body's velocity.
    KnifeEdge {
        /// The rigid body carrying the edge.
        body: B,
        /// The contact point, on `body`.
        #[cfg_attr(feature = "serde", serde(default))]
        point: [f64; 2],
        /// The direction the point may move along, in `body`'s frame; any non-zero length.
        blade: [f64; 2],
    },
    /// A coordinate of a body follows `f(t)`.
    #[cfg_attr(feature = "serde", serde(rename = "coordinate"))]
    DriveCoordinate {
        /// The driven body (not the ground).
        body: B,
        /// Which of its coordinates.
        coordinate: Coordinate,
        /// The prescribed value over time.
        #[cfg_attr(feature = "serde", serde(rename = "function"))]
        f: TimeFn,
    },
    /// `φ_b − φ_a = f(t)`.
    #[cfg_attr(feature = "serde", serde(rename = "relative_angle"))]
    DriveAngle {
        /// First body.
        a: B,
        /// Second body.
        b: B,
        /// The prescribed relative angle over time.
        #[cfg_attr(feature = "serde", serde(rename = "function"))]
        f: TimeFn,
    },
    /// Linear spring between two points.
    Spring between B {
        /// Force per unit stretch, not negative.
        stiffness: f64,
        /// Length without force, not negative.
        #[cfg_attr(feature = "serde", serde(default))]
        rest_length: f64,
    },
    /// Torsional spring on the relative angle `φ_b − φ_a`.
    TorsionSpring {
        /// First body.
        a: B,
        /// Second body.
        b: B,
        /// Torque per radian, not negative.
        stiffness: f64,
        /// Relative angle without torque.
        #[cfg_attr(feature = "serde", serde(default))]
        rest_angle: f64,
    },
    /// Linear damper between two points: force `c` times the rate of change of their distance.
    Damper between B {
        /// Force per unit stretch rate, not negative.
        damping: f64,
    },
    /// Rotary damper on the relative angle.
    RotaryDamper {
        /// First body.
        a: B,
        /// Second body.
        b: B,
        /// Torque per unit relative angular velocity, not negative.
        damping: f64,
    },
    /// A force `(f_x(t), f_y(t))` in world axes applied at a point of a body.
    #[cfg_attr(feature = "serde", serde(rename = "force"))]
    AppliedForce {
        /// The pushed body (not the ground).
        body: B,
        /// Where, on `body`.
        #[cfg_attr(feature = "serde", serde(default))]
        point: [f64; 2],
        /// World x component over time.
        #[cfg_attr(feature = "serde", serde(default))]
        fx: TimeFn,
        /// World y component over time.
        #[cfg_attr(feature = "serde", serde(default))]
        fy: TimeFn,
    },
    /// A torque `τ(t)` applied to a body.
    #[cfg_attr(feature = "serde", serde(rename = "torque"))]
    AppliedTorque {
        /// The turned body (a rigid body).
        body: B,
        /// The torque over time.
        #[cfg_attr(feature = "serde", serde(rename = "torque", default))]
        f: TimeFn,
    },
}
}

/// The list of a scenario file an element is written in; each takes its own kinds.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
pub enum Group {
    /// `[[joints]]`: revolute, prismatic, distance, fixed_angle, knife_edge.
    Joints,
    /// `[[drives]]`: relative_angle, coordinate.
    Drives,
    /// `[[forces]]`: spring, torsion_spring, damper, rotary_damper, force, torque.
    Forces,
}

impl Group {
    /// The list's name in scenario files (`joints`).
    pub fn name(self) -> &'static str {
        match self {
            Group::Joints => "joints",
            Group::Drives => "drives",
            Group::Forces => "forces",
        }
    }
}

impl<B> Element<B> {
    /// The element's kind, as scenario files name it (`revolute`, `relative_angle`).
    pub fn kind(&self) -> &'static str {
        match self {
            Element::Revolute { .. } => "revolute",
            Element::Prismatic { .. } => "prismatic",
            Element::Distance { .. } => "distance",
            Element::FixedAngle { .. } => "fixed_angle",
            Element::KnifeEdge { .. } => "knife_edge",
            Element::DriveCoordinate { .. } => "coordinate",
            Element::DriveAngle { .. } => "relative_angle",
            Element::Spring { .. } => "spring",
            Element::TorsionSpring { .. } => "torsion_spring",
            Element::Damper { .. } => "damper",
            Element::RotaryDamper { .. } => "rotary_damper",
            Element::AppliedForce { .. } => "force",
            Element::AppliedTorque { .. } => "torque",
        }
    }

    /// The list of a scenario file this kind of element belongs in.
    pub fn group(&self) -> Group {
        match self {
            Element::Revolute { .. }
            | Element::Prismatic { .. }
            | Element::Distance { .. }
            | Element::FixedAngle { .. }
            | Element::KnifeEdge { .. } => Group::Joints,
            Element::DriveCoordinate { .. } | Element::DriveAngle { .. } => Group::Drives,
            Element::Spring { .. }
            | Element::TorsionSpring { .. }
            | Element::Damper { .. }
            | Element::RotaryDamper { .. }
            | Element::AppliedForce { .. }
            | Element::AppliedTorque { .. } => Group::Forces,
        }
    }

    /// The same element with every body reference passed through `f`,
    /// which is told the reference's key (`a`, `b`, `body`) for its errors.
    pub fn try_map_bodies<C, E>(self, mut f: impl FnMut(&'static str, B) -> Result<C, E>) -> Result<Element<C>, E> {
        Ok(match self {
            Element::Revolute { a, pa, b, pb, limit } => {
                Element::Revolute { a: f("a", a)?, pa, b: f("b", b)?, pb, limit }
            }
            Element::Prismatic { a, pa, b, pb, axis, limit } => {
                Element::Prismatic { a: f("a", a)?, pa, b: f("b", b)?, pb, axis, limit }
            }
            Element::Distance { a, pa, b, pb, length } => {
                Element::Distance { a: f("a", a)?, pa, b: f("b", b)?, pb, length }
            }
            Element::FixedAngle { a, b, angle } => Element::FixedAngle { a: f("a", a)?, b: f("b", b)?, angle },
            Element::KnifeEdge { body, point, blade } => Element::KnifeEdge { body: f("body", body)?, point, blade },
            Element::DriveCoordinate { body, coordinate, f: g } => {
                Element::DriveCoordinate { body: f("body", body)?, coordinate, f: g }
            }
            Element::DriveAngle { a, b, f: g } => Element::DriveAngle { a: f("a", a)?, b: f("b", b)?, f: g },
            Element::Spring { a, pa, b, pb, stiffness, rest_length } => {
                Element::Spring { a: f("a", a)?, pa, b: f("b", b)?, pb, stiffness, rest_length }
            }
            Element::TorsionSpring { a, b, stiffness, rest_angle } => {
                Element::TorsionSpring { a: f("a", a)?, b: f("b", b)?, stiffness, rest_angle }
            }
            Element::Damper { a, pa, b, pb, damping } => {
                Element::Damper { a: f("a", a)?, pa, b: f("b", b)?, pb, damping }
            }
            Element::RotaryDamper { a, b, damping } => Element::RotaryDamper { a: f("a", a)?, b: f("b", b)?, damping },
            Element::AppliedForce { body, point, fx, fy } => {
                Element::AppliedForce { body: f("body", body)?, point, fx, fy }
            }
            Element::AppliedTorque { body, f: g } => Element::AppliedTorque { body: f("body", body)?, f: g },
        })
    }
}
