//! Planar joint limits as one-sided stops (`cdyn::stops`), against stops
//! computed by hand.
//!
//! A rigid rod hangs from the ground by a revolute joint `L` above its
//! centre of mass; its angle `φ` is 0 hanging and the joint's coordinate
//! (the relative angle to the ground). Released at rest at `φ₀ = 1.2`, it
//! is a pendulum `φ̈ = −w² sin φ`, `w² = m g L / I` (`I` about the pivot),
//! and falls onto the lower bound `φ = 0.3` at the time
//! [`time_to_swing`] gives, with rate `−√(2w² (cos 0.3 − cos 1.2))`.
//!
//! A point mass slides from rest down a frictionless line at `α` to the
//! horizontal: `s = ½ g sin α t²` along it, so it meets a stop `d` down
//! the line at `t* = √(2d / (g sin α))` with rate `g sin α t*`.

use cdyn::dynamics::Dynamics;
use cdyn::error::{Part, Problem};
use cdyn::limit::JointLimit;
use cdyn::model::timefn::TimeFn;
use cdyn::planar::{BodyId, Element, Mechanism};
use cdyn::reference::{PendulumExact, time_to_swing};
use cdyn::stops::{Change, Event, PlanarStops, StopSimulation, check_start, run_with_stops};
use cdyn::{Control, Scheme, Settings};
use std::f64::consts::FRAC_PI_2;

const G: f64 = 9.81;
const M: f64 = 2.0;
const L: f64 = 0.5;
const IC: f64 = 0.02;
const PHI0: f64 = 1.2;
const PHI_STOP: f64 = 0.3;

/// `w² = m g L / I` about the pivot.
fn w2() -> f64 {
    M * G * L / (IC + M * L * L)
}

/// The rod at `phi`, at rest, its joint limited by `limit`, with `more` elements.
fn rod(phi: f64, limit: JointLimit, more: Vec<Element>) -> Mechanism {
    let mut m = Mechanism::new([0.0, -G]);
    let rod = m.rigid("rod", M, IC, [L * phi.sin(), -L * phi.cos()], phi);
    m.add(Element::Revolute { a: BodyId::Ground, pa: [0.0, 0.0], b: rod, pb: [0.0, L], limit: Some(limit) });
    for e in more {
        m.add(e);
    }
    m
}

/// Runs `m` from its built state to `t_end`: the events and `(t, θ, θ̇)` at every step.
fn run(m: &Mechanism, scheme: Scheme, h: f64, t_end: f64) -> (Vec<Event>, Vec<[f64; 3]>) {
    let built = m.build().unwrap();
    let settings = Settings::new(scheme, h, Control::robust());
    let mut samples = Vec::new();
    let stops = PlanarStops::new(m.clone()).unwrap();
    let report = run_with_stops::<_, cdyn::Error>(&stops, settings, &built.q0, &built.v0, t_end, 1, |t, q, v| {
        let [theta, rate] = m.joint_coordinate(0, q, v)?;
        samples.push([t, theta, rate]);
        Ok(())
    })
    .unwrap();
    (report.events, samples)
}

