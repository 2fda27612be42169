#![doc = include_str!("../../../README.md")]
//!
//! # Map of the modules
//!
//! Each folder's page says what lives there and what it may import; the
//! imports point down this table, never up.
//!
//! | layer | modules |
//! |---|---|
//! | checking and leaves | [`error`], [`reference`](mod@reference) (closed-form motions), [`ad`] (the scalar physics is written in, one-pass Jacobians), [`linalg`] (`M`, `S = Φ_q M⁻¹ Φ_qᵀ` and its factorization), [`limit`] (joint limits and their sides, planar and spatial), `json_float` (with `serde`) |
//! | what a system is | [`model`]: coordinates, mass, constraint / force / kinetic elements, nonholonomic rows, unit vectors, time functions, declared invariants |
//! | what it does, uncontrolled | [`dynamics`]: `Φ`, `λ`, `A`, the energy constraint `Ψ`, diagnostics, the momenta it keeps, assembly onto the constraints |
//! | stepping | [`integrate`] (the schemes) |
//! | pushing violations back | [`control`]: the laws, methods by name, automatic gains, the exact projection, held invariants |
//! | running | [`simulate`] (the state equation and the loop), [`small`] (sizes known at compile time) |
//! | building systems | [`planar`] and [`spatial`] mechanisms, [`models`] (built-ins) |
//! | output | [`record`] (statistics, series, sinks) |
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
/// a new field is then not a breaking change. `name => field(Some): T`
/// sets an optional field from a plain `T`; `impl<B> Type<B> { … }` writes
/// them for a generic type.
macro_rules! setters {
    (@wrap $value:ident) => { $value };
    (@wrap $wrap:ident $value:ident) => { $wrap($value) };
    (impl<$($g:ident),*> $ty:ty { $($(#[$doc:meta])* $name:ident => $field:ident $(($wrap:ident))?: $t:ty),+ $(,)? }) => {
        impl<$($g),*> $ty {
            $(
                $(#[$doc])*
                #[must_use]
                pub fn $name(mut self, value: $t) -> Self {
                    self.$field = $crate::setters!(@wrap $($wrap)? value);
                    self
                }
            )+
        }
    };
    ($ty:ty { $($body:tt)+ }) => {
        $crate::setters!(impl<> $ty { $($body)+ });
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
pub mod limit;
pub mod linalg;
pub mod model;
pub mod models;
pub mod planar;
mod random;
pub mod record;
pub mod reference;
pub mod simulate;
pub mod small;
pub mod spatial;
pub mod stops;

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
