//! Joint actuators (`spatial::Actuator`): a torque as a function of time,
//! a PD servo to a target and the clamp at the joint's effort, against
//! hand-computed accelerations and the closed form of a damped
//! oscillator; their power in the energy balance; their velocity
//! Jacobian (by AD) against finite differences.

use cdyn::dynamics::Dynamics;
use cdyn::model::input::Input;
use cdyn::model::timefn::TimeFn;
use cdyn::spatial::{Actuator, Body, Joint, JointKind, JointLimit, Mechanism};
use cdyn::{Control, Error, Scheme, Settings, Simulation};

const G: f64 = 9.81;
/// The rod: mass, inertia about its centre, distance of the centre below the pivot.
const M: f64 = 2.0;
const INERTIA: [f64; 3] = [0.05, 0.04, 0.03];
const L: f64 = 0.5;

/// A rod hanging from a revolute joint about y at the origin, under gravity `g`, with `actuator`.
fn pendulum(g: f64, actuator: Actuator, limit: Option<JointLimit>) -> Mechanism {
    let rod = Body::new("rod", M, INERTIA).with_position([0.0, 0.0, -L]);
    let mut pivot = Joint::new(JointKind::Revolute, 0, None, [0.0; 3]).with_axis([0.0, 1.0, 0.0]);
    if let Some(limit) = limit {
        pivot = pivot.with_limit(limit);
    }
    Mechanism::new([0.0, 0.0, -g]).with_bodies(vec![rod]).with_joints(vec![pivot]).with_actuators(vec![actuator])
}

/// `I` about the pivot's axis.
fn pivot_inertia() -> f64 {
    INERTIA[1] + M * L * L
}

/// `(θ, θ̇, θ̈)` of joint 0 at the mechanism's initial state, `θ̈` from the dynamics.
fn joint_at_start(mechanism: &Mechanism, q: &[f64], v: &[f64], t: f64) -> [f64; 3] {
    let built = mechanism.build().unwrap();
    let mut d = Dynamics::new(&built.model);
    d.evaluate(&built.model, q, v, t).unwrap();
    mechanism.joint_coordinates(q, v, d.acc()).unwrap()[0].unwrap()
}

#[test]
fn a_torque_turns_the_pendulum_at_the_hand_computed_rate_and_the_clamp_holds_it_at_effort() {
    // At rest hanging straight down gravity has no moment: θ̈ = τ(0) / I.
    let torque = TimeFn::polynomial(vec![0.7, 3.0]);
    let driven = pendulum(G, Actuator::torque(0, torque.clone()), None);
    let built = driven.build().unwrap();
    let [_, _, acc] = joint_at_start(&driven, &built.q0, &built.v0, 0.0);
    let exact = 0.7 / pivot_inertia();
    assert!((acc - exact).abs() < 1e-12 * exact, "θ̈ = {acc} vs {exact}");
    // At t = 0.5 the law asks 2.2 N m; an effort of 1.2 N m gives 1.2.
    let clamped = pendulum(G, Actuator::torque(0, torque), Some(JointLimit::new(-1.0, 1.0).with_effort(1.2)));
    let [_, _, acc] = joint_at_start(&clamped, &built.q0, &built.v0, 0.5);
    assert!((acc - 1.2 / pivot_inertia()).abs() < 1e-12, "clamped θ̈ = {acc}");
    assert_eq!(clamped.actuator_torques().unwrap().at(0, &built.q0, &built.v0, 0.5), 1.2);
    assert_eq!(driven.actuator_torques().unwrap().at(0, &built.q0, &built.v0, 0.5), 2.2);

    // A servo at θ = 0.3 rad, θ̇ = −0.4 rad/s to a target 1 + 2 t at
    // t = 0.25 (θ_ref = 1.5, θ̇_ref = 2), kp = 8, kd = 1.5: τ = 8·1.2 +
    // 1.5·2.4 = 13.2, against gravity's −m g L sin θ; clamped at 5.
    let servo = Actuator::servo(0, TimeFn::linear(1.0, 2.0), 8.0, 1.5);
    let (q, v) = turned(0.3, -0.4);
    let free = pendulum(G, servo.clone(), None);
    let [theta, rate, acc] = joint_at_start(&free, &q, &v, 0.25);
    assert!((theta - 0.3).abs() < 1e-15 && (rate + 0.4).abs() < 1e-15, "{theta} {rate}");
    let gravity = -M * G * L * 0.3_f64.sin();
    let exact = (13.2 + gravity) / pivot_inertia();
    assert!((acc - exact).abs() < 1e-12 * exact.abs(), "servo θ̈ = {acc} vs {exact}");
    let held = pendulum(G, servo, Some(JointLimit::new(-3.0, 3.0).with_effort(5.0)));
    let [_, _, acc] = joint_at_start(&held, &q, &v, 0.25);
    let exact = (5.0 + gravity) / pivot_inertia();
    assert!((acc - exact).abs() < 1e-12 * exact.abs(), "clamped servo θ̈ = {acc} vs {exact}");
}

