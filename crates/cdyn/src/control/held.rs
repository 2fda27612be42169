//! Quadratic and declared invariants held beside the energy: angular
//! momenta ([`crate::model::angular`]) and first integrals the user declares
//! ([`crate::model::invariant`]).
//!
//! `robust`'s energy law moves the state along `(c P_E P M⁻¹Ψ_q, P_E P v)`.
//! Each held invariant `I_j` adds the velocity direction
//! `g_j = P_E P M⁻¹ ∂I_j/∂v` — its gradient in the metric `M`, projected
//! onto the constraints and off the linear momenta (for an angular
//! momentum `M⁻¹ ∂L/∂v = ξ`, the rotation itself) — and the gains `κ`
//! solve the small system `W κ = α (I − I₀) + (what the other terms do to
//! I)`, `W_ij` the rate at which direction `j` moves invariant `i`, for
//! the energy and every held invariant together: each decays at the rate
//! `α` exactly and none is traded for another. Where `W` is singular — a
//! body spinning about a principal axis, whose energy and angular momentum
//! change together — the dependent rows are left out (`docs/momenta.md`).

use crate::control::evaluation::Evaluation;
use crate::dynamics::Dynamics;
use crate::dynamics::momentum::{Kind, Momenta};
use crate::linalg::dot;
use crate::linalg::mass::MassMatrix;
use crate::model::Model;

pub use crate::dynamics::momentum::MAX_HELD;

/// The invariants a run holds beside the energy, with their gradients and
/// directions at the latest evaluation: `∂I_j/∂v`, `∂I_j/∂q`, the field
/// `M⁻¹ ∂I_j/∂v` (`ξ_j` for an angular momentum) and `g_j`, its `P_E P`,
/// all allocated once.
#[derive(Debug, Clone, Default)]
pub(crate) struct Held {
    /// Each a [`Kind::Rotation`] or a [`Kind::Declared`].
    kinds: Vec<Kind>,
    /// `I_j` held (its value at the start or after an impact), and at the latest update.
    targets: Vec<f64>,
    values: Vec<f64>,
    /// `k × n` each.
    field: Vec<f64>,
    grad_v: Vec<f64>,
    g: Vec<f64>,
    grad_q: Vec<f64>,
    /// `k × m`: `S⁻¹ Φ_q M⁻¹ ∂I_j/∂v`.
    rows: Vec<f64>,
    /// `n` each: `M v`, the energy's directions `P_E P v` and `c P_E P M⁻¹Ψ_q`,
    /// and two for `∂T/∂q` at `v ± s ξ`.
    mass_v: Vec<f64>,
    energy_v: Vec<f64>,
    energy_q: Vec<f64>,
    plus: Vec<f64>,
    minus: Vec<f64>,
    n: usize,
}

impl Held {
    /// Holds its invariants at `targets` (one each, in order) from now on.
    pub(crate) fn set_targets(&mut self, targets: &[f64]) {
        self.targets.copy_from_slice(targets);
    }

    /// Holds the invariants of `kinds` at `targets` in a model of `n`
    /// coordinates and `m` constraint rows.
    pub(crate) fn new(kinds: Vec<Kind>, targets: Vec<f64>, n: usize, m: usize) -> Self {
        let k = kinds.len();
        Self {
            kinds,
            targets,
            values: vec![0.0; k],
            field: vec![0.0; k * n],
            grad_v: vec![0.0; k * n],
            g: vec![0.0; k * n],
            grad_q: vec![0.0; k * n],
            rows: vec![0.0; k * m],
            mass_v: vec![0.0; n],
            energy_v: vec![0.0; n],
            energy_q: vec![0.0; n],
            plus: vec![0.0; n],
            minus: vec![0.0; n],
            n,
        }
    }

    /// Whether there are none.
    #[inline(always)]
    pub(crate) fn is_empty(&self) -> bool {
        self.kinds.is_empty()
    }

    fn len(&self) -> usize {
        self.kinds.len()
    }

