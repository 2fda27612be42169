//! Built-in systems, each with its initial state and, where one exists,
//! its reference solution. Tests, benchmarks and the command line share them.
//!
//! The planar mechanisms are described with [`Mechanism`](crate::planar::Mechanism)
//! (the same joints, drives and forces users get), one file each; the
//! pieces they share are in `parts.rs`.
//!
//! | model | free motion | reference |
//! |---|---|---|
//! | [`double_pendulum`] | 2 DOF | none (chaotic in general) |
//! | [`double_pendulum_angles`] | 2 DOF, `M(θ)` from `T` | none; the same motion as [`double_pendulum`] |
//! | [`chain`] | N DOF | rigid rotation when `g = 0`; the exact pendulum when `N = 1` |
//! | [`slider_crank`] | none (driven); 1 DOF with a load | exact kinematics; a load pendulum by a fine RK-4 |
//! | [`four_bar`] | none (driven); 1 DOF with a load | exact kinematics (circle intersection); a load by a fine RK-4 |
//! | [`four_bar_angles`] | the same in three joint angles, `M(q)` from `T` | the same |
//! | [`moving_support_pendulum`] | 1 DOF, driven support | exact pendulum in the accelerated frame, or a fine RK-4 |
//! | [`damped_pendulum`] | 1 DOF, rotary damper | exact pendulum when undamped, else a fine RK-4 |
//!
//! Angle conventions: the multi-link models (double pendulum, chain, load
//! pendulums) measure link angles counter-clockwise from the downward
//! vertical (−Y); the single pendulums ([`moving_support_pendulum`],
//! [`damped_pendulum`]) measure the angle counter-clockwise from +X, as
//! [`PendulumParams`] and [`PendulumExact`](crate::reference::PendulumExact)
//! do. Gravity acts along −Y.
//!
//! Every built-in model has a [`Kind`], the name scenario files give it;
//! `Kind::example` builds it from its parameters (with the `serde` feature).
//!
//! Fine references: where no closed form exists, a 1-D equation of motion
//! is integrated by [`crate::reference`]'s fine RK-4 (error about 1e-13).
//!
//! May import: `error`, `ad`, `model`, `planar`, `spatial`, `small`, `reference`.

pub mod andrews;
mod chain;
mod damped_pendulum;
mod double_pendulum;
mod four_bar;
mod kind;
mod moving_support;
mod parts;
mod pendulum;
mod slider_crank;

pub use andrews::andrews;
pub use chain::{ChainParams, chain};
pub use damped_pendulum::{DampedPendulumParams, damped_pendulum};
pub use double_pendulum::{DoublePendulumKinetic, DoublePendulumParams, double_pendulum, double_pendulum_angles};
pub use four_bar::{FourBarBranch, FourBarParams, four_bar, four_bar_angles};
pub use kind::Kind;
pub use moving_support::{MovingSupportParams, moving_support_pendulum};
pub use parts::LoadPendulum;
pub use pendulum::{PendulumParams, SmallPendulum, cartesian_pendulum, small_pendulum, theta_pendulum};
pub use slider_crank::{SliderCrankParams, slider_crank};

/// `(q, v)` of the exact solution at time `t`, in the model's coordinates.
pub type Reference = Box<dyn Fn(f64, &mut [f64], &mut [f64]) + Send + Sync>;

/// Maps a state `(q, v)` at time `t` to named observable quantities
/// (the time for what depends on it, as an actuator's torque).
pub type Observe = Box<dyn Fn(f64, &[f64], &[f64], &mut [f64]) + Send + Sync>;

/// A built-in system ready to simulate.
pub struct Example {
    /// The equations of motion.
    pub model: crate::Model,
    /// Initial positions, on the constraints.
    pub q0: Vec<f64>,
    /// Initial velocities, on the velocity constraints.
    pub v0: Vec<f64>,
    /// Names of the observables, e.g. `X, Y, VX, VY`; errors against the
    /// reference are reported for the first of them.
    pub observables: Vec<String>,
    /// Computes the observables of a state (see [`Example::observe`]).
    pub observe: Observe,
    /// The exact (or finely integrated) solution, where one exists.
    pub reference: Option<Reference>,
    /// What the system looks like, for a viewer: built-ins described as
    /// planar mechanisms have one; models in independent coordinates
    /// (angles) have none, since a drawing places bodies by their
    /// Cartesian coordinates.
    pub drawing: Option<crate::planar::Drawing>,
    /// The same for a spatial mechanism: what its 3-D figures draw.
    pub sketch: Option<crate::spatial::Sketch>,
}

impl Example {
    /// A mechanism as an example whose observables are its coordinates.
    pub fn from_mechanism(built: crate::planar::Built, reference: Option<Reference>) -> Self {
        let n = built.model.n();
        Example {
            model: built.model,
            q0: built.q0,
            v0: built.v0,
            observables: built.names,
            observe: Box::new(move |_t, q, _v, out| out.copy_from_slice(&q[..n])),
            reference,
            drawing: Some(built.drawing),
            sketch: None,
        }
    }

    /// A spatial mechanism as an example whose observables are its
    /// coordinates (`name.x` … `name.e3` for each body), then each revolute
    /// and prismatic joint's coordinate and its rate (`joints[k].q`,
    /// `joints[k].v`, `k` its index; see [`Mechanism::joint_coordinates`](crate::spatial::Mechanism::joint_coordinates)),
    /// then the torque (force) each actuator applies (`joints[k].tau`, `k`
    /// its joint), without reference or drawing.
    pub fn from_spatial(mechanism: &crate::spatial::Mechanism, built: crate::spatial::Built) -> Self {
        Self::from_spatial_named(mechanism, built, |k| format!("joints[{k}]"))
    }

