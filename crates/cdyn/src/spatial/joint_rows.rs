//! The constraint rows of joints between two spatial bodies, or a body and
//! the ground, from Haug's primitive constraints, written once generic over the scalar:
//!
//! * spherical: the joint's point on each body coincides (3 rows);
//! * dot-1: `(A_a u_a) · (A_b u_b) = 0` for body-fixed vectors;
//! * dot-2: `(A_a u_a) · d = 0` with `d` from the point on `a` to that on `b`;
//! * distance: `|d|² = L²`.
//!
//! | joint | rows | made of |
//! |---|---|---|
//! | spherical | 3 | spherical |
//! | revolute | 5 | spherical, dot-1 (f_a, h_b), dot-1 (g_a, h_b) |
//! | universal | 4 | spherical, dot-1 (h_a, h′_b) |
//! | cylindrical | 4 | dot-1 (f_a, h_b), dot-1 (g_a, h_b), dot-2 (f_a), dot-2 (g_a) |
//! | prismatic | 5 | cylindrical, dot-1 (f_a, g_b) |
//! | fixed | 6 | spherical, dot-1 (f_a, g_b), dot-1 (g_a, h_b), dot-1 (h_a, f_b) |
//! | distance | 1 | distance |
//!
//! where `(f, g, h)` is the joint's frame, `h` its axis, carried into each
//! body at the initial pose (so every joint starts assembled).

use super::joint::JointKind;
use super::rotation::rotate_fixed;
use crate::ad::jet::{Eps, JetN};
use crate::ad::scalar::Scalar;
use crate::model::constraint::Constraint;
use crate::model::timefn::TimeFn;

/// A joint's frame on one side: point `s` and axes `(f, g, h)`, in the
/// body's axes (relative to its centre of mass), or in space on the ground.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Frame {
    pub s: [f64; 3],
    pub axes: [[f64; 3]; 3],
}

/// What a joint's rows read of one side: its point and axes in space.
pub(super) trait Place<D> {
    fn point(&self) -> [D; 3];
    fn axis(&self, k: usize) -> [D; 3];
}

/// One side of a joint at a state: a body's pose, or the ground.
pub(super) enum Side<'a, D> {
    Body { r: [D; 3], p: [D; 4], frame: &'a Frame },
    Ground(&'a Frame),
}

impl<D: Scalar> Place<D> for Side<'_, D> {
    #[inline(always)]
    fn point(&self) -> [D; 3] {
        match self {
            Side::Body { r, p, frame } => {
                let [x, y, z] = rotate_fixed(*p, frame.s);
                [r[0] + x, r[1] + y, r[2] + z]
            }
            Side::Ground(frame) => frame.s.map(D::from),
        }
    }
    #[inline(always)]
    fn axis(&self, k: usize) -> [D; 3] {
        match self {
            Side::Body { p, frame, .. } => rotate_fixed(*p, frame.axes[k]),
            Side::Ground(frame) => frame.axes[k].map(D::from),
        }
    }
}

/// A body side of a joint's Jacobian pass: its seven coordinates are
/// `offset..offset + 7` of the pass's jet, and a point or axis depends on
/// them through `p` alone (and `r`, with unit slope). So it is rotated by a
/// 4-wide jet over `p` and then placed among the jet's derivatives: a
/// spatial joint's Jacobian costs two 4-wide rotations, where one pass of
/// a 14-wide jet carried the other body's zeros through every product.
struct Seeded<'a> {
    r: [f64; 3],
    p: [JetN<4>; 4],
    offset: usize,
    frame: &'a Frame,
}

impl<'a> Seeded<'a> {
    fn new(r: [f64; 3], p: [f64; 4], offset: usize, frame: &'a Frame) -> Self {
        Self { r, p: std::array::from_fn(|j| JetN::seeded(p[j], j)), offset, frame }
    }

