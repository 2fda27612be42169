//! Loads on a tree in joint coordinates — a spring (and its damper)
//! between two body points or a body point and the ground, a rotary
//! damper, a constant force at a body point, a constant torque — as
//! elements on the coordinates of the bodies' paths from the root, written
//! once generic over the scalar like every element, so that their forces'
//! Jacobians (generalized-α) and the spring's Hessian come by AD.
//!
//! A body's displacement is the product of its path's joint motions
//! (`G = e^{ξ₁θ₁} ⋯ e^{ξₖθₖ}`, each screw at the initial pose), and joint
//! `j`'s motion `(ω_j, v_j)` is its screw moved by the joints before it: a
//! point `x` of the body moves at `Σ_j θ̇_j (ω_j × x + v_j)`, and a force
//! `F` there, a torque `τ` on the body, give the coordinate `j` the
//! generalized forces `F · (ω_j × x + v_j)` and `τ · ω_j`.

use super::motion::{V3, add, dot, product, rotation, scale, times};
use crate::ad::scalar::Scalar;
use crate::model::force::{Force, Potential};
use crate::spatial::rotation::cross;

/// A joint of a body's path, at the initial pose: its screw and the slot
/// of its coordinate among the element's.
#[derive(Debug, Clone, Copy)]
pub(super) struct Step {
    pub rotary: bool,
    /// Signed unit axis: turning by `θ` moves the body.
    pub axis: V3,
    pub point: V3,
    pub slot: usize,
}

/// A body as a load sees it: its path from the root (empty: the ground).
pub(super) type Path = Vec<Step>;

type D3<D> = [D; 3];

fn lift<D: Scalar>(a: V3) -> D3<D> {
    a.map(D::from)
}

/// Walks `path` at the coordinates `x`: calls `each(slot, ω, v)` with each
/// joint's motion, root first, and returns the body's displacement `(R, p)`.
fn walk<D: Scalar, const K: usize>(
    path: &[Step],
    x: &[D; K],
    mut each: impl FnMut(usize, D3<D>, D3<D>),
) -> ([D3<D>; 3], D3<D>) {
    let one = |i: usize, j: usize| D::from(f64::from(u8::from(i == j)));
    let mut r: [D3<D>; 3] = std::array::from_fn(|i| std::array::from_fn(|j| one(i, j)));
    let mut p: D3<D> = [D::zero(); 3];
    for s in path {
        let w = times(&r, lift(s.axis));
        let theta = x[s.slot];
        if s.rotary {
            let at = add(times(&r, lift(s.point)), p);
            each(s.slot, w, cross(at, w));
            // G ∘ (x ↦ Q (x − P) + P): R Q, and p + R (P − Q P).
            let turn = rotation(s.axis, theta);
            let (point, arm): (D3<D>, D3<D>) = (lift(s.point), times(&turn, lift(s.point)));
            p = add(p, times(&r, std::array::from_fn(|i| point[i] - arm[i])));
            r = product(&r, &turn);
        } else {
            each(s.slot, [D::zero(); 3], w);
            p = add(p, scale(theta, w));
        }
    }
    (r, p)
}

/// A body point's place at `x` (a ground point where the path is empty).
fn place<D: Scalar, const K: usize>(path: &[Step], x: &[D; K], point: V3) -> D3<D> {
    let (r, p) = walk(path, x, |_, _, _| {});
    add(times(&r, lift(point)), p)
}

/// A body point's place and velocity at `(x, ẋ)`, and `F`'s generalized forces added into `out`
/// once `F` is known from them (`force(place, velocity)`).
fn apply<D: Scalar, const K: usize>(
    path: &[Step],
    x: &[D; K],
    xd: &[D; K],
    point: V3,
    out: &mut [D; K],
    force: impl FnOnce(D3<D>, D3<D>) -> D3<D>,
) {
    let mut motions = [([D::zero(); 3], [D::zero(); 3]); K];
    let mut on = [false; K];
    let (r, p) = walk(path, x, |slot, w, v| {
        motions[slot] = (w, v);
        on[slot] = true;
    });
    let at = add(times(&r, lift(point)), p);
    let unit = |(w, v): (D3<D>, D3<D>)| add(cross(w, at), v);
    let mut velocity = [D::zero(); 3];
    for k in (0..K).filter(|&k| on[k]) {
        let u = unit(motions[k]);
        velocity = add(velocity, scale(xd[k], u));
    }
    let f = force(at, velocity);
    for k in (0..K).filter(|&k| on[k]) {
        out[k] += dot(f, unit(motions[k]));
    }
}

