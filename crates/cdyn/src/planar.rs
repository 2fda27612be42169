//! Planar multibody systems described as bodies, joints, drives and
//! forces, turned into a [`Model`] of local elements.
//!
//! A rigid body has coordinates `(x, y, φ)` — its centre of mass and its
//! angle — and mass matrix `diag(m, m, I)`; a point mass has `(x, y)`.
//! Points on a body are given in its own frame, relative to the centre of
//! mass. Joints, springs and dampers are written once, generic over the
//! scalar, on the coordinates of the one or two bodies they connect.

use crate::error::{Error, Part, Problem, Result, finite, non_negative, positive};
use crate::model::{Model, ModelBuilder};
use crate::scalar::Scalar;
use crate::timefn::TimeFn;
use crate::{Constraint, Force, Potential};

/// A body of a [`Mechanism`], or the ground.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum BodyId {
    Ground,
    Body(usize),
}

/// One body's description and initial state.
#[derive(Debug, Clone, PartialEq)]
pub struct Body {
    pub name: String,
    pub mass: f64,
    /// Moment of inertia about the centre of mass; `None` for a point mass.
    pub inertia: Option<f64>,
    pub position: [f64; 2],
    pub angle: f64,
    pub velocity: [f64; 2],
    pub angular_velocity: f64,
}

/// Which coordinate of a body a drive prescribes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Coordinate {
    X,
    Y,
    Angle,
}

/// An element of a mechanism, as described.
#[derive(Debug, Clone, PartialEq)]
pub enum Element {
    /// Points `pa` on `a` and `pb` on `b` coincide.
    Revolute { a: BodyId, pa: [f64; 2], b: BodyId, pb: [f64; 2] },
    /// Point `pb` on `b` slides along the line through `pa` on `a` with
    /// direction `axis` (in `a`'s frame); the relative angle stays fixed
    /// when both have one.
    Prismatic { a: BodyId, pa: [f64; 2], b: BodyId, pb: [f64; 2], axis: [f64; 2] },
    /// A massless rod of this length between two points.
    Distance { a: BodyId, pa: [f64; 2], b: BodyId, pb: [f64; 2], length: f64 },
    /// `φ_b − φ_a = angle`.
    FixedAngle { a: BodyId, b: BodyId, angle: f64 },
    /// A coordinate of a body follows `f(t)`.
    DriveCoordinate { body: BodyId, coordinate: Coordinate, f: TimeFn },
    /// `φ_b − φ_a = f(t)`.
    DriveAngle { a: BodyId, b: BodyId, f: TimeFn },
    /// Linear spring between two points.
    Spring { a: BodyId, pa: [f64; 2], b: BodyId, pb: [f64; 2], stiffness: f64, rest_length: f64 },
    /// Torsional spring on the relative angle `φ_b − φ_a`.
    TorsionSpring { a: BodyId, b: BodyId, stiffness: f64, rest_angle: f64 },
    /// Linear damper between two points: force `c` times the rate of change of their distance.
    Damper { a: BodyId, pa: [f64; 2], b: BodyId, pb: [f64; 2], damping: f64 },
    /// Rotary damper on the relative angle.
    RotaryDamper { a: BodyId, b: BodyId, damping: f64 },
    /// A force `(f_x(t), f_y(t))` in world axes applied at a point of a body.
    AppliedForce { body: BodyId, point: [f64; 2], fx: TimeFn, fy: TimeFn },
    /// A torque `τ(t)` applied to a body.
    AppliedTorque { body: BodyId, f: TimeFn },
}

/// A planar mechanism under construction.
#[derive(Debug, Clone, Default)]
pub struct Mechanism {
    pub bodies: Vec<Body>,
    pub elements: Vec<Element>,
    /// Gravitational acceleration, world axes.
    pub gravity: [f64; 2],
}

