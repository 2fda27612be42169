//! The benchmark's spatial chain ([`crate::spatial::chain`]: rods in Euler
//! parameters joined end to end by spherical joints, the first to a fixed
//! point) under the benchmark's control — CVSGF with `ζᵢ = α_g/(2|∇Φᵢ|²)`
//! and the gradient energy control with `ρ_v = α_e/(2|Ψ_v|²)`, applied by a
//! forward Euler step — and AB-3 with RK-4 start-up, written out by hand:
//!
//! * `M_p = 4GᵀJ′G + k ppᵀ = Eᵀ D E`, with `E = [G(p); pᵀ]` and
//!   `D = diag(4J′, k)`; since `E Eᵀ = |p|² I`, `M_p⁻¹ = Eᵀ D⁻¹ E / |p|⁴`;
//! * Lagrange's velocity terms `∂T/∂p − Ṁṗ = −4 G(ṗ)ᵀ J′ω′ − k|ṗ|² p`
//!   (`ω′ = 2G(p)ṗ`, and `G(a) b = −G(b) a`);
//! * `A(p) s` is a homogeneous quadratic in `p`, so its `∂/∂p` is linear in
//!   `p` and its second derivative along `ṗ` is `2 A(ṗ) s`, which gives `γ`;
//! * `S = Φ_q M⁻¹ Φ_qᵀ` is block tridiagonal, a 4 × 4 block per body (its
//!   joint's three rows and its normalization row `pᵀp − 1`), factored and
//!   solved by blocks in one pass down the chain and one back up.
//!
//! The `∫Ė` state is left out: without drives or non-conservative forces
//! cdyn's `Ė = λᵀΦ_t` is round-off. It is the floor the benchmark measures
//! cdyn's generic step against; a test holds it to cdyn's trajectory.

use crate::spatial::rotation::{body_rate, g_matrix, rotate_fixed};
use crate::{Application, Control, Energy, EnergyGain, Gain, Geometric, Scheme, Settings};

/// What one body contributes to an evaluation.
#[derive(Debug, Clone, Copy, Default)]
struct BodyTerms {
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
struct Block {
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
struct Chain {
    n: usize,
    mass: f64,
    gravity: f64,
    /// `J′` and `(4J′)⁻¹`, body axes; the normalization weight `k`.
    inertia: [[f64; 3]; 3],
    quarter_inverse: [[f64; 3]; 3],
    k: f64,
    /// The joint points in body axes: its top (towards the fixed point) and bottom.
    top: [f64; 3],
    bottom: [f64; 3],
    alpha_g: f64,
    alpha_e: f64,
    e0: f64,
    bodies: Vec<BodyTerms>,
    blocks: Vec<Block>,
}

/// The hand-written chain and its integrator.
#[derive(Debug, Clone)]
pub struct HandWrittenChain {
    /// The state `(q, v)` in cdyn's layout: body `b`'s `r` at `7b..7b + 3`,
    /// its `p` at `7b + 3..7b + 7`, all velocities after all positions.
    pub x: Vec<f64>,
    /// The step.
    pub h: f64,
    chain: Chain,
    /// `f` at the last three states, newest first.
    history: [Vec<f64>; 3],
    /// `U` at the current state, the RK-4 start-up's stages and state.
    u: Vec<f64>,
    stages: [Vec<f64>; 3],
    stage_x: Vec<f64>,
    steps: u64,
}

impl HandWrittenChain {
    /// The chain of `n` rods of `spatial::chain(n, theta0, g)` at rest,
    /// with step `h` and control rates `α_g`, `α_e`.
    pub fn new(n: usize, theta0: f64, g: f64, h: f64, alpha_g: f64, alpha_e: f64) -> Self {
        // The rods as the library's chain describes them: equal, uniform
        // (joined at their ends, their centres of mass between), body axes
        // the space axes at the start.
        let mechanism = crate::spatial::chain(n, theta0, g);
        let rod = &mechanism.bodies[0];
        let top: [f64; 3] = std::array::from_fn(|i| mechanism.joints[0].point[i] - rod.position[i]);
        let mut x = vec![0.0; 14 * n];
        for (b, body) in mechanism.bodies.iter().enumerate() {
            x[7 * b..7 * b + 3].copy_from_slice(&body.position);
            x[7 * b + 3..7 * b + 7].copy_from_slice(&body.orientation);
        }
        let inertia = rod.inertia;
        let j = nalgebra::Matrix3::from_fn(|a, b| inertia[a][b]);
        let j_inverse = j.try_inverse().expect("the chain's rods have a positive definite inertia");
        let quarter_inverse = std::array::from_fn(|a| std::array::from_fn(|b| 0.25 * j_inverse[(a, b)]));
        let k = 4.0 * (inertia[0][0] + inertia[1][1] + inertia[2][2]) / 3.0;
        let mut chain = Chain {
            n,
            mass: rod.mass,
            gravity: g,
            inertia,
            quarter_inverse,
            k,
            top,
            bottom: top.map(|x| -x),
            alpha_g,
            alpha_e,
            e0: 0.0,
            bodies: vec![BodyTerms::default(); n],
            blocks: vec![Block::default(); n],
        };
        chain.e0 = chain.energy(&x);
        Self {
            x,
            h,
            chain,
            history: std::array::from_fn(|_| vec![0.0; 14 * n]),
            u: vec![0.0; 14 * n],
            stages: std::array::from_fn(|_| vec![0.0; 14 * n]),
            stage_x: vec![0.0; 14 * n],
            steps: 0,
        }
    }

