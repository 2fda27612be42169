#![doc = include_str!("../../../README.md")]
//!
//! # Map of the modules
//!
//! | layer | modules |
//! |---|---|
//! | what a system is | [`model`] (coordinates, mass, elements), [`constraint`], [`nonholonomic`], [`force`], [`kinetic`], [`scalar`] (the number type physics is written in), [`timefn`] |
//! | building systems | [`planar`] and [`spatial`] mechanisms, [`models`] (built-ins), [`small`] (sizes known at compile time), [`assemble`] (consistent initial states) |
//! | what it does, uncontrolled | [`dynamics`] (`Φ`, `λ`, `A`), [`mass`], [`energy`] (`Ψ`), [`system`] (the state equation with its control term) |
//! | pushing violations back | [`control`] (the laws), [`methods`] (by name, presets), [`gains`] (automatic rates), [`projection`], [`unit_vector`] |
//! | what it keeps | [`momentum`] (symmetries found, corrections kept orthogonal), [`angular`], [`invariant`] (declared), [`held`] |
//! | stepping and output | [`integrate`] (schemes), [`simulate`] (the loop), [`record`], [`diagnostics`], `json_float` (with `serde`) |
//! | checking | [`reference`](mod@reference) (closed-form motions), [`error`] |
#![deny(missing_docs)]

/// Runs `$body` with the const `$k` equal to the run-time `$n`, one of the
/// listed values: code generic over a small size (an element's coordinates,
/// a mass block's width) is then compiled for each, with its loops unrolled.
macro_rules! with_const {
    ($n:expr, $k:ident, [$($v:literal),+], $body:expr) => {
        match $n {
            $($v => {
                const $k: usize = $v;
                $body
            })+
            n => unreachable!("no compiled size {n}"),
        }
    };
}
pub(crate) use with_const;

/// Builder-style setters, `with_<field>(value) -> Self`, for the fields of a
/// configuration type that users build: with the type `#[non_exhaustive]`,
/// a new field is then not a breaking change.
macro_rules! setters {
    ($ty:ty { $($(#[$doc:meta])* $name:ident => $field:ident: $t:ty),+ $(,)? }) => {
        impl $ty {
            $(
                $(#[$doc])*
                #[must_use]
                pub fn $name(mut self, value: $t) -> Self {
                    self.$field = value;
                    self
                }
            )+
        }
    };
}
pub(crate) use setters;

/// The book's Rust examples (`docs/library.md`), compiled and run as doctests.
#[cfg(doctest)]
#[doc = include_str!("../../../docs/library.md")]
pub struct BookLibrary;

pub mod angular;
pub mod assemble;
#[doc(hidden)] // for benchmarks only; see its module head
pub mod baseline;
pub mod constraint;
pub mod control;
pub mod diagnostics;
pub mod dynamics;
pub mod energy;
pub mod error;
mod evaluation;
pub mod force;
pub mod gains;
pub mod held;
pub mod integrate;
pub mod invariant;
mod jet;
#[cfg(feature = "serde")]
pub mod json_float;
pub mod kinetic;
mod linalg;
mod manifold;
pub mod mass;
pub mod methods;
pub mod model;
pub mod models;
pub mod momentum;
pub mod nonholonomic;
pub mod planar;
pub mod projection;
pub mod record;
pub mod reference;
pub mod scalar;
pub mod simulate;
pub mod small;
mod sparse;
pub mod spatial;
pub mod system;
pub mod timefn;
pub mod unit_vector;

pub use constraint::Constraint;
pub use control::{Control, Energy, EnergyGain, Gain, Geometric, Invariants, Rate, Velocity};
pub use error::{Error, Result};
pub use force::{Force, Potential};
pub use integrate::{Application, Scheme};
pub use invariant::Invariant;
pub use kinetic::Kinetic;
pub use model::Model;
pub use nonholonomic::Nonholonomic;
pub use scalar::Scalar;
pub use simulate::{Settings, Simulation};
