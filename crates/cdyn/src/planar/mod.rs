//! Planar multibody systems described as bodies, joints, drives and
//! forces, turned into a [`Model`](crate::Model) of local elements.
//!
//! A rigid body has coordinates `(x, y, φ)` — its centre of mass and its
//! angle — and mass matrix `diag(m, m, I)`; a point mass has `(x, y)`.
//! Points on a body are given in its own frame, relative to the centre of
//! mass. Joints, springs and dampers are written once, generic over the
//! scalar, on the coordinates of the one or two bodies they connect.
//!
//! With the `serde` feature, [`Body`] and [`Element<String>`] are the
//! scenario file's `[[bodies]]` and `[[joints]]`/`[[drives]]`/`[[forces]]`
//! entries (`format` reads the three lists), and
//! [`Mechanism::add_named`] resolves the body names.
//!
//! May import: `error`, `ad`, `model`, `limit`.

mod body;
mod build;
mod constraints;
mod coordinate;
mod drawing;
mod element;
mod ends;
#[cfg(feature = "serde")]
pub mod format;
mod inputs;
mod layout;
mod limit;
mod loads;
mod mechanism;

pub use body::{Body, BodyId, GROUND};
pub use build::Built;
pub use coordinate::JointSpace;
pub use drawing::{Anchor, Drawing, Link, Shape};
pub use element::{Coordinate, Element, Group};
pub use inputs::{Driven, input_keys};
pub use mechanism::Mechanism;
