//! A mechanism under construction: its bodies, elements and gravity, and
//! the ways to add to it — by [`BodyId`] in code, by name from a scenario
//! file.

use super::body::{Body, BodyId, GROUND};
use super::element::Element;
use super::inputs::Driven;
use crate::error::{Part, Problem, Result};
use crate::model::input::Input;

/// A planar mechanism under construction; [`Mechanism::build`] turns it into a model.
///
/// A pendulum: a point mass on a rod from the ground, held by `robust`:
///
/// ```
/// use cdyn::planar::{BodyId, Element, Mechanism};
/// use cdyn::{Control, Scheme, Settings, Simulation};
///
/// let mut m = Mechanism::new([0.0, -9.81]);
/// let bob = m.point("bob", 1.0, [1.0, 0.0]);
/// m.add(Element::Distance { a: BodyId::Ground, pa: [0.0, 0.0], b: bob, pb: [0.0, 0.0], length: 1.0 });
/// let built = m.build()?;
/// assert_eq!(built.names, ["bob.x", "bob.y"]);
/// let settings = Settings::new(Scheme::RungeKutta4, 1e-3, Control::robust());
/// let mut sim = Simulation::new(&built.model, settings, &built.q0, &built.v0)?;
/// sim.run::<cdyn::Error>(0.1, 10, |_| Ok(()))?;
/// assert!(sim.measure().phi.abs() < 1e-9 && sim.q()[1] < 0.0); // on the rod, falling
/// # Ok::<(), cdyn::Error>(())
/// ```
#[derive(Debug, Clone, Default)]
#[non_exhaustive]
pub struct Mechanism {
    /// The bodies, in coordinate order.
    pub bodies: Vec<Body>,
    /// The joints, drives and forces, in the order their rows and terms are added.
    pub elements: Vec<Element>,
    /// Gravitational acceleration, world axes.
    pub gravity: [f64; 2],
    /// The inputs that drive keys of the elements ([`Mechanism::drive`]).
    pub inputs: Vec<Driven>,
}

impl Mechanism {
    /// An empty mechanism under `gravity`.
    pub fn new(gravity: [f64; 2]) -> Self {
        Self { gravity, ..Self::default() }
    }

    /// Adds a rigid body at `position` with angle `angle`, at rest.
    pub fn rigid(&mut self, name: &str, mass: f64, inertia: f64, position: [f64; 2], angle: f64) -> BodyId {
        self.push(Body::rigid(name, mass, inertia, position, angle))
    }

    /// Adds a point mass at `position`, at rest.
    pub fn point(&mut self, name: &str, mass: f64, position: [f64; 2]) -> BodyId {
        self.push(Body::point(name, mass, position))
    }

    /// Adds a body; it is checked by [`Mechanism::build`].
    pub fn push(&mut self, body: Body) -> BodyId {
        self.bodies.push(body);
        BodyId::Body(self.bodies.len() - 1)
    }

    /// Adds an element; it is checked by [`Mechanism::build`].
    pub fn add(&mut self, element: Element) -> &mut Self {
        self.elements.push(element);
        self
    }

    /// Lets `input` drive the key `key` of element `element` (its position
    /// in [`Mechanism::elements`]) in place of the key's value: see
    /// [`Element::input_keys`] for the keys an element has. The model
    /// declares the input; checked by [`Mechanism::build`].
    pub fn drive(&mut self, element: usize, key: &str, input: &Input) -> &mut Self {
        self.inputs.push(Driven { element, key: key.to_string(), input: input.clone() });
        self
    }

    /// Adds an element that names its bodies, as a scenario file does:
    /// `"ground"` or the name of a body added before. An unknown name is
    /// an error at the element's position in [`Mechanism::elements`].
    pub fn add_named(&mut self, element: Element<String>) -> Result<&mut Self> {
        let at = Part::Element { index: self.elements.len(), kind: element.kind() };
        let element = element
            .try_map_bodies(|key, name| self.find(&name).ok_or(Problem::UnknownBody { key, name }))
            .map_err(|problem| problem.at(at))?;
        Ok(self.add(element))
    }

    /// The body called `name`, or the ground for `"ground"`.
    pub fn find(&self, name: &str) -> Option<BodyId> {
        if name == GROUND {
            return Some(BodyId::Ground);
        }
        self.bodies.iter().position(|b| b.name == name).map(BodyId::Body)
    }

    /// The body `id` refers to; `None` for the ground or a body that does not exist.
    pub fn body(&self, id: BodyId) -> Option<&Body> {
        match id {
            BodyId::Ground => None,
            BodyId::Body(i) => self.bodies.get(i),
        }
    }
}
