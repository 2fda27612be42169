//! Joint actuators: a torque about a revolute joint's axis (a force along
//! a prismatic joint's), between its two bodies, given as a function of
//! time or by a PD servo to a target, saturated at the joint limit's
//! `effort`.
//!
//! The torque `τ` acts on body `a` about the axis `h` (carried by `a`) and
//! `−τ` on `b`, so that its power is `τ θ̇` with `θ` the joint's coordinate
//! (the angle or displacement of `a` relative to `b`, see
//! [`Mechanism::joint_coordinates`](super::Mechanism::joint_coordinates)):
//! a positive torque drives `θ` up. It is a force element like the joint's
//! damping, written once generic over the scalar, so that its power enters
//! `Ė` and its Jacobians (generalized-α's Newton matrix) come by AD.

use super::body::SpatialBody;
use super::coordinate::JointCoordinate;
use super::joint_rows::{H, dot, pose};
use super::load::{apply, body_end, ground_end};
use super::rotation::{rotate_fixed, space_rate, torque_on_parameters};
use crate::ad::scalar::Scalar;
use crate::error::{Problem, Result};
use crate::limit::JointLimit;
use crate::model::force::Force;
use crate::model::timefn::TimeFn;

/// A joint actuator as the user describes it: on revolute or prismatic
/// joint `joint` (an index into [`Mechanism::joints`](super::Mechanism::joints);
/// in a scenario file an `[[actuators]]` entry naming it), either the
/// torque (force) `τ(t)`, or a PD servo
/// `τ = kp (θ_ref(t) − θ) + kd (θ̇_ref(t) − θ̇)` to the target `θ_ref`
/// (`θ − θ_ref` of a revolute joint taken in `(−π, π]`: the servo turns the
/// short way; but where the joint's limit is a range shorter than a turn,
/// `θ` is taken in that range and the servo turns within it, never through
/// the range's gap), `θ̇_ref` the target's derivative (an input's term,
/// constant between steps, has none).
///
/// Where the joint's [`limit`](super::Joint::limit) has a finite `effort`,
/// `τ` is clamped to `±effort`. The clamp is continuous but not smooth:
/// where it holds, `τ` no longer depends on `θ`, `θ̇`, and the Newton
/// matrix of generalized-α (whose force Jacobians come by AD from the same
/// code) sees a zero gain there and the servo's gains inside; a step that
/// crosses the corner converges like Newton on a kinked function, and
/// a scheme's order drops at the instants the clamp engages or releases.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Deserialize), serde(deny_unknown_fields))]
#[non_exhaustive]
pub struct Actuator<J = usize> {
    /// The joint it drives.
    pub joint: J,
    /// The torque (force) as a function of time; not with `target`.
    #[cfg_attr(feature = "serde", serde(default))]
    pub torque: Option<TimeFn>,
    /// A servo's target coordinate `θ_ref(t)`; not with `torque`.
    #[cfg_attr(feature = "serde", serde(default))]
    pub target: Option<TimeFn>,
    /// A servo's stiffness `kp` (N m/rad, N/m), non-negative.
    #[cfg_attr(feature = "serde", serde(default))]
    pub kp: f64,
    /// A servo's damping `kd` (N m s/rad, N s/m), non-negative.
    #[cfg_attr(feature = "serde", serde(default))]
    pub kd: f64,
}

impl<J> Actuator<J> {
    /// The torque (force) `torque(t)` on `joint`.
    pub fn torque(joint: J, torque: TimeFn) -> Self {
        Self { joint, torque: Some(torque), target: None, kp: 0.0, kd: 0.0 }
    }

    /// A PD servo of `joint` to `target(t)` with gains `kp`, `kd`.
    pub fn servo(joint: J, target: TimeFn, kp: f64, kd: f64) -> Self {
        Self { joint, torque: None, target: Some(target), kp, kd }
    }

    /// The same actuator on the joint `f(joint)` (a name to an index, say).
    pub fn map_joint<K>(self, f: impl FnOnce(J) -> K) -> Actuator<K> {
        let Actuator { joint, torque, target, kp, kd } = self;
        Actuator { joint: f(joint), torque, target, kp, kd }
    }

    /// The functions of time it reads (their inputs are the model's).
    pub fn functions(&self) -> impl Iterator<Item = &TimeFn> {
        self.torque.iter().chain(&self.target)
    }

