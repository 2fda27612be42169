//! Spatial multibody systems: rigid bodies in Euler parameters, joints
//! from Haug's primitive constraints, gravity and springs, turned into a
//! [`Model`](crate::Model) of local elements.
//!
//! A body has seven coordinates: its centre of mass `r` and its Euler
//! parameters `p = (e₀, e₁, e₂, e₃)` (a unit quaternion, scalar first, with
//! `A(p)` the rotation from body to space axes), and the velocities are
//! `(ṙ, ṗ)`. Its kinetic energy is `½ m |ṙ|² + ½ ω′ᵀ J′ ω′` with the body
//! angular velocity `ω′ = 2 G(p) ṗ`, plus `½ k (pᵀṗ)²`, which vanishes
//! with its derivatives on the constraint `pᵀṗ = 0` and makes the 4 × 4
//! mass block `4 GᵀJ′G + k p pᵀ` invertible. The normalization `pᵀp = 1`
//! is one more constraint row, held by the same controls as any joint.
//!
//! Why `ṗ` and not the body angular velocity as velocities: it keeps
//! `q̇ = v`, on which every integrator, control law, the projection and the
//! energy balance of the library are written, and its mass is
//! block-diagonal, which the sparse solver factors block by block
//! ([`BlockMass`](crate::linalg::mass::BlockMass)) at a cost linear in the number
//! of bodies. The price is the AD of the 4 × 4 block at every evaluation,
//! kept small by giving the energy as a velocity map
//! ([`VelocityMap`](crate::model::kinetic::VelocityMap)).
//!
//! Joints ([`Joint`]: spherical, revolute, universal, cylindrical,
//! prismatic, fixed, distance; revolute, prismatic and cylindrical ones
//! optionally driven) and loads ([`Load`]: spring-dampers, rotary dampers,
//! forces, torques) are placed by points and axes in space at the initial
//! pose, and carried into each body's frame there, so that a mechanism is
//! always assembled where it is defined. [`Actuator`]s drive revolute and
//! prismatic joints by a torque (force) of time or a PD servo, and
//! [`Mechanism::state_at_joints`] starts a mechanism at given joint
//! coordinates. `from_urdf` (feature `urdf`)
//! reads a robot; [`Sketch`] is what figures draw, bodies as their
//! [`Visual`]s.
//!
//! May import: `error`, `ad`, `linalg`, `model`, `dynamics`, `planar`, `limit`.

mod actuated;
mod actuator;
mod body;
mod chain;
mod coordinate;
mod coordinate_curvature;
mod joint;
mod joint_curvature;
mod joint_element;
mod joint_rows;
mod load;
mod mechanism;
mod named;
mod placing;
mod posing;
pub mod rotation;
mod sketch;
mod spring;
mod stops;
mod tree;
#[cfg(feature = "urdf")]
mod urdf;
mod visual;

pub use crate::limit::{JointLimit, Stop};
pub use actuator::{Actuator, ActuatorTorques};
pub use body::{Body, Rotation, SpatialBody, coordinate_names};
pub use chain::chain;
pub use coordinate::JointSpace;
pub use joint::{FRICTION_SLIP, Joint, JointKind};
pub use load::Load;
pub use mechanism::{Built, Coupling, Mechanism};
pub use named::MergedLink;
pub use sketch::{Anchor, Limb, Sketch};
pub use tree::{BodyPoses, CoordinateTorques, InJoints};
#[cfg(feature = "urdf")]
pub use urdf::{UrdfRobot, from_urdf, read_urdf};
pub use visual::{Shape, Visual};