    /// The gradients, fields and `g_j` of every invariant and its value at
    /// `(q, v)`, where `d` was just evaluated (and `momenta` updated). A
    /// declared one's gradients come by AD; an angular momentum's are
    /// `∂L/∂v = M ξ` and, with `gradients`, `∂L/∂q = Bᵀ M v + ∂(ξᵀ M(q) v)/∂q`
    /// (ξ frozen), the latter by polarization of `∂T/∂q`, exact for a `T`
    /// quadratic in `v`.
    pub(crate) fn update(
        &mut self,
        model: &Model,
        d: &Dynamics,
        momenta: &Momenta,
        q: &[f64],
        v: &[f64],
        gradients: bool,
    ) {
        let (k, n, m) = (self.len(), self.n, model.m());
        let mass = d.mass(model);
        mass.mul(v, &mut self.mass_v);
        for j in 0..k {
            let span = j * n..(j + 1) * n;
            let (field, grad_v) = (&mut self.field[span.clone()], &mut self.grad_v[span.clone()]);
            match &self.kinds[j] {
                Kind::Rotation(g) => {
                    g.at(q, field);
                    mass.mul(field, grad_v);
                    self.values[j] = dot(grad_v, v);
                }
                Kind::Declared(i) => {
                    let grad_q = &mut self.grad_q[span];
                    grad_q.fill(0.0);
                    grad_v.fill(0.0);
                    self.values[j] = model.declared_invariants()[*i].block.gradients(q, v, grad_q, grad_v);
                    mass.solve(grad_v, field);
                }
                Kind::Constant => field.fill(0.0),
            }
            d.jac_mul(model, &self.field[j * n..(j + 1) * n], &mut self.rows[j * m..(j + 1) * m]);
        }
        if m > 0 {
            let mut rhs: [&mut [f64]; MAX_HELD] = Default::default();
            rhs.iter_mut().zip(self.rows.chunks_mut(m)).for_each(|(r, row)| *r = row);
            d.solve_many(&mut rhs[..k]);
        }
        for j in 0..k {
            let g = &mut self.g[j * n..(j + 1) * n];
            g.copy_from_slice(&self.field[j * n..(j + 1) * n]);
            if m > 0 {
                d.add_weighted_jt(model, &self.rows[j * m..(j + 1) * m], -1.0, g);
            }
            momenta.project(g);
            let Kind::Rotation(generator) = &self.kinds[j] else { continue };
            if !gradients {
                continue;
            }
            let grad = &mut self.grad_q[j * n..(j + 1) * n];
            grad.fill(0.0);
            generator.add_transposed(&self.mass_v, grad);
            if model.mass().is_none() {
                let xi = &self.field[j * n..(j + 1) * n];
                let (tv, txi) = (dot(v, &self.mass_v), dot(xi, &self.grad_v[j * n..(j + 1) * n]));
                if txi > 0.0 {
                    let s = if tv > 0.0 { (tv / txi).sqrt() } else { 1.0 };
                    for (buffer, sign) in [(&mut self.plus, 1.0), (&mut self.minus, -1.0)] {
                        self.energy_v.iter_mut().zip(v).zip(xi).for_each(|((w, v), x)| *w = v + sign * s * x);
                        buffer.fill(0.0);
                        model.kinetic_and_gradient(q, &self.energy_v, Some(buffer));
                    }
                    let scale = 0.5 / s;
                    grad.iter_mut()
                        .zip(self.plus.iter().zip(&self.minus))
                        .for_each(|(g, (p, m))| *g += scale * (p - m));
                }
            }
        }
    }

    /// `W_ij = ∂I_i/∂v · g_j` (`k × k`, row-major into `out`): `g_j` moves
    /// `I_i` at this rate. Symmetric, `⟨g_i, g_j⟩_M`, since `P_E P` is
    /// M-self-adjoint.
    fn gram(&self, out: &mut [f64]) {
        let (k, n) = (self.len(), self.n);
        for i in 0..k {
            for j in 0..k {
                out[i * k + j] = dot(&self.grad_v[i * n..(i + 1) * n], &self.g[j * n..(j + 1) * n]);
            }
        }
    }

