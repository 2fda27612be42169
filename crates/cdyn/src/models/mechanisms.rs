//! Built-in planar mechanisms, described with [`Mechanism`] (the same
//! joints, drives and forces users get), each with a consistent initial
//! state and, where one exists, a reference solution.
//!
//! | model | free motion | reference |
//! |---|---|---|
//! | [`double_pendulum`] | 2 DOF | none (chaotic in general) |
//! | [`chain`] | N DOF | rigid rotation when `g = 0`; the exact pendulum when `N = 1` |
//! | [`slider_crank`] | none (driven); 1 DOF with a load | exact kinematics; a load pendulum by a fine RK-4 |
//! | [`four_bar`] | none (driven); 1 DOF with a load | exact kinematics (circle intersection); a load by a fine RK-4 |
//! | [`moving_support_pendulum`] | 1 DOF, driven support | exact pendulum in the accelerated frame, or a fine RK-4 |
//! | [`damped_pendulum`] | 1 DOF, rotary damper | exact pendulum when undamped, else a fine RK-4 |
//!
//! Angle conventions: the multi-link models (double pendulum, chain, load
//! pendulums) measure link angles counter-clockwise from the downward
//! vertical (−Y); the single pendulums ([`moving_support_pendulum`],
//! [`damped_pendulum`]) measure the angle counter-clockwise from +X, as
//! [`super::PendulumParams`] and [`PendulumExact`] do. Gravity acts along −Y.
//!
//! A rigid link is a body whose centre of mass is the link's midpoint and
//! whose own x-axis points along the link, from its first joint to its
//! second; its angle coordinate is the link's angle from +X.
//!
//! Fine references: where no closed form exists, a 1-D equation of motion
//! is integrated by classical RK-4 with a small fixed step (about 1e-3 of
//! the fastest time scale), incrementally: successive calls with increasing
//! `t` cost only the new steps. Its error is about 1e-13.

use std::f64::consts::{FRAC_PI_2, PI};

use super::{Example, Observe, Reference};
use crate::error::{Error, Part, Problem, Result, non_negative, positive};
use crate::planar::{Body, BodyId, Coordinate, Element, Mechanism};
use crate::reference::PendulumExact;
use crate::timefn::TimeFn;

use fine_ode::FineOde;

fn finite(name: &'static str, value: f64) -> Result<f64> {
    if value.is_finite() { Ok(value) } else { Err(Error::InvalidParameter { name, value, reason: "must be finite" }) }
}

/// `(cos a, sin a)`
fn dir(a: f64) -> [f64; 2] {
    let (s, c) = a.sin_cos();
    [c, s]
}

/// `(−sin a, cos a)`, the direction rotated a quarter turn counter-clockwise.
fn perp(a: f64) -> [f64; 2] {
    let (s, c) = a.sin_cos();
    [-s, c]
}

/// `(sin a, −cos a)`: the unit vector at angle `a` from the downward vertical.
fn hanging(a: f64) -> [f64; 2] {
    let (s, c) = a.sin_cos();
    [s, -c]
}

fn add(p: [f64; 2], k: f64, d: [f64; 2]) -> [f64; 2] {
    [p[0] + k * d[0], p[1] + k * d[1]]
}

fn point_body(name: &str, mass: f64, position: [f64; 2], velocity: [f64; 2]) -> Body {
    Body { name: name.into(), mass, inertia: None, position, angle: 0.0, velocity, angular_velocity: 0.0 }
}

fn rigid_body(
    name: &str,
    mass: f64,
    inertia: f64,
    position: [f64; 2],
    angle: f64,
    velocity: [f64; 2],
    angular_velocity: f64,
) -> Body {
    Body { name: name.into(), mass, inertia: Some(inertia), position, angle, velocity, angular_velocity }
}

/// An example whose observables are `first` (computed by `observe_first`)
/// followed by every coordinate.
fn example(
    built: crate::planar::Built,
    first: &[&str],
    observe_first: impl Fn(&[f64], &[f64], &mut [f64]) + Send + Sync + 'static,
    reference: Option<Reference>,
) -> Example {
    let k = first.len();
    let n = built.model.n();
    let mut observables: Vec<String> = first.iter().map(|s| s.to_string()).collect();
    observables.extend(built.names);
    let observe: Observe = Box::new(move |q, v, out| {
        observe_first(q, v, &mut out[..k]);
        out[k..k + n].copy_from_slice(&q[..n]);
    });
    Example { model: built.model, q0: built.q0, v0: built.v0, observables, observe, reference }
}

// ---------------------------------------------------------------------------
// Double pendulum
// ---------------------------------------------------------------------------

/// A double pendulum: two point masses on massless rods, the first rod
/// pinned at the origin. Angles are counter-clockwise from the downward
/// vertical; `theta2` is the second rod's absolute angle.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DoublePendulumParams {
    pub m1: f64,
    pub m2: f64,
    pub l1: f64,
    pub l2: f64,
    /// Gravitational acceleration, along −Y.
    pub gravity: f64,
    /// Initial angle of the first rod from the downward vertical.
    pub theta1: f64,
    /// Initial angle of the second rod from the downward vertical.
    pub theta2: f64,
    pub omega1: f64,
    pub omega2: f64,
}

impl Default for DoublePendulumParams {
    /// Unit masses and rods, both released at rest from the horizontal: the
    /// classic chaotic demonstration.
    fn default() -> Self {
        Self {
            m1: 1.0,
            m2: 1.0,
            l1: 1.0,
            l2: 1.0,
            gravity: 9.81,
            theta1: FRAC_PI_2,
            theta2: FRAC_PI_2,
            omega1: 0.0,
            omega2: 0.0,
        }
    }
}

impl DoublePendulumParams {
    fn validate(&self) -> Result<()> {
        positive("m1", self.m1)?;
        positive("m2", self.m2)?;
        positive("l1", self.l1)?;
        positive("l2", self.l2)?;
        non_negative("gravity", self.gravity)?;
        finite("theta1", self.theta1)?;
        finite("theta2", self.theta2)?;
        finite("omega1", self.omega1)?;
        finite("omega2", self.omega2)?;
        Ok(())
    }
}

/// The double pendulum in Cartesian coordinates
/// `q = (bob1.x, bob1.y, bob2.x, bob2.y)`.
///
/// Observables: `bob2.x`, `bob2.y` (the tip), `theta1`, `theta2` (from the
/// downward vertical, in (−π, π]), then the coordinates. No reference: the
/// motion is chaotic in general.
pub fn double_pendulum(p: DoublePendulumParams) -> Result<Example> {
    p.validate()?;
    let p1 = add([0.0, 0.0], p.l1, hanging(p.theta1));
    let p2 = add(p1, p.l2, hanging(p.theta2));
    let v1 = add([0.0, 0.0], p.l1 * p.omega1, dir(p.theta1));
    let v2 = add(v1, p.l2 * p.omega2, dir(p.theta2));
    let mut m = Mechanism::new([0.0, -p.gravity]);
    let b1 = m.push(point_body("bob1", p.m1, p1, v1));
    let b2 = m.push(point_body("bob2", p.m2, p2, v2));
    m.add(Element::Distance { a: BodyId::Ground, pa: [0.0, 0.0], b: b1, pb: [0.0, 0.0], length: p.l1 });
    m.add(Element::Distance { a: b1, pa: [0.0, 0.0], b: b2, pb: [0.0, 0.0], length: p.l2 });
    let built = m.build()?;
    Ok(example(
        built,
        &["bob2.x", "bob2.y", "theta1", "theta2"],
        |q, _v, out| {
            out[0] = q[2];
            out[1] = q[3];
            out[2] = q[0].atan2(-q[1]);
            out[3] = (q[2] - q[0]).atan2(q[1] - q[3]);
        },
        None,
    ))
}

