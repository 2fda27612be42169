//! Spatial bodies and joints (`cdyn::spatial`): derivatives against finite
//! differences, the freedom each joint leaves, the block-diagonal mass
//! path against the dense one, and the rigid-body references (Euler's
//! torque-free motion, the heavy top benchmark).

use cdyn::dynamics::{DependentRows, Dynamics, LinearSolver};
use cdyn::model::timefn::TimeFn;
use cdyn::reference::torque_free_rate;
use cdyn::spatial::rotation::{about, body_rate, compose, rate_from_body, rotate, space_rate};
use cdyn::spatial::{Body, Built, Joint, JointKind, Mechanism, SpatialBody};
use cdyn::{Control, Error, Model, Scheme, Settings, Simulation, methods};
use nalgebra::DMatrix;
use proptest::prelude::*;

fn close(a: f64, b: f64, tol: f64) -> bool {
    (a - b).abs() <= tol * (1.0 + a.abs().max(b.abs()))
}

fn unit(x: [f64; 3]) -> [f64; 3] {
    let n = x.iter().map(|x| x * x).sum::<f64>().sqrt();
    x.map(|x| x / n)
}

fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
}

/// Every kind of joint with its relative freedom, at `point` with `axis`
/// (a universal joint's second axis perpendicular to it; a distance
/// joint's second end at `point_b`).
fn joints(point: [f64; 3], axis: [f64; 3], point_b: [f64; 3], b: Option<usize>) -> Vec<(Joint, usize)> {
    let other = unit(cross(axis, [0.3, -0.5, 0.8]));
    let at = |kind| Joint::new(kind, 0, b, point);
    vec![
        (at(JointKind::Spherical), 3),
        (at(JointKind::Revolute).with_axis(axis), 1),
        (at(JointKind::Universal).with_axis(axis).with_axis_b(other), 2),
        (at(JointKind::Cylindrical).with_axis(axis), 2),
        (at(JointKind::Prismatic).with_axis(axis), 1),
        (at(JointKind::Fixed).with_axis(axis), 0),
        (at(JointKind::Distance).with_point_b(point_b), 5),
        // Driven: nothing is left free at a given time.
        (
            at(JointKind::Revolute)
                .with_axis(axis)
                .with_angle(TimeFn::polynomial(vec![0.0, 0.5]).with_sines(vec![[0.3, 2.0, 0.0]])),
            0,
        ),
        (at(JointKind::Prismatic).with_axis(axis).with_displacement(TimeFn::polynomial(vec![0.0, 0.2, -0.4])), 0),
    ]
}

/// Two bodies at the given poses joined by `joint`, or one body and the
/// ground (`joint.b` is `None`).
fn pair(joint: Joint, poses: [([f64; 3], [f64; 4]); 2]) -> Mechanism {
    let bodies: Vec<Body> = poses
        .iter()
        .enumerate()
        .take(if joint.b.is_none() { 1 } else { 2 })
        .map(|(i, &(r, p))| {
            Body::new(&format!("b{i}"), 1.0 + i as f64, [1.0; 3]).with_position(r).with_orientation(p).with_inertia([
                [1.0, 0.1, 0.0],
                [0.1, 1.5, -0.2],
                [0.0, -0.2, 2.0],
            ])
        })
        .collect();
    Mechanism::new([0.0, 0.0, -9.81]).with_bodies(bodies).with_joints(vec![joint])
}

fn phi(model: &Model, q: &[f64]) -> Vec<f64> {
    phi_at(model, q, 0.0)
}

fn phi_at(model: &Model, q: &[f64], t: f64) -> Vec<f64> {
    let mut out = vec![0.0; model.m()];
    model.constraint_values(q, t, &mut out);
    out
}

fn dense_jacobian(model: &Model, d: &Dynamics) -> DMatrix<f64> {
    let pattern = model.pattern();
    DMatrix::from_fn(model.m(), model.n(), |r, c| {
        pattern.row(r).find(|&j| pattern.cols[j] as usize == c).map_or(0.0, |j| d.jac()[j])
    })
}

fn quaternion() -> impl Strategy<Value = [f64; 4]> {
    (prop::array::uniform3(-1.0..1.0f64), -3.0..3.0f64)
        .prop_filter("an axis", |(a, _)| a.iter().map(|x| x * x).sum::<f64>() > 0.01)
        .prop_map(|(a, angle)| about(unit(a), angle))
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(24))]

    /// `Φ_q`, `Φ̇` and `γ` of every joint against central differences, at
    /// random poses off the constraints and random velocities.
    #[test]
    fn joint_derivatives_match_finite_differences(
        ra in prop::array::uniform3(-1.0..1.0f64), pa in quaternion(),
        rb in prop::array::uniform3(-1.0..1.0f64), pb in quaternion(),
        point in prop::array::uniform3(-1.0..1.0f64),
        axis in prop::array::uniform3(0.1..1.0f64),
        dq in prop::collection::vec(-0.2..0.2f64, 14),
        v in prop::collection::vec(-2.0..2.0f64, 14),
        grounded in any::<bool>(),
    ) {
        let point_b = [point[0] + 0.5, point[1], point[2] - 0.3];
        for (joint, _) in joints(point, unit(axis), point_b, (!grounded).then_some(1)) {
            let kind = joint.kind;
            let Built { model, q0, .. } = pair(joint, [(ra, pa), (rb, pb)]).build().unwrap();
            let n = model.n();
            let q: Vec<f64> = q0.iter().zip(&dq).map(|(q, d)| q + d).collect();
            let v = &v[..n];
            let t0 = 0.3;
            let mut d = Dynamics::new(&model);
            d.evaluate(&model, &q, v, t0).unwrap();
            let jac = dense_jacobian(&model, &d);
            let h = 1e-6;
            for c in 0..n {
                let (mut qp, mut qm) = (q.clone(), q.clone());
                qp[c] += h;
                qm[c] -= h;
                let (p, m) = (phi_at(&model, &qp, t0), phi_at(&model, &qm, t0));
                for r in 0..model.m() {
                    let fd = (p[r] - m[r]) / (2.0 * h);
                    prop_assert!(close(jac[(r, c)], fd, 1e-7), "{kind:?} Φ_q[{r},{c}]: AD {} vs FD {fd}", jac[(r, c)]);
                }
            }
            // Along s ↦ (q + s v, t0 + s): Φ̇ = Φ_q v + Φ_t, and −γ the second derivative.
            let along = |s: f64| phi_at(&model, &q.iter().zip(v).map(|(q, v)| q + s * v).collect::<Vec<_>>(), t0 + s);
            // Φ along the line is a quartic in s (A(p) is quadratic in p): a
            // shorter step for the first difference keeps its truncation
            // error (h²/6 times the third derivative) below the tolerance.
            let (hs, h1) = (1e-4, 1e-5);
            let (p1, p0, m1) = (along(hs), along(0.0), along(-hs));
            let (f1, b1) = (along(h1), along(-h1));
            for r in 0..model.m() {
                let first = (f1[r] - b1[r]) / (2.0 * h1);
                let second = (p1[r] - 2.0 * p0[r] + m1[r]) / (hs * hs);
                prop_assert!(close(d.phi_dot()[r], first, 1e-6), "{kind:?} Φ̇[{r}]: AD {} vs FD {first}", d.phi_dot()[r]);
                prop_assert!(close(-d.gamma()[r], second, 1e-5), "{kind:?} γ[{r}]: AD {} vs FD {}", d.gamma()[r], -second);
            }
        }
    }

    /// At an assembled pose, each joint's rows (with the two normalizations)
    /// are independent, and the motions it should allow satisfy `Φ_q v = 0`:
    /// so it leaves exactly its degrees of freedom, and the right ones.
    #[test]
    fn each_joint_leaves_exactly_its_degrees_of_freedom(
        ra in prop::array::uniform3(-1.0..1.0f64), pa in quaternion(),
        rb in prop::array::uniform3(-1.0..1.0f64), pb in quaternion(),
        point in prop::array::uniform3(-1.0..1.0f64),
        axis in prop::array::uniform3(0.1..1.0f64),
    ) {
        let axis = unit(axis);
        let point_b = [point[0] + 0.5, point[1], point[2] - 0.3];
        for (joint, freedom) in joints(point, axis, point_b, Some(1)) {
            let kind = joint.kind;
            let axis_b = joint.axis_b.unwrap_or_default();
            let Built { model, q0: q, .. } = pair(joint, [(ra, pa), (rb, pb)]).build().unwrap();
            prop_assert!(phi(&model, &q).iter().all(|x| x.abs() < 1e-12), "{kind:?} not assembled");
            let mut d = Dynamics::new(&model);
            d.evaluate(&model, &q, &[0.0; 14], 0.0).unwrap();
            let jac = dense_jacobian(&model, &d);
            let rank = jac.clone().svd(false, false).rank(1e-9);
            prop_assert_eq!(rank, model.m(), "{:?}: rank of Φ_q", kind);
            prop_assert_eq!(14 - rank - 6, freedom, "{:?}: freedom left to body b", kind);
            // Body b moving, body a still: rotations about axes through a
            // point, and translations.
            let b = SpatialBody::of(1);
            let motion = |w: [f64; 3], about: [f64; 3], u: [f64; 3]| {
                let mut v = vec![0.0; 14];
                let arm: [f64; 3] = std::array::from_fn(|i| rb[i] - about[i]);
                let vc = cross(w, arm);
                let wb = rotate([pb[0], -pb[1], -pb[2], -pb[3]], w);
                v[b.first..b.first + 3].copy_from_slice(&std::array::from_fn::<f64, 3, _>(|i| vc[i] + u[i]));
                v[b.first + 3..b.first + 7].copy_from_slice(&rate_from_body(pb, wb));
                v
            };
            let z = [0.0; 3];
            let allowed: Vec<Vec<f64>> = match kind {
                JointKind::Spherical => (0..3).map(|i| motion(std::array::from_fn(|k| (k == i) as u8 as f64), point, z)).collect(),
                _ if freedom == 0 => vec![],
                JointKind::Revolute => vec![motion(axis, point, z)],
                JointKind::Universal => vec![motion(axis, point, z), motion(axis_b, point, z)],
                JointKind::Cylindrical => vec![motion(axis, point, z), motion(z, point, axis)],
                JointKind::Prismatic => vec![motion(z, point, axis)],
                JointKind::Fixed => vec![],
                JointKind::Distance => (0..3)
                    .map(|i| motion(std::array::from_fn(|k| (k == i) as u8 as f64), point, z))
                    .chain((0..2).map(|i| motion(std::array::from_fn(|k| (k == i) as u8 as f64), point_b, z)))
                    .collect(),
                other => panic!("no allowed motions written for {other:?}"),
            };
            for v in allowed {
                let phi_dot = &jac * nalgebra::DVector::from_vec(v);
                prop_assert!(phi_dot.amax() < 1e-12, "{:?}: an allowed motion violates Φ_q v = 0 by {}", kind, phi_dot.amax());
            }
        }
    }
}

