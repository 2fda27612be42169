//! The mass matrix at one state as the laws see it: whichever kind the model has.

use super::{BlockMass, DenseMass, DiagonalMass, MassMatrix};

/// The mass matrix at one state: constant diagonal, or `M(q)` evaluated
/// there. Each product matches once, outside its loops, so the diagonal
/// kind runs its own loops unchanged.
#[derive(Debug, Clone, Copy)]
#[non_exhaustive]
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
    fn psi_v(&self, v: &[f64], out: &mut [f64]) -> f64 {
        either!(self, m => m.psi_v(v, out))
    }
    #[inline(always)]
    fn psi_v_dot(&self, v: &[f64], x: impl Fn(usize) -> f64, extra: impl Fn(usize) -> f64, init: f64) -> f64 {
        either!(self, m => m.psi_v_dot(v, x, extra, init))
    }
    #[inline(always)]
    fn add_inverse_psi_v(&self, v: &[f64], scale: f64, out: &mut [f64]) {
        either!(self, m => m.add_inverse_psi_v(v, scale, out))
    }
}

impl MassAt<'_> {
    /// The `(row, column)` of each entry of `M` that can be non-zero, in
    /// the order [`entry_values`](Self::entry_values) writes them: the
    /// diagonal, then a block-diagonal `M(q)`'s blocks, or every entry of a dense one.
    pub(crate) fn entries(&self, out: &mut Vec<(u32, u32)>) {
        let n = self.n() as u32;
        match self {
            MassAt::Diagonal(_) => out.extend((0..n).map(|i| (i, i))),
            MassAt::Dense(_) => out.extend((0..n).flat_map(|i| (0..n).map(move |j| (i, j)))),
            MassAt::Blocks(m) => {
                out.extend((0..n).map(|i| (i, i)));
                for b in 0..m.blocks() {
                    let c = m.coordinates(b);
                    out.extend(c.iter().flat_map(|&i| c.iter().map(move |&j| (i, j))));
                }
            }
        }
    }

    /// The values of [`entries`](Self::entries), into `out`.
    pub(crate) fn entry_values(&self, out: &mut [f64]) {
        match self {
            MassAt::Diagonal(m) => out.copy_from_slice(m.diagonal()),
            MassAt::Dense(m) => out.copy_from_slice(m.matrix()),
            MassAt::Blocks(m) => {
                let (diagonal, blocks) = out.split_at_mut(m.n());
                diagonal.copy_from_slice(m.plain_diagonal());
                blocks.copy_from_slice(m.matrices());
            }
        }
    }
}