// ---------------------------------------------------------------------------
// Chain
// ---------------------------------------------------------------------------

/// An N-link pendulum chain: N equal point masses joined by equal massless
/// rods, the first rod pinned at the origin. It starts straight, at angle
/// `theta0` from the downward vertical, rotating rigidly at `omega0` about
/// the pivot (`v_i = ω × r_i`; at rest when `omega0 = 0`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ChainParams {
    /// Number of links (and of masses), at least 1.
    pub n: usize,
    /// Mass of each point mass.
    pub mass: f64,
    /// Length of each link.
    pub length: f64,
    /// Gravitational acceleration, along −Y.
    pub gravity: f64,
    /// Angle of the straight chain from the downward vertical.
    pub theta0: f64,
    /// Initial rigid angular velocity about the pivot.
    pub omega0: f64,
}

impl Default for ChainParams {
    /// Five unit links released at rest from the horizontal.
    fn default() -> Self {
        Self { n: 5, mass: 1.0, length: 1.0, gravity: 9.81, theta0: FRAC_PI_2, omega0: 0.0 }
    }
}

impl ChainParams {
    fn validate(&self) -> Result<()> {
        if self.n == 0 {
            return Err(Error::InvalidParameter { name: "n", value: 0.0, reason: "a chain needs at least one link" });
        }
        positive("mass", self.mass)?;
        positive("length", self.length)?;
        non_negative("gravity", self.gravity)?;
        finite("theta0", self.theta0)?;
        finite("omega0", self.omega0)?;
        Ok(())
    }
}

/// `(q, v)` of a straight chain at angle `theta` (from the downward
/// vertical) rotating rigidly at `omega`.
fn straight_chain(n: usize, length: f64, theta: f64, omega: f64, q: &mut [f64], v: &mut [f64]) {
    let (r, t) = (hanging(theta), dir(theta));
    for i in 0..n {
        let k = (i + 1) as f64 * length;
        q[2 * i] = k * r[0];
        q[2 * i + 1] = k * r[1];
        v[2 * i] = k * omega * t[0];
        v[2 * i + 1] = k * omega * t[1];
    }
}

/// The chain in Cartesian coordinates `q = (bob1.x, bob1.y, …, bobN.y)`.
///
/// Observables: `tip.x`, `tip.y` (the last mass), then the coordinates.
/// Reference: without gravity the straight chain keeps rotating rigidly,
/// `θ = θ0 + ω0 t` (exact); with gravity and one link it is the exact
/// pendulum ([`PendulumExact`]); otherwise none.
pub fn chain(p: ChainParams) -> Result<Example> {
    p.validate()?;
    let n = p.n;
    let (mut q0, mut v0) = (vec![0.0; 2 * n], vec![0.0; 2 * n]);
    straight_chain(n, p.length, p.theta0, p.omega0, &mut q0, &mut v0);
    let mut m = Mechanism::new([0.0, -p.gravity]);
    let mut prev = BodyId::Ground;
    for i in 0..n {
        let bob = m.push(point_body(
            &format!("bob{}", i + 1),
            p.mass,
            [q0[2 * i], q0[2 * i + 1]],
            [v0[2 * i], v0[2 * i + 1]],
        ));
        m.add(Element::Distance { a: prev, pa: [0.0, 0.0], b: bob, pb: [0.0, 0.0], length: p.length });
        prev = bob;
    }
    let built = m.build()?;
    let reference: Option<Reference> = if p.gravity == 0.0 {
        Some(Box::new(move |t, q, v| {
            straight_chain(n, p.length, p.theta0 + p.omega0 * t, p.omega0, q, v);
        }))
    } else if n == 1 {
        PendulumExact::new(p.gravity / p.length, p.theta0 - FRAC_PI_2, p.omega0).ok().map(|exact| -> Reference {
            Box::new(move |t, q, v| {
                let (theta, omega) = exact.angle(t);
                straight_chain(1, p.length, theta + FRAC_PI_2, omega, q, v);
            })
        })
    } else {
        None
    };
    Ok(example(
        built,
        &["tip.x", "tip.y"],
        move |q, _v, out| {
            out[0] = q[2 * n - 2];
            out[1] = q[2 * n - 1];
        },
        reference,
    ))
}

// ---------------------------------------------------------------------------
// Load pendulum (the free degree of freedom of the driven mechanisms)
// ---------------------------------------------------------------------------

/// A point mass on a massless rod hanging from a driven point of a
/// mechanism. The angle is counter-clockwise from the downward vertical.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LoadPendulum {
    pub mass: f64,
    pub length: f64,
    /// Initial angle of the rod from the downward vertical.
    pub angle: f64,
    /// Initial angular velocity of the rod.
    pub omega: f64,
}

impl Default for LoadPendulum {
    fn default() -> Self {
        Self { mass: 0.5, length: 1.0, angle: 0.2, omega: 0.0 }
    }
}

impl LoadPendulum {
    fn validate(&self) -> Result<()> {
        positive("load mass", self.mass)?;
        positive("load length", self.length)?;
        finite("load angle", self.angle)?;
        finite("load omega", self.omega)?;
        Ok(())
    }

    /// Adds the bob hanging from `point` (local) of `support`, whose world
    /// position and velocity are `s`, `sd`.
    fn attach(&self, m: &mut Mechanism, support: BodyId, point: [f64; 2], s: [f64; 2], sd: [f64; 2]) {
        let bob = m.push(point_body(
            "load",
            self.mass,
            add(s, self.length, hanging(self.angle)),
            add(sd, self.length * self.omega, dir(self.angle)),
        ));
        m.add(Element::Distance { a: support, pa: point, b: bob, pb: [0.0, 0.0], length: self.length });
    }

    /// The load's angle `φ(t)` and rate, for a support moving with
    /// acceleration `acc(t)`: `L φ̈ = −g sin φ − a_x cos φ − a_y sin φ`
    /// (the tangential component of `m p̈ = m g + tension`), by fine RK-4.
    fn motion(
        &self,
        gravity: f64,
        rate: f64,
        acc: impl Fn(f64) -> [f64; 2] + Send + Sync + 'static,
        horizon_acc: f64,
    ) -> FineOde<2> {
        let l = self.length;
        let scale = self.omega.abs() + ((gravity + horizon_acc) / l).sqrt() + 4.0 * rate.abs() + 1e-3;
        FineOde::new(1e-3 / scale, [self.angle, self.omega], move |t, [phi, w]| {
            let [ax, ay] = acc(t);
            let (s, c) = phi.sin_cos();
            [w, -(gravity * s + ax * c + ay * s) / l]
        })
    }
}