#[test]
fn a_servo_turns_within_a_limit_shorter_than_a_turn_and_the_short_way_without_one() {
    // Panda's joint 6 ranges over −0.0175..3.7525 rad, through π. From
    // θ = 0.2 to a target of 3.5 (kp = 8, no gravity, at rest) the servo in
    // that range asks τ = 8·3.3 = 26.4 (up, through π). The unlimited joint
    // turns the short way: θ − θ_ref = −3.3 is 2π − 3.3 in (−π, π], so
    // τ = −8·(2π − 3.3) (down). At θ = 3.3, which reads 3.3 − 2π, both ask
    // 8·0.2 = 1.6.
    let servo = Actuator::servo(0, TimeFn::constant(3.5), 8.0, 0.0);
    let range = JointLimit::new(-0.0175, 3.7525);
    let limited = pendulum(0.0, servo.clone(), Some(range));
    let free = pendulum(0.0, servo, None);
    let tau = |mechanism: &Mechanism, theta: f64| {
        let (q, v) = turned(theta, 0.0);
        let applied = mechanism.actuator_torques().unwrap().at(0, &q, &v, 0.0);
        let [_, _, acc] = joint_at_start(mechanism, &q, &v, 0.0);
        assert!((acc - applied / pivot_inertia()).abs() < 1e-12 * (1.0 + acc.abs()), "θ̈ {acc} for τ {applied}");
        applied
    };
    for (mechanism, theta, exact) in [
        (&limited, 0.2, 26.4),
        (&free, 0.2, -8.0 * (std::f64::consts::TAU - 3.3)),
        (&limited, 3.3, 1.6),
        (&free, 3.3, 1.6),
    ] {
        let applied = tau(mechanism, theta);
        assert!((applied - exact).abs() < 1e-12, "θ = {theta}: τ = {applied}, hand-computed {exact}");
    }
}

/// The rod's state turned by `theta` about y with rate `rate`.
fn turned(theta: f64, rate: f64) -> (Vec<f64>, Vec<f64>) {
    let (s, c) = (theta.sin(), theta.cos());
    // θ is the rod's angle about +y: its centre at (−L sin θ, 0, −L cos θ).
    let p = [(theta / 2.0).cos(), 0.0, (theta / 2.0).sin(), 0.0];
    let pd = [-(theta / 2.0).sin() * rate / 2.0, 0.0, (theta / 2.0).cos() * rate / 2.0, 0.0];
    let q = vec![-L * s, 0.0, -L * c, p[0], p[1], p[2], p[3]];
    let v = vec![-L * c * rate, 0.0, L * s * rate, pd[0], pd[1], pd[2], pd[3]];
    (q, v)
}

#[test]
fn a_pd_servo_without_gravity_follows_the_damped_oscillators_closed_form() {
    // I θ̈ = kp (θ_ref − θ) − kd θ̇ with a constant target: θ(t) = θ_ref +
    // (θ₀ − θ_ref) e^{−ζωt} (cos ω_d t + ζω/ω_d sin ω_d t) from rest.
    let (kp, kd, target) = (6.0, 0.9, 0.8);
    let mechanism = pendulum(0.0, Actuator::servo(0, TimeFn::constant(target), kp, kd), None);
    let built = mechanism.build().unwrap();
    let settings = Settings::new(Scheme::RungeKutta4, 1e-3, Control::none());
    let mut sim = Simulation::new(&built.model, settings, &built.q0, &built.v0).unwrap();
    let space = mechanism.joint_space().unwrap();
    let (i, zero) = (pivot_inertia(), vec![0.0; 7]);
    let (w, zeta) = ((kp / i).sqrt(), kd / (2.0 * (kp * i).sqrt()));
    let wd = w * (1.0 - zeta * zeta).sqrt();
    let (mut worst, mut psi) = (0.0_f64, 0.0_f64);
    sim.run::<Error>(3.0, 1, |s| {
        let t = s.t();
        let exact = target - target * (-zeta * w * t).exp() * ((wd * t).cos() + zeta * w / wd * (wd * t).sin());
        worst = worst.max((space.at(0, s.q(), s.v(), &zero)[0] - exact).abs());
        psi = psi.max(s.measure().psi.abs());
        Ok(())
    })
    .unwrap();
    println!("servo: largest |θ − closed form| {worst:.1e}, |Ψ| {psi:.1e}");
    assert!(worst < 1e-9, "{worst:e}");
    // The servo's power is in Ė: E₀ + ∫Ė stays the energy to the integrator's error.
    assert!(psi < 1e-9, "|Ψ| = {psi:e}");
}

