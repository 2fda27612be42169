//! How `M⁻¹` and `(Φ_q M⁻¹ Φ_qᵀ)⁻¹` are applied, by the kind of mass
//! matrix: constant diagonal, dense `M(q)`, or block-diagonal `M(q)`.

use crate::linalg::mass::{BlockMass, DenseMass, DiagonalMass, MassMatrix, WidthFn};
use crate::linalg::{Breakdown, DenseLdl, LinearSolver, Schur};
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
/// `J̃` is `Φ_q` with each row's entries on a block multiplied by `L_b⁻ᵀ`
/// and `W` is `M⁻¹` outside the blocks and 1 on them. Since a row that
/// reads a block reads all of it (the model checks), `J̃` and `M⁻¹ Φ_qᵀ`
/// keep the pattern of `Φ_q`, and `S` is assembled and factored by the
/// same sparse [`Schur`] as for a constant `M`.
#[derive(Clone)]
pub(super) struct Blocks {
    pub(super) mass: BlockMass,
    /// `Ψ_q = ∇V + ∂T/∂q` (`∂T/∂q` first, while it is summed).
    pub(super) psi_q: Vec<f64>,
    /// `Ṁ q̇`
    pub(super) mdot_v: Vec<f64>,
    /// `J̃`, in the pattern's order.
    pub(super) scaled: Vec<f64>,
    /// `M⁻¹ Φ_qᵀ`, entry by entry in the pattern's order.
    pub(super) weighted: Vec<f64>,
    /// The Jacobian entries outside every block, with their coordinate.
    pub(super) plain: Vec<(u32, u32)>,
    /// Each row's run of entries on one block: the block, and where its
    /// entries (in the block's coordinate order) start in `entries`.
    pub(super) segments: Vec<(u32, u32)>,
    pub(super) entries: Vec<u32>,
    pub(super) schur: Schur,
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
        let (mut plain, mut segments, mut entries) = (Vec::new(), Vec::new(), Vec::new());
        for r in 0..model.m() {
            let first_segment = segments.len();
            for j in pattern.row(r) {
                let c = pattern.cols[j];
                let (b, i) = owner[c as usize];
                if b == u32::MAX {
                    plain.push((j as u32, c));
                    continue;
                }
                let at = match segments[first_segment..].iter().find(|&&(sb, _)| sb == b) {
                    Some(&(_, at)) => at,
                    None => {
                        let at = entries.len() as u32;
                        segments.push((b, at));
                        entries.resize(entries.len() + blocks[b as usize].len(), 0);
                        at
                    }
                };
                entries[(at + i) as usize] = j as u32;
            }
        }
        // `S`'s weights: `M⁻¹` outside the blocks, 1 on them (in `J̃`).
        let weights: Vec<f64> =
            owner.iter().zip(diagonal).map(|(&(b, _), &m)| if b == u32::MAX { m } else { 1.0 }).collect();
        let weights = DiagonalMass::new(weights).expect("positive masses outside the blocks (checked by the model)");
        let nnz = pattern.nnz();
        Self {
            mass: BlockMass::new(diagonal, blocks),
            psi_q: vec![0.0; n],
            mdot_v: vec![0.0; n],
            scaled: vec![0.0; nnz],
            weighted: vec![0.0; nnz],
            plain,
            segments,
            entries,
            schur: Schur::new_for_blocks(pattern, &weights, solver),
        }
    }

    /// `J̃` and `M⁻¹ Φ_qᵀ` from `Φ_q`, then `S` factored and `b` solved in place.
    pub(super) fn factor_and_solve(&mut self, jac: &[f64], b: &mut [f64]) -> Result<(), Breakdown> {
        let inverse = self.mass.inverse();
        for &(j, c) in &self.plain {
            let (j, c) = (j as usize, c as usize);
            self.scaled[j] = jac[j];
            self.weighted[j] = jac[j] * inverse[c];
        }
        // One row's entries on one block: `J̃` is `L⁻¹` times them, `M⁻¹ Φ_qᵀ` `L⁻ᵀ L⁻¹`.
        struct Segment<'a> {
            entries: &'a [u32],
            jac: &'a [f64],
            scaled: &'a mut [f64],
            weighted: &'a mut [f64],
        }
        impl WidthFn for Segment<'_> {
            #[inline(always)]
            fn call<const K: usize>(self, mass: &BlockMass, b: usize) {
                let idx: &[u32; K] = self.entries[..K].try_into().expect("a block's K entries");
                let x = mass.forward(b, idx.map(|j| self.jac[j as usize]));
                idx.iter().zip(x).for_each(|(&j, x)| self.scaled[j as usize] = x);
                let y = mass.backward(b, x);
                idx.iter().zip(y).for_each(|(&j, y)| self.weighted[j as usize] = y);
            }
        }
        for &(block, at) in &self.segments {
            let segment = Segment {
                entries: &self.entries[at as usize..],
                jac,
                scaled: &mut self.scaled,
                weighted: &mut self.weighted,
            };
            self.mass.at_width(block as usize, segment);
        }
        self.schur.factor_and_solve(&self.scaled, b)
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