/// Writes the load's `(q, v)` at `at` given the support's position and velocity.
fn load_state(load: &LoadPendulum, phi: [f64; 2], s: [f64; 2], sd: [f64; 2], at: usize, q: &mut [f64], v: &mut [f64]) {
    let p = add(s, load.length, hanging(phi[0]));
    let pv = add(sd, load.length * phi[1], dir(phi[0]));
    q[at..at + 2].copy_from_slice(&p);
    v[at..at + 2].copy_from_slice(&pv);
}

/// Largest magnitude of `acc` over `[0, period]` (64 samples), to size the
/// reference step.
fn max_acc(acc: impl Fn(f64) -> [f64; 2], period: f64) -> f64 {
    (0..64)
        .map(|i| {
            let [x, y] = acc(period * f64::from(i) / 64.0);
            x.hypot(y)
        })
        .fold(0.0, f64::max)
}

// ---------------------------------------------------------------------------
// Slider-crank
// ---------------------------------------------------------------------------

/// A slider-crank: the crank (pinned at the origin) is driven at constant
/// angular speed by a [`Element::DriveAngle`] relative to the ground; the
/// connecting rod joins the crank tip to the slider, which moves on the
/// X axis ([`Element::Prismatic`] with the ground, so it does not turn).
///
/// Without a load the driven slider-crank has no free motion (as many
/// constraints as coordinates): its motion is the kinematics, and the
/// simulation computes the forces and the drive's power. The optional
/// `load` pendulum hanging from the slider adds one free degree of freedom
/// that the drive has to shake.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SliderCrankParams {
    /// Crank radius `r`.
    pub crank_radius: f64,
    /// Connecting rod length `l > r`.
    pub rod_length: f64,
    pub crank_mass: f64,
    /// About the crank's centre (its midpoint).
    pub crank_inertia: f64,
    pub rod_mass: f64,
    /// About the rod's centre (its midpoint).
    pub rod_inertia: f64,
    pub slider_mass: f64,
    pub slider_inertia: f64,
    /// Constant crank speed `ω`.
    pub omega: f64,
    /// Initial crank angle from +X.
    pub theta0: f64,
    /// Gravitational acceleration, along −Y.
    pub gravity: f64,
    /// Pendulum hanging from the slider's centre.
    pub load: Option<LoadPendulum>,
}

impl Default for SliderCrankParams {
    /// `r = 0.5`, `l = 1.5`, uniform bars of 1 kg/m, a 1 kg slider, one
    /// revolution every π seconds, no load.
    fn default() -> Self {
        Self {
            crank_radius: 0.5,
            rod_length: 1.5,
            crank_mass: 0.5,
            crank_inertia: 0.5 * 0.25 / 12.0,
            rod_mass: 1.5,
            rod_inertia: 1.5 * 2.25 / 12.0,
            slider_mass: 1.0,
            slider_inertia: 0.01,
            omega: 2.0,
            theta0: 0.0,
            gravity: 9.81,
            load: None,
        }
    }
}

impl SliderCrankParams {
    fn validate(&self) -> Result<()> {
        let r = positive("crank_radius", self.crank_radius)?;
        let l = positive("rod_length", self.rod_length)?;
        if l <= r {
            return Err(Error::InvalidParameter {
                name: "rod_length",
                value: l,
                reason: "must exceed the crank radius for the crank to turn",
            });
        }
        positive("crank_mass", self.crank_mass)?;
        positive("crank_inertia", self.crank_inertia)?;
        positive("rod_mass", self.rod_mass)?;
        positive("rod_inertia", self.rod_inertia)?;
        positive("slider_mass", self.slider_mass)?;
        positive("slider_inertia", self.slider_inertia)?;
        validate_drive(self.omega, self.theta0, self.gravity, self.load.as_ref())
    }
}

/// Checks shared by the crank-driven mechanisms: drive speed, initial
/// crank angle, gravity and the optional load pendulum.
fn validate_drive(omega: f64, theta0: f64, gravity: f64, load: Option<&LoadPendulum>) -> Result<()> {
    finite("omega", omega)?;
    finite("theta0", theta0)?;
    non_negative("gravity", gravity)?;
    load.map_or(Ok(()), LoadPendulum::validate)
}

/// Exact kinematics of the slider-crank at crank angle `θ`, speed `ω`.
#[derive(Debug, Clone, Copy)]
struct SliderCrankState {
    crank: [f64; 6],
    rod: [f64; 6],
    /// Slider `x`, `ẋ`, `ẍ`.
    slider: [f64; 3],
}

fn slider_crank_kinematics(r: f64, l: f64, theta: f64, omega: f64) -> SliderCrankState {
    let (s, c) = theta.sin_cos();
    let root = (l * l - r * r * s * s).sqrt(); // l cos β
    let u = r * r * s * c;
    let x = r * c + root;
    let xd = -omega * (r * s + u / root);
    let xdd = -omega * omega * (r * c + r * r * (c * c - s * s) / root + u * u / root.powi(3));
    let beta = -(r * s / l).asin();
    let beta_d = -r * omega * c / root;
    let b = [r * c, r * s];
    let bd = [-r * omega * s, r * omega * c];
    SliderCrankState {
        crank: [0.5 * b[0], 0.5 * b[1], theta, 0.5 * bd[0], 0.5 * bd[1], omega],
        rod: [0.5 * (b[0] + x), 0.5 * b[1], beta, 0.5 * (bd[0] + xd), 0.5 * bd[1], beta_d],
        slider: [x, xd, xdd],
    }
}

/// Writes crank, rod and slider `(q, v)` (the first 9 coordinates).
fn slider_crank_state(k: &SliderCrankState, q: &mut [f64], v: &mut [f64]) {
    q[..3].copy_from_slice(&k.crank[..3]);
    v[..3].copy_from_slice(&k.crank[3..]);
    q[3..6].copy_from_slice(&k.rod[..3]);
    v[3..6].copy_from_slice(&k.rod[3..]);
    q[6..9].copy_from_slice(&[k.slider[0], 0.0, 0.0]);
    v[6..9].copy_from_slice(&[k.slider[1], 0.0, 0.0]);
}

