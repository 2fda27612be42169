//! A spatial mechanism's joint limits as stops: each finite side of each
//! limit, its bound and its gap at a state (the rows holding them are
//! `StopRow`s, built by `build_holding`).
//!
//! A revolute joint's angle is read in `(−π, π]`. In a range shorter than
//! a turn that tells where the joint is ([`JointLimit::unwrap_angle`]); in
//! a range of a turn or more (UR5's ±2π, TIAGo's fingers' −2.62 … 6.28) it
//! does not: a stop there reads the angle of the range nearest a reference
//! (0 unless told), and its gap is periodic ([`Mechanism::stop_period`]),
//! its turns followed from step to step by the run ([`crate::stops`]).

use super::joint::JointKind;
use super::mechanism::Mechanism;
use crate::error::Result;
use crate::limit::{JointLimit, Stop};
use std::f64::consts::TAU;

impl Mechanism {
    /// Every finite side of every joint's limit, lower before upper, joints in order.
    pub fn stops(&self) -> Vec<Stop> {
        let mut out = Vec::new();
        for (joint, j) in self.joints.iter().enumerate() {
            let Some(l) = j.limit else { continue };
            out.extend(l.finite_sides().map(|upper| Stop { joint, upper }));
        }
        out
    }

    /// The stop's bound, its sign `s` (1 lower, −1 upper) and its joint's restitution.
    pub fn stop_bound(&self, stop: Stop) -> (f64, f64, f64) {
        let l = self.limit(stop);
        let (bound, sign) = l.side(stop.upper);
        (bound, sign, l.restitution)
    }

    fn limit(&self, stop: Stop) -> JointLimit {
        self.joints[stop.joint].limit.expect("a stop's joint has a limit")
    }

    /// The period of the stop's gap: `Some(2π)` for a revolute joint whose
    /// range is a turn or more, where an angle read from the state alone
    /// is the joint's only up to whole turns; `None` otherwise.
    pub fn stop_period(&self, stop: Stop) -> Option<f64> {
        let multi_turn = self.joints[stop.joint].kind == JointKind::Revolute && !self.limit(stop).within_a_turn();
        multi_turn.then_some(TAU)
    }

    /// The gap `g = s (θ − bound)` and its rate `ġ` of each stop at `(q, v)`.
    pub fn gaps(&self, stops: &[Stop], q: &[f64], v: &[f64]) -> Result<Vec<[f64; 2]>> {
        let theta = self.joint_coordinates(q, v, &vec![0.0; q.len()])?;
        Ok(stops
            .iter()
            .map(|&s| {
                let [x, rate, _] = theta[s.joint].expect("a stop's joint has a coordinate");
                self.stop_gap(s, x, rate)
            })
            .collect())
    }

    /// The gap and its rate of `stop` where its joint's coordinate is `θ`
    /// (as [`Mechanism::joint_coordinates`] reads it) moving at `θ̇`; a
    /// periodic stop's ([`Mechanism::stop_period`]) at the angle `θ + 2πk`
    /// of its joint's range nearest 0.
    pub fn stop_gap(&self, stop: Stop, theta: f64, rate: f64) -> [f64; 2] {
        let limit = self.limit(stop);
        let theta = if self.stop_period(stop).is_some() { limit.turn_nearest(theta, 0.0) } else { theta };
        limit.gap(stop.upper, theta, rate)
    }
}
