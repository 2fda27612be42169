//! The tree in joint coordinates in layers: its closed forms against
//! finite differences of its own `T` and `V`, its accelerations against
//! the same mechanism in body coordinates (a different formulation: seven
//! coordinates per body, the joints as constraint rows, `M(q)` and the
//! rows by automatic differentiation), the energy over a run, a stop
//! computed by hand, and impacts in both formulations. (Gravity's Hessian: a unit test in `tree/gravity.rs`.)

use cdyn::dynamics::Dynamics;
use cdyn::linalg::mass::DenseMass;
use cdyn::model::timefn::TimeFn;
use cdyn::spatial::{Actuator, Body, Coupling, Joint, JointKind, JointLimit, Load, Mechanism};
use cdyn::stops::{Change, Event, MechanismStops, TreeStops, Unilateral, run_with_stops};
use cdyn::{Control, Scheme, Settings, Simulation};

/// A branched tree: a revolute root on a tilted axis, a revolute joint on
/// it, a prismatic joint beyond, a revolute joint given child first (its
/// `θ` counts the parent against the child), a body welded to the second
/// body, and a second branch from the root; full inertia tensors and
/// bodies turned away from the space axes.
fn branched() -> Mechanism {
    let tensor = |a: f64, b: f64, c: f64, d: f64| [[a, d, 0.3 * d], [d, b, -0.5 * d], [0.3 * d, -0.5 * d, c]];
    let body = |name: &str, m: f64, r: [f64; 3], p: [f64; 4], j: [[f64; 3]; 3]| {
        let norm = p.iter().map(|x| x * x).sum::<f64>().sqrt();
        Body::new(name, m, [1.0; 3]).with_inertia(j).with_position(r).with_orientation(p.map(|x| x / norm))
    };
    let bodies = vec![
        body("root", 2.0, [0.1, 0.05, -0.2], [0.9, 0.1, -0.2, 0.3], tensor(0.05, 0.06, 0.04, 0.01)),
        body("arm", 1.5, [0.4, 0.0, -0.3], [0.7, 0.3, 0.1, -0.2], tensor(0.03, 0.02, 0.025, 0.004)),
        body("slider", 0.8, [0.6, 0.2, -0.35], [1.0, 0.0, 0.0, 0.0], tensor(0.01, 0.012, 0.009, 0.002)),
        body("hand", 0.5, [0.7, 0.35, -0.5], [0.8, -0.3, 0.4, 0.1], tensor(0.004, 0.005, 0.003, 0.001)),
        body("weld", 0.3, [0.45, -0.1, -0.25], [0.6, 0.0, 0.6, 0.2], tensor(0.002, 0.003, 0.0025, 0.0005)),
        body("branch", 1.1, [-0.25, 0.15, -0.4], [0.9, -0.1, 0.0, 0.4], tensor(0.02, 0.015, 0.018, 0.003)),
    ];
    let joint = |kind, a, b, point, axis: Option<[f64; 3]>| {
        let j = Joint::new(kind, a, b, point);
        match axis {
            Some(axis) => j.with_axis(axis),
            None => j,
        }
    };
    let joints = vec![
        joint(JointKind::Revolute, 0, None, [0.0; 3], Some([0.0, 0.3, 1.0])),
        joint(JointKind::Revolute, 1, Some(0), [0.3, 0.0, -0.1], Some([1.0, 0.2, 0.0])),
        joint(JointKind::Prismatic, 2, Some(1), [0.5, 0.1, -0.2], Some([0.2, 1.0, 0.1])),
        joint(JointKind::Revolute, 2, Some(3), [0.6, 0.3, -0.4], Some([0.0, 1.0, 1.0])),
        joint(JointKind::Fixed, 4, Some(1), [0.45, -0.1, -0.25], Some([0.0, 0.0, 1.0])),
        joint(JointKind::Revolute, 5, Some(0), [-0.2, 0.1, -0.3], Some([0.3, -0.2, 1.0])),
    ];
    Mechanism::new([0.0, -1.2, -9.81]).with_bodies(bodies).with_joints(joints)
}

