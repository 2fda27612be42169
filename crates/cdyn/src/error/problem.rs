//! What is wrong with a part of a model.

use super::{Error, Part};

/// What is wrong with a part of a model.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
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
    /// An input set to drive a key of an element that it cannot drive.
    #[error("input {input:?} on {key}: {reason}")]
    InputKey {
        /// The input.
        input: String,
        /// The key it was to drive.
        key: String,
        /// Why it cannot.
        reason: String,
    },
    /// A time function with a non-finite coefficient.
    #[error("time function has a non-finite coefficient")]
    NonFiniteFunction,
    /// A model without coordinates.
    #[error("a model needs at least one coordinate")]
    NoCoordinates,
    /// A spatial mechanism without bodies (a URDF whose links are all
    /// welded to its root).
    #[error(
        "no body moves: a spatial mechanism needs at least one (a URDF's links with a mass welded to its root are part of the ground)"
    )]
    NoBodies,
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
    /// A coupling refers to a joint that does not exist.
    #[error("joint {index} does not exist")]
    NoSuchJoint {
        /// The missing joint's position.
        index: usize,
    },
    /// A one-sided stop that cannot be met as asked.
    #[error("{reason}")]
    Stop {
        /// Which stop and why.
        reason: String,
    },
    /// A joint that starts past one side of its limit: a run with stops
    /// starts within them.
    #[error("{joint}: starts {by:.3e} past its {} limit {bound}", if *upper { "upper" } else { "lower" })]
    StartsPastLimit {
        /// Which stop (its index among the system's).
        stop: usize,
        /// The joint, as the system names it (`joint 2`, `element 0 (revolute)`).
        joint: String,
        /// The upper bound (else the lower).
        upper: bool,
        /// The bound.
        bound: f64,
        /// How far past it (`> 0`).
        by: f64,
    },
    /// A joint limit whose bounds are not numbers or not ordered.
    #[error("limit lower = {lower}, upper = {upper}: {reason}")]
    BadLimit {
        /// The lower bound.
        lower: f64,
        /// The upper bound.
        upper: f64,
        /// What is wrong.
        reason: &'static str,
    },
    /// A mechanism that joint coordinates cannot describe, or an element they do not model yet.
    #[error("in joint coordinates: {reason}")]
    JointCoordinates {
        /// Why.
        reason: String,
    },
    /// A joint without a coordinate of its own where one is needed.
    #[error("joint {index} is {kind}: only revolute and prismatic joints have a coordinate (to couple or to limit)")]
    NoCoordinate {
        /// The joint's position.
        index: usize,
        /// Its kind.
        kind: &'static str,
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
    /// A joint actuator whose keys make no one law, and why.
    #[error("{reason}")]
    Actuator {
        /// Why.
        reason: &'static str,
    },
    /// Joint values a mechanism cannot be placed at, and why.
    #[error("{reason}")]
    Posing {
        /// Which joint and why.
        reason: String,
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

impl Problem {
    /// This problem, said of `part`.
    pub fn at(self, part: Part) -> Error {
        Error::InvalidModel { at: part, problem: self }
    }
}
