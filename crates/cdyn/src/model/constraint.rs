//! Holonomic constraints as small local elements.
//!
//! An element reads `K` coordinates and yields `R` constraint rows. The
//! library differentiates it with dual numbers: one first-order pass per
//! coordinate gives the local Jacobian block, and one second-order pass along
//! `(v, 1)` gives `Φ̇ = Φ_q v + Φ_t` and `γ` (Eq. 5). Blocks are stored by
//! element type so a chain of ten thousand rods is one monomorphized loop.

use crate::ad::jet::JetN;
use crate::ad::scalar::Scalar;
use num_dual::{Dual2_64, Dual64, HyperDual64};
use std::any::Any;

/// `R` holonomic constraints `Φ(x, t) = 0` on `K` coordinates `x`.
pub trait Constraint<const K: usize, const R: usize>: Send + Sync + 'static {
    /// The constraint values; written once for every scalar type.
    fn eval<D: Scalar>(&self, x: [D; K], t: D) -> [D; R];

    /// `∂Φ_r/∂x_j` at `(x, t)`, row by row. The default differentiates
    /// [`eval`](Self::eval) ([`jacobian_of`]); an element whose parts each
    /// read a few of its coordinates (a spatial joint's two bodies) may
    /// compose narrower dual passes of its own.
    #[inline(always)]
    fn jacobian(&self, x: [f64; K], t: f64) -> [[f64; K]; R]
    where
        Self: Sized,
    {
        jacobian_of(self, x, t)
    }

    /// Along the path `(x + s v, t + s)`: each row's `[Φ, Φ̇, Φ̈]` at
    /// `s = 0` (`Φ̈` at zero acceleration, which is `−γ`), and the Jacobian
    /// at `(x, t)`. The default differentiates [`eval`](Self::eval) on
    /// second-order dual numbers ([`second_order_of`]) and takes
    /// [`jacobian`](Self::jacobian); an element whose parts both need (a
    /// spatial joint's rotated points and axes) may form them once.
    #[inline(always)]
    fn second_order(&self, x: [f64; K], v: [f64; K], t: f64) -> ([[f64; 3]; R], [[f64; K]; R])
    where
        Self: Sized,
    {
        (second_order_of(self, x, v, t), self.jacobian(x, t))
    }

    /// `Σ_r w_r ∇²Φ_r` at `(x, t)`, `K × K` and symmetric: the derivative
    /// of `Φ_xᵀ w` in `x`, which an implicit step's Newton matrix needs.
    /// The default takes one hyper-dual pass of [`eval`](Self::eval) per
    /// pair of coordinates ([`curvature_of`]); an element that knows its
    /// second derivatives (a spatial joint: `A(p)s` is quadratic in `p`)
    /// may compose them instead.
    #[inline(always)]
    fn curvature(&self, x: [f64; K], t: f64, w: &[f64; R]) -> [[f64; K]; K]
    where
        Self: Sized,
    {
        curvature_of(self, x, t, w)
    }

    /// Which coordinates each row can depend on: an entry `false` here must
    /// be zero at every state, and its products are left out when
    /// `Φ_q M⁻¹ Φ_qᵀ` is assembled (a spherical joint's row reads one
    /// component of each centre of mass, not three). All `true` by default.
    fn reads(&self) -> [[bool; K]; R] {
        [[true; K]; R]
    }
}

/// Where one evaluation of the constraints goes: per row `Φ`, `Φ̇`, `Φ_t`,
/// `γ`, the Jacobian entries of each row in the order of its coordinates,
/// and the right-hand side of Eq. 7, `Φ_q a − γ`, for the given
/// unconstrained acceleration `a = M⁻¹ G` (formed here while the row's
/// derivatives are in registers, saving a pass over the Jacobian).
pub(crate) struct ConstraintValues<'a> {
    pub free_acc: &'a [f64],
    pub rhs: &'a mut [f64],
    pub phi: &'a mut [f64],
    pub phi_dot: &'a mut [f64],
    pub phi_t: &'a mut [f64],
    pub gamma: &'a mut [f64],
    pub jac: &'a mut [f64],
}

/// The outputs of constraint passes that a workspace keeps: `Φ`, `Φ̇`,
/// `Φ_t`, `γ` and the Jacobian values (in [`Pattern`](crate::linalg::sparse::Pattern) order).
#[derive(Clone)]
pub(crate) struct ConstraintBuffers {
    pub phi: Vec<f64>,
    pub phi_dot: Vec<f64>,
    pub phi_t: Vec<f64>,
    pub gamma: Vec<f64>,
    pub jac: Vec<f64>,
}

