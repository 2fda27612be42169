//! Potentials and non-conservative forces as small local elements.
//!
//! A potential element contributes `V` and, by automatic differentiation,
//! the conservative force `−∇V`. A force element contributes a generalized
//! force on its coordinates; its power `F·v` is the energy input `Ė` that the
//! energy constraint integrates.

use crate::ad::jet::JetN;
use crate::ad::scalar::Scalar;
use crate::model::constraint::{JET_FROM, block_entries, second_derivatives, seeded, seeded_jets};
use num_dual::Dual64;
use std::any::Any;

/// Potential energy `V(x)` of `K` coordinates.
pub trait Potential<const K: usize>: Send + Sync + 'static {
    /// `V(x)`, for any scalar type (dual numbers give `∇V` and more).
    fn energy<D: Scalar>(&self, x: [D; K]) -> D;

    /// `V(x)` and `∇V(x)`. The default differentiates
    /// [`energy`](Self::energy) ([`energy_and_gradient_of`]); an element
    /// that knows its gradient (a spatial spring) may give it instead.
    #[inline(always)]
    fn energy_and_gradient(&self, x: [f64; K]) -> (f64, [f64; K])
    where
        Self: Sized,
    {
        energy_and_gradient_of(self, x)
    }

    /// `∇²V(x)`, which an implicit step's Newton matrix needs. The default
    /// takes one hyper-dual pass of [`energy`](Self::energy) per pair of
    /// coordinates ([`hessian_of`]); an element that knows its second
    /// derivatives (a spatial spring) may give them instead.
    #[inline(always)]
    fn hessian(&self, x: [f64; K]) -> [[f64; K]; K]
    where
        Self: Sized,
    {
        hessian_of(self, x)
    }
}

/// `∇²V(x)` by hyper-dual passes of `p.energy`, one per pair of coordinates.
pub fn hessian_of<P: Potential<K>, const K: usize>(p: &P, x: [f64; K]) -> [[f64; K]; K] {
    second_derivatives(&x, |y| p.energy(y).eps1eps2)
}

/// A non-conservative generalized force on `K` coordinates, from their
/// positions `x`, velocities `xd` and the time.
pub trait Force<const K: usize>: Send + Sync + 'static {
    /// The force on each coordinate, for any scalar type.
    fn force<D: Scalar>(&self, x: [D; K], xd: [D; K], t: D) -> [D; K];
}

/// A run of potential elements of one type.
pub(crate) trait PotentialBlock: Send + Sync {
    /// Returns `V` and adds `∇V` into `grad`.
    fn energy_and_gradient(&self, q: &[f64], grad: &mut [f64]) -> f64;
    fn energy(&self, q: &[f64]) -> f64;
    /// The `(row, column)` of each entry of [`hessians`](Self::hessians), element after element.
    fn hessian_entries(&self, out: &mut Vec<(u32, u32)>);
    /// Writes `scale · ∇²V` of each element (`K × K`, row-major) into `out`; returns the entries written.
    fn hessians(&self, q: &[f64], scale: f64, out: &mut [f64]) -> usize;
    fn as_any_mut(&mut self) -> &mut dyn Any;
}

/// A run of force elements of one type.
pub(crate) trait ForceBlock: Send + Sync {
    /// Adds the forces into `f` and returns their power.
    fn add_forces(&self, q: &[f64], v: &[f64], t: f64, f: &mut [f64]) -> f64;
    /// Adds `−∂Q/∂v · w` into `out` (one directional dual pass per element).
    fn add_damping(&self, q: &[f64], v: &[f64], w: &[f64], t: f64, out: &mut [f64]);
    /// The `(row, column)` of each entry of [`jacobians`](Self::jacobians), element after element.
    fn jacobian_entries(&self, out: &mut Vec<(u32, u32)>);
    /// Writes `−(c_q ∂f/∂x + c_v ∂f/∂ẋ)` of each element (`K × K`,
    /// row-major) into `out` — one dual pass per coordinate, seeded in
    /// both — and returns the entries written.
    fn jacobians(&self, q: &[f64], v: &[f64], t: f64, c_q: f64, c_v: f64, out: &mut [f64]) -> usize;
    /// Its elements and the coordinates each reads.
    fn elements(&self) -> (usize, usize);
    fn as_any_mut(&mut self) -> &mut dyn Any;
}