/// Principal moments `J₁ < J₂ < J₃` of the torque-free body.
const J: [f64; 3] = [1.0, 2.0, 3.0];
/// Initial body angular velocity `(a, 0, c)` in principal axes.
const W0: [f64; 3] = [1.0, 0.0, 1.0];

/// Euler's torque-free motion from `ω(0) = (a, 0, c)` ([`torque_free_rate`]).
fn euler_exact(t: f64) -> [f64; 3] {
    torque_free_rate(J, [W0[0], W0[2]], t)
}

/// A free body whose body axes are turned by `turn` from its principal
/// axes: inertia `Q diag(J) Qᵀ` and initial angular velocity `Q ω₀` in its
/// own axes, orientation `turn⁻¹`, so that the principal axes start on
/// the space axes and the motion is Euler's.
fn free_body(turn: [f64; 4]) -> Mechanism {
    let column = |c: usize| rotate(turn, std::array::from_fn(|k| (k == c) as u8 as f64));
    let q = [column(0), column(1), column(2)];
    let inertia = std::array::from_fn(|a| std::array::from_fn(|b| (0..3).map(|k| q[k][a] * J[k] * q[k][b]).sum()));
    let body = Body::new("top", 2.0, J)
        .with_inertia(inertia)
        .with_orientation([turn[0], -turn[1], -turn[2], -turn[3]])
        .with_angular_velocity(rotate(turn, W0));
    Mechanism::new([0.0; 3]).with_bodies(vec![body])
}

/// Largest error of the spatial angular velocity against Euler's solution
/// (rotated into space: the principal axes start on the space axes), of
/// `|p| − 1` and of the energy, over `t_end`.
fn torque_free(turn: [f64; 4], h: f64, t_end: f64, control: Control) -> [f64; 3] {
    let Built { model, q0, v0, .. } = free_body(turn).build().unwrap();
    let mut sim = Simulation::new(&model, Settings::new(Scheme::RungeKutta4, h, control), &q0, &v0).unwrap();
    let t0 = 0.5 * (0..3).map(|i| J[i] * W0[i] * W0[i]).sum::<f64>();
    let mut worst = [0.0_f64; 3];
    let b = SpatialBody::of(0);
    sim.run::<Error>(t_end, (0.01 / h).round() as u64, |s| {
        let (p, pd) = (b.orientation(s.q()), b.orientation(s.v()));
        // Body rate in principal axes: ω_principal = Qᵀ ω′.
        let w = rotate([turn[0], -turn[1], -turn[2], -turn[3]], body_rate(p, pd));
        let exact = euler_exact(s.t());
        let energy = 0.5 * (0..3).map(|i| J[i] * w[i] * w[i]).sum::<f64>();
        let errors = [
            (0..3).map(|i| (w[i] - exact[i]).abs()).fold(0.0, f64::max),
            (p.iter().map(|x| x * x).sum::<f64>().sqrt() - 1.0).abs(),
            (energy - t0).abs(),
        ];
        worst = std::array::from_fn(|i| worst[i].max(errors[i]));
        Ok(())
    })
    .unwrap();
    worst
}

#[test]
fn a_free_body_with_a_full_inertia_tensor_follows_eulers_solution() {
    let turn = compose(about([0.0, 0.0, 1.0], 0.4), about(unit([1.0, 1.0, 0.0]), 0.9));
    let errors: Vec<[f64; 3]> = [0.02, 0.01].iter().map(|&h| torque_free(turn, h, 10.0, Control::none())).collect();
    println!("RK-4, none, 10 s: h = 0.02 {:?}; h = 0.01 {:?}", errors[0], errors[1]);
    let order = (errors[0][0] / errors[1][0]).log2();
    assert!((order - 4.0).abs() < 0.25, "observed order {order:.2}: {errors:?}");
    assert!(errors[1][0] < 3e-8, "{errors:?}");
    // The controls hold |p| = 1 and the energy to round-off without
    // making the angular velocity worse.
    let robust = torque_free(turn, 0.02, 10.0, methods::robust());
    println!("RK-4, robust, h = 0.02: {robust:?}");
    assert!(robust[1] < 1e-12 && robust[2] < 1e-12, "{robust:?}");
    assert!(robust[0] <= errors[0][0] * 1.01, "robust {robust:?} vs none {:?}", errors[0]);
}

/// The heavy top of Brüls & Cardona's Lie-group benchmark: 15 kg, inertia
/// diag(0.234375, 0.46875, 0.234375) kg m² at the centre of mass, which is
/// 1 m from the fixed point along the body y axis; gravity 9.81 along −z;
/// body angular velocity (0, 150, −4.61538) rad/s; p₀ = (1, 0, 0, 0).
fn heavy_top() -> Mechanism {
    let w0 = [0.0, 150.0, -4.61538];
    let top = Body::new("top", 15.0, [0.234375, 0.46875, 0.234375])
        .with_position([0.0, 1.0, 0.0])
        .with_velocity(cross(w0, [0.0, 1.0, 0.0]))
        .with_angular_velocity(w0);
    let fixed = Joint::new(JointKind::Spherical, 0, None, [0.0; 3]);
    Mechanism::new([0.0, 0.0, -9.81]).with_bodies(vec![top]).with_joints(vec![fixed])
}

fn heavy_top_at(t_end: f64, h: f64, control: Control, solver: LinearSolver) -> (Vec<f64>, Vec<f64>) {
    let settings = Settings::new(Scheme::RungeKutta4, h, control).with_solver(solver);
    end_state(&heavy_top().build().unwrap(), settings, t_end)
}

/// `(q, v)` at `t_end` of a run from the built initial state.
fn end_state(built: &Built, settings: Settings, t_end: f64) -> (Vec<f64>, Vec<f64>) {
    let Built { model, q0, v0, .. } = built;
    let mut sim = Simulation::new(model, settings, q0, v0).unwrap();
    sim.run::<Error>(t_end, u64::MAX, |_| Ok(())).unwrap();
    (sim.q().to_vec(), sim.v().to_vec())
}

#[test]
fn the_heavy_top_agrees_with_the_published_values_at_0_2_s() {
    // Published (Exudyn's heavy-top test, MATLAB RK-4 at h = 1e-4): Euler
    // parameters (−0.70828, 0.43878, 0.54573, 0.0894) and body angular
    // velocity (−2.6916, 150, 4.9173) at t = 0.2 s.
    let p_ref = [-0.70828, 0.43878, 0.54573, 0.0894];
    let decimals = [5, 5, 5, 4];
    let w_ref = [-2.6916, 150.0, 4.9173];
    for control in [Control::none(), methods::robust()] {
        let (q, v) = heavy_top_at(0.2, 1e-4, control, LinearSolver::Auto);
        let p = SpatialBody::of(0).orientation(&q);
        let w = body_rate(p, SpatialBody::of(0).orientation(&v));
        println!(
            "heavy top at 0.2 s: p = {p:?}, ω′ = {w:?}, spatial ω = {:?}",
            space_rate(p, SpatialBody::of(0).orientation(&v))
        );
        for i in 0..4 {
            // Agreement to the digits published: within half a unit of the last one.
            let half = 0.5 * 10f64.powi(-decimals[i]);
            assert!((p[i] - p_ref[i]).abs() <= half, "p[{i}] = {} vs published {}", p[i], p_ref[i]);
        }
        for i in 0..3 {
            assert!((w[i] - w_ref[i]).abs() <= 0.5e-4, "ω′[{i}] = {} vs published {}", w[i], w_ref[i]);
        }
    }
}

