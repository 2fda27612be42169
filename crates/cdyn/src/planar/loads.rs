//! The potentials and forces of planar mechanisms: gravity, springs,
//! dampers and applied loads.

use super::ends::{End, angle_of};
use crate::ad::scalar::Scalar;
use crate::model::input::Parameter;
use crate::model::timefn::TimeFn;
use crate::{Force, Potential};

/// `V = −m g · p` on a body's centre of mass; `w = −m g`.
pub(super) struct Gravity {
    pub(super) w: [f64; 2],
}

impl Potential<2> for Gravity {
    #[inline(always)]
    fn energy<D: Scalar>(&self, [x, y]: [D; 2]) -> D {
        x * self.w[0] + y * self.w[1]
    }
}

/// `V = k (|p_b − p_a| − l₀)² / 2`.
pub(super) struct Spring<const K: usize> {
    pub(super) a: End,
    pub(super) b: End,
    pub(super) k: f64,
    pub(super) l0: Parameter,
}

impl<const K: usize> Potential<K> for Spring<K> {
    #[inline(always)]
    fn energy<D: Scalar>(&self, x: [D; K]) -> D {
        let (pa, pb) = (self.a.position(&x), self.b.position(&x));
        let (dx, dy) = (pb[0] - pa[0], pb[1] - pa[1]);
        let stretch = (dx * dx + dy * dy).sqrt() - self.l0.value();
        stretch * stretch * (0.5 * self.k)
    }
}

/// `V = k (φ_b − φ_a − rest)² / 2`.
pub(super) struct Torsion<const K: usize> {
    pub(super) a: Option<usize>,
    pub(super) b: Option<usize>,
    pub(super) k: f64,
    pub(super) rest: Parameter,
}

impl<const K: usize> Potential<K> for Torsion<K> {
    #[inline(always)]
    fn energy<D: Scalar>(&self, x: [D; K]) -> D {
        let turn = angle_of(self.b, &x) - angle_of(self.a, &x) - self.rest.value();
        turn * turn * (0.5 * self.k)
    }
}

/// A linear dashpot between two points.
pub(super) struct Damper<const K: usize> {
    pub(super) a: End,
    pub(super) b: End,
    pub(super) c: f64,
}

impl<const K: usize> Force<K> for Damper<K> {
    #[inline(always)]
    fn force<D: Scalar>(&self, x: [D; K], xd: [D; K], _t: D) -> [D; K] {
        let (pa, pb) = (self.a.position(&x), self.b.position(&x));
        let (va, vb) = (self.a.velocity(&x, &xd), self.b.velocity(&x, &xd));
        let d = [pb[0] - pa[0], pb[1] - pa[1]];
        let len2 = d[0] * d[0] + d[1] * d[1];
        let mut out = [D::from(0.0); K];
        if len2.re() == 0.0 {
            return out;
        }
        // Force on b: −c (d·Δv / |d|²) d, i.e. −c times the stretch rate along the unit direction.
        let rate = (d[0] * (vb[0] - va[0]) + d[1] * (vb[1] - va[1])) / len2;
        let f = [-(d[0] * rate) * self.c, -(d[1] * rate) * self.c];
        self.b.apply(&x, f, &mut out);
        self.a.apply(&x, [-f[0], -f[1]], &mut out);
        out
    }
}

/// Torque `−c (ω_b − ω_a)` on `b`, its opposite on `a`.
pub(super) struct RotaryDamper<const K: usize> {
    pub(super) a: Option<usize>,
    pub(super) b: Option<usize>,
    pub(super) c: f64,
}

impl<const K: usize> Force<K> for RotaryDamper<K> {
    #[inline(always)]
    fn force<D: Scalar>(&self, _x: [D; K], xd: [D; K], _t: D) -> [D; K] {
        let torque = -(angle_of(self.b, &xd) - angle_of(self.a, &xd)) * self.c;
        let mut out = [D::from(0.0); K];
        if let Some(b) = self.b {
            out[b] += torque;
        }
        if let Some(a) = self.a {
            out[a] -= torque;
        }
        out
    }
}

/// A world-axes force `(f_x(t), f_y(t))` at one end.
pub(super) struct PointLoad<const K: usize> {
    pub(super) end: End,
    pub(super) fx: TimeFn,
    pub(super) fy: TimeFn,
}

impl<const K: usize> Force<K> for PointLoad<K> {
    #[inline(always)]
    fn force<D: Scalar>(&self, x: [D; K], _xd: [D; K], t: D) -> [D; K] {
        let mut out = [D::from(0.0); K];
        self.end.apply(&x, [self.fx.eval(t), self.fy.eval(t)], &mut out);
        out
    }
}

/// A torque `τ(t)` on one angle coordinate.
pub(super) struct Torque {
    pub(super) f: TimeFn,
}

impl Force<1> for Torque {
    #[inline(always)]
    fn force<D: Scalar>(&self, _x: [D; 1], _xd: [D; 1], t: D) -> [D; 1] {
        [self.f.eval(t)]
    }
}
