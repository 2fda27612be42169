//! A spatial mechanism's joint limits as stops: the sides of each limit
//! its joint's coordinate can meet, their bounds and their gaps at a state
//! (the rows holding them are `StopRow`s, built by `build_holding`).

use super::joint::JointKind;
use super::mechanism::Mechanism;
use crate::error::Result;
use crate::limit::{JointLimit, Stop};

impl Mechanism {
    /// Every finite side of every joint's limit that the joint's coordinate
    /// can meet (an angle is in `(−π, π]`: in a range of a turn or more, a
    /// bound at or beyond ±π is not a stop), lower before upper, joints in order.
    pub fn stops(&self) -> Vec<Stop> {
        let mut out = Vec::new();
        for (joint, j) in self.joints.iter().enumerate() {
            let Some(l) = j.limit else { continue };
            for upper in l.finite_sides().filter(|&upper| reachable(j.kind, &l, l.side(upper).0)) {
                out.push(Stop { joint, upper });
            }
        }
        out
    }

    /// How many finite bounds no stop stands for: a revolute joint's at or
    /// beyond ±π in a range of a turn or more.
    pub fn unreachable_limits(&self) -> usize {
        let bounds = self.joints.iter().filter_map(|j| j.limit.map(|l| (j.kind, l)));
        bounds
            .flat_map(|(kind, l)| [l.lower, l.upper].map(|b| b.is_finite() && !reachable(kind, &l, b)))
            .filter(|&x| x)
            .count()
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
    /// (as [`Mechanism::joint_coordinates`] reads it: an angle in a range
    /// shorter than a turn taken as the range's) moving at `θ̇`.
    pub fn stop_gap(&self, stop: Stop, theta: f64, rate: f64) -> [f64; 2] {
        self.limit(stop).gap(stop.upper, theta, rate)
    }
}

/// Whether a bound of `limit` is a stop: a revolute joint's angle, measured
/// in `(−π, π]`, meets any bound of a range shorter than a turn, and in a
/// longer range only one inside ±π.
fn reachable(kind: JointKind, limit: &JointLimit, bound: f64) -> bool {
    match kind {
        JointKind::Revolute => limit.within_a_turn() || bound.abs() < std::f64::consts::PI,
        _ => bound.is_finite(),
    }
}