#[test]
fn a_rod_falling_onto_its_limit_is_stopped_when_the_elliptic_integral_says_and_held() {
    let t_star = time_to_swing(w2(), PHI0, PHI_STOP).unwrap();
    let rate = (2.0 * w2() * (PHI_STOP.cos() - PHI0.cos())).sqrt();
    let inertia = IC + M * L * L;
    let m = rod(PHI0, JointLimit::new(PHI_STOP, f64::INFINITY), vec![]);
    for scheme in [Scheme::RungeKutta4, Scheme::AdamsBashforth3] {
        let h = 1e-3;
        let (events, samples) = run(&m, scheme, h, 1.5);
        let [Event { t, change: Change::Impact { rate: hit, kinetic_lost, held: true }, .. }] = events[..] else {
            panic!("{scheme:?}: {events:?}")
        };
        eprintln!("{scheme:?}: t = {t} (t* = {t_star}), rate {hit} ({rate}), lost {kinetic_lost}");
        // Hit at the crossing, stepped to within the step: the time and
        // rate there, as closely as the scheme follows the pendulum (AB-3's
        // third-order error reaches 4e-8 s in the crossing).
        let close = if scheme == Scheme::RungeKutta4 { 1e-9 } else { 1e-6 };
        assert!((t - t_star).abs() < close, "{scheme:?}: stopped at {t}, by hand {t_star}");
        assert!((-hit - rate).abs() < close * rate, "{scheme:?}: {hit} against {rate}");
        // Plastic: the joint's whole kinetic energy ½ I θ̇², to round-off.
        assert!((kinetic_lost - 0.5 * inertia * hit * hit).abs() < 1e-12 * kinetic_lost, "{kinetic_lost}");
        let after: Vec<_> = samples.iter().filter(|[s, ..]| *s > t + h).collect();
        assert!(after.len() > 1000);
        let worst = after.iter().fold(0.0_f64, |w, [_, x, r]| w.max((x - PHI_STOP).abs()).max(r.abs()));
        assert!(worst < 1e-9, "{scheme:?}: off the stop by {worst}");
        assert!(samples.iter().all(|[_, x, _]| *x >= PHI_STOP - 1e-9), "{scheme:?}: past the stop");
    }
}

#[test]
fn a_rod_with_restitution_rebounds_at_minus_e_times_its_rate() {
    let e = 0.5;
    let m = rod(PHI0, JointLimit::new(PHI_STOP, f64::INFINITY).with_restitution(e), vec![]);
    let (events, samples) = run(&m, Scheme::RungeKutta4, 1e-3, 1.0);
    let Event { t, step, change: Change::Impact { rate, kinetic_lost, held: false }, .. } = events[0] else {
        panic!("{events:?}")
    };
    // Hit at the crossing, at its rate: θ̇⁺ = −e θ̇⁻ there, and from then
    // on the free pendulum, whose rate at the step's end the sample reads.
    let crossing = (2.0 * w2() * (PHI_STOP.cos() - PHI0.cos())).sqrt();
    assert!((rate + crossing).abs() < 1e-9 * crossing, "{rate} against {crossing}");
    let [sampled, _, after] = samples[step as usize];
    let expected = PendulumExact::new(w2(), PHI_STOP - FRAC_PI_2, e * crossing).unwrap().angle(sampled - t).1;
    assert!((after - expected).abs() < 1e-9 * crossing, "{after} against {expected}");
    let inertia = IC + M * L * L;
    assert!((kinetic_lost - 0.5 * inertia * (1.0 - e * e) * rate * rate).abs() < 1e-9 * kinetic_lost);
}

#[test]
fn a_held_rod_is_released_when_a_growing_torque_outweighs_gravity() {
    // At rest on its stop φ = 0.3, gravity pushes the rod into it with the
    // torque m g L sin 0.3; a torque c t turns it away, and the stop's
    // multiplier changes sign when they balance: t = m g L sin 0.3 / c.
    let c = 10.0;
    let torque = Element::AppliedTorque { body: BodyId::Body(0), f: TimeFn::linear(0.0, c) };
    let m = rod(PHI_STOP, JointLimit::new(PHI_STOP, f64::INFINITY), vec![torque]);
    let h = 1e-3;
    let (events, samples) = run(&m, Scheme::RungeKutta4, h, 0.5);
    let t_release = M * G * L * PHI_STOP.sin() / c;
    // Held at the first step (gravity first), released once, not hit again.
    let [
        Event { step: 1, change: Change::Impact { held: true, .. }, .. },
        Event { t, change: Change::Release { multiplier }, .. },
    ] = events[..]
    else {
        panic!("{events:?}")
    };
    eprintln!("released at {t} (balance at {t_release}), multiplier {multiplier}");
    assert!(t >= t_release && t < t_release + h + 1e-12, "released at {t}, balance at {t_release}");
    // At rest on the stop, its multiplier is the net torque away from it.
    assert!((multiplier - (c * t - M * G * L * PHI_STOP.sin())).abs() < 1e-9, "{multiplier}");
    assert!(samples.iter().filter(|[s, ..]| *s <= t).all(|[_, x, _]| (x - PHI_STOP).abs() < 1e-9));
    assert!(samples.last().unwrap()[1] > PHI_STOP + 0.01, "{:?}", samples.last());
}