#[test]
fn the_heavy_top_agrees_with_kynemas_regression_values_at_2_s() {
    // Kynema's heavy-top regression test (tests/regression_tests/regression/
    // verification/dynamic_heavy_top.cpp), attributed there to the
    // Brüls–Cardona–Arnold Lie-group integrator at dt = 2e-6: Euler
    // parameters and centre of mass at t = 2 s, to 15 digits.
    let p_ref = [0.122947275600560, -0.491079359219981, 0.350430794926147, -0.787986857972906];
    let r_ref = [-0.150416985652933, -0.724164450779749, -0.673023460701136];
    let state = |h: f64| {
        let (q, _) = heavy_top_at(2.0, h, methods::robust(), LinearSolver::Auto);
        let (p, r) = (SpatialBody::of(0).orientation(&q), SpatialBody::of(0).position(&q));
        [p[0], p[1], p[2], p[3], r[0], r[1], r[2]]
    };
    let reference = [p_ref[0], p_ref[1], p_ref[2], p_ref[3], r_ref[0], r_ref[1], r_ref[2]];
    let gap = |a: &[f64; 7], b: &[f64; 7]| (0..7).map(|i| (a[i] - b[i]).abs()).fold(0.0, f64::max);
    let (coarse, fine) = (state(5e-5), state(2.5e-5));
    println!(
        "heavy top at 2 s: {fine:?}; gap to Kynema's {:.2e} at h = 5e-5, {:.2e} at 2.5e-5; h against h/2 {:.2e}",
        gap(&coarse, &reference),
        gap(&fine, &reference),
        gap(&coarse, &fine)
    );
    // cdyn is converged (1.8e-10 between h and h/2) and 1.19e-6 from the
    // reference at either step: the gap is the reference's own error (a
    // second-order scheme at dt = 2e-6), so its 15 printed digits hold to
    // about six.
    assert!(gap(&coarse, &fine) < 1e-9, "not converged");
    assert!(gap(&fine, &reference) < 2e-6, "{:e} from Kynema's values", gap(&fine, &reference));
    assert!((gap(&coarse, &reference) - gap(&fine, &reference)).abs() < 1e-8, "the gap moves with cdyn's step");
}

#[test]
fn block_diagonal_and_dense_mass_paths_agree() {
    // The spatial chain of four rods (28 coordinates): blocks by default, or dense on request.
    let Built { model, q0, v0, .. } = cdyn::spatial::chain(4, 0.3, 9.81).build().unwrap();
    assert_eq!(model.mass_blocks().map(<[_]>::len), Some(4));
    let run = |solver| {
        let settings = Settings::new(Scheme::RungeKutta4, 1e-3, methods::robust()).with_solver(solver);
        let mut sim = Simulation::new(&model, settings, &q0, &v0).unwrap();
        sim.run::<Error>(1.0, u64::MAX, |_| Ok(())).unwrap();
        sim.q().to_vec()
    };
    let (blocks, dense, sparse) = (run(LinearSolver::Auto), run(LinearSolver::Dense), run(LinearSolver::Sparse));
    let gap = |a: &[f64], b: &[f64]| a.iter().zip(b).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max);
    assert!(gap(&blocks, &dense) < 1e-12, "block path and dense path differ by {:e}", gap(&blocks, &dense));
    // Sparse: the block path with S factored sparse (Auto factors these 16 rows densely).
    assert!(gap(&blocks, &sparse) < 1e-12, "S dense and sparse differ by {:e}", gap(&blocks, &sparse));
    // The motion is not trivial: the chain swings.
    assert!(gap(&blocks, &q0) > 0.1);
}

/// A symmetric top (about its body z axis) on a fixed point, in steady
/// precession: tilt θ, spin ω₃ about its axis, and the slow root Ω of
/// `m g l = Ω (C ω₃ − A Ω cos θ)`, `A` its transverse moment about the
/// fixed point. Returns the largest error of the axis's tilt and of its
/// azimuth against `Ω t` over `t_end`, and Ω.
fn steady_precession(h: f64, t_end: f64, control: Control) -> (f64, f64, f64) {
    let (mechanism, theta, omega) = precessing_top();
    let Built { model, q0, v0, .. } = mechanism.build().unwrap();
    let mut sim = Simulation::new(&model, Settings::new(Scheme::RungeKutta4, h, control), &q0, &v0).unwrap();
    let (mut tilt, mut azimuth) = (0.0_f64, 0.0_f64);
    sim.run::<Error>(t_end, (0.01 / h).round() as u64, |s| {
        let k = rotate(SpatialBody::of(0).orientation(s.q()), [0.0, 0.0, 1.0]);
        tilt = tilt.max((k[2].acos() - theta).abs());
        let turned = k[1].atan2(k[0]) - omega * s.t();
        azimuth = azimuth
            .max(((turned + std::f64::consts::PI).rem_euclid(std::f64::consts::TAU) - std::f64::consts::PI).abs());
        Ok(())
    })
    .unwrap();
    (tilt, azimuth, omega)
}

/// The top of [`steady_precession`], its tilt θ and precession rate Ω.
fn precessing_top() -> (Mechanism, f64, f64) {
    let (m, l, g, ac, c, theta, w3): (f64, f64, f64, f64, f64, f64, f64) = (1.0, 0.5, 9.81, 0.01, 0.018, 0.5, 200.0);
    let a = ac + m * l * l;
    let omega = (c * w3 - ((c * w3).powi(2) - 4.0 * a * theta.cos() * m * g * l).sqrt()) / (2.0 * a * theta.cos());
    let axis = [theta.sin(), 0.0, theta.cos()];
    let p0 = about([0.0, 1.0, 0.0], theta);
    let spin = w3 - omega * theta.cos();
    let w: [f64; 3] = std::array::from_fn(|i| omega * (i == 2) as u8 as f64 + spin * axis[i]);
    let top = Body::new("top", m, [ac, ac, c])
        .with_position(axis.map(|x| x * l))
        .with_orientation(p0)
        .with_velocity(cross(w, axis.map(|x| x * l)))
        .with_angular_velocity(rotate([p0[0], -p0[1], -p0[2], -p0[3]], w));
    let fixed = Joint::new(JointKind::Spherical, 0, None, [0.0; 3]);
    let mechanism = Mechanism::new([0.0, 0.0, -g]).with_bodies(vec![top]).with_joints(vec![fixed]);
    (mechanism, theta, omega)
}

#[test]
fn a_symmetric_top_precesses_steadily_at_the_closed_form_rate() {
    let coarse = steady_precession(2e-4, 2.0, Control::none());
    let fine = steady_precession(1e-4, 2.0, Control::none());
    let robust = steady_precession(2e-4, 2.0, methods::robust());
    println!(
        "Ω = {:.6} rad/s; tilt and azimuth errors over 2 s: h = 2e-4 {:.2e} {:.2e}, h = 1e-4 {:.2e} {:.2e}, robust h = 2e-4 {:.2e} {:.2e}",
        coarse.2, coarse.0, coarse.1, fine.0, fine.1, robust.0, robust.1
    );
    // The precession turns Ω · 2 s ≈ 3 rad; the axis stays on its cone and
    // on schedule to the integrator's error, which falls at order four.
    assert!(fine.0 < 1e-7 && fine.1 < 1e-7, "{fine:?}");
    assert!(coarse.1 / fine.1 > 12.0, "no fourth-order convergence: {coarse:?} → {fine:?}");
    assert!(
        robust.0 <= coarse.0 * 1.01 + 1e-12 && robust.1 <= coarse.1 * 1.01 + 1e-12,
        "robust {robust:?} vs none {coarse:?}"
    );
}

/// The normalization `pᵀp = 1` held by each method of `cdyn compare`, on
/// the heavy top at a step where the uncontrolled drift shows: `||p| − 1|`
/// and the error of `p` at 0.2 s against a run at a twentieth of the step.
#[test]
fn every_method_holds_the_heavy_tops_normalization_and_robust_is_no_worse() {
    let (reference, _) = heavy_top_at(0.2, 2.5e-5, Control::none(), LinearSolver::Auto);
    let p_ref = SpatialBody::of(0).orientation(&reference);
    let run = |scheme: Scheme, h: f64, control: Control| {
        let Built { model, q0, v0, .. } = heavy_top().build().unwrap();
        let mut sim = Simulation::new(&model, Settings::new(scheme, h, control), &q0, &v0).unwrap();
        let mut drift = 0.0_f64;
        sim.run::<Error>(0.2, 10, |s| {
            let p = SpatialBody::of(0).orientation(s.q());
            drift = drift.max((p.iter().map(|x| x * x).sum::<f64>().sqrt() - 1.0).abs());
            Ok(())
        })
        .unwrap();
        let p = SpatialBody::of(0).orientation(sim.q());
        (drift, (0..4).map(|i| (p[i] - p_ref[i]).abs()).fold(0.0, f64::max))
    };
    for (scheme, h) in [(Scheme::AdamsBashforth3, 1e-4), (Scheme::RungeKutta4, 5e-4)] {
        let none = run(scheme, h, Control::none());
        for (name, control) in
            cdyn::control::methods::compare_cases(&cdyn::control::methods::MethodGains::paper(), true)
        {
            let (drift, error) = run(scheme, h, control);
            println!("{scheme:?} h = {h}: {name:>22}  max||p| − 1| {drift:.2e}  |p − p_ref| at 0.2 s {error:.2e}");
            if name == "robust" || name == "projection" {
                assert!(drift < 1e-10, "{name}: ||p| − 1| = {drift:e}");
                assert!(error <= none.1 * 1.01, "{name}: error {error:e} worse than none's {:e}", none.1);
            }
        }
    }
}

