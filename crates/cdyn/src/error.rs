//! The library's one error type. Every variant says where (step, time,
//! constraint row, the part of a model) and what, as data, so a caller can
//! print a one-line message or name the entry of its own input at fault.

use thiserror::Error;

/// Everything that can go wrong while building a model or simulating it.
#[derive(Debug, Clone, PartialEq, Error)]
#[non_exhaustive]
pub enum Error {
    /// A setting or parameter outside its domain.
    #[error("invalid {name} = {value}: {reason}")]
    InvalidParameter {
        /// The parameter's name as the caller wrote it (`h`, `rod_length`).
        name: &'static str,
        /// The refused value.
        value: f64,
        /// Why it was refused, e.g. "must be finite and positive".
        reason: &'static str,
    },
    /// A model that cannot be simulated as described.
    #[error("invalid model: {at}{problem}")]
    InvalidModel {
        /// The part of the model at fault.
        at: Part,
        /// What is wrong with it.
        problem: Problem,
    },
    /// The initial state is off the constraints by more than the tolerance.
    #[error(
        "initial state violates the constraints: max |Φ| = {phi:.3e}, max |Φ̇| = {phi_dot:.3e} (tolerance {tolerance:.1e})"
    )]
    InconsistentInitialState {
        /// Largest constraint violation.
        phi: f64,
        /// Largest velocity-constraint violation.
        phi_dot: f64,
        /// The tolerance it exceeds.
        tolerance: f64,
    },
    /// `Φ_q M⁻¹ Φ_qᵀ` is singular: the constraints are redundant or degenerate here.
    #[error(
        "singular constraint matrix at step {step}, t = {}: constraint row {row} is linearly dependent on the others (if the constraints are redundant, set dependent_rows = \"tolerate\")", Time(*t)
    )]
    SingularConstraints {
        /// Steps taken before the failure.
        step: u64,
        /// Time of the failure.
        t: f64,
        /// The dependent constraint row.
        row: usize,
    },
    /// The mass matrix `M(q)` of kinetic-energy elements is not positive definite at the state.
    #[error(
        "mass matrix M(q) not positive definite at step {step}, t = {}: coordinate {coordinate} has no inertia there", Time(*t)
    )]
    MassNotPositive {
        /// Steps taken before the failure.
        step: u64,
        /// Time of the failure.
        t: f64,
        /// The coordinate whose pivot failed.
        coordinate: usize,
    },
    /// The state stopped being finite.
    #[error("simulation diverged at step {step}, t = {}: the state is no longer finite", Time(*t))]
    Diverged {
        /// Steps taken before the failure.
        step: u64,
        /// Time of the failure.
        t: f64,
    },
    /// The constraint violation grew past the configured limit.
    #[error(
        "simulation diverged at step {step}, t = {}: max |Φ| = {phi:.3e} exceeds the limit {limit:.1e}",
        Time(*t)
    )]
    ViolationLimit {
        /// Steps taken before the failure.
        step: u64,
        /// Time of the failure.
        t: f64,
        /// The violation reached.
        phi: f64,
        /// The configured limit.
        limit: f64,
    },
    /// The exact projection (the `projection` method) did not converge.
    #[error(
        "projection did not converge at step {step}, t = {}: {invariant} = {residual:.3e}{} after {iterations} Newton iterations (raise max_iterations or tolerance, or set on_failure = \"continue\")",
        Time(*t),
        row.map_or(String::new(), |r| format!(" in constraint row {r}"))
    )]
    ProjectionFailed {
        /// Steps taken, including the one whose result could not be projected.
        step: u64,
        /// Time of the state that could not be projected.
        t: f64,
        /// `|Φ|` or `|Ψ|`.
        invariant: &'static str,
        /// The worst violation left.
        residual: f64,
        /// The worst constraint row, for `|Φ|`.
        row: Option<usize>,
        /// Newton iterations taken.
        iterations: u32,
    },
    /// Method keys that do not describe one method.
    #[error("{0}")]
    Method(#[from] KeyProblem),
    /// A combination of settings this kind of simulation does not offer.
    #[error("{0}")]
    Unsupported(&'static str),
    /// The pendulum's energy lies within a relative 1e-10 of the upright
    /// energy: the period diverges and the elliptic closed form of the
    /// reference solution degenerates.
    #[error("pendulum energy lies on the separatrix (just reaches the top); no elliptic closed form")]
    Separatrix,
}

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

/// The part of a model an [`Error::InvalidModel`] is about.
#[derive(Debug, Clone, PartialEq, Eq, Default)]
#[non_exhaustive]
pub enum Part {
    /// The model as a whole.
    #[default]
    Model,
    /// A body of a mechanism, by position (from 0) and name.
    Body {
        /// Position in the mechanism's body list.
        index: usize,
        /// The body's name.
        name: String,
    },
    /// A joint, drive or force of a mechanism, by position (from 0) in the
    /// mechanism's element list and kind (`revolute`).
    Element {
        /// Position in the mechanism's element list.
        index: usize,
        /// The element's kind, as in scenario files.
        kind: &'static str,
    },
    /// One block of constraint rows, potentials or forces added to a model builder.
    Block {
        /// What the block is: "a constraint", "a potential", "a force".
        what: &'static str,
    },
    /// An element of a URDF file: `link "forearm"`, `joint "elbow"`.
    Urdf {
        /// Its kind and name.
        element: String,
    },
    /// The initial positions and velocities.
    InitialState,
    /// Projecting the initial state onto the constraints.
    Assembly,
    /// One axis (`x` or `y`) of a moving support's prescribed motion.
    Support(&'static str),
}

impl std::fmt::Display for Part {
    /// The part followed by ": ", or nothing for the whole model.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Part::Model => Ok(()),
            Part::Body { index, name } => write!(f, "body {index} ({name}): "),
            Part::Element { index, kind } => write!(f, "element {index} ({kind}): "),
            Part::Block { what } => write!(f, "{what}: "),
            Part::Urdf { element } => write!(f, "{element}: "),
            Part::InitialState => write!(f, "initial state: "),
            Part::Assembly => write!(f, "assembly: "),
            Part::Support(axis) => write!(f, "support {axis}(t): "),
        }
    }
}

