//! The library's integration tests, one module per file, in one test binary: one link of the
//! libraries and one copy of the generic code they instantiate, where a
//! binary per file took most of a cold CI build (a 12-minute test build,
//! 50 binaries). The allocation-counting tests, which install their own
//! global allocator, stay binaries of their own.

mod actuators;
mod andrews;
mod angular;
mod convergence;
mod derivatives;
mod euler_parameters;
mod generalized_alpha;
mod inputs;
mod joint_coordinates;
mod kinetic;
mod layout;
mod limits;
mod mechanisms;
mod momentum;
mod nonholonomic;
mod pendulum;
mod planar;
mod planar_limits;
mod rank;
mod rattle;
mod record;
mod series;
mod small;
mod sparse;
mod spatial;
mod stabilization;
mod stable_api;
mod urdf;
