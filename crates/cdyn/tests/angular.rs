//! Angular momenta (`cdyn::model::angular`), in layers: the rotations found
//! against hand-built cases (a free body keeps all three, a top on a fixed
//! point the vertical one, a top whose point is off the axis or a push a
//! millionth of gravity none), the rotation field and its momentum against
//! the rigid-body formulas, `robust`'s energy and angular momenta restored
//! at their rate at a state off both, and a free asymmetric body's angular
//! momentum over 1 000 s.

use cdyn::dynamics::momentum::{self, Kind, ROUND_OFF};
use cdyn::integrate::Rhs;
use cdyn::simulate::system::{ControlledSystem, System};
use cdyn::spatial::rotation::{about, body_rate, compose, e_matrix, rotate};
use cdyn::spatial::{Body, Built, Joint, JointKind, Mechanism, SpatialBody};
use cdyn::{
    Control, Energy, Geometric, Invariant, Model, Rate, Scalar, Scheme, Settings, Simulation, Velocity, methods,
};

fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
}

/// A free asymmetric body with a full inertia tensor in its own axes,
/// moving and tumbling, off the origin.
fn free_body() -> Mechanism {
    let body = Body::new("body", 2.0, [1.0; 3])
        // Principal moments 1, 2, 3 kg m² about axes turned 0.7 rad about (1, 2, 3).
        .with_inertia([
            [1.544859710076236, -0.45817463857111, 0.591356595893453],
            [-0.45817463857111, 1.702467921455299, 0.096314688900842],
            [0.591356595893453, 0.096314688900842, 2.752672368468465],
        ])
        .with_position([0.3, -0.2, 0.5])
        .with_velocity([0.1, 0.25, -0.05])
        .with_orientation(compose(about([0.0, 0.0, 1.0], 0.4), about([0.6, 0.8, 0.0], 0.9)))
        .with_angular_velocity([1.18, 0.48, 0.62]);
    Mechanism::new([0.0; 3]).with_bodies(vec![body])
}

/// The heavy top of Brüls & Cardona on a fixed point at `pivot`, under `gravity`.
fn top(pivot: [f64; 3], gravity: [f64; 3]) -> Mechanism {
    let w0 = [0.0, 150.0, -4.61538];
    let arm = [0.0, 1.0, 0.0];
    let top = Body::new("top", 15.0, [0.234375, 0.46875, 0.234375])
        .with_position(std::array::from_fn(|i| pivot[i] + arm[i]))
        .with_velocity(cross(w0, arm))
        .with_angular_velocity(w0);
    let fixed = Joint::new(JointKind::Spherical, 0, None, pivot);
    Mechanism::new(gravity).with_bodies(vec![top]).with_joints(vec![fixed])
}

fn found(m: &Mechanism) -> Vec<String> {
    let Built { model, q0, v0, .. } = m.build().unwrap();
    momentum::detect(&model, &q0, &v0).kept.into_iter().map(|m| m.name).collect()
}

#[test]
fn rotations_are_found_where_nothing_turns_the_system() {
    let all = ["x", "y", "z"];
    let mut expected: Vec<String> = all.iter().map(|a| format!("linear momentum {a}")).collect();
    expected.extend(all.iter().map(|a| format!("angular momentum {a}")));
    assert_eq!(found(&free_body()), expected);
    let g = [0.0, 0.0, -9.81];
    assert_eq!(found(&top([0.0; 3], g)), ["angular momentum z"]);
    // On a vertical line through the origin the point may be anywhere.
    assert_eq!(found(&top([0.0, 0.0, 2.0], g)), ["angular momentum z"]);
    // Off the origin's axis, it keeps the momentum about its own vertical;
    // gravity a millionth off vertical keeps none.
    assert_eq!(found(&top([1.0, 0.0, 0.0], g)), ["angular momentum z about [1.0, 0.0, 0.0]"]);
    assert!(found(&top([0.0; 3], [9.81e-6, 0.0, -9.81])).is_empty());
    // Zero gravity: every axis through the fixed point.
    let names = found(&top([0.0; 3], [0.0; 3]));
    assert_eq!(names, all.map(|a| format!("angular momentum {a}")));
}