/// What is wrong with a part of a model.
#[derive(Debug, Clone, PartialEq, Error)]
#[non_exhaustive]
pub enum Problem {
    /// A number outside its domain.
    #[error("{name} = {value} {reason}")]
    Parameter {
        /// The parameter's name.
        name: &'static str,
        /// The refused value.
        value: f64,
        /// Why, e.g. "must be finite and positive".
        reason: &'static str,
    },
    /// A time function with a non-finite coefficient.
    #[error("time function has a non-finite coefficient")]
    NonFiniteFunction,
    /// A model without coordinates.
    #[error("a model needs at least one coordinate")]
    NoCoordinates,
    /// More coordinates or Jacobian entries than 32-bit indices can hold.
    #[error("{n} coordinates and {nnz} Jacobian entries: at most 2³² − 1 of each are supported")]
    TooLarge {
        /// Coordinates.
        n: usize,
        /// Jacobian entries.
        nnz: usize,
    },
    /// More constraint rows than coordinates.
    #[error("{m} constraints on {n} coordinates: more constraints than coordinates")]
    TooManyConstraints {
        /// Constraint rows.
        m: usize,
        /// Coordinates.
        n: usize,
    },
    /// An element reads a coordinate the model does not have.
    #[error("reads coordinate {index}, but the model has only {n}")]
    NoSuchCoordinate {
        /// The coordinate read.
        index: usize,
        /// Coordinates of the model.
        n: usize,
    },
    /// A rotation whose angular momentum is declared does not fit the model.
    #[error("{0}")]
    Rotation(String),
    /// An element reads one coordinate twice.
    #[error("reads coordinate {index} twice")]
    CoordinateTwice {
        /// The coordinate read twice.
        index: usize,
    },
    /// An element refers to a body that does not exist.
    #[error("body {index} does not exist")]
    NoSuchBody {
        /// The missing body's position.
        index: usize,
    },
    /// An element names a body that is neither a body of the mechanism nor the ground.
    #[error("{key} = {name:?}: no body of that name (and not \"ground\")")]
    UnknownBody {
        /// The key naming the body (`a`, `b`, `body`).
        key: &'static str,
        /// The name given.
        name: String,
    },
    /// A body named `ground` (which elements use for the world frame) or nothing.
    #[error("name {name:?} is reserved or empty")]
    ReservedName {
        /// The name given.
        name: String,
    },
    /// A second body with the name of an earlier one.
    #[error("a body with this name already exists")]
    DuplicateName,
    /// An element connects a body to itself.
    #[error("connects {body} to itself")]
    SameBody {
        /// The body's name (or `ground`).
        body: String,
    },
    /// An element needs a body's angle, but the body is a point mass.
    #[error("body {body} is a point mass and has no angle")]
    NoAngle {
        /// The point mass's name.
        body: String,
    },
    /// An element is attached off the only point of a point mass.
    #[error("body {body} is a point mass: its only point is [0, 0]")]
    PointMassOffset {
        /// The point mass's name.
        body: String,
    },
    /// A drive, force, torque or knife edge on the ground, which does not move.
    #[error("the ground cannot be {0}")]
    OnGround(&'static str),
    /// A point mass given an angle or angular velocity.
    #[error("a point mass (no inertia) has no angle or angular_velocity")]
    PointMassRotation,
    /// Initial positions or velocities of the wrong length.
    #[error("{positions} positions and {velocities} velocities, the model has {n} coordinates")]
    StateLength {
        /// Positions given.
        positions: usize,
        /// Velocities given.
        velocities: usize,
        /// Coordinates of the model.
        n: usize,
    },
    /// A non-finite initial position or velocity.
    #[error("component {index} is {value}")]
    NonFiniteState {
        /// Index into positions followed by velocities.
        index: usize,
        /// The value.
        value: f64,
    },
    /// The constraints are singular where the state is to be projected.
    #[error(
        "the constraints are singular at the given positions (row {row}, iteration {iteration}; if they are redundant, set dependent_rows = \"tolerate\")"
    )]
    SingularAssembly {
        /// The dependent row.
        row: usize,
        /// The Newton iteration.
        iteration: usize,
    },
    /// A four-bar whose crank cannot turn through a full circle (Grashof).
    #[error(
        "four-bar a = {}, b = {}, c = {}, d = {}: the crank cannot turn fully (needs |b − c| < d − a and d + a < b + c)",
        lengths[0], lengths[1], lengths[2], lengths[3]
    )]
    NoFullTurn {
        /// Crank, coupler, rocker and ground lengths.
        lengths: [f64; 4],
    },
    /// A spatial body's orientation that is not a unit quaternion.
    #[error("orientation has length {norm}: Euler parameters must be a unit quaternion (within 1e-6)")]
    NotUnitQuaternion {
        /// Its length.
        norm: f64,
    },
    /// A spatial body's inertia tensor that is not physical.
    #[error("inertia {reason}")]
    Inertia {
        /// What is wrong with it.
        reason: &'static str,
    },
    /// A joint key given to a kind that does not take it, or missing from one that needs it.
    #[error("{}", if *wanted { format!("a {kind} joint needs {key}") } else { format!("a {kind} joint takes no {key}") })]
    JointKey {
        /// The key.
        key: &'static str,
        /// The joint's kind.
        kind: &'static str,
        /// Whether the kind needs it.
        wanted: bool,
    },
    /// A URDF file that cdyn cannot take, and why.
    #[error("{reason}")]
    Urdf {
        /// Why.
        reason: String,
    },
    /// A joint axis of zero (or non-finite) length.
    #[error("{name} has zero length")]
    ZeroAxis {
        /// The axis's name (`axis`, `axis_b`).
        name: &'static str,
    },
    /// Positions that are not finite.
    #[error("the positions are not finite")]
    NonFinitePositions,
    /// The mass matrix `M(q)` of kinetic-energy elements is not positive definite.
    #[error("the mass matrix M(q) is not positive definite (pivot of coordinate {coordinate})")]
    MassNotPositive {
        /// The coordinate whose pivot failed.
        coordinate: usize,
    },
    /// The projection onto the constraints did not converge.
    #[error("did not converge: max |Φ| = {phi:.3e} after {iterations} Newton iterations")]
    NoConvergence {
        /// The violation left.
        phi: f64,
        /// Newton iterations taken.
        iterations: usize,
    },
}

