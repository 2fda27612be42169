//! A joint's own coordinate `θ` in the bodies' redundant coordinates: the
//! angle of body `a` relative to `b` about a revolute joint's axis
//! (right-handed, in `(−π, π]`), or the displacement of `a` relative to `b`
//! along a prismatic joint's axis, both from the initial pose (where the
//! mechanism is assembled, `θ = 0`). It is what a `<mimic>` coupling ties
//! ([`Mimic`]), what a joint limit's stop holds ([`StopRow`]) and what joint-space output reports
//! ([`Mechanism::joint_coordinates`](super::Mechanism::joint_coordinates),
//! an angle in a limit's range shorter than a turn taken as that range's);
//! written once, generic over the scalar, so that its rate and
//! acceleration come by dual numbers.

use super::body::SpatialBody;
use super::joint_rows::{F, Frame, G, H, Place, Side, dot, pose};
use crate::ad::scalar::Scalar;
use crate::limit::JointLimit;
use crate::model::constraint::Constraint;
use num_dual::{Dual2_64, Dual64};

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
    /// The range a revolute joint's angle is read in: its `limit`, where
    /// that is shorter than a turn ([`JointLimit::within_a_turn`]).
    pub(super) fn range(&self, limit: Option<JointLimit>) -> Option<JointLimit> {
        limit.filter(|l| self.rotary && l.within_a_turn())
    }

    /// `θ` read in `(−π, π]` ([`at`](Self::at) from 0), shifted by whole
    /// turns into `range` if there is one: its derivatives are unchanged.
    pub(super) fn in_range<D: Scalar, const K: usize>(
        &self,
        x: &[D; K],
        sides: [Option<usize>; 2],
        range: Option<JointLimit>,
    ) -> D {
        let theta = self.at(x, sides, D::zero());
        match range {
            Some(range) => theta + (range.unwrap_angle(theta.re()) - theta.re()),
            None => theta,
        }
    }

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

    /// Marks in `read` the coordinates [`at`](Self::at) depends on: an
    /// angle turns with the sides' Euler parameters alone, a displacement
    /// moves with their positions too.
    pub(super) fn reads(&self, sides: [Option<usize>; 2], read: &mut [bool]) {
        let from = if self.rotary { 3 } else { 0 };
        for k in sides.into_iter().flatten() {
            read[7 * k + from..7 * k + 7].fill(true);
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
    fn reads(&self) -> [[bool; K]; 1] {
        let mut read = [false; K];
        self.leader.0.reads(self.leader.1, &mut read);
        self.follower.0.reads(self.follower.1, &mut read);
        [read]
    }
    /// `w (∇²θ_follower − m ∇²θ_leader)`, in closed form.
    fn curvature(&self, x: [f64; K], _t: f64, w: &[f64; 1]) -> [[f64; K]; K] {
        let (f, l) = (self.follower.0.hessian(&x, self.follower.1), self.leader.0.hessian(&x, self.leader.1));
        std::array::from_fn(|i| std::array::from_fn(|j| w[0] * (f[i][j] - self.multiplier * l[i][j])))
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

impl StopRow {
    /// Its joint's sides among its `K` coordinates: one body, or two.
    fn sides<const K: usize>() -> [Option<usize>; 2] {
        [Some(0), (K == 14).then_some(1)]
    }
}

impl<const K: usize> Constraint<K, 1> for StopRow {
    fn eval<D: Scalar>(&self, x: [D; K], _t: D) -> [D; 1] {
        [self.coordinate.at(&x, StopRow::sides::<K>(), D::from(self.bound)) * self.sign]
    }
    fn reads(&self) -> [[bool; K]; 1] {
        let mut read = [false; K];
        self.coordinate.reads(StopRow::sides::<K>(), &mut read);
        [read]
    }
    /// `w s ∇²θ`, in closed form.
    fn curvature(&self, x: [f64; K], _t: f64, w: &[f64; 1]) -> [[f64; K]; K] {
        let scale = w[0] * self.sign;
        self.coordinate.hessian(&x, StopRow::sides::<K>()).map(|row| row.map(|h| scale * h))
    }
}

/// The coordinates of a mechanism's revolute and prismatic joints, read
/// from a state without allocating (a recorder writes them at every
/// sample): built once by [`Mechanism::joint_space`](super::Mechanism::joint_space).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct JointSpace {
    read: Vec<Readable>,
}

/// One joint that has a coordinate: its index, its coordinate, its bodies
/// and, for a revolute joint whose limit is shorter than a turn, that
/// limit, the range its angle is reported in.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Readable {
    joint: usize,
    coordinate: JointCoordinate,
    a: usize,
    b: Option<usize>,
    range: Option<JointLimit>,
}

impl JointSpace {
    /// From `(joint index, its coordinate, body a, body b, its limit)` for
    /// each joint that has one.
    pub(super) fn new(
        read: impl IntoIterator<Item = (usize, JointCoordinate, usize, Option<usize>, Option<JointLimit>)>,
    ) -> Self {
        let read = read.into_iter().map(|(joint, coordinate, a, b, limit)| Readable {
            joint,
            coordinate,
            a,
            b,
            range: coordinate.range(limit),
        });
        Self { read: read.collect() }
    }

    /// The index in [`Mechanism::joints`](super::Mechanism::joints) of each joint read, in order.
    pub fn joints(&self) -> impl ExactSizeIterator<Item = usize> + '_ {
        self.read.iter().map(|r| r.joint)
    }

    /// `(θ, θ̇, θ̈)` of the `i`-th joint read at the state `(q, v)` with
    /// accelerations `a` (all of the mechanism's length; see
    /// [`Mechanism::joint_coordinates`](super::Mechanism::joint_coordinates)
    /// for the range an angle is in).
    /// Panics if `i` is not below [`JointSpace::joints`]' count or a slice is short.
    pub fn at(&self, i: usize, q: &[f64], v: &[f64], a: &[f64]) -> [f64; 3] {
        let theta = self.read(i, |c| Dual2_64::new(q[c], v[c], a[c]));
        [theta.re, theta.v1, theta.v2]
    }

    /// `(θ, θ̇)` of the `i`-th joint read at `(q, v)`, as [`at`](Self::at)
    /// gives them, by a first-order pass (what a joint limit reads every step).
    pub fn rate(&self, i: usize, q: &[f64], v: &[f64]) -> [f64; 2] {
        let theta = self.read(i, |c| Dual64::new(q[c], v[c]));
        [theta.re, theta.eps]
    }

    /// The `i`-th joint's coordinate of its bodies' coordinates, each
    /// (its index in the state) made a scalar by `scalar`.
    fn read<D: Scalar>(&self, i: usize, scalar: impl Fn(usize) -> D) -> D {
        let r = &self.read[i];
        let body = |k: usize| SpatialBody::of(if k < 7 { r.a } else { r.b.unwrap_or(r.a) }).first + k % 7;
        let x: [D; 14] = std::array::from_fn(|k| scalar(body(k)));
        r.coordinate.in_range(&x, [Some(0), r.b.map(|_| 1)], r.range)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::constraint::{curvature_of, jacobian_of, second_derivatives};
    use crate::random::Lcg;

    /// A joint coordinate on random frames (orthonormal axes, as a joint's
    /// are), revolute or prismatic.
    fn coordinate(rotary: bool, random: &mut Lcg) -> JointCoordinate {
        let mut frame = || {
            let s = std::array::from_fn(|_| random.next());
            let mut axes: [[f64; 3]; 3] = std::array::from_fn(|_| std::array::from_fn(|_| random.next()));
            for k in 0..3 {
                for j in 0..k {
                    let along = dot(axes[k], axes[j]);
                    axes[k] = std::array::from_fn(|i| axes[k][i] - along * axes[j][i]);
                }
                let norm = dot(axes[k], axes[k]).sqrt();
                axes[k] = axes[k].map(|x| x / norm);
            }
            Frame { s, axes }
        };
        JointCoordinate { rotary, a: frame(), b: frame() }
    }

    /// What a row reads holds every non-zero of its Jacobian (a jet pass),
    /// and its curvature over those coordinates alone is the curvature over
    /// all of them, to the bit; its closed-form curvature is the hyper-dual
    /// passes' to round-off: for a stop on one body or two and a `<mimic>`
    /// between two joints, of angles and of displacements.
    fn reads_cover_the_derivatives<C: Constraint<K, 1>, const K: usize>(row: &C, random: &mut Lcg) {
        for _ in 0..10 {
            let mut x: [f64; K] = std::array::from_fn(|_| random.next());
            // Unit Euler parameters, as a state near its constraints has them.
            for body in x.chunks_exact_mut(7) {
                let norm = body[3..].iter().map(|e| e * e).sum::<f64>().sqrt();
                body[3..].iter_mut().for_each(|e| *e /= norm);
            }
            let (jac, reads) = (jacobian_of(row, x, 0.0), row.reads());
            assert!(jac[0].iter().zip(&reads[0]).all(|(j, &r)| r || *j == 0.0), "{jac:?} {reads:?}");
            let all = second_derivatives(&x, |y| row.eval(y, 0.0.into())[0].eps1eps2 * 1.5);
            assert_eq!(curvature_of(row, x, 0.0, &[1.5]), all);
            // The closed form the rows give.
            let closed = row.curvature(x, 0.0, &[1.5]);
            let scale = all.iter().flatten().fold(1.0_f64, |m, h| m.max(h.abs()));
            let gap = closed.iter().flatten().zip(all.iter().flatten()).fold(0.0_f64, |m, (a, b)| m.max((a - b).abs()));
            assert!(gap <= 1e-13 * scale, "{gap:e} of {scale:e}");
        }
    }

    /// A joint's `(θ, θ̇)` by the first-order pass is the second-order
    /// pass's, for a revolute joint between two bodies and a prismatic one
    /// on the ground.
    #[test]
    fn a_joints_rate_is_read_as_its_acceleration_pass_reads_it() {
        let mut random = Lcg(5);
        let joints =
            [(0, coordinate(true, &mut random), 1, Some(0), None), (1, coordinate(false, &mut random), 0, None, None)];
        let space = JointSpace::new(joints);
        for _ in 0..10 {
            let mut state = || -> Vec<f64> { (0..14).map(|_| random.next()).collect() };
            let (q, v, a) = (state(), state(), state());
            for i in 0..2 {
                let [theta, rate, _] = space.at(i, &q, &v, &a);
                let [first, first_rate] = space.rate(i, &q, &v);
                // The same products, summed in another order: θ̇ to round-off.
                assert_eq!(first, theta);
                assert!((first_rate - rate).abs() <= 1e-14 * (1.0 + rate.abs()), "{first_rate} vs {rate}");
            }
        }
    }

    #[test]
    fn joint_coordinate_rows_read_what_they_depend_on() {
        let mut random = Lcg(3);
        for rotary in [true, false] {
            let stop = StopRow { coordinate: coordinate(rotary, &mut random), bound: 0.3, sign: -1.0 };
            reads_cover_the_derivatives::<_, 7>(&stop, &mut random);
            reads_cover_the_derivatives::<_, 14>(&stop, &mut random);
            let follower = (coordinate(rotary, &mut random), [Some(0), Some(1)]);
            let leader = (coordinate(!rotary, &mut random), [Some(2), None]);
            let mimic = Mimic { follower, leader, multiplier: 0.8, offset: 0.1 };
            reads_cover_the_derivatives::<_, 21>(&mimic, &mut random);
        }
        // An angle does not read the bodies' positions; a displacement does.
        let stop = |rotary, random: &mut Lcg| StopRow { coordinate: coordinate(rotary, random), bound: 0.0, sign: 1.0 };
        let read = <StopRow as Constraint<14, 1>>::reads(&stop(true, &mut random))[0];
        assert_eq!(read.iter().filter(|r| **r).count(), 8);
        assert!(<StopRow as Constraint<14, 1>>::reads(&stop(false, &mut random))[0].iter().all(|r| *r));
    }
}