#[test]
fn the_energy_balance_closes_on_a_pendulum_driven_by_a_torque_and_an_input() {
    // τ(t) = 0.4 sin 3t + u under gravity, u set to 0.5 at t = 1: the
    // actuator's work enters ∫Ė, so Ψ = T + V − E₀ − ∫Ė stays at the
    // integrator's error, and the input changes the motion.
    let u = Input::new("push", 0.0);
    let torque = TimeFn::sine(0.4, 3.0, 0.0).with_input((u, 1.0));
    let mechanism = pendulum(G, Actuator::torque(0, torque), None);
    let built = mechanism.build().unwrap();
    assert_eq!(built.model.inputs().iter().map(|u| u.name()).collect::<Vec<_>>(), ["push"]);
    let settings = Settings::new(Scheme::RungeKutta4, 1e-3, Control::none());
    let run = |push: f64| {
        let mut sim = Simulation::new(&built.model, settings, &built.q0, &built.v0).unwrap();
        let mut psi = 0.0_f64;
        sim.set_input_named("push", 0.0).unwrap();
        sim.run::<Error>(1.0, 1, |s| {
            psi = psi.max(s.measure().psi.abs());
            Ok(())
        })
        .unwrap();
        sim.set_input_named("push", push).unwrap();
        sim.run::<Error>(2.0, 1, |s| {
            psi = psi.max(s.measure().psi.abs());
            Ok(())
        })
        .unwrap();
        (psi, mechanism.joint_coordinates(sim.q(), sim.v(), &[0.0; 7]).unwrap()[0].unwrap())
    };
    let ((psi, pushed), (_, free)) = (run(0.5), run(0.0));
    println!("driven pendulum: |Ψ| {psi:.1e}, θ(2) {} pushed vs {} not", pushed[0], free[0]);
    assert!(psi < 1e-9, "|Ψ| = {psi:e}");
    assert!((pushed[0] - free[0]).abs() > 0.05, "{pushed:?} {free:?}");
}

#[test]
fn the_servos_velocity_jacobian_by_ad_matches_finite_differences() {
    // −∂Q/∂v · w (what generalized-α's Newton matrix takes) against central
    // differences of Q along w, at a turned, moving state.
    let servo = Actuator::servo(0, TimeFn::sine(0.5, 2.0, 0.1), 7.0, 1.3);
    let mechanism = pendulum(G, servo, None);
    let model = mechanism.build().unwrap().model;
    let (q, v) = turned(0.4, 0.9);
    let w = [0.3, -0.2, 0.5, 0.1, -0.4, 0.7, 0.2];
    let mut ad = vec![0.0; 7];
    model.add_damping(&q, &v, &w, 0.3, &mut ad);
    let force = |s: f64| {
        let vs: Vec<f64> = v.iter().zip(&w).map(|(v, w)| v + s * w).collect();
        let mut f = vec![0.0; 7];
        model.add_forces(&q, &vs, 0.3, &mut f);
        f
    };
    let (up, down, h) = (force(1e-6), force(-1e-6), 1e-6);
    for k in 0..7 {
        let fd = -(up[k] - down[k]) / (2.0 * h);
        assert!((ad[k] - fd).abs() < 1e-7 * (1.0 + fd.abs()), "coordinate {k}: {} vs {fd}", ad[k]);
    }
    assert!(ad.iter().any(|x| x.abs() > 0.1), "the servo damps: {ad:?}");
}

#[test]
fn bad_actuators_are_refused_with_the_reason() {
    let refused = |actuator: Actuator| pendulum(G, actuator, None).build().err().unwrap().to_string();
    let both = Actuator::torque(0, TimeFn::constant(1.0)).with_target(TimeFn::constant(0.0));
    assert!(refused(both).contains("give one"), "{}", refused(Actuator::torque(0, TimeFn::constant(1.0))));
    let negative = Actuator::servo(0, TimeFn::constant(0.0), -1.0, 1.0);
    assert!(refused(negative).contains("kp"));
    let gains = Actuator::torque(0, TimeFn::constant(1.0)).with_kd(2.0);
    assert!(refused(gains).contains("servo's gains"));
    assert!(refused(Actuator::torque(3, TimeFn::constant(1.0))).contains("joint"));
    let weld = Mechanism::new([0.0; 3])
        .with_bodies(vec![Body::new("rod", M, INERTIA)])
        .with_joints(vec![Joint::new(JointKind::Spherical, 0, None, [0.0; 3])])
        .with_actuators(vec![Actuator::torque(0, TimeFn::constant(1.0))]);
    let line = weld.build().err().unwrap().to_string();
    assert!(line.contains("spherical"), "{line}");
}