/// A mechanism turned into a model, with its initial state.
pub struct Built {
    pub model: Model,
    pub q0: Vec<f64>,
    pub v0: Vec<f64>,
    /// `body.x`, `body.y`, `body.angle` for every coordinate.
    pub names: Vec<String>,
    /// Index of each body's first coordinate.
    pub offsets: Vec<usize>,
    /// For every constraint row, the index of the element it comes from.
    pub row_elements: Vec<usize>,
}

impl Mechanism {
    pub fn new(gravity: [f64; 2]) -> Self {
        Self { gravity, ..Self::default() }
    }

    /// Adds a rigid body at `position` with angle `angle`, at rest.
    pub fn rigid(&mut self, name: &str, mass: f64, inertia: f64, position: [f64; 2], angle: f64) -> BodyId {
        self.push(Body {
            name: name.into(),
            mass,
            inertia: Some(inertia),
            position,
            angle,
            velocity: [0.0; 2],
            angular_velocity: 0.0,
        })
    }

    /// Adds a point mass at `position`, at rest.
    pub fn point(&mut self, name: &str, mass: f64, position: [f64; 2]) -> BodyId {
        self.push(Body {
            name: name.into(),
            mass,
            inertia: None,
            position,
            angle: 0.0,
            velocity: [0.0; 2],
            angular_velocity: 0.0,
        })
    }

    pub fn push(&mut self, body: Body) -> BodyId {
        self.bodies.push(body);
        BodyId::Body(self.bodies.len() - 1)
    }

    pub fn add(&mut self, element: Element) -> &mut Self {
        self.elements.push(element);
        self
    }

    pub fn body(&self, id: BodyId) -> Option<&Body> {
        match id {
            BodyId::Ground => None,
            BodyId::Body(i) => self.bodies.get(i),
        }
    }

    /// A body's name for messages: its own, `ground`, or its position if it does not exist.
    fn name(&self, id: BodyId) -> String {
        match id {
            BodyId::Ground => "ground".into(),
            BodyId::Body(i) => self.bodies.get(i).map_or_else(|| format!("body {i}"), |b| b.name.clone()),
        }
    }

    /// The model, its initial state and coordinate names. Errors name the
    /// body or element (by position, from 0) at fault.
    pub fn build(&self) -> Result<Built> {
        if !self.gravity.iter().all(|g| g.is_finite()) {
            let value = self.gravity.into_iter().find(|g| !g.is_finite()).unwrap_or(f64::NAN);
            return Err(Error::InvalidParameter { name: "gravity", value, reason: "must be finite" });
        }
        let mut mass = Vec::new();
        let (mut q0, mut v0, mut names, mut offsets) = (Vec::new(), Vec::new(), Vec::new(), Vec::new());
        for (i, b) in self.bodies.iter().enumerate() {
            let at = || Part::Body { index: i, name: b.name.clone() };
            positive("mass", b.mass).map_err(|e| e.at(at()))?;
            let state = b.position.iter().chain(&b.velocity).chain([&b.angle, &b.angular_velocity]);
            if let Some((index, &value)) = state.enumerate().find(|(_, x)| !x.is_finite()) {
                return Err(Problem::NonFiniteState { index, value }.at(at()));
            }
            offsets.push(mass.len());
            mass.extend([b.mass, b.mass]);
            q0.extend(b.position);
            v0.extend(b.velocity);
            names.extend([format!("{}.x", b.name), format!("{}.y", b.name)]);
            if let Some(inertia) = b.inertia {
                positive("inertia", inertia).map_err(|e| e.at(at()))?;
                mass.push(inertia);
                q0.push(b.angle);
                v0.push(b.angular_velocity);
                names.push(format!("{}.angle", b.name));
            }
        }
        let mut builder = Model::builder(mass);
        for (i, b) in self.bodies.iter().enumerate() {
            if self.gravity != [0.0, 0.0] {
                let w = [-b.mass * self.gravity[0], -b.mass * self.gravity[1]];
                builder = builder.potential(Gravity { w }, [offsets[i], offsets[i] + 1]);
            }
        }
        let mut row_elements = Vec::new();
        for (k, e) in self.elements.iter().enumerate() {
            builder = self
                .add_element(builder, e, &offsets)
                .map_err(|why| why.at(Part::Element { index: k, kind: e.kind() }))?;
            row_elements.resize(builder.rows(), k);
        }
        Ok(Built { model: builder.build()?, q0, v0, names, offsets, row_elements })
    }

