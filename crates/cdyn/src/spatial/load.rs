//! Loads on a spatial mechanism: spring-dampers between two points, rotary
//! dampers about an axis, and constant forces and torques. A force `F` at
//! a body point `s` acts on the body's coordinates as `F` on `r` and
//! `2 E(p)ᵀ ((A s) × F)` on `p`, a torque `n` as `2 E(p)ᵀ n`, whose power
//! `nᵀ ω` (with `ω = 2 E ṗ`) is what the energy balance integrates. Springs
//! are potentials (their energy is part of `V`); dampers, forces and
//! torques are forces.

use super::joint::FRICTION_SLIP;
use super::rotation::{cross, rotate_fixed, space_rate as rate, torque_on_parameters as on_parameters};
use crate::ad::scalar::Scalar;
use crate::model::force::{Force, Potential};

/// A load as the user describes it, at the initial pose; in a scenario
/// file a `[[forces]]` entry, tagged by `kind`, its bodies named (`B =
/// String`; `b` omitted or `"ground"` for the ground).
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Deserialize),
    serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)
)]
#[non_exhaustive]
pub enum Load<B = usize> {
    /// A linear spring and damper from `point` on `a` to `point_b` on `b`
    /// (in space at the initial pose): the force `k (l − length) + c l̇`
    /// along the line, pulling the points together when positive.
    Spring {
        /// The first body.
        a: B,
        /// The second body; `None` for the ground.
        #[cfg_attr(feature = "serde", serde(default))]
        b: Option<B>,
        /// The end on `a`.
        point: [f64; 3],
        /// The end on `b`.
        point_b: [f64; 3],
        /// `k`, non-negative.
        stiffness: f64,
        /// `c`, non-negative.
        #[cfg_attr(feature = "serde", serde(default))]
        damping: f64,
        /// The unstretched length; default: the initial distance.
        #[cfg_attr(feature = "serde", serde(default))]
        length: Option<f64>,
    },
    /// A rotary damper: the torque `−c ω_rel h` on `b` and its opposite on
    /// `a`, `h` the axis carried by `a`, `ω_rel` the rate of `b` relative
    /// to `a` about it. With the ground for `b`, the torque `−c ω h` on `a`
    /// alone, `h` fixed in space and `ω` `a`'s rate about it.
    RotaryDamper {
        /// The first body.
        a: B,
        /// The second body; `None` for the ground.
        #[cfg_attr(feature = "serde", serde(default))]
        b: Option<B>,
        /// The axis, in space at the initial pose.
        axis: [f64; 3],
        /// `c`, non-negative.
        damping: f64,
    },
    /// A constant force (space axes) at a point of a body.
    Force {
        /// The body.
        body: B,
        /// The force.
        force: [f64; 3],
        /// Where it acts, in space at the initial pose; default the centre of mass.
        #[cfg_attr(feature = "serde", serde(default))]
        point: Option<[f64; 3]>,
    },
    /// A constant torque (space axes) on a body.
    Torque {
        /// The body.
        body: B,
        /// The torque.
        torque: [f64; 3],
    },
}

impl<B> Load<B> {
    /// Its name in scenario files and messages.
    pub fn kind(&self) -> &'static str {
        match self {
            Load::Spring { .. } => "spring",
            Load::RotaryDamper { .. } => "rotary_damper",
            Load::Force { .. } => "force",
            Load::Torque { .. } => "torque",
        }
    }
}

/// One end of a two-point load at a state: a body point (its arm `A s`
/// from the centre of mass) or a ground point.
pub(super) struct End<D> {
    at: [D; 3],
    pub(super) velocity: [D; 3],
    /// `(r, p, A s)` of a body end.
    body: Option<([D; 4], [D; 3])>,
}

/// The end at body point `s` of the body whose `(r, p)` start at `x[at]`.
pub(super) fn body_end<D: Scalar, const K: usize>(x: &[D; K], xd: &[D; K], at: usize, s: [f64; 3]) -> End<D> {
    let p: [D; 4] = std::array::from_fn(|i| x[at + 3 + i]);
    let arm = rotate_fixed(p, s);
    let w = rate(p, std::array::from_fn(|i| xd[at + 3 + i]));
    let spin = cross(w, arm);
    End {
        at: std::array::from_fn(|i| x[at + i] + arm[i]),
        velocity: std::array::from_fn(|i| xd[at + i] + spin[i]),
        body: Some((p, arm)),
    }
}

pub(super) fn ground_end<D: Scalar>(point: [f64; 3]) -> End<D> {
    End { at: point.map(D::from), velocity: [D::zero(); 3], body: None }
}