/// Every refused input is one error naming the part and the reason.
#[test]
fn bad_bodies_and_joints_are_refused_with_the_part_and_the_reason() {
    let body = |f: fn(&mut Body)| {
        let mut b = Body::new("arm", 1.0, [1.0, 1.0, 1.0]);
        f(&mut b);
        let joint = Joint::new(JointKind::Spherical, 0, None, [0.0; 3]);
        Mechanism::new([0.0; 3]).with_bodies(vec![b]).with_joints(vec![joint]).build().err().map(|e| e.to_string())
    };
    type Change = fn(&mut Body);
    let cases: [(Change, &str); 7] = [
        (|b| b.orientation = [0.0; 4], "body 0 (arm): orientation has length 0"),
        (|b| b.orientation = [0.9, 0.1, 0.0, 0.0], "unit quaternion"),
        (|b| b.orientation[1] = f64::NAN, "orientation has length NaN"),
        (|b| b.inertia[2][2] = -1.0, "body 0 (arm): inertia must be positive definite"),
        (|b| b.inertia = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 3.0]], "not physical"),
        (|b| b.inertia[0][1] = 0.5, "symmetric"),
        (|b| b.mass = 0.0, "body 0 (arm): mass = 0"),
    ];
    for (change, expected) in cases {
        let message = body(change).expect("refused");
        assert!(message.contains(expected), "{message:?} should contain {expected:?}");
    }
    // A unit quaternion typed to 7 digits is normalized, not refused.
    assert_eq!(body(|b| b.orientation = [0.6, 0.8000001, 0.0, 0.0]), None);

    let two = |joint: Joint<String>| {
        let bodies = vec![Body::new("a", 1.0, [1.0; 3]), Body::new("b", 1.0, [1.0; 3])];
        Mechanism::named(bodies, vec![joint], vec![], [0.0; 3]).and_then(|m| m.build()).err().map(|e| e.to_string())
    };
    let named = |j: Joint, a: &str, b: &str| j.map_bodies(|i| [a, b][i].to_string());
    let joint = |kind| named(Joint::new(kind, 0, Some(1), [0.0; 3]), "a", "b");
    let spherical = |a, b| named(Joint::new(JointKind::Spherical, 0, Some(1), [0.0; 3]), a, b);
    let cases = [
        (joint(JointKind::Spherical).with_angle(TimeFn::linear(0.0, 1.0)), "a spherical joint takes no angle"),
        (joint(JointKind::Revolute).with_axis([0.0; 3]), "element 0 (revolute): axis has zero length"),
        (joint(JointKind::Revolute), "element 0 (revolute): a revolute joint needs axis"),
        (joint(JointKind::Spherical).with_axis([1.0, 0.0, 0.0]), "a spherical joint takes no axis"),
        (joint(JointKind::Universal).with_axis([1.0, 0.0, 0.0]).with_axis_b([1.0, 1.0, 0.0]), "perpendicular"),
        (joint(JointKind::Distance).with_point_b([0.0; 3]), "point_b must differ from point"),
        (spherical("c", "b"), "a = \"c\": no body of that name"),
        (spherical("a", "a"), "connects a to itself"),
        (
            named(Joint::new(JointKind::Spherical, 0, Some(1), [f64::INFINITY, 0.0, 0.0]), "a", "b"),
            "point = inf must be finite",
        ),
    ];
    for (j, expected) in cases {
        let message = two(j).expect("refused");
        assert!(message.contains(expected), "{message:?} should contain {expected:?}");
    }
    // The ground is `b` omitted or named; duplicate and reserved body names are refused.
    assert_eq!(two(spherical("a", "ground")), None);
    let dup =
        Mechanism::named(vec![Body::new("a", 1.0, [1.0; 3]), Body::new("a", 1.0, [1.0; 3])], vec![], vec![], [0.0; 3]);
    assert!(dup.unwrap_err().to_string().contains("body 1 (a): a body with this name already exists"));
}

/// The IFToMM spatial rigid slider-crank (R. Masoudi): crank AB (0.08 m,
/// 0.12 kg, inertia 1e-4 about its axis x) on a revolute joint at
/// A = (0, 0.1, 0.12), a spherical joint at B, rod BC (0.3 m, 0.5 kg,
/// inertia 4e-4 about its axis and 4e-3 across), a universal joint at C
/// (slider axis x, rod axis across the rod and x), and a 2 kg slider on
/// the x axis; gravity −z; the crank starts upright at 6 rad/s. The
/// crank's centre of mass is on its axis (`on_axis`, as in MBDyn's
/// submission) or mid-crank (as in Exudyn's model). Returns, at each of
/// `times`, the slider's x and the crank's unwrapped angle.
fn spatial_slider_crank(on_axis: bool, h: f64, times: &[f64]) -> Vec<(f64, f64)> {
    let w = 6.0;
    let crank_centre = if on_axis { [0.0, 0.1, 0.12] } else { [0.0, 0.1, 0.16] };
    let crank = Body::new("crank", 0.12, [1e-4, 1e-4, 1e-5])
        .with_position(crank_centre)
        .with_velocity(cross([w, 0.0, 0.0], [0.0, 0.0, crank_centre[2] - 0.12]))
        .with_angular_velocity([w, 0.0, 0.0]);
    let u = [0.2 / 0.3, -0.1 / 0.3, -0.2 / 0.3];
    let rod_inertia = std::array::from_fn(|a| {
        std::array::from_fn(|b| 0.004 * ((a == b) as u8 as f64) + (0.0004 - 0.004) * u[a] * u[b])
    });
    let rod = Body::new("rod", 0.5, [1.0; 3])
        .with_inertia(rod_inertia)
        .with_position([0.1, 0.05, 0.1])
        .with_velocity([0.12, -0.24, 0.0])
        .with_angular_velocity([1.92, -0.96, 0.48]);
    let slider = Body::new("slider", 2.0, [1e-4; 3]).with_position([0.2, 0.0, 0.0]).with_velocity([0.24, 0.0, 0.0]);
    let joints = vec![
        Joint::new(JointKind::Revolute, 0, None, [0.0, 0.1, 0.12]).with_axis([1.0, 0.0, 0.0]),
        Joint::new(JointKind::Spherical, 0, Some(1), [0.0, 0.1, 0.2]),
        Joint::new(JointKind::Universal, 2, Some(1), [0.2, 0.0, 0.0])
            .with_axis([1.0, 0.0, 0.0])
            .with_axis_b(unit([0.0, -2.0, 1.0])),
        Joint::new(JointKind::Prismatic, 2, None, [0.2, 0.0, 0.0]).with_axis([1.0, 0.0, 0.0]),
    ];
    let mechanism = Mechanism::new([0.0, 0.0, -9.81]).with_bodies(vec![crank, rod, slider]).with_joints(joints);
    let Built { model, q0, v0, .. } = mechanism.build().unwrap();
    let mut sim = Simulation::new(&model, Settings::new(Scheme::RungeKutta4, h, methods::robust()), &q0, &v0).unwrap();
    let (mut angle, mut last) = (0.0_f64, 0.0_f64);
    let mut out = Vec::new();
    let mut next = times.iter().peekable();
    sim.run::<Error>(*times.last().unwrap(), 1, |s| {
        let p = SpatialBody::of(0).orientation(s.q());
        let now = 2.0 * p[1].atan2(p[0]);
        let turn = now - last;
        angle += turn - std::f64::consts::TAU * (turn / std::f64::consts::TAU).round();
        last = now;
        if next.peek().is_some_and(|&&t| (s.t() - t).abs() < 0.5 * h) {
            next.next();
            out.push((SpatialBody::of(2).position(s.q())[0], angle));
        }
        Ok(())
    })
    .unwrap();
    out
}

#[test]
fn the_iftomm_spatial_slider_crank_against_the_published_solutions() {
    let times = [0.5, 1.0, 2.0, 3.0, 4.0, 5.0];
    // Slider x of F. González's submission (Δt = 0.01; Exudyn's copy of
    // the IFToMM files), and MBDyn's (P. Masarati, a dissipative multistep
    // method, ρ∞ = 0.6, Δt = 4 ms) x and crank angle.
    let gonzalez = [0.184952803, 0.211754668, 0.289063554, 0.228450093, 0.188208161, 0.240761815];
    let mbdyn = [
        (0.1849586, 5.574337),
        (0.2124956, 10.89762117),
        (0.2880209, 20.98050345),
        (0.2259940, 31.96080157),
        (0.1860648, 43.46958242),
        (0.2517906, 54.11434361),
    ];
    let mid = spatial_slider_crank(false, 1e-4, &times);
    let mid_coarse = spatial_slider_crank(false, 2e-4, &times);
    let on_axis = spatial_slider_crank(true, 1e-4, &times);
    let mut worst = 0.0_f64;
    for (i, t) in times.iter().enumerate() {
        let ((x, angle), (xc, ac), (xa, aa)) = (mid[i], mid_coarse[i], on_axis[i]);
        println!(
            "t = {t}: mid-crank x = {x:.7} θ = {angle:.6} (h vs 2h {:.1e}, {:.1e}); on the axis x = {xa:.7} θ = {aa:.6}; González x = {}, MBDyn x = {} θ = {}",
            (x - xc).abs(),
            (angle - ac).abs(),
            gonzalez[i],
            mbdyn[i].0,
            mbdyn[i].1
        );
        // Converged: the step's error is far below the gaps to the submissions.
        assert!((x - xc).abs() < 1e-9 && (angle - ac).abs() < 1e-8, "t = {t}: not converged");
        worst = worst.max((x - gonzalez[i]).abs());
    }
    // With the crank's centre of mass mid-crank, cdyn follows González's
    // slider to 4.2e-5 m over 5 s (the test allows 1e-4 m, 0.05 % of the
    // stroke, since the submissions carry their own integration error);
    // with it on the axis the motion is another one (0.014 m off at 5 s).
    assert!(worst < 1e-4, "mid-crank: {worst:e} from González's solution");
    assert!((on_axis[5].0 - gonzalez[5]).abs() > 1e-3);
}

