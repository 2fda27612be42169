//! Fixed-step schemes as data (Eqs. 54–59): their weights, order and
//! start-up, and one step `x_k → x_{k+1}` with the control term either in
//! the right-hand side or integrated by a separate Euler step. Explicit
//! one-step (Runge–Kutta), multistep (Adams–Bashforth) and
//! predictor-corrector (Adams–Bashforth–Moulton, PECE) formulas.
//!
//! The integrator knows nothing of models: it sees a right-hand side split
//! into `f` (what the scheme integrates) and the control term `U`.
//!
//! - `scheme`: the schemes as data — name, order, cost, history, start-up
//!   and formula (multistep weights, predictor-corrector, Butcher tableau);
//! - `rhs`: what a scheme steps — the state equation and the storage of a state;
//! - `integrator`: one step of a right-hand side by a scheme's formula,
//!   the start-up while the history fills, and where the control term goes.
//!
//! May import: nothing (the leaf every stepping loop builds on).

mod integrator;
mod rhs;
mod scheme;

pub use integrator::Integrator;
pub use rhs::{Buffer, Rhs};
pub use scheme::{Application, Formula, Scheme, SchemeInfo};
