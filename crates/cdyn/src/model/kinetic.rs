//! Kinetic energy as small local elements, for coordinates whose inertia
//! depends on the configuration (angles, relative coordinates).
//!
//! The user writes `T(x, ẋ)` of `K` coordinates once, generic over the
//! scalar, as for constraints and potentials. The library takes by dual
//! numbers what the equations of motion need of it:
//!
//! * the local mass matrix `M_e = ∂²T/∂ẋ²` (one hyper-dual pass per pair
//!   `i ≤ j`: `T` along `ẋ + ε₁eᵢ + ε₂eⱼ`, whose `ε₁ε₂` part is `M_ij`);
//! * `Ṁ_e ẋ`, whose entry `i` is `Σⱼ ∂²T/∂ẋᵢ∂xⱼ ẋⱼ` (one hyper-dual pass per
//!   coordinate: `T` at `(x + ε₂ẋ, ẋ + ε₁eᵢ)`);
//! * `∂T/∂x` (one dual pass per coordinate).
//!
//! Lagrange's equations `d/dt(∂T/∂ẋ) − ∂T/∂x = Q` are then
//! `M q̈ = Q + ∂T/∂q − Ṁ q̇`, so the velocity terms join the applied force
//! `G`. `T` must be quadratic in the velocities (a natural system, the case
//! of every mechanism without moving frames); then `∂T/∂ẋ = M ẋ` and
//! `T = ½ ẋᵀ M ẋ`, which the energy constraint relies on.

use crate::ad::scalar::Scalar;
use crate::model::constraint::seeded;
use num_dual::{Dual64, HyperDual64};
use std::any::Any;

/// Kinetic energy `T(x, ẋ)` of `K` coordinates, quadratic in `ẋ`.
pub trait Kinetic<const K: usize>: Send + Sync + 'static {
    /// `T(x, ẋ)`, for any scalar type (dual numbers give `M(x)` and its derivatives).
    fn energy<D: Scalar>(&self, x: [D; K], xd: [D; K]) -> D;
}

/// What one element contributes at a state.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Local<const K: usize> {
    /// `T`
    pub energy: f64,
    /// `M_e = ∂²T/∂ẋ²`
    pub mass: [[f64; K]; K],
    /// `∂T/∂x`
    pub grad_q: [f64; K],
    /// `Ṁ_e ẋ`
    pub mdot_v: [f64; K],
}

/// Differentiates one element at `(x, ẋ)`.
#[inline(always)]
pub fn local<T: Kinetic<K>, const K: usize>(t: &T, x: [f64; K], xd: [f64; K]) -> Local<K> {
    let hyper = |x0: &[f64; K], dx: &[f64; K], v0: &[f64; K], dv1: &[f64; K], dv2: &[f64; K]| -> HyperDual64 {
        let x = std::array::from_fn(|k| HyperDual64::new(x0[k], 0.0, dx[k], 0.0));
        let v = std::array::from_fn(|k| HyperDual64::new(v0[k], dv1[k], dv2[k], 0.0));
        t.energy(x, v)
    };
    let unit = |i: usize| -> [f64; K] { std::array::from_fn(|k| if k == i { 1.0 } else { 0.0 }) };
    let zero = [0.0; K];
    let mut mass = [[0.0; K]; K];
    for i in 0..K {
        for j in i..K {
            let m = hyper(&x, &zero, &xd, &unit(i), &unit(j)).eps1eps2;
            mass[i][j] = m;
            mass[j][i] = m;
        }
    }
    let mdot_v = std::array::from_fn(|i| hyper(&x, &xd, &xd, &unit(i), &zero).eps1eps2);
    let grad_q = std::array::from_fn(|j| t.energy(seeded(&x, j), xd.map(Into::into)).eps);
    // T = ½ ẋᵀ M ẋ for a T quadratic in ẋ; taken from T itself so that a
    // user's T that is not quadratic shows up as an energy error, not silently.
    let energy = t.energy(x, xd);
    Local { energy, mass, grad_q, mdot_v }
}

