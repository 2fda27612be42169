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

use cdyn::spatial::{Body, Joint, JointKind, JointLimit, Mechanism};
use cdyn::stops::{Change, Event, MechanismStops, run_with_stops};
use cdyn::{Control, Scheme, Settings};

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
        assert!((t - t_star).abs() < 1e-6, "{scheme:?}: stopped at {t}, by hand {t_star}");
        // Seen at the step's end, up to h after the crossing: the rate then, within h |θ̈|.
        assert!((-hit - rate).abs() < h * k(), "{scheme:?}: {hit} against {rate}");
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
    // The sample at the impact's step is after it: θ̇⁺ = −e θ̇⁻ with θ̇⁻
    // the rate at the crossing (the closed form's), not the step end's
    // `rate`, up to h later (its rebound would give back energy).
    let (_, [_, after, _]) = samples[step as usize];
    let crossing = (2.0 * k() * (PHI_STOP.cos() - PHI0.cos())).sqrt();
    assert!((after - e * crossing).abs() < 1e-7 * crossing, "{after} against {crossing}, at {t}");
    assert!(-rate > crossing && -rate - crossing < 1e-3 * k(), "{rate} against {crossing}");
    // Energy taken: all the joint's kinetic energy less what it leaves with.
    let inertia = JYY + M * L * L;
    assert!((kinetic_lost - 0.5 * inertia * (rate * rate - after * after)).abs() < 1e-9 * kinetic_lost);
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