/// A body's angular velocity at `(x, ẋ)` and its joints' axes `ω_j` (by slot, zero off the path).
fn spin<D: Scalar, const K: usize>(path: &[Step], x: &[D; K], xd: &[D; K]) -> (D3<D>, [D3<D>; K], [D3<D>; 3]) {
    let mut axes = [[D::zero(); 3]; K];
    let (r, _) = walk(path, x, |slot, w, _| axes[slot] = w);
    let mut w = [D::zero(); 3];
    for (k, a) in axes.iter().enumerate() {
        w = add(w, scale(xd[k], *a));
    }
    (w, axes, r)
}

/// `½ k (|x_a − x_b| − L)²` of a spring between a point of `a` and one of `b` (or the ground).
pub(super) struct SpringEnergy {
    pub a: Path,
    pub b: Path,
    pub points: [V3; 2],
    pub k: f64,
    pub length: f64,
}

impl<const K: usize> Potential<K> for SpringEnergy {
    fn energy<D: Scalar>(&self, x: [D; K]) -> D {
        let (pa, pb) = (place(&self.a, &x, self.points[0]), place(&self.b, &x, self.points[1]));
        let d: D3<D> = std::array::from_fn(|i| pa[i] - pb[i]);
        let stretch = dot(d, d).sqrt() - self.length;
        stretch * stretch * (0.5 * self.k)
    }
}

/// A spring's damper: `−c ḋ` along the line from `b`'s point to `a`'s.
pub(super) struct LineDamper {
    pub a: Path,
    pub b: Path,
    pub points: [V3; 2],
    pub c: f64,
}

impl<const K: usize> Force<K> for LineDamper {
    fn force<D: Scalar>(&self, x: [D; K], xd: [D; K], _t: D) -> [D; K] {
        let mut out = [D::zero(); K];
        // The line and its rate, from both ends' places and velocities.
        let (mut ends, mut speeds) = ([[D::zero(); 3]; 2], [[D::zero(); 3]; 2]);
        for (e, path) in [&self.a, &self.b].into_iter().enumerate() {
            apply(path, &x, &xd, self.points[e], &mut [D::zero(); K], |at, v| {
                (ends[e], speeds[e]) = (at, v);
                [D::zero(); 3]
            });
        }
        let d: D3<D> = std::array::from_fn(|i| ends[0][i] - ends[1][i]);
        let length = dot(d, d).sqrt();
        let n: D3<D> = d.map(|x| x / length);
        let rate = dot(n, std::array::from_fn(|i| speeds[0][i] - speeds[1][i]));
        let f: D3<D> = n.map(|x| -(x * rate * self.c));
        apply(&self.a, &x, &xd, self.points[0], &mut out, |_, _| f);
        apply(&self.b, &x, &xd, self.points[1], &mut out, |_, _| f.map(|x| -x));
        out
    }
}

/// `−c ((ω_a − ω_b) · h) h` on `a` and its opposite on `b`, `h` carried by
/// `a`, or fixed in space where `b` is the ground (as in body coordinates).
pub(super) struct RotaryDamper {
    pub a: Path,
    pub b: Path,
    /// `h` at the initial pose.
    pub axis: V3,
    pub c: f64,
    pub ground: bool,
}

impl<const K: usize> Force<K> for RotaryDamper {
    fn force<D: Scalar>(&self, x: [D; K], xd: [D; K], _t: D) -> [D; K] {
        let (wa, axes_a, ra) = spin(&self.a, &x, &xd);
        let (wb, axes_b, _) = spin(&self.b, &x, &xd);
        let h = if self.ground { lift(self.axis) } else { times(&ra, lift(self.axis)) };
        let rel = dot(std::array::from_fn(|i| wa[i] - wb[i]), h);
        let tau: D3<D> = h.map(|x| -(x * rel * self.c));
        std::array::from_fn(|k| dot(tau, axes_a[k]) - dot(tau, axes_b[k]))
    }
}

/// A constant force in space at a point of a body.
pub(super) struct PointForce {
    pub body: Path,
    pub point: V3,
    pub force: V3,
}

impl<const K: usize> Force<K> for PointForce {
    fn force<D: Scalar>(&self, x: [D; K], xd: [D; K], _t: D) -> [D; K] {
        let mut out = [D::zero(); K];
        apply(&self.body, &x, &xd, self.point, &mut out, |_, _| lift(self.force));
        out
    }
}

/// A constant torque in space on a body.
pub(super) struct BodyTorque {
    pub body: Path,
    pub torque: V3,
}

impl<const K: usize> Force<K> for BodyTorque {
    fn force<D: Scalar>(&self, x: [D; K], xd: [D; K], _t: D) -> [D; K] {
        let (_, axes, _) = spin(&self.body, &x, &xd);
        std::array::from_fn(|k| dot(lift(self.torque), axes[k]))
    }
}
