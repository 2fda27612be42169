//! The mass matrix `M`: every product with `M` or `M⁻¹` the library forms
//! goes through here, so that the rest of the crate never assumes its shape.
//!
//! In redundant (Cartesian) coordinates every body's mass matrix is constant
//! and diagonal — `(m, m, I)` for a planar body, `m` per axis for a point
//! mass — which is what makes the formulation cheap: `M⁻¹` is free and
//! `S = Φ_q M⁻¹ Φ_qᵀ` inherits the sparsity of the constraints. That is the
//! common kind ([`DiagonalMass`]). Coordinates such as angles have a
//! configuration-dependent `M(q)` ([`crate::model::kinetic`]): it is evaluated at
//! every state into a [`DenseMass`] and factored once per evaluation.
//! [`MassAt`] is either, as the control laws and the energy see it: they
//! ask it, not the diagonal, for what they need.
//!
//! The diagonal kind is generic over its storage: a `Vec` for a general
//! model, an array for a small system, whose loops then keep their
//! compile-time lengths.

use crate::error::{Result, positive};

/// What the dynamics, the energy and the control laws need of a mass matrix.
///
/// The vectors have one entry per coordinate. `Ψ_v` is the velocity gradient
/// of the energy constraint, `Ψ_v = ∂T/∂v = (M v)ᵀ` (Eq. 14 ff.).
pub trait MassMatrix {
    /// Number of coordinates `n`.
    fn n(&self) -> usize;
    /// `out = M x`.
    fn mul(&self, x: &[f64], out: &mut [f64]);
    /// `out = M⁻¹ x`.
    fn solve(&self, x: &[f64], out: &mut [f64]);
    /// The kinetic energy `½ vᵀ M v`.
    fn kinetic(&self, v: &[f64]) -> f64;
    /// `|Ψ_v|² = |M v|²`, which sets the gain of the gradient energy control (Eq. 27).
    fn psi_v_norm2(&self, v: &[f64]) -> f64;
    /// `Ψ_v x = (M v) · x`, summed in coordinate order after `init`, with
    /// `extra(i)` added to the `i`-th term before it joins the sum (the
    /// Baumgarte-type energy control sums `Ψ_v A + Ψ_q v` in one pass).
    fn psi_v_dot(&self, v: &[f64], x: impl Fn(usize) -> f64, extra: impl Fn(usize) -> f64, init: f64) -> f64;
    /// `out += scale · Ψ_vᵀ = scale · M v`.
    fn add_psi_v(&self, v: &[f64], scale: f64, out: &mut [f64]);
    /// `out += scale · M⁻¹ Ψ_vᵀ`. Since `Ψ_vᵀ = M v`, this is `scale · v`
    /// for every kind of `M`, formed without the round trip through `M`.
    fn add_inverse_psi_v(&self, v: &[f64], scale: f64, out: &mut [f64]);
}

/// A constant diagonal mass matrix, kept with its inverse, over storage `S`
/// (`Vec<f64>` or `[f64; N]`).
#[derive(Debug, Clone, PartialEq)]
pub struct DiagonalMass<S = Vec<f64>> {
    diagonal: S,
    inverse: S,
}

impl<S: AsRef<[f64]> + AsMut<[f64]> + Clone> DiagonalMass<S> {
    /// The mass matrix with this diagonal; every entry must be finite and positive.
    pub fn new(diagonal: S) -> Result<Self> {
        for &m in diagonal.as_ref() {
            positive("mass", m)?;
        }
        let mut inverse = diagonal.clone();
        for w in inverse.as_mut() {
            *w = 1.0 / *w;
        }
        Ok(Self { diagonal, inverse })
    }
}

impl<S: AsRef<[f64]>> DiagonalMass<S> {
    /// The diagonal of `M`.
    #[inline(always)]
    pub fn diagonal(&self) -> &S {
        &self.diagonal
    }