#[test]
fn the_rotation_field_turns_each_body_and_its_momentum_is_the_bodys() {
    let Built { model, q0, v0, .. } = free_body().build().unwrap();
    let symmetries = momentum::detect(&model, &q0, &v0);
    let b = SpatialBody::of(0);
    let mut sim = Simulation::new(&model, Settings::new(Scheme::RungeKutta4, 0.01, Control::none()), &q0, &v0).unwrap();
    for _ in 0..3 {
        for _ in 0..37 {
            sim.step().unwrap();
        }
        let (q, v) = (sim.q().to_vec(), sim.v().to_vec());
        let (r, p, rd, pd) = (b.position(&q), b.orientation(&q), b.position(&v), b.orientation(&v));
        // L = m r × ṙ + A J′ ω′, with A J′ ω′ = J ω in space axes.
        let body = &free_body().bodies[0];
        let w_body = body_rate(p, pd);
        let jw: [f64; 3] = std::array::from_fn(|i| (0..3).map(|k| body.inertia[i][k] * w_body[k]).sum());
        let spin = rotate(p, jw);
        let orbit = cross(r, rd).map(|x| x * body.mass);
        for (axis, name) in ["x", "y", "z"].iter().enumerate() {
            let j = symmetries.kept.iter().position(|m| m.name == format!("angular momentum {name}")).unwrap();
            let Kind::Rotation(g) = &symmetries.kept[j].kind else { panic!("{name}: not a rotation") };
            let mut xi = vec![0.0; model.n()];
            g.at(&q, &mut xi);
            // The field turns the body about the axis at unit rate.
            let turn: [f64; 4] = std::array::from_fn(|i| xi[3 + i]);
            let e = e_matrix(p);
            let omega: [f64; 3] = std::array::from_fn(|i| 2.0 * (0..4).map(|k| e[i][k] * turn[k]).sum::<f64>());
            let unit: [f64; 3] = std::array::from_fn(|i| f64::from(u8::from(i == axis)));
            let moved = cross(unit, r);
            // Exact for |p| = 1, which the uncontrolled run keeps to 1e-10.
            let off = (p.iter().map(|x| x * x).sum::<f64>() - 1.0).abs();
            for i in 0..3 {
                assert!((omega[i] - unit[i]).abs() <= 1e-14 + off, "{name}: ω = {omega:?}");
                assert!((xi[i] - moved[i]).abs() < 1e-15, "{name}: ξ_r = {xi:?}");
            }
            let exact = orbit[axis] + spin[axis];
            let l = sim.momentum(j);
            assert!((l - exact).abs() < 1e-14 * (1.0 + exact.abs()), "{name}: {l:.16e} against {exact:.16e}");
        }
    }
}

/// `Ψ` and the angular momenta at `x` (with `e` the state's last entry).
fn invariants(system: &mut ControlledSystem<'_>, model: &Model, x: &[f64], e0: f64) -> Vec<f64> {
    let n = model.n();
    let (q, v) = (&x[..n], &x[n..2 * n]);
    let mut out = vec![model.kinetic(q, v) + model.potential(q, None) - e0 - x[2 * n]];
    let turning: Vec<usize> =
        (0..system.symmetries().kept.len()).filter(|&j| system.symmetries().kept[j].kind != Kind::Constant).collect();
    out.extend(turning.into_iter().map(|j| system.momentum(j, x)));
    out
}