    /// Where a body's coordinates are and what it is, for one end of an element.
    fn attach(&self, id: BodyId, point: [f64; 2], offsets: &[usize], idx: &mut Vec<usize>) -> Result<End> {
        for p in point {
            finite("point", p)?;
        }
        match id {
            BodyId::Ground => Ok(End::Ground { point }),
            BodyId::Body(i) => {
                let b = self.bodies.get(i).ok_or(Problem::NoSuchBody { index: i })?;
                let at = idx.len();
                let first = offsets[i];
                match b.inertia {
                    Some(_) => {
                        idx.extend([first, first + 1, first + 2]);
                        Ok(End::Rigid { at, local: point })
                    }
                    None if point == [0.0, 0.0] => {
                        idx.extend([first, first + 1]);
                        Ok(End::Point { at })
                    }
                    None => Err(Problem::PointMassOffset { body: b.name.clone() }.into()),
                }
            }
        }
    }

    /// The angle coordinate of a body, for elements on relative angles.
    fn attach_angle(&self, id: BodyId, offsets: &[usize], idx: &mut Vec<usize>) -> Result<Option<usize>> {
        match id {
            BodyId::Ground => Ok(None),
            BodyId::Body(i) => {
                let b = self.bodies.get(i).ok_or(Problem::NoSuchBody { index: i })?;
                if b.inertia.is_none() {
                    return Err(Problem::NoAngle { body: b.name.clone() }.into());
                }
                idx.push(offsets[i] + 2);
                Ok(Some(idx.len() - 1))
            }
        }
    }