    /// The diagonal of `M⁻¹`: the weights `1/m_c` of the products
    /// `J_a J_b / m_c` that sum to the entries of `S = Φ_q M⁻¹ Φ_qᵀ`.
    #[inline(always)]
    pub fn inverse(&self) -> &S {
        &self.inverse
    }
}

// The arithmetic below is written term for term as it was before the mass
// matrix had a type (`(s · m) · v`, not `s · (m · v)`), so results stay
// bit-identical; change an association only on purpose.
impl<S: AsRef<[f64]>> MassMatrix for DiagonalMass<S> {
    #[inline(always)]
    fn n(&self) -> usize {
        self.diagonal.as_ref().len()
    }

    #[inline(always)]
    fn mul(&self, x: &[f64], out: &mut [f64]) {
        for ((o, m), x) in out.iter_mut().zip(self.diagonal.as_ref()).zip(x) {
            *o = m * x;
        }
    }

    #[inline(always)]
    fn solve(&self, x: &[f64], out: &mut [f64]) {
        for ((o, w), x) in out.iter_mut().zip(self.inverse.as_ref()).zip(x) {
            *o = x * w;
        }
    }

    #[inline(always)]
    fn kinetic(&self, v: &[f64]) -> f64 {
        0.5 * self.diagonal.as_ref().iter().zip(v).map(|(m, v)| m * v * v).sum::<f64>()
    }

    #[inline(always)]
    fn psi_v_norm2(&self, v: &[f64]) -> f64 {
        self.diagonal.as_ref().iter().zip(v).map(|(m, v)| (m * v) * (m * v)).sum()
    }

    #[inline(always)]
    fn psi_v_dot(&self, v: &[f64], x: impl Fn(usize) -> f64, extra: impl Fn(usize) -> f64, init: f64) -> f64 {
        let mut sum = init;
        for (i, (m, v)) in self.diagonal.as_ref().iter().zip(v).enumerate() {
            sum += m * v * x(i) + extra(i);
        }
        sum
    }

    #[inline(always)]
    fn add_psi_v(&self, v: &[f64], scale: f64, out: &mut [f64]) {
        for ((o, m), v) in out.iter_mut().zip(self.diagonal.as_ref()).zip(v) {
            *o += scale * m * v;
        }
    }

    #[inline(always)]
    fn add_inverse_psi_v(&self, v: &[f64], scale: f64, out: &mut [f64]) {
        for (o, v) in out.iter_mut().zip(v) {
            *o += scale * v;
        }
    }
}

/// A symmetric positive definite `M`, evaluated at one state and kept
/// with its Cholesky factor `M = L Lᵀ`; storage allocated once.
#[derive(Debug, Clone, PartialEq)]
pub struct DenseMass {
    n: usize,
    /// `M`, row-major.
    matrix: Vec<f64>,
    /// `L`, row-major lower triangle.
    factor: Vec<f64>,
}

impl DenseMass {
    /// Storage for an `n × n` matrix, zero.
    pub fn new(n: usize) -> Self {
        Self { n, matrix: vec![0.0; n * n], factor: vec![0.0; n * n] }
    }

    /// `M`, row-major, to be filled before [`factor`](Self::factor).
    pub fn matrix_mut(&mut self) -> &mut [f64] {
        &mut self.matrix
    }

    /// `M`, row-major.
    pub fn matrix(&self) -> &[f64] {
        &self.matrix
    }

    /// Factors `M = L Lᵀ`. `Err(k)` names the first coordinate whose pivot
    /// is not positive (or not finite): `M` is not positive definite there.
    pub fn factor(&mut self) -> std::result::Result<(), usize> {
        let n = self.n;
        let (a, l) = (&self.matrix, &mut self.factor);
        for j in 0..n {
            let mut d = a[j * n + j];
            for k in 0..j {
                d -= l[j * n + k] * l[j * n + k];
            }
            // Relative to the diagonal entry: a pivot lost to round-off is singular.
            if d.is_nan() || d <= 1e-14 * a[j * n + j].abs() || !d.is_finite() {
                return Err(j);
            }
            let d = d.sqrt();
            l[j * n + j] = d;
            for i in j + 1..n {
                let mut s = a[i * n + j];
                for k in 0..j {
                    s -= l[i * n + k] * l[j * n + k];
                }
                l[i * n + j] = s / d;
            }
        }
        Ok(())
    }