#[test]
fn a_block_sliding_down_an_incline_is_stopped_at_its_limit() {
    let (alpha, d, h) = (0.5_f64, 0.4, 1e-3);
    let mut m = Mechanism::new([0.0, -G]);
    let block = m.point("block", 3.0, [0.0, 0.0]);
    let limit = JointLimit::new(f64::NEG_INFINITY, d);
    let axis = [alpha.cos(), -alpha.sin()];
    m.add(Element::Prismatic { a: BodyId::Ground, pa: [0.0, 0.0], b: block, pb: [0.0, 0.0], axis, limit: Some(limit) });
    let (events, samples) = run(&m, Scheme::RungeKutta4, h, 0.6);
    let a = G * alpha.sin();
    let t_star = (2.0 * d / a).sqrt();
    let [Event { t, step, change: Change::Impact { rate, kinetic_lost, held: true }, .. }] = events[..] else {
        panic!("{events:?}")
    };
    eprintln!("stopped at {t} (t* = {t_star}), rate {rate}");
    // The motion is quadratic in t, which the crossing's cubic meets exactly.
    assert!((t - t_star).abs() < 1e-12, "stopped at {t}, by hand {t_star}");
    // Hit there, within step `step`, at the gap's rate then.
    assert!(t > (step - 1) as f64 * h && t <= step as f64 * h, "{t} in step {step}");
    assert!((rate + a * t_star).abs() < 1e-12, "{rate}");
    assert!((kinetic_lost - 0.5 * 3.0 * rate * rate).abs() < 1e-12 * kinetic_lost);
    let after = samples.iter().filter(|[s, ..]| *s > t + h);
    assert!(after.fold(0.0_f64, |w, [_, x, r]| w.max((x - d).abs()).max(r.abs())) < 1e-9);
}

#[test]
fn a_held_stops_row_is_its_gap_and_its_jacobian_the_gaps_gradient() {
    // A slider on a line along a free crank's axis (the gap turns with the
    // crank), both sides of its limit.
    let mut m = Mechanism::new([0.0, -G]);
    let crank = m.rigid("crank", 1.0, 0.1, [0.2, -0.4], 0.7);
    let slider = m.rigid("slider", 2.0, 0.1, [1.1, 0.6], -0.2);
    let limit = JointLimit::new(-0.25, 1.5);
    let (pa, pb) = ([0.3, 0.1], [-0.05, 0.02]);
    m.add(Element::Prismatic { a: crank, pa, b: slider, pb, axis: [3.0, 4.0], limit: Some(limit) });
    let q = [0.2, -0.4, 0.7, 1.1, 0.6, -0.2];
    let stops = m.stops();
    assert_eq!(stops.len(), 2);
    for stop in stops {
        let model = m.build_holding(&[stop]).unwrap().model;
        let row = model.m() - 1;
        let gap = |q: &[f64]| m.gaps(&[stop], q, &[0.0; 6]).unwrap()[0][0];
        let mut phi = vec![0.0; model.m()];
        model.constraint_values(&q, 0.0, &mut phi);
        assert!((phi[row] - gap(&q)).abs() < 1e-15, "{stop:?}: {} against {}", phi[row], gap(&q));
        // Φ̇ = Φ_q e_j is column j of the row's Jacobian.
        let mut dynamics = Dynamics::new(&model);
        for j in 0..6 {
            let unit: [f64; 6] = std::array::from_fn(|i| f64::from(u8::from(i == j)));
            dynamics.evaluate(&model, &q, &unit, 0.0).unwrap();
            let at = |s: f64| gap(&std::array::from_fn::<_, 6, _>(|i| q[i] + s * unit[i]));
            let fd = (at(1e-6) - at(-1e-6)) / 2e-6;
            let column = dynamics.phi_dot()[row];
            assert!((column - fd).abs() < 1e-8, "{stop:?}, column {j}: {column} against {fd}");
            assert_eq!(m.gaps(&[stop], &q, &unit).unwrap()[0][1], column, "{stop:?}, column {j}");
        }
    }
}

