//! The joint limits of a mechanism in joint coordinates as stops
//! ([`TreeStops`]): the same stops as [`MechanismStops`](super::MechanismStops)
//! ([`Mechanism::stops`]), their gaps read from the coordinates
//! themselves. A joint coordinate counts whole turns, so no gap is
//! periodic: UR5's ±2π are two stops a joint reaches after two turns.

use super::reads::LimitReads;
use super::unilateral::Unilateral;
use crate::error::{Problem, Result};
use crate::model::Model;
use crate::spatial::Mechanism;

/// A [`Mechanism`]'s joint limits in joint coordinates
/// ([`Mechanism::in_joint_coordinates`]) as a [`Unilateral`] system.
#[derive(Debug, Clone)]
pub struct TreeStops {
    mechanism: Mechanism,
    reads: LimitReads,
}

impl TreeStops {
    /// The stops of `mechanism`'s joint limits; an error where the
    /// mechanism has no joint coordinates or a limited joint has no coordinate.
    pub fn new(mechanism: Mechanism) -> Result<Self> {
        let joints = mechanism.in_joint_coordinates()?.joints;
        let limits = mechanism.joints.iter().enumerate().filter_map(|(k, j)| Some((k, j.limit?)));
        let no_coordinate =
            |index: usize| Problem::NoCoordinate { index, kind: mechanism.joints[index].kind.name() }.into();
        let reads = LimitReads::new(mechanism.stops(), joints.iter().copied(), limits, joints.len(), no_coordinate)?;
        Ok(Self { mechanism, reads })
    }

    /// The mechanism.
    pub fn mechanism(&self) -> &Mechanism {
        &self.mechanism
    }
}

impl Unilateral for TreeStops {
    fn stops(&self) -> usize {
        self.reads.len()
    }

    fn model_holding(&self, held: &[usize]) -> Result<Model> {
        Ok(self.mechanism.in_joint_coordinates_holding(&self.reads.held(held))?.model)
    }

    /// `g = s (θ − bound)` and `ġ = s θ̇`, `θ` the coordinate itself.
    fn gaps(&self, q: &[f64], v: &[f64], gaps: &mut [[f64; 2]]) -> Result<()> {
        self.reads.gaps(q, v, gaps, |i, stop| {
            let (bound, sign, _) = self.mechanism.stop_bound(stop);
            [sign * (q[i] - bound), sign * v[i]]
        })
    }

    fn restitution(&self, stop: usize) -> f64 {
        self.mechanism.stop_bound(self.reads.stop(stop)).2
    }

    fn speed_bounds(&self) -> usize {
        self.reads.speed_bounds()
    }

    /// Joints (by index) faster than their limit's `velocity`.
    fn overspeed(&self, q: &[f64], v: &[f64], exceeded: &mut dyn FnMut(usize, f64)) -> Result<()> {
        self.reads.overspeed(q, v, |i| v[i], exceeded)
    }

    fn joint(&self, stop: usize) -> String {
        format!("joint {}", self.reads.stop(stop).joint)
    }

    fn side(&self, stop: usize) -> (bool, f64) {
        let stop = self.reads.stop(stop);
        (stop.upper, self.mechanism.stop_bound(stop).0)
    }
}