    /// `(M v)_i`
    #[inline(always)]
    fn row_dot(&self, i: usize, v: &[f64]) -> f64 {
        self.matrix[i * self.n..(i + 1) * self.n].iter().zip(v).map(|(m, v)| m * v).sum()
    }
}

impl MassMatrix for DenseMass {
    fn n(&self) -> usize {
        self.n
    }

    fn mul(&self, x: &[f64], out: &mut [f64]) {
        for (i, o) in out.iter_mut().enumerate() {
            *o = self.row_dot(i, x);
        }
    }

    /// With the factor of the last [`factor`](DenseMass::factor): `L y = x`, then `Lᵀ out = y`, in `out`.
    fn solve(&self, x: &[f64], out: &mut [f64]) {
        let (n, l) = (self.n, &self.factor);
        for i in 0..n {
            let s: f64 = (0..i).map(|k| l[i * n + k] * out[k]).sum();
            out[i] = (x[i] - s) / l[i * n + i];
        }
        for i in (0..n).rev() {
            let s: f64 = (i + 1..n).map(|k| l[k * n + i] * out[k]).sum();
            out[i] = (out[i] - s) / l[i * n + i];
        }
    }

    fn kinetic(&self, v: &[f64]) -> f64 {
        0.5 * (0..self.n).map(|i| v[i] * self.row_dot(i, v)).sum::<f64>()
    }

    fn psi_v_norm2(&self, v: &[f64]) -> f64 {
        (0..self.n).map(|i| self.row_dot(i, v).powi(2)).sum()
    }

    fn psi_v_dot(&self, v: &[f64], x: impl Fn(usize) -> f64, extra: impl Fn(usize) -> f64, init: f64) -> f64 {
        let mut sum = init;
        for i in 0..self.n {
            sum += self.row_dot(i, v) * x(i) + extra(i);
        }
        sum
    }

    fn add_psi_v(&self, v: &[f64], scale: f64, out: &mut [f64]) {
        for (i, o) in out.iter_mut().enumerate() {
            *o += scale * self.row_dot(i, v);
        }
    }

    fn add_inverse_psi_v(&self, v: &[f64], scale: f64, out: &mut [f64]) {
        for (o, v) in out.iter_mut().zip(v) {
            *o += scale * v;
        }
    }
}

/// The largest kinetic element a [`BlockMass`] keeps as a block; a model
/// with a wider one is factored densely.
pub const MAX_BLOCK: usize = 8;

/// Runs `$body` with the const `$k` equal to the block width `$n` (1 to
/// [`MAX_BLOCK`]).
macro_rules! by_width {
    ($n:expr, $k:ident, $body:expr) => {
        crate::with_const!($n, $k, [1, 2, 3, 4, 5, 6, 7, 8], $body)
    };
}
const _: () = assert!(MAX_BLOCK == 8, "by_width! lists the widths up to MAX_BLOCK");