pub(crate) struct PotentialGroup<P, const K: usize> {
    pub items: Vec<(P, [usize; K])>,
}

impl<P: Potential<K>, const K: usize> PotentialBlock for PotentialGroup<P, K> {
    fn energy_and_gradient(&self, q: &[f64], grad: &mut [f64]) -> f64 {
        let mut total = 0.0;
        for (p, idx) in &self.items {
            let (energy, gradient) = p.energy_and_gradient(std::array::from_fn(|j| q[idx[j]]));
            total += energy;
            for j in 0..K {
                grad[idx[j]] += gradient[j];
            }
        }
        total
    }

    fn energy(&self, q: &[f64]) -> f64 {
        let mut total = 0.0;
        for (p, idx) in &self.items {
            total += p.energy(std::array::from_fn(|j| q[idx[j]]));
        }
        total
    }

    fn hessian_entries(&self, out: &mut Vec<(u32, u32)>) {
        block_entries(&self.items, out);
    }

    fn hessians(&self, q: &[f64], scale: f64, out: &mut [f64]) -> usize {
        for ((p, idx), block) in self.items.iter().zip(out.chunks_exact_mut(K * K)) {
            let h = p.hessian(std::array::from_fn(|j| q[idx[j]]));
            block.iter_mut().zip(h.as_flattened()).for_each(|(b, h)| *b = scale * h);
        }
        self.items.len() * K * K
    }

    fn as_any_mut(&mut self) -> &mut dyn Any {
        self
    }
}

/// `V(x)` and `∇V(x)`: one scalar dual pass per coordinate, or one jet
/// pass over more than `JET_FROM` (see `constraint.rs`).
#[inline(always)]
pub fn energy_and_gradient_of<P: Potential<K>, const K: usize>(p: &P, x: [f64; K]) -> (f64, [f64; K]) {
    if K == 0 {
        return (p.energy(x), [0.0; K]);
    }
    if K > JET_FROM {
        let e = p.energy(seeded_jets(&x));
        return (e.re, e.eps.0.into());
    }
    let mut energy = 0.0;
    let gradient = std::array::from_fn(|j| {
        let e = p.energy(seeded(&x, j));
        energy = e.re;
        e.eps
    });
    (energy, gradient)
}

pub(crate) struct ForceGroup<F, const K: usize> {
    pub items: Vec<(F, [usize; K])>,
}

impl<F: Force<K>, const K: usize> ForceBlock for ForceGroup<F, K> {
    fn add_forces(&self, q: &[f64], v: &[f64], t: f64, out: &mut [f64]) -> f64 {
        let mut power = 0.0;
        for (f, idx) in &self.items {
            let x = std::array::from_fn(|j| q[idx[j]]);
            let xd = std::array::from_fn(|j| v[idx[j]]);
            let fx = f.force(x, xd, t);
            for j in 0..K {
                out[idx[j]] += fx[j];
                power += fx[j] * xd[j];
            }
        }
        power
    }

    fn add_damping(&self, q: &[f64], v: &[f64], w: &[f64], t: f64, out: &mut [f64]) {
        for (f, idx) in &self.items {
            let x = std::array::from_fn(|j| Dual64::from(q[idx[j]]));
            let along = std::array::from_fn(|j| Dual64::new(v[idx[j]], w[idx[j]]));
            let fx = f.force(x, along, Dual64::from(t));
            for j in 0..K {
                out[idx[j]] -= fx[j].eps;
            }
        }
    }

    fn jacobian_entries(&self, out: &mut Vec<(u32, u32)>) {
        block_entries(&self.items, out);
    }