/// A state of `n` coordinates, reproducibly spread over `±scale`.
fn spread(n: usize, seed: u64, scale: f64) -> Vec<f64> {
    let mut s = seed;
    (0..n)
        .map(|_| {
            s = s.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            scale * (2.0 * ((s >> 11) as f64 / (1u64 << 53) as f64) - 1.0)
        })
        .collect()
}

#[test]
fn the_closed_forms_agree_with_finite_differences_of_the_energies() {
    let built = branched().in_joint_coordinates().unwrap();
    let model = &built.model;
    let n = model.n();
    assert_eq!(n, 5);
    for seed in 1..4 {
        let (q, v) = (spread(n, seed, 1.2), spread(n, seed + 10, 2.0));
        let mut mass = DenseMass::new(n);
        let (mut grad_q, mut mdot_v) = (vec![0.0; n], vec![0.0; n]);
        let energy = model.mass_at(&q, &v, &mut mass, &mut grad_q, &mut mdot_v).unwrap();
        let m = mass.matrix().to_vec();
        let kinetic = |q: &[f64], v: &[f64]| model.kinetic(q, v);
        assert!((energy - kinetic(&q, &v)).abs() < 1e-14 * energy);
        let unit = |i: usize| -> Vec<f64> { (0..n).map(|k| f64::from(u8::from(k == i))).collect() };
        let sum = |a: &[f64], b: &[f64]| -> Vec<f64> { a.iter().zip(b).map(|(a, b)| a + b).collect() };
        let along = |x: &[f64], d: &[f64], s: f64| -> Vec<f64> { x.iter().zip(d).map(|(x, d)| x + s * d).collect() };
        let scale = m.iter().fold(0.0_f64, |s, x| s.max(x.abs()));
        for i in 0..n {
            for j in 0..n {
                // T is quadratic in v: M_ij = T(e_i + e_j) − T(e_i) − T(e_j) (also for i = j).
                let exact = kinetic(&q, &sum(&unit(i), &unit(j))) - kinetic(&q, &unit(i)) - kinetic(&q, &unit(j));
                assert!((m[i * n + j] - exact).abs() < 1e-13 * scale, "M[{i}][{j}] = {} vs {exact}", m[i * n + j]);
            }
            let e = 1e-6;
            let fd = (kinetic(&along(&q, &unit(i), e), &v) - kinetic(&along(&q, &unit(i), -e), &v)) / (2.0 * e);
            assert!((grad_q[i] - fd).abs() < 1e-7 * energy, "∂T/∂θ_{i} = {} vs {fd}", grad_q[i]);
        }
        // Ṁ θ̇ = d/ds M(θ + s θ̇) θ̇.
        let mass_along = |s: f64| {
            let mut mass = DenseMass::new(n);
            let (mut g, mut d) = (vec![0.0; n], vec![0.0; n]);
            model.mass_at(&along(&q, &v, s), &v, &mut mass, &mut g, &mut d).unwrap();
            mass.matrix().to_vec()
        };
        let (plus, minus) = (mass_along(1e-6), mass_along(-1e-6));
        for i in 0..n {
            let fd: f64 = (0..n).map(|j| (plus[i * n + j] - minus[i * n + j]) / 2e-6 * v[j]).sum();
            assert!((mdot_v[i] - fd).abs() < 1e-7 * energy, "(Ṁ θ̇)_{i} = {} vs {fd}", mdot_v[i]);
        }
        // Gravity: ∇V and ∇²V.
        let potential = |q: &[f64]| model.potential(q, None);
        let mut grad = vec![0.0; n];
        let v0 = model.potential(&q, Some(&mut grad));
        assert!((v0 - potential(&q)).abs() < 1e-15 * v0.abs().max(1.0));
        for i in 0..n {
            let e = 1e-6;
            let fd = (potential(&along(&q, &unit(i), e)) - potential(&along(&q, &unit(i), -e))) / (2.0 * e);
            assert!((grad[i] - fd).abs() < 1e-7, "∂V/∂θ_{i} = {} vs {fd}", grad[i]);
        }
    }
}

