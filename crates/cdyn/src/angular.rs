//! Angular momenta: the momenta of rigid rotations, quadratic in the
//! state, held by gradient feedback the way the energy is.
//!
//! A rigid rotation of the whole system about an axis moves the coordinates
//! along a field `ξ(q) = B q + b` affine in `q` (a [`Generator`]): for a
//! planar body `(x, y, θ)` turning about the point `c`,
//! `ξ = (−(y − c_y), x − c_x, 1)`; for a spatial body `(r, p)` about the
//! axis `a` through `c`, `ξ_r = a × (r − c)` and `ξ_p = ½ (0, a) ⊗ p`, so
//! that `2 E(p) ξ_p = a`. The system is symmetric under it when
//! `Φ_q ξ = 0`, `Q·ξ = 0` and the energy does not change under the
//! rotation lifted to the velocities (`v ↦ v + s B v`):
//! `Ψ_q·ξ + (M v)·(B v) = 0`. Its momentum `L = ξ(q)ᵀ M v` is then
//! conserved: `dL/dt = (B v)·M v + ξ·(∂T/∂q − ∇V + Q − Φ_qᵀλ) = 0`.
//!
//! `L` is quadratic in the state, so no explicit scheme keeps it and a
//! correction cannot keep it by staying M-orthogonal to a fixed direction,
//! as it keeps a linear momentum ([`crate::momentum`]). `robust` holds it
//! with its energy: the velocities move along `g_j = P_E P ξ_j` — the
//! gradient `M⁻¹ ∂L_j/∂v = ξ_j` projected onto the constraints and off the
//! linear momenta — next to the energy's `(c P_E P M⁻¹Ψ_q, P_E P v)`, and
//! the gains `κ` solve the small system `W κ = α (I − I₀) + (what the other
//! terms do to I)` for the energy and every angular momentum together, so
//! that each decays at the rate `α` exactly and none is traded for another.
//! Where `W` is singular — a body spinning about a principal axis, whose
//! energy and angular momentum change together — the dependent rows are
//! left out (`docs/momenta.md`).

use crate::control::Evaluation;
use crate::dynamics::Dynamics;
use crate::mass::MassMatrix;
use crate::model::Model;
use crate::momentum::Momenta;

/// The most angular momenta a run holds.
pub const MAX_ROTATIONS: usize = 6;

/// An infinitesimal rigid rotation of the system as a field on the
/// coordinates, `ξ(q) = B q + b`.
#[derive(Debug, Clone, PartialEq)]
pub struct Generator {
    /// What its momentum is called ("angular momentum z").
    pub name: String,
    /// The non-zero entries of `B`: row, column, weight.
    pub linear: Vec<(u32, u32, f64)>,
    /// The non-zero entries of `b`.
    pub offset: Vec<(u32, f64)>,
    /// Declared by the user: reported when the model does not keep it.
    pub declared: bool,
}

impl Generator {
    /// The rotation about the unit `axis` (normalized here) through `point`
    /// of every body of a mechanism, read from its coordinate names: a
    /// planar body's `name.x`, `name.y` and `name.angle` (the axis must be
    /// `z`), a spatial body's `name.x`, `name.y`, `name.z` and Euler
    /// parameters `name.e0` … `name.e3`. An error names a coordinate that
    /// belongs to no body, or an axis that is not allowed.
    pub fn rotation(
        name: &str,
        names: &[String],
        axis: [f64; 3],
        point: [f64; 3],
        declared: bool,
    ) -> Result<Generator, String> {
        let length = axis.iter().map(|a| a * a).sum::<f64>().sqrt();
        if !(length > 0.0 && length.is_finite()) || point.iter().any(|p| !p.is_finite()) {
            return Err(format!("axis {axis:?} through {point:?}: must be finite, the axis not zero"));
        }
        let a = axis.map(|x| x / length);
        let spatial = names.iter().any(|n| n.ends_with(".e0"));
        if !spatial && (a[0] != 0.0 || a[1] != 0.0) {
            return Err(format!("axis {axis:?}: a planar mechanism turns about z only"));
        }
        let (mut linear, mut offset) = (Vec::new(), Vec::new());
        let mut i = 0;
        while i < names.len() {
            let body = names[i].rsplit_once('.').map_or("", |(b, _)| b);
            let fields: &[&str] = if spatial {
                &["x", "y", "z", "e0", "e1", "e2", "e3"]
            } else if names.get(i + 2).is_some_and(|n| *n == format!("{body}.angle")) {
                &["x", "y", "angle"]
            } else {
                &["x", "y"]
            };
            for (k, f) in fields.iter().enumerate() {
                if names.get(i + k).is_none_or(|n| *n != format!("{body}.{f}")) {
                    return Err(format!("coordinate {}: not a body's {f}", names.get(i + k).map_or("(none)", |n| n)));
                }
            }
            let at = |k: usize| (i + k) as u32;
            if spatial {
                // ξ_r = a × r − a × c
                let cross = [[0.0, -a[2], a[1]], [a[2], 0.0, -a[0]], [-a[1], a[0], 0.0]];
                for (r, row) in cross.iter().enumerate() {
                    for (c, &w) in row.iter().enumerate().filter(|(_, w)| **w != 0.0) {
                        linear.push((at(r), at(c), w));
                    }
                    let b = -(0..3).map(|c| row[c] * point[c]).sum::<f64>();
                    if b != 0.0 {
                        offset.push((at(r), b));
                    }
                }
                // ξ_p = ½ (0, a) ⊗ p = ½ [[0, −aᵀ], [a, [a]×]] p
                let half = [
                    [0.0, -a[0], -a[1], -a[2]],
                    [a[0], 0.0, -a[2], a[1]],
                    [a[1], a[2], 0.0, -a[0]],
                    [a[2], -a[1], a[0], 0.0],
                ];
                for (r, row) in half.iter().enumerate() {
                    for (c, &w) in row.iter().enumerate().filter(|(_, w)| **w != 0.0) {
                        linear.push((at(3 + r), at(3 + c), 0.5 * w));
                    }
                }
            } else {
                // (−(y − c_y), x − c_x, 1), turned by the sign of a_z
                let s = a[2];
                linear.extend([(at(0), at(1), -s), (at(1), at(0), s)]);
                offset.extend([(at(0), s * point[1]), (at(1), -s * point[0])].into_iter().filter(|(_, b)| *b != 0.0));
                if fields.len() == 3 {
                    offset.push((at(2), s));
                }
            }
            i += fields.len();
        }
        Ok(Generator { name: name.to_string(), linear, offset, declared })
    }