    /// `x` rotated by the body, moved by `r` when `moved`, as an `N`-wide jet.
    #[inline(always)]
    fn place<const N: usize>(&self, x: [f64; 3], moved: bool) -> [JetN<N>; 3] {
        let x = rotate_fixed(self.p, x);
        let at = |i: usize| {
            let mut d = [0.0; N];
            d[self.offset + 3..self.offset + 7].copy_from_slice(x[i].eps.0.as_slice());
            if moved {
                d[self.offset + i] = 1.0;
            }
            JetN::new(x[i].re + if moved { self.r[i] } else { 0.0 }, Eps(d.into()))
        };
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

pub(super) fn dot<D: Scalar>(a: [D; 3], b: [D; 3]) -> D {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

pub(super) const F: usize = 0;
pub(super) const G: usize = 1;
pub(super) const H: usize = 2;

/// The rows of a joint of `R` rows, with its frames on both sides.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct JointRows<const R: usize> {
    pub kind: JointKind,
    pub a: Frame,
    pub b: Frame,
    /// Squared length of a distance joint.
    pub length2: f64,
    /// Drives: angle about, displacement along the axis.
    pub angle: Option<TimeFn>,
    pub displacement: Option<TimeFn>,
}

impl<const R: usize> JointRows<R> {
    fn rows<D: Scalar>(&self, a: impl Place<D>, b: impl Place<D>, t: D) -> [D; R] {
        let mut out = self.kinematic_rows(&a, &b);
        let mut next = self.kind.rows();
        // At the initial pose both sides' frames coincide, so a's f axis
        // turned by θ about h relative to b is f cos θ + g sin θ in b's
        // frame: the row is sin(θ − f(t)).
        if let Some(angle) = &self.angle {
            let (fa, theta) = (a.axis(F), angle.eval(t));
            out[next] = dot(fa, b.axis(G)) * theta.cos() - dot(fa, b.axis(F)) * theta.sin();
            next += 1;
        }
        if let Some(displacement) = &self.displacement {
            let (pa, pb) = (a.point(), b.point());
            let d: [D; 3] = std::array::from_fn(|i| pa[i] - pb[i]);
            out[next] = dot(d, b.axis(H)) - displacement.eval(t);
        }
        out
    }

    /// What each row reads of the bodies' centres of mass: the rows that
    /// are components of `d` one component of each, the dot-1 rows and the
    /// angle drive none (they turn with `p` alone), the others all three.
    /// The Euler parameters are read by every row. A unit test checks this
    /// against the Jacobian's zeros.
    fn reads_position(&self) -> [Reach; R] {
        let mut out = [Reach::All; R];
        let components = |out: &mut [Reach; R]| (0..3).for_each(|i| out[i] = Reach::Component(i));
        match self.kind {
            JointKind::Spherical => components(&mut out),
            JointKind::Revolute | JointKind::Universal | JointKind::Fixed => {
                components(&mut out);
                (3..self.kind.rows()).for_each(|k| out[k] = Reach::None);
            }
            JointKind::Cylindrical | JointKind::Prismatic => {
                out[0] = Reach::None;
                out[1] = Reach::None;
                if self.kind == JointKind::Prismatic {
                    out[4] = Reach::None;
                }
            }
            JointKind::Distance => {}
        }
        if self.angle.is_some() {
            out[self.kind.rows()] = Reach::None;
        }
        out
    }

    /// [`Constraint::reads`] for a joint whose bodies' poses start at the offsets `sides`.
    fn reads<const K: usize>(&self, sides: &[usize]) -> [[bool; K]; R] {
        self.reads_position().map(|reach| {
            let mut row = [false; K];
            for &at in sides {
                (0..3).for_each(|i| row[at + i] = reach.reads(i));
                (3..7).for_each(|i| row[at + i] = true);
            }
            row
        })
    }

    fn kinematic_rows<D: Scalar>(&self, a: &impl Place<D>, b: &impl Place<D>) -> [D; R] {
        let mut out = [D::zero(); R];
        let (pa, pb) = (a.point(), b.point());
        let d: [D; 3] = std::array::from_fn(|i| pb[i] - pa[i]);
        let mut put = |k: usize, x: D| out[k] = x;
        match self.kind {
            JointKind::Spherical => (0..3).for_each(|i| put(i, d[i])),
            JointKind::Revolute => {
                (0..3).for_each(|i| put(i, d[i]));
                let hb = b.axis(H);
                put(3, dot(a.axis(F), hb));
                put(4, dot(a.axis(G), hb));
            }
            JointKind::Universal => {
                (0..3).for_each(|i| put(i, d[i]));
                put(3, dot(a.axis(H), b.axis(H)));
            }
            JointKind::Cylindrical | JointKind::Prismatic => {
                let (fa, ga, hb) = (a.axis(F), a.axis(G), b.axis(H));
                put(0, dot(fa, hb));
                put(1, dot(ga, hb));
                put(2, dot(fa, d));
                put(3, dot(ga, d));
                if self.kind == JointKind::Prismatic {
                    put(4, dot(fa, b.axis(G)));
                }
            }
            JointKind::Fixed => {
                (0..3).for_each(|i| put(i, d[i]));
                put(3, dot(a.axis(F), b.axis(G)));
                put(4, dot(a.axis(G), b.axis(H)));
                put(5, dot(a.axis(H), b.axis(F)));
            }
            JointKind::Distance => put(0, dot(d, d) - self.length2),
        }
        out
    }
}

/// Which components of a centre of mass a joint's row reads.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Reach {
    None,
    Component(usize),
    All,
}

impl Reach {
    fn reads(self, i: usize) -> bool {
        match self {
            Reach::None => false,
            Reach::Component(j) => i == j,
            Reach::All => true,
        }
    }
}

/// A joint between two bodies: reads `(r_a, p_a, r_b, p_b)`.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct BodyToBody<const R: usize>(pub JointRows<R>);

/// A joint between a body and the ground: reads `(r_a, p_a)`.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct BodyToGround<const R: usize>(pub JointRows<R>);

pub(super) fn pose<D: Copy, const K: usize>(x: &[D; K], at: usize) -> ([D; 3], [D; 4]) {
    (std::array::from_fn(|i| x[at + i]), std::array::from_fn(|i| x[at + 3 + i]))
}

impl<const R: usize> Constraint<14, R> for BodyToBody<R> {
    fn eval<D: Scalar>(&self, x: [D; 14], t: D) -> [D; R] {
        let ((ra, pa), (rb, pb)) = (pose(&x, 0), pose(&x, 7));
        self.0.rows(Side::Body { r: ra, p: pa, frame: &self.0.a }, Side::Body { r: rb, p: pb, frame: &self.0.b }, t)
    }