/// Largest `|Ψ|` (the energy balance: `T + V − E₀ − ∫Ė`) and the final
/// state of a run without control, RK-4.
fn uncontrolled(mechanism: &Mechanism, h: f64, t_end: f64) -> (f64, Vec<f64>, Vec<f64>) {
    let Built { model, q0, v0, .. } = mechanism.build().unwrap();
    let mut sim = Simulation::new(&model, Settings::new(Scheme::RungeKutta4, h, Control::none()), &q0, &v0).unwrap();
    let mut psi = 0.0_f64;
    sim.run::<Error>(t_end, 1, |s| {
        psi = psi.max(s.measure().psi.abs());
        Ok(())
    })
    .unwrap();
    (psi, sim.q().to_vec(), sim.v().to_vec())
}

#[test]
fn springs_dampers_forces_torques_and_drives_against_closed_forms() {
    use cdyn::spatial::Load;
    let (m, k, c) = (2.0, 50.0, 1.5);
    // A body hanging on a damped spring from the origin, stretched 0.1
    // beyond its length 0.9, no gravity: z(t) = −0.9 − 0.1 e^{−ζωt}(cos ω_d t + ζω/ω_d sin ω_d t).
    let bob = Body::new("bob", m, [0.1, 0.1, 0.1]).with_position([0.0, 0.0, -1.0]);
    let spring = Load::Spring {
        a: 0,
        b: None,
        point: [0.0, 0.0, -1.0],
        point_b: [0.0; 3],
        stiffness: k,
        damping: c,
        length: Some(0.9),
    };
    let hanging = Mechanism::new([0.0; 3]).with_bodies(vec![bob]).with_loads(vec![spring]);
    let (psi, q, _) = uncontrolled(&hanging, 1e-3, 2.0);
    let (w, zeta) = ((k / m).sqrt(), c / (2.0 * (k * m).sqrt()));
    let wd = w * (1.0 - zeta * zeta).sqrt();
    let exact = -0.9 - 0.1 * (-zeta * w * 2.0).exp() * ((wd * 2.0).cos() + zeta * w / wd * (wd * 2.0).sin());
    println!("damped spring: z(2) = {} vs {exact}, max |Ψ| {psi:.1e}", q[2]);
    assert!((q[2] - exact).abs() < 1e-9, "z(2) = {} vs {exact}", q[2]);
    // The damper's power is in the energy balance: Ψ stays at the integrator's error.
    assert!(psi < 1e-9, "|Ψ| = {psi:e}");

    // A free body under a constant torque about its second principal axis,
    // from rest: ω = n t / J₂; and a force at an offset point: the centre
    // accelerates as F/m and the body turns under (s × F) / J.
    let torqued = Body::new("wheel", 3.0, [0.5, 0.8, 1.1]);
    let loads = vec![
        Load::Torque { body: 0, torque: [0.0, 0.4, 0.0] },
        Load::Force { body: 0, force: [0.0, 0.0, 0.6], point: Some([0.0, 0.0, 0.0]) },
    ];
    let free = Mechanism::new([0.0; 3]).with_bodies(vec![torqued]).with_loads(loads);
    let (psi, q, v) = uncontrolled(&free, 1e-3, 1.0);
    let w = body_rate(SpatialBody::of(0).orientation(&q), SpatialBody::of(0).orientation(&v));
    println!("torque: ω(1) = {w:?}, v_z = {}, max |Ψ| {psi:.1e}", v[2]);
    assert!((w[1] - 0.4 / 0.8).abs() < 1e-12 && w[0].abs() < 1e-12 && w[2].abs() < 1e-12, "{w:?}");
    assert!((v[2] - 0.6 / 3.0).abs() < 1e-12 && (q[2] - 0.5 * 0.6 / 3.0).abs() < 1e-12, "{v:?}");
    assert!(psi < 1e-12, "|Ψ| = {psi:e}");

    // A wheel spinning on a damped revolute axle: ω = ω₀ e^{−c t / J}.
    let spinning = Body::new("wheel", 1.0, [0.3, 0.3, 0.5]).with_angular_velocity([0.0, 0.0, 5.0]);
    let axle = Joint::new(JointKind::Revolute, 0, None, [0.0; 3]).with_axis([0.0, 0.0, 1.0]);
    let damper = Load::RotaryDamper { a: 0, b: None, axis: [0.0, 0.0, 1.0], damping: 0.2 };
    let wheel = Mechanism::new([0.0; 3]).with_bodies(vec![spinning]).with_joints(vec![axle]).with_loads(vec![damper]);
    let (psi, q, v) = uncontrolled(&wheel, 1e-3, 2.0);
    let w = space_rate(SpatialBody::of(0).orientation(&q), SpatialBody::of(0).orientation(&v));
    let exact = 5.0 * (-0.2 * 2.0 / 0.5_f64).exp();
    println!("rotary damper: ω(2) = {} vs {exact}, max |Ψ| {psi:.1e}", w[2]);
    assert!((w[2] - exact).abs() < 1e-10 && psi < 1e-10, "ω = {w:?} vs {exact}, |Ψ| {psi:e}");

    // A crank driven at θ = 3t + 0.2 sin 5t about a revolute joint, under
    // gravity: its angle follows the drive, and the drive's work (λᵀΦ_t)
    // is in the energy balance.
    // Started at the drive's rate θ̇(0) = 4 (v = ω × r).
    let crank = Body::new("crank", 1.0, [0.01, 0.1, 0.1])
        .with_position([0.5, 0.0, 0.0])
        .with_velocity([0.0, 0.0, -2.0])
        .with_angular_velocity([0.0, 4.0, 0.0]);
    let drive = TimeFn::polynomial(vec![0.0, 3.0]).with_sines(vec![[0.2, 5.0, 0.0]]);
    let pivot = Joint::new(JointKind::Revolute, 0, None, [0.0; 3]).with_axis([0.0, 1.0, 0.0]).with_angle(drive.clone());
    let driven = Mechanism::new([0.0, 0.0, -9.81]).with_bodies(vec![crank]).with_joints(vec![pivot]);
    let (psi, q, _) = uncontrolled(&driven, 1e-3, 1.0);
    let p = SpatialBody::of(0).orientation(&q);
    // Turned about +y by θ: p = (cos θ/2, 0, sin θ/2, 0); compare the crank's direction.
    let x = rotate(p, [1.0, 0.0, 0.0]);
    let theta: f64 = drive.eval(1.0);
    println!("driven crank: direction {x:?} vs angle {theta}, max |Ψ| {psi:.1e}");
    assert!((x[0] - theta.cos()).abs() < 1e-10 && (x[2] + theta.sin()).abs() < 1e-10, "{x:?} vs {theta}");
    assert!(psi < 1e-8, "|Ψ| = {psi:e}");
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    /// A body's rotational energy differentiated as a velocity map, as a
    /// plain kinetic energy by hyper-dual numbers, and in the closed forms
    /// spatial bodies use give the same `M`, `Ṁ ẋ`, `∂T/∂x` and `T`, also
    /// off the normalization.
    #[test]
    fn the_velocity_map_and_the_kinetic_energy_agree(
        p in prop::array::uniform4(-1.2..1.2f64),
        pd in prop::array::uniform4(-3.0..3.0f64),
        j in prop::array::uniform3(0.5..2.0f64),
        off in -0.3..0.3f64,
    ) {
        let inertia = [[j[0] + j[1], off, 0.1], [off, j[1] + j[2], -0.2], [0.1, -0.2, j[0] + j[2]]];
        let body = cdyn::spatial::Rotation::new(inertia);
        let (a, b) = (cdyn::model::kinetic::local(&body, p, pd), cdyn::model::kinetic::local_map(&body, p, pd));
        let closed = cdyn::model::kinetic::VelocityMap::derivatives(&body, p, pd);
        let scale = 1.0 + a.energy.abs();
        for other in [b, closed] {
            prop_assert!((a.energy - other.energy).abs() < 1e-13 * scale);
            for r in 0..4 {
                prop_assert!((a.grad_q[r] - other.grad_q[r]).abs() < 1e-12 * scale, "∂T/∂x {:?} vs {:?}", a.grad_q, other.grad_q);
                prop_assert!((a.mdot_v[r] - other.mdot_v[r]).abs() < 1e-12 * scale, "Ṁẋ {:?} vs {:?}", a.mdot_v, other.mdot_v);
                for c in 0..4 {
                    prop_assert!((a.mass[r][c] - other.mass[r][c]).abs() < 1e-13 * scale, "M {:?} vs {:?}", a.mass, other.mass);
                }
            }
        }
    }
}