    /// `out = ξ(q) = B q + b`.
    pub fn at(&self, q: &[f64], out: &mut [f64]) {
        out.fill(0.0);
        self.offset.iter().for_each(|&(i, b)| out[i as usize] += b);
        self.linear.iter().for_each(|&(r, c, w)| out[r as usize] += w * q[c as usize]);
    }

    /// Checks the entries name coordinates of a model of `n`.
    pub(crate) fn check(&self, n: usize) -> Result<(), String> {
        let rows = self.linear.iter().flat_map(|&(r, c, _)| [r, c]).chain(self.offset.iter().map(|&(i, _)| i));
        match rows.into_iter().find(|&i| i as usize >= n) {
            Some(i) => Err(format!("{}: coordinate {i} of a model of {n}", self.name)),
            None if self.linear.iter().map(|e| e.2).chain(self.offset.iter().map(|e| e.1)).any(|w| !w.is_finite()) => {
                Err(format!("{}: its weights must be finite", self.name))
            }
            None => Ok(()),
        }
    }

    /// `out += Bᵀ x`.
    fn add_transposed(&self, x: &[f64], out: &mut [f64]) {
        self.linear.iter().for_each(|&(r, c, w)| out[c as usize] += w * x[r as usize]);
    }

    /// `x · B y`.
    pub(crate) fn form(&self, x: &[f64], y: &[f64]) -> f64 {
        self.linear.iter().map(|&(r, c, w)| x[r as usize] * w * y[c as usize]).sum()
    }
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(a, b)| a * b).sum()
}

