//! Holonomic constraints as small local elements.
//!
//! An element reads `K` coordinates and yields `R` constraint rows. The
//! library differentiates it with dual numbers: a `K`-direction first-order
//! pass gives the local Jacobian block, and one second-order pass along
//! `(v, 1)` gives `Φ̇ = Φ_q v + Φ_t` and `γ` (Eq. 5). Blocks are stored by
//! element type so a chain of ten thousand rods is one monomorphized loop.

use crate::scalar::Scalar;
use num_dual::{Dual2_64, DualSVec64};
use std::any::Any;

/// `R` holonomic constraints `Φ(x, t) = 0` on `K` coordinates `x`.
pub trait Constraint<const K: usize, const R: usize>: Send + Sync + 'static {
    /// The constraint values; written once for every scalar type.
    fn eval<D: Scalar>(&self, x: [D; K], t: D) -> [D; R];
}

/// Where one evaluation of the constraints goes: per row `Φ`, `Φ̇`, `γ`,
/// and the Jacobian entries of each row in the order of its coordinates.
pub(crate) struct ConstraintValues<'a> {
    pub phi: &'a mut [f64],
    pub phi_dot: &'a mut [f64],
    pub gamma: &'a mut [f64],
    pub jac: &'a mut [f64],
}

/// A run of constraint elements of one type (object-safe face).
pub(crate) trait ConstraintBlock: Send + Sync {
    fn rows(&self) -> usize;
    /// Coordinates read by each row (the same `K` for every row of the block).
    fn width(&self) -> usize;
    /// Appends the coordinate index of every Jacobian entry, row by row.
    fn columns(&self, out: &mut Vec<usize>);
    fn evaluate(&self, q: &[f64], v: &[f64], t: f64, out: ConstraintValues<'_>);
    /// `Φ` only, in plain `f64`.
    fn values(&self, q: &[f64], t: f64, phi: &mut [f64]);
    fn as_any_mut(&mut self) -> &mut dyn Any;
}

pub(crate) struct ConstraintGroup<C, const K: usize, const R: usize> {
    pub items: Vec<(C, [usize; K])>,
}

impl<C: Constraint<K, R>, const K: usize, const R: usize> ConstraintBlock for ConstraintGroup<C, K, R> {
    fn rows(&self) -> usize {
        self.items.len() * R
    }

    fn width(&self) -> usize {
        K
    }

    fn columns(&self, out: &mut Vec<usize>) {
        for (_, idx) in &self.items {
            for _ in 0..R {
                out.extend_from_slice(idx);
            }
        }
    }

    fn evaluate(&self, q: &[f64], v: &[f64], t: f64, out: ConstraintValues<'_>) {
        for (e, (c, idx)) in self.items.iter().enumerate() {
            let grad: [DualSVec64<K>; K] = std::array::from_fn(|j| DualSVec64::<K>::from_re(q[idx[j]]).derivative(j));
            let rows = c.eval(grad, DualSVec64::from_re(t));
            // Second directional derivative of s ↦ Φ(q + s v, t + s): Φ̈ at zero
            // acceleration, which is −γ.
            let path: [Dual2_64; K] = std::array::from_fn(|j| Dual2_64::new(q[idx[j]], v[idx[j]], 0.0));
            let along = c.eval(path, Dual2_64::new(t, 1.0, 0.0));
            for r in 0..R {
                let row = e * R + r;
                out.phi[row] = rows[r].re;
                out.phi_dot[row] = along[r].v1;
                out.gamma[row] = -along[r].v2;
                let jac = &mut out.jac[row * K..(row + 1) * K];
                match &rows[r].eps.0 {
                    Some(d) => jac.copy_from_slice(d.as_slice()),
                    None => jac.fill(0.0),
                }
            }
        }
    }

    fn values(&self, q: &[f64], t: f64, phi: &mut [f64]) {
        for (e, (c, idx)) in self.items.iter().enumerate() {
            let rows = c.eval(std::array::from_fn(|j| q[idx[j]]), t);
            phi[e * R..(e + 1) * R].copy_from_slice(&rows);
        }
    }

    fn as_any_mut(&mut self) -> &mut dyn Any {
        self
    }
}