#[test]
fn joint_accelerations_agree_with_the_mechanism_in_body_coordinates() {
    let mut mechanism = branched();
    // Damping and friction act on both formulations' joint rates; a torque
    // of time on the root, a servo clamped at its effort on the hand and a
    // drive on the branch, at t = 0.4.
    mechanism.joints[1] = mechanism.joints[1].clone().with_damping(0.7).with_friction(0.2);
    mechanism.joints[2] = mechanism.joints[2].clone().with_damping(1.3);
    mechanism.joints[3] = mechanism.joints[3].clone().with_limit(JointLimit::new(-3.0, 3.0).with_effort(0.4));
    let drive = TimeFn::sine(0.3, 2.0, 0.1);
    mechanism.joints[5] = mechanism.joints[5].clone().with_angle(drive.clone());
    mechanism.actuators = vec![
        Actuator::torque(0, TimeFn::polynomial(vec![0.5, -1.0, 2.0])),
        Actuator::servo(3, TimeFn::linear(0.2, 0.5), 3.0, 0.4),
    ];
    // Every load: springs with dampers between two bodies and to the
    // ground, rotary dampers between two bodies and from a welded one to the
    // ground, a force at a point and a torque.
    mechanism.loads = vec![
        Load::Spring {
            a: 3,
            b: Some(5),
            point: [0.72, 0.33, -0.52],
            point_b: [-0.2, 0.2, -0.45],
            stiffness: 40.0,
            damping: 1.5,
            length: Some(0.3),
        },
        Load::Spring {
            a: 2,
            b: None,
            point: [0.6, 0.25, -0.3],
            point_b: [0.8, 0.0, 0.1],
            stiffness: 25.0,
            damping: 0.8,
            length: None,
        },
        Load::RotaryDamper { a: 1, b: Some(0), axis: [0.3, 1.0, 0.0], damping: 0.6 },
        Load::RotaryDamper { a: 4, b: None, axis: [0.0, 0.2, 1.0], damping: 0.9 },
        Load::Force { body: 3, force: [1.0, -2.0, 0.5], point: Some([0.75, 0.3, -0.55]) },
        Load::Torque { body: 5, torque: [0.2, 0.1, -0.3] },
    ];
    let t = 0.4;
    let in_joints = mechanism.in_joint_coordinates().unwrap();
    let bodies = mechanism.build().unwrap();
    let n = in_joints.model.n();
    let driven = in_joints.joints.iter().position(|&j| j == 5).unwrap();
    let (mut poses, mut pose) = (in_joints.poses.clone(), vec![0.0; 7 * mechanism.bodies.len()]);
    let (mut tree, mut full) = (Dynamics::new(&in_joints.model), Dynamics::new(&bodies.model));
    let mut worst: f64 = 0.0;
    for seed in 1..6 {
        let (mut theta, mut rate) = (spread(n, seed, 1.5), spread(n, seed + 20, 3.0));
        // On the drive's row, where its two forms (θ − f and the body
        // coordinates' own) have the same second derivative.
        (theta[driven], rate[driven]) = (drive.eval(t), drive.derivative().eval(t));
        tree.evaluate(&in_joints.model, &theta, &rate, t).unwrap();
        let (q, v) = in_joints.bodies(&mechanism, &theta, &rate).unwrap();
        full.evaluate(&bodies.model, &q, &v, t).unwrap();
        // The bodies' poses as a run in joint coordinates records them.
        poses.at(&theta, &mut pose);
        for (mine, theirs) in pose.chunks(7).zip(q.chunks(7)) {
            let same = |s: f64| (0..7).all(|i| (mine[i] - if i < 3 { 1.0 } else { s } * theirs[i]).abs() < 1e-12);
            assert!(same(1.0) || same(-1.0), "{mine:?} against {theirs:?}");
        }
        let read = mechanism.joint_coordinates(&q, &v, full.acc()).unwrap();
        for (c, &joint) in in_joints.joints.iter().enumerate() {
            let [_, r, a] = read[joint].unwrap();
            assert!((r - rate[c]).abs() < 1e-12, "joint {joint}: rate {r} vs {}", rate[c]);
            let scale = a.abs().max(1.0);
            worst = worst.max((tree.acc()[c] - a).abs() / scale);
            assert!((tree.acc()[c] - a).abs() < 1e-9 * scale, "joint {joint}: θ̈ {} vs {a}", tree.acc()[c]);
        }
    }
    assert!(worst > 0.0, "two formulations agree to round-off, not bit for bit");
    // The driven joint follows its drive, the clamped servo pushes at its effort.
    let c = driven;
    assert!((tree.acc()[c] - drive.derivative().derivative().eval(t)).abs() < 1e-9);
    assert_eq!((in_joints.q0[c], in_joints.v0[c]), (drive.eval(0.0), drive.derivative().eval(0.0)));
}

