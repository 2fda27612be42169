//! Turning a [`Mechanism`] into a [`Model`]: bodies become coordinates and
//! masses, every element becomes the constraint, potential or force block
//! of its kind on the coordinates of the bodies it connects.

use super::body::{Body, BodyId};
use super::constraints::{AnchoredRod, Distance, KnifeEdge, OnLine, PointRod, Prescribed, RelativeAngle, Revolute};
use super::element::{Coordinate, Element};
use super::ends::{End, idx_array, with_k};
use super::inputs::wire;
use super::layout::{Layout, offsets};
use super::limit::{check_limit, stop_row};
use super::loads::{Damper, Gravity, PointLoad, RotaryDamper, Spring, Torque, Torsion};
use super::mechanism::Mechanism;
use crate::error::{Error, Part, Problem, Result, finite, non_negative, positive};
use crate::limit::Stop;
use crate::model::angular::Generator;
use crate::model::input::Parameter;
use crate::model::timefn::TimeFn;
use crate::model::{Model, ModelBuilder};

/// A mechanism turned into a model, with its initial state.
pub struct Built {
    /// The model: coordinates `x, y[, angle]` per body, in body order.
    pub model: Model,
    /// Initial positions.
    pub q0: Vec<f64>,
    /// Initial velocities.
    pub v0: Vec<f64>,
    /// `body.x`, `body.y`, `body.angle` for every coordinate.
    pub names: Vec<String>,
    /// Index of each body's first coordinate.
    pub offsets: Vec<usize>,
    /// For every constraint row, the index of the element it comes from.
    pub row_elements: Vec<usize>,
    /// What the mechanism looks like, for a viewer ([`Mechanism::drawing`]).
    pub drawing: super::Drawing,
}

impl Mechanism {
    /// The model, its initial state and coordinate names. Errors name the
    /// body or element (by position, from 0) at fault.
    pub fn build(&self) -> Result<Built> {
        self.build_holding(&[])
    }

    /// [`Mechanism::build`] with the joint limits' stops `held` as rows
    /// `g = 0` after all others, in that order (see [`Mechanism::stops`]);
    /// each row's element is its joint's.
    pub fn build_holding(&self, held: &[Stop]) -> Result<Built> {
        if !self.gravity.iter().all(|g| g.is_finite()) {
            let value = self.gravity.into_iter().find(|g| !g.is_finite()).unwrap_or(f64::NAN);
            return Err(Error::InvalidParameter { name: "gravity", value, reason: "must be finite" });
        }
        let mut mass = Vec::new();
        let (mut q0, mut v0, mut names) = (Vec::new(), Vec::new(), Vec::new());
        let mut earlier = std::collections::HashSet::with_capacity(self.bodies.len());
        for (i, b) in self.bodies.iter().enumerate() {
            b.check(i, &mut earlier)?;
            mass.extend([b.mass, b.mass]);
            q0.extend(b.position);
            v0.extend(b.velocity);
            names.extend([format!("{}.x", b.name), format!("{}.y", b.name)]);
            if let Some(inertia) = b.inertia {
                mass.push(inertia);
                q0.push(b.angle);
                v0.push(b.angular_velocity);
                names.push(format!("{}.angle", b.name));
            }
        }
        let offsets = offsets(&self.bodies);
        let mut builder = Model::builder(mass).coordinate_names(names.clone());
        // The rigid translations: kept where nothing holds the mechanism in place.
        for (axis, name) in
            ["linear momentum x", "linear momentum y"].into_iter().enumerate().filter(|_| !offsets.is_empty())
        {
            let direction: Vec<(usize, f64)> = offsets.iter().map(|&o| (o + axis, 1.0)).collect();
            builder = builder.momentum_candidate(name, &direction);
        }
        // The rigid rotation about the origin: kept where nothing turns it.
        if let Ok(g) = Generator::rotation("angular momentum z", &names, [0.0, 0.0, 1.0], [0.0; 3], false) {
            builder = builder.rotation_candidate(g);
        }
        for (i, b) in self.bodies.iter().enumerate() {
            if self.gravity != [0.0, 0.0] {
                let w = [-b.mass * self.gravity[0], -b.mass * self.gravity[1]];
                builder = builder.potential(Gravity { w }, [offsets[i], offsets[i] + 1]);
            }
        }
        for (j, d) in self.inputs.iter().enumerate() {
            if d.element >= self.elements.len() {
                return Err(Problem::InputKey {
                    input: d.input.name().into(),
                    key: d.key.clone(),
                    reason: format!("element {} does not exist", d.element),
                }
                .into());
            }
            if !self.inputs[..j].iter().any(|earlier| earlier.input == d.input) {
                builder = builder.input(&d.input);
            }
        }
        let layout = Layout { bodies: &self.bodies, offsets: &offsets };
        let mut row_elements = Vec::new();
        for (k, e) in self.elements.iter().enumerate() {
            let driven: Vec<_> = self.inputs.iter().filter(|d| d.element == k).collect();
            let at = || Part::Element { index: k, kind: e.kind() };
            let (e, constant) = wire(e, &driven).map_err(|why| why.at(at()))?;
            builder = layout.add(builder, &e, constant).map_err(|why| why.at(at()))?;
            check_limit(&layout, &e).map_err(|why| why.at(at()))?;
            row_elements.resize(builder.rows(), k);
        }
        for &stop in held {
            let e = self.elements.get(stop.joint).ok_or(Problem::NoSuchJoint { index: stop.joint })?;
            let at = Part::Element { index: stop.joint, kind: e.kind() };
            builder = stop_row(&layout, builder, e, stop).map_err(|why| why.at(at))?;
            row_elements.push(stop.joint);
        }
        Ok(Built { model: builder.build()?, q0, v0, names, offsets, row_elements, drawing: self.drawing() })
    }
}

