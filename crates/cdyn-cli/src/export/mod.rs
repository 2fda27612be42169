//! A scenario packed for other tools: the variables a stepped case shows
//! them ([`variables`]: parameters, inputs, outputs, a GUID), and the FMI
//! 2.0 co-simulation FMU `cdyn fmu` writes ([`fmu`]: the model
//! description, the archive).
//!
//! May import: `io`, `case`, `study`.

pub mod fmu;
pub mod variables;
mod zip;