impl Error {
    /// The constraint row a simulation error is about, if any.
    pub fn row(&self) -> Option<usize> {
        match self {
            Error::SingularConstraints { row, .. } => Some(*row),
            Error::InvalidModel { problem: Problem::SingularAssembly { row, .. }, .. } => Some(*row),
            Error::ProjectionFailed { row, .. } => *row,
            _ => None,
        }
    }

    /// The same error, said of `part`: a refused parameter becomes an
    /// [`Error::InvalidModel`] at `part`; an invalid model error of the whole
    /// model is moved to `part`; other errors are kept.
    pub fn at(self, part: Part) -> Error {
        match self {
            Error::InvalidParameter { name, value, reason } => {
                Error::InvalidModel { at: part, problem: Problem::Parameter { name, value, reason } }
            }
            Error::InvalidModel { at: Part::Model, problem } => Error::InvalidModel { at: part, problem },
            other => other,
        }
    }
}

impl Problem {
    /// This problem, said of `part`.
    pub fn at(self, part: Part) -> Error {
        Error::InvalidModel { at: part, problem: self }
    }
}

impl From<Problem> for Error {
    /// A problem of the whole model.
    fn from(problem: Problem) -> Self {
        Error::InvalidModel { at: Part::Model, problem }
    }
}

/// A time as people write it: `step · h` rounded to 12 significant digits
/// (`0.3`, not the `0.30000000000000004` of `3 × 0.1`), far below any step.
pub fn tidy_time(t: f64) -> f64 {
    format!("{t:.11e}").parse().unwrap_or(t)
}

