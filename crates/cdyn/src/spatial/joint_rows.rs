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
use crate::ad::scalar::Scalar;
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
    pub(super) fn rows<D: Scalar>(&self, a: impl Place<D>, b: impl Place<D>, t: D) -> [D; R] {
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
    pub(super) fn reads<const K: usize>(&self, sides: &[usize]) -> [[bool; K]; R] {
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

pub(super) fn pose<D: Copy, const K: usize>(x: &[D; K], at: usize) -> ([D; 3], [D; 4]) {
    (std::array::from_fn(|i| x[at + i]), std::array::from_fn(|i| x[at + 3 + i]))
}