    /// Its law, checked: one of `torque` and `target`, finite, gains
    /// non-negative and only for a servo, which needs one of them positive.
    pub(super) fn law(&self, effort: f64) -> Result<Law> {
        let kp = crate::error::non_negative("kp", self.kp)?;
        let kd = crate::error::non_negative("kd", self.kd)?;
        if self.functions().any(|f| !f.is_finite()) {
            return Err(Problem::NonFiniteFunction.into());
        }
        let refuse = |reason| Err(Problem::Actuator { reason }.into());
        let drive = match (&self.torque, &self.target) {
            (Some(_), Some(_)) => return refuse("torque and target: give one, a torque or a servo's target"),
            (None, None) => return refuse("an actuator needs a torque or a servo's target"),
            (Some(_), None) if kp != 0.0 || kd != 0.0 => {
                return refuse("kp and kd are a servo's gains (with target), not a torque's");
            }
            (Some(torque), None) => Drive::Torque(torque.clone()),
            (None, Some(_)) if kp == 0.0 && kd == 0.0 => {
                return refuse("a servo needs kp or kd positive: with no gain it does nothing");
            }
            (None, Some(target)) => Drive::Servo { rate: target.derivative(), target: target.clone(), kp, kd },
        };
        Ok(Law { drive, effort })
    }
}

crate::setters!(impl<J> Actuator<J> {
    /// With this torque (force) as a function of time.
    with_torque => torque(Some): TimeFn,
    /// With this servo target.
    with_target => target(Some): TimeFn,
    /// With this servo stiffness.
    with_kp => kp: f64,
    /// With this servo damping.
    with_kd => kd: f64,
});

/// What sets the torque before the clamp.
#[derive(Debug, Clone, PartialEq)]
enum Drive {
    Torque(TimeFn),
    Servo { target: TimeFn, rate: TimeFn, kp: f64, kd: f64 },
}

/// An actuator's law, checked, with its joint's effort bound.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Law {
    drive: Drive,
    effort: f64,
}

/// An actuator on a joint: its law and the joint's coordinate. Reads
/// `(r, p)` of `a` (`K = 7`, `b` the ground) or of `a` and `b` (`K = 14`).
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct JointActuator {
    pub law: Law,
    pub coordinate: JointCoordinate,
    /// A revolute joint's limit shorter than a turn: the range its servo
    /// reads `θ` in (Panda's joint 6, −0.0175 to 3.7525, servoed from 0.2
    /// to 3.5 turns up, where the short way would drive it down into its
    /// lower stop).
    pub range: Option<JointLimit>,
}

impl Law {
    /// `τ` at time `t`, clamped, for a servo whose joint is `error(θ_ref)`
    /// off its target `θ_ref` and moves at `rate()` (read only by a servo).
    #[inline(always)]
    pub(crate) fn torque<D: Scalar>(&self, t: D, error: impl FnOnce(D) -> D, rate: impl FnOnce() -> D) -> D {
        let tau = match &self.drive {
            Drive::Torque(f) => f.eval(t),
            Drive::Servo { target, rate: target_rate, kp, kd } => {
                (target_rate.eval(t) - rate()) * *kd - error(target.eval(t)) * *kp
            }
        };
        // The clamp: τ held at ±effort, whose derivatives are then zero.
        if tau.re() > self.effort {
            D::from(self.effort)
        } else if tau.re() < -self.effort {
            D::from(-self.effort)
        } else {
            tau
        }
    }
}

impl JointActuator {
    /// `τ` at the coordinates `x`, rates `xd` and time `t`, clamped.
    fn torque<D: Scalar, const K: usize>(&self, x: &[D; K], xd: &[D; K], t: D) -> D {
        let error = |target: D| match self.range {
            Some(_) => self.coordinate.in_range(x, self.sides::<K>(), self.range) - target,
            None => self.coordinate.at(x, self.sides::<K>(), target),
        };
        self.law.torque(t, error, || self.rate(x, xd))
    }

    fn sides<const K: usize>(&self) -> [Option<usize>; 2] {
        [Some(0), (K == 14).then_some(1)]
    }

    /// `θ̇` where the joint holds: `(ω_a − ω_b) · h` of a revolute joint,
    /// the rate of `a`'s point relative to `b`'s along `h` of a prismatic one.
    fn rate<D: Scalar, const K: usize>(&self, x: &[D; K], xd: &[D; K]) -> D {
        let h = self.axis(x);
        let (a, b) = self.ends(x, xd);
        if self.coordinate.rotary {
            let w = |at: usize| space_rate(pose(x, at).1, std::array::from_fn(|i| xd[at + 3 + i]));
            let wb = if K == 14 { w(7) } else { [D::zero(); 3] };
            let wa = w(0);
            dot(std::array::from_fn(|i| wa[i] - wb[i]), h)
        } else {
            dot(std::array::from_fn(|i| a.velocity[i] - b.velocity[i]), h)
        }
    }

