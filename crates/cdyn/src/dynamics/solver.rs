//! How `M⁻¹` and `(Φ_q M⁻¹ Φ_qᵀ)⁻¹` are applied, by the kind of mass
//! matrix: constant diagonal, dense `M(q)`, or block-diagonal `M(q)`.

use crate::linalg::mass::{BlockMass, DenseMass, MassMatrix, WidthFn};
use crate::linalg::{AssembledSchur, Breakdown, DenseLdl, DependentRows, LinearSolver, Schur, products};
use crate::model::Model;

/// How `M⁻¹` and `(Φ_q M⁻¹ Φ_qᵀ)⁻¹` are applied: decided by the model's mass.
// The constant path's structure stays inline (no indirection in the hot
// loops); there is one workspace per model, so its size does not matter.
#[allow(clippy::large_enum_variant)]
#[derive(Clone)]
pub(super) enum Solver {
    /// Constant diagonal `M`: `S` assembled on the Jacobian's pattern.
    Constant(Schur),
    /// `M(q)`: evaluated, factored and used densely.
    General(Box<General>),
    /// A block-diagonal `M(q)`: factored block by block, `S` sparse.
    Blocks(Box<Blocks>),
}

/// Coordinates from which [`LinearSolver::Auto`] factors a block-diagonal
/// `M(q)` by blocks: below, the dense path is as cheap (a double pendulum
/// in angles, n = 2, took 9 % more instructions per step by blocks).
pub const BLOCKS_FROM: usize = 16;

/// The workspace of a block-diagonal `M(q)` ([`BlockMass`]), allocated once.
///
/// With `M_b = L_b L_bᵀ` on each block, `S = Φ_q M⁻¹ Φ_qᵀ = J̃ W J̃ᵀ`, where
/// `J̃` is `Φ_q` with each row's entries on a block multiplied by `L_b⁻¹`
/// and `W` is `M⁻¹` outside the blocks and 1 on them. Since a row that
/// reads a block reads all of it (the model checks), a row's `J̃` on a
/// block is a dense segment, and `S`'s entries from that block are the dot
/// products of the segments on it, taken block by block at the block's
/// width; the entries outside the blocks are summed product by product.
/// `S` is then factored in a band or along its sparse pattern ([`AssembledSchur`]).
#[derive(Clone)]
pub(super) struct Blocks {
    pub(super) mass: BlockMass,
    /// `Ψ_q = ∇V + ∂T/∂q` (`∂T/∂q` first, while it is summed).
    pub(super) psi_q: Vec<f64>,
    /// `Ṁ q̇`
    pub(super) mdot_v: Vec<f64>,
    /// `M⁻¹ Φ_qᵀ`, entry by entry in the pattern's order.
    pub(super) weighted: Vec<f64>,
    /// The Jacobian entries outside every block, with their coordinate.
    pub(super) plain: Vec<(u32, u32)>,
    /// The products `J_a J_b (M⁻¹)_cc` on coordinates outside the blocks,
    /// with the slot of `S` each adds to.
    plain_products: Vec<(u32, u32, f64, u32)>,
    /// Each block's segments (`segment_start` by block): where a row's
    /// entries on it start in `entries`, which holds their places in the
    /// Jacobian in the block's coordinate order, and in `tilde`, which
    /// holds `J̃` on them.
    segment_start: Vec<u32>,
    segments: Vec<u32>,
    entries: Vec<u32>,
    tilde: Vec<f64>,
    /// Each block's pairs of segments (`pair_start` by block) and the slot
    /// of `S` their dot product adds to.
    pair_start: Vec<u32>,
    pairs: Vec<(u32, u32, u32)>,
    /// `S`'s entries by slot, assembled each step.
    s: Vec<f64>,
    pub(super) schur: AssembledSchur,
}