    fn jacobian(&self, x: [f64; 14], t: f64) -> [[f64; 14]; R] {
        let ((ra, pa), (rb, pb)) = (pose(&x, 0), pose(&x, 7));
        let (a, b) = (Seeded::new(ra, pa, 0, &self.0.a), Seeded::new(rb, pb, 7, &self.0.b));
        self.0.rows::<JetN<14>>(a, b, JetN::from_re(t)).map(|row| row.eps.0.into())
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
        self.0.rows::<JetN<7>>(a, Side::Ground(&self.0.b), JetN::from_re(t)).map(|row| row.eps.0.into())
    }

    fn reads(&self) -> [[bool; 7]; R] {
        self.0.reads(&[0])
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::constraint::jacobian_of;

    /// A reproducible stream of numbers in (−1, 1).
    fn numbers(seed: u64) -> impl FnMut() -> f64 {
        let mut s = seed;
        move || {
            s = s.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            (s >> 11) as f64 / (1u64 << 52) as f64 - 1.0
        }
    }

    /// The joints' composed Jacobians against one jet pass of their rows,
    /// at poses off the constraints with quaternions off unit length; and
    /// the entries `reads` leaves out are zero in that pass.
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
            let (c, p) = (two.jacobian(q, t), jacobian_of(&two, q, t));
            assert!(c.iter().flatten().zip(p.iter().flatten()).all(|(a, b)| close(*a, *b)), "{kind:?}: {c:?} vs {p:?}");
            let unread_are_zero = |p: &[f64], reads: &[bool]| p.iter().zip(reads).all(|(p, &r)| r || *p == 0.0);
            assert!(unread_are_zero(p.as_flattened(), two.reads().as_flattened()), "{kind:?} reads");
            let (c, p) = (one.jacobian(q7, t), jacobian_of(&one, q7, t));
            assert!(c.iter().flatten().zip(p.iter().flatten()).all(|(a, b)| close(*a, *b)), "{kind:?} grounded");
            assert!(unread_are_zero(p.as_flattened(), one.reads().as_flattened()), "{kind:?} grounded reads");
        }
    }

    #[test]
    fn composed_jacobians_equal_the_plain_jet_pass_and_unread_entries_are_zero_for_every_joint() {
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
