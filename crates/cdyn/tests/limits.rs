//! Joint limits as one-sided stops (`cdyn::stops`), against a pendulum
//! whose stop is computed by hand: a rod on a revolute joint, released
//! from rest at φ₀ = 1.2 rad from the vertical, falls onto a stop at
//! φ = 0.3 rad, where gravity keeps pushing it.
//!
//! With `k = m g L / I` (I about the pivot) energy gives
//! `φ̇² = 2k (cos φ − cos φ₀)`, so the stop is reached at
//! `t* = ∫_{0.3}^{1.2} dφ / √(2k (cos φ − cos φ₀))` with rate
//! `√(2k (cos 0.3 − cos 1.2))`; there all the kinetic energy `½ I φ̇²` is
//! lost with `e = 0` (a one-joint pendulum's velocity is all along the
//! joint), and the rod is held at 0.3 rad from then on.

use cdyn::reference::PendulumExact;
use cdyn::spatial::{Body, Joint, JointKind, JointLimit, Mechanism};
use cdyn::stops::{Change, Event, MechanismStops, run_with_stops};
use cdyn::{Control, Scheme, Settings};
use std::f64::consts::{FRAC_PI_2, PI, TAU};

const G: f64 = 9.81;
const M: f64 = 2.0;
const L: f64 = 0.5;
const JYY: f64 = 0.02;
const PHI0: f64 = 1.2;
const PHI_STOP: f64 = 0.3;

fn k() -> f64 {
    M * G * L / (JYY + M * L * L)
}

/// The rod at φ₀, its joint's coordinate θ = φ − φ₀ limited below at the stop.
fn pendulum(limit: JointLimit) -> Mechanism {
    pendulum_at(PHI0, limit)
}

/// The rod at rest at `phi0` from the vertical, its joint limited by `limit`.
fn pendulum_at(phi0: f64, limit: JointLimit) -> Mechanism {
    let rod = Body::new("rod", M, [0.02, JYY, 0.005])
        .with_position([-L * phi0.sin(), 0.0, -L * phi0.cos()])
        .with_orientation([(phi0 / 2.0).cos(), 0.0, (phi0 / 2.0).sin(), 0.0]);
    let pivot = Joint::new(JointKind::Revolute, 0, None, [0.0; 3]).with_axis([0.0, 1.0, 0.0]).with_limit(limit);
    Mechanism::new([0.0, 0.0, -G]).with_bodies(vec![rod]).with_joints(vec![pivot])
}

/// `t*`, by the closed form (shared with the planar and CLI tests).
fn stop_time() -> f64 {
    cdyn::reference::time_to_swing(k(), PHI0, PHI_STOP).unwrap()
}

/// Runs the pendulum to `t_end`, returning the events and the joint's `(θ, θ̇)` at each sample.
fn run(scheme: Scheme, h: f64, limit: JointLimit, t_end: f64) -> (Vec<Event>, Vec<(f64, [f64; 3])>) {
    let mechanism = pendulum(limit);
    let (events, samples) = run_mechanism(&mechanism, scheme, h, None, t_end, 1);
    (events, samples.into_iter().map(|(t, joints)| (t, joints[0])).collect())
}

/// `(t, each joint's (θ, θ̇, θ̈))` at each sample.
type Samples = Vec<(f64, Vec<[f64; 3]>)>;

/// Runs `mechanism` with its stops (`robust`) from its built state, its
/// velocities `v0` where given, to `t_end`; returns the events and, every
/// `every` steps, `(t, each joint's (θ, θ̇, θ̈ = 0))`.
fn run_mechanism(
    mechanism: &Mechanism,
    scheme: Scheme,
    h: f64,
    v0: Option<&[f64]>,
    t_end: f64,
    every: u64,
) -> (Vec<Event>, Samples) {
    let built = mechanism.build().unwrap();
    let settings = Settings::new(scheme, h, Control::robust());
    let system = MechanismStops::new(mechanism.clone()).unwrap();
    let mut samples = Vec::new();
    let v0 = v0.unwrap_or(&built.v0);
    let report = run_with_stops::<_, cdyn::Error>(&system, settings, &built.q0, v0, t_end, every, |t, q, v| {
        let joints = mechanism.joint_coordinates(q, v, &vec![0.0; q.len()])?;
        samples.push((t, joints.into_iter().map(Option::unwrap).collect()));
        Ok(())
    })
    .unwrap();
    (report.events, samples)
}

