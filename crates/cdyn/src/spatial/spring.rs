//! A spatial spring's gradient and Hessian in closed form, where dual
//! passes of its energy rotated both ends again on every pass (a jet pass
//! of 14-wide numbers for the gradient, 105 hyper-dual passes for the
//! Hessian). Each end is a body point `r + A(p)s`, whose derivatives in
//! `p` are [`rotate_jacobian`] and, being quadratic in `p`, the same
//! second derivatives at every pose ([`rotate_hessian`]).

use super::joint_curvature::add_rotation_block;
use super::load::SpringEnergy;
use super::rotation::{rotate_fixed, rotate_hessian, rotate_jacobian};

impl SpringEnergy {
    /// `ℓ = |g|`, `n = g/ℓ`, `∇g` (3 × `K`) and `∇ℓ = nᵀ∇g` of
    /// `g = x_b − x_a`, each end's `∇x` being `(I, ∂(A s)/∂p)` on its
    /// body's coordinates.
    fn line<const K: usize>(&self, x: &[f64; K]) -> (f64, [f64; 3], [[f64; K]; 3], [f64; K]) {
        let end = |at: usize, s: [f64; 3]| -> ([f64; 3], [[f64; K]; 3]) {
            let p = std::array::from_fn(|i| x[at + 3 + i]);
            let (arm, jacobian) = (rotate_fixed(p, s), rotate_jacobian(p, s));
            let mut d = [[0.0; K]; 3];
            for i in 0..3 {
                d[i][at + i] = 1.0;
                d[i][at + 3..at + 7].copy_from_slice(&jacobian[i]);
            }
            (std::array::from_fn(|i| x[at + i] + arm[i]), d)
        };
        let (xa, da) = end(0, self.sa);
        let (xb, db) = if self.ground { (self.sb, [[0.0; K]; 3]) } else { end(7, self.sb) };
        let g: [f64; 3] = std::array::from_fn(|i| xb[i] - xa[i]);
        let l = (g[0] * g[0] + g[1] * g[1] + g[2] * g[2]).sqrt();
        let n = g.map(|g| g / l);
        let dg: [[f64; K]; 3] = std::array::from_fn(|i| std::array::from_fn(|j| db[i][j] - da[i][j]));
        let dl = std::array::from_fn(|j| n[0] * dg[0][j] + n[1] * dg[1][j] + n[2] * dg[2][j]);
        (l, n, dg, dl)
    }

    /// `V = ½ k (ℓ − ℓ₀)²` and `∇V = k (ℓ − ℓ₀) ∇ℓ` (the jet pass was a
    /// fifth of the flyball governor's RK-4 run).
    pub(super) fn gradient_at<const K: usize>(&self, x: &[f64; K]) -> (f64, [f64; K]) {
        let (l, _, _, dl) = self.line(x);
        let stretch = l - self.length;
        (0.5 * self.k * stretch * stretch, dl.map(|d| self.k * stretch * d))
    }

    /// `∇²V = k ∇ℓ ⊗ ∇ℓ + k (ℓ − ℓ₀) ((∇gᵀ∇g − ∇ℓ ⊗ ∇ℓ)/ℓ + Σᵢ nᵢ ∇²gᵢ)`
    /// (the hyper-dual passes took most of a generalized-α step of the
    /// flyball governor).
    pub(super) fn hessian_at<const K: usize>(&self, x: &[f64; K]) -> [[f64; K]; K] {
        let (l, n, dg, dl) = self.line(x);
        let force = self.k * (l - self.length);
        let mut h = [[0.0; K]; K];
        for a in 0..K {
            for b in 0..K {
                let gg = dg[0][a] * dg[0][b] + dg[1][a] * dg[1][b] + dg[2][a] * dg[2][b];
                h[a][b] = self.k * dl[a] * dl[b] + force * (gg - dl[a] * dl[b]) / l;
            }
        }
        add_rotation_block(&mut h, 0, rotate_hessian(self.sa, n.map(|n| -force * n)));
        if !self.ground {
            add_rotation_block(&mut h, 7, rotate_hessian(self.sb, n.map(|n| force * n)));
        }
        h
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::force::Potential;
    use crate::model::force::{energy_and_gradient_of, hessian_of};

    /// The spring's closed-form energy, gradient and Hessian against a
    /// jet pass and one hyper-dual pass per pair, between two bodies and to
    /// the ground, at poses with quaternions off unit length and the spring
    /// stretched and compressed.
    #[test]
    fn the_springs_gradient_and_hessian_are_the_dual_passes() {
        for (seed, length) in [(1, 0.2), (2, 3.0)] {
            let mut random = crate::random::Lcg(seed);
            let mut three = || [random.next(), random.next(), random.next()];
            let (sa, sb) = (three(), three());
            let spring = |ground| SpringEnergy { sa, sb, ground, k: 7.0, length };
            let x: [f64; 14] = std::array::from_fn(|_| random.next());
            let close = |a: &[f64], b: &[f64]| a.iter().zip(b).all(|(a, b)| (a - b).abs() <= 1e-13 * (1.0 + b.abs()));
            let (two, one) = (spring(false), spring(true));
            // The first case stretched, the second compressed.
            let (l, ..) = two.line(&x);
            assert_eq!(l > length, seed == 1, "ℓ = {l}, ℓ₀ = {length}");
            let (c, p) = (Potential::<14>::hessian(&two, x), hessian_of::<_, 14>(&two, x));
            assert!(close(c.as_flattened(), p.as_flattened()), "{c:?} vs {p:?}");
            let x7: [f64; 7] = std::array::from_fn(|i| x[i]);
            let (c, p) = (Potential::<7>::hessian(&one, x7), hessian_of::<_, 7>(&one, x7));
            assert!(close(c.as_flattened(), p.as_flattened()), "grounded: {c:?} vs {p:?}");
            let ((e, c), (f, p)) = (Potential::<14>::energy_and_gradient(&two, x), energy_and_gradient_of(&two, x));
            assert!(close(&[e], &[f]) && close(&c, &p), "gradient: {c:?} vs {p:?}");
            let ((e, c), (f, p)) = (Potential::<7>::energy_and_gradient(&one, x7), energy_and_gradient_of(&one, x7));
            assert!(close(&[e], &[f]) && close(&c, &p), "grounded gradient: {c:?} vs {p:?}");
        }
    }
}
