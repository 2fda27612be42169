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

pub mod ad;
#[doc(hidden)] // for benchmarks only; see its module head
pub mod baseline;
pub mod control;
pub mod dynamics;
pub mod error;
pub mod integrate;
#[cfg(feature = "serde")]
pub mod json_float;
pub mod linalg;
pub mod model;
pub mod models;
pub mod planar;
pub mod record;
pub mod reference;
pub mod simulate;
pub mod small;
pub mod spatial;

/// The flat paths of 0.1 (`cdyn::mass`, `cdyn::gains`, …), kept so that
/// programs written against them still build; see `CHANGELOG.md`.
#[doc(hidden)]
pub use crate::{
    ad::scalar,
    control::{gains, held, methods, projection},
    dynamics::{assemble, diagnostics, energy, momentum},
    linalg::mass,
    model::{angular, constraint, force, invariant, kinetic, nonholonomic, timefn, unit_vector},
    simulate::system,
};

pub use ad::scalar::Scalar;
pub use control::{Control, Energy, EnergyGain, Gain, Geometric, Invariants, Rate, Velocity};
pub use error::{Error, Result};
pub use integrate::{Application, Scheme};
pub use model::Model;
pub use model::constraint::Constraint;
pub use model::force::{Force, Potential};
pub use model::invariant::Invariant;
pub use model::kinetic::Kinetic;
pub use model::nonholonomic::Nonholonomic;
pub use simulate::{Settings, Simulation};