impl Blocks {
    pub(super) fn new(model: &Model, blocks: &[Vec<u32>], solver: LinearSolver) -> Self {
        let (n, pattern) = (model.n(), model.pattern());
        let mut owner = vec![(u32::MAX, 0u32); n];
        for (b, coords) in blocks.iter().enumerate() {
            for (i, &c) in coords.iter().enumerate() {
                owner[c as usize] = (b as u32, i as u32);
            }
        }
        let diagonal = model.diagonal_mass();
        let schur = AssembledSchur::new(pattern, n, solver);
        let slot = schur.slot_finder();
        // Every row's segment on every block it reads: (block, row, start).
        let (mut plain, mut found, mut entries) = (Vec::new(), Vec::new(), Vec::new());
        for r in 0..model.m() {
            let first_segment = found.len();
            for j in pattern.row(r) {
                let c = pattern.cols[j];
                let (b, i) = owner[c as usize];
                if b == u32::MAX {
                    plain.push((j as u32, c));
                    continue;
                }
                let at = match found[first_segment..].iter().find(|&&(sb, _, _)| sb == b) {
                    Some(&(_, _, at)) => at,
                    None => {
                        let at = entries.len() as u32;
                        found.push((b, r, at));
                        entries.resize(entries.len() + blocks[b as usize].len(), 0);
                        at
                    }
                };
                entries[(at + i) as usize] = j as u32;
            }
        }
        // By block, then row: each block's segments are one run.
        found.sort_by_key(|&(b, r, _)| (b, r));
        let (mut segment_start, mut segments, mut pair_start, mut pairs) = (vec![0], Vec::new(), vec![0], Vec::new());
        let mut rest = found.as_slice();
        for b in 0..blocks.len() as u32 {
            let (on_block, after) = rest.split_at(rest.iter().take_while(|&&(sb, ..)| sb == b).count());
            rest = after;
            for (k, &(_, ra, at_a)) in on_block.iter().enumerate() {
                segments.push(at_a);
                for &(_, rb, at_b) in &on_block[..=k] {
                    pairs.push((at_a, at_b, slot(ra, rb) as u32));
                }
            }
            segment_start.push(segments.len() as u32);
            pair_start.push(pairs.len() as u32);
        }
        let mass = BlockMass::new(diagonal, blocks);
        let plain_products = products(pattern, n)
            .into_iter()
            .filter(|&(.., col)| owner[col].0 == u32::MAX)
            .map(|(a, b, ja, jb, col)| (ja as u32, jb as u32, mass.inverse()[col], slot(a, b) as u32))
            .collect();
        let slots = schur.slots();
        drop(slot);
        let blocks = Self {
            mass,
            psi_q: vec![0.0; n],
            mdot_v: vec![0.0; n],
            weighted: vec![0.0; pattern.nnz()],
            plain,
            plain_products,
            segment_start,
            segments,
            tilde: vec![0.0; entries.len()],
            entries,
            pair_start,
            pairs,
            s: vec![0.0; slots],
            schur,
        };
        blocks.check(pattern.nnz());
        blocks
    }

    /// Checks the bounds the unchecked assembly relies on: every segment's
    /// places lie in `entries` and `tilde`, every place indexes a Jacobian of
    /// `nnz` entries and every coordinate the mass, and every pair and
    /// product adds to a slot of `S`.
    fn check(&self, nnz: usize) {
        let mass = &self.mass;
        let ok = (0..mass.blocks()).all(|b| {
            let k = mass.coordinates(b).len();
            let span = |start: &[u32]| start[b] as usize..start[b + 1] as usize;
            let inside = |at: u32| at as usize + k <= self.entries.len();
            self.segments[span(&self.segment_start)].iter().all(|&at| inside(at))
                && self.pairs[span(&self.pair_start)]
                    .iter()
                    .all(|&(a, c, slot)| inside(a) && inside(c) && (slot as usize) < self.s.len())
        });
        let n = mass.inverse().len();
        let ok = ok
            && self.tilde.len() == self.entries.len()
            && self.weighted.len() == nnz
            && self.entries.iter().all(|&j| (j as usize) < nnz)
            && self.plain.iter().all(|&(j, c)| (j as usize) < nnz && (c as usize) < n)
            && self
                .plain_products
                .iter()
                .all(|&(a, b, _, slot)| (a as usize) < nnz && (b as usize) < nnz && (slot as usize) < self.s.len());
        assert!(ok, "inconsistent structure of the block assembly");
    }

    /// Sets what a dependent row does; where that changes how `S` is
    /// factored, its entries move to the other factorization's slots.
    pub(super) fn set_dependent_rows(&mut self, dependent: DependentRows) {
        if let Some(slot) = self.schur.set_dependent_rows(dependent) {
            self.pairs.iter_mut().for_each(|p| p.2 = slot[p.2 as usize]);
            self.plain_products.iter_mut().for_each(|p| p.3 = slot[p.3 as usize]);
            self.s = vec![0.0; self.schur.slots()];
            self.check(self.weighted.len());
        }
    }

