//! Which part of a model an error is about.

/// The part of a model an [`Error::InvalidModel`](super::Error::InvalidModel) is about.
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
