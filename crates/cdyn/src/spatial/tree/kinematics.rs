//! The tree's poses and motion subspaces at joint coordinates `θ`, by
//! products of exponentials: joint `t` moves its subtree by a screw about
//! (along) its axis as its parent's motion has carried it, so with
//! `G_t = exp(S_t θ_t) G_λ(t)` every column `S_t` of the motion subspace
//! is the joint's initial screw moved by its parent's displacement, in
//! space axes, and each node's bodies are its initial inertia moved by `G_t`.

use super::Tree;
use super::motion::{Inertia, M3, Motion, V3, add, product, rotation, scale, times};
use crate::spatial::rotation::cross;

/// One node (a joint with a coordinate) at `θ`.
#[derive(Debug, Clone, Copy, Default)]
pub(super) struct At {
    /// `G_t`: `x ↦ r x + p`, the displacement of the node's bodies from the initial pose.
    pub r: M3,
    pub p: V3,
    /// The joint's column of the motion subspace.
    pub s: Motion,
    /// The node's own bodies' inertia at the origin.
    pub inertia: Inertia,
}

/// The nodes at the last `θ` asked for, kept while `θ` does not change
/// (the potential and the kinetic energy are evaluated at the same `q`).
#[derive(Debug, Clone)]
pub(super) struct Kinematics {
    theta: Vec<f64>,
    fresh: bool,
    pub nodes: Vec<At>,
}

const IDENTITY: M3 = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];

impl Kinematics {
    pub fn new(tree: &Tree) -> Self {
        Self { theta: vec![0.0; tree.n], fresh: false, nodes: vec![At::default(); tree.nodes.len()] }
    }

    /// Brings the nodes to `q` (the model's coordinates, `θ` among them).
    pub fn update(&mut self, tree: &Tree, q: &[f64]) {
        let theta = &q[..tree.n];
        if self.fresh && self.theta == theta {
            return;
        }
        self.fresh = false;
        self.theta.copy_from_slice(theta);
        for (t, node) in tree.nodes.iter().enumerate() {
            let (r0, p0) = match node.parent {
                Some(parent) => (self.nodes[parent].r, self.nodes[parent].p),
                None => (IDENTITY, [0.0; 3]),
            };
            let axis = times(&r0, node.axis);
            let angle = theta[node.coordinate];
            let (s, r, p) = if node.rotary {
                let point = add(times(&r0, node.point), p0);
                let turn = rotation(axis, angle);
                // x ↦ Q (x − P) + P after G_λ.
                let p = add(times(&turn, [p0[0] - point[0], p0[1] - point[1], p0[2] - point[2]]), point);
                (Motion { w: axis, v: cross(point, axis) }, product(&turn, &r0), p)
            } else {
                (Motion { w: [0.0; 3], v: axis }, r0, add(p0, scale(angle, axis)))
            };
            self.nodes[t] = At { r, p, s, inertia: node.inertia.moved(&r, p) };
        }
        self.fresh = true;
    }
}