#[test]
fn a_pendulum_falling_onto_its_stop_is_stopped_there_and_held() {
    let (t_star, rate) = (stop_time(), (2.0 * k() * (PHI_STOP.cos() - PHI0.cos())).sqrt());
    let inertia = JYY + M * L * L;
    for scheme in [Scheme::RungeKutta4, Scheme::AdamsBashforth3] {
        let h = 1e-3;
        let (events, samples) = run(scheme, h, JointLimit::new(PHI_STOP - PHI0, f64::INFINITY), 1.5);
        // One impact, held: gravity keeps pushing into the stop.
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
        // Plastic: the joint's whole kinetic energy is taken, to round-off.
        assert!((kinetic_lost - 0.5 * inertia * hit * hit).abs() < 1e-12 * kinetic_lost, "{kinetic_lost}");
        // Held at the stop from then on, at rest.
        let after: Vec<_> = samples.iter().filter(|(s, _)| *s > t + h).collect();
        assert!(after.len() > 500);
        let worst = after.iter().fold(0.0_f64, |w, (_, [x, r, _])| w.max((x - (PHI_STOP - PHI0)).abs()).max(r.abs()));
        assert!(worst < 1e-9, "{scheme:?}: off the stop by {worst}");
        // Before the stop, the free pendulum: φ̇² = 2k (cos φ − cos φ₀)
        // (by RK-4; AB-3's third-order error at h = 1e-3 is 1.3e-8 here).
        if scheme == Scheme::AdamsBashforth3 {
            continue;
        }
        let free = samples.iter().filter(|(s, _)| *s < t - h);
        let energy =
            free.fold(0.0_f64, |w, (_, [x, r, _])| w.max((r * r - 2.0 * k() * ((x + PHI0).cos() - PHI0.cos())).abs()));
        assert!(energy < 1e-9, "{scheme:?}: {energy}");
    }
}

#[test]
fn a_range_shorter_than_a_turn_is_told_apart_through_pi() {
    // From rest at φ₀ = 3 (near upright) the rod falls through the bottom,
    // its joint's angle θ = φ − φ₀ through −π at φ = 3 − π, onto the stop
    // θ = −5.9 (φ = −2.9) of its range [−5.9, 0.1], shorter than a turn.
    // Measured in (−π, π], θ jumps to +π there: read as such, it was past
    // the upper bound, and −5.9 was no stop. Short of the top, gravity
    // pulls the rod back off the stop: released the step after.
    let (phi0, lower) = (3.0, -5.9);
    let mechanism = pendulum_at(phi0, JointLimit::new(lower, 0.1));
    let (events, _) = run_mechanism(&mechanism, Scheme::RungeKutta4, 1e-3, None, 3.0, 100);
    let (t_star, rate) = (
        cdyn::reference::time_to_swing(k(), phi0, phi0 + lower).unwrap(),
        (2.0 * k() * ((phi0 + lower).cos() - phi0.cos())).sqrt(),
    );
    let [
        Event { stop: 0, step, t, change: Change::Impact { rate: hit, held: true, .. }, .. },
        Event { stop: 0, step: released, change: Change::Release { .. }, .. },
    ] = events[..]
    else {
        panic!("{events:?}")
    };
    assert_eq!(released, step + 1);
    assert!((t - t_star).abs() < 1e-6, "stopped at {t}, by hand {t_star}");
    assert!((-hit - rate).abs() < 1e-3 * k(), "{hit} against {rate}");
}

