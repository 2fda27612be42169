//! The rows and forces of a tree on its joint coordinates: a `<mimic>`
//! coupling, a held stop, a drive, an actuator. Each reads one or two
//! coordinates, written once generic over the scalar like every element
//! (their Jacobians, `γ` and generalized-α's Newton terms come by AD).

use crate::ad::scalar::Scalar;
use crate::model::constraint::Constraint;
use crate::model::force::Force;
use crate::model::timefn::TimeFn;
use crate::spatial::actuator::Law;

/// `x_f − m x_l − offset`: a `<mimic>` coupling.
pub(super) struct Coupled {
    pub multiplier: f64,
    pub offset: f64,
}

impl Constraint<2, 1> for Coupled {
    fn eval<D: Scalar>(&self, [follower, leader]: [D; 2], _t: D) -> [D; 1] {
        [follower - leader * self.multiplier - self.offset]
    }
}

/// `s (θ − bound)`: a held stop.
pub(super) struct Bound {
    pub bound: f64,
    pub sign: f64,
}

impl Constraint<1, 1> for Bound {
    fn eval<D: Scalar>(&self, [theta]: [D; 1], _t: D) -> [D; 1] {
        [(theta - self.bound) * self.sign]
    }
}

/// `θ − f(t)`: a driven joint.
pub(super) struct Driven(pub TimeFn);

impl Constraint<1, 1> for Driven {
    fn eval<D: Scalar>(&self, [theta]: [D; 1], t: D) -> [D; 1] {
        [theta - self.0.eval(t)]
    }
}

/// An actuator's torque on its coordinate. A servo's error is `θ − θ_ref`
/// itself: a joint coordinate counts turns, so the servo turns the way
/// the numbers say (to 2π + 0.1 from 0, a whole turn and a little).
pub(super) struct Actuated(pub Law);

impl Force<1> for Actuated {
    fn force<D: Scalar>(&self, [theta]: [D; 1], [rate]: [D; 1], t: D) -> [D; 1] {
        [self.0.torque(t, |target| theta - target, || rate)]
    }
}