/// The slider-crank in coordinates `crank.(x, y, angle)`, `rod.(x, y,
/// angle)`, `slider.(x, y, angle)` and, with a load, `load.(x, y)`.
///
/// Observables: `slider.x`, `slider.vx`, `rod.angle`, `load.angle` (with a
/// load; from the downward vertical), then the coordinates. Reference: the
/// exact kinematics, `θ = θ0 + ωt`, `x = r cos θ + √(l² − r² sin² θ)`,
/// `β = −asin(r sin θ / l)` and their rates; the load's angle by a fine RK-4
/// of its equation under the slider's exact acceleration.
pub fn slider_crank(p: SliderCrankParams) -> Result<Example> {
    p.validate()?;
    let (r, l) = (p.crank_radius, p.rod_length);
    let k = slider_crank_kinematics(r, l, p.theta0, p.omega);
    let mut m = Mechanism::new([0.0, -p.gravity]);
    let [cx, cy, ca, cvx, cvy, cw] = k.crank;
    let crank = m.push(rigid_body("crank", p.crank_mass, p.crank_inertia, [cx, cy], ca, [cvx, cvy], cw));
    let [rx, ry, ra, rvx, rvy, rw] = k.rod;
    let rod = m.push(rigid_body("rod", p.rod_mass, p.rod_inertia, [rx, ry], ra, [rvx, rvy], rw));
    let slider =
        m.push(rigid_body("slider", p.slider_mass, p.slider_inertia, [k.slider[0], 0.0], 0.0, [k.slider[1], 0.0], 0.0));
    m.add(Element::Revolute { a: BodyId::Ground, pa: [0.0, 0.0], b: crank, pb: [-0.5 * r, 0.0] });
    m.add(Element::DriveAngle { a: BodyId::Ground, b: crank, f: TimeFn::linear(p.theta0, p.omega) });
    m.add(Element::Revolute { a: crank, pa: [0.5 * r, 0.0], b: rod, pb: [-0.5 * l, 0.0] });
    m.add(Element::Revolute { a: rod, pa: [0.5 * l, 0.0], b: slider, pb: [0.0, 0.0] });
    m.add(Element::Prismatic { a: BodyId::Ground, pa: [0.0, 0.0], b: slider, pb: [0.0, 0.0], axis: [1.0, 0.0] });
    if let Some(load) = &p.load {
        load.attach(&mut m, slider, [0.0, 0.0], [k.slider[0], 0.0], [k.slider[1], 0.0]);
    }
    let built = m.build()?;

    let (theta0, omega) = (p.theta0, p.omega);
    let acc = move |t: f64| [slider_crank_kinematics(r, l, theta0 + omega * t, omega).slider[2], 0.0];
    let load = p.load.map(|load| {
        let horizon = max_acc(acc, 2.0 * PI / omega.abs().max(1e-3));
        (load, load.motion(p.gravity, omega, acc, horizon))
    });
    let reference: Reference = Box::new(move |t, q, v| {
        let k = slider_crank_kinematics(r, l, theta0 + omega * t, omega);
        slider_crank_state(&k, q, v);
        if let Some((load, ode)) = &load {
            let s = [k.slider[0], 0.0];
            load_state(load, ode.at(t), s, [k.slider[1], 0.0], 9, q, v);
        }
    });
    let has_load = p.load.is_some();
    let first: &[&str] = if has_load {
        &["slider.x", "slider.vx", "rod.angle", "load.angle"]
    } else {
        &["slider.x", "slider.vx", "rod.angle"]
    };
    Ok(example(
        built,
        first,
        move |q, v, out| {
            out[0] = q[6];
            out[1] = v[6];
            out[2] = q[5];
            if has_load {
                out[3] = (q[9] - q[6]).atan2(q[7] - q[10]);
            }
        },
        Some(reference),
    ))
}

// ---------------------------------------------------------------------------
// Four-bar linkage
// ---------------------------------------------------------------------------

/// Which of the two assemblies of a four-bar linkage: joint C lies to the
/// left or to the right of the directed line from B (crank tip) to D
/// (rocker pivot).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum FourBarBranch {
    /// C to the left of B→D (with A left of D: the "open", C-above assembly).
    #[default]
    Left,
    Right,
}

/// A four-bar linkage: ground pivots A = (0, 0) and D = (d, 0); crank AB
/// (length a) driven at constant angular speed by a [`Element::DriveAngle`]
/// relative to the ground; coupler BC (length b); rocker DC (length c);
/// revolute joints at A, B, C, D. The crank must turn fully without
/// reaching a toggle position: `|b − c| < d − a` and `d + a < b + c`
/// (Grashof, crank shortest and adjacent to the ground).
///
/// As for [`SliderCrankParams`], the driven linkage has no free motion of
/// its own; an optional `load` pendulum hanging from joint C adds one.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FourBarParams {
    /// Crank length `a` (AB).
    pub crank_length: f64,
    /// Coupler length `b` (BC).
    pub coupler_length: f64,
    /// Rocker length `c` (DC).
    pub rocker_length: f64,
    /// Ground length `d` (AD).
    pub ground_length: f64,
    pub crank_mass: f64,
    pub crank_inertia: f64,
    pub coupler_mass: f64,
    pub coupler_inertia: f64,
    pub rocker_mass: f64,
    pub rocker_inertia: f64,
    /// Constant crank speed `ω`.
    pub omega: f64,
    /// Initial crank angle from +X.
    pub theta0: f64,
    /// Gravitational acceleration, along −Y.
    pub gravity: f64,
    pub branch: FourBarBranch,
    /// Pendulum hanging from joint C.
    pub load: Option<LoadPendulum>,
}

impl Default for FourBarParams {
    /// A Grashof crank-rocker `a = 1, b = 3, c = 2.5, d = 3` (s + l = 4 <
    /// p + q = 5.5, crank shortest), uniform bars of 1 kg/m, ω = 2, the open
    /// assembly, no load.
    fn default() -> Self {
        let bar = |len: f64| (len, len * len * len / 12.0);
        let ((ma, ia), (mb, ib), (mc, ic)) = (bar(1.0), bar(3.0), bar(2.5));
        Self {
            crank_length: 1.0,
            coupler_length: 3.0,
            rocker_length: 2.5,
            ground_length: 3.0,
            crank_mass: ma,
            crank_inertia: ia,
            coupler_mass: mb,
            coupler_inertia: ib,
            rocker_mass: mc,
            rocker_inertia: ic,
            omega: 2.0,
            theta0: 0.0,
            gravity: 9.81,
            branch: FourBarBranch::Left,
            load: None,
        }
    }
}

impl FourBarParams {
    fn validate(&self) -> Result<()> {
        let a = positive("crank_length", self.crank_length)?;
        let b = positive("coupler_length", self.coupler_length)?;
        let c = positive("rocker_length", self.rocker_length)?;
        let d = positive("ground_length", self.ground_length)?;
        if (b - c).abs() >= d - a || d + a >= b + c {
            return Err(Problem::NoFullTurn { lengths: [a, b, c, d] }.into());
        }
        positive("crank_mass", self.crank_mass)?;
        positive("crank_inertia", self.crank_inertia)?;
        positive("coupler_mass", self.coupler_mass)?;
        positive("coupler_inertia", self.coupler_inertia)?;
        positive("rocker_mass", self.rocker_mass)?;
        positive("rocker_inertia", self.rocker_inertia)?;
        validate_drive(self.omega, self.theta0, self.gravity, self.load.as_ref())
    }
}

/// Exact kinematics of the four-bar at crank angle `θ`, speed `ω`.
#[derive(Debug, Clone, Copy)]
struct FourBarState {
    /// Angles of crank, coupler, rocker.
    angle: [f64; 3],
    /// Their rates.
    rate: [f64; 3],
    /// Acceleration of joint C.
    c_acc: [f64; 2],
}