#[test]
fn a_stop_with_restitution_throws_the_joint_back() {
    let e = 0.5;
    let (events, samples) =
        run(Scheme::RungeKutta4, 1e-3, JointLimit::new(PHI_STOP - PHI0, f64::INFINITY).with_restitution(e), 1.0);
    let Event { t, step, change: Change::Impact { rate, kinetic_lost, held: false }, .. } = events[0] else {
        panic!("{events:?}")
    };
    // Hit at the crossing, at its rate: θ̇⁺ = −e θ̇⁻ there, and from then
    // on the free pendulum, whose rate at the step's end the sample reads.
    let crossing = (2.0 * k() * (PHI_STOP.cos() - PHI0.cos())).sqrt();
    assert!((t - stop_time()).abs() < 1e-9, "hit at {t}, by hand {}", stop_time());
    assert!((rate + crossing).abs() < 1e-9 * crossing, "{rate} against {crossing}");
    let (sampled, [_, after, _]) = samples[step as usize];
    let rebound = PendulumExact::new(k(), PHI_STOP - FRAC_PI_2, e * crossing).unwrap();
    let expected = rebound.angle(sampled - t).1;
    assert!((after - expected).abs() < 1e-9 * crossing, "{after} against {expected}, {} s after the hit", sampled - t);
    // Energy taken: the joint's kinetic energy less what it leaves with.
    let inertia = JYY + M * L * L;
    assert!((kinetic_lost - 0.5 * inertia * (1.0 - e * e) * rate * rate).abs() < 1e-9 * kinetic_lost);
}

#[test]
fn bounces_end_held_when_the_next_would_last_less_than_a_step() {
    // Gravity presses the rod into its stop at g̈ = −k sin 0.3 = −5.6 rad/s²;
    // hit at 4.7 rad/s with e = 0.5, it flies 2 e |ġ| / |g̈| = 0.85 s, then
    // half that each time: the tenth bounce would last under h = 1e-3, so
    // the eleventh impact holds it (a bounce per step without end before).
    let (e, h) = (0.5, 1e-3);
    let (events, samples) =
        run(Scheme::RungeKutta4, h, JointLimit::new(PHI_STOP - PHI0, f64::INFINITY).with_restitution(e), 3.0);
    let held: Vec<bool> = events.iter().map(|e| matches!(e.change, Change::Impact { held, .. } if held)).collect();
    assert!((9..=13).contains(&events.len()), "{} impacts: {events:?}", events.len());
    assert!(held[..held.len() - 1].iter().all(|h| !h) && held[held.len() - 1], "{events:?}");
    let last = events.last().unwrap().t;
    assert!(last < 0.34 + 2.0 * 0.85, "held at {last}");
    let after = samples.iter().filter(|(t, _)| *t > last + h);
    assert!(after.clone().count() > 500);
    assert!(after.fold(0.0_f64, |w, (_, [x, _, _])| w.max((x - (PHI_STOP - PHI0)).abs())) < 1e-9);
}

#[test]
fn a_stop_pulled_away_from_is_released() {
    // The same rod thrown upwards from φ₀ onto a stop above it, φ = 1.5:
    // gravity pulls it off the stop, which lets it go at once.
    let mechanism = pendulum(JointLimit::new(-10.0, 0.3)); // θ ≤ 0.3
    let mut built = mechanism.build().unwrap();
    let w = 4.0; // rad/s about y, from φ₀ upwards
    built.v0 = Mechanism::new([0.0; 3])
        .with_bodies(vec![mechanism.bodies[0].clone().with_angular_velocity([0.0, w, 0.0]).with_velocity([
            -L * PHI0.cos() * w,
            0.0,
            L * PHI0.sin() * w,
        ])])
        .build()
        .unwrap()
        .v0;
    let (events, samples) = run_mechanism(&mechanism, Scheme::RungeKutta4, 1e-3, Some(&built.v0), 1.0, 1);
    let theta: Vec<f64> = samples.iter().map(|(_, joints)| joints[0][0]).collect();
    let kinds: Vec<_> = events.iter().map(|e| matches!(e.change, Change::Impact { .. })).collect();
    assert_eq!(kinds[..2], [true, false], "{events:?}");
    assert_eq!(events[1].step, events[0].step + 1);
    assert!(theta.iter().all(|&x| x <= 0.3 + 1e-9));
    assert!(*theta.last().unwrap() < 0.0); // it fell back
}

#[test]
fn bad_limits_are_refused_naming_the_joint() {
    for (limit, says) in [
        (JointLimit::new(1.0, -1.0), "limit lower = 1, upper = -1: lower is above upper"),
        (JointLimit::new(f64::NAN, 1.0), "a bound is not a number"),
        (JointLimit::new(-1.0, 1.0).with_restitution(2.0), "restitution = 2"),
    ] {
        let e = pendulum(limit).build().err().expect("refused").to_string();
        assert!(e.contains("element 0 (revolute)"), "{e}");
        assert!(e.contains(says), "{e}");
    }
}

