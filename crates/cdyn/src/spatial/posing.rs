//! A mechanism's initial state at given joint coordinates and rates, by
//! forward kinematics over a spanning tree of its joints.
//!
//! Exact, not iterated: each joint's motion (a rotation about its axis
//! through its point, or a slide along the axis) is applied to the bodies
//! beyond it, the deepest joints first and each in the pose where the
//! mechanism is defined, which composes them as a chain does (a joint's
//! axis moved by the joints before it is the same motion conjugated). The
//! joints then read back the given values to round-off, where adding rows
//! `θ = value` and solving the assembly by Newton would read them back to
//! its tolerance. Joints that close loops are not in the tree; the loop
//! rows are left to the assembly.

use super::joint::{Joint, JointKind};
use super::mechanism::Mechanism;
use super::rotation::{about, compose, cross, rate_from_body, rotate, unrotate};
use crate::error::{Problem, Result};

/// A joint of the tree: its index, the body beyond it, the body (or the
/// ground) before it, and `+1` when the body beyond is `a` (`θ` measures
/// `a` relative to `b`), `−1` when it is `b`.
pub(super) struct Edge {
    pub joint: usize,
    pub beyond: usize,
    pub before: Option<usize>,
    pub sign: f64,
}

impl Mechanism {
    /// The initial positions and velocities with revolute and prismatic
    /// joints at the `coordinates` `(joint, θ)` and `rates` `(joint, θ̇)`
    /// (as [`Mechanism::joint_coordinates`] counts them, from the pose the
    /// mechanism is defined in): the bodies beyond each joint, on a
    /// spanning tree of the joints from the ground, turned (slid) by
    /// forward kinematics. With rates given, every body's velocity is the
    /// joints' (the bodies' own velocities are not added); without, the
    /// bodies keep their own, carried along. A joint not given stays at 0.
    /// Refused: a joint that is not revolute or prismatic, or that closes a
    /// loop (its coordinate follows from the others).
    pub fn state_at_joints(
        &self,
        coordinates: &[(usize, f64)],
        rates: &[(usize, f64)],
    ) -> Result<(Vec<f64>, Vec<f64>)> {
        let edges = self.spanning_tree();
        for &(joint, value) in coordinates.iter().chain(rates) {
            let j = self.joints.get(joint).ok_or(Problem::NoSuchJoint { index: joint })?;
            if !matches!(j.kind, JointKind::Revolute | JointKind::Prismatic) {
                return Err(Problem::NoCoordinate { index: joint, kind: j.kind.name() }.into());
            }
            crate::error::finite("joint coordinate", value)?;
            if !edges.iter().any(|e| e.joint == joint) {
                let reason = format!("joint {joint} closes a loop: its coordinate follows from the other joints'");
                return Err(Problem::Posing { reason }.into());
            }
        }
        let value =
            |list: &[(usize, f64)], joint: usize| list.iter().filter(|e| e.0 == joint).map(|e| e.1).sum::<f64>();
        let mut poses = Vec::with_capacity(self.bodies.len());
        for body in &self.bodies {
            poses.push((body.position, body.check()?));
        }
        let defined = poses.clone();
        // Deepest joints first, each in the defined pose.
        for edge in edges.iter().rev() {
            let theta = edge.sign * value(coordinates, edge.joint);
            if theta == 0.0 {
                continue;
            }
            let (point, axis) = line(&self.joints[edge.joint]);
            for k in self.beyond(&edges, edge.beyond) {
                let (r, p) = &mut poses[k];
                if self.joints[edge.joint].kind == JointKind::Revolute {
                    let turn = about(axis, theta);
                    let arm = rotate(turn, std::array::from_fn(|i| r[i] - point[i]));
                    *r = std::array::from_fn(|i| point[i] + arm[i]);
                    *p = compose(turn, *p);
                } else {
                    *r = std::array::from_fn(|i| r[i] + theta * axis[i]);
                }
            }
        }
        // The bodies' velocities: the joints' twists, root first, each about
        // its axis as placed (carried by the body before it).
        let mut twists: Vec<([f64; 3], [f64; 3])> = if rates.is_empty() {
            self.bodies.iter().zip(&poses).map(|(b, (_, p))| (b.velocity, rotate(*p, b.angular_velocity))).collect()
        } else {
            vec![([0.0; 3], [0.0; 3]); self.bodies.len()]
        };
        for edge in &edges {
            let rate = edge.sign * value(rates, edge.joint);
            if rate == 0.0 {
                continue;
            }
            let (point, axis) = line(&self.joints[edge.joint]);
            let (point, axis) = match edge.before {
                None => (point, axis),
                Some(k) => {
                    let ((r0, p0), (r, p)) = (defined[k], poses[k]);
                    let arm = rotate(p, unrotate(p0, std::array::from_fn(|i| point[i] - r0[i])));
                    (std::array::from_fn(|i| r[i] + arm[i]), rotate(p, unrotate(p0, axis)))
                }
            };
            for k in self.beyond(&edges, edge.beyond) {
                let (v, w) = &mut twists[k];
                if self.joints[edge.joint].kind == JointKind::Revolute {
                    let spin = cross(axis, std::array::from_fn(|i| poses[k].0[i] - point[i]));
                    (0..3).for_each(|i| (w[i], v[i]) = (w[i] + rate * axis[i], v[i] + rate * spin[i]));
                } else {
                    (0..3).for_each(|i| v[i] += rate * axis[i]);
                }
            }
        }
        let (mut q, mut v) = (Vec::with_capacity(7 * poses.len()), Vec::with_capacity(7 * poses.len()));
        for ((r, p), (rd, w)) in poses.into_iter().zip(twists) {
            q.extend(r.into_iter().chain(p));
            v.extend(rd.into_iter().chain(rate_from_body(p, unrotate(p, w))));
        }
        Ok((q, v))
    }

