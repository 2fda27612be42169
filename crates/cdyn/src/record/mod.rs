//! Recording a run: the statistics a summary reports ([`Recorder`],
//! [`Record`]), the sampled time series for figures ([`Series`]), and each
//! sample handed to a [`Sink`] as the run goes ([`Sample`]).
//!
//! May import: `error`, `json_float`, `model`, `dynamics`, `simulate`,
//! `models`.

mod recorder;
mod sample;
mod series;

pub use recorder::*;
pub use sample::*;
pub use series::*;