/// A block-diagonal `M(q)`: a constant diagonal on most coordinates, and
/// small dense blocks, each the mass of one kinetic element, on disjoint
/// sets of coordinates (the Euler parameters of a spatial body, a 4 × 4
/// block `4 Gᵀ J′ G + k p pᵀ`). Each block is factored on its own, so the
/// cost is linear in the number of bodies where a dense `M(q)` is cubic.
#[derive(Debug, Clone, PartialEq)]
pub struct BlockMass {
    /// `M_cc` of the coordinates outside every block (0 inside one).
    diagonal: Vec<f64>,
    /// `1 / M_cc` outside the blocks (0 inside one).
    inverse: Vec<f64>,
    /// Block `b`'s coordinates are `coords[start[b]..start[b + 1]]`.
    start: Vec<u32>,
    coords: Vec<u32>,
    /// Block `b`'s `k × k` matrix, row-major, from `values_start(b)`.
    matrix: Vec<f64>,
    /// The inverse `L⁻¹` of its Cholesky factor, row-major lower triangle:
    /// products with `L⁻¹` and `L⁻ᵀ` are independent sums, where
    /// substitution chains a division per coordinate (spatial chain: the
    /// divisions' latency was most of the per-row block products).
    factor: Vec<f64>,
    /// Where each block's matrix starts in `matrix` and `factor`.
    at: Vec<u32>,
}

impl BlockMass {
    /// `diagonal` on the coordinates outside `blocks` (each a list of
    /// coordinates, pairwise disjoint, at most [`MAX_BLOCK`] long).
    pub(crate) fn new(diagonal: &[f64], blocks: &[Vec<u32>]) -> Self {
        let mut start = vec![0u32];
        let mut coords = Vec::new();
        let mut at = vec![0u32];
        let mut inside = vec![false; diagonal.len()];
        for b in blocks {
            debug_assert!(b.len() <= MAX_BLOCK);
            coords.extend_from_slice(b);
            start.push(coords.len() as u32);
            at.push(at.last().unwrap() + (b.len() * b.len()) as u32);
            b.iter().for_each(|&c| inside[c as usize] = true);
        }
        let plain = |c: usize, x: f64| if inside[c] { 0.0 } else { x };
        let len = *at.last().unwrap() as usize;
        Self {
            diagonal: diagonal.iter().enumerate().map(|(c, &m)| plain(c, m)).collect(),
            inverse: diagonal.iter().enumerate().map(|(c, &m)| plain(c, 1.0 / m)).collect(),
            start,
            coords,
            matrix: vec![0.0; len],
            factor: vec![0.0; len],
            at,
        }
    }

    /// Number of blocks.
    pub fn blocks(&self) -> usize {
        self.start.len() - 1
    }

    /// Block `b`'s coordinates.
    #[inline(always)]
    pub fn coordinates(&self, b: usize) -> &[u32] {
        &self.coords[self.start[b] as usize..self.start[b + 1] as usize]
    }

    /// The diagonal of `M⁻¹` outside the blocks (0 on block coordinates).
    #[inline(always)]
    pub fn inverse(&self) -> &[f64] {
        &self.inverse
    }

    /// All blocks' matrices, one after another (each `k × k`, row-major),
    /// to be filled before [`factor`](Self::factor).
    pub(crate) fn matrices_mut(&mut self) -> &mut [f64] {
        &mut self.matrix
    }

    /// Adds `x` to entry `(i, i)` of block `b`'s matrix.
    pub(crate) fn add_to_diagonal(&mut self, b: usize, i: usize, x: f64) {
        let k = self.coordinates(b).len();
        self.matrix[self.at[b] as usize + i * k + i] += x;
    }

    /// Block `b`'s coordinates and matrix, at its width `K`.
    #[inline(always)]
    fn block<const K: usize>(&self, b: usize) -> (&[u32; K], &[f64]) {
        let at = self.at[b] as usize;
        (self.coordinates(b).try_into().expect("block of width K"), &self.matrix[at..at + K * K])
    }

    /// Factors every block, `M_b = L_b L_bᵀ`, and keeps `L_b⁻¹`. `Err(c)`
    /// names the first coordinate whose pivot is not positive (or not finite).
    pub fn factor(&mut self) -> std::result::Result<(), usize> {
        for b in 0..self.blocks() {
            let at = self.at[b] as usize;
            let k = self.coordinates(b).len();
            let (a, l) = (&self.matrix[at..at + k * k], &mut self.factor[at..at + k * k]);
            by_width!(k, K, factor_block::<K>(a, l)).map_err(|j| self.coordinates(b)[j] as usize)?;
        }
        Ok(())
    }