    fn jacobians(&self, q: &[f64], v: &[f64], t: f64, c_q: f64, c_v: f64, out: &mut [f64]) -> usize {
        for ((f, idx), block) in self.items.iter().zip(out.chunks_exact_mut(K * K)) {
            if K > JET_FROM {
                // One jet pass, coordinate `j`'s position and rate seeded
                // alike in direction `j`, where each scalar pass evaluated
                // the whole force again (a rotary damper with friction on two
                // bodies' Euler parameters, K = 8: its rotations eight times).
                let seed = |x: &[f64], c: f64| {
                    std::array::from_fn(|j| {
                        let mut jet = JetN::<K>::seeded(x[idx[j]], j);
                        jet.eps.0[j] = c;
                        jet
                    })
                };
                let forces = f.force(seed(q, c_q), seed(v, c_v), JetN::from_re(t));
                for (row, force) in block.chunks_exact_mut(K).zip(&forces) {
                    row.iter_mut().zip(force.eps.0.iter()).for_each(|(b, d)| *b = -d);
                }
                continue;
            }
            for j in 0..K {
                let x = std::array::from_fn(|k| Dual64::new(q[idx[k]], if k == j { c_q } else { 0.0 }));
                let xd = std::array::from_fn(|k| Dual64::new(v[idx[k]], if k == j { c_v } else { 0.0 }));
                let column = f.force(x, xd, Dual64::from(t));
                for i in 0..K {
                    block[i * K + j] = -column[i].eps;
                }
            }
        }
        self.items.len() * K * K
    }

    fn elements(&self) -> (usize, usize) {
        (self.items.len(), K)
    }

    fn as_any_mut(&mut self) -> &mut dyn Any {
        self
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::random::Lcg;

    /// A force on `K` coordinates, nonlinear in positions, rates and time.
    struct Wobble;
    impl<const K: usize> Force<K> for Wobble {
        fn force<D: Scalar>(&self, x: [D; K], xd: [D; K], t: D) -> [D; K] {
            std::array::from_fn(|i| {
                (x[i] * x[(i + 1) % K] + t).sin() * xd[(i + 2) % K] - xd[i] * xd[i] * x[(i + 3) % K]
            })
        }
    }

    /// `−(c_q ∂f/∂q + c_v ∂f/∂v)` of a group — by a jet pass over more than
    /// `JET_FROM` coordinates, by scalar passes over fewer — against central
    /// differences of its forces, on coordinates shuffled among others.
    fn jacobians_match_differences<const K: usize>() {
        let mut random = Lcg(K as u64);
        let n = K + 3;
        // Distinct, out of order (5 is prime to n = 6 and 11).
        let idx: [usize; K] = std::array::from_fn(|i| (5 * i + 2) % n);
        let group = ForceGroup { items: vec![(Wobble, idx)] };
        let (q, v): (Vec<f64>, Vec<f64>) =
            ((0..n).map(|_| random.next()).collect(), (0..n).map(|_| random.next()).collect());
        let (t, c_q, c_v) = (0.3, 0.7, -1.9);
        let mut block = vec![0.0; K * K];
        assert_eq!(group.jacobians(&q, &v, t, c_q, c_v, &mut block), K * K);
        let forces = |q: &[f64], v: &[f64]| {
            let mut f = vec![0.0; n];
            group.add_forces(q, v, t, &mut f);
            f
        };
        let step = 1e-6;
        for (j, &c) in idx.iter().enumerate() {
            let shifted = |x: &[f64], by: f64| {
                let mut x = x.to_vec();
                x[c] += by;
                x
            };
            let dq = (forces(&shifted(&q, step), &v), forces(&shifted(&q, -step), &v));
            let dv = (forces(&q, &shifted(&v, step)), forces(&q, &shifted(&v, -step)));
            for (i, &r) in idx.iter().enumerate() {
                let by_q = (dq.0[r] - dq.1[r]) / (2.0 * step);
                let by_v = (dv.0[r] - dv.1[r]) / (2.0 * step);
                let expected = -(c_q * by_q + c_v * by_v);
                assert!(
                    (block[i * K + j] - expected).abs() < 1e-8,
                    "K = {K}, ({i}, {j}): {} vs {expected}",
                    block[i * K + j]
                );
            }
        }
    }

    #[test]
    fn force_jacobians_match_central_differences() {
        jacobians_match_differences::<3>();
        jacobians_match_differences::<8>();
    }
}
