//! The commands of `cdyn` as a library: scenario files, cases, runs,
//! `compare`, `sweep` and `paper`, shared by the `cdyn` binary and the
//! Python package (crates/cdyn-py), so both read scenarios, run cases and
//! word errors the same way.

#![deny(missing_docs)]

pub mod alloc_count;
pub mod bench;
pub mod compare;
pub mod frames;
pub mod gif;
pub mod heatmap;
pub mod interrupt;
pub mod output;
pub mod paper;
pub mod plot;
pub mod progress;
pub mod report;
pub mod runner;
pub mod scenario;
pub mod suite;
pub mod suite_plot;
pub mod sweep;
pub mod terminal;
pub mod view3d;
pub mod viewer;