fn four_bar_kinematics([a, b, c, d]: [f64; 4], sigma: f64, theta: f64, omega: f64) -> FourBarState {
    // Circle intersection: C at distance b from B and c from D. The
    // direction B→D never reverses (D is outside the crank circle), so the
    // angles below are continuous in θ.
    let bp = [a * theta.cos(), a * theta.sin()];
    let bd = [d - bp[0], -bp[1]];
    let e2 = bd[0] * bd[0] + bd[1] * bd[1];
    let e = e2.sqrt();
    let toward_d = bd[1].atan2(bd[0]);
    let at_b = ((e2 + b * b - c * c) / (2.0 * e * b)).clamp(-1.0, 1.0).acos();
    let at_d = ((e2 + c * c - b * b) / (2.0 * e * c)).clamp(-1.0, 1.0).acos();
    let beta = toward_d + sigma * at_b;
    let psi = toward_d + PI - sigma * at_d;
    // Loop closure a e(θ) + b e(β) = d e_x + c e(ψ), differentiated:
    // a ω e⊥(θ) + b β̇ e⊥(β) = c ψ̇ e⊥(ψ); e⊥(x)·e(y) = sin(y − x).
    let s_bp = (beta - psi).sin();
    let psi_d = a * omega * (beta - theta).sin() / (c * s_bp);
    let beta_d = a * omega * (psi - theta).sin() / (b * s_bp);
    // Once more (θ̈ = 0), dotted with e(β):
    // −a ω² cos(θ − β) − b β̇² = c ψ̈ sin(β − ψ) − c ψ̇² cos(ψ − β).
    let psi_dd = (-a * omega * omega * (theta - beta).cos() - b * beta_d * beta_d
        + c * psi_d * psi_d * (psi - beta).cos())
        / (c * s_bp);
    let (ep, np) = (dir(psi), perp(psi));
    FourBarState {
        angle: [theta, beta, psi],
        rate: [omega, beta_d, psi_d],
        c_acc: [c * (psi_dd * np[0] - psi_d * psi_d * ep[0]), c * (psi_dd * np[1] - psi_d * psi_d * ep[1])],
    }
}

/// Writes crank, coupler, rocker `(q, v)` (the first 9 coordinates) and
/// returns joint C's position and velocity.
fn four_bar_state([a, b, c, d]: [f64; 4], k: &FourBarState, q: &mut [f64], v: &mut [f64]) -> ([f64; 2], [f64; 2]) {
    let [theta, beta, psi] = k.angle;
    let [w, beta_d, psi_d] = k.rate;
    let bp = add([0.0, 0.0], a, dir(theta));
    let bv = add([0.0, 0.0], a * w, perp(theta));
    let crank = (add([0.0, 0.0], 0.5 * a, dir(theta)), add([0.0, 0.0], 0.5 * a * w, perp(theta)));
    let coupler = (add(bp, 0.5 * b, dir(beta)), add(bv, 0.5 * b * beta_d, perp(beta)));
    let rocker = (add([d, 0.0], 0.5 * c, dir(psi)), add([0.0, 0.0], 0.5 * c * psi_d, perp(psi)));
    for (i, ((p, pv), angle, rate)) in
        [(crank, theta, w), (coupler, beta, beta_d), (rocker, psi, psi_d)].into_iter().enumerate()
    {
        q[3 * i..3 * i + 3].copy_from_slice(&[p[0], p[1], angle]);
        v[3 * i..3 * i + 3].copy_from_slice(&[pv[0], pv[1], rate]);
    }
    (add([d, 0.0], c, dir(psi)), add([0.0, 0.0], c * psi_d, perp(psi)))
}

/// The four-bar in coordinates `crank.(x, y, angle)`, `coupler.(x, y,
/// angle)`, `rocker.(x, y, angle)` and, with a load, `load.(x, y)`.
///
/// Observables: `rocker.angle`, `coupler.angle`, `rocker.rate`, `load.angle`
/// (with a load; from the downward vertical), then the coordinates.
/// Reference: the exact kinematics by circle intersection on the chosen
/// branch, rates and accelerations from the differentiated loop closure;
/// the load's angle by a fine RK-4 under joint C's exact acceleration.
pub fn four_bar(p: FourBarParams) -> Result<Example> {
    p.validate()?;
    let dims = [p.crank_length, p.coupler_length, p.rocker_length, p.ground_length];
    let [a, b, c, d] = dims;
    let sigma = match p.branch {
        FourBarBranch::Left => 1.0,
        FourBarBranch::Right => -1.0,
    };
    let k = four_bar_kinematics(dims, sigma, p.theta0, p.omega);
    let (mut q0, mut v0) = ([0.0; 9], [0.0; 9]);
    let (cp, cv) = four_bar_state(dims, &k, &mut q0, &mut v0);
    let mut m = Mechanism::new([0.0, -p.gravity]);
    let mut body = |name: &str, mass, inertia, i: usize| {
        m.push(rigid_body(
            name,
            mass,
            inertia,
            [q0[3 * i], q0[3 * i + 1]],
            q0[3 * i + 2],
            [v0[3 * i], v0[3 * i + 1]],
            v0[3 * i + 2],
        ))
    };
    let crank = body("crank", p.crank_mass, p.crank_inertia, 0);
    let coupler = body("coupler", p.coupler_mass, p.coupler_inertia, 1);
    let rocker = body("rocker", p.rocker_mass, p.rocker_inertia, 2);
    m.add(Element::Revolute { a: BodyId::Ground, pa: [0.0, 0.0], b: crank, pb: [-0.5 * a, 0.0] });
    m.add(Element::DriveAngle { a: BodyId::Ground, b: crank, f: TimeFn::linear(p.theta0, p.omega) });
    m.add(Element::Revolute { a: crank, pa: [0.5 * a, 0.0], b: coupler, pb: [-0.5 * b, 0.0] });
    m.add(Element::Revolute { a: coupler, pa: [0.5 * b, 0.0], b: rocker, pb: [0.5 * c, 0.0] });
    m.add(Element::Revolute { a: BodyId::Ground, pa: [d, 0.0], b: rocker, pb: [-0.5 * c, 0.0] });
    if let Some(load) = &p.load {
        load.attach(&mut m, rocker, [0.5 * c, 0.0], cp, cv);
    }
    let built = m.build()?;

    let (theta0, omega) = (p.theta0, p.omega);
    let acc = move |t: f64| four_bar_kinematics(dims, sigma, theta0 + omega * t, omega).c_acc;
    let load = p.load.map(|load| {
        let horizon = max_acc(acc, 2.0 * PI / omega.abs().max(1e-3));
        (load, load.motion(p.gravity, omega, acc, horizon))
    });
    let reference: Reference = Box::new(move |t, q, v| {
        let k = four_bar_kinematics(dims, sigma, theta0 + omega * t, omega);
        let (cp, cv) = four_bar_state(dims, &k, q, v);
        if let Some((load, ode)) = &load {
            load_state(load, ode.at(t), cp, cv, 9, q, v);
        }
    });
    let has_load = p.load.is_some();
    let first: &[&str] = if has_load {
        &["rocker.angle", "coupler.angle", "rocker.rate", "load.angle"]
    } else {
        &["rocker.angle", "coupler.angle", "rocker.rate"]
    };
    Ok(example(
        built,
        first,
        move |q, v, out| {
            out[0] = q[8];
            out[1] = q[5];
            out[2] = v[8];
            if has_load {
                // C is the rocker's far end.
                let cp = add([q[6], q[7]], 0.5 * c, dir(q[8]));
                out[3] = (q[9] - cp[0]).atan2(cp[1] - q[10]);
            }
        },
        Some(reference),
    ))
}