    /// `J̃`, `M⁻¹ Φ_qᵀ` and `S` from `Φ_q`, then `S` factored and `b` solved in place.
    pub(super) fn factor_and_solve(&mut self, jac: &[f64], b: &mut [f64]) -> Result<(), Breakdown> {
        assert!(jac.len() == self.weighted.len(), "a Jacobian of the pattern's length");
        let inverse = self.mass.inverse();
        self.s.fill(0.0);
        // SAFETY: `check` bounded the places by the Jacobian's length (its
        // length is asserted above), the coordinates by `inverse`'s and the
        // slots by `s`'s.
        unsafe {
            for &(j, c) in &self.plain {
                let (j, c) = (j as usize, c as usize);
                *self.weighted.get_unchecked_mut(j) = jac.get_unchecked(j) * inverse.get_unchecked(c);
            }
            for &(ja, jb, w, slot) in &self.plain_products {
                *self.s.get_unchecked_mut(slot as usize) +=
                    jac.get_unchecked(ja as usize) * jac.get_unchecked(jb as usize) * w;
            }
        }
        // One block's segments: `J̃` is `L⁻¹` times them, `M⁻¹ Φ_qᵀ` `L⁻ᵀ L⁻¹`;
        // then the dot products of every pair of them.
        struct Block<'a> {
            segments: &'a [u32],
            pairs: &'a [(u32, u32, u32)],
            entries: &'a [u32],
            jac: &'a [f64],
            tilde: &'a mut [f64],
            weighted: &'a mut [f64],
            s: &'a mut [f64],
        }
        impl WidthFn for Block<'_> {
            #[inline(always)]
            fn call<const K: usize>(self, mass: &BlockMass, b: usize) {
                // SAFETY: `new` checked (`check`) that every segment's `K`
                // places lie in `entries` and `tilde`, that `entries` holds
                // places < nnz = `jac.len()` = `weighted.len()`, and every
                // pair's slot < `s.len()`. Unchecked: the pairs' loop is
                // most of the assembly, and its bounds checks a third of it.
                unsafe {
                    let segment = |values: &[f64], at: u32| -> [f64; K] {
                        *(values.as_ptr().add(at as usize) as *const [f64; K])
                    };
                    for &at in self.segments {
                        let idx = &*(self.entries.as_ptr().add(at as usize) as *const [u32; K]);
                        let x = mass.forward(b, idx.map(|j| *self.jac.get_unchecked(j as usize)));
                        *(self.tilde.as_mut_ptr().add(at as usize) as *mut [f64; K]) = x;
                        let y = mass.backward(b, x);
                        idx.iter().zip(y).for_each(|(&j, y)| *self.weighted.get_unchecked_mut(j as usize) = y);
                    }
                    for &(at_a, at_b, slot) in self.pairs {
                        let (x, y) = (segment(self.tilde, at_a), segment(self.tilde, at_b));
                        *self.s.get_unchecked_mut(slot as usize) += x.iter().zip(y).map(|(x, y)| x * y).sum::<f64>();
                    }
                }
            }
        }
        for block in 0..self.mass.blocks() {
            let span = |start: &[u32]| start[block] as usize..start[block + 1] as usize;
            let pass = Block {
                segments: &self.segments[span(&self.segment_start)],
                pairs: &self.pairs[span(&self.pair_start)],
                entries: &self.entries,
                jac,
                tilde: &mut self.tilde,
                weighted: &mut self.weighted,
                s: &mut self.s,
            };
            self.mass.at_width(block, pass);
        }
        self.schur.factor_and_solve_assembled(&self.s, b)
    }
}

/// The workspace of a configuration-dependent `M(q)`, allocated once.
#[derive(Clone)]
pub(super) struct General {
    pub(super) mass: DenseMass,
    /// `Ψ_q = ∇V + ∂T/∂q` (`∂T/∂q` first, while it is summed).
    pub(super) psi_q: Vec<f64>,
    /// `Ṁ q̇`
    pub(super) mdot_v: Vec<f64>,
    /// Row `r` of `Φ_q`, dense (`n` entries per row).
    pub(super) jac: Vec<f64>,
    /// Row `r` of `(M⁻¹ Φ_qᵀ)ᵀ`: `M⁻¹` times row `r` of `Φ_q`.
    pub(super) weighted: Vec<f64>,
    pub(super) schur: DenseLdl,
}

