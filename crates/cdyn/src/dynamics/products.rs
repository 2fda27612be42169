//! Products with the last evaluation's `Φ_q` and `M⁻¹`, and solves with
//! its factorization of `S = Φ_q M⁻¹ Φ_qᵀ`: what the control laws and the
//! implicit schemes apply to their own vectors.

use crate::dynamics::Dynamics;
use crate::dynamics::solver::Solver;
use crate::model::Model;

impl Dynamics {
    /// `out += scale · M⁻¹ Φ_qᵀ y` with the Jacobian of the last
    /// [`evaluate`](Self::evaluate), without bounds checks: the control laws
    /// take up to three such products per evaluation, and the checks were
    /// half their cost on a chain of 1 000 bodies.
    pub fn add_weighted_jt(&self, model: &Model, y: &[f64], scale: f64, out: &mut [f64]) {
        let jac = &self.constraints.jac;
        match (&self.solver, model.mass()) {
            (Solver::Constant(_), Some(mass)) => {
                let weight = mass.inverse();
                assert!(weight.len() == model.n(), "a mass of another model");
                // SAFETY: `scatter` passes entries `j` < nnz = `jac.len()` and coordinates `c` < n.
                scatter(model, jac, scale, [y], [out], |s, j, c| unsafe {
                    s * weight.get_unchecked(c) * jac.get_unchecked(j)
                })
            }
            (Solver::Blocks(b), _) => {
                let weighted = &b.weighted;
                // SAFETY: as above; `weighted` has an entry per Jacobian entry.
                scatter(model, weighted, scale, [y], [out], |s, j, _| unsafe { s * weighted.get_unchecked(j) })
            }
            (Solver::General(g), _) => g.add_weighted_jt(model.n(), y, scale, out),
            (Solver::Constant(_), None) => unreachable!("a workspace built for another model"),
        }
    }

    /// `out[k] −= M⁻¹ Φ_qᵀ y[k]` for `K` pairs in one pass over the Jacobian
    /// (the coupled control terms' products, and `A`'s constraint forces
    /// with them), each with the arithmetic of
    /// [`add_weighted_jt`](Self::add_weighted_jt) at scale −1.
    pub fn add_weighted_jt_many<const K: usize>(&self, model: &Model, y: [&[f64]; K], out: [&mut [f64]; K]) {
        let jac = &self.constraints.jac;
        match (&self.solver, model.mass()) {
            (Solver::Constant(_), Some(mass)) => {
                let weight = mass.inverse();
                assert!(weight.len() == model.n(), "a mass of another model");
                // SAFETY: as in `add_weighted_jt`.
                scatter(model, jac, -1.0, y, out, |s, j, c| unsafe {
                    s * weight.get_unchecked(c) * jac.get_unchecked(j)
                })
            }
            (Solver::Blocks(b), _) => {
                let weighted = &b.weighted;
                // SAFETY: as in `add_weighted_jt`.
                scatter(model, weighted, -1.0, y, out, |s, j, _| unsafe { s * weighted.get_unchecked(j) })
            }
            (Solver::General(g), _) => {
                y.into_iter().zip(out).for_each(|(y, out)| g.add_weighted_jt(model.n(), y, -1.0, out))
            }
            (Solver::Constant(_), None) => unreachable!("a workspace built for another model"),
        }
    }

    /// `out += Φ_qᵀ y` with the Jacobian of the last evaluation: the
    /// constraint forces of multipliers `y`, unweighted by `M⁻¹` (in the
    /// loop of [`add_weighted_jt`](Self::add_weighted_jt): with bounds
    /// checks it was 4 % of a robot's generalized-α step).
    pub fn add_jt(&self, model: &Model, y: &[f64], out: &mut [f64]) {
        let jac = &self.constraints.jac;
        // SAFETY: `scatter` passes entries `j` < nnz = `jac.len()`.
        scatter(model, jac, 1.0, [y], [out], |s, j, _| unsafe { s * jac.get_unchecked(j) })
    }

    /// `out = Φ_q x` with the Jacobian of the last [`evaluate`](Self::evaluate),
    /// without bounds checks (see [`add_weighted_jt`](Self::add_weighted_jt)).
    pub fn jac_mul(&self, model: &Model, x: &[f64], out: &mut [f64]) {
        let (pattern, jac) = (model.pattern(), &self.constraints.jac);
        assert!(x.len() == model.n() && out.len() == model.m(), "vectors of the wrong length");
        assert!(jac.len() == pattern.cols.len(), "a Jacobian of another model");
        // SAFETY: as in `add_weighted_jt`.
        unsafe {
            for (r, o) in out.iter_mut().enumerate() {
                let (a, b) = (*pattern.start.get_unchecked(r) as usize, *pattern.start.get_unchecked(r + 1) as usize);
                *o = (a..b)
                    .map(|j| jac.get_unchecked(j) * x.get_unchecked(*pattern.cols.get_unchecked(j) as usize))
                    .sum();
            }
        }
    }

    /// Solves `(Φ_q M⁻¹ Φ_qᵀ) x = b` in place for up to four vectors at
    /// once, with the factorization of the last [`evaluate`](Self::evaluate).
    pub fn solve_many(&self, bs: &mut [&mut [f64]]) {
        match &self.solver {
            Solver::Constant(schur) => schur.solve_many(bs),
            Solver::General(g) => bs.iter_mut().for_each(|b| g.schur.solve(b)),
            Solver::Blocks(b) => b.schur.solve_many(bs),
        }
    }
}

/// `out[k]_c += term(s, j, c)` over every Jacobian entry `j` (coordinate
/// `c`) of every row `r`, with `s = scale · y[k]_r`: the loop of
/// `add_weighted_jt` (one vector) and of its pair (scale −1), without
/// bounds checks. `values`, the per-entry array `term` reads, is checked
/// for its length here.
#[inline(always)]
fn scatter<const K: usize>(
    model: &Model,
    values: &[f64],
    scale: f64,
    y: [&[f64]; K],
    out: [&mut [f64]; K],
    term: impl Fn(f64, usize, usize) -> f64,
) {
    let pattern = model.pattern();
    let (m, n) = (model.m(), model.n());
    assert!(y.iter().all(|y| y.len() == m) && out.iter().all(|o| o.len() == n), "vectors of the wrong length");
    assert!(values.len() == pattern.cols.len(), "a Jacobian of another model");
    // SAFETY: a model's pattern is built by `ModelBuilder::build` from
    // checked coordinates (< n) with `start` rising from 0 to
    // `cols.len()`, and it cannot be changed afterwards; `y` and `start`
    // have m (+ 1) entries, `out` n.
    unsafe {
        for r in 0..m {
            let s: [f64; K] = std::array::from_fn(|k| scale * *y[k].get_unchecked(r));
            let (a, b) = (*pattern.start.get_unchecked(r) as usize, *pattern.start.get_unchecked(r + 1) as usize);
            for j in a..b {
                let c = *pattern.cols.get_unchecked(j) as usize;
                for k in 0..K {
                    *out[k].get_unchecked_mut(c) += term(s[k], j, c);
                }
            }
        }
    }
}
