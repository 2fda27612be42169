//! The tree's kinetic energy as one kinetic block of the model, in closed
//! form: `M(θ)` by composite rigid bodies, `Ṁ θ̇ − ∂T/∂θ` (Lagrange's
//! velocity terms) by the recursive Newton–Euler passes at `θ̈ = 0`, and
//! `∂T/∂θ_t = −(S_t ×ₘ V_t) · H_t`, `H_t` the momentum of the subtree.
//!
//! The last follows from `T = ½ Σ_b V_b · I_b V_b` in space axes: moving
//! joint `t` by `dθ` moves every body `b` of its subtree, which changes
//! `V_b` by `S_t ×ₘ (V_b − V_t) dθ` and `I_b` by `(S_t ×_f I_b − I_b S_t ×ₘ) dθ`;
//! the two `V_b` terms cancel, leaving `−(S_t ×ₘ V_t) · I_b V_b`.

use super::motion::Motion;
use super::{Shared, Work};
use crate::model::kinetic::KineticBlock;
use std::any::Any;
use std::sync::Arc;

pub(super) struct TreeKinetic(pub Arc<Shared>);

impl TreeKinetic {
    /// Fills the work's velocities and subtree momenta at `(θ, θ̇)` (and
    /// the Newton–Euler forces at `θ̈ = 0` when `forces`); returns `T`.
    fn passes(&self, work: &mut Work, q: &[f64], v: &[f64], forces: bool) -> f64 {
        let tree = &self.0.tree;
        work.kin.update(tree, q);
        let Work { kin, vel, acc, momentum, force, .. } = work;
        let mut energy = 0.0;
        for (t, node) in tree.nodes.iter().enumerate() {
            let at = &kin.nodes[t];
            let rate = v[node.coordinate];
            let (v0, a0) = node.parent.map_or((Motion::default(), Motion::default()), |p| (vel[p], acc[p]));
            vel[t] = v0.plus(at.s.scaled(rate));
            let h = at.inertia.times(vel[t]);
            energy += 0.5 * vel[t].dot(h);
            momentum[t] = h;
            if forces {
                // Ṡ_t = V_t ×ₘ S_t: the axis is carried by the parent.
                acc[t] = a0.plus(vel[t].cross(at.s).scaled(rate));
                force[t] = at.inertia.times(acc[t]).plus(vel[t].cross_wrench(h));
            }
        }
        for t in (0..tree.nodes.len()).rev() {
            if let Some(p) = tree.nodes[t].parent {
                momentum[p] = momentum[p].plus(momentum[t]);
                if forces {
                    force[p] = force[p].plus(force[t]);
                }
            }
        }
        energy
    }

    /// `∂T/∂θ_t = −(S_t ×ₘ V_t) · H_t`, after [`passes`](Self::passes).
    fn gradient(&self, work: &Work, t: usize) -> f64 {
        -work.kin.nodes[t].s.cross(work.vel[t]).dot(work.momentum[t])
    }

    /// `M(θ)` by composite rigid bodies, written into `put(i, j, value)` for every `i, j`.
    fn mass(&self, work: &mut Work, mut put: impl FnMut(usize, usize, f64)) {
        let tree = &self.0.tree;
        for (t, at) in work.kin.nodes.iter().enumerate() {
            work.composite[t] = at.inertia;
        }
        for t in (0..tree.nodes.len()).rev() {
            if let Some(p) = tree.nodes[t].parent {
                work.composite[p] = work.composite[p].plus(&work.composite[t]);
            }
        }
        for (t, node) in tree.nodes.iter().enumerate() {
            let f = work.composite[t].times(work.kin.nodes[t].s);
            let i = node.coordinate;
            put(i, i, work.kin.nodes[t].s.dot(f));
            let mut up = node.parent;
            while let Some(a) = up {
                let (j, m) = (tree.nodes[a].coordinate, work.kin.nodes[a].s.dot(f));
                put(i, j, m);
                put(j, i, m);
                up = tree.nodes[a].parent;
            }
        }
    }

    fn all(
        &self,
        q: &[f64],
        v: &[f64],
        grad_q: &mut [f64],
        mdot_v: &mut [f64],
        put: impl FnMut(usize, usize, f64),
    ) -> f64 {
        let mut work = self.0.lock();
        let energy = self.passes(&mut work, q, v, true);
        for (t, node) in self.0.tree.nodes.iter().enumerate() {
            let s = work.kin.nodes[t].s;
            let gradient = self.gradient(&work, t);
            grad_q[node.coordinate] += gradient;
            // Ṁ θ̇ = (Ṁ θ̇ − ∂T/∂θ) + ∂T/∂θ.
            mdot_v[node.coordinate] += s.dot(work.force[t]) + gradient;
        }
        self.mass(&mut work, put);
        energy
    }
}

impl KineticBlock for TreeKinetic {
    fn add_all(&self, q: &[f64], v: &[f64], mass: &mut [f64], grad_q: &mut [f64], mdot_v: &mut [f64]) -> f64 {
        let n = grad_q.len();
        self.all(q, v, grad_q, mdot_v, |i, j, m| mass[i * n + j] += m)
    }

    fn add_blocks(&self, q: &[f64], v: &[f64], blocks: &mut [f64], grad_q: &mut [f64], mdot_v: &mut [f64]) -> f64 {
        let k = self.0.tree.n;
        self.all(q, v, grad_q, mdot_v, |i, j, m| blocks[i * k + j] = m)
    }

    fn items(&self) -> usize {
        1
    }

    fn width(&self) -> usize {
        self.0.tree.n
    }

    fn coordinates(&self) -> Vec<Vec<u32>> {
        vec![(0..self.0.tree.n as u32).collect()]
    }

    fn energy(&self, q: &[f64], v: &[f64], grad_q: Option<&mut [f64]>) -> f64 {
        let mut work = self.0.lock();
        let energy = self.passes(&mut work, q, v, false);
        if let Some(g) = grad_q {
            for (t, node) in self.0.tree.nodes.iter().enumerate() {
                g[node.coordinate] += self.gradient(&work, t);
            }
        }
        energy
    }

    fn as_any_mut(&mut self) -> &mut dyn Any {
        self
    }
}