impl General {
    /// `S = Φ_q (M⁻¹ Φ_qᵀ)` from the pattern and values of `Φ_q`, factored, and `b` solved in place.
    pub(super) fn factor_and_solve(&mut self, model: &Model, jac: &[f64], b: &mut [f64]) -> Result<(), Breakdown> {
        let (n, m, pattern) = (model.n(), model.m(), model.pattern());
        self.jac.fill(0.0);
        for r in 0..m {
            for j in pattern.row(r) {
                self.jac[r * n + pattern.cols[j] as usize] = jac[j];
            }
            let (row, out) = (&self.jac[r * n..(r + 1) * n], &mut self.weighted[r * n..(r + 1) * n]);
            self.mass.solve(row, out);
        }
        let s = self.schur.matrix_mut();
        for a in 0..m {
            for c in 0..=a {
                s[a * m + c] =
                    self.jac[a * n..(a + 1) * n].iter().zip(&self.weighted[c * n..]).map(|(x, y)| x * y).sum();
            }
        }
        self.schur.factor(jac)?;
        self.schur.solve(b);
        Ok(())
    }

    /// `out += scale · M⁻¹ Φ_qᵀ y`
    pub(super) fn add_weighted_jt(&self, n: usize, y: &[f64], scale: f64, out: &mut [f64]) {
        for (r, &yr) in y.iter().enumerate() {
            let s = scale * yr;
            for (o, w) in out.iter_mut().zip(&self.weighted[r * n..(r + 1) * n]) {
                *o += s * w;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dynamics::Dynamics;

    /// The band of `Auto` and the column kernel of `Sparse` on a moving
    /// spatial chain: the same `λ`, `A` and solves, and the column kernel
    /// again once dependent rows are tolerated.
    #[test]
    fn a_spatial_chain_is_factored_in_a_band_with_the_column_kernels_answers() {
        let built = crate::spatial::chain(12, 0.3, 9.81).build().unwrap();
        let (model, q) = (&built.model, &built.q0);
        let v: Vec<f64> = (0..model.n()).map(|i| 0.4 * (0.7 * i as f64).sin()).collect();
        let banded = |d: &Dynamics| matches!(&d.solver, Solver::Blocks(b) if b.schur.banded());
        let (mut band, mut columns) =
            (Dynamics::with_solver(model, LinearSolver::Auto), Dynamics::with_solver(model, LinearSolver::Sparse));
        assert!(banded(&band) && !banded(&columns));
        band.evaluate(model, q, &v, 0.0).unwrap();
        columns.evaluate(model, q, &v, 0.0).unwrap();
        let close = |a: &[f64], b: &[f64], what: &str| {
            let scale = a.iter().fold(1.0_f64, |s, x| s.max(x.abs()));
            let error = a.iter().zip(b).fold(0.0_f64, |e, (a, b)| e.max((a - b).abs()));
            assert!(error <= 1e-12 * scale, "{what}: {error:e} of {scale:e}");
        };
        close(band.lambda(), columns.lambda(), "λ");
        close(band.acc(), columns.acc(), "A");
        let rhs: Vec<f64> = (0..model.m()).map(|i| (1.0 + i as f64).cos()).collect();
        let (mut x, mut y) = (rhs.clone(), rhs.clone());
        band.solve_many(&mut [&mut x]);
        columns.solve_many(&mut [&mut y]);
        close(&x, &y, "S⁻¹b");
        // Tolerating dependent rows moves S to the column kernel, whose
        // answers are then the column kernel's to the bit; and back.
        let first = band.acc().to_vec();
        band.set_dependent_rows(DependentRows::Tolerate);
        columns.set_dependent_rows(DependentRows::Tolerate);
        assert!(!banded(&band));
        band.evaluate(model, q, &v, 0.0).unwrap();
        columns.evaluate(model, q, &v, 0.0).unwrap();
        assert_eq!(band.acc(), columns.acc());
        band.set_dependent_rows(DependentRows::Error);
        assert!(banded(&band));
        band.evaluate(model, q, &v, 0.0).unwrap();
        assert_eq!(band.acc(), first);
    }
}