    /// Calls `f` with the width `K` of block `b`: each width's loops are
    /// compiled apart and unrolled (a block's width is known only at run
    /// time; spatial bodies' are 4).
    #[inline(always)]
    pub(crate) fn at_width(&self, b: usize, f: impl WidthFn) {
        by_width!(self.coordinates(b).len(), K, f.call::<K>(self, b))
    }

    /// `L_b⁻¹ x`.
    #[inline(always)]
    pub(crate) fn forward<const K: usize>(&self, b: usize, x: [f64; K]) -> [f64; K] {
        let at = self.at[b] as usize;
        let inv = &self.factor[at..at + K * K];
        std::array::from_fn(|i| (0..=i).map(|c| inv[i * K + c] * x[c]).sum())
    }

    /// `L_b⁻ᵀ x`.
    #[inline(always)]
    pub(crate) fn backward<const K: usize>(&self, b: usize, x: [f64; K]) -> [f64; K] {
        let at = self.at[b] as usize;
        let inv = &self.factor[at..at + K * K];
        std::array::from_fn(|i| (i..K).map(|c| inv[c * K + i] * x[c]).sum())
    }

    /// Calls `f(c, (M x)_c)` once for every coordinate `c` (every
    /// coordinate outside the blocks has a positive mass: the model checks).
    #[inline(always)]
    fn each_product(&self, x: &[f64], mut f: impl FnMut(usize, f64)) {
        for (c, (m, x)) in self.diagonal.iter().zip(x).enumerate() {
            if *m != 0.0 {
                f(c, m * x);
            }
        }
        struct Product<'a, F>(&'a [f64], &'a mut F);
        impl<F: FnMut(usize, f64)> WidthFn for Product<'_, F> {
            #[inline(always)]
            fn call<const K: usize>(self, mass: &BlockMass, b: usize) {
                let (coords, a) = mass.block::<K>(b);
                let x: [f64; K] = coords.map(|c| self.0[c as usize]);
                for i in 0..K {
                    (self.1)(coords[i] as usize, (0..K).map(|j| a[i * K + j] * x[j]).sum());
                }
            }
        }
        for b in 0..self.blocks() {
            self.at_width(b, Product(x, &mut f));
        }
    }
}

/// An operation on one block of a [`BlockMass`], generic over its width.
pub(crate) trait WidthFn {
    fn call<const K: usize>(self, mass: &BlockMass, b: usize);
}

/// `A = L Lᵀ` for the `K × K` row-major `a`, with `L⁻¹` left in `l`;
/// `Err(j)` for the first pivot `j` that is not positive (or not finite).
#[inline(always)]
fn factor_block<const K: usize>(a: &[f64], l: &mut [f64]) -> std::result::Result<(), usize> {
    let (a, l) = (&a[..K * K], &mut l[..K * K]);
    for j in 0..K {
        let d = a[j * K + j] - (0..j).map(|i| l[j * K + i] * l[j * K + i]).sum::<f64>();
        // Relative to the diagonal entry, as for a dense `M`.
        if d.is_nan() || d <= 1e-14 * a[j * K + j].abs() || !d.is_finite() {
            return Err(j);
        }
        let d = d.sqrt();
        l[j * K + j] = d;
        for i in j + 1..K {
            let s = a[i * K + j] - (0..j).map(|c| l[i * K + c] * l[j * K + c]).sum::<f64>();
            l[i * K + j] = s / d;
        }
    }
    // L⁻¹ in place, row by row: row i of L⁻¹ from the rows above it,
    // left to right, each entry read from L just before it is replaced.
    for i in 0..K {
        let d = 1.0 / l[i * K + i];
        for j in 0..i {
            let s: f64 = (j..i).map(|m| l[i * K + m] * l[m * K + j]).sum();
            l[i * K + j] = -s * d;
        }
        l[i * K + i] = d;
    }
    Ok(())
}