impl ConstraintBuffers {
    /// Buffers for `m` rows and `nnz` Jacobian entries.
    pub fn new(m: usize, nnz: usize) -> Self {
        Self { phi: vec![0.0; m], phi_dot: vec![0.0; m], phi_t: vec![0.0; m], gamma: vec![0.0; m], jac: vec![0.0; nnz] }
    }

    /// Where a pass writes, for the unconstrained acceleration `free_acc`,
    /// with `Φ_q a − γ` going to `rhs`.
    pub fn pass<'a>(&'a mut self, free_acc: &'a [f64], rhs: &'a mut [f64]) -> ConstraintValues<'a> {
        ConstraintValues {
            free_acc,
            rhs,
            phi: &mut self.phi,
            phi_dot: &mut self.phi_dot,
            phi_t: &mut self.phi_t,
            gamma: &mut self.gamma,
            jac: &mut self.jac,
        }
    }
}

/// A run of constraint elements of one type (object-safe face).
pub(crate) trait ConstraintBlock: Send + Sync {
    fn rows(&self) -> usize;
    /// Coordinates read by each row (the same `K` for every row of the block).
    fn width(&self) -> usize;
    /// Appends the coordinate index of every Jacobian entry, row by row
    /// (the model checks they fit in `u32`).
    fn columns(&self, out: &mut Vec<u32>);
    /// Appends, entry by entry as [`columns`](Self::columns), whether it
    /// can be non-zero (see [`Constraint::reads`]).
    fn reads(&self, out: &mut Vec<bool>) {
        out.extend(std::iter::repeat_n(true, self.rows() * self.width()));
    }
    fn evaluate(&self, q: &[f64], v: &[f64], t: f64, out: ConstraintValues<'_>);
    /// `Φ` only, in plain `f64`.
    fn values(&self, q: &[f64], t: f64, phi: &mut [f64]);
    /// Whether its rows are position-level constraints `Φ(q, t)` (not velocity-level only).
    fn holonomic(&self) -> bool {
        true
    }
    /// The `(row, column)` of each entry of [`curvatures`](Self::curvatures),
    /// element after element (none for velocity-level rows).
    fn curvature_entries(&self, _out: &mut Vec<(u32, u32)>) {}
    /// Writes `scale · Σ_r λ_r ∇²Φ_r` of each element (`K × K`, row-major;
    /// `lambda` the block's rows) into `out` — the derivative of `Φ_qᵀ λ`
    /// in `q` — and returns the entries written.
    fn curvatures(&self, _q: &[f64], _t: f64, _lambda: &[f64], _scale: f64, _out: &mut [f64]) -> usize {
        0
    }
    fn as_any_mut(&mut self) -> &mut dyn Any;
}

/// The methods of [`ConstraintBlock`] that every group of `R`-row
/// elements on `K` coordinates (`items`) has alike, holonomic or not; the
/// caller's `local` differentiates one element.
macro_rules! group_layout {
    () => {
        fn rows(&self) -> usize {
            self.items.len() * R
        }

        fn width(&self) -> usize {
            K
        }

        fn columns(&self, out: &mut Vec<u32>) {
            columns_of::<_, K, R>(&self.items, out);
        }

        fn evaluate(&self, q: &[f64], v: &[f64], t: f64, out: ConstraintValues<'_>) {
            evaluate_items(&self.items, q, v, t, out, local);
        }

        fn as_any_mut(&mut self) -> &mut dyn Any {
            self
        }
    };
}
pub(crate) use group_layout;

pub(crate) struct ConstraintGroup<C, const K: usize, const R: usize> {
    pub items: Vec<(C, [usize; K])>,
}

impl<C: Constraint<K, R>, const K: usize, const R: usize> ConstraintBlock for ConstraintGroup<C, K, R> {
    group_layout!();

    fn reads(&self, out: &mut Vec<bool>) {
        for (c, _) in &self.items {
            out.extend(c.reads().as_flattened());
        }
    }

    fn values(&self, q: &[f64], t: f64, phi: &mut [f64]) {
        for (e, (c, idx)) in self.items.iter().enumerate() {
            let rows = c.eval(std::array::from_fn(|j| q[idx[j]]), t);
            phi[e * R..(e + 1) * R].copy_from_slice(&rows);
        }
    }

    fn curvature_entries(&self, out: &mut Vec<(u32, u32)>) {
        block_entries(&self.items, out);
    }