#[test]
fn a_mimic_coupling_holds_and_energy_is_kept_over_a_run() {
    let mechanism = branched().with_couplings(vec![Coupling::new(5, 1, -0.5, 0.1)]);
    let built = mechanism.in_joint_coordinates().unwrap();
    assert_eq!(built.model.m(), 1);
    let mut q0 = built.q0.clone();
    // Start on the coupling: θ_5 = −0.5 θ_1 + 0.1 with θ_1 = 0.
    q0[4] = 0.1;
    // Without control: RK-4 keeps a linear row's Φ and Φ̇ to round-off, and
    // the energy to its truncation error.
    let settings = Settings::new(Scheme::RungeKutta4, 1e-3, Control::none());
    let mut sim = Simulation::new(&built.model, settings, &q0, &built.v0).unwrap();
    let e0 = built.model.potential(&q0, None);
    sim.run::<cdyn::Error>(2.0, 1000, |_| Ok(())).unwrap();
    let end = sim.measure();
    assert!(end.phi.abs() < 1e-12 && end.phi_dot.abs() < 1e-12, "|Φ| = {}, |Φ̇| = {}", end.phi, end.phi_dot);
    assert!(end.psi.abs() < 1e-9 * e0.abs(), "Ψ = {} of E = {e0}", end.psi);
    let q = sim.q();
    assert!(q[0].abs() > 0.1, "the tree moved under gravity: {q:?}");
}

#[test]
fn what_joint_coordinates_cannot_describe_is_refused_by_name() {
    let loop_closed = branched().with_joints({
        let mut j = branched().joints;
        j.push(Joint::new(JointKind::Spherical, 3, Some(5), [0.2, 0.2, -0.5]));
        j
    });
    let message = |m: Mechanism| m.in_joint_coordinates().err().map(|e| e.to_string()).unwrap_or_default();
    let text = message(loop_closed);
    assert!(text.contains("spherical") && text.contains("coordinate"), "{text}");
    let mut looped = branched();
    looped.joints.push(Joint::new(JointKind::Revolute, 3, Some(5), [0.2, 0.2, -0.5]).with_axis([0.0, 0.0, 1.0]));
    let text = message(looped);
    // The breadth-first tree reaches `hand` through the new joint first, so the older one closes the loop.
    assert!(text.contains("element 3 (revolute)") && text.contains("closes a loop"), "{text}");
    let mut floating = branched();
    floating.joints.remove(5);
    let text = message(floating);
    assert!(text.contains("branch") && text.contains("not joined to the ground"), "{text}");
    let mut driven = branched();
    driven.joints[2] = driven.joints[2].clone().with_angle(TimeFn::linear(0.0, 1.0));
    let text = message(driven);
    assert!(text.contains("element 2 (prismatic)") && text.contains("angle"), "{text}");
    let mut welded = branched();
    welded.actuators = vec![Actuator::torque(4, TimeFn::constant(1.0))];
    let text = message(welded);
    assert!(text.contains("actuator") && text.contains("fixed"), "{text}");
    let mut lost = branched();
    lost.joints[1].point[2] = f64::NAN;
    let text = message(lost);
    assert!(text.contains("element 1 (revolute)") && text.contains("point = NaN must be finite"), "{text}");
    // A load reaches at most 12 joint coordinates (the sizes its AD elements are compiled for).
    let links: Vec<Body> = (0..13)
        .map(|k| Body::new(&format!("l{k}"), 1.0, [0.01; 3]).with_position([0.1 * k as f64 + 0.05, 0.0, 0.0]))
        .collect();
    let pins: Vec<Joint> = (0..13)
        .map(|k| {
            Joint::new(JointKind::Revolute, k, k.checked_sub(1), [0.1 * k as f64, 0.0, 0.0]).with_axis([0.0, 0.0, 1.0])
        })
        .collect();
    let tip = Load::Torque { body: 12, torque: [0.0, 0.0, 1.0] };
    let text = message(Mechanism::new([0.0; 3]).with_bodies(links).with_joints(pins).with_loads(vec![tip]));
    assert!(text.contains("element 13 (torque)") && text.contains("13 joints from the ground"), "{text}");
    let mut inverted = branched();
    inverted.joints[2] = inverted.joints[2].clone().with_limit(JointLimit::new(1.0, -1.0));
    let text = message(inverted);
    assert!(text.contains("element 2 (prismatic)") && text.contains("lower"), "{text}");
}