/// The IFToMM stiff flyball governor (benchmark A05, M. González): a shaft
/// (1 m × 0.01 m × 0.01 m, 3000 kg/m³: 0.3 kg) on a revolute joint about
/// the vertical z axis at its foot; two rods of the same size on revolute
/// joints at A, B = (±0.05, 0, 1), each with a 5 kg point mass at its tip;
/// a 0.1 m cube slider (3 kg) on a prismatic joint along the shaft,
/// centred at height `s`; from each rod's midpoint to the slider's side
/// (±0.05, 0, s) a spring-damper, `k` = 8e5 N/m, `c` = 4e4 N s/m, rest
/// length 0.5 m, in place of the coupler rods. Gravity −z. The rods
/// point outwards `beta` below the horizontal, and everything turns at
/// `omega` about z. At the benchmark's start (β = 30°, s = 0.5 m) the
/// springs are at rest.
mod flyball {
    use super::*;
    use cdyn::Scalar;
    use cdyn::spatial::Load;
    use nalgebra::SVector;

    pub const K: f64 = 8e5;
    pub const C: f64 = 4e4;
    const G: f64 = 9.81;
    /// Rod, its tip mass, slider, shaft.
    const M_ROD: f64 = 0.3;
    const M_TIP: f64 = 5.0;
    const M_SLIDER: f64 = 3.0;
    /// The pivots' offset from the axis.
    const A: f64 = 0.05;
    /// A 1 m × 0.01 m × 0.01 m bar of 0.3 kg: about its axis, and across.
    const J_AXIAL: f64 = M_ROD * 2e-4 / 12.0;
    const J_ACROSS: f64 = M_ROD * (1.0 + 1e-4) / 12.0;
    const J_SLIDER: f64 = M_SLIDER * 0.02 / 12.0;

    /// Body indices.
    pub const SHAFT: usize = 0;
    pub const SLIDER: usize = 1;
    pub const RODS: [usize; 2] = [2, 3];

    /// A rod (0.3 kg) with a 5 kg mass at its tip: its centre of mass and
    /// inertia there, in space axes, for the rod along `d` from `pivot`.
    fn rod(name: &str, pivot: [f64; 3], d: [f64; 3], omega: f64) -> Body {
        let mass = M_ROD + M_TIP;
        let centre: [f64; 3] = std::array::from_fn(|i| pivot[i] + d[i] * (0.5 * M_ROD + M_TIP) / mass);
        let offset = |at: f64| -> [f64; 3] { std::array::from_fn(|i| pivot[i] + at * d[i] - centre[i]) };
        let (r, p) = (offset(0.5), offset(1.0));
        let point = |m: f64, x: [f64; 3], a: usize, b: usize| {
            m * ((a == b) as u8 as f64 * x.iter().map(|c| c * c).sum::<f64>() - x[a] * x[b])
        };
        let inertia = std::array::from_fn(|a| {
            std::array::from_fn(|b| {
                let bar = J_AXIAL * d[a] * d[b] + J_ACROSS * ((a == b) as u8 as f64 - d[a] * d[b]);
                bar + point(M_ROD, r, a, b) + point(M_TIP, p, a, b)
            })
        });
        spinning(Body::new(name, mass, [1.0; 3]).with_inertia(inertia).with_position(centre), omega)
    }

    /// `body`, turning at `omega` about the z axis (body axes = space axes).
    fn spinning(body: Body, omega: f64) -> Body {
        let w = [0.0, 0.0, omega];
        let position = body.position;
        body.with_velocity(cross(w, position)).with_angular_velocity(w)
    }

    pub fn mechanism(beta: f64, s: f64, omega: f64) -> Mechanism {
        let shaft = Body::new("shaft", 0.3, [J_ACROSS, J_ACROSS, J_AXIAL]).with_position([0.0, 0.0, 0.5]);
        let slider = Body::new("slider", M_SLIDER, [J_SLIDER; 3]).with_position([0.0, 0.0, s]);
        let mut bodies = vec![spinning(shaft, omega), spinning(slider, omega)];
        let mut joints = vec![
            Joint::new(JointKind::Revolute, SHAFT, None, [0.0; 3]).with_axis([0.0, 0.0, 1.0]),
            Joint::new(JointKind::Prismatic, SLIDER, Some(SHAFT), [0.0, 0.0, s]).with_axis([0.0, 0.0, 1.0]),
        ];
        let mut loads = Vec::new();
        for (side, index) in [1.0, -1.0].into_iter().zip(RODS) {
            let pivot = [side * A, 0.0, 1.0];
            let d = [side * beta.cos(), 0.0, -beta.sin()];
            bodies.push(rod(if side > 0.0 { "rod_a" } else { "rod_b" }, pivot, d, omega));
            joints.push(Joint::new(JointKind::Revolute, index, Some(SHAFT), pivot).with_axis([0.0, 1.0, 0.0]));
            loads.push(Load::Spring {
                a: index,
                b: Some(SLIDER),
                point: std::array::from_fn(|i| pivot[i] + 0.5 * d[i]),
                point_b: [side * A, 0.0, s],
                stiffness: K,
                damping: C,
                length: Some(0.5),
            });
        }
        Mechanism::new([0.0, 0.0, -G]).with_bodies(bodies).with_joints(joints).with_loads(loads)
    }

    /// The potential in the frame turning at `omega`, `V − ½Ω² I_z`, of
    /// the symmetric pose (β, s), in those two coordinates alone: gravity,
    /// both springs, and the moment of inertia about the axis.
    fn amended<D: Scalar>(beta: D, s: D, omega: f64) -> D {
        let (sin, cos) = (beta.sin(), beta.cos());
        let length = ((cos * 0.5).powi(2) + (-sin * 0.5 - s + 1.0).powi(2)).sqrt();
        let gravity = ((-sin * 0.5 + 1.0) * M_ROD + (-sin + 1.0) * M_TIP) * (2.0 * G) + s * (M_SLIDER * G);
        let springs = (length - 0.5).powi(2) * K;
        let rod_about_axis =
            sin * sin * J_AXIAL + cos * cos * J_ACROSS + (cos * 0.5 + A).powi(2) * M_ROD + (cos + A).powi(2) * M_TIP;
        gravity + springs - rod_about_axis * omega * omega
    }

    /// The steady state turning at `omega`: the minimum of [`amended`],
    /// by Newton with its exact Hessian from β = 20° on the pose where the
    /// springs are at rest (s = 1 − sin β; at Ω = 2π the potential along
    /// those poses is least near 18°).
    pub fn steady(omega: f64) -> (f64, f64) {
        let start = 20f64.to_radians();
        let mut x = SVector::from([start, 1.0 - start.sin()]);
        for _ in 0..50 {
            let (_, grad, hess) = num_dual::hessian(|y| amended(y[0], y[1], omega), &x);
            let dx = hess.lu().solve(&grad).unwrap();
            x -= dx;
            if dx.amax() < 1e-15 {
                break;
            }
        }
        (x[0], x[1])
    }

    /// The angle below the horizontal of a rod, its axis carried from the
    /// initial `d0`.
    pub fn rod_angle(q: &[f64], index: usize, d0: [f64; 3]) -> f64 {
        let d = rotate(SpatialBody::of(index).orientation(q), d0);
        (-d[2]).atan2(d[0].hypot(d[1]))
    }

    /// The angular momentum about the z axis: the only torque about it,
    /// none, so it is conserved.
    pub fn momentum_z(mechanism: &Mechanism, q: &[f64], v: &[f64]) -> f64 {
        let mut l = 0.0;
        for (i, body) in mechanism.bodies.iter().enumerate() {
            let b = SpatialBody::of(i);
            let (r, rd, p, pd) = (b.position(q), b.position(v), b.orientation(q), b.orientation(v));
            let w = body_rate(p, pd);
            let jw: [f64; 3] = std::array::from_fn(|a| (0..3).map(|c| body.inertia[a][c] * w[c]).sum());
            l += body.mass * cross(r, rd)[2] + rotate(p, jw)[2];
        }
        l
    }
}