/// The generalized force of `f` at `end` into `out[at..at + 7]`.
pub(super) fn apply<D: Scalar>(end: &End<D>, f: [D; 3], out: &mut [D], at: usize) {
    if let Some((p, arm)) = end.body {
        let q = on_parameters(p, cross(arm, f));
        for i in 0..3 {
            out[at + i] += f[i];
        }
        for i in 0..4 {
            out[at + 3 + i] += q[i];
        }
    }
}

/// The spring's potential `½ k (l − l₀)²` between body points (`K = 14`)
/// or a body point and a ground point (`K = 7`, `ground` set).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct SpringEnergy {
    pub sa: [f64; 3],
    pub sb: [f64; 3],
    pub ground: bool,
    pub k: f64,
    pub length: f64,
}

impl SpringEnergy {
    fn ends<D: Scalar, const K: usize>(&self, x: &[D; K]) -> (End<D>, End<D>) {
        let zero = [D::zero(); K];
        let a = body_end(x, &zero, 0, self.sa);
        let b = if self.ground { ground_end(self.sb) } else { body_end(x, &zero, 7, self.sb) };
        (a, b)
    }
}

fn potential<D: Scalar>(s: &SpringEnergy, a: End<D>, b: End<D>) -> D {
    let d: [D; 3] = std::array::from_fn(|i| b.at[i] - a.at[i]);
    let stretch = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt() - s.length;
    stretch * stretch * (0.5 * s.k)
}

impl Potential<14> for SpringEnergy {
    fn energy<D: Scalar>(&self, x: [D; 14]) -> D {
        let (a, b) = self.ends(&x);
        potential(self, a, b)
    }
    fn energy_and_gradient(&self, x: [f64; 14]) -> (f64, [f64; 14]) {
        self.gradient_at(&x)
    }
    fn hessian(&self, x: [f64; 14]) -> [[f64; 14]; 14] {
        self.hessian_at(&x)
    }
}

impl Potential<7> for SpringEnergy {
    fn energy<D: Scalar>(&self, x: [D; 7]) -> D {
        let (a, b) = self.ends(&x);
        potential(self, a, b)
    }
    fn energy_and_gradient(&self, x: [f64; 7]) -> (f64, [f64; 7]) {
        self.gradient_at(&x)
    }
    fn hessian(&self, x: [f64; 7]) -> [[f64; 7]; 7] {
        self.hessian_at(&x)
    }
}

/// The damper of a spring: `−c l̇` along the line, between body points
/// (`K = 14`) or a body point and a ground point (`K = 7`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct LineDamper {
    pub sa: [f64; 3],
    pub sb: [f64; 3],
    pub ground: bool,
    pub c: f64,
}

impl LineDamper {
    fn forces<D: Scalar, const K: usize>(&self, x: [D; K], xd: [D; K]) -> [D; K] {
        let a = body_end(&x, &xd, 0, self.sa);
        let b = if self.ground { ground_end(self.sb) } else { body_end(&x, &xd, 7, self.sb) };
        let d: [D; 3] = std::array::from_fn(|i| b.at[i] - a.at[i]);
        let l = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
        let u = d.map(|x| x / l);
        let rate = (0..3).fold(D::zero(), |s, i| s + (b.velocity[i] - a.velocity[i]) * u[i]);
        // On b: −c l̇ u; on a: the opposite.
        let on_b = u.map(|x| -(x * rate) * self.c);
        let mut out = [D::zero(); K];
        apply(&a, on_b.map(|x| -x), &mut out, 0);
        apply(&b, on_b, &mut out, 7);
        out
    }
}

impl Force<14> for LineDamper {
    fn force<D: Scalar>(&self, x: [D; 14], xd: [D; 14], _t: D) -> [D; 14] {
        self.forces(x, xd)
    }
}

impl Force<7> for LineDamper {
    fn force<D: Scalar>(&self, x: [D; 7], xd: [D; 7], _t: D) -> [D; 7] {
        self.forces(x, xd)
    }
}

/// A joint's resisting torque (force) at the relative rate `r`:
/// `−c r − μ r / √(r² + s²)`, viscous damping and Coulomb friction
/// regularized at the slip rate `s` ([`FRICTION_SLIP`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Law {
    pub damping: f64,
    pub friction: f64,
}

impl Law {
    pub fn damper(damping: f64) -> Self {
        Self { damping, friction: 0.0 }
    }

    #[inline(always)]
    fn resist<D: Scalar>(&self, r: D) -> D {
        let friction = if self.friction == 0.0 {
            D::zero()
        } else {
            r / (r * r + FRICTION_SLIP * FRICTION_SLIP).sqrt() * self.friction
        };
        -(r * self.damping + friction)
    }
}

