//! A combination of method keys that does not describe one method.

/// A combination of method keys ([`MethodKeys`](crate::control::methods::MethodKeys))
/// that does not describe one method.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[non_exhaustive]
pub enum KeyProblem {
    /// Two keys that each set the same gain.
    #[error("give one of {0}, {1}, not both")]
    Both(&'static str, &'static str),
    /// A gain of a method that is not selected.
    #[error("{key} is only used with {method}")]
    Unused {
        /// The key given.
        key: &'static str,
        /// The selection that uses it, e.g. `geometric = "cvsgf"`.
        method: &'static str,
    },
    /// A key that a preset sets itself.
    #[error("{preset} sets {key} itself; remove {key}, or write the method out key by key")]
    Preset {
        /// The preset, e.g. `preset = "robust"`.
        preset: &'static str,
        /// The key given.
        key: &'static str,
    },
    /// A selected method without its gains, or with an incomplete set.
    #[error("{method} takes {takes}")]
    Gains {
        /// The selection, e.g. `geometric = "cvsgf"`.
        method: &'static str,
        /// What it needs, e.g. `one of zeta, alpha_g`.
        takes: &'static str,
    },
}