impl MassMatrix for BlockMass {
    fn n(&self) -> usize {
        self.diagonal.len()
    }

    fn mul(&self, x: &[f64], out: &mut [f64]) {
        self.each_product(x, |c, y| out[c] = y);
    }

    fn solve(&self, x: &[f64], out: &mut [f64]) {
        for ((o, w), x) in out.iter_mut().zip(&self.inverse).zip(x) {
            *o = x * w;
        }
        struct Solve<'a>(&'a [f64], &'a mut [f64]);
        impl WidthFn for Solve<'_> {
            #[inline(always)]
            fn call<const K: usize>(self, mass: &BlockMass, b: usize) {
                let (coords, _) = mass.block::<K>(b);
                let y = mass.backward(b, mass.forward(b, coords.map(|c| self.0[c as usize])));
                coords.iter().zip(y).for_each(|(&c, y)| self.1[c as usize] = y);
            }
        }
        for b in 0..self.blocks() {
            self.at_width(b, Solve(x, out));
        }
    }

    fn kinetic(&self, v: &[f64]) -> f64 {
        let mut sum = 0.0;
        self.each_product(v, |c, y| sum += v[c] * y);
        0.5 * sum
    }

    fn psi_v_norm2(&self, v: &[f64]) -> f64 {
        let mut sum = 0.0;
        self.each_product(v, |_, y| sum += y * y);
        sum
    }

    fn psi_v_dot(&self, v: &[f64], x: impl Fn(usize) -> f64, extra: impl Fn(usize) -> f64, init: f64) -> f64 {
        let mut sum = init;
        self.each_product(v, |c, y| sum += y * x(c) + extra(c));
        sum
    }

    fn add_psi_v(&self, v: &[f64], scale: f64, out: &mut [f64]) {
        self.each_product(v, |c, y| out[c] += scale * y);
    }

    fn add_inverse_psi_v(&self, v: &[f64], scale: f64, out: &mut [f64]) {
        for (o, v) in out.iter_mut().zip(v) {
            *o += scale * v;
        }
    }
}

