//! A spatial mechanism's joint limits as stops ([`MechanismStops`]): each
//! finite side of a limit its joint can meet ([`Mechanism::stops`]), read
//! at every step without allocating.

use super::reads::LimitReads;
use super::unilateral::Unilateral;
use crate::error::{Problem, Result};
use crate::model::Model;
use crate::spatial::{JointSpace, Mechanism};

/// A [`Mechanism`]'s joint limits as a [`Unilateral`] system. Built once
/// (the reader of its joints' coordinates and where each stop and velocity
/// bound reads it), so that a step reads the gaps and rates without
/// allocating.
#[derive(Debug, Clone)]
pub struct MechanismStops {
    mechanism: Mechanism,
    space: JointSpace,
    reads: LimitReads,
    /// The accelerations the coordinates are read with (not used: zeros).
    zeros: Vec<f64>,
}

impl MechanismStops {
    /// The stops of `mechanism`'s joint limits; an error if a limited
    /// joint has no coordinate (neither revolute nor prismatic).
    pub fn new(mechanism: Mechanism) -> Result<Self> {
        let space = mechanism.joint_space()?;
        let limits = mechanism.joints.iter().enumerate().filter_map(|(k, j)| Some((k, j.limit?)));
        let n = 7 * mechanism.bodies.len();
        let no_coordinate =
            |index: usize| Problem::NoCoordinate { index, kind: mechanism.joints[index].kind.name() }.into();
        let reads = LimitReads::new(mechanism.stops(), space.joints(), limits, n, no_coordinate)?;
        Ok(Self { zeros: vec![0.0; n], mechanism, space, reads })
    }

    /// The mechanism.
    pub fn mechanism(&self) -> &Mechanism {
        &self.mechanism
    }

    /// `(θ, θ̇)` of the `i`-th joint read.
    fn at(&self, i: usize, q: &[f64], v: &[f64]) -> [f64; 2] {
        let [x, rate, _] = self.space.at(i, q, v, &self.zeros);
        [x, rate]
    }
}

impl Unilateral for MechanismStops {
    fn stops(&self) -> usize {
        self.reads.len()
    }

    fn model_holding(&self, held: &[usize]) -> Result<Model> {
        Ok(self.mechanism.build_holding(&self.reads.held(held))?.model)
    }

    /// `g = s (θ − bound)` and `ġ = s θ̇` (see [`Mechanism::stop_gap`]).
    fn gaps(&self, q: &[f64], v: &[f64], gaps: &mut [[f64; 2]]) -> Result<()> {
        self.reads.gaps(q, v, gaps, |i, stop| {
            let [x, rate] = self.at(i, q, v);
            self.mechanism.stop_gap(stop, x, rate)
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
        self.reads.overspeed(q, v, |i| self.at(i, q, v)[1], exceeded)
    }

    fn joint(&self, stop: usize) -> String {
        format!("joint {}", self.reads.stop(stop).joint)
    }

    fn side(&self, stop: usize) -> (bool, f64) {
        let stop = self.reads.stop(stop);
        (stop.upper, self.mechanism.stop_bound(stop).0)
    }
}
