//! A spatial mechanism's joint limits as stops ([`MechanismStops`]): each
//! finite side of a limit its joint can meet ([`Mechanism::stops`]), read
//! at every step without allocating.

use super::unilateral::Unilateral;
use crate::error::{Problem, Result};
use crate::model::Model;
use crate::spatial::{JointSpace, Mechanism, Stop};

/// A [`Mechanism`]'s joint limits as a [`Unilateral`] system. Built once
/// (the reader of its joints' coordinates and where each stop and velocity
/// bound reads it), so that a step reads the gaps and rates without
/// allocating.
#[derive(Debug, Clone)]
pub struct MechanismStops {
    mechanism: Mechanism,
    stops: Vec<Stop>,
    space: JointSpace,
    /// Each stop's joint, as the `i` of [`JointSpace::at`].
    stop_reads: Vec<usize>,
    /// Each velocity bound: `(i of JointSpace::at, joint, bound)`.
    speed_reads: Vec<(usize, usize, f64)>,
    /// The accelerations the coordinates are read with (not used: zeros).
    zeros: Vec<f64>,
}

impl MechanismStops {
    /// The stops of `mechanism`'s joint limits; an error if a limited
    /// joint has no coordinate (neither revolute nor prismatic).
    pub fn new(mechanism: Mechanism) -> Result<Self> {
        let stops = mechanism.stops();
        let space = mechanism.joint_space()?;
        let read: Vec<usize> = space.joints().collect();
        let at = |joint: usize| read.iter().position(|&j| j == joint);
        let stop_reads = stops
            .iter()
            .map(|s| at(s.joint).ok_or_else(|| no_coordinate(&mechanism, s.joint)))
            .collect::<Result<_>>()?;
        let limited = mechanism.joints.iter().enumerate().filter_map(|(k, j)| j.limit.map(|l| (k, l.velocity)));
        let speed_reads = limited.filter_map(|(joint, bound)| Some((at(joint)?, joint, bound))).collect();
        let zeros = vec![0.0; 7 * mechanism.bodies.len()];
        Ok(Self { mechanism, stops, space, stop_reads, speed_reads, zeros })
    }

    /// The mechanism.
    pub fn mechanism(&self) -> &Mechanism {
        &self.mechanism
    }
}

fn no_coordinate(mechanism: &Mechanism, index: usize) -> crate::Error {
    Problem::NoCoordinate { index, kind: mechanism.joints[index].kind.name() }.into()
}

impl Unilateral for MechanismStops {
    fn stops(&self) -> usize {
        self.stops.len()
    }

    fn model_holding(&self, held: &[usize]) -> Result<Model> {
        let held: Vec<_> = held.iter().map(|&k| self.stops[k]).collect();
        Ok(self.mechanism.build_holding(&held)?.model)
    }

    /// `g = s (θ − bound)` and `ġ = s θ̇` (see [`Mechanism::stop_gap`]).
    fn gaps(&self, q: &[f64], v: &[f64], gaps: &mut [[f64; 2]]) -> Result<()> {
        check_state(self.zeros.len(), q, v)?;
        for ((gap, &stop), &i) in gaps.iter_mut().zip(&self.stops).zip(&self.stop_reads) {
            let [x, rate, _] = self.space.at(i, q, v, &self.zeros);
            *gap = self.mechanism.stop_gap(stop, x, rate);
        }
        Ok(())
    }

    fn restitution(&self, stop: usize) -> f64 {
        self.mechanism.stop_bound(self.stops[stop]).2
    }

    fn speed_bounds(&self) -> usize {
        self.speed_reads.len()
    }

    /// Joints (by index) faster than their limit's `velocity`.
    fn overspeed(&self, q: &[f64], v: &[f64], exceeded: &mut dyn FnMut(usize, f64)) -> Result<()> {
        check_state(self.zeros.len(), q, v)?;
        for &(i, joint, bound) in &self.speed_reads {
            let ratio = self.space.at(i, q, v, &self.zeros)[1].abs() / bound;
            if ratio > 1.0 {
                exceeded(joint, ratio);
            }
        }
        Ok(())
    }

    fn name(&self, stop: usize) -> String {
        let s = self.stops[stop];
        format!("joint {}'s {} limit", s.joint, if s.upper { "upper" } else { "lower" })
    }
}

/// Checks `q` and `v` have the mechanism's `n` coordinates (the reader
/// indexes them).
fn check_state(n: usize, q: &[f64], v: &[f64]) -> Result<()> {
    if q.len() != n || v.len() != n {
        let (positions, velocities) = (q.len(), v.len());
        return Err(Problem::StateLength { positions, velocities, n }.into());
    }
    Ok(())
}