/// The angular momenta a run holds, with their directions at the latest
/// evaluation: `ξ_j`, `M ξ_j`, `g_j = P_E P ξ_j` and `∂L_j/∂q`, all
/// allocated once.
#[derive(Debug, Clone, Default)]
pub(crate) struct Rotations {
    generators: Vec<Generator>,
    /// `L_j` at the start: what is held.
    targets: Vec<f64>,
    /// `L_j` at the latest update.
    values: Vec<f64>,
    /// `k × n` each.
    xi: Vec<f64>,
    mass_xi: Vec<f64>,
    g: Vec<f64>,
    grad_q: Vec<f64>,
    /// `k × m`: `S⁻¹ Φ_q ξ_j`.
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

impl Rotations {
    /// Holds the momenta of `generators` at `targets` in a model of `n`
    /// coordinates and `m` constraint rows.
    pub(crate) fn new(generators: Vec<Generator>, targets: Vec<f64>, n: usize, m: usize) -> Self {
        let k = generators.len();
        Self {
            generators,
            targets,
            values: vec![0.0; k],
            xi: vec![0.0; k * n],
            mass_xi: vec![0.0; k * n],
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
        self.generators.is_empty()
    }

    fn len(&self) -> usize {
        self.generators.len()
    }

    /// `ξ_j`, `M ξ_j`, `g_j = P_E P ξ_j` and `L_j` at `(q, v)`, where `d`
    /// was just evaluated (and `momenta` updated); with `gradients`, also
    /// `∂L_j/∂q = Bᵀ M v + ∂(ξᵀ M(q) v)/∂q` (ξ frozen), the latter by
    /// polarization of `∂T/∂q`, exact for a `T` quadratic in `v`.
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
            let (xi, mass_xi) = (&mut self.xi[j * n..(j + 1) * n], &mut self.mass_xi[j * n..(j + 1) * n]);
            self.generators[j].at(q, xi);
            mass.mul(xi, mass_xi);
            self.values[j] = dot(mass_xi, v);
            d.jac_mul(model, xi, &mut self.rows[j * m..(j + 1) * m]);
        }
        if m > 0 {
            let mut rhs: [&mut [f64]; MAX_ROTATIONS] = Default::default();
            rhs.iter_mut().zip(self.rows.chunks_mut(m)).for_each(|(r, row)| *r = row);
            d.solve_many(&mut rhs[..k]);
        }
        for j in 0..k {
            let g = &mut self.g[j * n..(j + 1) * n];
            g.copy_from_slice(&self.xi[j * n..(j + 1) * n]);
            if m > 0 {
                d.add_weighted_jt(model, &self.rows[j * m..(j + 1) * m], -1.0, g);
            }
            momenta.project(g);
            if !gradients {
                continue;
            }
            let grad = &mut self.grad_q[j * n..(j + 1) * n];
            grad.fill(0.0);
            self.generators[j].add_transposed(&self.mass_v, grad);
            if model.mass().is_none() {
                let xi = &self.xi[j * n..(j + 1) * n];
                let (tv, txi) = (dot(v, &self.mass_v), dot(xi, &self.mass_xi[j * n..(j + 1) * n]));
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

    /// `W_ij = M ξ_i · g_j` (`k × k`, row-major into `out`): `g_j` moves
    /// `L_i` at this rate. Symmetric, since `P_E P` is M-self-adjoint.
    fn gram(&self, out: &mut [f64]) {
        let (k, n) = (self.len(), self.n);
        for i in 0..k {
            for j in 0..k {
                out[i * k + j] = dot(&self.mass_xi[i * n..(i + 1) * n], &self.g[j * n..(j + 1) * n]);
            }
        }
    }

    /// Zeroes row and column `first + j` of `a` (`size × size`) when `g_j`
    /// is negligible against `ξ_j` (`|g_j|²_M ≤ 10⁻¹² |ξ_j|²_M`): the
    /// rotation moves nothing the constraints and the linear momenta leave
    /// free, and its momentum follows from theirs.
    fn leave_out_if_degenerate(&self, j: usize, a: &mut [f64], size: usize, first: usize) {
        let n = self.n;
        let (xi, mass_xi) = (&self.xi[j * n..(j + 1) * n], &self.mass_xi[j * n..(j + 1) * n]);
        let i = first + j;
        if !(a[i * size + i] > 1e-12 * dot(xi, mass_xi)) {
            for l in 0..size {
                a[i * size + l] = 0.0;
                a[l * size + i] = 0.0;
            }
        }
    }

    /// Moves the velocities along the `g_j` so that every `L_j` is back at
    /// its target: exact, since `L` is linear in `v` at fixed `q`, and
    /// `Φ_q g_j = 0` leaves `Φ̇` as it is. For the `projection` method, at a
    /// state where [`update`](Self::update) was just called.
    pub(crate) fn restore(&self, v: &mut [f64]) {
        let k = self.len();
        let mut deviation = [0.0; MAX_ROTATIONS];
        deviation.iter_mut().zip(self.values.iter().zip(&self.targets)).for_each(|(d, (l, t))| *d = l - t);
        self.remove_along(&mut deviation[..k], v);
    }

    /// Makes `direction` (in the range of `P_E P`) M-orthogonal to the
    /// `g_j`, so that a step along it leaves every `L_j` as it is.
    pub(crate) fn orthogonalize(&self, direction: &mut [f64]) {
        let (k, n) = (self.len(), self.n);
        let mut along = [0.0; MAX_ROTATIONS];
        (0..k).for_each(|j| along[j] = dot(&self.mass_xi[j * n..(j + 1) * n], direction));
        self.remove_along(&mut along[..k], direction);
    }

    /// `x −= Σ κ_j g_j` with `W κ = rates`: what moves the `L_j` at `rates`.
    fn remove_along(&self, rates: &mut [f64], x: &mut [f64]) {
        let (k, n) = (self.len(), self.n);
        let mut w = [0.0; MAX_ROTATIONS * MAX_ROTATIONS];
        self.gram(&mut w);
        (0..k).for_each(|j| self.leave_out_if_degenerate(j, &mut w[..k * k], k, 0));
        let mut kappa = [0.0; MAX_ROTATIONS];
        solve_independent(&mut w[..k * k], k, rates, &mut kappa[..k]);
        for j in 0..k {
            x.iter_mut().zip(&self.g[j * n..(j + 1) * n]).for_each(|(x, g)| *x -= kappa[j] * g);
        }
    }

    /// `robust`'s energy law with the angular momenta held beside it: adds
    /// `−κ₀ (c P_E P M⁻¹Ψ_q, P_E P v) − Σ κ_j (0, g_j)` to `U`, which holds
    /// the other terms already, with `κ` such that `Ψ` and every `L_j − L_j⁰`
    /// decay at the rate `alpha` under the whole control. `energy` is
    /// whether the energy's direction may be used (not at rest). `rows` are
    /// two scratch vectors of `m`, `w` one of `n`.
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn hold<E: Evaluation>(
        &mut self,
        d: &E,
        v: &[f64],
        psi: f64,
        alpha: f64,
        c: f64,
        energy: impl Fn(f64, f64) -> bool,
        u_q: &mut [f64],
        u_v: &mut [f64],
        [y_v, y_w]: [&mut [f64]; 2],
        w: &mut [f64],
    ) {
        let (k, n) = (self.len(), self.n);
        let (mass, momenta) = (d.mass(), d.momenta());
        let grad = d.grad_potential();
        // The energy's direction: P_E P v and c P_E P M⁻¹Ψ_q.
        let (phi_dot, phi_t) = (d.phi_dot(), d.phi_t());
        y_v.iter_mut().zip(phi_dot).zip(phi_t).for_each(|((y, pd), pt)| *y = pd - pt);
        mass.solve(grad, w);
        d.jac_mul(w, y_w);
        d.solve_many(&mut [&mut *y_v, &mut *y_w]);
        self.energy_v.copy_from_slice(v);
        self.energy_q.copy_from_slice(w);
        d.add_weighted_jt_pair([y_v, y_w], [&mut self.energy_v, &mut self.energy_q]);
        momenta.project(&mut self.energy_v);
        momenta.project(&mut self.energy_q);
        self.energy_q.iter_mut().for_each(|x| *x *= c);
        // Rates of (Ψ, L_1 … L_k) along a change (δq, δv).
        let rate = |i: usize, dq: &[f64], dv: &[f64]| match i {
            0 => dot(grad, dq) + dot(&self.mass_v, dv),
            j => dot(&self.grad_q[(j - 1) * n..j * n], dq) + dot(&self.mass_xi[(j - 1) * n..j * n], dv),
        };
        let size = k + 1;
        let mut a = [0.0; (MAX_ROTATIONS + 1) * (MAX_ROTATIONS + 1)];
        let mut rhs = [0.0; MAX_ROTATIONS + 1];
        let whole = dot(v, &self.mass_v);
        for i in 0..size {
            a[i * size] = rate(i, &self.energy_q, &self.energy_v);
            for j in 1..size {
                a[i * size + j] = match i {
                    0 => dot(&self.mass_v, &self.g[(j - 1) * n..j * n]),
                    i => dot(&self.mass_xi[(i - 1) * n..i * n], &self.g[(j - 1) * n..j * n]),
                };
            }
            let deviation = if i == 0 { psi } else { self.values[i - 1] - self.targets[i - 1] };
            rhs[i] = alpha * deviation + rate(i, u_q, u_v);
        }
        // At rest, or with all the motion along the linear momenta, the
        // energy has no direction of its own: its row and column are left out.
        if !energy(a[0], whole) {
            for j in 0..size {
                a[j] = 0.0;
                a[j * size] = 0.0;
            }
            rhs[0] = 0.0;
        }
        for j in 0..k {
            self.leave_out_if_degenerate(j, &mut a[..size * size], size, 1);
        }
        let mut kappa = [0.0; MAX_ROTATIONS + 1];
        solve_independent(&mut a[..size * size], size, &mut rhs[..size], &mut kappa[..size]);
        // Bounded corrections, as the energy law caps its gain: the energy's
        // gain at most α, and the rotations' velocity change at most α |v|_M.
        let mut limit: f64 = 1.0;
        if kappa[0].abs() > alpha {
            limit = limit.min(alpha / kappa[0].abs());
        }
        let mut gram = [0.0; MAX_ROTATIONS * MAX_ROTATIONS];
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
    let mut scale = [0.0; MAX_ROTATIONS + 1];
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
    let mut rows: [usize; MAX_ROTATIONS + 1] = std::array::from_fn(|i| i);
    let mut cols: [usize; MAX_ROTATIONS + 1] = std::array::from_fn(|i| i);
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
        if !(best.0 > DEPENDENT) {
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