/// A time in a message: [`tidy_time`], in plain decimals between 1e-4 and
/// 1e9 and with an exponent outside (not 309 digits for 1e308).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Time(pub f64);

impl std::fmt::Display for Time {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let t = tidy_time(self.0);
        if t == 0.0 || (1e-4..1e9).contains(&t.abs()) { write!(f, "{t}") } else { write!(f, "{t:e}") }
    }
}

/// The library's result type.
pub type Result<T, E = Error> = std::result::Result<T, E>;

/// Checks that `value` is finite; names it otherwise.
pub fn finite(name: &'static str, value: f64) -> Result<f64> {
    if value.is_finite() { Ok(value) } else { Err(Error::InvalidParameter { name, value, reason: "must be finite" }) }
}

/// Checks that `value` is finite and positive; names it otherwise.
pub fn positive(name: &'static str, value: f64) -> Result<f64> {
    if value.is_finite() && value > 0.0 {
        Ok(value)
    } else {
        Err(Error::InvalidParameter { name, value, reason: "must be finite and positive" })
    }
}

/// Checks that `value` is finite and not negative; names it otherwise.
pub fn non_negative(name: &'static str, value: f64) -> Result<f64> {
    if value.is_finite() && value >= 0.0 {
        Ok(value)
    } else {
        Err(Error::InvalidParameter { name, value, reason: "must be finite and not negative" })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn times_print_as_written() {
        assert_eq!(Time(3.0 * 0.1).to_string(), "0.3");
        assert_eq!(Time(1e308).to_string(), "1e308");
        assert_eq!(Time(2.5e-6).to_string(), "2.5e-6");
        assert_eq!(Time(0.0).to_string(), "0");
        assert_eq!(Time(4766.0 * 0.001).to_string(), "4.766");
    }
}