/// The hand-computed stop of `tests/limits.rs` in joint coordinates: a rod
/// released from rest at φ₀ = 1.2 rad from the vertical falls onto a stop
/// at φ = 0.3 rad (`θ = φ − φ₀ = −0.9`), reached at `t*` with all its
/// kinetic energy lost (`e = 0`), and is held there by gravity.
#[test]
fn a_pendulum_in_joint_coordinates_is_stopped_at_its_limit_when_computed_by_hand() {
    let (g, m, l, jyy, phi0, phi_stop) = (9.81, 2.0, 0.5, 0.02, 1.2_f64, 0.3_f64);
    let rod = Body::new("rod", m, [0.02, jyy, 0.005])
        .with_position([-l * phi0.sin(), 0.0, -l * phi0.cos()])
        .with_orientation([(phi0 / 2.0).cos(), 0.0, (phi0 / 2.0).sin(), 0.0]);
    let limit = JointLimit::new(phi_stop - phi0, f64::INFINITY);
    let pivot = Joint::new(JointKind::Revolute, 0, None, [0.0; 3]).with_axis([0.0, 1.0, 0.0]).with_limit(limit);
    let mechanism = Mechanism::new([0.0, 0.0, -g]).with_bodies(vec![rod]).with_joints(vec![pivot]);
    let inertia = jyy + m * l * l;
    let k = m * g * l / inertia;
    let t_star = cdyn::reference::time_to_swing(k, phi0, phi_stop).unwrap();
    let rate = (2.0 * k * (phi_stop.cos() - phi0.cos())).sqrt();
    let built = mechanism.in_joint_coordinates().unwrap();
    let system = TreeStops::new(mechanism).unwrap();
    let h = 1e-3;
    let settings = Settings::new(Scheme::RungeKutta4, h, Control::robust());
    let mut held = Vec::new();
    let report = run_with_stops::<_, cdyn::Error>(&system, settings, &built.q0, &built.v0, 1.5, 1, |t, q, v| {
        held.push((t, q[0], v[0]));
        Ok(())
    })
    .unwrap();
    let [Event { t, change: Change::Impact { rate: hit, kinetic_lost, held: true }, .. }] = report.events[..] else {
        panic!("{:?}", report.events)
    };
    assert!((t - t_star).abs() < 1e-9, "stopped at {t}, by hand {t_star}");
    assert!((-hit - rate).abs() < 1e-9 * rate, "{hit} against {rate}");
    assert!((kinetic_lost - 0.5 * inertia * hit * hit).abs() < 1e-12 * kinetic_lost, "{kinetic_lost}");
    let after: Vec<_> = held.iter().filter(|(s, ..)| *s > t + h).collect();
    assert!(after.len() > 500);
    let worst = after.iter().fold(0.0_f64, |w, (_, x, r)| w.max((x - (phi_stop - phi0)).abs()).max(r.abs()));
    assert!(worst < 1e-9, "off the stop by {worst}");
}