    /// Zeroes row and column `first + j` of `a` (`size × size`) when `g_j`
    /// is negligible against its field `f_j = M⁻¹ ∂I_j/∂v`
    /// (`|g_j|²_M ≤ 10⁻¹² |f_j|²_M`): it moves nothing the constraints and
    /// the linear momenta leave free, and its value follows from theirs.
    fn leave_out_if_degenerate(&self, j: usize, a: &mut [f64], size: usize, first: usize) {
        let n = self.n;
        let (field, grad_v) = (&self.field[j * n..(j + 1) * n], &self.grad_v[j * n..(j + 1) * n]);
        let i = first + j;
        let diagonal = a[i * size + i];
        if diagonal.is_nan() || diagonal <= 1e-12 * dot(field, grad_v) {
            for l in 0..size {
                a[i * size + l] = 0.0;
                a[l * size + i] = 0.0;
            }
        }
    }

    /// Moves the velocities along the `g_j` so that every `I_j` is back at
    /// its target, leaving `Φ̇` as it is (`Φ_q g_j = 0`): exact for a
    /// momentum, which is linear in `v` at fixed `q`, one Newton step for a
    /// declared invariant. For the `projection` method, at a state where
    /// [`update`](Self::update) was just called.
    pub(crate) fn restore(&self, v: &mut [f64]) {
        let k = self.len();
        let mut deviation = [0.0; MAX_HELD];
        deviation.iter_mut().zip(self.values.iter().zip(&self.targets)).for_each(|(d, (l, t))| *d = l - t);
        self.remove_along(&mut deviation[..k], v);
    }

    /// Makes `direction` (in the range of `P_E P`) M-orthogonal to the
    /// `g_j`, so that a step along it leaves every `I_j` as it is (to first
    /// order).
    pub(crate) fn orthogonalize(&self, direction: &mut [f64]) {
        let (k, n) = (self.len(), self.n);
        let mut along = [0.0; MAX_HELD];
        (0..k).for_each(|j| along[j] = dot(&self.grad_v[j * n..(j + 1) * n], direction));
        self.remove_along(&mut along[..k], direction);
    }

    /// `x −= Σ κ_j g_j` with `W κ = rates`: what moves the `I_j` at `rates`.
    fn remove_along(&self, rates: &mut [f64], x: &mut [f64]) {
        let (k, n) = (self.len(), self.n);
        let mut w = [0.0; MAX_HELD * MAX_HELD];
        self.gram(&mut w);
        (0..k).for_each(|j| self.leave_out_if_degenerate(j, &mut w[..k * k], k, 0));
        let mut kappa = [0.0; MAX_HELD];
        solve_independent(&mut w[..k * k], k, rates, &mut kappa[..k]);
        for j in 0..k {
            x.iter_mut().zip(&self.g[j * n..(j + 1) * n]).for_each(|(x, g)| *x -= kappa[j] * g);
        }
    }

