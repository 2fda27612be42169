//! A planar mechanism's joint limits as stops: each finite side of a
//! revolute or prismatic joint's limit ([`Mechanism::stops`]).

use super::unilateral::Unilateral;
use crate::error::Result;
use crate::model::Model;
use crate::planar::Mechanism;

impl Unilateral for Mechanism {
    fn stops(&self) -> usize {
        Mechanism::stops(self).len()
    }

    fn model_holding(&self, held: &[usize]) -> Result<Model> {
        let stops = Mechanism::stops(self);
        let held: Vec<_> = held.iter().map(|&k| stops[k]).collect();
        Ok(self.build_holding(&held)?.model)
    }

    /// Allocates (the planar mechanism reads each joint's coordinate
    /// afresh), unlike the spatial [`MechanismStops`](super::MechanismStops).
    fn gaps(&self, q: &[f64], v: &[f64], gaps: &mut [[f64; 2]]) -> Result<()> {
        gaps.copy_from_slice(&Mechanism::gaps(self, &Mechanism::stops(self), q, v)?);
        Ok(())
    }

    fn restitution(&self, stop: usize) -> f64 {
        self.stop_bound(Mechanism::stops(self)[stop]).2
    }

    /// Joints (by element index) faster than their limit's `velocity`.
    fn speed_bounds(&self) -> usize {
        self.elements.iter().filter(|e| e.limit().is_some_and(|l| l.velocity.is_finite())).count()
    }

    fn overspeed(&self, q: &[f64], v: &[f64], exceeded: &mut dyn FnMut(usize, f64)) -> Result<()> {
        let bounded = self.elements.iter().enumerate().filter_map(|(k, e)| Some((k, e.limit()?.velocity)));
        for (k, bound) in bounded.filter(|(_, bound)| bound.is_finite()) {
            let ratio = self.joint_coordinate(k, q, v)?[1].abs() / bound;
            if ratio > 1.0 {
                exceeded(k, ratio);
            }
        }
        Ok(())
    }

    fn name(&self, stop: usize) -> String {
        let s = Mechanism::stops(self)[stop];
        let kind = self.elements[s.joint].kind();
        format!("element {} ({kind})'s {} limit", s.joint, if s.upper { "upper" } else { "lower" })
    }
}
