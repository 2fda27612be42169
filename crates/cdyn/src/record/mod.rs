//! Recording a run: the statistics a summary reports, the sampled time
//! series for figures, and each sample handed to a [`Sink`] as the run goes.
//!
//! May import: `error`, `json_float`, `model`, `dynamics`, `simulate`,
//! `models`.

mod recorder;

pub use recorder::*;
