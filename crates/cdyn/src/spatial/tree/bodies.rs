//! The bodies' poses at joint coordinates, in the mechanism's own body
//! coordinates (`r`, then Euler parameters `p`, seven per body): what a
//! run in joint coordinates records and draws, the same columns as a run
//! in body coordinates. Each node's rotation is composed as a unit
//! quaternion from the root, by half angles, so that the Euler parameters
//! are continuous in `θ` (a rotation matrix's quaternion has a sign to choose).

use super::kinematics::Kinematics;
use super::motion::times;
use super::{Shared, Tree};
use crate::spatial::rotation::{about, compose};
use std::sync::Arc;

/// Reads the bodies' poses at `θ` without allocating.
#[derive(Debug, Clone)]
pub struct BodyPoses {
    tree: Tree,
    kin: Kinematics,
    turns: Vec<[f64; 4]>,
}

impl BodyPoses {
    pub(super) fn new(shared: &Arc<Shared>) -> Self {
        let tree = shared.tree.clone();
        Self { kin: Kinematics::new(&tree), turns: vec![[1.0, 0.0, 0.0, 0.0]; tree.nodes.len()], tree }
    }

    /// How many values [`at`](Self::at) writes: seven per body.
    pub fn len(&self) -> usize {
        7 * self.tree.bodies.len()
    }

    /// Whether the mechanism has no bodies (it always has one).
    pub fn is_empty(&self) -> bool {
        self.tree.bodies.is_empty()
    }

    /// Writes every body's `(r, p)` at the joint coordinates `q` into `out`.
    pub fn at(&mut self, q: &[f64], out: &mut [f64]) {
        self.kin.update(&self.tree, q);
        for (t, node) in self.tree.nodes.iter().enumerate() {
            let parent = node.parent.map_or([1.0, 0.0, 0.0, 0.0], |p| self.turns[p]);
            self.turns[t] = if node.rotary {
                // The axis as the parent has carried it: S_t's ω.
                compose(about(self.kin.nodes[t].s.w, q[node.coordinate]), parent)
            } else {
                parent
            };
        }
        for ((carrier, r0, p0), out) in self.tree.bodies.iter().zip(out.chunks_exact_mut(7)) {
            let (r, p) = match carrier {
                None => (*r0, *p0),
                Some(t) => {
                    let at = &self.kin.nodes[*t];
                    let c = times(&at.r, *r0);
                    ([c[0] + at.p[0], c[1] + at.p[1], c[2] + at.p[2]], compose(self.turns[*t], *p0))
                }
            };
            out[..3].copy_from_slice(&r);
            out[3..].copy_from_slice(&p);
        }
    }
}
