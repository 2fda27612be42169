//! A joint's rows as a model element ([`BodyToBody`], [`BodyToGround`]) and
//! their derivatives. A joint without drives forms its Jacobian and its
//! rows' rates in one pass, side by side: each body's points and axes are
//! rotated once, with their derivatives in its seven coordinates in closed
//! form (`∂(A(p)s)/∂p` is linear in `p`), and combined by the product rule
//! at each side's width. A joint with drives differentiates its rows
//! ([`JointRows`]) as written.

use super::joint::JointKind;
use super::joint_rows::{F, Frame, G, H, JointRows, Place, Side, pose};
use super::rotation::{rotate_fixed, rotate_jacobian};
use crate::ad::jet::{Eps, JetN};
use crate::ad::scalar::Scalar;
use crate::model::constraint::{Constraint, curvature_of, second_order_of};

/// A joint between two bodies: reads `(r_a, p_a, r_b, p_b)`.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct BodyToBody<const R: usize>(pub JointRows<R>);

/// A joint between a body and the ground: reads `(r_a, p_a)`.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct BodyToGround<const R: usize>(pub JointRows<R>);

/// A body side of a joint's Jacobian pass: its seven coordinates are
/// `offset..offset + 7` of the pass's jet, and a point or axis depends on
/// them through `p` alone (and `r`, with unit slope). So it is rotated with
/// its 3 × 4 derivative in `p` (`rotate_jacobian`) and then placed among the
/// jet's derivatives, where one pass of a 14-wide jet carried the other
/// body's zeros through every product.
struct Seeded<'a> {
    r: [f64; 3],
    p: [f64; 4],
    offset: usize,
    frame: &'a Frame,
    /// `ṙ` and `ṗ`, for the rows' rates (zero for the Jacobian alone).
    rates: ([f64; 3], [f64; 4]),
}

impl<'a> Seeded<'a> {
    fn new(r: [f64; 3], p: [f64; 4], offset: usize, frame: &'a Frame) -> Self {
        Self { r, p, offset, frame, rates: ([0.0; 3], [0.0; 4]) }
    }

    /// Moving at `(ṙ, ṗ)`.
    fn moving(self, (rd, pd): ([f64; 3], [f64; 4])) -> Self {
        Self { rates: (rd, pd), ..self }
    }

    /// `x` rotated by the body, moved by `r` when `moved`, as an `N`-wide
    /// jet: its [`sided`](Self::sided) derivatives placed at the body's offset.
    #[inline(always)]
    fn place<const N: usize>(&self, x: [f64; 3], moved: bool) -> [JetN<N>; 3] {
        let sided = self.sided(x, moved);
        let at = |i: usize| {
            let mut d = [0.0; N];
            d[self.offset..self.offset + 7].copy_from_slice(&sided.d[i]);
            JetN::new(sided.x[i], Eps(d.into()))
        };
        // Written out: `array::from_fn` of jets was an outlined call through memory.
        [at(0), at(1), at(2)]
    }
}

impl<const N: usize> Place<JetN<N>> for Seeded<'_> {
    fn point(&self) -> [JetN<N>; 3] {
        self.place(self.frame.s, true)
    }
    fn axis(&self, k: usize) -> [JetN<N>; 3] {
        self.place(self.frame.axes[k], false)
    }
}

/// A point or axis of one side with its derivatives in that side's seven
/// coordinates `(r, p)`: what the Jacobian pass of a joint without drives
/// combines by the product rule, side by side (each side's derivatives at
/// width 7), where a jet over both sides' 14 coordinates multiplies the
/// other side's zeros in every product.
#[derive(Clone, Copy)]
pub(super) struct Sided {
    pub(super) x: [f64; 3],
    pub(super) d: [[f64; 7]; 3],
    /// `x`, `ẋ` and `ẍ` along the side's motion at zero acceleration.
    motion: Motion,
    /// The body-fixed vector `s` it rotates (`x = A(p)s`, plus `r` for a point).
    pub(super) s: [f64; 3],
}

/// A vector and its first and second rates.
type Motion = [[f64; 3]; 3];

/// A row's derivatives in its two sides' coordinates.
type Halves = [[f64; 7]; 2];

/// What a joint's Jacobian pass reads of one side.
pub(super) trait SidedPlace {
    fn point(&self) -> Sided;
    fn axis(&self, k: usize) -> Sided;
}