impl Layout<'_> {
    /// Adds element `e` to the model; `constant` is the input that takes
    /// the place of its rest length or angle, if one does.
    fn add(&self, builder: ModelBuilder, e: &Element, constant: Option<Parameter>) -> Result<ModelBuilder> {
        match *e {
            Element::Revolute { a, pa, b, pb, .. } => self.revolute(builder, a, pa, b, pb),
            Element::Prismatic { a, pa, b, pb, axis, .. } => self.prismatic(builder, a, pa, b, pb, axis),
            Element::Distance { a, pa, b, pb, length } => self.distance(builder, a, pa, b, pb, length),
            Element::FixedAngle { a, b, angle } => {
                finite("angle", angle)?;
                self.relative_angle(builder, a, b, TimeFn::constant(angle))
            }
            Element::KnifeEdge { body, point, blade } => self.knife_edge(builder, body, point, blade),
            Element::DriveCoordinate { body, coordinate, ref f } => self.coordinate(builder, body, coordinate, f),
            Element::DriveAngle { a, b, ref f } => {
                finite_fn(f)?;
                self.relative_angle(builder, a, b, f.clone())
            }
            Element::Spring { a, pa, b, pb, stiffness, rest_length } => {
                let k = non_negative("stiffness", stiffness)?;
                let l0 = match constant {
                    Some(input) => input,
                    None => Parameter::Fixed(non_negative("rest_length", rest_length)?),
                };
                let (ea, eb, idx) = self.two_points(a, pa, b, pb)?;
                Ok(with_k!(idx, K, builder.potential(Spring::<K> { a: ea, b: eb, k, l0: l0.clone() }, idx_array(&idx))))
            }
            Element::TorsionSpring { a, b, stiffness, rest_angle } => {
                let k = non_negative("stiffness", stiffness)?;
                let rest = match constant {
                    Some(input) => input,
                    None => Parameter::Fixed(finite("rest_angle", rest_angle)?),
                };
                let (ia, ib, idx) = self.two_angles(a, b)?;
                Ok(with_k!(
                    idx,
                    K,
                    builder.potential(Torsion::<K> { a: ia, b: ib, k, rest: rest.clone() }, idx_array(&idx))
                ))
            }
            Element::Damper { a, pa, b, pb, damping } => {
                let c = non_negative("damping", damping)?;
                let (ea, eb, idx) = self.two_points(a, pa, b, pb)?;
                Ok(with_k!(idx, K, builder.force(Damper::<K> { a: ea, b: eb, c }, idx_array(&idx))))
            }
            Element::RotaryDamper { a, b, damping } => {
                let c = non_negative("damping", damping)?;
                let (ia, ib, idx) = self.two_angles(a, b)?;
                Ok(with_k!(idx, K, builder.force(RotaryDamper::<K> { a: ia, b: ib, c }, idx_array(&idx))))
            }
            Element::AppliedForce { body, point, ref fx, ref fy } => self.applied_force(builder, body, point, fx, fy),
            Element::AppliedTorque { body, ref f } => {
                finite_fn(f)?;
                if body == BodyId::Ground {
                    return Err(Problem::OnGround("turned by a torque").into());
                }
                let mut idx = Vec::new();
                self.attach_angle(body, &mut idx)?;
                Ok(builder.force(Torque { f: f.clone() }, [idx[0]]))
            }
        }
    }

    fn revolute(
        &self,
        builder: ModelBuilder,
        a: BodyId,
        pa: [f64; 2],
        b: BodyId,
        pb: [f64; 2],
    ) -> Result<ModelBuilder> {
        let (ea, eb, idx) = self.two_points(a, pa, b, pb)?;
        Ok(with_k!(idx, K, builder.constrain(Revolute::<K> { a: ea, b: eb }, idx_array(&idx))))
    }

    /// A rod between two point masses, or a point mass and the ground, gets
    /// its fixed-layout form (`PointRod`, `AnchoredRod`): chains are made of
    /// them and their derivative passes are the hot path.
    fn distance(
        &self,
        builder: ModelBuilder,
        a: BodyId,
        pa: [f64; 2],
        b: BodyId,
        pb: [f64; 2],
        length: f64,
    ) -> Result<ModelBuilder> {
        self.distinct(a, b)?;
        let length = positive("length", length)?;
        let (ea, eb, idx) = self.two_points(a, pa, b, pb)?;
        Ok(match (ea, eb) {
            (End::Point { .. }, End::Point { .. }) => builder.constrain(PointRod { length }, idx_array(&idx)),
            (End::Ground { point: anchor }, End::Point { .. }) | (End::Point { .. }, End::Ground { point: anchor }) => {
                builder.constrain(AnchoredRod { anchor, length }, idx_array(&idx))
            }
            _ => with_k!(idx, K, builder.constrain(Distance::<K> { a: ea, b: eb, length }, idx_array(&idx))),
        })
    }

    /// The point stays on the line; when both ends can turn (or one is the
    /// ground) their relative angle is also held at its initial value, as
    /// a slider in a guide does.
    fn prismatic(
        &self,
        builder: ModelBuilder,
        a: BodyId,
        pa: [f64; 2],
        b: BodyId,
        pb: [f64; 2],
        axis: [f64; 2],
    ) -> Result<ModelBuilder> {
        self.distinct(a, b)?;
        let norm = positive("|axis|", axis[0].hypot(axis[1]))?;
        let normal = [-axis[1] / norm, axis[0] / norm];
        let (ea, eb, idx) = self.two_points(a, pa, b, pb)?;
        let builder = with_k!(idx, K, builder.constrain(OnLine::<K> { a: ea, b: eb, normal }, idx_array(&idx)));
        if [a, b].into_iter().all(|id| self.body(id).is_none_or(|b| b.inertia.is_some())) {
            let angle = |id| self.body(id).map_or(0.0, |b: &Body| b.angle);
            self.relative_angle(builder, a, b, TimeFn::constant(angle(b) - angle(a)))
        } else {
            Ok(builder)
        }
    }

    /// A knife edge on a rigid body: its blocked direction is the blade's
    /// normal, of unit length so that `|Φ̇|` is a speed.
    fn knife_edge(
        &self,
        builder: ModelBuilder,
        body: BodyId,
        point: [f64; 2],
        blade: [f64; 2],
    ) -> Result<ModelBuilder> {
        if body == BodyId::Ground {
            return Err(Problem::OnGround("given a knife edge").into());
        }
        let norm = positive("|blade|", blade[0].hypot(blade[1]))?;
        let normal = [-blade[1] / norm, blade[0] / norm];
        // The angle first: a point mass is refused for having none.
        let mut angle = Vec::new();
        self.attach_angle(body, &mut angle)?;
        let mut idx = Vec::new();
        let edge = self.attach(body, point, &mut idx)?;
        Ok(builder.nonholonomic(KnifeEdge { edge, normal }, idx_array(&idx)))
    }

    /// `φ_b − φ_a = f(t)`: fixed angles, angle drives and prismatic guides.
    fn relative_angle(&self, builder: ModelBuilder, a: BodyId, b: BodyId, f: TimeFn) -> Result<ModelBuilder> {
        let (ia, ib, idx) = self.two_angles(a, b)?;
        Ok(with_k!(idx, K, builder.constrain(RelativeAngle::<K> { a: ia, b: ib, f }, idx_array(&idx))))
    }

    fn coordinate(
        &self,
        builder: ModelBuilder,
        body: BodyId,
        coordinate: Coordinate,
        f: &TimeFn,
    ) -> Result<ModelBuilder> {
        finite_fn(f)?;
        let BodyId::Body(i) = body else {
            return Err(Problem::OnGround("driven").into());
        };
        let b = self.bodies.get(i).ok_or(Problem::NoSuchBody { index: i })?;
        let k = match coordinate {
            Coordinate::X => 0,
            Coordinate::Y => 1,
            Coordinate::Angle if b.inertia.is_some() => 2,
            Coordinate::Angle => return Err(Problem::NoAngle { body: b.name.clone() }.into()),
        };
        Ok(builder.constrain(Prescribed { f: f.clone() }, [self.offsets[i] + k]))
    }

    fn applied_force(
        &self,
        builder: ModelBuilder,
        body: BodyId,
        point: [f64; 2],
        fx: &TimeFn,
        fy: &TimeFn,
    ) -> Result<ModelBuilder> {
        finite_fn(fx)?;
        finite_fn(fy)?;
        if body == BodyId::Ground {
            return Err(Problem::OnGround("pushed by a force").into());
        }
        let mut idx = Vec::new();
        let end = self.attach(body, point, &mut idx)?;
        Ok(with_k!(idx, K, builder.force(PointLoad::<K> { end, fx: fx.clone(), fy: fy.clone() }, idx_array(&idx))))
    }
}

/// Drives and loads need finite coefficients: a NaN would only show up mid-run.
fn finite_fn(f: &TimeFn) -> Result<()> {
    if f.is_finite() { Ok(()) } else { Err(Problem::NonFiniteFunction.into()) }
}
