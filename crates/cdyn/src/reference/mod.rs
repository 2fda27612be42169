//! References the checks measure against: the planar pendulum in closed
//! form ([`PendulumExact`], to about 1e-12, and the time it takes to
//! swing from rest to an angle, [`time_to_swing`]), Euler's torque-free rigid body
//! ([`torque_free_rate`]), the elliptic functions both are written in, and
//! for the built-in models without a closed form a fine RK-4 of a small
//! equation of motion (`fine_ode`, error about 1e-13).
//!
//! May import: `error`.

pub mod elliptic;
pub(crate) mod fine_ode;
mod pendulum;
mod top;

pub use pendulum::{PendulumExact, time_to_swing};
pub use top::torque_free_rate;