/// The mass matrix at one state: constant diagonal, or `M(q)` evaluated
/// there. Each product matches once, outside its loops, so the diagonal
/// kind runs its own loops unchanged.
#[derive(Debug, Clone, Copy)]
pub enum MassAt<'a> {
    /// A constant diagonal `M`.
    Diagonal(&'a DiagonalMass),
    /// `M(q)` at the state of the last evaluation.
    Dense(&'a DenseMass),
    /// A block-diagonal `M(q)` at the state of the last evaluation.
    Blocks(&'a BlockMass),
}

/// Forwards each product to the kind at hand.
macro_rules! either {
    ($self:ident, $m:ident => $e:expr) => {
        match $self {
            MassAt::Diagonal($m) => $e,
            MassAt::Dense($m) => $e,
            MassAt::Blocks($m) => $e,
        }
    };
}

impl MassMatrix for MassAt<'_> {
    #[inline(always)]
    fn n(&self) -> usize {
        either!(self, m => m.n())
    }
    #[inline(always)]
    fn mul(&self, x: &[f64], out: &mut [f64]) {
        either!(self, m => m.mul(x, out))
    }
    #[inline(always)]
    fn solve(&self, x: &[f64], out: &mut [f64]) {
        either!(self, m => m.solve(x, out))
    }
    #[inline(always)]
    fn kinetic(&self, v: &[f64]) -> f64 {
        either!(self, m => m.kinetic(v))
    }
    #[inline(always)]
    fn psi_v_norm2(&self, v: &[f64]) -> f64 {
        either!(self, m => m.psi_v_norm2(v))
    }
    #[inline(always)]
    fn psi_v_dot(&self, v: &[f64], x: impl Fn(usize) -> f64, extra: impl Fn(usize) -> f64, init: f64) -> f64 {
        either!(self, m => m.psi_v_dot(v, x, extra, init))
    }
    #[inline(always)]
    fn add_psi_v(&self, v: &[f64], scale: f64, out: &mut [f64]) {
        either!(self, m => m.add_psi_v(v, scale, out))
    }
    #[inline(always)]
    fn add_inverse_psi_v(&self, v: &[f64], scale: f64, out: &mut [f64]) {
        either!(self, m => m.add_inverse_psi_v(v, scale, out))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn diagonal_products_agree_with_their_definitions() {
        let mass = DiagonalMass::new(vec![2.0, 0.5, 4.0]).unwrap();
        let v = [1.0, -2.0, 0.25];
        let mut mv = [0.0; 3];
        mass.mul(&v, &mut mv);
        assert_eq!(mv, [2.0, -1.0, 1.0]);
        let mut back = [0.0; 3];
        mass.solve(&mv, &mut back);
        assert_eq!(back, v);
        assert_eq!(mass.kinetic(&v), 0.5 * (2.0 + 2.0 + 0.25));
        assert_eq!(mass.psi_v_norm2(&v), 4.0 + 1.0 + 1.0);
        assert_eq!(mass.psi_v_dot(&v, |_| 1.0, |_| 0.0, 0.5), 0.5 + 2.0);
        let mut out = [1.0; 3];
        mass.add_psi_v(&v, -1.0, &mut out);
        assert_eq!(out, [-1.0, 2.0, 0.0]);
        // M⁻¹ Ψ_vᵀ = v.
        let mut out = [0.0; 3];
        mass.add_inverse_psi_v(&v, 2.0, &mut out);
        assert_eq!(out, [2.0, -4.0, 0.5]);
        // Array storage behaves the same.
        let small = DiagonalMass::new([2.0, 0.5, 4.0]).unwrap();
        assert_eq!(small.kinetic(&v), mass.kinetic(&v));
        assert_eq!(small.inverse(), &[0.5, 2.0, 0.25]);
    }

    #[test]
    fn dense_products_agree_with_their_definitions() {
        let mut mass = DenseMass::new(3);
        mass.matrix_mut().copy_from_slice(&[4.0, 1.0, 0.5, 1.0, 3.0, -1.0, 0.5, -1.0, 2.0]);
        mass.factor().unwrap();
        let v = [1.0, -2.0, 0.25];
        let mut mv = [0.0; 3];
        mass.mul(&v, &mut mv);
        assert_eq!(mv, [4.0 - 2.0 + 0.125, 1.0 - 6.0 - 0.25, 0.5 + 2.0 + 0.5]);
        let mut back = [0.0; 3];
        mass.solve(&mv, &mut back);
        for (b, v) in back.iter().zip(&v) {
            assert!((b - v).abs() < 1e-14, "{back:?}");
        }
        let vmv: f64 = mv.iter().zip(&v).map(|(a, b)| a * b).sum();
        assert_eq!(mass.kinetic(&v), 0.5 * vmv);
        assert_eq!(mass.psi_v_norm2(&v), mv.iter().map(|x| x * x).sum::<f64>());
        let mut out = [0.0; 3];
        mass.add_psi_v(&v, 2.0, &mut out);
        assert_eq!(out, mv.map(|x| 2.0 * x));
        // Not positive definite: the pivot of coordinate 1 is 1 − 4 < 0.
        mass.matrix_mut().copy_from_slice(&[1.0, 2.0, 0.0, 2.0, 1.0, 0.0, 0.0, 0.0, 1.0]);
        assert_eq!(mass.factor(), Err(1));
    }

    #[test]
    fn a_mass_that_is_not_positive_is_an_error() {
        for bad in [0.0, -1.0, f64::NAN, f64::INFINITY] {
            let err = DiagonalMass::new(vec![1.0, bad]).unwrap_err();
            assert!(err.to_string().contains("mass"), "{err}");
        }
    }
}
