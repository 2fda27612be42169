//! Where an element's bodies are among the mechanism's coordinates: the
//! checked bodies and each one's first coordinate ([`Layout`]), and the
//! ends, angles and coordinates an element reads — for the elements
//! (`build`) and for the joints' limits (`limit`).

use super::body::{Body, BodyId};
use super::ends::End;
use crate::error::{Problem, Result, finite};

/// The checked bodies and where each one's coordinates start: what an
/// element needs to find the coordinates it reads.
pub(super) struct Layout<'a> {
    pub(super) bodies: &'a [Body],
    pub(super) offsets: &'a [usize],
}

/// Where each body's coordinates start: `x, y` for a point mass, `x, y,
/// angle` for a rigid body, in body order.
pub(super) fn offsets(bodies: &[Body]) -> Vec<usize> {
    bodies
        .iter()
        .scan(0, |next, b| {
            let first = *next;
            *next += if b.inertia.is_some() { 3 } else { 2 };
            Some(first)
        })
        .collect()
}

impl Layout<'_> {
    /// The body `id` refers to; `None` for the ground (or a body that does not exist).
    pub(super) fn body(&self, id: BodyId) -> Option<&Body> {
        match id {
            BodyId::Ground => None,
            BodyId::Body(i) => self.bodies.get(i),
        }
    }

    /// Both ends of a two-point element, on two different bodies, and the
    /// coordinates they read (`a`'s first).
    pub(super) fn two_points(
        &self,
        a: BodyId,
        pa: [f64; 2],
        b: BodyId,
        pb: [f64; 2],
    ) -> Result<(End, End, Vec<usize>)> {
        self.distinct(a, b)?;
        let mut idx = Vec::new();
        let ea = self.attach(a, pa, &mut idx)?;
        let eb = self.attach(b, pb, &mut idx)?;
        Ok((ea, eb, idx))
    }

    /// The angle coordinates of two different bodies (`None` for the
    /// ground), and the coordinates they read.
    pub(super) fn two_angles(&self, a: BodyId, b: BodyId) -> Result<(Option<usize>, Option<usize>, Vec<usize>)> {
        self.distinct(a, b)?;
        let mut idx = Vec::new();
        let ia = self.attach_angle(a, &mut idx)?;
        let ib = self.attach_angle(b, &mut idx)?;
        Ok((ia, ib, idx))
    }

    /// Where a body's coordinates are and what it is, for one end of an element.
    pub(super) fn attach(&self, id: BodyId, point: [f64; 2], idx: &mut Vec<usize>) -> Result<End> {
        for p in point {
            finite("point", p)?;
        }
        let BodyId::Body(i) = id else {
            return Ok(End::Ground { point });
        };
        let b = self.bodies.get(i).ok_or(Problem::NoSuchBody { index: i })?;
        let (at, first) = (idx.len(), self.offsets[i]);
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

    /// The angle coordinate of a body, for elements on relative angles.
    pub(super) fn attach_angle(&self, id: BodyId, idx: &mut Vec<usize>) -> Result<Option<usize>> {
        let BodyId::Body(i) = id else {
            return Ok(None);
        };
        let b = self.bodies.get(i).ok_or(Problem::NoSuchBody { index: i })?;
        if b.inertia.is_none() {
            return Err(Problem::NoAngle { body: b.name.clone() }.into());
        }
        idx.push(self.offsets[i] + 2);
        Ok(Some(idx.len() - 1))
    }

    /// An element connects two different bodies.
    pub(super) fn distinct(&self, a: BodyId, b: BodyId) -> Result<()> {
        if a == b { Err(Problem::SameBody { body: self.name(a) }.into()) } else { Ok(()) }
    }

    /// A body's name for messages: its own, `ground`, or its position if it does not exist.
    fn name(&self, id: BodyId) -> String {
        match id {
            BodyId::Ground => "ground".into(),
            BodyId::Body(i) => self.bodies.get(i).map_or_else(|| format!("body {i}"), |b| b.name.clone()),
        }
    }
}