    /// `robust`'s energy law with the held invariants beside it: adds
    /// `−κ₀ (c P_E P M⁻¹Ψ_q, P_E P v) − Σ κ_j (0, g_j)` to `U`, which holds
    /// the other terms already, with `κ` such that `Ψ` and every `I_j − I_j⁰`
    /// decay at the rate `alpha` under the whole control. `energy(N, 2T)`
    /// says whether the energy's direction, of rate `N`, may be used (not at
    /// rest); `None` where the energy term is left out. `rows` are two
    /// scratch vectors of `m`, `w` one of `n`.
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn hold<E: Evaluation>(
        &mut self,
        d: &E,
        v: &[f64],
        psi: f64,
        alpha: f64,
        c: f64,
        energy: Option<impl Fn(f64, f64) -> bool>,
        u_q: &mut [f64],
        u_v: &mut [f64],
        [y_v, y_w]: [&mut [f64]; 2],
        w: &mut [f64],
    ) {
        let (k, n) = (self.len(), self.n);
        let (mass, momenta) = (d.mass(), d.momenta());
        let grad = d.grad_potential();
        // The energy's direction: P_E P v and c P_E P M⁻¹Ψ_q (none where the
        // energy term is left out).
        if energy.is_some() {
            let (phi_dot, phi_t) = (d.phi_dot(), d.phi_t());
            y_v.iter_mut().zip(phi_dot).zip(phi_t).for_each(|((y, pd), pt)| *y = pd - pt);
            mass.solve(grad, w);
            d.potential_rate(w, y_w);
            d.solve_many(&mut [&mut *y_v, &mut *y_w]);
            self.energy_v.copy_from_slice(v);
            self.energy_q.copy_from_slice(w);
            d.add_weighted_jt_pair([y_v, y_w], [&mut self.energy_v, &mut self.energy_q]);
            momenta.project(&mut self.energy_v);
            momenta.project(&mut self.energy_q);
            self.energy_q.iter_mut().for_each(|x| *x *= c);
        } else {
            self.energy_v.fill(0.0);
            self.energy_q.fill(0.0);
        }
        // Rates of (Ψ, L_1 … L_k) along a change (δq, δv).
        let rate = |i: usize, dq: &[f64], dv: &[f64]| match i {
            0 => dot(grad, dq) + dot(&self.mass_v, dv),
            j => dot(&self.grad_q[(j - 1) * n..j * n], dq) + dot(&self.grad_v[(j - 1) * n..j * n], dv),
        };
        let size = k + 1;
        let mut a = [0.0; (MAX_HELD + 1) * (MAX_HELD + 1)];
        let mut rhs = [0.0; MAX_HELD + 1];
        let whole = dot(v, &self.mass_v);
        for i in 0..size {
            a[i * size] = rate(i, &self.energy_q, &self.energy_v);
            for j in 1..size {
                a[i * size + j] = match i {
                    0 => dot(&self.mass_v, &self.g[(j - 1) * n..j * n]),
                    i => dot(&self.grad_v[(i - 1) * n..i * n], &self.g[(j - 1) * n..j * n]),
                };
            }
            let deviation = if i == 0 { psi } else { self.values[i - 1] - self.targets[i - 1] };
            rhs[i] = alpha * deviation + rate(i, u_q, u_v);
        }
        // At rest, or with all the motion along the linear momenta, the
        // energy has no direction of its own: its row and column are left out.
        if !energy.is_some_and(|free| free(a[0], whole)) {
            for j in 0..size {
                a[j] = 0.0;
                a[j * size] = 0.0;
            }
            rhs[0] = 0.0;
        }
        for j in 0..k {
            self.leave_out_if_degenerate(j, &mut a[..size * size], size, 1);
        }
        let mut kappa = [0.0; MAX_HELD + 1];
        solve_independent(&mut a[..size * size], size, &mut rhs[..size], &mut kappa[..size]);
        // Bounded corrections, as the energy law caps its gain: the energy's
        // gain at most α, and the held invariants' velocity change at most α |v|_M.
        let mut limit: f64 = 1.0;
        if kappa[0].abs() > alpha {
            limit = limit.min(alpha / kappa[0].abs());
        }
        let mut gram = [0.0; MAX_HELD * MAX_HELD];
        self.gram(&mut gram);
        let turned: f64 = (0..k)
            .flat_map(|i| (0..k).map(move |j| (i, j)))
            .map(|(i, j)| kappa[1 + i] * gram[i * k + j] * kappa[1 + j])
            .sum();
        if turned > alpha * alpha * whole {
            limit = limit.min(alpha * (whole / turned).sqrt());
        }
        if !(limit.is_finite() && kappa.iter().all(|x| x.is_finite())) {
            return;
        }
        let k0 = limit * kappa[0];
        u_q.iter_mut().zip(&self.energy_q).for_each(|(u, x)| *u -= k0 * x);
        u_v.iter_mut().zip(&self.energy_v).for_each(|(u, x)| *u -= k0 * x);
        for j in 0..k {
            let kj = limit * kappa[1 + j];
            u_v.iter_mut().zip(&self.g[j * n..(j + 1) * n]).for_each(|(u, g)| *u -= kj * g);
        }
    }
}