// ---------------------------------------------------------------------------
// Pendulum on a moving support
// ---------------------------------------------------------------------------

/// A point mass on a rod from a support point whose `x` and `y` are
/// prescribed functions of time ([`Element::DriveCoordinate`]): the drives
/// exercise `Φ_t` and `Φ_tt`. The rod angle is counter-clockwise from +X,
/// as in [`super::PendulumParams`].
#[derive(Debug, Clone, PartialEq)]
pub struct MovingSupportParams {
    /// Mass of the (driven) support point.
    pub support_mass: f64,
    /// Mass of the bob.
    pub mass: f64,
    pub length: f64,
    /// Gravitational acceleration, along −Y.
    pub gravity: f64,
    /// Support `x(t)`.
    pub support_x: TimeFn,
    /// Support `y(t)`.
    pub support_y: TimeFn,
    /// Initial rod angle from +X (bob relative to the support).
    pub theta0: f64,
    /// Initial angular velocity of the rod.
    pub omega0: f64,
}

impl Default for MovingSupportParams {
    /// A support accelerating uniformly, `x = 0.5 t + t²`, `y = 0.5 t²`
    /// (`a = (2, 1)`), under `g = 9.81`; the bob 0.5 rad from the bottom, at
    /// rest relative to the support.
    fn default() -> Self {
        Self {
            support_mass: 1.0,
            mass: 1.0,
            length: 1.0,
            gravity: 9.81,
            support_x: TimeFn { polynomial: vec![0.0, 0.5, 1.0], sines: Vec::new() },
            support_y: TimeFn { polynomial: vec![0.0, 0.0, 0.5], sines: Vec::new() },
            theta0: -FRAC_PI_2 + 0.5,
            omega0: 0.0,
        }
    }
}

impl MovingSupportParams {
    /// A support oscillating as `x = ax sin(w t)`, `y = ay sin(w t)`.
    pub fn sinusoidal(ax: f64, ay: f64, w: f64) -> Self {
        let sine = |amp: f64| TimeFn { polynomial: Vec::new(), sines: vec![[amp, w, 0.0]] };
        Self { support_x: sine(ax), support_y: sine(ay), ..Self::default() }
    }

    fn validate(&self) -> Result<()> {
        positive("support_mass", self.support_mass)?;
        positive("mass", self.mass)?;
        positive("length", self.length)?;
        non_negative("gravity", self.gravity)?;
        finite("theta0", self.theta0)?;
        finite("omega0", self.omega0)?;
        for (axis, f) in [("x", &self.support_x), ("y", &self.support_y)] {
            if !f.is_finite() {
                return Err(Problem::NonFiniteFunction.at(Part::Support(axis)));
            }
        }
        Ok(())
    }
}

/// `f(t)`, `f'(t)`, `f''(t)` of a time function, by hand.
fn time_derivatives(f: &TimeFn, t: f64) -> [f64; 3] {
    let mut out = [0.0; 3];
    for (k, &c) in f.polynomial.iter().enumerate() {
        let k = k as i32;
        out[0] += c * t.powi(k);
        if k >= 1 {
            out[1] += c * f64::from(k) * t.powi(k - 1);
        }
        if k >= 2 {
            out[2] += c * f64::from(k * (k - 1)) * t.powi(k - 2);
        }
    }
    for &[amp, w, phase] in &f.sines {
        let (s, c) = (w * t + phase).sin_cos();
        out[0] += amp * s;
        out[1] += amp * w * c;
        out[2] -= amp * w * w * s;
    }
    out
}

/// The constant acceleration of a polynomial of degree ≤ 2 without sines.
fn uniform_acceleration(f: &TimeFn) -> Option<f64> {
    let higher = f.polynomial.iter().skip(3).all(|&c| c == 0.0);
    (f.sines.iter().all(|s| s[0] == 0.0) && higher).then(|| 2.0 * f.polynomial.get(2).copied().unwrap_or(0.0))
}

/// The pendulum on a moving support, coordinates `support.(x, y)`,
/// `bob.(x, y)`.
///
/// Observables: `rel.x`, `rel.y` (bob relative to the support, the
/// pendulum proper), then the coordinates. Reference: for a uniformly
/// accelerated support (both functions polynomials of degree ≤ 2), the
/// motion relative to the support is an ordinary pendulum under the
/// effective gravity `g_eff = (0, −g) − a`: with `ρ` the angle that turns
/// −Y onto `g_eff`, `θ − ρ` obeys `θ̈' = −(|g_eff|/L) cos θ'`, which is
/// [`PendulumExact`]. Otherwise (or on the separatrix) the rod angle by a
/// fine RK-4 of `L θ̈ = g_eff(t) · (−sin θ, cos θ)`.
pub fn moving_support_pendulum(p: MovingSupportParams) -> Result<Example> {
    p.validate()?;
    let (len, th0, om0) = (p.length, p.theta0, p.omega0);
    let [sx, sxd, _] = time_derivatives(&p.support_x, 0.0);
    let [sy, syd, _] = time_derivatives(&p.support_y, 0.0);
    let mut m = Mechanism::new([0.0, -p.gravity]);
    let support = m.push(point_body("support", p.support_mass, [sx, sy], [sxd, syd]));
    let bob = m.push(point_body("bob", p.mass, add([sx, sy], len, dir(th0)), add([sxd, syd], len * om0, perp(th0))));
    for (coordinate, f) in [(Coordinate::X, &p.support_x), (Coordinate::Y, &p.support_y)] {
        m.add(Element::DriveCoordinate { body: support, coordinate, f: f.clone() });
    }
    m.add(Element::Distance { a: support, pa: [0.0, 0.0], b: bob, pb: [0.0, 0.0], length: len });
    let built = m.build()?;

    let (fx, fy) = (p.support_x.clone(), p.support_y.clone());
    let support_at = move |t: f64| (time_derivatives(&fx, t), time_derivatives(&fy, t));
    let write = move |t: f64, theta: f64, omega: f64, q: &mut [f64], v: &mut [f64]| {
        let ([x, xd, _], [y, yd, _]) = support_at(t);
        q[..2].copy_from_slice(&[x, y]);
        v[..2].copy_from_slice(&[xd, yd]);
        q[2..4].copy_from_slice(&add([x, y], len, dir(theta)));
        v[2..4].copy_from_slice(&add([xd, yd], len * omega, perp(theta)));
    };
    let g = p.gravity;
    let exact = match (uniform_acceleration(&p.support_x), uniform_acceleration(&p.support_y)) {
        (Some(ax), Some(ay)) => {
            let geff = [-ax, -g - ay];
            let mag = geff[0].hypot(geff[1]);
            if mag == 0.0 {
                // Weightless in the support frame: uniform rotation.
                Some(None)
            } else {
                let rho = geff[1].atan2(geff[0]) + FRAC_PI_2;
                PendulumExact::new(mag / len, th0 - rho, om0).ok().map(|e| Some((e, rho)))
            }
        }
        _ => None,
    };
    let reference: Reference = match exact {
        Some(Some((e, rho))) => Box::new(move |t, q, v| {
            let (th, om) = e.angle(t);
            write(t, th + rho, om, q, v);
        }),
        Some(None) => Box::new(move |t, q, v| write(t, th0 + om0 * t, om0, q, v)),
        None => {
            let (fx, fy) = (p.support_x.clone(), p.support_y.clone());
            let acc = move |t: f64| [time_derivatives(&fx, t)[2], time_derivatives(&fy, t)[2]];
            let scale = om0.abs()
                + ((g + max_acc(&acc, 10.0)) / len).sqrt()
                + [&p.support_x, &p.support_y]
                    .iter()
                    .flat_map(|f| f.sines.iter().map(|s| s[1].abs()))
                    .fold(0.0, f64::max)
                + 1e-3;
            let ode = FineOde::new(1e-3 / scale, [th0, om0], move |t, [th, w]| {
                let [ax, ay] = acc(t);
                let (s, c) = th.sin_cos();
                [w, (ax * s - (g + ay) * c) / len]
            });
            Box::new(move |t, q, v| {
                let [th, om] = ode.at(t);
                write(t, th, om, q, v);
            })
        }
    };
    Ok(example(
        built,
        &["rel.x", "rel.y"],
        |q, _v, out| {
            out[0] = q[2] - q[0];
            out[1] = q[3] - q[1];
        },
        Some(reference),
    ))
}

