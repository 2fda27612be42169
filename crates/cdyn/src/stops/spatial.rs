//! A spatial mechanism's joint limits as stops ([`MechanismStops`]): each
//! finite side of a limit ([`Mechanism::stops`]), read at every step
//! without allocating. A revolute joint whose range is a turn or more
//! (UR5's ±2π) has periodic gaps ([`Unilateral::period`]): read from the
//! state alone, its angle is the one of its range nearest 0, or the one
//! nearest the angle it was started at ([`MechanismStops::starting_at`]).

use super::reads::LimitReads;
use super::turns::nearest;
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
    /// Each joint's coordinate at the start, where given: a periodic stop's
    /// gap is read nearest its gap there.
    start: Vec<Option<f64>>,
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
        let start = vec![None; mechanism.joints.len()];
        Ok(Self { mechanism, space, reads, start })
    }

    /// The stops of a mechanism started at the joint coordinates `start`
    /// (`(joint index, θ)`, as [`Mechanism::state_at_joints`] takes them):
    /// a revolute joint whose range is a turn or more is read at the turn
    /// of its `θ` (5.0 in −2.62 … 6.28 is 5.0, not −1.28; 7.0 is 7.0, past
    /// the upper bound, a start a run refuses) where its stops are read
    /// from the state alone (a run's start). Other joints are as they
    /// were; a joint that does not exist, or a `θ` that is not finite, is
    /// an error.
    pub fn starting_at(mut self, start: &[(usize, f64)]) -> Result<Self> {
        for &(joint, theta) in start {
            *self.start.get_mut(joint).ok_or(Problem::NoSuchJoint { index: joint })? =
                Some(crate::error::finite("joint coordinate", theta)?);
        }
        Ok(self)
    }

    /// The mechanism.
    pub fn mechanism(&self) -> &Mechanism {
        &self.mechanism
    }
}

impl Unilateral for MechanismStops {
    fn stops(&self) -> usize {
        self.reads.len()
    }

    fn model_holding(&self, held: &[usize]) -> Result<Model> {
        Ok(self.mechanism.build_holding(&self.reads.held(held))?.model)
    }

    /// `g = s (θ − bound)` and `ġ = s θ̇` (see [`Mechanism::stop_gap`]), a
    /// periodic stop's gap the one nearest its gap at its joint's start
    /// where given ([`MechanismStops::starting_at`]).
    fn gaps(&self, q: &[f64], v: &[f64], gaps: &mut [[f64; 2]]) -> Result<()> {
        // A joint's two stops follow each other: its coordinate is read once.
        let mut last: Option<(usize, [f64; 2])> = None;
        self.reads.gaps(q, v, gaps, |i, stop| {
            let [x, rate] = match last {
                Some((read, at)) if read == i => at,
                _ => {
                    let at = self.space.rate(i, q, v);
                    last = Some((i, at));
                    at
                }
            };
            let [g, rate] = self.mechanism.stop_gap(stop, x, rate);
            match (self.start[stop.joint], self.mechanism.stop_period(stop)) {
                (Some(start), Some(period)) => {
                    let (bound, sign, _) = self.mechanism.stop_bound(stop);
                    [nearest(g, sign * (start - bound), period), rate]
                }
                _ => [g, rate],
            }
        })
    }

    /// 2π for the stops of a revolute joint whose range is a turn or more
    /// ([`Mechanism::stop_period`]).
    fn period(&self, stop: usize) -> Option<f64> {
        self.mechanism.stop_period(self.reads.stop(stop))
    }

    fn restitution(&self, stop: usize) -> f64 {
        self.mechanism.stop_bound(self.reads.stop(stop)).2
    }

    fn speed_bounds(&self) -> usize {
        self.reads.speed_bounds()
    }

    /// Joints (by index) faster than their limit's `velocity`.
    fn overspeed(&self, q: &[f64], v: &[f64], exceeded: &mut dyn FnMut(usize, f64)) -> Result<()> {
        self.reads.overspeed(q, v, |i| self.space.rate(i, q, v)[1], exceeded)
    }

    fn joint(&self, stop: usize) -> String {
        format!("joint {}", self.reads.stop(stop).joint)
    }

    fn side(&self, stop: usize) -> (bool, f64) {
        let stop = self.reads.stop(stop);
        (stop.upper, self.mechanism.stop_bound(stop).0)
    }
}
