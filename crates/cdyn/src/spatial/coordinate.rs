//! A joint's own coordinate `θ` in the bodies' redundant coordinates: the
//! angle of body `a` relative to `b` about a revolute joint's axis
//! (right-handed, in `(−π, π]`), or the displacement of `a` relative to `b`
//! along a prismatic joint's axis, both from the initial pose (where the
//! mechanism is assembled, `θ = 0`). It is what a `<mimic>` coupling ties
//! ([`Mimic`]), what a joint limit's stop holds ([`StopRow`]) and what joint-space output reports
//! ([`Mechanism::joint_coordinates`](super::Mechanism::joint_coordinates));
//! written once, generic over the scalar, so that its rate and
//! acceleration come by dual numbers.

use super::joint_rows::{F, Frame, G, H, Place, Side, dot, pose};
use crate::ad::scalar::Scalar;
use crate::model::constraint::Constraint;

/// The coordinate of one revolute or prismatic joint, with its frames on
/// both sides (as its rows have them).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct JointCoordinate {
    /// An angle (revolute) or a displacement (prismatic).
    pub rotary: bool,
    pub a: Frame,
    pub b: Frame,
}

impl JointCoordinate {
    /// `θ − reference` at the sides' poses; for an angle, wrapped into
    /// `(−π, π]`, so that a reference near ±π is met without a jump.
    ///
    /// At the initial pose both frames coincide, so `a`'s `f` axis turned
    /// by `θ` about `h` is `f_b cos θ + g_b sin θ`.
    pub(super) fn from<D: Scalar>(&self, a: &impl Place<D>, b: &impl Place<D>, reference: D) -> D {
        if self.rotary {
            let fa = a.axis(F);
            let (c, s) = (dot(fa, b.axis(F)), dot(fa, b.axis(G)));
            let (cr, sr) = (reference.cos(), reference.sin());
            (s * cr - c * sr).atan2(c * cr + s * sr)
        } else {
            let (pa, pb) = (a.point(), b.point());
            dot(std::array::from_fn(|i| pa[i] - pb[i]), b.axis(H)) - reference
        }
    }

    /// `θ` of the joint whose sides are `sides` (a body's slot in `x`, or
    /// the ground) in the coordinates `x` of `K / 7` bodies.
    pub(super) fn at<D: Scalar, const K: usize>(&self, x: &[D; K], sides: [Option<usize>; 2], reference: D) -> D {
        let side = |slot: Option<usize>, frame| match slot {
            Some(k) => {
                let (r, p) = pose(x, 7 * k);
                Side::Body { r, p, frame }
            }
            None => Side::Ground(frame),
        };
        self.from(&side(sides[0], &self.a), &side(sides[1], &self.b), reference)
    }
}

/// A `<mimic>` coupling, one constraint row: `θ_follower − (m θ_leader + o) = 0`,
/// on the coordinates of the (up to four) bodies of the two joints, `K = 7 ×` their number.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Mimic {
    pub follower: (JointCoordinate, [Option<usize>; 2]),
    pub leader: (JointCoordinate, [Option<usize>; 2]),
    pub multiplier: f64,
    pub offset: f64,
}

impl<const K: usize> Constraint<K, 1> for Mimic {
    fn eval<D: Scalar>(&self, x: [D; K], _t: D) -> [D; 1] {
        let zero = D::from(0.0);
        let leader = self.leader.0.at(&x, self.leader.1, zero);
        [self.follower.0.at(&x, self.follower.1, leader * self.multiplier + self.offset)]
    }
}

/// The row holding a joint at a stop of its limit: `g = s (θ − bound)`,
/// `s = 1` at a lower bound and `−1` at an upper one (`g ≥ 0` allowed), on
/// the coordinates of the joint's (one or two) bodies, `K = 7 ×` their number.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct StopRow {
    pub coordinate: JointCoordinate,
    pub bound: f64,
    pub sign: f64,
}

impl<const K: usize> Constraint<K, 1> for StopRow {
    fn eval<D: Scalar>(&self, x: [D; K], _t: D) -> [D; 1] {
        let b = (K == 14).then_some(1);
        [self.coordinate.at(&x, [Some(0), b], D::from(self.bound)) * self.sign]
    }
}
