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
//!
//! Here the chain and its integrator; `evaluation` one evaluation of
//! `f` and `U` by blocks; `blocks` the 4 × 4 algebra of one body.
//!
//! May import: `integrate`, `control`, `simulate`, `spatial`.

mod blocks;
mod evaluation;

use crate::{Application, Control, Energy, EnergyGain, Gain, Geometric, Scheme, Settings};
use evaluation::{Block, BodyTerms, Chain};

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

#[cfg(test)]
mod tests {
    use super::blocks::quaternion;
    use super::*;
    use crate::Simulation;

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