    fn add_element(&self, builder: ModelBuilder, e: &Element, offsets: &[usize]) -> Result<ModelBuilder> {
        let mut idx = Vec::new();
        let same = |a: &BodyId, b: &BodyId| {
            if a == b { Err(Problem::SameBody { body: self.name(*a) }) } else { Ok(()) }
        };
        let finite_fn = |f: &TimeFn| if f.is_finite() { Ok(()) } else { Err(Problem::NonFiniteFunction) };
        Ok(match e {
            Element::Revolute { a, pa, b, pb } => {
                same(a, b)?;
                let (ea, eb) = (self.attach(*a, *pa, offsets, &mut idx)?, self.attach(*b, *pb, offsets, &mut idx)?);
                with_k!(idx, K, builder.constrain(Revolute::<K> { a: ea, b: eb }, idx_array(&idx)))
            }
            Element::Distance { a, pa, b, pb, length } => {
                same(a, b)?;
                let length = positive("length", *length)?;
                let (ea, eb) = (self.attach(*a, *pa, offsets, &mut idx)?, self.attach(*b, *pb, offsets, &mut idx)?);
                match (ea, eb) {
                    (End::Point { .. }, End::Point { .. }) => builder.constrain(PointRod { length }, idx_array(&idx)),
                    (End::Ground { point: anchor }, End::Point { .. })
                    | (End::Point { .. }, End::Ground { point: anchor }) => {
                        builder.constrain(AnchoredRod { anchor, length }, idx_array(&idx))
                    }
                    _ => with_k!(idx, K, builder.constrain(Distance::<K> { a: ea, b: eb, length }, idx_array(&idx))),
                }
            }
            Element::Prismatic { a, pa, b, pb, axis } => {
                same(a, b)?;
                let norm = axis[0].hypot(axis[1]);
                positive("|axis|", norm)?;
                let normal = [-axis[1] / norm, axis[0] / norm];
                let (ea, eb) = (self.attach(*a, *pa, offsets, &mut idx)?, self.attach(*b, *pb, offsets, &mut idx)?);
                let builder = with_k!(idx, K, builder.constrain(OnLine::<K> { a: ea, b: eb, normal }, idx_array(&idx)));
                // No relative rotation, when both ends can rotate or one is the ground.
                let both_angles = [a, b].iter().all(|id| self.body(**id).is_none_or(|b| b.inertia.is_some()));
                if both_angles {
                    self.relative_angle(
                        builder,
                        *a,
                        *b,
                        TimeFn::constant(self.initial_relative_angle(*a, *b)),
                        offsets,
                    )?
                } else {
                    builder
                }
            }
            Element::FixedAngle { a, b, angle } => {
                same(a, b)?;
                finite("angle", *angle)?;
                self.relative_angle(builder, *a, *b, TimeFn::constant(*angle), offsets)?
            }
            Element::DriveAngle { a, b, f } => {
                same(a, b)?;
                finite_fn(f)?;
                self.relative_angle(builder, *a, *b, f.clone(), offsets)?
            }
            Element::DriveCoordinate { body, coordinate, f } => {
                finite_fn(f)?;
                let BodyId::Body(i) = *body else {
                    return Err(Problem::OnGround("driven").into());
                };
                let b = self.bodies.get(i).ok_or(Problem::NoSuchBody { index: i })?;
                let k = match coordinate {
                    Coordinate::X => 0,
                    Coordinate::Y => 1,
                    Coordinate::Angle if b.inertia.is_some() => 2,
                    Coordinate::Angle => {
                        return Err(Problem::NoAngle { body: b.name.clone() }.into());
                    }
                };
                builder.constrain(Prescribed { f: f.clone() }, [offsets[i] + k])
            }
            Element::Spring { a, pa, b, pb, stiffness, rest_length } => {
                same(a, b)?;
                let (k, l0) = (non_negative("stiffness", *stiffness)?, non_negative("rest_length", *rest_length)?);
                let (ea, eb) = (self.attach(*a, *pa, offsets, &mut idx)?, self.attach(*b, *pb, offsets, &mut idx)?);
                with_k!(idx, K, builder.potential(Spring::<K> { a: ea, b: eb, k, l0 }, idx_array(&idx)))
            }
            Element::TorsionSpring { a, b, stiffness, rest_angle } => {
                same(a, b)?;
                let k = non_negative("stiffness", *stiffness)?;
                finite("rest_angle", *rest_angle)?;
                let (ia, ib) = (self.attach_angle(*a, offsets, &mut idx)?, self.attach_angle(*b, offsets, &mut idx)?);
                with_k!(idx, K, builder.potential(Torsion::<K> { a: ia, b: ib, k, rest: *rest_angle }, idx_array(&idx)))
            }
            Element::Damper { a, pa, b, pb, damping } => {
                same(a, b)?;
                let c = non_negative("damping", *damping)?;
                let (ea, eb) = (self.attach(*a, *pa, offsets, &mut idx)?, self.attach(*b, *pb, offsets, &mut idx)?);
                with_k!(idx, K, builder.force(Damper::<K> { a: ea, b: eb, c }, idx_array(&idx)))
            }
            Element::RotaryDamper { a, b, damping } => {
                same(a, b)?;
                let c = non_negative("damping", *damping)?;
                let (ia, ib) = (self.attach_angle(*a, offsets, &mut idx)?, self.attach_angle(*b, offsets, &mut idx)?);
                with_k!(idx, K, builder.force(RotaryDamper::<K> { a: ia, b: ib, c }, idx_array(&idx)))
            }
            Element::AppliedForce { body, point, fx, fy } => {
                finite_fn(fx)?;
                finite_fn(fy)?;
                if *body == BodyId::Ground {
                    return Err(Problem::OnGround("pushed by a force").into());
                }
                let end = self.attach(*body, *point, offsets, &mut idx)?;
                with_k!(idx, K, builder.force(PointLoad::<K> { end, fx: fx.clone(), fy: fy.clone() }, idx_array(&idx)))
            }
            Element::AppliedTorque { body, f } => {
                finite_fn(f)?;
                if *body == BodyId::Ground {
                    return Err(Problem::OnGround("turned by a torque").into());
                }
                self.attach_angle(*body, offsets, &mut idx)?;
                builder.force(Torque { f: f.clone() }, [idx[0]])
            }
        })
    }