    /// The axis `h` carried by `a`, in space.
    fn axis<D: Scalar, const K: usize>(&self, x: &[D; K]) -> [D; 3] {
        rotate_fixed(pose(x, 0).1, self.coordinate.a.axes[H])
    }

    fn ends<D: Scalar, const K: usize>(&self, x: &[D; K], xd: &[D; K]) -> (super::load::End<D>, super::load::End<D>) {
        let a = body_end(x, xd, 0, self.coordinate.a.s);
        let b = if K == 14 { body_end(x, xd, 7, self.coordinate.b.s) } else { ground_end(self.coordinate.b.s) };
        (a, b)
    }

    fn forces<D: Scalar, const K: usize>(&self, x: [D; K], xd: [D; K], t: D) -> [D; K] {
        let tau = self.torque(&x, &xd, t);
        let n = self.axis(&x).map(|h| h * tau);
        let mut out = [D::zero(); K];
        if self.coordinate.rotary {
            let on = |at: usize, n: [D; 3]| torque_on_parameters(pose(&x, at).1, n);
            out[3..7].copy_from_slice(&on(0, n));
            if K == 14 {
                out[10..14].copy_from_slice(&on(7, n.map(|x| -x)));
            }
        } else {
            let (a, b) = self.ends(&x, &xd);
            apply(&a, n, &mut out, 0);
            apply(&b, n.map(|x| -x), &mut out, 7);
        }
        out
    }

    /// The torque applied at the state `(q, v)` (the bodies' 7 or 14
    /// coordinates and rates) at time `t`.
    pub fn applied<const K: usize>(&self, x: [f64; K], xd: [f64; K], t: f64) -> f64 {
        self.torque(&x, &xd, t)
    }
}

impl Force<14> for JointActuator {
    fn force<D: Scalar>(&self, x: [D; 14], xd: [D; 14], t: D) -> [D; 14] {
        self.forces(x, xd, t)
    }
}

impl Force<7> for JointActuator {
    fn force<D: Scalar>(&self, x: [D; 7], xd: [D; 7], t: D) -> [D; 7] {
        self.forces(x, xd, t)
    }
}

/// The torques a mechanism's actuators apply, read from a state without
/// allocating (a recorder writes them at every sample): built once by
/// [`Mechanism::actuator_torques`](super::Mechanism::actuator_torques).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct ActuatorTorques {
    read: Vec<Applied>,
}

#[derive(Debug, Clone, PartialEq)]
struct Applied {
    joint: usize,
    actuator: JointActuator,
    a: usize,
    b: Option<usize>,
}

impl ActuatorTorques {
    /// From `(joint index, its actuator, body a, body b)` for each actuator.
    pub(super) fn new(read: Vec<(usize, JointActuator, usize, Option<usize>)>) -> Self {
        let read = read.into_iter().map(|(joint, actuator, a, b)| Applied { joint, actuator, a, b }).collect();
        Self { read }
    }

    /// The joint (an index into [`Mechanism::joints`](super::Mechanism::joints))
    /// of each actuator, in order.
    pub fn joints(&self) -> impl ExactSizeIterator<Item = usize> + '_ {
        self.read.iter().map(|r| r.joint)
    }

    /// The torque (force) the `i`-th actuator applies at the state `(q, v)`
    /// at time `t`, after the clamp at the joint's effort. Panics if `i` is
    /// not below [`ActuatorTorques::joints`]' count or a slice is short.
    pub fn at(&self, i: usize, q: &[f64], v: &[f64], t: f64) -> f64 {
        let r = &self.read[i];
        let body = |k: usize| SpatialBody::of(if k < 7 { r.a } else { r.b.unwrap_or(r.a) }).first + k % 7;
        match r.b {
            Some(_) => {
                let (x, xd): ([f64; 14], [f64; 14]) =
                    (std::array::from_fn(|k| q[body(k)]), std::array::from_fn(|k| v[body(k)]));
                r.actuator.applied(x, xd, t)
            }
            None => {
                let (x, xd): ([f64; 7], [f64; 7]) =
                    (std::array::from_fn(|k| q[body(k)]), std::array::from_fn(|k| v[body(k)]));
                r.actuator.applied(x, xd, t)
            }
        }
    }
}