    fn curvatures(&self, q: &[f64], t: f64, lambda: &[f64], scale: f64, out: &mut [f64]) -> usize {
        for ((c, idx), (weights, block)) in
            self.items.iter().zip(lambda.chunks_exact(R).zip(out.chunks_exact_mut(K * K)))
        {
            let x: [f64; K] = std::array::from_fn(|j| q[idx[j]]);
            let h = c.curvature(x, t, weights.try_into().expect("R multipliers an element"));
            block.iter_mut().zip(h.as_flattened()).for_each(|(b, h)| *b = scale * h);
        }
        self.items.len() * K * K
    }
}

/// The `(row, column)` of every entry of each element's `K × K` block, row-major.
pub(crate) fn block_entries<T, const K: usize>(items: &[(T, [usize; K])], out: &mut Vec<(u32, u32)>) {
    for (_, idx) in items {
        for i in idx {
            out.extend(idx.iter().map(|j| (*i as u32, *j as u32)));
        }
    }
}

/// Appends the coordinate index of every Jacobian entry of `items`, `R`
/// rows per element (any kind of element: holonomic or nonholonomic).
pub(crate) fn columns_of<C, const K: usize, const R: usize>(items: &[(C, [usize; K])], out: &mut Vec<u32>) {
    for (_, idx) in items {
        for _ in 0..R {
            out.extend(idx.iter().map(|&i| i as u32));
        }
    }
}

/// Writes every element's rows, as `local` differentiates them, into `out`.
#[inline(always)]
pub(crate) fn evaluate_items<C, const K: usize, const R: usize>(
    items: &[(C, [usize; K])],
    q: &[f64],
    v: &[f64],
    t: f64,
    out: ConstraintValues<'_>,
    local: impl Fn(&C, [f64; K], [f64; K], [f64; K], f64) -> Local<K, R>,
) {
    // Per element: its rows of every output, as fixed-size chunks (no
    // bounds checks inside the loop).
    let rows = out
        .rhs
        .chunks_exact_mut(R)
        .zip(out.phi.chunks_exact_mut(R))
        .zip(out.phi_dot.chunks_exact_mut(R))
        .zip(out.phi_t.chunks_exact_mut(R))
        .zip(out.gamma.chunks_exact_mut(R))
        .zip(out.jac.chunks_exact_mut(R * K));
    for ((c, idx), (((((rhs, phi), phi_dot), phi_t), gamma), jac)) in items.iter().zip(rows) {
        let gather = |s: &[f64]| std::array::from_fn(|j| s[idx[j]]);
        let l = local(c, gather(q), gather(v), gather(out.free_acc), t);
        rhs.copy_from_slice(&l.rhs);
        phi.copy_from_slice(&l.phi);
        phi_dot.copy_from_slice(&l.phi_dot);
        phi_t.copy_from_slice(&l.phi_t);
        gamma.copy_from_slice(&l.gamma);
        jac.copy_from_slice(l.jac.as_flattened());
    }
}

/// One element's rows at a state: what [`ConstraintValues`] holds, locally.
pub(crate) struct Local<const K: usize, const R: usize> {
    pub phi: [f64; R],
    pub phi_dot: [f64; R],
    pub phi_t: [f64; R],
    pub gamma: [f64; R],
    /// `Φ_q a − γ`
    pub rhs: [f64; R],
    /// `∂Φ_r/∂x_j`, row by row.
    pub jac: [[f64; K]; R],
}

/// Elements reading more coordinates than this take their Jacobian from one
/// [`JetN`] pass, fewer from one scalar dual pass per coordinate.
pub(crate) const JET_FROM: usize = 5;

/// Differentiates one element at positions `x`, velocities `v`, free
/// accelerations `a` and time `t`.
#[inline(always)]
pub(crate) fn local<C: Constraint<K, R>, const K: usize, const R: usize>(
    c: &C,
    x: [f64; K],
    v: [f64; K],
    a: [f64; K],
    t: f64,
) -> Local<K, R> {
    let (along, jac) = c.second_order(x, v, t);
    let dot = |row: &[f64; K], y: &[f64; K]| row.iter().zip(y).map(|(a, b)| a * b).sum::<f64>();
    let jv: [f64; R] = std::array::from_fn(|r| dot(&jac[r], &v));
    let ja: [f64; R] = std::array::from_fn(|r| dot(&jac[r], &a));
    Local {
        phi: along.map(|[phi, ..]| phi),
        phi_dot: along.map(|[_, rate, _]| rate),
        phi_t: std::array::from_fn(|r| along[r][1] - jv[r]),
        gamma: along.map(|[.., curvature]| -curvature),
        rhs: std::array::from_fn(|r| ja[r] + along[r][2]),
        jac,
    }
}

/// Each row's `[Φ, Φ̇, Φ̈]` along `(x + s v, t + s)` at `s = 0`, `Φ̈` at zero
/// acceleration: the second directional derivative, by one pass of
/// [`eval`](Constraint::eval) on second-order dual numbers.
#[inline(always)]
pub fn second_order_of<C: Constraint<K, R>, const K: usize, const R: usize>(
    c: &C,
    x: [f64; K],
    v: [f64; K],
    t: f64,
) -> [[f64; 3]; R] {
    let path: [Dual2_64; K] = std::array::from_fn(|j| Dual2_64::new(x[j], v[j], 0.0));
    c.eval(path, Dual2_64::new(t, 1.0, 0.0)).map(|d| [d.re, d.v1, d.v2])
}

/// `Φ_x` by dual passes of `c.eval`. For an element of a few coordinates,
/// one scalar dual pass per coordinate is cheapest (planar chain, K = 4:
/// num-dual's vector dual was ten times dearer); over more than
/// `JET_FROM`, one pass of a `JetN`, whose derivative is a plain array
/// (100-body spatial chain, before its joints composed their own: 1.98 M
/// instructions per step with scalar passes, 1.73 M with num-dual's vector
/// dual, 1.62 M with the jet). A planar joint between two bodies (K = 6)
/// takes the jet: each scalar pass took the sine and cosine of both
/// angles again (the slider-crank's AB-3 step 14.6 k → 11.6 k
/// instructions, the four-bar's 14.9 k → 11.5 k).
#[inline(always)]
pub fn jacobian_of<C: Constraint<K, R>, const K: usize, const R: usize>(c: &C, x: [f64; K], t: f64) -> [[f64; K]; R] {
    let mut jac = [[0.0; K]; R];
    if K > JET_FROM {
        let rows = c.eval(seeded_jets(&x), JetN::from_re(t));
        for r in 0..R {
            jac[r].copy_from_slice(rows[r].eps.0.as_slice());
        }
    } else {
        for j in 0..K {
            let rows = c.eval(seeded(&x, j), Dual64::from(t));
            for r in 0..R {
                jac[r][j] = rows[r].eps;
            }
        }
    }
    jac
}

/// `Σ_r w_r ∇²Φ_r` by hyper-dual passes of `c.eval`, one per pair of the
/// coordinates some row [`reads`](Constraint::reads) (an element that
/// reads 8 of its 14 coordinates: 36 pairs, not 105).
pub fn curvature_of<C: Constraint<K, R>, const K: usize, const R: usize>(
    c: &C,
    x: [f64; K],
    t: f64,
    w: &[f64; R],
) -> [[f64; K]; K] {
    let rows = c.reads();
    let read = std::array::from_fn(|j| rows.iter().any(|row| row[j]));
    second_derivatives_of(&x, &read, |y| c.eval(y, t.into()).iter().zip(w).map(|(r, w)| r.eps1eps2 * w).sum())
}

/// The second derivatives of a scalar function at `x`: `f` along
/// `x + ε₁eᵢ + ε₂eⱼ`, whose `ε₁ε₂` part `f` returns, one pass per pair `i ≤ j`.
#[inline(always)]
pub(crate) fn second_derivatives<const K: usize>(x: &[f64; K], f: impl Fn([HyperDual64; K]) -> f64) -> [[f64; K]; K] {
    second_derivatives_of(x, &[true; K], f)
}

/// As [`second_derivatives`], where `f` depends on the coordinates marked
/// in `read` only (the others' rows and columns are zero).
#[inline(always)]
fn second_derivatives_of<const K: usize>(
    x: &[f64; K],
    read: &[bool; K],
    f: impl Fn([HyperDual64; K]) -> f64,
) -> [[f64; K]; K] {
    let unit = |k: usize, i: usize| if k == i { 1.0 } else { 0.0 };
    let mut h = [[0.0; K]; K];
    for i in (0..K).filter(|&i| read[i]) {
        for j in (i..K).filter(|&j| read[j]) {
            h[i][j] = f(std::array::from_fn(|k| HyperDual64::new(x[k], unit(k, i), unit(k, j), 0.0)));
            h[j][i] = h[i][j];
        }
    }
    h
}

/// `x` as dual numbers with unit derivative in coordinate `j`.
#[inline(always)]
pub(crate) fn seeded<const K: usize>(x: &[f64; K], j: usize) -> [Dual64; K] {
    std::array::from_fn(|i| Dual64::new(x[i], if i == j { 1.0 } else { 0.0 }))
}

/// `x` as jets, coordinate `j` with unit derivative in direction `j`: the
/// one pass that gives every first derivative.
#[inline(always)]
pub(crate) fn seeded_jets<const K: usize>(x: &[f64; K]) -> [JetN<K>; K] {
    std::array::from_fn(|j| JetN::seeded(x[j], j))
}