    /// The same, joint `k`'s columns named `{joint_name(k)}.q`, `.v` and
    /// `.tau` (a URDF robot's joints by their names, say).
    pub fn from_spatial_named(
        mechanism: &crate::spatial::Mechanism,
        built: crate::spatial::Built,
        joint_name: impl Fn(usize) -> String,
    ) -> Self {
        let n = built.model.n();
        let mut observables: Vec<String> =
            mechanism.bodies.iter().flat_map(|b| crate::spatial::coordinate_names(&b.name)).collect();
        // A mechanism that builds has every joint's frames and every
        // actuator's law, so its joint space and its torques read.
        let joints = mechanism.joint_space().unwrap_or_default();
        let torques = mechanism.actuator_torques().unwrap_or_default();
        observables
            .extend(joints.joints().flat_map(|k| [format!("{}.q", joint_name(k)), format!("{}.v", joint_name(k))]));
        observables.extend(torques.joints().map(|k| format!("{}.tau", joint_name(k))));
        let pairs = 2 * joints.joints().len();
        // No acceleration is reported: θ̈ is read with a = 0 and dropped.
        let zero = vec![0.0; n];
        let observe = move |t: f64, q: &[f64], v: &[f64], out: &mut [f64]| {
            out[..n].copy_from_slice(&q[..n]);
            for (i, pair) in out[n..n + pairs].chunks_exact_mut(2).enumerate() {
                let [theta, rate, _] = joints.at(i, q, v, &zero);
                pair.copy_from_slice(&[theta, rate]);
            }
            for (i, tau) in out[n + pairs..].iter_mut().enumerate() {
                *tau = torques.at(i, q, v, t);
            }
        };
        Example {
            model: built.model,
            q0: built.q0,
            v0: built.v0,
            observables,
            observe: Box::new(observe),
            reference: None,
            drawing: None,
            sketch: Some(mechanism.sketch()),
        }
    }

    /// A spatial mechanism in joint coordinates
    /// ([`Mechanism::in_joint_coordinates`](crate::spatial::Mechanism::in_joint_coordinates))
    /// as an example with the observables of [`Example::from_spatial_named`]:
    /// the bodies' coordinates (their poses at `θ`), each joint's `.q` and
    /// `.v` (the coordinates themselves), each actuator's `.tau`.
    pub fn from_joint_coordinates(
        mechanism: &crate::spatial::Mechanism,
        in_joints: crate::spatial::InJoints,
        joint_name: impl Fn(usize) -> String,
    ) -> Self {
        let mut observables: Vec<String> =
            mechanism.bodies.iter().flat_map(|b| crate::spatial::coordinate_names(&b.name)).collect();
        let joints = &in_joints.joints;
        observables
            .extend(joints.iter().flat_map(|&k| [format!("{}.q", joint_name(k)), format!("{}.v", joint_name(k))]));
        observables.extend(mechanism.actuators.iter().map(|a| format!("{}.tau", joint_name(a.joint))));
        let (bodies, n) = (in_joints.poses.len(), in_joints.model.n());
        let crate::spatial::InJoints { model, q0, v0, poses, torques, .. } = in_joints;
        let poses = std::sync::Mutex::new(poses);
        let observe = move |t: f64, q: &[f64], v: &[f64], out: &mut [f64]| {
            poses.lock().unwrap_or_else(|e| e.into_inner()).at(q, &mut out[..bodies]);
            for (c, pair) in out[bodies..bodies + 2 * n].chunks_exact_mut(2).enumerate() {
                pair.copy_from_slice(&[q[c], v[c]]);
            }
            for (i, tau) in out[bodies + 2 * n..].iter_mut().enumerate() {
                *tau = torques.at(i, q, v, t);
            }
        };
        Example {
            model,
            q0,
            v0,
            observables,
            observe: Box::new(observe),
            reference: None,
            drawing: None,
            sketch: Some(mechanism.sketch()),
        }
    }

    /// The observables of the state `(q, v)` at time `t`.
    pub fn observe(&self, t: f64, q: &[f64], v: &[f64]) -> Vec<f64> {
        let mut out = vec![0.0; self.observables.len()];
        (self.observe)(t, q, v, &mut out);
        out
    }

    /// Error of the first observable against the reference at time `t`.
    pub fn error(&self, q: &[f64], v: &[f64], t: f64) -> Option<f64> {
        let n = self.model.n();
        let (mut qr, mut vr, mut at_ref) = (vec![0.0; n], vec![0.0; n], vec![0.0; self.observables.len()]);
        self.error_of(self.observe(t, q, v)[0], t, &mut qr, &mut vr, &mut at_ref)
    }

    /// The error of `first`, the first observable of a state, against the
    /// reference at time `t`, into caller-held buffers (the reference state
    /// `qr`, `vr` and its observables `at_ref`), so that a recorder sampling
    /// a long run allocates nothing.
    pub fn error_of(&self, first: f64, t: f64, qr: &mut [f64], vr: &mut [f64], at_ref: &mut [f64]) -> Option<f64> {
        let reference = self.reference.as_ref()?;
        reference(t, qr, vr);
        (self.observe)(t, qr, vr, at_ref);
        Some(first - at_ref[0])
    }
}