    /// cdyn's settings for what this integrator writes out: AB-3 at `h`,
    /// CVSGF at `α_g` and the gradient energy control at `α_e`, applied by
    /// a forward Euler step.
    pub fn settings(&self) -> Settings {
        let control = Control {
            geometric: Geometric::Gradient(Gain::Rate(self.chain.alpha_g)),
            energy: Energy::Gradient(EnergyGain::Rate { alpha_e: self.chain.alpha_e }),
            application: Application::ForwardEuler,
            ..Control::none()
        };
        Settings::new(Scheme::AdamsBashforth3, self.h, control)
    }

    /// Starts again from the state `x` (its energy the new `E₀`).
    pub fn restart(&mut self, x: &[f64]) {
        self.x.copy_from_slice(x);
        self.chain.e0 = self.chain.energy(x);
        self.steps = 0;
    }

    /// Advances [`x`](Self::x) by one step `h`.
    pub fn step(&mut self) {
        let h = self.h;
        self.history.rotate_right(1);
        self.chain.eval(&self.x, &mut self.history[0], Some(&mut self.u));
        if self.steps < 2 {
            // RK-4 start-up on f; the control's Euler step after it.
            let (x, f0, stage_x) = (&mut self.x, &self.history[0], &mut self.stage_x);
            let [k2, k3, k4] = &mut self.stages;
            let mut stage = |from: &[f64], c: f64, out: &mut [f64]| {
                for ((s, x), k) in stage_x.iter_mut().zip(x.iter()).zip(from) {
                    *s = x + c * h * k;
                }
                self.chain.eval(stage_x, out, None);
            };
            stage(f0, 0.5, k2);
            stage(k2, 0.5, k3);
            stage(k3, 1.0, k4);
            for i in 0..x.len() {
                x[i] += h * (f0[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]) / 6.0 + h * self.u[i];
            }
        } else {
            let [a, b, c] = &self.history;
            for i in 0..self.x.len() {
                self.x[i] += h * (23.0 * a[i] - 16.0 * b[i] + 5.0 * c[i]) / 12.0 + h * self.u[i];
            }
        }
        self.steps += 1;
    }
}

impl Chain {
    /// `T + V` at the state `x`.
    fn energy(&self, x: &[f64]) -> f64 {
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
    fn body_energy(&self, z: f64, rd: &[f64], pd: [f64; 4], momentum_p: &[f64; 4]) -> f64 {
        0.5 * self.mass * dot(rd, rd) + 0.5 * dot(&pd, momentum_p) + self.mass * self.gravity * z
    }

    /// `J′ω′`, `ω′ = 2 G(p) ṗ`.
    #[inline(always)]
    fn body_rate_inertia(&self, p: [f64; 4], pd: [f64; 4]) -> [f64; 3] {
        let w = body_rate(p, pd);
        std::array::from_fn(|a| dot(&self.inertia[a], &w))
    }

    /// `M_p ṗ = Eᵀ D E ṗ = 2 G(p)ᵀ J′ω′ + k (pᵀṗ) p`.
    #[inline(always)]
    fn momentum(&self, p: [f64; 4], pd: [f64; 4], j_omega: &[f64; 3]) -> [f64; 4] {
        let (g, along) = (g_matrix(p), self.k * dot(&p, &pd));
        std::array::from_fn(|j| 2.0 * (0..3).map(|a| g[a][j] * j_omega[a]).sum::<f64>() + along * p[j])
    }

    /// Evaluates `f = (v, A)` at `x`, and the control term `U` when asked.
    fn eval(&mut self, x: &[f64], f: &mut [f64], mut u: Option<&mut [f64]>) {
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
            let top = d_rotate(p, self.top);
            let bottom = d_rotate(p, self.bottom).map(|row| row.map(|x| -x));
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

/// `∂(A(p) s)/∂p`, row by row: `A(p) s = (e₀² − eᵀe) s + 2e(eᵀs) + 2e₀(e × s)`
/// gives `2(e₀ s + e × s)` for `e₀` and `2((eᵀs) I + e sᵀ − s eᵀ − e₀ [s]×)` for `e`.
#[inline(always)]
fn d_rotate([e0, e1, e2, e3]: [f64; 4], s: [f64; 3]) -> [[f64; 4]; 3] {
    let e = [e1, e2, e3];
    let es = dot(&e, &s);
    let cross = [e2 * s[2] - e3 * s[1], e3 * s[0] - e1 * s[2], e1 * s[1] - e2 * s[0]];
    // [s]× e = s × e, so row i of [s]× is ∂(s × e)_i/∂e.
    let skew = [[0.0, -s[2], s[1]], [s[2], 0.0, -s[0]], [-s[1], s[0], 0.0]];
    std::array::from_fn(|i| {
        let mut row = [2.0 * (e0 * s[i] + cross[i]), 0.0, 0.0, 0.0];
        for j in 0..3 {
            let identity = if i == j { es } else { 0.0 };
            row[j + 1] = 2.0 * (identity + e[i] * s[j] - s[i] * e[j] - e0 * skew[i][j]);
        }
        row
    })
}

#[inline(always)]
fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(a, b)| a * b).sum()
}

fn quaternion(x: &[f64]) -> [f64; 4] {
    [x[0], x[1], x[2], x[3]]
}

/// The Cholesky factor of the lower triangle of `s`.
#[inline(always)]
fn cholesky(s: &[[f64; 4]; 4]) -> [[f64; 4]; 4] {
    let mut l = [[0.0; 4]; 4];
    for j in 0..4 {
        let d = (s[j][j] - (0..j).map(|k| l[j][k] * l[j][k]).sum::<f64>()).sqrt();
        l[j][j] = d;
        for i in j + 1..4 {
            l[i][j] = (s[i][j] - (0..j).map(|k| l[i][k] * l[j][k]).sum::<f64>()) / d;
        }
    }
    l
}

/// `L⁻¹ x`
#[inline(always)]
fn forward(l: &[[f64; 4]; 4], mut x: [f64; 4]) -> [f64; 4] {
    for i in 0..4 {
        x[i] = (x[i] - (0..i).map(|k| l[i][k] * x[k]).sum::<f64>()) / l[i][i];
    }
    x
}

/// `L⁻ᵀ x`
#[inline(always)]
fn backward(l: &[[f64; 4]; 4], mut x: [f64; 4]) -> [f64; 4] {
    for i in (0..4).rev() {
        x[i] = (x[i] - (i + 1..4).map(|k| l[k][i] * x[k]).sum::<f64>()) / l[i][i];
    }
    x
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Simulation;
    use crate::spatial::rotation::rotate;

    #[test]
    fn the_rotation_jacobian_is_the_derivative_of_the_rotation() {
        let (p, s) = ([0.9, -0.3, 0.25, 0.4], [0.3, -1.1, 0.7]);
        let jac = d_rotate(p, s);
        for j in 0..4 {
            let h = 1e-6;
            let at = |d: f64| rotate(std::array::from_fn(|i| p[i] + if i == j { d } else { 0.0 }), s);
            let (plus, minus) = (at(h), at(-h));
            for i in 0..3 {
                let fd = (plus[i] - minus[i]) / (2.0 * h);
                assert!((jac[i][j] - fd).abs() < 1e-9, "∂(As)_{i}/∂p_{j}: {} against {fd}", jac[i][j]);
            }
        }
    }

    /// The hand-written chain and cdyn's, with the benchmark's control,
    /// through the RK-4 start-up and 2 s of AB-3, from rest (a plane swing)
    /// and turning about the vertical (a swing in three dimensions, where the
    /// rods' gyroscopic terms act).
    #[test]
    fn the_hand_written_chain_follows_cdyns_trajectory() {
        let h = 1e-3;
        for (n, spin) in [(1, 0.0), (4, 0.0), (60, 0.0), (1, 0.7), (4, 0.7), (60, 0.3)] {
            let built = crate::spatial::chain(n, 0.3, 1.0).build().unwrap();
            // A rigid turn at `spin` about the z axis through the fixed point: ṙ = Ω × r, ω′ = Ω (body axes are space axes).
            let mut v0 = built.v0.clone();
            for b in 0..n {
                let r = &built.q0[7 * b..7 * b + 3];
                v0[7 * b..7 * b + 3].copy_from_slice(&[-spin * r[1], spin * r[0], 0.0]);
                let p = quaternion(&built.q0[7 * b + 3..]);
                v0[7 * b + 3..7 * b + 7]
                    .copy_from_slice(&crate::spatial::rotation::rate_from_body(p, [0.0, 0.0, spin]));
            }
            let mut hand = HandWrittenChain::new(n, 0.3, 1.0, h, 0.4 / h, 0.4 / h);
            let mut sim = Simulation::new(&built.model, hand.settings(), &built.q0, &v0).unwrap();
            let x0: Vec<f64> = built.q0.iter().chain(&v0).copied().collect();
            let distance = |a: &[f64], b: &[f64]| a.iter().zip(b).fold(0.0_f64, |m, (x, y)| m.max((x - y).abs()));
            assert!(distance(&hand.x, &built.q0.iter().chain(&built.v0).copied().collect::<Vec<_>>()) < 1e-15);
            hand.restart(&x0);
            let mut worst = 0.0_f64;
            for _ in 0..2000 {
                sim.step().unwrap();
                hand.step();
                let (q, v) = hand.x.split_at(7 * n);
                worst = worst.max(distance(q, sim.q())).max(distance(v, sim.v()));
            }
            let moved = distance(&hand.x, &x0);
            eprintln!("N = {n}, Ω = {spin}: hand-written against cdyn {worst:e} (moved {moved:.3})");
            assert!(moved > 0.1, "N = {n}: the chain moved only {moved}");
            assert!(worst < 1e-10, "N = {n}, Ω = {spin}: the trajectories differ by {worst:e}");
        }
    }
}