/// A kinetic energy `T = ½ wᵀ J w` of `V` velocities `w = B(x) ẋ`, linear
/// in `ẋ`, with a constant symmetric `J` — a rigid body's rotation in
/// Euler parameters (`w = (2 G(p) ṗ, pᵀṗ)`), any body whose velocities are
/// a linear map of the coordinates' rates. The user writes the map once,
/// generic over the scalar; being linear in `ẋ` lets the library take `M`,
/// `Ṁ ẋ` and `∂T/∂x` by `2K` dual passes of the map instead of
/// `K(K + 1)/2 + 2K` hyper-dual passes of `T` (see [`local_map`]).
pub trait VelocityMap<const K: usize, const V: usize>: Send + Sync + 'static {
    /// `w = B(x) ẋ`, linear in `ẋ`, for any scalar type.
    fn velocities<D: Scalar>(&self, x: [D; K], xd: [D; K]) -> [D; V];
    /// `J`, symmetric.
    fn inertia(&self) -> [[f64; V]; V];

    /// What the equations of motion need of the element at `(x, ẋ)`. The
    /// default takes it by dual passes of the map ([`local_map`]); an
    /// element that knows closed forms may return them instead (and test
    /// them against `local_map`).
    #[inline(always)]
    fn derivatives(&self, x: [f64; K], xd: [f64; K]) -> Local<K>
    where
        Self: Sized,
    {
        local_map(self, x, xd)
    }
}

/// Differentiates a [`VelocityMap`] element at `(x, ẋ)`:
///
/// * `B` and `Ḃ = dB/ds (x + s ẋ)` column by column: `w(x + s ẋ, e_j)` with
///   a dual `s` (K passes);
/// * `M = Bᵀ J B`, `Ṁ ẋ = Ḃᵀ J w + Bᵀ J Ḃ ẋ`, `T = ½ wᵀ J w`, `w = B ẋ`;
/// * `∂T/∂x_k = wᵀ J ∂w/∂x_k`, `∂w/∂x_k` from `w(x + ε e_k, ẋ)` (K passes).
pub fn local_map<T: VelocityMap<K, V>, const K: usize, const V: usize>(t: &T, x: [f64; K], xd: [f64; K]) -> Local<K> {
    let j = t.inertia();
    let unit = |i: usize| -> [Dual64; K] { std::array::from_fn(|k| Dual64::from(if k == i { 1.0 } else { 0.0 })) };
    let moving: [Dual64; K] = std::array::from_fn(|k| Dual64::new(x[k], xd[k]));
    // Columns of B and Ḃ.
    let (mut b, mut bdot) = ([[0.0; K]; V], [[0.0; K]; V]);
    for c in 0..K {
        let col = t.velocities(moving, unit(c));
        for r in 0..V {
            (b[r][c], bdot[r][c]) = (col[r].re, col[r].eps);
        }
    }
    let times =
        |m: &[[f64; K]; V], v: &[f64; K]| -> [f64; V] { std::array::from_fn(|r| (0..K).map(|c| m[r][c] * v[c]).sum()) };
    let jv = |v: &[f64; V]| -> [f64; V] { std::array::from_fn(|r| (0..V).map(|c| j[r][c] * v[c]).sum()) };
    let w = times(&b, &xd);
    let (jw, jbdot_xd) = (jv(&w), jv(&times(&bdot, &xd)));
    let jb: [[f64; K]; V] = std::array::from_fn(|r| std::array::from_fn(|c| (0..V).map(|m| j[r][m] * b[m][c]).sum()));
    let mass = std::array::from_fn(|a| std::array::from_fn(|c| (0..V).map(|r| b[r][a] * jb[r][c]).sum()));
    let mdot_v = std::array::from_fn(|a| (0..V).map(|r| bdot[r][a] * jw[r] + b[r][a] * jbdot_xd[r]).sum());
    let xd_fixed = xd.map(Dual64::from);
    let grad_q = std::array::from_fn(|k| {
        let dw = t.velocities(seeded(&x, k), xd_fixed);
        (0..V).map(|r| jw[r] * dw[r].eps).sum()
    });
    let energy = 0.5 * (0..V).map(|r| w[r] * jw[r]).sum::<f64>();
    Local { energy, mass, grad_q, mdot_v }
}

/// What the model needs of a kinetic element, whichever way it is
/// differentiated: by hyper-dual passes of `T` (every [`Kinetic`]) or by dual
/// passes of its velocity map ([`ByMap`]).
pub(crate) trait KineticElement<const K: usize>: Send + Sync + 'static {
    fn local(&self, x: [f64; K], xd: [f64; K]) -> Local<K>;
    /// `T`, and `∂T/∂x` when asked.
    fn energy(&self, x: [f64; K], xd: [f64; K], grad: Option<&mut [f64; K]>) -> f64;
}

/// Every [`Kinetic`] element, differentiated by hyper-dual passes of `T`.
impl<T: Kinetic<K>, const K: usize> KineticElement<K> for T {
    #[inline(always)]
    fn local(&self, x: [f64; K], xd: [f64; K]) -> Local<K> {
        local(self, x, xd)
    }
    fn energy(&self, x: [f64; K], xd: [f64; K], grad: Option<&mut [f64; K]>) -> f64 {
        if let Some(g) = grad {
            *g = std::array::from_fn(|j| Kinetic::energy(self, seeded(&x, j), xd.map(Into::into)).eps);
        }
        Kinetic::energy(self, x, xd)
    }
}

