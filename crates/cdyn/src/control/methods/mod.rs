//! Stabilization methods by name: the flat table of keys in which scenario
//! files write a method (`geometric = "cvsgf"`, `zeta = 20.0`, …), and the
//! named cases of the paper's comparison, for `cdyn paper`, `compare`,
//! `bench` and benchmarks. A simulation itself needs only a [`Control`].
//!
//! - `keys`: [`MethodKeys`], the scenario table, and the kinds it names;
//! - `keys_to_control`: [`MethodKeys::control`] and [`MethodKeys::gains`];
//! - `cases`: [`MethodGains`] and the named cases ([`redundant_cases`], …).
//!
//! May import: `error`, `integrate` (and `control`, whose laws it names).

mod cases;
mod keys;
mod keys_to_control;

pub use cases::{MethodGains, compare_cases, independent_cases, projection, redundant_cases, robust};
pub use keys::{EnergyKind, GeometricKind, MethodKeys, Preset, RateKey, VelocityKind};
