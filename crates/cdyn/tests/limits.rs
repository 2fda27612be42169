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
    let rod = Body::new("rod", M, [0.02, JYY, 0.005])
        .with_position([-L * PHI0.sin(), 0.0, -L * PHI0.cos()])
        .with_orientation([(PHI0 / 2.0).cos(), 0.0, (PHI0 / 2.0).sin(), 0.0]);
    let pivot = Joint::new(JointKind::Revolute, 0, None, [0.0; 3]).with_axis([0.0, 1.0, 0.0]).with_limit(limit);
    Mechanism::new([0.0, 0.0, -G]).with_bodies(vec![rod]).with_joints(vec![pivot])
}

/// `t*` by Simpson's rule after `φ = φ₀ − s²`, which takes the root's
/// singularity at φ₀ away: `dφ/√(…) = 2 s ds/√(2k (cos(φ₀ − s²) − cos φ₀))`.
fn stop_time() -> f64 {
    let f = |s: f64| {
        if s == 0.0 {
            2.0 / (2.0 * k() * PHI0.sin()).sqrt()
        } else {
            2.0 * s / (2.0 * k() * ((PHI0 - s * s).cos() - PHI0.cos())).sqrt()
        }
    };
    let (b, n) = ((PHI0 - PHI_STOP).sqrt(), 20_000);
    let h = b / n as f64;
    (0..=n)
        .map(|i| {
            f(i as f64 * h)
                * if i == 0 || i == n {
                    1.0
                } else if i % 2 == 1 {
                    4.0
                } else {
                    2.0
                }
        })
        .sum::<f64>()
        * h
        / 3.0
}

/// Runs the pendulum to `t_end`, returning the events and the joint's `(θ, θ̇)` at each sample.
fn run(scheme: Scheme, h: f64, limit: JointLimit, t_end: f64) -> (Vec<Event>, Vec<(f64, [f64; 3])>) {
    let mechanism = pendulum(limit);
    let built = mechanism.build().unwrap();
    let settings = Settings::new(scheme, h, Control::robust());
    let mut samples = Vec::new();
    let events = run_with_stops::<_, cdyn::Error>(
        &MechanismStops::new(mechanism.clone()).unwrap(),
        settings,
        &built.q0,
        &built.v0,
        t_end,
        1,
        |t, q, v| {
            samples.push((t, mechanism.joint_coordinates(q, v, &vec![0.0; q.len()])?[0].unwrap()));
            Ok(())
        },
    )
    .unwrap();
    (events.events, samples)
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
fn a_stop_with_restitution_throws_the_joint_back() {
    let e = 0.5;
    let (events, samples) =
        run(Scheme::RungeKutta4, 1e-3, JointLimit::new(PHI_STOP - PHI0, f64::INFINITY).with_restitution(e), 1.0);
    let Event { t, step, change: Change::Impact { rate, kinetic_lost, held: false }, .. } = events[0] else {
        panic!("{events:?}")
    };
    // The sample at the impact's step is after it: θ̇⁺ = −e θ̇⁻.
    let (_, [_, after, _]) = samples[step as usize];
    assert!((after + e * rate).abs() < 1e-9 * rate.abs(), "{after} against {rate}, at {t}");
    // Energy taken: (1 − e²) of the joint's kinetic energy.
    let inertia = JYY + M * L * L;
    assert!((kinetic_lost - (1.0 - e * e) * 0.5 * inertia * rate * rate).abs() < 1e-9 * kinetic_lost);
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
    let settings = Settings::new(Scheme::RungeKutta4, 1e-3, Control::robust());
    let mut theta = Vec::new();
    let report = run_with_stops::<_, cdyn::Error>(
        &MechanismStops::new(mechanism.clone()).unwrap(),
        settings,
        &built.q0,
        &built.v0,
        1.0,
        1,
        |_, q, v| {
            theta.push(mechanism.joint_coordinates(q, v, &vec![0.0; q.len()])?[0].unwrap()[0]);
            Ok(())
        },
    )
    .unwrap();
    let events = report.events;
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
