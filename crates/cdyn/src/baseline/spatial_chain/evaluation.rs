//! One evaluation of the hand-written chain: the bodies' terms, the block
//! tridiagonal factorization of `S` and its solves, the multipliers, the
//! accelerations and the control term.

use super::blocks::{backward, cholesky, dot, forward, quaternion};
use crate::spatial::rotation::{body_rate, g_matrix, rotate_fixed, rotate_jacobian};

/// What one body contributes to an evaluation.
#[derive(Debug, Clone, Copy, Default)]
pub(super) struct BodyTerms {
    /// `∂Φ/∂p` of the joint at the body's top (its own), row by row, and of
    /// the joint at its bottom (the next body's, whose rows subtract it).
    top: [[f64; 4]; 3],
    bottom: [[f64; 4]; 3],
    /// `M_p⁻¹` times each of those rows, and times `2p` (the normalization's gradient).
    w_top: [[f64; 4]; 3],
    w_bottom: [[f64; 4]; 3],
    w_norm: [f64; 4],
    /// `M_p⁻¹ (∂T/∂p − Ṁṗ)`: the unconstrained acceleration of `p`.
    free_p: [f64; 4],
    /// `A(p) s` and `2 A(ṗ) s` at the bottom point.
    at_bottom: [f64; 3],
    curve_bottom: [f64; 3],
    /// `M_p ṗ`
    momentum_p: [f64; 4],
}

/// One body's block of the factorization: its joint's rows 0–2, its normalization row 3.
#[derive(Debug, Clone, Copy, Default)]
pub(super) struct Block {
    /// `L_bb`, lower triangle.
    l: [[f64; 4]; 4],
    /// `L_b,b−1`: the joint's rows against the block above (its normalization column included).
    above: [[f64; 4]; 3],
    /// The right-hand side, forward-solved, then the multipliers.
    y: [f64; 4],
    /// `Φ / |∇Φ|²` of the four rows (the CVSGF direction's weights).
    phi_over_g2: [f64; 4],
}

/// The model, control and work space of one evaluation.
#[derive(Debug, Clone)]
pub(super) struct Chain {
    pub(super) n: usize,
    pub(super) mass: f64,
    pub(super) gravity: f64,
    /// `J′` and `(4J′)⁻¹`, body axes; the normalization weight `k`.
    pub(super) inertia: [[f64; 3]; 3],
    pub(super) quarter_inverse: [[f64; 3]; 3],
    pub(super) k: f64,
    /// The joint points in body axes: its top (towards the fixed point) and bottom.
    pub(super) top: [f64; 3],
    pub(super) bottom: [f64; 3],
    pub(super) alpha_g: f64,
    pub(super) alpha_e: f64,
    pub(super) e0: f64,
    pub(super) bodies: Vec<BodyTerms>,
    pub(super) blocks: Vec<Block>,
}

impl Chain {
    /// `T + V` at the state `x`.
    pub(super) fn energy(&self, x: &[f64]) -> f64 {
        let (q, v) = x.split_at(7 * self.n);
        (0..self.n)
            .map(|b| {
                let (p, pd) = (quaternion(&q[7 * b + 3..]), quaternion(&v[7 * b + 3..]));
                let momentum_p = self.momentum(p, pd, &self.body_rate_inertia(p, pd));
                self.body_energy(q[7 * b + 2], &v[7 * b..7 * b + 3], pd, &momentum_p)
            })
            .sum()
    }

    /// One body's `T + V` at height `z`, from its velocities and `M_p ṗ`.
    #[inline(always)]
    pub(super) fn body_energy(&self, z: f64, rd: &[f64], pd: [f64; 4], momentum_p: &[f64; 4]) -> f64 {
        0.5 * self.mass * dot(rd, rd) + 0.5 * dot(&pd, momentum_p) + self.mass * self.gravity * z
    }

    /// `J′ω′`, `ω′ = 2 G(p) ṗ`.
    #[inline(always)]
    pub(super) fn body_rate_inertia(&self, p: [f64; 4], pd: [f64; 4]) -> [f64; 3] {
        let w = body_rate(p, pd);
        std::array::from_fn(|a| dot(&self.inertia[a], &w))
    }

