//! The constraint elements of planar joints and drives, each generic over
//! the scalar so that `Φ_q` and `γ` come from dual-number passes.

use super::ends::{End, angle_of};
use crate::Constraint;
use crate::ad::scalar::Scalar;
use crate::model::nonholonomic::Nonholonomic;
use crate::model::timefn::TimeFn;

/// Two points coincide: `p_a − p_b = 0`.
pub(super) struct Revolute<const K: usize> {
    pub(super) a: End,
    pub(super) b: End,
}

impl<const K: usize> Constraint<K, 2> for Revolute<K> {
    #[inline(always)]
    fn eval<D: Scalar>(&self, x: [D; K], _t: D) -> [D; 2] {
        let (pa, pb) = (self.a.position(&x), self.b.position(&x));
        [pa[0] - pb[0], pa[1] - pb[1]]
    }
}

/// Two points at a fixed distance: `(|p_b − p_a|² − L²) / 2 = 0`.
pub(super) struct Distance<const K: usize> {
    pub(super) a: End,
    pub(super) b: End,
    pub(super) length: f64,
}

impl<const K: usize> Constraint<K, 1> for Distance<K> {
    #[inline(always)]
    fn eval<D: Scalar>(&self, x: [D; K], _t: D) -> [D; 1] {
        let (pa, pb) = (self.a.position(&x), self.b.position(&x));
        let (dx, dy) = (pb[0] - pa[0], pb[1] - pa[1]);
        [(dx * dx + dy * dy - self.length * self.length) * 0.5]
    }
}

/// [`Distance`] between two point masses `(x_a, y_a, x_b, y_b)`: the rod of
/// chains, ropes and nets, with its coordinates at fixed places so that
/// its derivative passes select nothing at run time.
pub(super) struct PointRod {
    pub(super) length: f64,
}

impl Constraint<4, 1> for PointRod {
    #[inline(always)]
    fn eval<D: Scalar>(&self, [xa, ya, xb, yb]: [D; 4], _t: D) -> [D; 1] {
        let (dx, dy) = (xb - xa, yb - ya);
        [(dx * dx + dy * dy - self.length * self.length) * 0.5]
    }
}

/// [`Distance`] between a fixed point and a point mass `(x, y)`.
pub(super) struct AnchoredRod {
    pub(super) anchor: [f64; 2],
    pub(super) length: f64,
}

impl Constraint<2, 1> for AnchoredRod {
    #[inline(always)]
    fn eval<D: Scalar>(&self, [x, y]: [D; 2], _t: D) -> [D; 1] {
        let (dx, dy) = (x - self.anchor[0], y - self.anchor[1]);
        [(dx * dx + dy * dy - self.length * self.length) * 0.5]
    }
}

/// `(p_b − p_a) · n = 0` with `n` the line's normal turning with `a`.
pub(super) struct OnLine<const K: usize> {
    pub(super) a: End,
    pub(super) b: End,
    pub(super) normal: [f64; 2],
}

impl<const K: usize> Constraint<K, 1> for OnLine<K> {
    #[inline(always)]
    fn eval<D: Scalar>(&self, x: [D; K], _t: D) -> [D; 1] {
        let (pa, pb) = (self.a.position(&x), self.b.position(&x));
        let phi = self.a.angle(&x);
        let (s, c) = (phi.sin(), phi.cos());
        let [nx, ny] = self.normal;
        let (wx, wy) = (c * nx - s * ny, s * nx + c * ny);
        [(pb[0] - pa[0]) * wx + (pb[1] - pa[1]) * wy]
    }
}

/// `φ_b − φ_a − f(t) = 0`.
pub(super) struct RelativeAngle<const K: usize> {
    pub(super) a: Option<usize>,
    pub(super) b: Option<usize>,
    pub(super) f: TimeFn,
}

impl<const K: usize> Constraint<K, 1> for RelativeAngle<K> {
    #[inline(always)]
    fn eval<D: Scalar>(&self, x: [D; K], t: D) -> [D; 1] {
        [angle_of(self.b, &x) - angle_of(self.a, &x) - self.f.eval(t)]
    }
}

/// `x − f(t) = 0` on one coordinate.
pub(super) struct Prescribed {
    pub(super) f: TimeFn,
}

impl Constraint<1, 1> for Prescribed {
    #[inline(always)]
    fn eval<D: Scalar>(&self, [x]: [D; 1], t: D) -> [D; 1] {
        [x - self.f.eval(t)]
    }
}

/// A knife edge on a rigid body `(x, y, φ)`: the velocity of the point
/// `edge` has no component along `normal` (both in the body's frame,
/// `normal` of unit length), `ṗ · R(φ) n = 0`. Ideal: `b = 0`.
pub(super) struct KnifeEdge {
    pub(super) edge: End,
    pub(super) normal: [f64; 2],
}

impl Nonholonomic<3, 1> for KnifeEdge {
    #[inline(always)]
    fn eval<D: Scalar>(&self, q: [D; 3], v: [D; 3], _t: D) -> [D; 1] {
        let [vx, vy] = self.edge.velocity(&q, &v);
        let (s, c) = (q[2].sin(), q[2].cos());
        let [nx, ny] = self.normal;
        [vx * (c * nx - s * ny) + vy * (s * nx + c * ny)]
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use num_dual::{Dual2_64, Dual64};

    /// The fixed-layout rods are the general distance element, written for
    /// one layout: same values and derivatives.
    #[test]
    fn point_rods_agree_with_the_general_distance() {
        let general = Distance::<4> { a: End::Point { at: 0 }, b: End::Point { at: 2 }, length: 1.3 };
        let anchored = Distance::<2> { a: End::Ground { point: [0.4, -0.2] }, b: End::Point { at: 0 }, length: 0.7 };
        let x = [0.3, -1.1, 1.2, 0.5];
        let v = [0.7, -0.2, 0.1, 1.4];
        let along = |i: usize| Dual2_64::new(x[i], v[i], 0.0);
        let t = Dual2_64::new(0.0, 1.0, 0.0);
        let [a] = PointRod { length: 1.3 }.eval(std::array::from_fn(along), t);
        let [b] = general.eval(std::array::from_fn(along), t);
        assert_eq!((a.re, a.v1, a.v2), (b.re, b.v1, b.v2));
        for j in 0..4 {
            let seeded = |i: usize| Dual64::new(x[i], if i == j { 1.0 } else { 0.0 });
            let [a] = PointRod { length: 1.3 }.eval(std::array::from_fn(seeded), Dual64::from(0.0));
            let [b] = general.eval(std::array::from_fn(seeded), Dual64::from(0.0));
            assert_eq!((a.re, a.eps), (b.re, b.eps));
        }
        let rod = AnchoredRod { anchor: [0.4, -0.2], length: 0.7 };
        let [a] = rod.eval([along(0), along(1)], t);
        let [b] = anchored.eval([along(0), along(1)], t);
        assert_eq!((a.re, a.v1, a.v2), (b.re, b.v1, b.v2));
    }
}
