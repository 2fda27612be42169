//! A joint coordinate's second derivatives `∇²θ` in closed form, over the
//! coordinates of the bodies it reads: the curvature a joint-limit stop
//! and a `<mimic>` row give generalized-α's Newton matrix, where hyper-dual
//! passes, one per pair of read coordinates, took a quarter of Panda's
//! step (231 for its fingers' `<mimic>` on three bodies).
//!
//! A displacement is `(x_a − x_b) · h_b`, an angle `atan2(s, c)` with
//! `c = f_a · f_b` and `s = f_a · g_b`: dot products of the sides' vectors
//! `A(p)s` (plus `r` for a point), differentiated twice as a joint's rows
//! are (`joint_curvature`); the derivatives of `atan2` do the rest.

use super::coordinate::JointCoordinate;
use super::joint_curvature::{At, curve, outer, wide};
use super::joint_element::{Sided, sided, still};
use super::joint_rows::{F, G, H, pose};

/// `s` rotated by the body in `slot` (moved by its `r` when `moved`), as a
/// joint's rows have it, with where the body's coordinates start; `s`
/// itself on the ground.
fn vector<const K: usize>(x: &[f64; K], slot: Option<usize>, s: [f64; 3], moved: bool) -> (Sided, At) {
    match slot {
        None => (still(s), None),
        Some(k) => {
            let (r, p) = pose(x, 7 * k);
            (sided(r, p, ([0.0; 3], [0.0; 4]), s, moved), Some(7 * k))
        }
    }
}

/// A scalar with its gradient and second derivatives.
struct Second<const K: usize> {
    value: f64,
    grad: [f64; K],
    hess: [[f64; K]; K],
}

/// `u · v`, its gradient and, by the product rule of the joints'
/// curvatures ([`outer`], [`curve`]), its second derivatives.
fn dot<const K: usize>((u, at_u): &(Sided, At), (v, at_v): &(Sided, At)) -> Second<K> {
    let (gu, gv) = (wide::<K>(u, *at_u), wide::<K>(v, *at_v));
    let value = (0..3).map(|i| u.x[i] * v.x[i]).sum();
    let grad = std::array::from_fn(|j| (0..3).map(|i| gu[i][j] * v.x[i] + u.x[i] * gv[i][j]).sum());
    let mut hess = [[0.0; K]; K];
    outer(&mut hess, &gu, &gv, 1.0);
    curve(&mut hess, u, *at_u, v.x);
    curve(&mut hess, v, *at_v, u.x);
    Second { value, grad, hess }
}

impl JointCoordinate {
    /// `∇²θ` over the `K` coordinates of the bodies in `sides` (as
    /// [`at`](Self::at) reads them; the reference it is taken from moves
    /// `θ` by a constant or, in a `<mimic>`, by the leader's own `θ`).
    pub(super) fn hessian<const K: usize>(&self, x: &[f64; K], sides: [Option<usize>; 2]) -> [[f64; K]; K] {
        let [a, b] = sides;
        if self.rotary {
            let fa = vector(x, a, self.a.axes[F], false);
            let c = dot::<K>(&fa, &vector(x, b, self.b.axes[F], false));
            let s = dot::<K>(&fa, &vector(x, b, self.b.axes[G], false));
            // θ = atan2(s, c): ∇θ = (c∇s − s∇c)/ρ, ρ = c² + s², and
            // ∇²θ = (c∇²s − s∇²c + ∇s⊗∇c − ∇c⊗∇s)/ρ − ∇θ ⊗ ∇ρ/ρ.
            let rho = c.value * c.value + s.value * s.value;
            let slope: [f64; K] = std::array::from_fn(|j| (c.value * s.grad[j] - s.value * c.grad[j]) / rho);
            let spread: [f64; K] = std::array::from_fn(|j| 2.0 * (c.value * c.grad[j] + s.value * s.grad[j]));
            std::array::from_fn(|j| {
                std::array::from_fn(|l| {
                    (c.value * s.hess[j][l] - s.value * c.hess[j][l] + s.grad[j] * c.grad[l]
                        - c.grad[j] * s.grad[l]
                        - slope[j] * spread[l])
                        / rho
                })
            })
        } else {
            let (pa, pb) = (vector(x, a, self.a.s, true), vector(x, b, self.b.s, true));
            let hb = vector(x, b, self.b.axes[H], false);
            let (along_a, along_b) = (dot::<K>(&pa, &hb), dot::<K>(&pb, &hb));
            std::array::from_fn(|j| std::array::from_fn(|l| along_a.hess[j][l] - along_b.hess[j][l]))
        }
    }
}