/// A rod on joint `j` and a second rod on joint `k`, a `<mimic>` of `j` at
/// half its angle; `j` limited to ±0.3 and, where `k_limit`, `k` to ±0.15.
#[cfg(feature = "urdf")]
fn mimic_pair(k_limit: bool) -> Mechanism {
    let k_limit = if k_limit { r#"<limit lower="-0.15" upper="0.15" effort="1" velocity="10"/>"# } else { "" };
    let urdf = format!(
        r#"<robot name="pair"><link name="base"/>
        <joint name="j" type="revolute"><parent link="base"/><child link="a"/>
          <axis xyz="0 1 0"/><limit lower="-0.3" upper="0.3" effort="1" velocity="10"/></joint>
        <link name="a"><inertial><origin xyz="0.2 0 0"/><mass value="2"/>
          <inertia ixx="0.01" ixy="0" ixz="0" iyy="0.02" iyz="0" izz="0.02"/></inertial></link>
        <joint name="k" type="revolute"><parent link="a"/><child link="b"/>
          <origin xyz="0.4 0 0"/><axis xyz="0 1 0"/><mimic joint="j" multiplier="0.5"/>{k_limit}</joint>
        <link name="b"><inertial><origin xyz="0.1 0 0"/><mass value="1"/>
          <inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial></link></robot>"#
    );
    cdyn::spatial::read_urdf(&urdf, [0.0, 0.0, -G]).unwrap().mechanism
}

#[cfg(feature = "urdf")]
#[test]
fn stops_a_mimic_reaches_with_its_leader_are_held_by_one_row() {
    // Falling from the horizontal, j reaches its bound 0.3 and k, at half
    // j's angle, its bound 0.15 at the same instant: the two stops' rows
    // and the mimic row are dependent, so one row holds both. The run is
    // the one with k's limit left out, to round-off.
    let run = |k_limit: bool| {
        let (events, samples) = run_mechanism(&mimic_pair(k_limit), Scheme::RungeKutta4, 1e-3, None, 1.0, 10);
        (events, samples.into_iter().map(|(_, j)| [j[0][0], j[1][0]]).collect::<Vec<_>>())
    };
    let (events, joints) = run(true);
    let (alone, reduced) = run(false);
    // Both of the stops met are hit, at the same step, and held.
    let hit: Vec<_> =
        events.iter().map(|e| (e.stop, e.step, matches!(e.change, Change::Impact { held: true, .. }))).collect();
    assert_eq!(hit.len(), 2, "{events:?}");
    assert!(hit[0].1 == hit[1].1 && hit[0].2 && hit[1].2, "{events:?}");
    assert_eq!(alone.len(), 1, "{alone:?}");
    let [j, k] = *joints.last().unwrap();
    assert!((j.abs() - 0.3).abs() < 1e-9 && (k - 0.5 * j).abs() < 1e-9, "{j} {k}");
    let worst =
        joints.iter().zip(&reduced).map(|(a, b)| (a[0] - b[0]).abs().max((a[1] - b[1]).abs())).fold(0.0, f64::max);
    assert!(worst < 1e-12, "{worst}");
}

/// TIAGo's finger joints' range, more than a turn: −2.62 … 6.28 rad.
#[allow(clippy::approx_constant)] // its URDF's bound, 6.28, not 2π
const FINGER: (f64, f64) = (-2.62, 6.28);

/// The rod of [`pendulum_at`] hanging (`φ = 0`), without gravity, its
/// joint limited by `limit`, turning from `θ₀` at the constant rate `ω`
/// (`I ω²/2` its kinetic energy, I about the pivot) to `t_end`; its stops
/// read from `θ₀`'s turn where `from_start`, else from the state alone.
/// Returns the events and each step's `(t, (θ, θ̇))`, θ as the output
/// reads it (in (−π, π] for a range of a turn or more).
fn turning(
    limit: JointLimit,
    theta0: f64,
    omega: f64,
    from_start: bool,
    t_end: f64,
) -> (Vec<Event>, Vec<(f64, [f64; 2])>) {
    let mut mechanism = pendulum_at(0.0, limit);
    mechanism.gravity = [0.0; 3];
    let (q0, v0) = mechanism.state_at_joints(&[(0, theta0)], &[(0, omega)]).unwrap();
    let mut system = MechanismStops::new(mechanism.clone()).unwrap();
    if from_start {
        system = system.starting_at(&[(0, theta0)]).unwrap();
    }
    let settings = Settings::new(Scheme::RungeKutta4, 1e-3, Control::robust());
    let mut samples = Vec::new();
    let report = run_with_stops::<_, cdyn::Error>(&system, settings, &q0, &v0, t_end, 1, |t, q, v| {
        let [x, rate, _] = mechanism.joint_coordinates(q, v, &vec![0.0; q.len()])?[0].unwrap();
        samples.push((t, [x, rate]));
        Ok(())
    })
    .unwrap();
    (report.events, samples)
}

/// That the run of [`turning`] at `ω` hit stop `stop` (0 lower, 1 upper)
/// of bound `bound` once, at `t*`, took all the kinetic energy there and
/// left the rod at the bound, at rest.
fn stopped_once_at(events: &[Event], samples: &[(f64, [f64; 2])], stop: usize, bound: f64, omega: f64, t_star: f64) {
    let Event { stop: hit, step, t, change: Change::Impact { rate, kinetic_lost, held: true }, .. } = events[0] else {
        panic!("{events:?}")
    };
    eprintln!("stop {hit} at {t} (t* = {t_star}), rate {rate}, lost {kinetic_lost}");
    assert_eq!(hit, stop, "{events:?}");
    // θ = θ₀ + ω t exactly (no load), and the crossing is the root of the
    // cubic through the step's ends: a straight line here.
    assert!((t - t_star).abs() < 1e-9, "stopped at {t}, by hand {t_star}");
    // Hit there, within step `step`, at the rate |ω|, all of it taken.
    assert!(t > (step - 1) as f64 * 1e-3 && t <= step as f64 * 1e-3, "{t} in step {step}");
    let expected = omega.abs();
    assert!((rate + expected).abs() < 1e-9, "{rate} against {expected}");
    let energy = 0.5 * (JYY + M * L * L) * expected * expected;
    assert!((kinetic_lost - energy).abs() < 1e-9 * energy, "{kinetic_lost} against {energy}");
    // Nothing presses the rod into the stop: its row's multiplier is
    // round-off against the rod's centripetal force m L ω² (it has been
    // 1.6e-115 and 6e-56), which may release it; nothing else happens.
    let round_off = 1e-12 * M * L * omega * omega;
    assert!(
        events[1..].iter().all(|e| matches!(e.change, Change::Release { multiplier } if multiplier.abs() < round_off)),
        "{events:?}"
    );
    // At the bound (a turn away from the (−π, π] the output reads), at rest.
    let after: Vec<_> = samples.iter().filter(|(s, _)| *s > t + 1e-3).collect();
    assert!(after.len() > 300);
    let off = |x: f64| ((x - bound + PI).rem_euclid(TAU) - PI).abs();
    let worst = after.iter().fold(0.0_f64, |w, (_, [x, r])| w.max(off(*x)).max(r.abs()));
    assert!(worst < 1e-9, "off the stop by {worst}");
}

#[test]
fn multi_turn_limits_a_finger_turning_up_passes_pi_and_its_lower_bound_a_turn_on_to_its_upper_stop() {
    // From 0 at 2 rad/s, θ passes π at 1.57 s and 3.66 = −2.62 + 2π at
    // 1.83 s (read in (−π, π] as −2.62: the spurious lower stop of before),
    // and meets its upper stop 6.28 at 3.14 s.
    let (lower, upper) = FINGER;
    let (events, samples) = turning(JointLimit::new(lower, upper), 0.0, 2.0, false, 3.5);
    stopped_once_at(&events, &samples, 1, upper, 2.0, upper / 2.0);
    // Down from 0 at 2 rad/s it meets −2.62 at 1.31 s, as before.
    let (events, samples) = turning(JointLimit::new(lower, upper), 0.0, -2.0, false, 1.7);
    stopped_once_at(&events, &samples, 0, lower, -2.0, -lower / 2.0);
}

#[test]
fn multi_turn_limits_a_joint_of_range_two_pi_each_way_turns_twice_and_stops() {
    // ±2π, started at −6.0: up at 2 rad/s it turns 2π + 6 = 12.28 rad,
    // nearly two turns, to its upper stop at 6.14 s.
    let (events, samples) = turning(JointLimit::new(-TAU, TAU), -6.0, 2.0, true, 6.5);
    stopped_once_at(&events, &samples, 1, TAU, 2.0, (TAU + 6.0) / 2.0);
    // Its stops read from the state alone take −6.0 as the angle of the
    // range nearest 0, −6.0 + 2π = 0.283: a turn less to go.
    let (events, samples) = turning(JointLimit::new(-TAU, TAU), -6.0, 2.0, false, 3.5);
    stopped_once_at(&events, &samples, 1, TAU, 2.0, (TAU - (TAU - 6.0)) / 2.0);
}

#[test]
fn multi_turn_limits_read_from_the_state_alone_are_in_the_range_nearest_0_or_the_start() {
    use cdyn::stops::{Unilateral, check_start};
    let (lower, upper) = FINGER;
    let mut mechanism = pendulum_at(0.0, JointLimit::new(lower, upper));
    mechanism.gravity = [0.0; 3];
    let stops = MechanismStops::new(mechanism.clone()).unwrap();
    let gaps = |stops: &MechanismStops, theta: f64| {
        let (q, v) = mechanism.state_at_joints(&[(0, theta)], &[(0, 1.0)]).unwrap();
        let mut gaps = [[0.0; 2]; 2];
        stops.gaps(&q, &v, &mut gaps).unwrap();
        (gaps, check_start(stops, &q, &v))
    };
    let close = |a: [[f64; 2]; 2], b: [[f64; 2]; 2]| {
        a.iter().flatten().zip(b.iter().flatten()).all(|(x, y)| (x - y).abs() < 1e-12)
    };
    // Both stops have period 2π; read (−π, π] from the state, the angle is
    // taken in the range nearest 0: 5.0 as 5.0 − 2π = −1.283, −3.0 (below
    // −2.62) as −3.0 + 2π = 3.283. Gaps θ + 2.62 and 6.28 − θ, rates 1, −1.
    assert_eq!((stops.period(0), stops.period(1)), (Some(TAU), Some(TAU)));
    for (theta, read) in [(5.0, 5.0 - TAU), (-3.0, -3.0 + TAU), (2.0, 2.0)] {
        let (g, start) = gaps(&stops, theta);
        assert!(close(g, [[read - lower, 1.0], [upper - read, -1.0]]), "{theta}: {g:?}");
        start.unwrap();
    }
    // Started at 5.0 (or 7.0), its stops read that turn: 7.0 is past 6.28.
    let started = |theta: f64| stops.clone().starting_at(&[(0, theta)]).unwrap();
    let (g, start) = gaps(&started(5.0), 5.0);
    assert!(close(g, [[5.0 - lower, 1.0], [upper - 5.0, -1.0]]), "{g:?}");
    start.unwrap();
    let (g, start) = gaps(&started(7.0), 7.0);
    assert!(close(g, [[7.0 - lower, 1.0], [upper - 7.0, -1.0]]), "{g:?}");
    let refused = start.unwrap_err().to_string();
    assert!(refused.contains("starts 7.200e-1 past its upper limit 6.28"), "{refused}");
    // A joint that does not exist is refused.
    assert!(stops.clone().starting_at(&[(1, 0.0)]).is_err());
}

#[test]
fn multi_turn_limits_keep_their_turn_across_a_state_set_between_steps() {
    // The finger of the test above, stepped to 2 s (θ = 4.0, read −2.28 in
    // (−π, π]) and put at its own state: read from the state alone its
    // upper gap would be 6.28 + 2.28, and 6.28 missed; set between steps,
    // it is taken nearest the run's, 2.28, and the stop met at 3.14 s.
    let (lower, upper) = FINGER;
    let mut mechanism = pendulum_at(0.0, JointLimit::new(lower, upper));
    mechanism.gravity = [0.0; 3];
    let (q0, v0) = mechanism.state_at_joints(&[], &[(0, 2.0)]).unwrap();
    let system = MechanismStops::new(mechanism).unwrap();
    let settings = Settings::new(Scheme::RungeKutta4, 1e-3, Control::robust());
    let mut run = cdyn::stops::StopSimulation::new(&system, settings, &q0, &v0).unwrap();
    while run.steps() < 2000 {
        run.step().unwrap();
    }
    let (q, v, e) = run.simulation(|s| (s.q().to_vec(), s.v().to_vec(), s.energy_input()));
    run.set_state(&q, &v, e).unwrap();
    while run.steps() < 3500 {
        run.step().unwrap();
    }
    let [Event { stop: 1, t, change: Change::Impact { held: true, .. }, .. }, ..] = run.report().events[..] else {
        panic!("{:?}", run.report().events)
    };
    assert!((t - upper / 2.0).abs() < 1e-9, "stopped at {t}");
}

#[test]
fn multi_turn_limits_an_elastic_finger_rebounds_from_one_stop_through_pi_to_the_other() {
    // e = 1: thrown back from 6.28 at 3.14 s, the finger turns down the
    // whole range, 8.9 rad, through π and 0 onto −2.62, at 2 rad/s from the
    // impact (within its step) on. Read from the state alone
    // after the impact (θ = 6.28 read as 6.28 − 2π = −0.003), the gaps lost
    // a turn, and the lower stop was met a turn early, at 4.45 s (seen).
    let (lower, upper) = FINGER;
    let (events, samples) = turning(JointLimit::new(lower, upper).with_restitution(1.0), 0.0, 2.0, false, 8.0);
    let [
        Event { stop: 1, step, t: up, change: Change::Impact { held: false, .. }, .. },
        Event { stop: 0, t: down, change: Change::Impact { held: false, .. }, .. },
    ] = events[..]
    else {
        panic!("{events:?}")
    };
    assert!((up - upper / 2.0).abs() < 1e-9, "{up}");
    let (_, [_, back]) = samples[step as usize];
    assert!((back + 2.0).abs() < 1e-9, "{back}");
    let expected = up + (upper - lower) / 2.0;
    eprintln!("upper stop at {up}, rebound at {back}, lower stop at {down} (by hand {expected})");
    assert!((down - expected).abs() < 1e-9, "hit the lower stop at {down}, by hand {expected}");
}

/// RATTLE and generalized-α, second-order schemes that step the model,
/// take the part steps to the crossing themselves: the impact's time and
/// rate converge on the closed form's at their order (errors a quarter at
/// half the step), where an impact seen at the step's end would be off by
/// up to `h |θ̈|` in its rate at any order.
#[test]
fn schemes_that_step_the_model_locate_the_impact_at_their_order() {
    let (t_star, rate) = (stop_time(), (2.0 * k() * (PHI_STOP.cos() - PHI0.cos())).sqrt());
    for scheme in [Scheme::Rattle, Scheme::GeneralizedAlpha] {
        let errors = [2e-3, 1e-3].map(|h| {
            let mechanism = pendulum(JointLimit::new(PHI_STOP - PHI0, f64::INFINITY));
            let built = mechanism.build().unwrap();
            let settings = Settings::new(scheme, h, Control::none());
            let system = MechanismStops::new(mechanism).unwrap();
            let report =
                run_with_stops::<_, cdyn::Error>(&system, settings, &built.q0, &built.v0, 0.5, 1, |_, _, _| Ok(()));
            let events = report.unwrap().events;
            let [Event { t, change: Change::Impact { rate: hit, held: true, .. }, .. }] = events[..] else {
                panic!("{scheme:?}: {events:?}")
            };
            [(t - t_star).abs(), (-hit - rate).abs()]
        });
        eprintln!("{scheme:?}: errors in t and rate at h = 2e-3, 1e-3: {errors:?}");
        for (coarse, fine) in errors[0].iter().zip(errors[1]) {
            let order = (coarse / fine).log2();
            assert!((1.8..2.3).contains(&order) && fine < 2e-5, "{scheme:?}: {errors:?}, order {order}");
        }
    }
}
