//! A spatial mechanism's joint limits as stops: each finite side of a
//! limit its joint can meet ([`Mechanism::stops`]).

use super::unilateral::Unilateral;
use crate::error::Result;
use crate::model::Model;
use crate::spatial::Mechanism;

impl Unilateral for Mechanism {
    fn stops(&self) -> usize {
        Mechanism::stops(self).len()
    }

    fn model_holding(&self, held: &[usize]) -> Result<Model> {
        let stops = Mechanism::stops(self);
        let held: Vec<_> = held.iter().map(|&k| stops[k]).collect();
        Ok(self.build_holding(&held)?.model)
    }

    fn gaps(&self, q: &[f64], v: &[f64]) -> Result<Vec<[f64; 2]>> {
        Mechanism::gaps(self, &Mechanism::stops(self), q, v)
    }

    fn restitution(&self, stop: usize) -> f64 {
        self.stop_bound(Mechanism::stops(self)[stop]).2
    }

    /// Joints (by index) faster than their limit's `velocity`.
    fn overspeed(&self, q: &[f64], v: &[f64]) -> Result<Vec<(usize, f64)>> {
        let theta = self.joint_coordinates(q, v, &vec![0.0; q.len()])?;
        let bounds = self.joints.iter().map(|j| j.limit.map_or(f64::INFINITY, |l| l.velocity));
        Ok(theta
            .iter()
            .zip(bounds)
            .enumerate()
            .filter_map(|(k, (x, bound))| x.map(|[_, rate, _]| (k, rate.abs() / bound)))
            .filter(|&(_, ratio)| ratio > 1.0)
            .collect())
    }

    fn name(&self, stop: usize) -> String {
        let s = Mechanism::stops(self)[stop];
        format!("joint {}'s {} limit", s.joint, if s.upper { "upper" } else { "lower" })
    }
}
