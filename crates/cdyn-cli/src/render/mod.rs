//! What the commands write for people to look at: the summary and figures
//! of a set of runs ([`report`]), plots ([`plot`]), heat maps
//! ([`heatmap`]), the suite's figure ([`suite_plot`]), work-precision
//! diagrams ([`precision_plot`]), animated GIFs
//! ([`gif`], [`gif3d`]), the HTML viewer ([`viewer`]) and the spatial
//! views ([`view3d`], and the 3-D scene the page and GIF animate:
//! [`scene3d`]).
//!
//! May import: `io`, `case`, `study`.

pub mod gif;
pub mod gif3d;
pub mod heatmap;
pub mod plot;
pub mod precision_plot;
pub mod report;
pub mod scene3d;
pub mod suite_plot;
pub mod view3d;
pub mod viewer;