#[test]
fn robust_restores_the_energy_and_each_angular_momentum_at_their_rate() {
    let alpha = 15.0;
    let robust = Control::none()
        .with_geometric(Geometric::Newton(Rate::Given(20.0)))
        .with_velocity(Velocity::Gradient(Rate::Given(10.0)))
        .with_energy(Energy::Projected { alpha_e: Rate::Given(alpha), position_weight: 16.0 });
    // robust with its energy term left out (stiff dampers): the angular
    // momenta decay at the constraints' rate α_g, Ψ is left alone.
    let left_out = robust.with_geometric(Geometric::Newton(Rate::Given(alpha))).with_energy(Energy::None);
    let cases = [
        ("free body", free_body(), robust),
        ("heavy top", top([0.0; 3], [0.0, 0.0, -9.81]), robust),
        ("free body, energy left out", free_body(), left_out),
    ];
    for (label, mechanism, control) in cases {
        let Built { model, q0, v0, .. } = mechanism.build().unwrap();
        let n = model.n();
        let e0 = model.kinetic(&q0, &v0) + model.potential(&q0, None);
        let mut system = ControlledSystem::new(&model, control, e0);
        system.set_symmetries(momentum::detect(&model, &q0, &v0));
        // A state off the energy and off the angular momenta (and slightly
        // off the constraints): the velocities pushed by a few per cent.
        let mut x: Vec<f64> = q0.iter().chain(&v0).copied().collect();
        x.push(0.0);
        for i in 0..n {
            x[i] += 1e-7 * ((i * 7 % 5) as f64 - 2.0);
            x[n + i] *= 1.0 + 0.03 * ((i * 3 % 4) as f64 - 1.5);
        }
        let (mut f, mut u) = (vec![0.0; 2 * n + 1], vec![0.0; 2 * n + 1]);
        system.eval(&x, 0.0, &mut f, Some(&mut u)).unwrap();
        let held = invariants(&mut system, &model, &x, e0);
        assert!(held.len() > 1, "{label}: no angular momentum found");
        // The rates U gives them, by central differences (exact in v, O(s²) in q).
        let s = 1e-6;
        let at = |sign: f64| -> Vec<f64> { x.iter().zip(&u).map(|(x, u)| x + sign * s * u).collect() };
        let (plus, minus) = (at(1.0), at(-1.0));
        let (hp, hm) = (invariants(&mut system, &model, &plus, e0), invariants(&mut system, &model, &minus, e0));
        let first = if control.energy == Energy::None { 1 } else { 0 };
        for (i, name) in std::iter::once("Ψ".to_string()).chain((1..held.len()).map(|j| format!("L{j}"))).enumerate() {
            if i < first {
                continue;
            }
            let rate = (hp[i] - hm[i]) / (2.0 * s);
            let initial = if i == 0 { 0.0 } else { invariants_initial(&system, i) };
            let expected = -alpha * (held[i] - initial);
            println!("{label} {name}: rate {rate:.6e}, expected {expected:.6e}");
            assert!(
                (rate - expected).abs() < 1e-6 * expected.abs().max(1e-9),
                "{label} {name}: rate {rate:.9e}, expected {expected:.9e}"
            );
        }
    }
}

/// The initial value of the `i`-th angular momentum (1-based) of `system`.
fn invariants_initial(system: &ControlledSystem<'_>, i: usize) -> f64 {
    system.symmetries().kept.iter().filter(|m| m.kind != Kind::Constant).nth(i - 1).unwrap().initial
}

/// A free asymmetric body tumbling for 1 000 s at RK-4, h = 0.01: with no
/// control its angular momentum drifts at the scheme's truncation error;
/// `robust` and `projection` hold it (and the energy) to round-off.
#[test]
fn a_free_body_keeps_its_angular_momentum_for_1000_s_under_robust() {
    let Built { model, q0, v0, .. } = free_body().build().unwrap();
    let (mut drift, mut energy) = (Vec::new(), Vec::new());
    for (name, control) in
        [("none", Control::none()), ("robust", methods::robust()), ("projection", methods::projection())]
    {
        let mut sim = Simulation::new(&model, Settings::new(Scheme::RungeKutta4, 0.01, control), &q0, &v0).unwrap();
        let angular: Vec<usize> =
            (0..sim.symmetries().kept.len()).filter(|&j| sim.symmetries().kept[j].kind != Kind::Constant).collect();
        assert_eq!(angular.len(), 3);
        let start: Vec<f64> = angular.iter().map(|&j| sim.momentum(j)).collect();
        let scale = angular.iter().map(|&j| sim.symmetries().kept[j].scale).fold(0.0, f64::max);
        let (mut worst, mut psi): (f64, f64) = (0.0, 0.0);
        for step in 1..=100_000 {
            sim.step().unwrap();
            if step % 100 == 0 {
                for (k, &j) in angular.iter().enumerate() {
                    worst = worst.max((sim.momentum(j) - start[k]).abs() / scale);
                }
                psi = psi.max(sim.measure().psi.abs());
            }
        }
        println!("{name:10}: angular momentum drift over 1000 s {worst:.2e} of its scale, max |Ψ| {psi:.2e}");
        drift.push(worst);
        energy.push(psi);
    }
    assert!(drift[0] > 1e-10, "none keeps it too well to tell: {drift:?}");
    assert!(drift[1] < ROUND_OFF && drift[2] < ROUND_OFF, "{drift:?}");
    assert!(energy[1] <= energy[0] && energy[2] <= energy[0], "max |Ψ| {energy:?}");
}

