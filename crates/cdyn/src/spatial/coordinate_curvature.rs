//! A joint coordinate's second derivatives `∇²θ` in closed form, over the
//! coordinates of the bodies it reads: the curvature a joint-limit stop
//! and a `<mimic>` row give generalized-α's Newton matrix, where hyper-dual
//! passes, one per pair of read coordinates, took a quarter of Panda's
//! step (231 for its fingers' `<mimic>` on three bodies).
//!
//! A displacement is `(x_a − x_b) · h_b`, an angle `atan2(s, c)` with
//! `c = f_a · f_b` and `s = f_a · g_b`: dot products of vectors `A(p)s`
//! (plus `r` for a point), whose gradient in `p` is `rotate_jacobian` and
//! whose second derivatives, `A(p)s` being quadratic in `p`, are the
//! constant `rotate_hessian`. The product rule and the derivatives of
//! `atan2` do the rest.

use super::coordinate::JointCoordinate;
use super::joint_rows::{F, G, H, pose};
use super::rotation::{rotate_fixed, rotate_hessian, rotate_jacobian};

/// A side's vector over an element's `K` coordinates.
struct Vector<const K: usize> {
    x: [f64; 3],
    grad: [[f64; K]; 3],
    /// The body-fixed vector it rotates, and where its body's `p` starts
    /// (`None` on the ground, where it is fixed).
    s: [f64; 3],
    p_at: Option<usize>,
}

/// `s` rotated by the body in `slot` (moved by its `r` when `moved`), or
/// `s` itself on the ground.
fn vector<const K: usize>(x: &[f64; K], slot: Option<usize>, s: [f64; 3], moved: bool) -> Vector<K> {
    let Some(k) = slot else {
        return Vector { x: s, grad: [[0.0; K]; 3], s, p_at: None };
    };
    let (r, p) = pose(x, 7 * k);
    let (y, jacobian) = (rotate_fixed(p, s), rotate_jacobian(p, s));
    let mut grad = [[0.0; K]; 3];
    for i in 0..3 {
        grad[i][7 * k + 3..7 * k + 7].copy_from_slice(&jacobian[i]);
        if moved {
            grad[i][7 * k + i] = 1.0;
        }
    }
    let x = std::array::from_fn(|i| y[i] + if moved { r[i] } else { 0.0 });
    Vector { x, grad, s, p_at: Some(7 * k + 3) }
}

/// A scalar with its gradient and second derivatives.
struct Second<const K: usize> {
    value: f64,
    grad: [f64; K],
    hess: [[f64; K]; K],
}

/// `u · v`: `∇²(u · v) = Σᵢ (vᵢ ∇²uᵢ + uᵢ ∇²vᵢ + ∇uᵢ ⊗ ∇vᵢ + ∇vᵢ ⊗ ∇uᵢ)`.
fn dot<const K: usize>(u: &Vector<K>, v: &Vector<K>) -> Second<K> {
    let value = (0..3).map(|i| u.x[i] * v.x[i]).sum();
    let grad = std::array::from_fn(|j| (0..3).map(|i| u.grad[i][j] * v.x[i] + u.x[i] * v.grad[i][j]).sum());
    let mut hess: [[f64; K]; K] = std::array::from_fn(|j| {
        std::array::from_fn(|l| (0..3).map(|i| u.grad[i][j] * v.grad[i][l] + v.grad[i][j] * u.grad[i][l]).sum())
    });
    for (w, weights) in [(u, v.x), (v, u.x)] {
        if let Some(at) = w.p_at {
            let h = rotate_hessian(w.s, weights);
            for k in 0..4 {
                for l in 0..4 {
                    hess[at + k][at + l] += h[k][l];
                }
            }
        }
    }
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
            let c = dot(&fa, &vector(x, b, self.b.axes[F], false));
            let s = dot(&fa, &vector(x, b, self.b.axes[G], false));
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
            let (along_a, along_b) = (dot(&pa, &hb), dot(&pb, &hb));
            std::array::from_fn(|j| std::array::from_fn(|l| along_a.hess[j][l] - along_b.hess[j][l]))
        }
    }
}