#[test]
fn the_stiff_flyball_governor_keeps_its_steady_state_momentum_and_energy_balance() {
    let omega = std::f64::consts::TAU;
    // Started at the steady state computed independently (two reduced
    // coordinates, the amended potential), it must stay there.
    let (beta, s) = flyball::steady(omega);
    let mechanism = flyball::mechanism(beta, s, omega);
    let Built { model, q0, v0, .. } = mechanism.build().unwrap();
    let mut sim = Simulation::new(&model, Settings::new(Scheme::RungeKutta4, 1e-4, Control::none()), &q0, &v0).unwrap();
    let d0 = [beta.cos(), 0.0, -beta.sin()];
    let (mut moved, mut height) = (0.0_f64, 0.0_f64);
    sim.run::<Error>(1.0, 10, |s2| {
        moved = moved.max((flyball::rod_angle(s2.q(), flyball::RODS[0], d0) - beta).abs());
        height = height.max((SpatialBody::of(flyball::SLIDER).position(s2.q())[2] - s).abs());
        Ok(())
    })
    .unwrap();
    println!(
        "steady state at Ω = 2π: β = {:.6}°, s = {s:.9} m; over 1 s the rod moved {moved:.2e} rad, the slider {height:.2e} m",
        beta.to_degrees()
    );
    assert!(moved < 1e-9 && height < 1e-10, "{moved:e} {height:e}");

    // From the benchmark's start (springs at rest, rods at 30°) the rods
    // swing up towards the steady state: no torque about z, so the angular
    // momentum about it stays; the energy lost is the dampers' work (Ψ).
    let start = flyball::mechanism(30f64.to_radians(), 0.5, omega);
    let Built { model, q0, v0, .. } = start.build().unwrap();
    let l0 = flyball::momentum_z(&start, &q0, &v0);
    // The slider's height and both rods' angles, every 1 ms.
    let rods_at = |d: f64| [d * 30f64.to_radians().cos(), 0.0, -30f64.to_radians().sin()];
    let observed = |q: &[f64]| {
        let angle = |k: usize, d| flyball::rod_angle(q, flyball::RODS[k], rods_at(d));
        [SpatialBody::of(flyball::SLIDER).position(q)[2], angle(0, 1.0), angle(1, -1.0)]
    };
    let run_with = |settings: Settings| {
        let h = settings.h;
        let mut sim = Simulation::new(&model, settings, &q0, &v0).unwrap();
        let (mut momentum, mut psi, mut samples) = (0.0_f64, 0.0_f64, Vec::new());
        sim.run::<Error>(2.0, (1e-3 / h).round() as u64, |s2| {
            momentum = momentum.max((flyball::momentum_z(&start, s2.q(), s2.v()) - l0).abs() / l0);
            psi = psi.max(s2.measure().psi.abs());
            samples.push(observed(s2.q()));
            Ok(())
        })
        .unwrap();
        (sim.q().to_vec(), momentum, psi, sim.measure().phi.abs(), samples)
    };
    let run = |h: f64, control: Control| {
        let (q, momentum, psi, phi, _) = run_with(Settings::new(Scheme::RungeKutta4, h, control));
        (q, momentum, psi, phi)
    };
    let (coarse, momentum, psi, phi) = run(1e-4, Control::none());
    let (fine, _, _, _, fine_samples) = run_with(Settings::new(Scheme::RungeKutta4, 5e-5, Control::none()));
    // Generalized-α at a 1 kHz rate, 20× RK-4's step (at which RK-4 blows
    // up): within 1e-4 m and 1e-4 rad of RK-4 at h = 5e-5 at every 1 ms.
    let (_, a_momentum, _, a_phi, a_samples) = run_with(Settings::new(Scheme::GeneralizedAlpha, 1e-3, Control::none()));
    assert_eq!(a_samples.len(), fine_samples.len());
    let worst: [f64; 3] = std::array::from_fn(|k| {
        a_samples.iter().zip(&fine_samples).map(|(a, f)| (a[k] - f[k]).abs()).fold(0.0, f64::max)
    });
    println!(
        "generalized-α, h = 1e-3: slider height within {:.1e} m, rods within {:.1e}, {:.1e} rad; |ΔL_z|/L_z {a_momentum:.1e}, |Φ| {a_phi:.1e}",
        worst[0], worst[1], worst[2]
    );
    assert!(worst.iter().all(|w| *w < 1e-4) && a_phi < 1e-9, "{worst:?}, |Φ| {a_phi:e}");
    // At 10× the largest step RK-4 runs at (2.5e-4; it stops from 4e-4,
    // where h λ_d passes its stability limit), still within 1e-4 at the
    // samples both have (every 5 ms): measured 3.9e-5 m and 4.0e-5 rad.
    let mut sim =
        Simulation::new(&model, Settings::new(Scheme::GeneralizedAlpha, 2.5e-3, Control::none()), &q0, &v0).unwrap();
    let mut coarse_worst = [0.0_f64; 3];
    sim.run::<Error>(2.0, 2, |s2| {
        let o = observed(s2.q());
        let f = fine_samples[(s2.t() / 1e-3).round() as usize];
        coarse_worst = std::array::from_fn(|k| coarse_worst[k].max((o[k] - f[k]).abs()));
        Ok(())
    })
    .unwrap();
    println!("generalized-α, h = 2.5e-3: slider height, rods within {coarse_worst:?}");
    assert!(coarse_worst.iter().all(|w| *w < 1e-4), "{coarse_worst:?}");
    for h in [4e-4, 1e-3] {
        assert!(
            Simulation::new(&model, Settings::new(Scheme::RungeKutta4, h, Control::none()), &q0, &v0)
                .unwrap()
                .run::<Error>(0.1, 1, |_| Ok(()))
                .is_err(),
            "RK-4 at h = {h} fails"
        );
    }
    let gap = |a: &[f64]| a.iter().zip(&fine).map(|(x, y)| (x - y).abs()).fold(0.0, f64::max);
    println!(
        "from the start, 2 s, RK-4 h = 1e-4: |ΔL_z|/L_z {momentum:.1e}, |Ψ| {psi:.1e} J, |Φ| {phi:.1e}, to h/2 {:.1e}",
        gap(&coarse)
    );
    assert!(momentum < 1e-10 && psi < 1e-6 && phi < 1e-9 && gap(&coarse) < 1e-9);
    // Its dampers are stiff against the step (h λ_d = 0.81): robust
    // leaves out its energy term (gains::STIFF_DISSIPATION_H) and is closer
    // than none.
    let (robust, r_momentum, _, r_phi) = run(1e-4, methods::robust());
    println!("robust: |ΔL_z|/L_z {r_momentum:.1e}, |Φ| {r_phi:.1e}, to h/2 {:.1e}", gap(&robust));
    assert!(r_momentum <= momentum && r_phi < 1e-12 && gap(&robust) <= gap(&coarse));
    // So does the projection of Ψ, and the projection, keeping Φ and Φ̇,
    // is closer than none too.
    let (projection, p_momentum, _, p_phi) = run(1e-4, methods::projection());
    println!("projection: |ΔL_z|/L_z {p_momentum:.1e}, |Φ| {p_phi:.1e}, to h/2 {:.1e}", gap(&projection));
    assert!(p_phi < 1e-10 && gap(&projection) <= gap(&coarse));
    // With an energy term kept (robust's at an explicit rate), the state is
    // held to E₀ minus the dampers' work as the scheme integrated it, which
    // carries more error than the state (none's |Ψ| above against its
    // state's energy error, about 4e-9 J): printed, not asserted.
    let with_energy = methods::robust()
        .with_energy(cdyn::Energy::Projected { alpha_e: cdyn::Rate::Given(1.0 / 1e-4), position_weight: 16.0 });
    let (q, m, p, f) = run(1e-4, with_energy);
    println!("robust with its energy term: {m:.1e}, |Ψ| {p:.1e}, |Φ| {f:.1e}, to h/2 {:.1e}", gap(&q));
}

/// Renormalization, the common practice with Euler parameters (not a cdyn
/// method), after every step of an uncontrolled run: how it treats `ṗ`.
#[derive(Clone, Copy)]
enum Renormalization {
    /// `p ← p/|p|` alone.
    Plain,
    /// Also `ṗ` made tangent, `ṗ ← ṗ − (pᵀṗ) p`: `pᵀp = 1` and its derivative hold.
    Tangent,
    /// `(p, ṗ) ← (p, ṗ)/|p|`, then `ṗ` made tangent: the derivative of the
    /// map `p ↦ p/|p|` applied to `ṗ`, so the body keeps its rotation and its
    /// angular velocity `ω′ = 2G(p)ṗ/|p|²` (which the other two change by the
    /// factor `|p|` they remove).
    Lifted,
}

/// An uncontrolled run renormalized after every step, stepped with the
/// library's own integrator and right-hand side, so it differs from `none`
/// by the renormalization alone: the state at `t_end`. The joints drift as
/// without control.
fn renormalized(built: &Built, scheme: Scheme, h: f64, t_end: f64, how: Renormalization) -> Vec<f64> {
    let Built { model, q0, v0, .. } = built;
    let n = model.n();
    let e0 = model.kinetic(q0, v0) + model.potential(q0, None);
    let mut system = cdyn::simulate::system::ControlledSystem::new(model, Control::none(), e0);
    let mut integrator = cdyn::integrate::Integrator::new(scheme, Control::none().application, 2 * n + 1);
    let mut x = [q0.as_slice(), v0.as_slice(), &[0.0]].concat();
    let steps = cdyn::simulate::steps_to(t_end, h).unwrap();
    for k in 0..steps {
        integrator.step(&mut system, &mut x, k as f64 * h, h).unwrap();
        for b in 0..n / 7 {
            let p = SpatialBody::of(b).euler_parameters();
            let norm = p.iter().map(|&i| x[i] * x[i]).sum::<f64>().sqrt();
            p.iter().for_each(|&i| x[i] /= norm);
            if let Renormalization::Lifted = how {
                p.iter().for_each(|&i| x[n + i] /= norm);
            }
            if let Renormalization::Tangent | Renormalization::Lifted = how {
                let along = p.iter().map(|&i| x[i] * x[n + i]).sum::<f64>();
                p.iter().for_each(|&i| x[n + i] -= along * x[i]);
            }
        }
    }
    x.truncate(2 * n);
    x
}

/// The same run under a cdyn control: the state at `t_end`.
fn controlled(built: &Built, scheme: Scheme, h: f64, t_end: f64, control: Control) -> Vec<f64> {
    let (q, v) = end_state(built, Settings::new(scheme, h, control), t_end);
    [q, v].concat()
}