// ---------------------------------------------------------------------------
// Damped pendulum
// ---------------------------------------------------------------------------

/// A rigid pendulum pinned at one end, with a rotary damper (torque
/// `−c ω`) between it and the ground. The angle of the pivot→centre line is
/// counter-clockwise from +X, as in [`super::PendulumParams`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DampedPendulumParams {
    pub mass: f64,
    /// Moment of inertia about the centre of mass.
    pub inertia: f64,
    /// Distance from the pivot to the centre of mass.
    pub length: f64,
    /// Gravitational acceleration, along −Y.
    pub gravity: f64,
    /// Rotary damping coefficient `c ≥ 0`.
    pub damping: f64,
    /// Initial angle from +X.
    pub theta0: f64,
    pub omega0: f64,
}

impl Default for DampedPendulumParams {
    /// A uniform 1 kg, 1 m bar pinned at one end (`l_c = 0.5`, `I = 1/12`),
    /// `c = 0.1`, released at rest from the horizontal: the energy decays
    /// roughly as `e^{−(c/I_pivot) t} = e^{−0.3 t}`.
    fn default() -> Self {
        Self { mass: 1.0, inertia: 1.0 / 12.0, length: 0.5, gravity: 9.81, damping: 0.1, theta0: 0.0, omega0: 0.0 }
    }
}

impl DampedPendulumParams {
    fn validate(&self) -> Result<()> {
        positive("mass", self.mass)?;
        positive("inertia", self.inertia)?;
        positive("length", self.length)?;
        non_negative("gravity", self.gravity)?;
        non_negative("damping", self.damping)?;
        finite("theta0", self.theta0)?;
        finite("omega0", self.omega0)?;
        Ok(())
    }

    /// Moment of inertia about the pivot.
    pub fn pivot_inertia(&self) -> f64 {
        self.inertia + self.mass * self.length * self.length
    }
}

/// The damped pendulum, coordinates `bar.(x, y, angle)`.
///
/// Observables: `theta` (the body angle, continuous), `omega`, then the
/// coordinates. Reference: `I_pivot θ̈ = −m g l_c cos θ − c θ̇` — for `c = 0`
/// the exact pendulum, otherwise a fine RK-4 (error about 1e-13).
pub fn damped_pendulum(p: DampedPendulumParams) -> Result<Example> {
    p.validate()?;
    let (lc, th0, om0) = (p.length, p.theta0, p.omega0);
    let state = move |theta: f64, omega: f64, q: &mut [f64], v: &mut [f64]| {
        let (c, n) = (dir(theta), perp(theta));
        q[..3].copy_from_slice(&[lc * c[0], lc * c[1], theta]);
        v[..3].copy_from_slice(&[lc * omega * n[0], lc * omega * n[1], omega]);
    };
    let (mut q0, mut v0) = ([0.0; 3], [0.0; 3]);
    state(th0, om0, &mut q0, &mut v0);
    let mut m = Mechanism::new([0.0, -p.gravity]);
    let bar = m.push(rigid_body("bar", p.mass, p.inertia, [q0[0], q0[1]], q0[2], [v0[0], v0[1]], v0[2]));
    m.add(Element::Revolute { a: BodyId::Ground, pa: [0.0, 0.0], b: bar, pb: [-lc, 0.0] });
    m.add(Element::RotaryDamper { a: BodyId::Ground, b: bar, damping: p.damping });
    let built = m.build()?;

    let ip = p.pivot_inertia();
    let w2 = p.mass * p.gravity * lc / ip;
    let cd = p.damping / ip;
    let exact = (cd == 0.0).then(|| PendulumExact::new(w2, th0, om0).ok()).flatten();
    let reference: Reference = match exact {
        Some(e) => Box::new(move |t, q, v| {
            let (th, om) = e.angle(t);
            state(th, om, q, v);
        }),
        None => {
            let scale = (om0 * om0 + 4.0 * w2).sqrt() + cd + 1e-3;
            let ode = FineOde::new(1e-3 / scale, [th0, om0], move |_t, [th, w]| [w, -w2 * th.cos() - cd * w]);
            Box::new(move |t, q, v| {
                let [th, om] = ode.at(t);
                state(th, om, q, v);
            })
        }
    };
    Ok(example(
        built,
        &["theta", "omega"],
        |q, v, out| {
            out[0] = q[2];
            out[1] = v[2];
        },
        Some(reference),
    ))
}

/// Classical RK-4 with a small fixed step, continued incrementally: the
/// state at the last whole step is cached, so calls with increasing `t`
/// only integrate the new interval; a call with an earlier `t` restarts
/// from `t = 0`. The increments are added with Kahan compensation, so that
/// the rounding of ~10⁵ small steps does not accumulate past ~1e-14.
mod fine_ode {
    use std::sync::{Mutex, PoisonError};

    type Rhs<const N: usize> = Box<dyn Fn(f64, [f64; N]) -> [f64; N] + Send + Sync>;

    /// More steps than this per call are refused (the result is NaN).
    const MAX_STEPS: f64 = 1e9;

    /// Steps taken, the state at `steps · h`, and its Kahan compensation.
    type Cache<const N: usize> = (u64, [f64; N], [f64; N]);

    pub(crate) struct FineOde<const N: usize> {
        rhs: Rhs<N>,
        y0: [f64; N],
        h: f64,
        cache: Mutex<Cache<N>>,
    }

    impl<const N: usize> FineOde<N> {
        /// `y' = rhs(t, y)`, `y(0) = y0`, step `h > 0`.
        pub(crate) fn new(
            h: f64,
            y0: [f64; N],
            rhs: impl Fn(f64, [f64; N]) -> [f64; N] + Send + Sync + 'static,
        ) -> Self {
            Self { rhs: Box::new(rhs), y0, h, cache: Mutex::new((0, y0, [0.0; N])) }
        }

