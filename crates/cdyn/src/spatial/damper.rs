//! A rotary damper across a joint: the torque `−c ω_rel h` on body `b` and
//! its opposite on `a`, where `h` is the axis carried by `a` and `ω_rel`
//! the rate of `b` relative to `a` about it. A torque `n` (in space) acts on
//! a body's Euler parameters as the generalized force `2 E(p)ᵀ n`, whose
//! power `nᵀ ω` is what the energy balance integrates.

use super::rotation::{e_matrix, rotate};
use crate::force::Force;
use crate::scalar::Scalar;

/// A rotary damper as the user describes it, at the initial pose.
#[derive(Debug, Clone, PartialEq)]
pub struct Damper {
    /// The first body.
    pub a: usize,
    /// The second body, or `None` for the ground.
    pub b: Option<usize>,
    /// The axis, in space at the initial pose.
    pub axis: [f64; 3],
    /// The damping coefficient (torque per rate), non-negative.
    pub c: f64,
}

/// `ω = 2 E(p) ṗ`, generic.
fn rate<D: Scalar>(p: [D; 4], pd: [D; 4]) -> [D; 3] {
    let e = e_matrix(p);
    std::array::from_fn(|i| (e[i][0] * pd[0] + e[i][1] * pd[1] + e[i][2] * pd[2] + e[i][3] * pd[3]) * 2.0)
}

/// `2 E(p)ᵀ n`
fn on_parameters<D: Scalar>(p: [D; 4], n: [D; 3]) -> [D; 4] {
    let e = e_matrix(p);
    std::array::from_fn(|j| (e[0][j] * n[0] + e[1][j] * n[1] + e[2][j] * n[2]) * 2.0)
}

/// Between two bodies: reads their Euler parameters `(p_a, p_b)`; the axis in `a`'s axes.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct BodyDamper {
    pub axis: [f64; 3],
    pub c: f64,
}

impl Force<8> for BodyDamper {
    fn force<D: Scalar>(&self, x: [D; 8], xd: [D; 8], _t: D) -> [D; 8] {
        let (pa, pb): ([D; 4], [D; 4]) = (std::array::from_fn(|i| x[i]), std::array::from_fn(|i| x[4 + i]));
        let (va, vb): ([D; 4], [D; 4]) = (std::array::from_fn(|i| xd[i]), std::array::from_fn(|i| xd[4 + i]));
        let h = rotate(pa, self.axis.map(D::from));
        let (wa, wb) = (rate(pa, va), rate(pb, vb));
        let rel = (0..3).fold(D::zero(), |s, i| s + (wb[i] - wa[i]) * h[i]);
        let n: [D; 3] = std::array::from_fn(|i| -(rel * h[i]) * self.c);
        let (fa, fb) = (on_parameters(pa, n.map(|x| -x)), on_parameters(pb, n));
        std::array::from_fn(|i| if i < 4 { fa[i] } else { fb[i - 4] })
    }
}

/// Between a body and the ground: reads its Euler parameters; the axis in space.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct GroundDamper {
    pub axis: [f64; 3],
    pub c: f64,
}

impl Force<4> for GroundDamper {
    fn force<D: Scalar>(&self, p: [D; 4], pd: [D; 4], _t: D) -> [D; 4] {
        let w = rate(p, pd);
        let rel = (0..3).fold(D::zero(), |s, i| s + w[i] * self.axis[i]);
        on_parameters(p, self.axis.map(|h| -(rel * h) * self.c))
    }
}