/// What each run ends with: the largest error of the positions against a
/// converged run, `max ||p| − 1|`, `max |Φ|` and `|T + V − E₀|`.
fn judged(built: &Built, x: &[f64], reference: &[f64]) -> [f64; 4] {
    let model = &built.model;
    let n = model.n();
    let (q, v) = x.split_at(n);
    let drift = (0..n / 7)
        .map(|b| (SpatialBody::of(b).orientation(q).iter().map(|x| x * x).sum::<f64>().sqrt() - 1.0).abs())
        .fold(0.0, f64::max);
    let e0 = model.kinetic(&built.q0, &built.v0) + model.potential(&built.q0, None);
    [
        (0..n).map(|i| (q[i] - reference[i]).abs()).fold(0.0, f64::max),
        drift,
        phi(model, q).iter().fold(0.0, |a: f64, x| a.max(x.abs())),
        (model.kinetic(q, v) + model.potential(q, None) - e0).abs(),
    ]
}

/// Renormalization against cdyn's methods, on the heavy top, the
/// precessing top, a free body and a chain of five rods, with AB-3 and
/// RK-4 (the table is printed for docs/library.md, "Spatial systems"). Every kind holds `|p| = 1`
/// exactly, as `robust` and `projection` do, but leaves the joints and the
/// energy as without control. On the spinning tops with AB-3, plain
/// renormalization makes the motion worse than no control at all (heavy
/// top 7.6×, the same at h/2 and h/4; precessing top 75×): at every step it
/// changes the angular velocity of the rotation `p` represents,
/// `2G(p)ṗ/|p|²`, by the factor `|p|` it removes. Lifted to `ṗ`, so that
/// the angular velocity is kept, it makes them 7.5× and 55× better; and
/// `robust` and `projection`, which carry `ṗ` along the same way, 49× and
/// 49–99× (without that, 2.3× and 31×).
#[test]
fn plain_renormalization_against_the_controls() {
    let cases: [(&str, Mechanism, f64); 4] = [
        ("heavy top", heavy_top(), 0.2),
        ("precessing top", precessing_top().0, 1.0),
        ("free body", free_body(compose(about([0.0, 0.0, 1.0], 0.4), about(unit([1.0, 1.0, 0.0]), 0.9))), 10.0),
        ("chain of 5 rods", cdyn::spatial::chain(5, 0.6, 9.81), 2.0),
    ];
    for (name, mechanism, t_end) in cases {
        let built = mechanism.build().unwrap();
        let h0 = if name.ends_with("top") { 1e-4 } else { 2e-3 };
        let reference = controlled(&built, Scheme::RungeKutta4, h0 / 8.0, t_end, Control::none());
        for (scheme, h) in [(Scheme::AdamsBashforth3, h0), (Scheme::RungeKutta4, 4.0 * h0)] {
            let mut rows: Vec<(&str, [f64; 4])> = methods::compare_cases(&methods::MethodGains::paper(), true)
                .into_iter()
                .map(|(method, control)| {
                    (method, judged(&built, &controlled(&built, scheme, h, t_end, control), &reference))
                })
                .collect();
            for (method, how) in [
                ("renormalize", Renormalization::Plain),
                ("renormalize, tangent ṗ", Renormalization::Tangent),
                ("renormalize, lifted ṗ", Renormalization::Lifted),
            ] {
                rows.push((method, judged(&built, &renormalized(&built, scheme, h, t_end, how), &reference)));
            }
            println!("{name}, {scheme:?}, h = {h}, {t_end} s: error of q, ||p| − 1|, |Φ|, |T + V − E₀|");
            for (method, [error, drift, phi, energy]) in &rows {
                println!("  {method:>22} {error:9.2e} {drift:9.2e} {phi:9.2e} {energy:9.2e}");
            }
            let row = |method: &str| rows.iter().find(|(m, _)| *m == method).unwrap().1;
            let (none, robust) = (row("none"), row("robust"));
            let (plain, lifted) = (row("renormalize"), row("renormalize, lifted ṗ"));
            // `projection` to its default tolerance (1e-10).
            for (method, bound) in [("robust", 1e-12), ("projection", 1e-10)] {
                assert!(row(method)[1] <= bound, "{name}: {method} lets |p| drift: {:?}", row(method));
            }
            // Joints (more rows than normalizations): renormalization leaves them to drift, the controls hold them.
            if built.model.m() > built.model.n() / 7 {
                assert!(lifted[2] > 1e3 * robust[2].max(1e-15), "{name}: {lifted:?} vs {robust:?}");
            }
            // The spinning tops with AB-3: plain renormalization changes the spin at every step.
            if name.ends_with("top") && scheme == Scheme::AdamsBashforth3 {
                assert!(plain[0] > 5.0 * none[0], "{name}: renormalized {plain:?} vs none {none:?}");
                assert!(lifted[0] < none[0] / 5.0, "{name}: lifted {lifted:?} vs none {none:?}");
                // Carrying ṗ along (unit vectors) is what takes robust and projection this far.
                for method in ["robust", "projection"] {
                    assert!(row(method)[0] < none[0] / 10.0, "{name}: {method} {:?} vs none {none:?}", row(method));
                }
            }
        }
    }
}

/// Newton's law alone (no velocity or energy term, `α = 7`) at `(q, v)`:
/// checks that it adds `U_v = ε ṗ` on the Euler parameters `p` and nothing
/// elsewhere, with `ε = pᵀU_q/|p|²` — the identity behind `carry_rate`,
/// which computes `ε` from `Φ` alone — and returns `ε`.
fn carried_rate(model: &Model, q: &[f64], v: &[f64], p: [usize; 4], dependent: DependentRows) -> f64 {
    let n = model.n();
    let alpha = 7.0;
    let control = Control::none().with_geometric(cdyn::Geometric::Newton(cdyn::Rate::Given(alpha)));
    let e0 = model.kinetic(q, v) + model.potential(q, None);
    let mut system = cdyn::simulate::system::ControlledSystem::new(model, control, e0);
    system.set_dependent_rows(dependent);
    let x = [q, v, &[0.0]].concat();
    let (mut f, mut u) = (vec![0.0; 2 * n + 1], vec![0.0; 2 * n + 1]);
    cdyn::integrate::Rhs::eval(&mut system, &x, 0.0, &mut f, Some(&mut u)).unwrap();
    let (u_q, u_v) = (&u[..n], &u[n..2 * n]);
    let norm2: f64 = p.iter().map(|&i| q[i] * q[i]).sum();
    let epsilon = p.iter().map(|&i| q[i] * u_q[i]).sum::<f64>() / norm2;
    // The row is |p|² − 1 = Φ: ε = −α Φ / (2|p|²).
    assert!((epsilon + alpha * (norm2 - 1.0) / (2.0 * norm2)).abs() < 1e-12, "ε = {epsilon}");
    for i in 0..n {
        let expected = if p.contains(&i) { epsilon * v[i] } else { 0.0 };
        assert!((u_v[i] - expected).abs() <= 1e-12 * v[i].abs().max(1.0), "U_v[{i}] = {} ≠ {expected}", u_v[i]);
    }
    epsilon
}

/// A unit vector's carried velocity at a state off the sphere (|p| = 1.02)
/// and off the joint; and with the normalization entered twice, the second
/// row dropped as dependent, the unit vector is carried once, not twice.
#[test]
fn newton_carries_the_euler_parameters_rates_along_its_rescaling() {
    let Built { model, mut q0, v0, .. } = heavy_top().build().unwrap();
    let p = SpatialBody::of(0).euler_parameters();
    p.iter().for_each(|&i| q0[i] *= 1.02);
    q0[0] += 1e-3;
    assert!(carried_rate(&model, &q0, &v0, p, DependentRows::Error) < -0.1);
    let inertia = heavy_top().bodies[0].inertia;
    let twice = Model::builder(vec![15.0, 15.0, 15.0, 0.0, 0.0, 0.0, 0.0])
        .kinetic_map(cdyn::spatial::Rotation::new(inertia), p)
        .unit_vector(p)
        .unit_vector(p)
        .build()
        .unwrap();
    assert_eq!(twice.unit_vectors().len(), 2);
    carried_rate(&twice, &q0, &v0, p, DependentRows::Tolerate);
}

/// Projecting a free body's `p` back to unit length (assembly, as the
/// `projection` method after each step) keeps its angular velocity: the
/// rates are carried along, so the state is the same motion, renormalized.
#[test]
fn projecting_the_euler_parameters_keeps_the_angular_velocity() {
    let Built { model, q0, v0, .. } = free_body(about(unit([1.0, 2.0, 0.5]), 0.7)).build().unwrap();
    let b = SpatialBody::of(0);
    let w = body_rate(b.orientation(&q0), b.orientation(&v0));
    let (mut q, mut v) = (q0.clone(), v0.clone());
    // The same rotation and angular velocity, represented by 1.03 p.
    b.euler_parameters().iter().for_each(|&i| (q[i], v[i]) = (1.03 * q0[i], 1.03 * v0[i]));
    let assembly = cdyn::dynamics::assemble::assemble(&model, &mut q, &mut v, 0.0, 1e-14).unwrap();
    assert!(assembly.newton_iterations > 1, "{assembly:?}");
    let (p, pd) = (b.orientation(&q), b.orientation(&v));
    let w_after = body_rate(p, pd);
    let gap = |a: &[f64], b: &[f64]| a.iter().zip(b).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max);
    assert!(gap(&p, &b.orientation(&q0)) < 1e-14, "{p:?}");
    assert!(gap(&w_after, &w) < 1e-12 * w.iter().map(|x| x.abs()).fold(0.0, f64::max), "{w_after:?} vs {w:?}");
}