/// Below this, relative to the largest diagonal entry, a pivot is a
/// dependent row: its invariant changes with the others and is left to them.
const DEPENDENT: f64 = 1e-9;

/// Solves `a x = b` (`k × k`, row-major, both overwritten) by elimination
/// with complete pivoting, scaled by the diagonal; the unknowns of pivots
/// below [`DEPENDENT`] (relative) are set to zero and their equations
/// dropped, as are a zero diagonal entry's row and column (the caller
/// zeroes those it finds degenerate).
pub(crate) fn solve_independent(a: &mut [f64], k: usize, b: &mut [f64], x: &mut [f64]) {
    x.fill(0.0);
    // Scale rows and columns by the diagonal, so that the threshold is
    // relative whatever the units of the invariants.
    let mut scale = [0.0; MAX_HELD + 1];
    for i in 0..k {
        let d = a[i * k + i].abs();
        scale[i] = if d > 0.0 && d.is_finite() { 1.0 / d.sqrt() } else { 0.0 };
    }
    for i in 0..k {
        b[i] *= scale[i];
        for j in 0..k {
            a[i * k + j] *= scale[i] * scale[j];
        }
    }
    let mut rows: [usize; MAX_HELD + 1] = std::array::from_fn(|i| i);
    let mut cols: [usize; MAX_HELD + 1] = std::array::from_fn(|i| i);
    let mut rank = 0;
    while rank < k {
        let mut best = (0.0, rank, rank);
        for r in rank..k {
            for c in rank..k {
                let x = a[rows[r] * k + cols[c]].abs();
                if x > best.0 {
                    best = (x, r, c);
                }
            }
        }
        if best.0.is_nan() || best.0 <= DEPENDENT {
            break;
        }
        rows.swap(rank, best.1);
        cols.swap(rank, best.2);
        let (pr, pc) = (rows[rank], cols[rank]);
        let pivot = a[pr * k + pc];
        for &r in &rows[rank + 1..k] {
            let f = a[r * k + pc] / pivot;
            if f != 0.0 {
                for &c in &cols[rank..k] {
                    a[r * k + c] -= f * a[pr * k + c];
                }
                b[r] -= f * b[pr];
            }
        }
        rank += 1;
    }
    for i in (0..rank).rev() {
        let (r, c) = (rows[i], cols[i]);
        let s: f64 = (i + 1..rank).map(|j| a[r * k + cols[j]] * x[cols[j]]).sum();
        x[c] = (b[r] - s) / a[r * k + c];
    }
    for i in 0..k {
        x[i] *= scale[i];
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_dependent_row_is_left_out() {
        // The same equation twice, x0 + x1 = 1, and a row and column of zeros.
        let mut a = [1.0, 1.0, 0.0, 1.0, 1.0, 0.0, 0.0, 0.0, 0.0];
        let mut b = [1.0, 1.0, 5.0];
        let mut x = [0.0; 3];
        solve_independent(&mut a, 3, &mut b, &mut x);
        assert!((x[0] + x[1] - 1.0).abs() < 1e-15 && x[0] * x[1] == 0.0 && x[2] == 0.0, "{x:?}");
        let mut a = [4.0, 1.0, 1.0, 3.0];
        let mut b = [1.0, 2.0];
        let mut x = [0.0; 2];
        solve_independent(&mut a, 2, &mut b, &mut x);
        assert!((4.0 * x[0] + x[1] - 1.0).abs() < 1e-14 && (x[0] + 3.0 * x[1] - 2.0).abs() < 1e-14);
    }
}