    /// `M_p ṗ = Eᵀ D E ṗ = 2 G(p)ᵀ J′ω′ + k (pᵀṗ) p`.
    #[inline(always)]
    pub(super) fn momentum(&self, p: [f64; 4], pd: [f64; 4], j_omega: &[f64; 3]) -> [f64; 4] {
        let (g, along) = (g_matrix(p), self.k * dot(&p, &pd));
        std::array::from_fn(|j| 2.0 * (0..3).map(|a| g[a][j] * j_omega[a]).sum::<f64>() + along * p[j])
    }

    /// Evaluates `f = (v, A)` at `x`, and the control term `U` when asked.
    pub(super) fn eval(&mut self, x: &[f64], f: &mut [f64], mut u: Option<&mut [f64]>) {
        let n = self.n;
        let (q, v) = x.split_at(7 * n);
        let (fq, fv) = f.split_at_mut(7 * n);
        fq.copy_from_slice(v);
        let (inv_m, free_r) = (1.0 / self.mass, [0.0, 0.0, -self.gravity]);
        let delta = |k: usize, l: usize| if k == l { inv_m } else { 0.0 };
        let (mut energy, mut momentum2) = (0.0, 0.0);
        // Down the chain: each body's terms, its block of S assembled, factored and forward-solved.
        for b in 0..n {
            let (r, p, rd, pd) =
                (&q[7 * b..7 * b + 3], quaternion(&q[7 * b + 3..]), &v[7 * b..7 * b + 3], quaternion(&v[7 * b + 3..]));
            let (pp, pd2) = (dot(&p, &p), dot(&pd, &pd));
            let g = g_matrix(p);
            // D⁻¹E, then M_p⁻¹ = Eᵀ (D⁻¹E) / |p|⁴.
            let mut de: [[f64; 4]; 4] = [[0.0; 4]; 4];
            for a in 0..3 {
                de[a] = std::array::from_fn(|j| (0..3).map(|c| self.quarter_inverse[a][c] * g[c][j]).sum());
            }
            de[3] = p.map(|x| x / self.k);
            let scale = 1.0 / (pp * pp);
            let inverse: [[f64; 4]; 4] = std::array::from_fn(|i| {
                std::array::from_fn(|j| scale * ((0..3).map(|a| g[a][i] * de[a][j]).sum::<f64>() + p[i] * de[3][j]))
            });
            let times = |x: &[f64; 4]| -> [f64; 4] { std::array::from_fn(|i| dot(&inverse[i], x)) };
            let j_omega = self.body_rate_inertia(p, pd);
            let gd = g_matrix(pd);
            let lagrange: [f64; 4] = std::array::from_fn(|j| {
                -4.0 * (0..3).map(|a| gd[a][j] * j_omega[a]).sum::<f64>() - self.k * pd2 * p[j]
            });
            let momentum_p = self.momentum(p, pd, &j_omega);
            energy += self.body_energy(r[2], rd, pd, &momentum_p);
            momentum2 += self.mass * self.mass * dot(rd, rd) + dot(&momentum_p, &momentum_p);
            let top = rotate_jacobian(p, self.top);
            let bottom = rotate_jacobian(p, self.bottom).map(|row| row.map(|x| -x));
            let terms = BodyTerms {
                top,
                bottom,
                w_top: top.map(|row| times(&row)),
                w_bottom: bottom.map(|row| times(&row)),
                w_norm: times(&p.map(|x| 2.0 * x)),
                free_p: times(&lagrange),
                at_bottom: rotate_fixed(p, self.bottom),
                curve_bottom: rotate_fixed(pd, self.bottom).map(|x| 2.0 * x),
                momentum_p,
            };
            let (at_top, curve_top) = (rotate_fixed(p, self.top), rotate_fixed(pd, self.top).map(|x| 2.0 * x));
            // The joint's rows and the normalization row: S_bb and the right-hand side Φ_q M⁻¹G − γ.
            let mut s = [[0.0; 4]; 4];
            let mut c = [0.0; 4];
            let mut phi = [0.0; 4];
            let mut g2 = [0.0; 4];
            for k in 0..3 {
                for l in 0..=k {
                    s[k][l] = dot(&top[k], &terms.w_top[l]) + delta(k, l);
                }
                s[3][k] = dot(&top[k], &terms.w_norm);
                c[k] = dot(&top[k], &terms.free_p) + curve_top[k];
                phi[k] = r[k] + at_top[k];
                g2[k] = 1.0 + dot(&top[k], &top[k]);
            }
            s[3][3] = 2.0 * dot(&p, &terms.w_norm);
            c[3] = 2.0 * dot(&p, &terms.free_p) + 2.0 * pd2;
            (phi[3], g2[3]) = (pp - 1.0, 4.0 * pp);
            let mut above = [[0.0; 4]; 3];
            if b == 0 {
                (0..3).for_each(|k| c[k] += free_r[k]);
            } else {
                // The joint also reads the body above (its bottom point), which couples it to that block.
                let up = &self.bodies[b - 1];
                let r_up = &q[7 * (b - 1)..7 * b - 4];
                for k in 0..3 {
                    for l in 0..=k {
                        s[k][l] += dot(&up.bottom[k], &up.w_bottom[l]) + delta(k, l);
                    }
                    c[k] += dot(&up.bottom[k], &up.free_p) - up.curve_bottom[k];
                    phi[k] -= r_up[k] + up.at_bottom[k];
                    g2[k] += 1.0 + dot(&up.bottom[k], &up.bottom[k]);
                    let coupling: [f64; 4] = std::array::from_fn(|l| {
                        if l < 3 {
                            dot(&up.bottom[k], &up.w_top[l]) - delta(k, l)
                        } else {
                            dot(&up.bottom[k], &up.w_norm)
                        }
                    });
                    above[k] = forward(&self.blocks[b - 1].l, coupling);
                }
                let y_up = self.blocks[b - 1].y;
                for k in 0..3 {
                    for l in 0..=k {
                        s[k][l] -= dot(&above[k], &above[l]);
                    }
                    c[k] -= dot(&above[k], &y_up);
                }
            }
            let l = cholesky(&s);
            self.blocks[b] =
                Block { l, above, y: forward(&l, c), phi_over_g2: std::array::from_fn(|i| phi[i] / g2[i]) };
            self.bodies[b] = terms;
        }
        let psi = energy - self.e0;
        let kappa = if momentum2 > 1e-30 { self.alpha_e * psi / momentum2 } else { 0.0 };
        // Back up: the multipliers, the accelerations and the control term.
        for b in (0..n).rev() {
            let (lambda_below, weights_below) = match self.blocks.get(b + 1) {
                Some(next) => (next.y, next.phi_over_g2),
                None => ([0.0; 4], [0.0; 4]),
            };
            let mut y = self.blocks[b].y;
            if b + 1 < n {
                let below = &self.blocks[b + 1].above;
                for l in 0..4 {
                    y[l] -= (0..3).map(|k| below[k][l] * lambda_below[k]).sum::<f64>();
                }
            }
            let lambda = backward(&self.blocks[b].l, y);
            self.blocks[b].y = lambda;
            let t = &self.bodies[b];
            for k in 0..3 {
                fv[7 * b + k] = free_r[k] - (lambda[k] - lambda_below[k]) * inv_m;
            }
            for j in 0..4 {
                fv[7 * b + 3 + j] = t.free_p[j]
                    - (0..3).map(|k| t.w_top[k][j] * lambda[k] + t.w_bottom[k][j] * lambda_below[k]).sum::<f64>()
                    - t.w_norm[j] * lambda[3];
            }
            if let Some(u) = u.as_deref_mut() {
                let (w, p) = (self.blocks[b].phi_over_g2, quaternion(&q[7 * b + 3..]));
                let (uq, uv) = u.split_at_mut(7 * n);
                for k in 0..3 {
                    uq[7 * b + k] = -self.alpha_g * (w[k] - weights_below[k]);
                    uv[7 * b + k] = -kappa * self.mass * v[7 * b + k];
                }
                for j in 0..4 {
                    let along = (0..3).map(|k| t.top[k][j] * w[k] + t.bottom[k][j] * weights_below[k]).sum::<f64>();
                    uq[7 * b + 3 + j] = -self.alpha_g * (along + 2.0 * p[j] * w[3]);
                    uv[7 * b + 3 + j] = -kappa * t.momentum_p[j];
                }
            }
        }
    }
}