#[test]
fn bad_limits_are_refused_naming_the_joint() {
    for (limit, says) in [
        (JointLimit::new(1.0, -1.0), "limit lower = 1, upper = -1: lower is above upper"),
        (JointLimit::new(f64::NAN, 1.0), "a bound is not a number"),
        (JointLimit::new(-1.0, 1.0).with_restitution(2.0), "restitution = 2"),
        (JointLimit::new(-1.0, 1.0).with_velocity(-1.0), "velocity limit = -1"),
        (JointLimit::new(-1.0, 1.0).with_effort(5.0), "limit effort = 5: a planar joint has no actuator"),
    ] {
        let e = rod(0.0, limit, vec![]).build().err().expect("refused").to_string();
        assert!(e.contains("element 0 (revolute)") && e.contains(says), "{e}");
    }
    // A point mass has no angle for a revolute joint's limit to bound.
    let mut m = Mechanism::new([0.0, -G]);
    let bob = m.point("bob", 1.0, [0.0, -1.0]);
    let anchor = m.rigid("anchor", 1.0, 0.1, [0.0, 0.0], 0.0);
    m.add(Element::Revolute {
        a: anchor,
        pa: [0.0, 0.0],
        b: bob,
        pb: [0.0, 0.0],
        limit: Some(JointLimit::new(-1.0, 1.0)),
    });
    let e = m.build().err().expect("refused").to_string();
    assert!(e.contains("element 0 (revolute)") && e.contains("body bob is a point mass"), "{e}");
}

#[test]
fn a_start_past_a_limit_is_refused_naming_the_joint_the_side_the_bound_and_the_distance() {
    // The rod at 0.2 rad, its lower bound at 0.3: 0.1 past it.
    let m = rod(0.2, JointLimit::new(PHI_STOP, f64::INFINITY), vec![]);
    let built = m.build().unwrap();
    let stops = PlanarStops::new(m).unwrap();
    let refused = check_start(&stops, &built.q0, &built.v0).unwrap_err();
    let cdyn::Error::InvalidModel {
        at: Part::InitialState,
        problem: Problem::StartsPastLimit { stop, joint, upper, bound, by },
    } = refused.clone()
    else {
        panic!("{refused:?}")
    };
    assert_eq!((stop, joint.as_str(), upper, bound), (0, "element 0 (revolute)", false, PHI_STOP));
    assert!((by - 0.1).abs() < 1e-15, "{by}");
    let says = "invalid model: initial state: element 0 (revolute): starts 1.000e-1 past its lower limit 0.3";
    assert_eq!(refused.to_string(), says);
    // The run refuses it with the same error; at the bound it starts.
    let settings = Settings::new(Scheme::RungeKutta4, 1e-3, Control::robust());
    let Err(e) = StopSimulation::new(&stops, settings, &built.q0, &built.v0) else { panic!("started past its limit") };
    assert_eq!(e, refused);
    let at_bound = rod(PHI_STOP, JointLimit::new(PHI_STOP, f64::INFINITY), vec![]);
    let built = at_bound.build().unwrap();
    assert_eq!(check_start(&PlanarStops::new(at_bound).unwrap(), &built.q0, &built.v0), Ok(()));
}
