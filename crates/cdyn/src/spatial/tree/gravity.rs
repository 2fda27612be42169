//! Uniform gravity on the tree as one potential block, in closed form:
//! `V = −g · Σ_b m_b c_b`, `∂V/∂θ_t = −S_t · (h_t × g, m_t g)` with `m_t`
//! and `h_t` the mass and first moment of joint `t`'s subtree, and, for
//! `t` on the path from the root to `u`,
//! `∂²V/∂θ_t∂θ_u = −g · (ω_t × (ω_u × h_u + m_u v_u))`: the velocity that
//! joint `u` gives the subtree's centre of mass, turned by joint `t`.

use super::motion::{V3, add, dot, scale};
use super::{Shared, Work};
use crate::model::force::PotentialBlock;
use crate::spatial::rotation::cross;
use std::any::Any;
use std::sync::Arc;

pub(super) struct TreeGravity {
    pub shared: Arc<Shared>,
    pub gravity: V3,
}

impl TreeGravity {
    /// `V`, with every subtree's mass and first moment left in the work.
    fn subtrees(&self, work: &mut Work, q: &[f64]) -> f64 {
        let tree = &self.shared.tree;
        work.kin.update(tree, q);
        let mut energy = 0.0;
        for (t, at) in work.kin.nodes.iter().enumerate() {
            work.subtree[t] = (at.inertia.mass, at.inertia.h);
            energy -= dot(self.gravity, at.inertia.h);
        }
        for t in (0..tree.nodes.len()).rev() {
            if let Some(p) = tree.nodes[t].parent {
                let (m, h) = work.subtree[t];
                work.subtree[p] = (work.subtree[p].0 + m, add(work.subtree[p].1, h));
            }
        }
        energy
    }
}

impl PotentialBlock for TreeGravity {
    fn energy_and_gradient(&self, q: &[f64], grad: &mut [f64]) -> f64 {
        let mut work = self.shared.lock();
        let energy = self.subtrees(&mut work, q);
        for (t, node) in self.shared.tree.nodes.iter().enumerate() {
            let ((m, h), s) = (work.subtree[t], work.kin.nodes[t].s);
            grad[node.coordinate] -= dot(s.w, cross(h, self.gravity)) + m * dot(s.v, self.gravity);
        }
        energy
    }

    fn energy(&self, q: &[f64]) -> f64 {
        let mut work = self.shared.lock();
        work.kin.update(&self.shared.tree, q);
        work.kin.nodes.iter().map(|at| -dot(self.gravity, at.inertia.h)).sum()
    }

    fn hessian_entries(&self, out: &mut Vec<(u32, u32)>) {
        let n = self.shared.tree.n as u32;
        out.extend((0..n).flat_map(|i| (0..n).map(move |j| (i, j))));
    }

    fn hessians(&self, q: &[f64], scale_by: f64, out: &mut [f64]) -> usize {
        let tree = &self.shared.tree;
        let n = tree.n;
        let mut work = self.shared.lock();
        self.subtrees(&mut work, q);
        out[..n * n].fill(0.0);
        for (u, node) in tree.nodes.iter().enumerate() {
            let ((m, h), su) = (work.subtree[u], work.kin.nodes[u].s);
            let moving = add(cross(su.w, h), scale(m, su.v));
            let (mut up, j) = (Some(u), node.coordinate);
            while let Some(t) = up {
                let i = tree.nodes[t].coordinate;
                let value = -scale_by * dot(self.gravity, cross(work.kin.nodes[t].s.w, moving));
                out[i * n + j] = value;
                out[j * n + i] = value;
                up = tree.nodes[t].parent;
            }
        }
        n * n
    }

    fn as_any_mut(&mut self) -> &mut dyn Any {
        self
    }
}

#[cfg(test)]
mod tests {
    use crate::spatial::{Body, Joint, JointKind, Mechanism};

    /// `∇²V` against central differences of the closed-form `∇V` (itself
    /// held to differences of `V` in `tests/joint_coordinates.rs`), on a
    /// chain of a revolute, a prismatic and a revolute joint on tilted
    /// axes, with a branch, at a few states.
    #[test]
    fn the_hessian_agrees_with_differences_of_the_gradient() {
        let body = |name: &str, r: [f64; 3]| Body::new(name, 1.3, [0.02, 0.03, 0.025]).with_position(r);
        let joint = |kind, a, b, point, axis| Joint::new(kind, a, b, point).with_axis(axis);
        let mechanism = Mechanism::new([0.4, -1.0, -9.81])
            .with_bodies(vec![body("a", [0.2, 0.0, -0.1]), body("b", [0.4, 0.1, -0.3]), body("c", [0.5, 0.3, -0.5])])
            .with_joints(vec![
                joint(JointKind::Revolute, 0, None, [0.0; 3], [0.0, 0.3, 1.0]),
                joint(JointKind::Prismatic, 1, Some(0), [0.3, 0.0, -0.2], [0.2, 1.0, 0.1]),
                joint(JointKind::Revolute, 2, Some(0), [0.4, 0.2, -0.4], [1.0, 0.0, 0.5]),
            ]);
        let model = mechanism.in_joint_coordinates().unwrap().model;
        let n = model.n();
        let mut entries = Vec::new();
        model.iteration_entries(&mut entries);
        assert_eq!(entries.len(), n * n);
        for q in [[0.3, -0.2, 1.1], [-1.4, 0.5, -0.7], [2.5, 0.05, 0.2]] {
            let mut hessian = vec![0.0; entries.len()];
            model.iteration_values(&q, &[0.0; 3], 0.0, 1.0, 0.0, &mut hessian);
            let gradient_at = |i: usize, s: f64| {
                let mut x = q;
                x[i] += s;
                let mut g = vec![0.0; n];
                model.potential(&x, Some(&mut g));
                g
            };
            for i in 0..n {
                let (plus, minus) = (gradient_at(i, 1e-6), gradient_at(i, -1e-6));
                for j in 0..n {
                    let fd = (plus[j] - minus[j]) / 2e-6;
                    let at = entries.iter().position(|&e| e == (j as u32, i as u32)).unwrap();
                    assert!((hessian[at] - fd).abs() < 1e-6, "∂²V/∂θ_{j}∂θ_{i} = {} vs {fd}", hessian[at]);
                }
            }
        }
    }
}
