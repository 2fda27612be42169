//! A block-diagonal `M(q)`: a diagonal and small dense blocks, each factored on its own.

use super::MassMatrix;

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

    /// `M_cc` of the coordinates outside every block (0 inside one).
    pub(crate) fn plain_diagonal(&self) -> &[f64] {
        &self.diagonal
    }

    /// All blocks' matrices, one after another (each `k × k`, row-major).
    pub(crate) fn matrices(&self) -> &[f64] {
        &self.matrix
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
    let a = &a[..K * K];
    // In a local array, which the compiler keeps in registers and whose
    // loops it unrolls (through the slice they ran as loops: 350
    // instructions a block of 4, a twentieth of a spatial chain's step).
    let mut f = [[0.0; K]; K];
    for j in 0..K {
        let d = a[j * K + j] - (0..j).map(|i| f[j][i] * f[j][i]).sum::<f64>();
        // Relative to the diagonal entry, as for a dense `M`.
        if d.is_nan() || d <= 1e-14 * a[j * K + j].abs() || !d.is_finite() {
            return Err(j);
        }
        let d = d.sqrt();
        f[j][j] = d;
        for i in j + 1..K {
            let s = a[i * K + j] - (0..j).map(|c| f[i][c] * f[j][c]).sum::<f64>();
            f[i][j] = s / d;
        }
    }
    // L⁻¹ in place, row by row: row i of L⁻¹ from the rows above it,
    // left to right, each entry read from L just before it is replaced.
    for i in 0..K {
        let d = 1.0 / f[i][i];
        for j in 0..i {
            let s: f64 = (j..i).map(|m| f[i][m] * f[m][j]).sum();
            f[i][j] = -s * d;
        }
        f[i][i] = d;
    }
    l[..K * K].copy_from_slice(f.as_flattened());
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

    fn psi_v_dot(&self, v: &[f64], x: impl Fn(usize) -> f64, extra: impl Fn(usize) -> f64, init: f64) -> f64 {
        let mut sum = init;
        self.each_product(v, |c, y| sum += y * x(c) + extra(c));
        sum
    }

    fn add_inverse_psi_v(&self, v: &[f64], scale: f64, out: &mut [f64]) {
        for (o, v) in out.iter_mut().zip(v) {
            *o += scale * v;
        }
    }
}
