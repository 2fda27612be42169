//! A mechanism whose joints form a tree on the ground, in joint
//! coordinates: one coordinate per revolute or prismatic joint (its
//! angle or displacement from the initial pose, as
//! [`Mechanism::joint_coordinates`](super::Mechanism::joint_coordinates)
//! counts it), bodies welded by fixed joints riding with their parent,
//! and nothing left for the constraints to hold but `<mimic>` couplings,
//! drives and held stops. It is the formulation of robot libraries
//! (Pinocchio, MuJoCo): a UR5 has 6 coordinates instead of 42 coordinates
//! and 36 rows.
//!
//! The kinetic energy and gravity are given to the model as one element
//! each, in closed form by the spatial algebra of Featherstone's
//! recursions in space axes (`dynamics`, `gravity`), not by automatic
//! differentiation: `T` over a tree is a composition the dual numbers would
//! differentiate at `O(n²)` passes per state.
//!
//! Here the tree and the work its elements share; `build` the tree and
//! model from a mechanism; `elements` the rows and forces on its
//! coordinates; `loads` springs, dampers, forces and torques on bodies; `bodies` the bodies' poses for output; `kinematics` the
//! poses at `θ`; `motion` the spatial vectors.
//!
//! May import: `error`, `ad`, `model`, `limit`, `spatial`.

mod bodies;
mod build;
mod dynamics;
mod elements;
mod gravity;
mod kinematics;
mod loads;
mod motion;

pub use bodies::BodyPoses;
pub use build::{CoordinateTorques, InJoints};

use kinematics::Kinematics;
use motion::{Inertia, Motion, V3, Wrench};
use std::sync::{Mutex, MutexGuard};

/// A joint with a coordinate, in an order where every parent comes before its children.
#[derive(Debug, Clone)]
pub(super) struct Node {
    /// The nearest joint with a coordinate between this one and the ground.
    parent: Option<usize>,
    /// Its coordinate's position in the model.
    coordinate: usize,
    rotary: bool,
    /// The unit axis at the initial pose, signed so that turning by `θ`
    /// about it moves the child (the side away from the ground).
    axis: V3,
    /// A point of the axis at the initial pose.
    point: V3,
    /// The bodies it carries and no joint below it does, at the initial pose.
    inertia: Inertia,
}

/// The tree: its nodes, the coordinates they read (`0 .. n`), and each
/// body of the mechanism with the node that carries it (`None`: welded to
/// the ground) and its initial pose.
#[derive(Debug, Clone)]
pub(super) struct Tree {
    nodes: Vec<Node>,
    n: usize,
    bodies: Vec<(Option<usize>, V3, [f64; 4])>,
}

/// Buffers of one evaluation, a slot per node.
#[derive(Debug)]
pub(super) struct Work {
    kin: Kinematics,
    composite: Vec<Inertia>,
    vel: Vec<Motion>,
    acc: Vec<Motion>,
    momentum: Vec<Wrench>,
    force: Vec<Wrench>,
    subtree: Vec<(f64, V3)>,
}

/// The tree and the work of its kinetic and potential elements: both are
/// evaluated at the same `q` in a step, and share its kinematics.
#[derive(Debug)]
pub(super) struct Shared {
    tree: Tree,
    work: Mutex<Work>,
}

impl Shared {
    fn new(tree: Tree) -> Self {
        let k = tree.nodes.len();
        let work = Work {
            kin: Kinematics::new(&tree),
            composite: vec![Inertia::default(); k],
            vel: vec![Motion::default(); k],
            acc: vec![Motion::default(); k],
            momentum: vec![Wrench::default(); k],
            force: vec![Wrench::default(); k],
            subtree: vec![(0.0, [0.0; 3]); k],
        };
        Self { tree, work: Mutex::new(work) }
    }

    /// The work, for one evaluation. A poisoned lock is taken as is: every
    /// evaluation rewrites what it reads.
    fn lock(&self) -> MutexGuard<'_, Work> {
        self.work.lock().unwrap_or_else(|e| e.into_inner())
    }
}
