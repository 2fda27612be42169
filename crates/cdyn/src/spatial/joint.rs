//! A joint as the user describes it: what it allows ([`JointKind`]),
//! between which bodies, where, and optionally driven; `joint_rows` writes
//! its constraint rows.

use crate::limit::JointLimit;
use crate::model::timefn::TimeFn;

/// What a joint allows (its `kind` in scenario files).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(serde::Deserialize), serde(rename_all = "snake_case"))]
#[non_exhaustive]
pub enum JointKind {
    /// Rotation about the point.
    Spherical,
    /// Rotation about the axis through the point.
    Revolute,
    /// Rotation about `axis` on body `a` and about `axis_b` on body `b`
    /// (perpendicular to `axis` at the initial pose).
    Universal,
    /// Rotation about and sliding along the axis.
    Cylindrical,
    /// Sliding along the axis.
    Prismatic,
    /// No relative motion (a weld).
    Fixed,
    /// A massless rod from `point` on `a` to `point_b` on `b`, keeping
    /// their initial distance.
    Distance,
}

impl JointKind {
    /// The constraint rows of the joint.
    pub fn rows(&self) -> usize {
        match self {
            JointKind::Spherical => 3,
            JointKind::Revolute | JointKind::Prismatic => 5,
            JointKind::Universal | JointKind::Cylindrical => 4,
            JointKind::Fixed => 6,
            JointKind::Distance => 1,
        }
    }

    /// Its name in scenario files and messages.
    pub fn name(&self) -> &'static str {
        match self {
            JointKind::Spherical => "spherical",
            JointKind::Revolute => "revolute",
            JointKind::Universal => "universal",
            JointKind::Cylindrical => "cylindrical",
            JointKind::Prismatic => "prismatic",
            JointKind::Fixed => "fixed",
            JointKind::Distance => "distance",
        }
    }

    /// Whether it takes `axis`, `axis_b` and `point_b`.
    pub(crate) fn keys(&self) -> [bool; 3] {
        match self {
            JointKind::Spherical => [false, false, false],
            JointKind::Universal => [true, true, false],
            JointKind::Distance => [false, false, true],
            _ => [true, false, false],
        }
    }
}

/// A joint as the user describes it, at the initial pose; in a scenario
/// file a `[[joints]]` entry, its bodies named (`B = String`, `b` omitted
/// or `"ground"` for the ground).
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Deserialize), serde(deny_unknown_fields))]
#[non_exhaustive]
pub struct Joint<B = usize> {
    /// What it allows.
    pub kind: JointKind,
    /// The first body.
    pub a: B,
    /// The second body, or `None` for the ground.
    #[cfg_attr(feature = "serde", serde(default))]
    pub b: Option<B>,
    /// The joint's point, in space.
    pub point: [f64; 3],
    /// Its axis, in space (any length but zero): for revolute, universal,
    /// cylindrical, prismatic and fixed joints only.
    #[cfg_attr(feature = "serde", serde(default))]
    pub axis: Option<[f64; 3]>,
    /// A universal joint's axis on body `b`, in space.
    #[cfg_attr(feature = "serde", serde(default))]
    pub axis_b: Option<[f64; 3]>,
    /// A distance joint's end on body `b`, in space.
    #[cfg_attr(feature = "serde", serde(default))]
    pub point_b: Option<[f64; 3]>,
    /// A drive of a revolute or cylindrical joint: the angle of `a`
    /// relative to `b` (the ground when `b` is omitted) about the axis,
    /// right-handed, from the initial pose, as a function of time (one
    /// more row).
    #[cfg_attr(feature = "serde", serde(default))]
    pub angle: Option<TimeFn>,
    /// A drive of a prismatic or cylindrical joint: the displacement of `a`
    /// relative to `b` along the axis, from the initial pose.
    #[cfg_attr(feature = "serde", serde(default))]
    pub displacement: Option<TimeFn>,
    /// Viscous damping of a revolute or prismatic joint: the torque (force)
    /// `−c θ̇` between its bodies, `θ` the joint's coordinate: the angle of `a`
    /// relative to `b` about the axis, or its displacement along it, from the initial pose.
    #[cfg_attr(feature = "serde", serde(default))]
    pub damping: f64,
    /// Coulomb friction of a revolute or prismatic joint, regularized: the
    /// torque (force) `−μ θ̇ / √(θ̇² + s²)` with the slip rate `s =`
    /// [`FRICTION_SLIP`]. Below `s` it acts as a damper of `μ / s`, which
    /// an explicit step must resolve (a run checks it: see `docs/spatial.md`).
    #[cfg_attr(feature = "serde", serde(default))]
    pub friction: f64,
    /// The range of a revolute or prismatic joint's coordinate, its ends
    /// stops where a run halts the joint (see [`JointLimit`]).
    #[cfg_attr(feature = "serde", serde(default))]
    pub limit: Option<JointLimit>,
}

/// The slip rate of regularized joint friction ([`Joint::friction`]):
/// 0.01 rad/s (m/s for a prismatic joint). A joint held by friction alone
/// against a load `τ < μ` creeps at `s·τ/√(μ² − τ²)`; a sliding joint
/// feels `μ` to 0.5 % from `10 s` on.
pub const FRICTION_SLIP: f64 = 0.01;

impl Joint {
    /// A joint of `kind` between `a` and `b` (`None`: the ground) at `point`, without axes.
    pub fn new(kind: JointKind, a: usize, b: Option<usize>, point: [f64; 3]) -> Self {
        Self {
            kind,
            a,
            b,
            point,
            axis: None,
            axis_b: None,
            point_b: None,
            angle: None,
            displacement: None,
            damping: 0.0,
            friction: 0.0,
            limit: None,
        }
    }
}

crate::setters!(impl<B> Joint<B> {
    /// With its axis.
    with_axis => axis(Some): [f64; 3],
    /// With a universal joint's second axis.
    with_axis_b => axis_b(Some): [f64; 3],
    /// With a distance joint's second point.
    with_point_b => point_b(Some): [f64; 3],
    /// Driven in angle.
    with_angle => angle(Some): TimeFn,
    /// Driven in displacement.
    with_displacement => displacement(Some): TimeFn,
    /// With viscous damping `c`.
    with_damping => damping: f64,
    /// With Coulomb friction `μ`.
    with_friction => friction: f64,
    /// With a limit.
    with_limit => limit(Some): JointLimit,
});

impl<B> Joint<B> {
    /// Its constraint rows: the kind's and one per drive.
    pub fn rows(&self) -> usize {
        self.kind.rows() + self.angle.is_some() as usize + self.displacement.is_some() as usize
    }

    /// The same joint with its bodies passed through `f` (indices to names, say).
    pub fn map_bodies<C>(self, mut f: impl FnMut(B) -> C) -> Joint<C> {
        let Joint { kind, a, b, point, axis, axis_b, point_b, angle, displacement, damping, friction, limit } = self;
        Joint {
            kind,
            a: f(a),
            b: b.map(f),
            point,
            axis,
            axis_b,
            point_b,
            angle,
            displacement,
            damping,
            friction,
            limit,
        }
    }
}