impl Seeded<'_> {
    #[inline(always)]
    fn sided(&self, s: [f64; 3], moved: bool) -> Sided {
        sided(self.r, self.p, self.rates, s, moved)
    }
}

/// `s` rotated by the body at `(r, p)`, moved by `r` when `moved`, with its
/// derivatives in the body's seven coordinates and its rates along
/// `(ṙ, ṗ)`. `A(p) s` is a quadratic form in `p`, so along `p + t ṗ` its
/// second rate is `2 A(ṗ) s`.
#[inline(always)]
pub(super) fn sided(r: [f64; 3], p: [f64; 4], (rd, pd): ([f64; 3], [f64; 4]), s: [f64; 3], moved: bool) -> Sided {
    let (y, jacobian) = (rotate_fixed(p, s), rotate_jacobian(p, s));
    let mut d = [[0.0; 7]; 3];
    for i in 0..3 {
        d[i][3..7].copy_from_slice(&jacobian[i]);
        if moved {
            d[i][i] = 1.0;
        }
    }
    let x = [0, 1, 2].map(|i| y[i] + if moved { r[i] } else { 0.0 });
    let rate = [0, 1, 2].map(|i| {
        let turn: f64 = (0..4).map(|k| d[i][3 + k] * pd[k]).sum();
        turn + if moved { rd[i] } else { 0.0 }
    });
    let curvature = rotate_fixed(pd, s).map(|c| 2.0 * c);
    Sided { x, d, motion: [x, rate, curvature], s }
}

impl SidedPlace for Seeded<'_> {
    fn point(&self) -> Sided {
        self.sided(self.frame.s, true)
    }
    fn axis(&self, k: usize) -> Sided {
        self.sided(self.frame.axes[k], false)
    }
}

/// The ground's side: fixed in space, no coordinates.
struct Fixed<'a>(&'a Frame);

impl SidedPlace for Fixed<'_> {
    fn point(&self) -> Sided {
        still(self.0.s)
    }
    fn axis(&self, k: usize) -> Sided {
        still(self.0.axes[k])
    }
}

/// A vector fixed in space.
pub(super) fn still(x: [f64; 3]) -> Sided {
    Sided { x, d: [[0.0; 7]; 3], motion: [x, [0.0; 3], [0.0; 3]], s: x }
}

