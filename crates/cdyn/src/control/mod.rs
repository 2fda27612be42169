//! Pushing violations back: the control laws of the paper and beyond as
//! plain data with the control term `U(x, t)` they add ([`Control`]; the
//! projected energy law with the terms it solves together, `projected`),
//! methods by name and the paper's cases ([`methods`]), automatic gains
//! ([`gains`]), the exact projection ([`projection`]), the quadratic and
//! declared invariants held beside the energy ([`held`]), and what all of
//! them read of one evaluation of the dynamics (`evaluation`).
//!
//! May import: `error`, `ad`, `linalg`, `model`, `dynamics`, `integrate`.

pub(crate) mod evaluation;
pub mod gains;
pub mod held;
mod laws;
pub mod methods;
mod projected;
pub mod projection;
mod term;

pub use laws::*;
pub use term::*;
