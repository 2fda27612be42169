//! The planar multibody layer: two descriptions of one pendulum agree with
//! each other and with the exact solution; bad descriptions name the entry.

use cdyn::planar::{BodyId, Element, Mechanism};
use cdyn::reference::PendulumExact;
use cdyn::{Control, Error, Scheme, Settings, Simulation};

const G: f64 = 9.81;

/// Angle from +X of the vector from the pivot to the body, and its rate.
fn angle_of(q: &[f64], v: &[f64]) -> (f64, f64) {
    let (x, y) = (q[0], q[1]);
    (y.atan2(x), (x * v[1] - y * v[0]) / (x * x + y * y))
}

fn run(m: &Mechanism, h: f64, t_end: f64) -> Vec<(f64, f64, f64)> {
    let b = m.build().unwrap();
    let mut sim =
        Simulation::new(&b.model, Settings::new(Scheme::RungeKutta4, h, Control::none()), &b.q0, &b.v0).unwrap();
    let mut out = Vec::new();
    sim.run::<Error>(t_end, 10, |s| {
        let (th, om) = angle_of(s.q(), s.v());
        out.push((s.t(), th, om));
        Ok(())
    })
    .unwrap();
    out
}

#[test]
fn point_mass_on_a_rod_and_rigid_body_on_a_pin_are_the_same_pendulum() {
    // Rigid body: mass m, inertia I about its centre, pinned at distance L.
    // Point mass on a rod of the equivalent length L' = (I + mL²)/(mL).
    let (m, inertia, l) = (2.0, 0.3, 1.5);
    let l_eq = (inertia + m * l * l) / (m * l);
    let theta0: f64 = -0.3;
    let omega0 = 1.2;
    let (s, c) = theta0.sin_cos();

    let mut rigid = Mechanism::new([0.0, -G]);
    let body = rigid.rigid("bar", m, inertia, [l * c, l * s], theta0);
    rigid.bodies[0].velocity = [-l * s * omega0, l * c * omega0];
    rigid.bodies[0].angular_velocity = omega0;
    rigid.add(Element::Revolute { a: BodyId::Ground, pa: [0.0, 0.0], b: body, pb: [-l, 0.0], limit: None });

    let mut point = Mechanism::new([0.0, -G]);
    let bob = point.point("bob", m, [l_eq * c, l_eq * s]);
    point.bodies[0].velocity = [-l_eq * s * omega0, l_eq * c * omega0];
    point.add(Element::Distance { a: BodyId::Ground, pa: [0.0, 0.0], b: bob, pb: [0.0, 0.0], length: l_eq });

    let exact = PendulumExact::new(G / l_eq, theta0, omega0).unwrap();
    let (a, b) = (run(&rigid, 1e-3, 5.0), run(&point, 1e-3, 5.0));
    for ((t, th_a, om_a), (_, th_b, om_b)) in a.iter().zip(&b) {
        let (th, om) = exact.angle(*t);
        assert!((th_a - th).abs() < 1e-9 && (th_b - th).abs() < 1e-9, "t = {t}: {th_a} {th_b} vs {th}");
        assert!((om_a - om).abs() < 1e-8 && (om_b - om).abs() < 1e-8, "t = {t}: {om_a} {om_b} vs {om}");
    }
}

#[test]
fn bad_descriptions_name_the_element() {
    let mut m = Mechanism::new([0.0, -G]);
    let bob = m.point("bob", 1.0, [1.0, 0.0]);
    m.add(Element::Revolute { a: BodyId::Ground, pa: [0.0, 0.0], b: BodyId::Body(7), pb: [0.0, 0.0], limit: None });
    let err = m.build().err().unwrap().to_string();
    assert!(err.contains("element 0 (revolute)") && err.contains("body 7 does not exist"), "{err}");

    let mut m = Mechanism::new([0.0, -G]);
    let bob2 = m.point("bob", 1.0, [1.0, 0.0]);
    m.add(Element::FixedAngle { a: BodyId::Ground, b: bob2, angle: 0.0 });
    let err = m.build().err().unwrap().to_string();
    assert!(err.contains("point mass") && err.contains("no angle"), "{err}");

    let mut m = Mechanism::new([0.0, -G]);
    m.point("heavy", 0.0, [1.0, 0.0]);
    let err = m.build().err().unwrap().to_string();
    assert!(err.contains("body 0 (heavy)") && err.contains("mass"), "{err}");
    let _ = bob;
}

#[test]
fn assembly_projects_positions_and_velocities_onto_the_constraints() {
    use cdyn::dynamics::assemble::assemble;
    use cdyn::models::andrews::{constants, mechanism};
    // Andrews' mechanism with every angle off by up to 0.02 rad and random velocities.
    let mut q0 = constants::Q0;
    for (i, q) in q0.iter_mut().enumerate() {
        *q += 0.02 * ((i as f64) * 1.7).sin();
    }
    let mut m = mechanism(q0);
    for (i, b) in m.bodies.iter_mut().enumerate() {
        b.velocity = [0.3 * (i as f64).cos(), -0.2];
        b.angular_velocity = 5.0 - i as f64;
    }
    let built = m.build().unwrap();
    let (mut q, mut v) = (built.q0.clone(), built.v0.clone());
    let report = assemble(&built.model, &mut q, &mut v, 0.0, 1e-13).unwrap();
    assert!(report.phi_before > 1e-4 && report.phi_dot_before > 1e-3, "{report:?}");
    assert!(report.phi_after <= 1e-13 && report.phi_dot_after <= 1e-12, "{report:?}");
    assert!(report.newton_iterations <= 6, "Newton converges quadratically: {report:?}");
    // The corrected state is accepted by a simulation with the default consistency check.
    let s = Simulation::new(&built.model, Settings::new(Scheme::RungeKutta4, 1e-5, Control::none()), &q, &v);
    assert!(s.is_ok());
}

#[test]
fn assembly_respects_a_moving_drive() {
    // A bar driven at φ = 2t about a pin: after assembly Φ_q v = −Φ_t, i.e. ω = 2.
    use cdyn::dynamics::assemble::assemble;
    use cdyn::model::timefn::TimeFn;
    let mut m = Mechanism::new([0.0, -G]);
    let bar = m.rigid("bar", 1.0, 0.1, [0.52, 0.03], 0.05);
    m.add(Element::Revolute { a: BodyId::Ground, pa: [0.0, 0.0], b: bar, pb: [-0.5, 0.0], limit: None });
    m.add(Element::DriveAngle { a: BodyId::Ground, b: bar, f: TimeFn::linear(0.0, 2.0) });
    let built = m.build().unwrap();
    let (mut q, mut v) = (built.q0.clone(), built.v0.clone());
    assemble(&built.model, &mut q, &mut v, 0.0, 1e-14).unwrap();
    assert!(q[2].abs() < 1e-14 && (q[0] - 0.5).abs() < 1e-14 && q[1].abs() < 1e-14, "{q:?}");
    assert!((v[2] - 2.0).abs() < 1e-12 && v[0].abs() < 1e-12 && (v[1] - 1.0).abs() < 1e-12, "{v:?}");
}