/// A [`VelocityMap`] element.
pub(crate) struct ByMap<T, const V: usize>(pub T);

impl<T: VelocityMap<K, V>, const K: usize, const V: usize> KineticElement<K> for ByMap<T, V> {
    #[inline(always)]
    fn local(&self, x: [f64; K], xd: [f64; K]) -> Local<K> {
        self.0.derivatives(x, xd)
    }
    fn energy(&self, x: [f64; K], xd: [f64; K], grad: Option<&mut [f64; K]>) -> f64 {
        let l = self.0.derivatives(x, xd);
        if let Some(g) = grad {
            *g = l.grad_q;
        }
        l.energy
    }
}

/// A run of kinetic-energy elements of one type (object-safe face).
pub(crate) trait KineticBlock: Send + Sync {
    /// Adds `M(q)` into the row-major `n × n` matrix `mass`, `∂T/∂q` into
    /// `grad_q` and `Ṁ q̇` into `mdot_v`; returns `T`.
    fn add_all(&self, q: &[f64], v: &[f64], mass: &mut [f64], grad_q: &mut [f64], mdot_v: &mut [f64]) -> f64;
    /// As [`add_all`](Self::add_all), but each element's `M_e` is written
    /// (not added) to its own `K × K` block of `blocks`, one after another:
    /// the layout of a [`BlockMass`](crate::linalg::mass::BlockMass).
    fn add_blocks(&self, q: &[f64], v: &[f64], blocks: &mut [f64], grad_q: &mut [f64], mdot_v: &mut [f64]) -> f64;
    /// Number of elements.
    fn items(&self) -> usize;
    /// Coordinates each element reads (`K`).
    fn width(&self) -> usize;
    /// The coordinates each element reads, element after element (`K` each).
    fn coordinates(&self) -> Vec<Vec<u32>>;
    /// `T`, adding `∂T/∂q` into `grad_q` when given.
    fn energy(&self, q: &[f64], v: &[f64], grad_q: Option<&mut [f64]>) -> f64;
    fn as_any_mut(&mut self) -> &mut dyn Any;
}

pub(crate) struct KineticGroup<T, const K: usize> {
    pub items: Vec<(T, [usize; K])>,
}

impl<T: KineticElement<K>, const K: usize> KineticBlock for KineticGroup<T, K> {
    fn add_all(&self, q: &[f64], v: &[f64], mass: &mut [f64], grad_q: &mut [f64], mdot_v: &mut [f64]) -> f64 {
        let n = grad_q.len();
        let mut total = 0.0;
        for (t, idx) in &self.items {
            let l = t.local(idx.map(|i| q[i]), idx.map(|i| v[i]));
            total += l.energy;
            for a in 0..K {
                grad_q[idx[a]] += l.grad_q[a];
                mdot_v[idx[a]] += l.mdot_v[a];
                for b in 0..K {
                    mass[idx[a] * n + idx[b]] += l.mass[a][b];
                }
            }
        }
        total
    }

    fn add_blocks(&self, q: &[f64], v: &[f64], blocks: &mut [f64], grad_q: &mut [f64], mdot_v: &mut [f64]) -> f64 {
        let mut total = 0.0;
        for ((t, idx), block) in self.items.iter().zip(blocks.chunks_exact_mut(K * K)) {
            let l = t.local(idx.map(|i| q[i]), idx.map(|i| v[i]));
            total += l.energy;
            for a in 0..K {
                grad_q[idx[a]] += l.grad_q[a];
                mdot_v[idx[a]] += l.mdot_v[a];
                block[a * K..(a + 1) * K].copy_from_slice(&l.mass[a]);
            }
        }
        total
    }

    fn items(&self) -> usize {
        self.items.len()
    }

    fn width(&self) -> usize {
        K
    }

    fn coordinates(&self) -> Vec<Vec<u32>> {
        self.items.iter().map(|(_, idx)| idx.iter().map(|&i| i as u32).collect()).collect()
    }

    fn energy(&self, q: &[f64], v: &[f64], mut grad_q: Option<&mut [f64]>) -> f64 {
        let mut total = 0.0;
        for (t, idx) in &self.items {
            let (x, xd) = (idx.map(|i| q[i]), idx.map(|i| v[i]));
            match grad_q.as_deref_mut() {
                None => total += t.energy(x, xd, None),
                Some(g) => {
                    let mut local = [0.0; K];
                    total += t.energy(x, xd, Some(&mut local));
                    for j in 0..K {
                        g[idx[j]] += local[j];
                    }
                }
            }
        }
        total
    }

    fn as_any_mut(&mut self) -> &mut dyn Any {
        self
    }
}