    fn relative_angle(
        &self,
        builder: ModelBuilder,
        a: BodyId,
        b: BodyId,
        f: TimeFn,
        offsets: &[usize],
    ) -> Result<ModelBuilder> {
        let mut idx = Vec::new();
        let (ia, ib) = (self.attach_angle(a, offsets, &mut idx)?, self.attach_angle(b, offsets, &mut idx)?);
        Ok(with_k!(idx, K, builder.constrain(RelativeAngle::<K> { a: ia, b: ib, f }, idx_array(&idx))))
    }

    fn initial_relative_angle(&self, a: BodyId, b: BodyId) -> f64 {
        let angle = |id| self.body(id).map_or(0.0, |b| b.angle);
        angle(b) - angle(a)
    }
}

impl Element {
    /// The element's kind, as scenario files name it.
    pub fn kind(&self) -> &'static str {
        match self {
            Element::Revolute { .. } => "revolute",
            Element::Prismatic { .. } => "prismatic",
            Element::Distance { .. } => "distance",
            Element::FixedAngle { .. } => "fixed_angle",
            Element::DriveCoordinate { .. } => "drive_coordinate",
            Element::DriveAngle { .. } => "drive_angle",
            Element::Spring { .. } => "spring",
            Element::TorsionSpring { .. } => "torsion_spring",
            Element::Damper { .. } => "damper",
            Element::RotaryDamper { .. } => "rotary_damper",
            Element::AppliedForce { .. } => "force",
            Element::AppliedTorque { .. } => "torque",
        }
    }
}

/// Runs `$body` with the const `$k` equal to `$idx.len()` (1 to 6): the
/// elements are generic over how many coordinates they read.
macro_rules! with_k {
    ($idx:expr, $k:ident, $body:expr) => {
        match $idx.len() {
            1 => {
                const $k: usize = 1;
                $body
            }
            2 => {
                const $k: usize = 2;
                $body
            }
            3 => {
                const $k: usize = 3;
                $body
            }
            4 => {
                const $k: usize = 4;
                $body
            }
            5 => {
                const $k: usize = 5;
                $body
            }
            6 => {
                const $k: usize = 6;
                $body
            }
            n => unreachable!("an element reads at most two bodies, 6 coordinates, not {n}"),
        }
    };
}
use with_k;

fn idx_array<const K: usize>(idx: &[usize]) -> [usize; K] {
    std::array::from_fn(|j| idx[j])
}

/// One end of an element: where its point is, given the element's local coordinates.
#[derive(Debug, Clone, Copy, PartialEq)]
enum End {
    Ground { point: [f64; 2] },
    Point { at: usize },
    Rigid { at: usize, local: [f64; 2] },
}

impl End {
    /// World position of the point.
    #[inline(always)]
    fn position<D: Scalar, const K: usize>(&self, x: &[D; K]) -> [D; 2] {
        match *self {
            End::Ground { point } => [D::from(point[0]), D::from(point[1])],
            End::Point { at } => [pick(x, at), pick(x, at + 1)],
            End::Rigid { at, local: [lx, ly] } => {
                let phi = pick(x, at + 2);
                let (s, c) = (phi.sin(), phi.cos());
                [pick(x, at) + c * lx - s * ly, pick(x, at + 1) + s * lx + c * ly]
            }
        }
    }