        /// The RK-4 increment `y(t + h) − y(t)`.
        fn increment(&self, t: f64, y: [f64; N], h: f64) -> [f64; N] {
            let f = &self.rhs;
            let at = |k: [f64; N], c: f64| std::array::from_fn(|i| y[i] + c * k[i]);
            let k1 = f(t, y);
            let k2 = f(t + 0.5 * h, at(k1, 0.5 * h));
            let k3 = f(t + 0.5 * h, at(k2, 0.5 * h));
            let k4 = f(t + h, at(k3, h));
            std::array::from_fn(|i| h / 6.0 * (k1[i] + 2.0 * (k2[i] + k3[i]) + k4[i]))
        }

        /// `y(t)` for `t ≥ 0` (NaN for negative, non-finite or too distant `t`).
        pub(crate) fn at(&self, t: f64) -> [f64; N] {
            let whole = (t / self.h).floor();
            if !(0.0..=MAX_STEPS).contains(&whole) {
                return [f64::NAN; N];
            }
            let whole = whole as u64;
            let mut cache = self.cache.lock().unwrap_or_else(PoisonError::into_inner);
            if cache.0 > whole {
                *cache = (0, self.y0, [0.0; N]);
            }
            while cache.0 < whole {
                let (k, y, mut comp) = *cache;
                let dy = self.increment(k as f64 * self.h, y, self.h);
                let y = std::array::from_fn(|i| {
                    let d = dy[i] - comp[i];
                    let sum = y[i] + d;
                    comp[i] = (sum - y[i]) - d;
                    sum
                });
                *cache = (k + 1, y, comp);
            }
            let (k, y, comp) = *cache;
            let t0 = k as f64 * self.h;
            let dy = if t > t0 { self.increment(t0, y, t - t0) } else { [0.0; N] };
            std::array::from_fn(|i| y[i] + (dy[i] - comp[i]))
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: f64, b: f64, tol: f64, what: &str) {
        assert!((a - b).abs() <= tol, "{what}: {a} vs {b} (diff {:e})", a - b);
    }

    #[test]
    fn fine_ode_matches_the_exact_pendulum_and_is_incremental() {
        let (w2, th0, om0) = (9.81 * 3.0 / 2.0, 0.3, 1.0);
        let exact = PendulumExact::new(w2, th0, om0).unwrap();
        let ode =
            FineOde::new(1e-3 / (om0 * om0 + 4.0 * w2).sqrt(), [th0, om0], move |_t, [th, w]| [w, -w2 * th.cos()]);
        let mut worst = 0.0_f64;
        for i in 0..=200 {
            let t = 0.05 * f64::from(i) + 0.0123;
            let [th, om] = ode.at(t);
            let (te, oe) = exact.angle(t);
            worst = worst.max((th - te).abs()).max((om - oe).abs());
        }
        // Truncation ≈ 1.3e-14 here (16× below the 2e-13 measured at twice the
        // step), Kahan-summed rounding and the exact solution ≈ 1e-14 each.
        assert!(worst < 2e-13, "fine RK-4 vs exact pendulum over 10 s: {worst:e}");
        // Going back restarts and gives the same numbers.
        let late = ode.at(7.3);
        let early = ode.at(0.4);
        assert_eq!(ode.at(7.3), late);
        assert_eq!(ode.at(0.4), early);
        assert!(ode.at(-1.0)[0].is_nan());
    }

    /// Central differences of `f` at `t`.
    fn diff(f: impl Fn(f64) -> f64, t: f64) -> f64 {
        let h = 1e-5;
        (f(t + h) - f(t - h)) / (2.0 * h)
    }

    #[test]
    fn slider_crank_kinematics_rates_are_the_derivatives() {
        let (r, l, w) = (0.5, 1.5, 2.0);
        for i in 0..40 {
            let t = 0.17 * f64::from(i);
            let k = |t: f64| slider_crank_kinematics(r, l, 0.3 + w * t, w);
            let s = k(t);
            // Rod joins the crank tip and the slider.
            let b = [2.0 * s.crank[0], 2.0 * s.crank[1]];
            close((s.slider[0] - b[0]).hypot(b[1]), l, 1e-14, "rod length");
            close(s.rod[0], 0.5 * (b[0] + s.slider[0]), 1e-14, "rod centre");
            close(s.rod[2], (-b[1]).atan2(s.slider[0] - b[0]), 1e-14, "rod angle");
            for j in 0..3 {
                close(diff(|t| k(t).crank[j], t), s.crank[3 + j], 1e-8, "crank rate");
                close(diff(|t| k(t).rod[j], t), s.rod[3 + j], 1e-8, "rod rate");
            }
            close(diff(|t| k(t).slider[0], t), s.slider[1], 1e-8, "ẋ");
            close(diff(|t| k(t).slider[1], t), s.slider[2], 1e-7, "ẍ");
        }
    }

    #[test]
    fn four_bar_kinematics_close_the_loop_and_rates_are_the_derivatives() {
        let dims @ [a, b, c, d] = [1.0, 3.0, 2.5, 3.0];
        for sigma in [1.0, -1.0] {
            for i in 0..60 {
                let t = 0.13 * f64::from(i);
                let k = |t: f64| four_bar_kinematics(dims, sigma, 0.4 + 2.0 * t, 2.0);
                let s = k(t);
                let [th, be, ps] = s.angle;
                let bp = add([0.0, 0.0], a, dir(th));
                let c1 = add(bp, b, dir(be));
                let c2 = add([d, 0.0], c, dir(ps));
                close(c1[0], c2[0], 1e-13, "loop x");
                close(c1[1], c2[1], 1e-13, "loop y");
                // C on the chosen side of B→D.
                let cross = (d - bp[0]) * (c1[1] - bp[1]) - (-bp[1]) * (c1[0] - bp[0]);
                assert!(cross * sigma > 0.0, "branch");
                for j in 0..3 {
                    close(diff(|t| k(t).angle[j], t), s.rate[j], 1e-8, "rate");
                }
                let cpos = |t: f64| add([d, 0.0], c, dir(k(t).angle[2]));
                let cvel = |t: f64, j: usize| diff(|t| cpos(t)[j], t);
                for j in 0..2 {
                    close(diff(|t| cvel(t, j), t), s.c_acc[j], 1e-4, "C acceleration");
                }
            }
        }
    }

    #[test]
    fn time_derivatives_by_hand() {
        let f = TimeFn { polynomial: vec![1.0, -2.0, 0.5, 0.25], sines: vec![[0.3, 2.0, 0.1], [-0.2, 5.0, -1.0]] };
        for i in 0..20 {
            let t = 0.3 * f64::from(i) - 2.0;
            let [v, d1, d2] = time_derivatives(&f, t);
            close(v, f.eval(t), 1e-13, "f");
            close(d1, diff(|t| f.eval(t), t), 1e-8, "f'");
            close(d2, diff(|t| time_derivatives(&f, t)[1], t), 1e-8, "f''");
        }
        assert_eq!(uniform_acceleration(&f), None);
        let quad = TimeFn { polynomial: vec![1.0, 2.0, 3.0, 0.0], sines: vec![] };
        assert_eq!(uniform_acceleration(&quad), Some(6.0));
    }
}
