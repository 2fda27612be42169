//! Where a mechanism's joint limits read its joints' coordinates
//! ([`LimitReads`]): found once, when its stops are built, so that a step
//! reads each stop's gap and each velocity bound's rate without allocating.
//! Shared by the spatial and the planar stops, which differ only in how a
//! joint's coordinate is read and in what a gap is of it.

use crate::error::{Error, Problem, Result};
use crate::limit::{JointLimit, Stop};

/// A mechanism's stops and velocity bounds, each with the place of its
/// joint among the joints its reader reads.
#[derive(Debug, Clone)]
pub(super) struct LimitReads {
    stops: Vec<Stop>,
    /// Each stop's joint's place among those read.
    stop_reads: Vec<usize>,
    /// Each finite velocity bound: `(place read, joint, bound)`.
    speed_reads: Vec<(usize, usize, f64)>,
    /// The mechanism's coordinates (a reader indexes them).
    n: usize,
}

impl LimitReads {
    /// The `stops` of the joints `limits` (index and limit), read among the
    /// joints `read` (in the reader's order), in a state of `n`
    /// coordinates; `no_coordinate(joint)` if a stop's joint is not read.
    pub(super) fn new(
        stops: Vec<Stop>,
        read: impl Iterator<Item = usize>,
        limits: impl Iterator<Item = (usize, JointLimit)>,
        n: usize,
        no_coordinate: impl Fn(usize) -> Error,
    ) -> Result<Self> {
        let read: Vec<usize> = read.collect();
        let at = |joint: usize| read.iter().position(|&j| j == joint);
        let stop_reads =
            stops.iter().map(|s| at(s.joint).ok_or_else(|| no_coordinate(s.joint))).collect::<Result<_>>()?;
        let bounded = limits.filter(|(_, l)| l.velocity.is_finite());
        let speed_reads = bounded.filter_map(|(joint, l)| Some((at(joint)?, joint, l.velocity))).collect();
        Ok(Self { stops, stop_reads, speed_reads, n })
    }

    /// How many stops.
    pub(super) fn len(&self) -> usize {
        self.stops.len()
    }

    /// Stop `k`.
    pub(super) fn stop(&self, k: usize) -> Stop {
        self.stops[k]
    }

    /// The stops `held` (indices).
    pub(super) fn held(&self, held: &[usize]) -> Vec<Stop> {
        held.iter().map(|&k| self.stops[k]).collect()
    }

    /// Each stop's `gap(place read, stop)` into `gaps`, once `(q, v)` are
    /// checked to be of the mechanism's length.
    pub(super) fn gaps(
        &self,
        q: &[f64],
        v: &[f64],
        gaps: &mut [[f64; 2]],
        mut gap: impl FnMut(usize, Stop) -> [f64; 2],
    ) -> Result<()> {
        self.check_state(q, v)?;
        for ((out, &stop), &i) in gaps.iter_mut().zip(&self.stops).zip(&self.stop_reads) {
            *out = gap(i, stop);
        }
        Ok(())
    }

    /// How many velocity bounds.
    pub(super) fn speed_bounds(&self) -> usize {
        self.speed_reads.len()
    }

    /// Calls `exceeded(joint, |θ̇| / bound)` for each joint faster than its
    /// bound, its rate `rate(place read)`.
    pub(super) fn overspeed(
        &self,
        q: &[f64],
        v: &[f64],
        rate: impl Fn(usize) -> f64,
        exceeded: &mut dyn FnMut(usize, f64),
    ) -> Result<()> {
        self.check_state(q, v)?;
        for &(i, joint, bound) in &self.speed_reads {
            let ratio = rate(i).abs() / bound;
            if ratio > 1.0 {
                exceeded(joint, ratio);
            }
        }
        Ok(())
    }

    fn check_state(&self, q: &[f64], v: &[f64]) -> Result<()> {
        if q.len() != self.n || v.len() != self.n {
            let (positions, velocities) = (q.len(), v.len());
            return Err(Problem::StateLength { positions, velocities, n: self.n }.into());
        }
        Ok(())
    }
}