    /// World velocity of the point.
    #[inline(always)]
    fn velocity<D: Scalar>(&self, x: &[D], xd: &[D]) -> [D; 2] {
        match *self {
            End::Ground { .. } => [D::from(0.0); 2],
            End::Point { at } => [xd[at], xd[at + 1]],
            End::Rigid { at, local: [lx, ly] } => {
                let (s, c) = (x[at + 2].sin(), x[at + 2].cos());
                let (rx, ry) = (c * lx - s * ly, s * lx + c * ly);
                [xd[at] - xd[at + 2] * ry, xd[at + 1] + xd[at + 2] * rx]
            }
        }
    }

    /// Adds the generalized force of a world force `f` applied at the point.
    #[inline(always)]
    fn apply<D: Scalar>(&self, x: &[D], f: [D; 2], out: &mut [D]) {
        match *self {
            End::Ground { .. } => {}
            End::Point { at } => {
                out[at] += f[0];
                out[at + 1] += f[1];
            }
            End::Rigid { at, local: [lx, ly] } => {
                let (s, c) = (x[at + 2].sin(), x[at + 2].cos());
                let (rx, ry) = (c * lx - s * ly, s * lx + c * ly);
                out[at] += f[0];
                out[at + 1] += f[1];
                out[at + 2] += rx * f[1] - ry * f[0];
            }
        }
    }

    /// The angle of the end's body (0 for the ground).
    #[inline(always)]
    fn angle<D: Scalar, const K: usize>(&self, x: &[D; K]) -> D {
        match *self {
            End::Rigid { at, .. } => pick(x, at + 2),
            _ => D::from(0.0),
        }
    }
}

#[inline(always)]
fn angle_of<D: Scalar, const K: usize>(at: Option<usize>, x: &[D; K]) -> D {
    at.map_or(D::from(0.0), |i| pick(x, i))
}

/// `x[i]`, written as a chain of constant-index selections. Indexing a
/// small array of dual numbers with a runtime index forces it onto the
/// stack, where every wide load stalls on the narrow stores that built it:
/// measured 4× slower derivative passes than this.
#[inline(always)]
fn pick<D: Copy, const K: usize>(x: &[D; K], i: usize) -> D {
    debug_assert!(i < K);
    let mut out = x[0];
    for (j, &xj) in x.iter().enumerate().skip(1) {
        if i == j {
            out = xj;
        }
    }
    out
}

struct Revolute<const K: usize> {
    a: End,
    b: End,
}

impl<const K: usize> Constraint<K, 2> for Revolute<K> {
    #[inline(always)]
    fn eval<D: Scalar>(&self, x: [D; K], _t: D) -> [D; 2] {
        let (pa, pb) = (self.a.position(&x), self.b.position(&x));
        [pa[0] - pb[0], pa[1] - pb[1]]
    }
}

struct Distance<const K: usize> {
    a: End,
    b: End,
    length: f64,
}

impl<const K: usize> Constraint<K, 1> for Distance<K> {
    #[inline(always)]
    fn eval<D: Scalar>(&self, x: [D; K], _t: D) -> [D; 1] {
        let (pa, pb) = (self.a.position(&x), self.b.position(&x));
        let (dx, dy) = (pb[0] - pa[0], pb[1] - pa[1]);
        [(dx * dx + dy * dy - self.length * self.length) * 0.5]
    }
}

/// [`Distance`] between two point masses `(x_a, y_a, x_b, y_b)`: the rod of
/// chains, ropes and nets, with its coordinates at fixed places so that
/// its derivative passes select nothing at run time.
struct PointRod {
    length: f64,
}

impl Constraint<4, 1> for PointRod {
    #[inline(always)]
    fn eval<D: Scalar>(&self, [xa, ya, xb, yb]: [D; 4], _t: D) -> [D; 1] {
        let (dx, dy) = (xb - xa, yb - ya);
        [(dx * dx + dy * dy - self.length * self.length) * 0.5]
    }
}

