//! A planar mechanism's joint limits as stops ([`PlanarStops`]): each
//! finite side of a revolute or prismatic joint's limit
//! ([`Mechanism::stops`]), read at every step without allocating.

use super::reads::LimitReads;
use super::unilateral::Unilateral;
use crate::error::{Problem, Result};
use crate::limit::JointLimit;
use crate::model::Model;
use crate::planar::{JointSpace, Mechanism};

/// A planar [`Mechanism`]'s joint limits as a [`Unilateral`] system. Built
/// once (the reader of its joints' coordinates and where each stop and
/// velocity bound reads it), so that a step reads the gaps and rates
/// without allocating.
#[derive(Debug, Clone)]
pub struct PlanarStops {
    mechanism: Mechanism,
    space: JointSpace,
    reads: LimitReads,
}

impl PlanarStops {
    /// The stops of `mechanism`'s joint limits; an error if a limited
    /// element has no coordinate (a revolute joint on a point mass, or
    /// neither revolute nor prismatic).
    pub fn new(mechanism: Mechanism) -> Result<Self> {
        let space = mechanism.joint_space();
        let limits = mechanism.elements.iter().enumerate().filter_map(|(k, e)| Some((k, e.limit()?)));
        let n = mechanism.bodies.iter().map(|b| if b.inertia.is_some() { 3 } else { 2 }).sum();
        // Why the element has no coordinate, as reading it says.
        let no_coordinate = |element: usize| match mechanism.joint_coordinate(element, &vec![0.0; n], &vec![0.0; n]) {
            Err(e) => e,
            Ok(_) => Problem::NoSuchJoint { index: element }.into(),
        };
        let reads = LimitReads::new(mechanism.stops(), space.joints(), limits, n, no_coordinate)?;
        Ok(Self { mechanism, space, reads })
    }

    /// The mechanism.
    pub fn mechanism(&self) -> &Mechanism {
        &self.mechanism
    }

    fn limit(&self, element: usize) -> JointLimit {
        self.mechanism.elements[element].limit().expect("a stop's joint has a limit")
    }
}

impl Unilateral for PlanarStops {
    fn stops(&self) -> usize {
        self.reads.len()
    }

    fn model_holding(&self, held: &[usize]) -> Result<Model> {
        Ok(self.mechanism.build_holding(&self.reads.held(held))?.model)
    }

    /// `g = s (θ − bound)` and `ġ = s θ̇` (see [`Mechanism::gaps`]).
    fn gaps(&self, q: &[f64], v: &[f64], gaps: &mut [[f64; 2]]) -> Result<()> {
        self.reads.gaps(q, v, gaps, |i, stop| {
            let [theta, rate] = self.space.at(i, q, v);
            self.limit(stop.joint).gap(stop.upper, theta, rate)
        })
    }

    fn restitution(&self, stop: usize) -> f64 {
        self.mechanism.stop_bound(self.reads.stop(stop)).2
    }

    fn speed_bounds(&self) -> usize {
        self.reads.speed_bounds()
    }

    /// Joints (by element index) faster than their limit's `velocity`.
    fn overspeed(&self, q: &[f64], v: &[f64], exceeded: &mut dyn FnMut(usize, f64)) -> Result<()> {
        self.reads.overspeed(q, v, |i| self.space.at(i, q, v)[1], exceeded)
    }

    fn joint(&self, stop: usize) -> String {
        let element = self.reads.stop(stop).joint;
        format!("element {element} ({})", self.mechanism.elements[element].kind())
    }

    fn side(&self, stop: usize) -> (bool, f64) {
        let stop = self.reads.stop(stop);
        (stop.upper, self.mechanism.stop_bound(stop).0)
    }
}