/// The branched tree with three joints limited, falling onto them, in
/// both formulations: each impact is located within its step and applied
/// at the stop, so both see the same impacts at the same times and the
/// joints' angles and rates agree through them (seen at the step's end,
/// each impact's projection differed between the formulations at first
/// order in how late it was seen: 5e-5 of Panda's rate).
#[test]
fn impacts_keep_joint_and_body_coordinates_together() {
    let mut mechanism = branched();
    for (joint, range) in [(0, 0.25), (1, 0.2), (5, 0.15)] {
        mechanism.joints[joint] = mechanism.joints[joint].clone().with_limit(JointLimit::new(-range, range));
    }
    let built = mechanism.build().unwrap();
    let (bodies, in_bodies) =
        stopped(&MechanismStops::new(mechanism.clone()).unwrap(), (&built.q0, &built.v0), |q, v| {
            let joints = mechanism.joint_coordinates(q, v, &vec![0.0; q.len()]).unwrap();
            joints.into_iter().flatten().map(|[x, rate, _]| [x, rate]).collect()
        });
    let tree = mechanism.in_joint_coordinates().unwrap();
    let (joints, in_joints) = stopped(&TreeStops::new(mechanism.clone()).unwrap(), (&tree.q0, &tree.v0), |q, v| {
        q.iter().zip(v).map(|(x, rate)| [*x, *rate]).collect()
    });
    let impacts = |events: &[Event]| -> Vec<(usize, f64)> {
        events.iter().filter(|e| matches!(e.change, Change::Impact { .. })).map(|e| (e.stop, e.t)).collect()
    };
    let (seen_b, seen_j) = (impacts(&bodies), impacts(&joints));
    eprintln!("impacts: {seen_b:?}");
    assert!(seen_b.len() >= 3, "{bodies:?}");
    assert_eq!(seen_b.len(), seen_j.len(), "{bodies:?} against {joints:?}");
    for ((stop_b, t_b), (stop_j, t_j)) in seen_b.iter().zip(&seen_j) {
        assert!(stop_b == stop_j && (t_b - t_j).abs() < 1e-9, "{stop_b} at {t_b} against {stop_j} at {t_j}");
    }
    // Both list the joints in order: the tree's coordinates are joints 0,
    // 1, 2, 3 and 5 (the fixed joint 4 has none).
    assert_eq!(tree.joints, [0, 1, 2, 3, 5]);
    let worst = in_bodies.iter().zip(&in_joints).fold(0.0_f64, |w, (b, j)| {
        b.iter().zip(j).fold(w, |w, (b, j)| w.max((b[0] - j[0]).abs()).max((b[1] - j[1]).abs()))
    });
    eprintln!("largest difference of a joint's angle or rate: {worst:e}");
    assert!(worst < 1e-7, "{worst:e}");
}

/// `system` run with its stops from `(q0, v0)` for 1 s (RK-4, h = 1e-3,
/// `robust`): its events, and every 10 steps each joint's `(θ, θ̇)` as
/// `joints(q, v)` reads them.
fn stopped<U: Unilateral>(
    system: &U,
    (q0, v0): (&[f64], &[f64]),
    joints: impl Fn(&[f64], &[f64]) -> Vec<[f64; 2]>,
) -> (Vec<Event>, Vec<Vec<[f64; 2]>>) {
    let settings = Settings::new(Scheme::RungeKutta4, 1e-3, Control::robust());
    let mut samples = Vec::new();
    let report = run_with_stops::<_, cdyn::Error>(system, settings, q0, v0, 1.0, 10, |_, q, v| {
        samples.push(joints(q, v));
        Ok(())
    });
    (report.unwrap().events, samples)
}