/// [`Distance`] between a fixed point and a point mass `(x, y)`.
struct AnchoredRod {
    anchor: [f64; 2],
    length: f64,
}

impl Constraint<2, 1> for AnchoredRod {
    #[inline(always)]
    fn eval<D: Scalar>(&self, [x, y]: [D; 2], _t: D) -> [D; 1] {
        let (dx, dy) = (x - self.anchor[0], y - self.anchor[1]);
        [(dx * dx + dy * dy - self.length * self.length) * 0.5]
    }
}

/// `(p_b − p_a) · n = 0` with `n` the line's normal turning with `a`.
struct OnLine<const K: usize> {
    a: End,
    b: End,
    normal: [f64; 2],
}

impl<const K: usize> Constraint<K, 1> for OnLine<K> {
    #[inline(always)]
    fn eval<D: Scalar>(&self, x: [D; K], _t: D) -> [D; 1] {
        let (pa, pb) = (self.a.position(&x), self.b.position(&x));
        let phi = self.a.angle(&x);
        let (s, c) = (phi.sin(), phi.cos());
        let [nx, ny] = self.normal;
        let (wx, wy) = (c * nx - s * ny, s * nx + c * ny);
        [(pb[0] - pa[0]) * wx + (pb[1] - pa[1]) * wy]
    }
}

/// `φ_b − φ_a − f(t) = 0`.
struct RelativeAngle<const K: usize> {
    a: Option<usize>,
    b: Option<usize>,
    f: TimeFn,
}

impl<const K: usize> Constraint<K, 1> for RelativeAngle<K> {
    #[inline(always)]
    fn eval<D: Scalar>(&self, x: [D; K], t: D) -> [D; 1] {
        [angle_of(self.b, &x) - angle_of(self.a, &x) - self.f.eval(t)]
    }
}

/// `x − f(t) = 0` on one coordinate.
struct Prescribed {
    f: TimeFn,
}

impl Constraint<1, 1> for Prescribed {
    #[inline(always)]
    fn eval<D: Scalar>(&self, [x]: [D; 1], t: D) -> [D; 1] {
        [x - self.f.eval(t)]
    }
}

/// `V = −m g · p` on a body's centre of mass; `w = −m g`.
struct Gravity {
    w: [f64; 2],
}

impl Potential<2> for Gravity {
    #[inline(always)]
    fn energy<D: Scalar>(&self, [x, y]: [D; 2]) -> D {
        x * self.w[0] + y * self.w[1]
    }
}

struct Spring<const K: usize> {
    a: End,
    b: End,
    k: f64,
    l0: f64,
}

impl<const K: usize> Potential<K> for Spring<K> {
    #[inline(always)]
    fn energy<D: Scalar>(&self, x: [D; K]) -> D {
        let (pa, pb) = (self.a.position(&x), self.b.position(&x));
        let (dx, dy) = (pb[0] - pa[0], pb[1] - pa[1]);
        let stretch = (dx * dx + dy * dy).sqrt() - self.l0;
        stretch * stretch * (0.5 * self.k)
    }
}

struct Torsion<const K: usize> {
    a: Option<usize>,
    b: Option<usize>,
    k: f64,
    rest: f64,
}

impl<const K: usize> Potential<K> for Torsion<K> {
    #[inline(always)]
    fn energy<D: Scalar>(&self, x: [D; K]) -> D {
        let turn = angle_of(self.b, &x) - angle_of(self.a, &x) - self.rest;
        turn * turn * (0.5 * self.k)
    }
}

struct Damper<const K: usize> {
    a: End,
    b: End,
    c: f64,
}