/// `[u · w, (u · w)˙, (u · w)¨]` of two moving vectors.
#[inline(always)]
fn dot_motion(u: &Motion, w: &Motion) -> [f64; 3] {
    let dot = |a: &[f64; 3], b: &[f64; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    [
        dot(&u[0], &w[0]),
        dot(&u[1], &w[0]) + dot(&u[0], &w[1]),
        dot(&u[2], &w[0]) + 2.0 * dot(&u[1], &w[1]) + dot(&u[0], &w[2]),
    ]
}

/// `Σ_i w_i ∂u_i`: the derivatives of `u · w` through `u`, for a fixed `w`.
#[inline(always)]
fn through(u: &Sided, w: [f64; 3]) -> [f64; 7] {
    std::array::from_fn(|j| u.d[0][j] * w[0] + u.d[1][j] * w[1] + u.d[2][j] * w[2])
}

/// `u_a · w_b` of a vector on each side.
#[inline(always)]
fn dot_across(u: &Sided, w: &Sided) -> Halves {
    [through(u, w.x), through(w, u.x)]
}

/// `u_a · d` with `d = p_b − p_a`.
#[inline(always)]
fn dot_gap(u: &Sided, pa: &Sided, pb: &Sided) -> Halves {
    let d = [0, 1, 2].map(|i| pb.x[i] - pa.x[i]);
    let (by_axis, by_point) = (through(u, d), through(pa, u.x));
    [std::array::from_fn(|j| by_axis[j] - by_point[j]), through(pb, u.x)]
}

impl<const R: usize> JointRows<R> {
    /// [`kinematic_rows`](Self::kinematic_rows)' `[Φ, Φ̇, Φ̈]` along the
    /// sides' motion and their Jacobian, by sides; only for a joint without
    /// drives (`has_drives`), whose rows are these.
    fn kinematic_derivatives<const K: usize>(
        &self,
        a: &impl SidedPlace,
        b: &impl SidedPlace,
        place: impl Fn(Halves) -> [f64; K],
    ) -> ([[f64; 3]; R], [[f64; K]; R]) {
        let (mut rows, mut jac) = ([[0.0; 3]; R], [[0.0; K]; R]);
        let mut put = |k: usize, (row, halves): ([f64; 3], Halves)| {
            rows[k] = row;
            jac[k] = place(halves);
        };
        let (pa, pb) = (a.point(), b.point());
        let gap: Motion = std::array::from_fn(|k| std::array::from_fn(|i| pb.motion[k][i] - pa.motion[k][i]));
        let spherical = |i: usize| (gap.map(|x| x[i]), [pa.d[i].map(|x| -x), pb.d[i]]);
        let across = |u: &Sided, w: &Sided| (dot_motion(&u.motion, &w.motion), dot_across(u, w));
        let along_gap = |u: &Sided| (dot_motion(&u.motion, &gap), dot_gap(u, &pa, &pb));
        if matches!(self.kind, JointKind::Spherical | JointKind::Revolute | JointKind::Universal | JointKind::Fixed) {
            (0..3).for_each(|i| put(i, spherical(i)));
        }
        match self.kind {
            JointKind::Spherical => {}
            JointKind::Revolute => {
                let hb = b.axis(H);
                put(3, across(&a.axis(F), &hb));
                put(4, across(&a.axis(G), &hb));
            }
            JointKind::Universal => put(3, across(&a.axis(H), &b.axis(H))),
            JointKind::Cylindrical | JointKind::Prismatic => {
                let (fa, ga, hb) = (a.axis(F), a.axis(G), b.axis(H));
                put(0, across(&fa, &hb));
                put(1, across(&ga, &hb));
                put(2, along_gap(&fa));
                put(3, along_gap(&ga));
                if self.kind == JointKind::Prismatic {
                    put(4, across(&fa, &b.axis(G)));
                }
            }
            JointKind::Fixed => {
                put(3, across(&a.axis(F), &b.axis(G)));
                put(4, across(&a.axis(G), &b.axis(H)));
                put(5, across(&a.axis(H), &b.axis(F)));
            }
            JointKind::Distance => {
                let [x, rate, curvature] = dot_motion(&gap, &gap);
                let (by_a, by_b) = (through(&pa, gap[0]), through(&pb, gap[0]));
                put(0, ([x - self.length2, rate, curvature], [by_a.map(|x| -2.0 * x), by_b.map(|x| 2.0 * x)]));
            }
        }
        (rows, jac)
    }

    /// Whether the joint drives an angle or a displacement (rows beyond the
    /// kinematic ones).
    fn has_drives(&self) -> bool {
        self.angle.is_some() || self.displacement.is_some()
    }
}

/// A row's Jacobian over both sides' coordinates, `(r_a, p_a, r_b, p_b)`.
fn both(jac: Halves) -> [f64; 14] {
    std::array::from_fn(|j| if j < 7 { jac[0][j] } else { jac[1][j - 7] })
}

impl<const R: usize> Constraint<14, R> for BodyToBody<R> {
    fn eval<D: Scalar>(&self, x: [D; 14], t: D) -> [D; R] {
        let ((ra, pa), (rb, pb)) = (pose(&x, 0), pose(&x, 7));
        self.0.rows(Side::Body { r: ra, p: pa, frame: &self.0.a }, Side::Body { r: rb, p: pb, frame: &self.0.b }, t)
    }

    fn jacobian(&self, x: [f64; 14], t: f64) -> [[f64; 14]; R] {
        let ((ra, pa), (rb, pb)) = (pose(&x, 0), pose(&x, 7));
        let (a, b) = (Seeded::new(ra, pa, 0, &self.0.a), Seeded::new(rb, pb, 7, &self.0.b));
        if self.0.has_drives() {
            return self.0.rows::<JetN<14>>(a, b, JetN::from_re(t)).map(|row| row.eps.0.into());
        }
        self.0.kinematic_derivatives(&a, &b, both).1
    }

    fn second_order(&self, x: [f64; 14], v: [f64; 14], t: f64) -> ([[f64; 3]; R], [[f64; 14]; R]) {
        if self.0.has_drives() {
            return (second_order_of(self, x, v, t), self.jacobian(x, t));
        }
        let ((ra, pa), (rb, pb)) = (pose(&x, 0), pose(&x, 7));
        let a = Seeded::new(ra, pa, 0, &self.0.a).moving(pose(&v, 0));
        let b = Seeded::new(rb, pb, 7, &self.0.b).moving(pose(&v, 7));
        self.0.kinematic_derivatives(&a, &b, both)
    }

    fn curvature(&self, x: [f64; 14], t: f64, w: &[f64; R]) -> [[f64; 14]; 14] {
        if self.0.has_drives() {
            return curvature_of(self, x, t, w);
        }
        let ((ra, pa), (rb, pb)) = (pose(&x, 0), pose(&x, 7));
        let (a, b) = (Seeded::new(ra, pa, 0, &self.0.a), Seeded::new(rb, pb, 7, &self.0.b));
        self.0.kinematic_curvature(&a, &b, [Some(0), Some(7)], w)
    }

    fn reads(&self) -> [[bool; 14]; R] {
        self.0.reads(&[0, 7])
    }
}

impl<const R: usize> Constraint<7, R> for BodyToGround<R> {
    fn eval<D: Scalar>(&self, x: [D; 7], t: D) -> [D; R] {
        let (r, p) = pose(&x, 0);
        self.0.rows(Side::Body { r, p, frame: &self.0.a }, Side::Ground(&self.0.b), t)
    }

    fn jacobian(&self, x: [f64; 7], t: f64) -> [[f64; 7]; R] {
        let (r, p) = pose(&x, 0);
        let a = Seeded::new(r, p, 0, &self.0.a);
        if self.0.has_drives() {
            return self.0.rows::<JetN<7>>(a, Side::Ground(&self.0.b), JetN::from_re(t)).map(|row| row.eps.0.into());
        }
        self.0.kinematic_derivatives(&a, &Fixed(&self.0.b), |[jac, _]| jac).1
    }

    fn second_order(&self, x: [f64; 7], v: [f64; 7], t: f64) -> ([[f64; 3]; R], [[f64; 7]; R]) {
        if self.0.has_drives() {
            return (second_order_of(self, x, v, t), self.jacobian(x, t));
        }
        let (r, p) = pose(&x, 0);
        let a = Seeded::new(r, p, 0, &self.0.a).moving(pose(&v, 0));
        self.0.kinematic_derivatives(&a, &Fixed(&self.0.b), |[jac, _]| jac)
    }

    fn curvature(&self, x: [f64; 7], t: f64, w: &[f64; R]) -> [[f64; 7]; 7] {
        if self.0.has_drives() {
            return curvature_of(self, x, t, w);
        }
        let (r, p) = pose(&x, 0);
        self.0.kinematic_curvature(&Seeded::new(r, p, 0, &self.0.a), &Fixed(&self.0.b), [Some(0), None], w)
    }

    fn reads(&self) -> [[bool; 7]; R] {
        self.0.reads(&[0])
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::constraint::jacobian_of;
    use crate::model::timefn::TimeFn;

    /// A reproducible stream of numbers in [−1, 1).
    fn numbers(seed: u64) -> impl FnMut() -> f64 {
        let mut lcg = crate::random::Lcg(seed);
        move || lcg.next()
    }

    /// The joints' composed Jacobians, second-order rows and curvatures
    /// against one jet pass, one second-order dual pass and hyper-dual
    /// passes of their rows, at poses and rates off the constraints with
    /// quaternions off unit length; and the entries `reads` leaves out are
    /// zero in the jet pass.
    fn composed_is_the_plain_pass<const R: usize>(kind: JointKind, angle: bool, displacement: bool) {
        let mut x = numbers(R as u64 + 7 * kind.rows() as u64);
        let mut frame =
            || Frame { s: std::array::from_fn(|_| x()), axes: std::array::from_fn(|_| std::array::from_fn(|_| x())) };
        let rows = JointRows::<R> {
            kind,
            a: frame(),
            b: frame(),
            length2: 0.7,
            angle: angle.then(|| TimeFn::constant(0.4)),
            displacement: displacement.then(|| TimeFn::constant(-0.2)),
        };
        let mut x = numbers(99);
        for _ in 0..20 {
            let (q, t): ([f64; 14], f64) = (std::array::from_fn(|_| x()), x());
            let (two, one) = (BodyToBody(rows.clone()), BodyToGround(rows.clone()));
            let q7: [f64; 7] = std::array::from_fn(|i| q[i]);
            let close = |a: f64, b: f64| (a - b).abs() <= 1e-14 * (1.0 + b.abs());
            let same = |c: &[f64], p: &[f64]| c.iter().zip(p).all(|(a, b)| close(*a, *b));
            let (c, p) = (two.jacobian(q, t), jacobian_of(&two, q, t));
            assert!(same(c.as_flattened(), p.as_flattened()), "{kind:?}: {c:?} vs {p:?}");
            let unread_are_zero = |p: &[f64], reads: &[bool]| p.iter().zip(reads).all(|(p, &r)| r || *p == 0.0);
            assert!(unread_are_zero(p.as_flattened(), two.reads().as_flattened()), "{kind:?} reads");
            let (c, p) = (one.jacobian(q7, t), jacobian_of(&one, q7, t));
            assert!(same(c.as_flattened(), p.as_flattened()), "{kind:?} grounded");
            assert!(unread_are_zero(p.as_flattened(), one.reads().as_flattened()), "{kind:?} grounded reads");
            // Φ, Φ̇ and Φ̈ along a motion, with the Jacobian: against one
            // second-order dual pass of the rows and the plain jet pass.
            // Φ̈ sums products quadratic in v that cancel: its round-off
            // scales with |v|², not with its value.
            let v: [f64; 14] = std::array::from_fn(|_| 3.0 * x());
            let v7: [f64; 7] = std::array::from_fn(|i| v[i]);
            let scale = 1.0 + v.iter().map(|x| x * x).sum::<f64>();
            let moving_close = |a: f64, b: f64| (a - b).abs() <= 1e-14 * scale * (1.0 + b.abs());
            let ((rows, jac), plain) = (two.second_order(q, v, t), second_order_of(&two, q, v, t));
            assert!(
                rows.iter().flatten().zip(plain.iter().flatten()).all(|(a, b)| moving_close(*a, *b)),
                "{kind:?}: {rows:?} vs {plain:?}"
            );
            // The Jacobian does not depend on v: the first tolerance.
            assert!(same(jac.as_flattened(), jacobian_of(&two, q, t).as_flattened()), "{kind:?} Jacobian along");
            let ((rows, jac), plain) = (one.second_order(q7, v7, t), second_order_of(&one, q7, v7, t));
            assert!(
                rows.iter().flatten().zip(plain.iter().flatten()).all(|(a, b)| moving_close(*a, *b)),
                "{kind:?} grounded: {rows:?} vs {plain:?}"
            );
            assert!(
                same(jac.as_flattened(), jacobian_of(&one, q7, t).as_flattened()),
                "{kind:?} grounded Jacobian along"
            );
            // The curvature Σ w_r ∇²Φ_r against one hyper-dual pass per pair.
            let w: [f64; R] = std::array::from_fn(|_| 2.0 * x());
            let (c, p) = (two.curvature(q, t, &w), curvature_of(&two, q, t, &w));
            assert!(same(c.as_flattened(), p.as_flattened()), "{kind:?} curvature: {c:?} vs {p:?}");
            let (c, p) = (one.curvature(q7, t, &w), curvature_of(&one, q7, t, &w));
            assert!(same(c.as_flattened(), p.as_flattened()), "{kind:?} grounded curvature: {c:?} vs {p:?}");
        }
    }

    #[test]
    fn composed_derivatives_equal_the_plain_dual_passes_and_unread_entries_are_zero_for_every_joint() {
        composed_is_the_plain_pass::<3>(JointKind::Spherical, false, false);
        composed_is_the_plain_pass::<5>(JointKind::Revolute, false, false);
        composed_is_the_plain_pass::<6>(JointKind::Revolute, true, false);
        composed_is_the_plain_pass::<4>(JointKind::Universal, false, false);
        composed_is_the_plain_pass::<4>(JointKind::Cylindrical, false, false);
        composed_is_the_plain_pass::<6>(JointKind::Cylindrical, true, true);
        composed_is_the_plain_pass::<5>(JointKind::Prismatic, false, false);
        composed_is_the_plain_pass::<6>(JointKind::Prismatic, false, true);
        composed_is_the_plain_pass::<6>(JointKind::Fixed, false, false);
        composed_is_the_plain_pass::<1>(JointKind::Distance, false, false);
    }
}