    /// The joints of a spanning tree, breadth first from the ground and
    /// then from each body no joint holds to it, in joint order.
    pub(super) fn spanning_tree(&self) -> Vec<Edge> {
        let mut reached = vec![false; self.bodies.len()];
        let mut edges = Vec::new();
        let mut frontier: Vec<Option<usize>> = vec![None];
        let mut roots = 0..self.bodies.len();
        loop {
            let mut next = Vec::new();
            for &from in &frontier {
                for (joint, j) in self.joints.iter().enumerate() {
                    let (beyond, sign) = match (from, j.b) {
                        (f, b) if f == b && !reached[j.a] => (j.a, 1.0),
                        (Some(f), Some(b)) if f == j.a && !reached[b] => (b, -1.0),
                        _ => continue,
                    };
                    reached[beyond] = true;
                    edges.push(Edge { joint, beyond, before: from, sign });
                    next.push(Some(beyond));
                }
            }
            if next.is_empty() {
                match roots.find(|&k| !reached[k]) {
                    Some(root) => {
                        reached[root] = true;
                        next.push(Some(root));
                    }
                    None => return edges,
                }
            }
            frontier = next;
        }
    }

    /// `body` and every body beyond it in the tree.
    fn beyond(&self, edges: &[Edge], body: usize) -> Vec<usize> {
        let mut out = vec![body];
        let mut k = 0;
        while k < out.len() {
            let from = out[k];
            out.extend(edges.iter().filter(|e| e.before == Some(from)).map(|e| e.beyond));
            k += 1;
        }
        out
    }
}

/// A joint's point and unit axis, in space at the defined pose.
pub(super) fn line(joint: &Joint) -> ([f64; 3], [f64; 3]) {
    let axis = joint.axis.unwrap_or([0.0, 0.0, 1.0]);
    let norm = axis.iter().map(|x| x * x).sum::<f64>().sqrt();
    (joint.point, axis.map(|x| x / norm))
}