/// The top's angular momentum about a space axis through its fixed point,
/// written as a user would: `m (r × ṙ)·a + (A(p) J′ ω′)·a`, generic over
/// the scalar, on the body's seven coordinates.
struct TopMomentum {
    axis: [f64; 3],
}

impl Invariant<7> for TopMomentum {
    fn value<D: Scalar>(&self, x: [D; 7], xd: [D; 7]) -> D {
        let (r, p) = ([x[0], x[1], x[2]], [x[3], x[4], x[5], x[6]]);
        let (rd, pd) = ([xd[0], xd[1], xd[2]], [xd[3], xd[4], xd[5], xd[6]]);
        let w = body_rate(p, pd);
        let j = [0.234375, 0.46875, 0.234375];
        let spin = rotate(p, [w[0] * j[0], w[1] * j[1], w[2] * j[2]]);
        let orbit = [r[1] * rd[2] - r[2] * rd[1], r[2] * rd[0] - r[0] * rd[2], r[0] * rd[1] - r[1] * rd[0]];
        (0..3).fold(D::from(0.0), |sum, i| sum + (orbit[i] * 15.0 + spin[i]) * self.axis[i])
    }
}

/// A declared invariant, its gradients by AD: kept and held where the
/// model keeps it (the top's vertical angular momentum: `robust` holds it
/// as it holds the one it finds itself), reported with its drift where it
/// does not (the horizontal one, which gravity turns).
#[test]
fn a_declared_invariant_is_held_where_kept_and_reported_where_broken() {
    let Built { mut model, q0, v0, .. } = top([0.0; 3], [0.0, 0.0, -9.81]).build().unwrap();
    model.declare_invariant("declared L_z", TopMomentum { axis: [0.0, 0.0, 1.0] }, std::array::from_fn(|i| i)).unwrap();
    model.declare_invariant("declared L_x", TopMomentum { axis: [1.0, 0.0, 0.0] }, std::array::from_fn(|i| i)).unwrap();
    assert!(model.declare_invariant("outside", TopMomentum { axis: [1.0; 3] }, [1, 2, 3, 4, 5, 6, 7]).is_err());
    let found = momentum::detect(&model, &q0, &v0);
    let names: Vec<&str> = found.kept.iter().map(|m| m.name.as_str()).collect();
    // The builder's own "angular momentum z" is the same momentum: it is
    // dependent on the declared one and not held twice.
    assert_eq!(names, ["declared L_z"], "{:?}", found.broken);
    assert_eq!(found.broken.len(), 1);
    assert_eq!(found.broken[0].name, "declared L_x");
    assert!(found.broken[0].reason.starts_with("the motion changes it"), "{}", found.broken[0].reason);
    let mut drift = Vec::new();
    for control in [Control::none(), methods::robust(), methods::projection()] {
        let mut sim = Simulation::new(&model, Settings::new(Scheme::RungeKutta4, 2e-3, control), &q0, &v0).unwrap();
        let kept: Vec<&str> = sim.symmetries().kept.iter().map(|m| m.name.as_str()).collect();
        assert_eq!(kept, ["declared L_z"]);
        let l0 = sim.momentum(0);
        let mut worst: f64 = 0.0;
        for _ in 0..1000 {
            sim.step().unwrap();
            worst = worst.max((sim.momentum(0) - l0).abs() / sim.symmetries().kept[0].scale);
        }
        drift.push(worst);
    }
    let shown: Vec<String> = drift.iter().map(|d| format!("{d:.2e}")).collect();
    println!("declared L_z over 2 s, RK-4 h = 2e-3 (none, robust, projection): {shown:?}");
    assert!(drift[0] > 1e-10 && drift[1] < ROUND_OFF && drift[2] < ROUND_OFF, "{drift:?}");
}