impl<const K: usize> Force<K> for Damper<K> {
    #[inline(always)]
    fn force<D: Scalar>(&self, x: [D; K], xd: [D; K], _t: D) -> [D; K] {
        let (pa, pb) = (self.a.position(&x), self.b.position(&x));
        let (va, vb) = (self.a.velocity(&x, &xd), self.b.velocity(&x, &xd));
        let d = [pb[0] - pa[0], pb[1] - pa[1]];
        let len2 = d[0] * d[0] + d[1] * d[1];
        let mut out = [D::from(0.0); K];
        if len2.re() == 0.0 {
            return out;
        }
        // Force on b: −c (d·Δv / |d|²) d, i.e. −c times the stretch rate along the unit direction.
        let rate = (d[0] * (vb[0] - va[0]) + d[1] * (vb[1] - va[1])) / len2;
        let f = [-(d[0] * rate) * self.c, -(d[1] * rate) * self.c];
        self.b.apply(&x, f, &mut out);
        self.a.apply(&x, [-f[0], -f[1]], &mut out);
        out
    }
}

struct RotaryDamper<const K: usize> {
    a: Option<usize>,
    b: Option<usize>,
    c: f64,
}

impl<const K: usize> Force<K> for RotaryDamper<K> {
    #[inline(always)]
    fn force<D: Scalar>(&self, _x: [D; K], xd: [D; K], _t: D) -> [D; K] {
        let torque = -(angle_of(self.b, &xd) - angle_of(self.a, &xd)) * self.c;
        let mut out = [D::from(0.0); K];
        if let Some(b) = self.b {
            out[b] += torque;
        }
        if let Some(a) = self.a {
            out[a] -= torque;
        }
        out
    }
}

struct PointLoad<const K: usize> {
    end: End,
    fx: TimeFn,
    fy: TimeFn,
}

impl<const K: usize> Force<K> for PointLoad<K> {
    #[inline(always)]
    fn force<D: Scalar>(&self, x: [D; K], _xd: [D; K], t: D) -> [D; K] {
        let mut out = [D::from(0.0); K];
        self.end.apply(&x, [self.fx.eval(t), self.fy.eval(t)], &mut out);
        out
    }
}

struct Torque {
    f: TimeFn,
}

impl Force<1> for Torque {
    #[inline(always)]
    fn force<D: Scalar>(&self, _x: [D; 1], _xd: [D; 1], t: D) -> [D; 1] {
        [self.f.eval(t)]
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use num_dual::{Dual2_64, Dual64};

    /// The fixed-layout rods are the general distance element, written for
    /// one layout: same values and derivatives.
    #[test]
    fn point_rods_agree_with_the_general_distance() {
        let general = Distance::<4> { a: End::Point { at: 0 }, b: End::Point { at: 2 }, length: 1.3 };
        let anchored = Distance::<2> { a: End::Ground { point: [0.4, -0.2] }, b: End::Point { at: 0 }, length: 0.7 };
        let x = [0.3, -1.1, 1.2, 0.5];
        let v = [0.7, -0.2, 0.1, 1.4];
        let along = |i: usize| Dual2_64::new(x[i], v[i], 0.0);
        let t = Dual2_64::new(0.0, 1.0, 0.0);
        let [a] = PointRod { length: 1.3 }.eval(std::array::from_fn(along), t);
        let [b] = general.eval(std::array::from_fn(along), t);
        assert_eq!((a.re, a.v1, a.v2), (b.re, b.v1, b.v2));
        for j in 0..4 {
            let seeded = |i: usize| Dual64::new(x[i], if i == j { 1.0 } else { 0.0 });
            let [a] = PointRod { length: 1.3 }.eval(std::array::from_fn(seeded), Dual64::from(0.0));
            let [b] = general.eval(std::array::from_fn(seeded), Dual64::from(0.0));
            assert_eq!((a.re, a.eps), (b.re, b.eps));
        }
        let rod = AnchoredRod { anchor: [0.4, -0.2], length: 0.7 };
        let [a] = rod.eval([along(0), along(1)], t);
        let [b] = anchored.eval([along(0), along(1)], t);
        assert_eq!((a.re, a.v1, a.v2), (b.re, b.v1, b.v2));
    }
}
