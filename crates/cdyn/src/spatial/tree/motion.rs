//! Spatial vectors in space axes, at the origin (Featherstone's Plücker
//! coordinates): a motion `(ω, v)` with `v` the velocity of the body point
//! passing through the origin, a wrench `(n, f)` with `n` the moment about
//! the origin, and a rigid body's inertia there. Written out in 3-vectors:
//! every product here is a handful of cross products, not a 6 × 6 matrix.

use crate::ad::scalar::Scalar;
use crate::spatial::rotation::cross;

pub(super) type V3 = [f64; 3];
pub(super) type M3 = [[f64; 3]; 3];

// Written generic over the scalar: the tree's passes run them in `f64`,
// its loads (`loads.rs`) in dual numbers.

pub(super) fn dot<D: Scalar>(a: [D; 3], b: [D; 3]) -> D {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

pub(super) fn add<D: Scalar>(a: [D; 3], b: [D; 3]) -> [D; 3] {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}

pub(super) fn scale<D: Scalar>(s: D, a: [D; 3]) -> [D; 3] {
    [s * a[0], s * a[1], s * a[2]]
}

pub(super) fn times<D: Scalar>(m: &[[D; 3]; 3], a: [D; 3]) -> [D; 3] {
    [dot(m[0], a), dot(m[1], a), dot(m[2], a)]
}

pub(super) fn product<D: Scalar>(a: &[[D; 3]; 3], b: &[[D; 3]; 3]) -> [[D; 3]; 3] {
    std::array::from_fn(|i| std::array::from_fn(|j| a[i][0] * b[0][j] + a[i][1] * b[1][j] + a[i][2] * b[2][j]))
}

/// The rotation by `angle` about the unit `u` (Rodrigues).
pub(super) fn rotation<D: Scalar>(u: V3, angle: D) -> [[D; 3]; 3] {
    let (s, c) = angle.sin_cos();
    let k = D::from(1.0) - c;
    let skew = [[0.0, -u[2], u[1]], [u[2], 0.0, -u[0]], [-u[1], u[0], 0.0]];
    std::array::from_fn(|i| {
        std::array::from_fn(|j| k * (u[i] * u[j]) + s * skew[i][j] + if i == j { c } else { D::zero() })
    })
}

/// A twist (or a motion subspace's column, or a spatial acceleration).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub(super) struct Motion {
    pub w: V3,
    pub v: V3,
}

/// A wrench or a spatial momentum.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub(super) struct Wrench {
    pub n: V3,
    pub f: V3,
}

impl Motion {
    pub fn scaled(self, s: f64) -> Motion {
        Motion { w: scale(s, self.w), v: scale(s, self.v) }
    }
    pub fn plus(self, b: Motion) -> Motion {
        Motion { w: add(self.w, b.w), v: add(self.v, b.v) }
    }
    /// `self ×ₘ b`: the rate of change of a motion `b` carried by a body moving at `self`.
    pub fn cross(self, b: Motion) -> Motion {
        Motion { w: cross(self.w, b.w), v: add(cross(self.w, b.v), cross(self.v, b.w)) }
    }
    /// `self ×_f h`: the rate of change of a momentum `h` carried along at `self`.
    pub fn cross_wrench(self, h: Wrench) -> Wrench {
        Wrench { n: add(cross(self.w, h.n), cross(self.v, h.f)), f: cross(self.w, h.f) }
    }
    /// The power of a wrench on this motion.
    pub fn dot(self, h: Wrench) -> f64 {
        dot(self.w, h.n) + dot(self.v, h.f)
    }
}

impl Wrench {
    pub fn plus(self, b: Wrench) -> Wrench {
        Wrench { n: add(self.n, b.n), f: add(self.f, b.f) }
    }
}

/// A rigid body's (or a set of rigid bodies') inertia at the origin: its
/// mass, first moment `h = m c` and rotational inertia `Ī = I_c − m [c]×²`
/// about the origin. Sums of bodies are sums of these.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub(super) struct Inertia {
    pub mass: f64,
    pub h: V3,
    pub rot: M3,
}

impl Inertia {
    /// A body of `mass` with its centre at `c` and inertia `ic` about it, in space axes.
    pub fn of_body(mass: f64, c: V3, ic: M3) -> Inertia {
        let cc = dot(c, c);
        let rot = std::array::from_fn(|i| {
            std::array::from_fn(|j| ic[i][j] + mass * (if i == j { cc } else { 0.0 } - c[i] * c[j]))
        });
        Inertia { mass, h: scale(mass, c), rot }
    }

    pub fn plus(&self, b: &Inertia) -> Inertia {
        Inertia {
            mass: self.mass + b.mass,
            h: add(self.h, b.h),
            rot: std::array::from_fn(|i| add(self.rot[i], b.rot[i])),
        }
    }

    /// The momentum `I V = (Ī ω + h × v, m v + ω × h)`.
    pub fn times(&self, m: Motion) -> Wrench {
        Wrench { n: add(times(&self.rot, m.w), cross(self.h, m.v)), f: add(scale(self.mass, m.v), cross(m.w, self.h)) }
    }

    /// The same bodies displaced by `x ↦ R x + p`:
    /// `Ī′ = R Ī Rᵀ − [p]×[R h]× − [R h]×[p]× − m [p]×²`.
    pub fn moved(&self, r: &M3, p: V3) -> Inertia {
        let rh = times(r, self.h);
        let ri: M3 = std::array::from_fn(|i| {
            std::array::from_fn(|k| dot(r[i], [self.rot[0][k], self.rot[1][k], self.rot[2][k]]))
        });
        let (pr, pp) = (dot(p, rh), dot(p, p));
        // −[a]×[b]× = (a·b) 1 − b aᵀ.
        let rot = std::array::from_fn(|i| {
            std::array::from_fn(|j| {
                let diagonal = if i == j { 2.0 * pr + self.mass * pp } else { 0.0 };
                dot(ri[i], r[j]) + diagonal - rh[i] * p[j] - p[i] * rh[j] - self.mass * p[i] * p[j]
            })
        });
        Inertia { mass: self.mass, h: add(rh, scale(self.mass, p)), rot }
    }
}