/// The law on a coordinate that is the joint's own (a tree in joint coordinates).
impl Force<1> for Law {
    fn force<D: Scalar>(&self, _x: [D; 1], [rate]: [D; 1], _t: D) -> [D; 1] {
        [self.resist(rate)]
    }
}

/// A rotary damper between two bodies: reads `(p_a, p_b)`; the axis in `a`'s axes.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct BodyRotaryDamper {
    pub axis: [f64; 3],
    pub law: Law,
}

impl Force<8> for BodyRotaryDamper {
    fn force<D: Scalar>(&self, x: [D; 8], xd: [D; 8], _t: D) -> [D; 8] {
        let (pa, pb): ([D; 4], [D; 4]) = (std::array::from_fn(|i| x[i]), std::array::from_fn(|i| x[4 + i]));
        let (va, vb): ([D; 4], [D; 4]) = (std::array::from_fn(|i| xd[i]), std::array::from_fn(|i| xd[4 + i]));
        let h = rotate_fixed(pa, self.axis);
        let (wa, wb) = (rate(pa, va), rate(pb, vb));
        let rel = (0..3).fold(D::zero(), |s, i| s + (wb[i] - wa[i]) * h[i]);
        let torque = self.law.resist(rel);
        let n: [D; 3] = std::array::from_fn(|i| h[i] * torque);
        let (fa, fb) = (on_parameters(pa, n.map(|x| -x)), on_parameters(pb, n));
        std::array::from_fn(|i| if i < 4 { fa[i] } else { fb[i - 4] })
    }
}

/// A rotary damper between a body and the ground: reads its Euler parameters; the axis in space.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct GroundRotaryDamper {
    pub axis: [f64; 3],
    pub law: Law,
}

impl Force<4> for GroundRotaryDamper {
    fn force<D: Scalar>(&self, p: [D; 4], pd: [D; 4], _t: D) -> [D; 4] {
        let w = rate(p, pd);
        let rel = (0..3).fold(D::zero(), |s, i| s + w[i] * self.axis[i]);
        let torque = self.law.resist(rel);
        on_parameters(p, self.axis.map(|h| torque * h))
    }
}

/// A prismatic joint's damping and friction: the force `law(ṙ) h` on `b`
/// at its point `sb` and its opposite on `a` at `sa`, `h` the axis carried
/// by `a` (in its axes), `ṙ` the rate of `b`'s point relative to `a`'s
/// along it — the joint coordinate's rate, with the sign turned, wherever
/// the joint holds (the points then lie on the axis, which turns with both
/// bodies alike). Between two bodies (`K = 14`) or a body and the ground
/// (`K = 7`, `ground` set, `sb` in space).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Slide {
    pub sa: [f64; 3],
    pub sb: [f64; 3],
    pub axis: [f64; 3],
    pub ground: bool,
    pub law: Law,
}

impl Slide {
    fn forces<D: Scalar, const K: usize>(&self, x: [D; K], xd: [D; K]) -> [D; K] {
        let a = body_end(&x, &xd, 0, self.sa);
        let b = if self.ground { ground_end(self.sb) } else { body_end(&x, &xd, 7, self.sb) };
        let h = rotate_fixed(std::array::from_fn(|i| x[3 + i]), self.axis);
        let rel = (0..3).fold(D::zero(), |s, i| s + (b.velocity[i] - a.velocity[i]) * h[i]);
        let f = self.law.resist(rel);
        let on_b: [D; 3] = std::array::from_fn(|i| h[i] * f);
        let mut out = [D::zero(); K];
        apply(&a, on_b.map(|x| -x), &mut out, 0);
        apply(&b, on_b, &mut out, 7);
        out
    }
}

impl Force<14> for Slide {
    fn force<D: Scalar>(&self, x: [D; 14], xd: [D; 14], _t: D) -> [D; 14] {
        self.forces(x, xd)
    }
}

impl Force<7> for Slide {
    fn force<D: Scalar>(&self, x: [D; 7], xd: [D; 7], _t: D) -> [D; 7] {
        self.forces(x, xd)
    }
}

/// A constant force at body point `s`: reads `(r, p)`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct PointForce {
    pub s: [f64; 3],
    pub f: [f64; 3],
}

impl Force<7> for PointForce {
    fn force<D: Scalar>(&self, x: [D; 7], xd: [D; 7], _t: D) -> [D; 7] {
        let mut out = [D::zero(); 7];
        apply(&body_end(&x, &xd, 0, self.s), self.f.map(D::from), &mut out, 0);
        out
    }
}

/// A constant torque: reads `p`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct BodyTorque {
    pub n: [f64; 3],
}

impl Force<4> for BodyTorque {
    fn force<D: Scalar>(&self, p: [D; 4], _pd: [D; 4], _t: D) -> [D; 4] {
        on_parameters(p, self.n.map(D::from))
    }
}
