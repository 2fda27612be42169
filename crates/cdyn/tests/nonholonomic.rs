//! Nonholonomic constraints: the knife edge's and a rheonomic row's
//! derivatives against finite differences, the work of a rheonomic row in
//! the energy balance, a sled on an incline, the Chaplygin sleigh and a
//! bicycle with fixed steering against their closed forms, with and
//! without stabilization, and bad knife edges named.

use cdyn::control::methods;
use cdyn::control::{Control, Geometric, Rate, Velocity};
use cdyn::dynamics::Dynamics;
use cdyn::integrate::Application;
use cdyn::planar::{BodyId, Element, Mechanism};
use cdyn::{Model, Nonholonomic, Potential, Scalar, Scheme, Settings, Simulation};

/// Gravity along the incline: 9.81 sin 30°.
const G_INCLINE: f64 = 4.905;

/// A tractor and a trailer hitched by a pin, each on a knife edge off its
/// centre (the blades skewed), plus a spring pulling the tractor: one
/// holonomic pair of rows between two nonholonomic ones.
fn trailer() -> Mechanism {
    let mut m = Mechanism::new([0.3, -1.0]);
    let tractor = m.rigid("tractor", 2.0, 0.4, [0.0, 0.0], 0.2);
    let trailer = m.rigid("trailer", 1.0, 0.2, [-1.2, -0.3], 0.5);
    m.add(Element::KnifeEdge { body: tractor, point: [0.3, 0.1], blade: [1.0, 0.1] });
    m.add(Element::Revolute { a: tractor, pa: [-0.5, 0.0], b: trailer, pb: [0.6, 0.0], limit: None });
    m.add(Element::KnifeEdge { body: trailer, point: [-0.4, 0.0], blade: [2.0, -0.3] });
    m.add(Element::Spring {
        a: BodyId::Ground,
        pa: [3.0, 1.0],
        b: tractor,
        pb: [0.0, 0.0],
        stiffness: 4.0,
        rest_length: 1.0,
    });
    m
}

#[test]
fn knife_edge_rows_are_affine_and_their_derivatives_match_finite_differences() {
    let b = trailer().build().unwrap();
    let model = &b.model;
    assert_eq!((model.n(), model.m()), (6, 4));
    let q = [0.1, -0.2, 0.3, -1.1, -0.4, 0.7];
    let v = [0.5, -0.3, 1.1, 0.2, 0.8, -0.6];
    let t = 0.4;
    let mut d = Dynamics::new(model);
    let mut phi_dot = |q: &[f64], v: &[f64]| {
        d.evaluate(model, q, v, t).unwrap();
        d.phi_dot().to_vec()
    };
    let at_v = phi_dot(&q, &v);
    let at_zero = phi_dot(&q, &[0.0; 6]);
    let at_2v = phi_dot(&q, &v.map(|x| 2.0 * x));
    for r in [0, 3] {
        // Ideal: b = 0, and g(2v) = 2 g(v).
        assert_eq!(at_zero[r], 0.0);
        assert!((at_2v[r] - 2.0 * at_v[r]).abs() < 1e-15, "row {r}");
    }
    let mut d = Dynamics::new(model);
    d.evaluate(model, &q, &v, t).unwrap();
    let (jac, gamma, phi_t) = (d.jac().to_vec(), d.gamma().to_vec(), d.phi_t().to_vec());
    let pattern = model.pattern();
    // Nonholonomic rows: no position value, no work (Φ_t = b = 0 exactly).
    assert_eq!((d.phi()[0], d.phi()[3], phi_t[0], phi_t[3]), (0.0, 0.0, 0.0, 0.0));
    let eps = 1e-6;
    let mut fd = Dynamics::new(model);
    let mut g = |q: &[f64], v: &[f64]| {
        fd.evaluate(model, q, v, t).unwrap();
        fd.phi_dot().to_vec()
    };
    for r in [0, 3] {
        // A = ∂g/∂v, row by row.
        for e in pattern.start[r] as usize..pattern.start[r + 1] as usize {
            let c = pattern.cols[e] as usize;
            let (mut vp, mut vm) = (v, v);
            vp[c] += eps;
            vm[c] -= eps;
            let a = (g(&q, &vp)[r] - g(&q, &vm)[r]) / (2.0 * eps);
            assert!((jac[e] - a).abs() < 1e-9, "row {r} column {c}: {} vs {a}", jac[e]);
        }
        // γ = −(Ȧ v + ḃ) = −d/ds g(q + s v, v) at s = 0.
        let qp: Vec<f64> = q.iter().zip(&v).map(|(q, v)| q + eps * v).collect();
        let qm: Vec<f64> = q.iter().zip(&v).map(|(q, v)| q - eps * v).collect();
        let dg = (g(&qp, &v)[r] - g(&qm, &v)[r]) / (2.0 * eps);
        assert!((gamma[r] + dg).abs() < 1e-8, "row {r}: γ {} vs {}", gamma[r], -dg);
    }
    // The accelerations satisfy every row's second equation, Φ_q q̈ = γ.
    let mut row_acc = vec![0.0; model.m()];
    d.jac_mul(model, d.acc(), &mut row_acc);
    for (r, (a, g)) in row_acc.iter().zip(&gamma).enumerate() {
        assert!((a - g).abs() < 1e-12, "row {r}: {a} vs {g}");
    }
}

/// A rheonomic, non-ideal constraint with a configuration-dependent `A` on
/// a point `(x, y)`: `(1 + y²) ẋ + sin t ẏ + x cos t + t y = 0`.
struct Rheonomic;

impl Nonholonomic<2, 1> for Rheonomic {
    fn eval<D: Scalar>(&self, [x, y]: [D; 2], [vx, vy]: [D; 2], t: D) -> [D; 1] {
        [(y * y + 1.0) * vx + t.sin() * vy + x * t.cos() + t * y]
    }
}

/// Weight: `V = y`.
struct Weight;

impl Potential<1> for Weight {
    fn energy<D: Scalar>(&self, [y]: [D; 1]) -> D {
        y
    }
}

fn rheonomic_model() -> Model {
    Model::builder(vec![1.0, 2.0]).nonholonomic(Rheonomic, [0, 1]).potential(Weight, [1]).build().unwrap()
}

#[test]
fn rheonomic_rows_have_a_b_and_gamma_of_their_finite_differences() {
    let model = rheonomic_model();
    let (q, v, t) = ([0.4, -0.7], [1.3, 0.6], 0.8);
    let g = |q: [f64; 2], v: [f64; 2], t: f64| Rheonomic.eval(q, v, t)[0];
    let mut d = Dynamics::new(&model);
    d.evaluate(&model, &q, &v, t).unwrap();
    let eps = 1e-6;
    let a = [0, 1].map(|j| {
        let (mut vp, mut vm) = (v, v);
        vp[j] += eps;
        vm[j] -= eps;
        (g(q, vp, t) - g(q, vm, t)) / (2.0 * eps)
    });
    for j in 0..2 {
        assert!((d.jac()[j] - a[j]).abs() < 1e-9, "A[{j}]: {} vs {}", d.jac()[j], a[j]);
    }
    assert!((d.phi_t()[0] - g(q, [0.0; 2], t)).abs() < 1e-15, "b");
    assert!((d.phi_dot()[0] - g(q, v, t)).abs() < 1e-15, "A v + b");
    assert_eq!(d.phi()[0], 0.0);
    let along = |s: f64| g([q[0] + s * v[0], q[1] + s * v[1]], v, t + s);
    let dg = (along(eps) - along(-eps)) / (2.0 * eps);
    assert!((d.gamma()[0] + dg).abs() < 1e-8, "γ {} vs {}", d.gamma()[0], -dg);
}

/// The constraint force of a rheonomic row does work `λ b`; the energy
/// balance `Ψ = T + V − E₀ − ∫Ė` counts it, so `Ψ` stays at the scheme's
/// error while the energy itself changes.
#[test]
fn the_energy_balance_counts_the_work_of_a_rheonomic_row() {
    let model = rheonomic_model();
    let (q0, v0) = ([0.5, 0.2], [-0.5 / 1.04, 0.7]);
    let mut sim = Simulation::new(&model, Settings::new(Scheme::RungeKutta4, 1e-3, Control::none()), &q0, &v0).unwrap();
    let (mut psi, mut violation, mut work) = (0.0_f64, 0.0_f64, 0.0_f64);
    for _ in 0..3000 {
        sim.step().unwrap();
        let m = sim.measure();
        psi = psi.max(m.psi.abs());
        violation = violation.max(m.phi_dot);
        work = work.max(sim.energy_input().abs());
    }
    println!("rheonomic: max |Ψ| {psi:.3e}, max |∫Ė| {work:.3e}, max |Av + b| {violation:.3e}");
    assert!(work > 0.1, "the row does work: {work:.3e}");
    assert!(psi < 1e-9 && violation < 1e-9, "{psi:.3e} {violation:.3e}");
}

/// A sled with its edge at its centre of mass on an incline (gravity `−g'`
/// along y in the incline's plane). Its heading turns at the constant rate
/// `ω` (no torque about the contact), and the speed `u` along the blade
/// obeys `u̇ = −g' sin θ`, so with `θ = θ₀ + ωt` and `K = u₀ − (g'/ω) cos θ₀`:
///
/// * `u = K + (g'/ω) cos θ`,
/// * `x = x₀ + (K/ω)(sin θ − sin θ₀) + (g'/ω)(t/2 + (sin 2θ − sin 2θ₀)/(4ω))`,
/// * `y = y₀ − (K/ω)(cos θ − cos θ₀) + (g'/(2ω²))(sin²θ − sin²θ₀)`,
/// * `ẋ = u cos θ`, `ẏ = u sin θ`.
struct Sled {
    /// Gravity along −y in the incline's plane, `g sin(slope)`.
    g: f64,
    theta0: f64,
    omega: f64,
    u0: f64,
}

impl Sled {
    const MASS: f64 = 2.0;
    const INERTIA: f64 = 0.1;

    fn mechanism(&self) -> Mechanism {
        let mut m = Mechanism::new([0.0, -self.g]);
        let sled = m.rigid("sled", Self::MASS, Self::INERTIA, [0.0, 0.0], self.theta0);
        m.bodies[0].velocity = [self.u0 * self.theta0.cos(), self.u0 * self.theta0.sin()];
        m.bodies[0].angular_velocity = self.omega;
        m.add(Element::KnifeEdge { body: sled, point: [0.0, 0.0], blade: [1.0, 0.0] });
        m
    }

    /// `(q, v)` at `t`.
    fn exact(&self, t: f64) -> ([f64; 3], [f64; 3]) {
        let (g, w, th0) = (self.g, self.omega, self.theta0);
        let th = th0 + w * t;
        let k = self.u0 - g / w * th0.cos();
        let u = k + g / w * th.cos();
        let x = k / w * (th.sin() - th0.sin()) + g / w * (t / 2.0 + ((2.0 * th).sin() - (2.0 * th0).sin()) / (4.0 * w));
        let y = -k / w * (th.cos() - th0.cos()) + g / (2.0 * w * w) * (th.sin().powi(2) - th0.sin().powi(2));
        ([x, y, th], [u * th.cos(), u * th.sin(), w])
    }
}

struct Outcome {
    /// Largest error of any coordinate (positions and velocities) against the closed form.
    error: f64,
    /// Largest `|A q̇ + b|`.
    violation: f64,
    /// Largest `|E − E₀|`.
    energy: f64,
}

fn run(
    m: &Mechanism,
    scheme: Scheme,
    h: f64,
    t_end: f64,
    control: Control,
    exact: impl Fn(f64) -> ([f64; 3], [f64; 3]),
) -> Outcome {
    let b = m.build().unwrap();
    let mut sim = Simulation::new(&b.model, Settings::new(scheme, h, control), &b.q0, &b.v0).unwrap();
    let mut out = Outcome { error: 0.0, violation: 0.0, energy: 0.0 };
    let steps = (t_end / h).round() as u64;
    for _ in 0..steps {
        sim.step().unwrap();
        let (q, v) = exact(sim.t());
        for (a, e) in sim.q().iter().zip(&q).chain(sim.v().iter().zip(&v)) {
            out.error = out.error.max((a - e).abs());
        }
        let m = sim.measure();
        out.violation = out.violation.max(m.phi_dot);
        assert_eq!(m.phi, 0.0, "a knife edge has no position-level value");
        out.energy = out.energy.max(m.psi.abs());
    }
    out
}

fn baumgarte() -> Control {
    Control::none().with_geometric(Geometric::Baumgarte { alpha: 20.0, beta: 100.0 })
}

fn velocity_feedback(application: Application) -> Control {
    Control::none().with_velocity(Velocity::Gradient(Rate::Auto)).with_application(application)
}

#[test]
fn sled_on_an_incline_follows_its_closed_form_with_and_without_control() {
    let sled = Sled { g: G_INCLINE, theta0: 0.3, omega: 2.0, u0: 1.0 };
    let m = sled.mechanism();
    let cases = [
        ("none", Control::none()),
        ("baumgarte", baumgarte()),
        ("velocity (rhs)", Control::none().with_velocity(Velocity::Gradient(Rate::Given(50.0)))),
        ("velocity (post-step)", velocity_feedback(Application::PostStep)),
        ("robust", methods::robust()),
        ("projection", methods::projection()),
    ];
    for (name, control) in cases {
        let o = run(&m, Scheme::RungeKutta4, 1e-3, 10.0, control, |t| sled.exact(t));
        println!("{name:22} max error {:.3e}  max |Aq̇+b| {:.3e}  max |Ψ| {:.3e}", o.error, o.violation, o.energy);
        assert!(o.error < 1e-9, "{name}: error {:.3e}", o.error);
    }
}

/// The observed order of convergence on the sled: each scheme's own, so
/// the nonholonomic rows' `γ` is right (a wrong one leaves an error that
/// does not shrink with `h`).
#[test]
fn sled_errors_converge_at_each_schemes_order() {
    let sled = Sled { g: G_INCLINE, theta0: 0.3, omega: 2.0, u0: 1.0 };
    let m = sled.mechanism();
    for (scheme, h, order) in [
        (Scheme::AdamsBashforth2, 4e-3, 2.0),
        (Scheme::AdamsBashforth3, 4e-3, 3.0),
        (Scheme::RungeKutta4, 2e-2, 4.0),
        (Scheme::Rattle, 4e-3, 2.0),
    ] {
        let coarse = run(&m, scheme, h, 4.0, Control::none(), |t| sled.exact(t)).error;
        let fine = run(&m, scheme, h / 2.0, 4.0, Control::none(), |t| sled.exact(t)).error;
        let observed = (coarse / fine).log2();
        println!("{scheme:?}: errors {coarse:.3e}, {fine:.3e}, order {observed:.2}");
        assert!((observed - order).abs() < 0.25, "{scheme:?}: order {observed:.2}, expected {order}");
    }
}

/// Over a long run with a coarse step: without control `A q̇ + b` drifts
/// by the scheme's error; the velocity-level controls measured after the
/// step (post-step, and the projection) keep it at round-off. Applied by a
/// forward Euler step the feedback removes the violation of `x_k` while
/// stepping to `x_{k+1}`, so what is left is one step's drift.
///
/// Every one of them also lowers the coordinates' error. The sled's heading
/// rate is a first integral (no torque about the edge) which the scheme
/// keeps exactly; the run finds it (`cdyn::dynamics::momentum`), and the energy
/// correction of `robust` and `projection` moves `v` along `P_E P v`, which
/// leaves it alone. (Along `P v`, before, it rescaled the heading rate with
/// the rest of `v`: error 0.63 for robust, 0.67 for projection, against
/// 5.6e-3 without control; now 2.5e-3 and 2.5e-3, AB-3 at h = 0.01, 50 s.)
#[test]
fn velocity_level_controls_keep_the_knife_edge_at_round_off() {
    let sled = Sled { g: G_INCLINE, theta0: 0.3, omega: 2.0, u0: 1.0 };
    let m = sled.mechanism();
    let drift = run(&m, Scheme::AdamsBashforth3, 1e-2, 50.0, Control::none(), |t| sled.exact(t));
    println!("none                   max |Aq̇+b| {:.3e}  error {:.3e}", drift.violation, drift.error);
    assert!(drift.violation > 1e-8, "no control: {:.3e}", drift.violation);
    for (name, control) in [
        ("velocity (post-step)", velocity_feedback(Application::PostStep)),
        ("robust", methods::robust()),
        ("projection", methods::projection()),
    ] {
        let o = run(&m, Scheme::AdamsBashforth3, 1e-2, 50.0, control, |t| sled.exact(t));
        println!("{name:22} max |Aq̇+b| {:.3e}  error {:.3e}", o.violation, o.error);
        assert!(o.violation < 1e-13, "{name}: {:.3e}", o.violation);
        assert!(o.error < drift.error, "{name}: error {:.3e} vs {:.3e} uncontrolled", o.error, drift.error);
    }
    let o =
        run(&m, Scheme::AdamsBashforth3, 1e-2, 50.0, velocity_feedback(Application::ForwardEuler), |t| sled.exact(t));
    println!("velocity (forward euler) max |Aq̇+b| {:.3e}  error {:.3e}", o.violation, o.error);
    assert!(o.violation < drift.violation / 50.0, "{:.3e} vs {:.3e} uncontrolled", o.violation, drift.violation);
}

/// Sleds on other slopes, at other speeds and heading rates (several pass
/// through rest along the blade, where the speed reverses), over 50 s at
/// AB-3, h = 0.01: the heading rate is kept, so the heading is as exact
/// under every control as without (the run keeps the momentum of
/// `sled.angle`), and no control makes any coordinate worse than none.
#[test]
fn sleds_keep_their_heading_rate_under_every_control() {
    let g = |slope: f64| 9.81 * slope.to_radians().sin();
    let sleds = [
        Sled { g: g(60.0), theta0: 0.0, omega: 2.0, u0: 1.0 },
        Sled { g: g(30.0), theta0: 1.0, omega: 5.0, u0: 3.0 },
        Sled { g: g(15.0), theta0: -0.4, omega: 0.5, u0: 0.5 },
        Sled { g: g(45.0), theta0: 2.0, omega: -1.3, u0: 0.0 },
    ];
    for (k, sled) in sleds.iter().enumerate() {
        let m = sled.mechanism();
        let (t_end, h) = (50.0, 1e-2);
        let heading = |control: Control| {
            let b = m.build().unwrap();
            let mut sim =
                Simulation::new(&b.model, Settings::new(Scheme::AdamsBashforth3, h, control), &b.q0, &b.v0).unwrap();
            assert!(sim.symmetries().kept.iter().any(|p| p.name == "momentum of sled.angle"), "sled {k}");
            for _ in 0..(t_end / h).round() as u64 {
                sim.step().unwrap();
            }
            (sim.q()[2] - sled.exact(sim.t()).0[2]).abs()
        };
        let none = run(&m, Scheme::AdamsBashforth3, h, t_end, Control::none(), |t| sled.exact(t));
        for (name, control) in [
            ("none", Control::none()),
            ("velocity (post-step)", velocity_feedback(Application::PostStep)),
            ("robust", methods::robust()),
            ("projection", methods::projection()),
        ] {
            let o = run(&m, Scheme::AdamsBashforth3, h, t_end, control, |t| sled.exact(t));
            let theta = heading(control);
            println!("sled {k} {name:22} error {:.3e} (none {:.3e}), heading {theta:.3e}", o.error, none.error);
            assert!(theta < 1e-10, "sled {k} {name}: heading off by {theta:.3e}");
            assert!(o.error <= none.error, "sled {k} {name}: error {:.3e} vs {:.3e} uncontrolled", o.error, none.error);
        }
    }
}

/// The Chaplygin sleigh: a rigid body with a knife edge at distance `d`
/// along its axis from the centre of mass (here behind it, `d < 0`), free.
/// In body axes (`u` forward, `w` the turning rate, lateral speed `−d w`),
/// `u̇ = −d w²`, `ẇ = (m d/J) u w` with `J = I + m d²`; the energy gives
/// `m u² + J w² = m U²`, so `u = −U tanh(c (t − t₀))` and
/// `w = ±√(m/J) U sech(c (t − t₀))`, `c = m d U / J`, `t₀ = atanh(u₀/U)/c`;
/// the heading is `θ₀ ± √(m/J)(U/c)[gd(c(t − t₀)) − gd(−c t₀)]`.
#[test]
fn chaplygin_sleigh_speeds_follow_tanh_and_sech() {
    let (mass, inertia, d) = (1.0, 0.05, -0.3);
    let (theta0, u0, w0): (f64, f64, f64) = (0.4, 0.2, 1.5);
    let mut m = Mechanism::new([0.0, 0.0]);
    let sleigh = m.rigid("sleigh", mass, inertia, [0.0, 0.0], theta0);
    let (s, c) = theta0.sin_cos();
    let lateral = -d * w0;
    m.bodies[0].velocity = [u0 * c - lateral * s, u0 * s + lateral * c];
    m.bodies[0].angular_velocity = w0;
    m.add(Element::KnifeEdge { body: sleigh, point: [d, 0.0], blade: [1.0, 0.0] });

    let j = inertia + mass * d * d;
    let big_u = (u0 * u0 + j * w0 * w0 / mass).sqrt();
    let rate = mass * d * big_u / j;
    let t0 = (u0 / big_u).atanh() / rate;
    let scale = w0.signum() * (mass / j).sqrt() * big_u;
    let gd = |x: f64| x.sinh().atan();
    let exact = |t: f64| {
        let x = rate * (t - t0);
        (-big_u * x.tanh(), scale / x.cosh(), theta0 + scale / rate * (gd(x) - gd(-rate * t0)))
    };
    let b = m.build().unwrap();
    for (name, control) in [("none", Control::none()), ("robust", methods::robust())] {
        let mut sim =
            Simulation::new(&b.model, Settings::new(Scheme::RungeKutta4, 1e-3, control), &b.q0, &b.v0).unwrap();
        let (mut err_u, mut err_w, mut err_theta) = (0.0_f64, 0.0_f64, 0.0_f64);
        while sim.t() < 20.0 {
            sim.step().unwrap();
            let (q, v) = (sim.q(), sim.v());
            let (s, c) = q[2].sin_cos();
            let (u, w, theta) = exact(sim.t());
            err_u = err_u.max((v[0] * c + v[1] * s - u).abs());
            err_w = err_w.max((v[2] - w).abs());
            err_theta = err_theta.max((q[2] - theta).abs());
            // The lateral speed at the centre of mass is −d w.
            assert!((-v[0] * s + v[1] * c + d * v[2]).abs() < 1e-9, "{name}");
        }
        let (u_end, w_end, _) = exact(20.0);
        println!(
            "{name:8} max error u {err_u:.3e}  w {err_w:.3e}  θ {err_theta:.3e}  (u → {u_end:.6}, w → {w_end:.3e})"
        );
        assert!(err_u < 1e-9 && err_w < 1e-9 && err_theta < 1e-9, "{name}: {err_u:.3e} {err_w:.3e} {err_theta:.3e}");
        // The motion is the tanh/sech one and not a trivial one: it has spun down.
        assert!((u_end - big_u).abs() < 1e-3 * big_u && w_end.abs() < 1e-2 * w0);
    }
}

#[test]
fn bad_knife_edges_name_the_element() {
    let mut m = Mechanism::new([0.0, -1.0]);
    let sled = m.rigid("sled", 1.0, 0.1, [0.0, 0.0], 0.0);
    m.add(Element::KnifeEdge { body: sled, point: [0.0, 0.0], blade: [0.0, 0.0] });
    let err = m.build().err().unwrap().to_string();
    assert!(err.contains("element 0 (knife_edge)") && err.contains("|blade|"), "{err}");
    assert!(!err.contains('\n'), "{err}");

    let mut m = Mechanism::new([0.0, -1.0]);
    let bob = m.point("bob", 1.0, [0.0, 0.0]);
    m.add(Element::KnifeEdge { body: bob, point: [0.0, 0.0], blade: [1.0, 0.0] });
    let err = m.build().err().unwrap().to_string();
    assert!(err.contains("element 0 (knife_edge)") && err.contains("point mass"), "{err}");

    let mut m = Mechanism::new([0.0, -1.0]);
    m.rigid("sled", 1.0, 0.1, [0.0, 0.0], 0.0);
    m.add(Element::KnifeEdge { body: BodyId::Ground, point: [0.0, 0.0], blade: [1.0, 0.0] });
    let err = m.build().err().unwrap().to_string();
    assert!(err.contains("element 0 (knife_edge)") && err.contains("ground"), "{err}");

    let mut m = Mechanism::new([0.0, -1.0]);
    let sled = m.rigid("sled", 1.0, 0.1, [0.0, 0.0], 0.0);
    m.add(Element::KnifeEdge { body: sled, point: [f64::NAN, 0.0], blade: [1.0, 0.0] });
    let err = m.build().err().unwrap().to_string();
    assert!(err.contains("element 0 (knife_edge)") && err.contains("point"), "{err}");
}

/// The kinematic bicycle with its steering held: a frame on a rear knife
/// edge, a front wheel pinned to it at the fixed steering angle `δ` on a
/// knife edge of its own (holonomic and nonholonomic rows together). The
/// rear contact runs on a circle of radius `L / tan δ` at constant speed.
#[test]
fn a_bicycle_with_fixed_steering_drives_in_a_circle() {
    let (l, delta, u): (f64, f64, f64) = (1.2, 0.3, 2.0);
    let omega = u * delta.tan() / l;
    let radius = l / delta.tan();
    let mut m = Mechanism::new([0.0, 0.0]);
    let frame = m.rigid("frame", 1.0, 0.1, [0.0, 0.0], 0.0);
    let wheel = m.rigid("wheel", 0.5, 0.01, [l / 2.0, 0.0], delta);
    m.bodies[0].velocity = [u, omega * l / 2.0];
    m.bodies[0].angular_velocity = omega;
    m.bodies[1].velocity = [u, omega * l];
    m.bodies[1].angular_velocity = omega;
    m.add(Element::KnifeEdge { body: frame, point: [-l / 2.0, 0.0], blade: [1.0, 0.0] });
    m.add(Element::Revolute { a: frame, pa: [l / 2.0, 0.0], b: wheel, pb: [0.0, 0.0], limit: None });
    m.add(Element::FixedAngle { a: frame, b: wheel, angle: delta });
    m.add(Element::KnifeEdge { body: wheel, point: [0.0, 0.0], blade: [1.0, 0.0] });
    let b = m.build().unwrap();
    let centre = [-l / 2.0, radius];
    let lap = 2.0 * std::f64::consts::PI / omega;
    for (name, control) in [("none", Control::none()), ("robust", methods::robust())] {
        let mut sim =
            Simulation::new(&b.model, Settings::new(Scheme::RungeKutta4, 1e-3, control), &b.q0, &b.v0).unwrap();
        let (mut err_r, mut err_w, mut worst) = (0.0_f64, 0.0_f64, 0.0_f64);
        while sim.t() < lap {
            sim.step().unwrap();
            let (q, v) = (sim.q(), sim.v());
            let rear = [q[0] - l / 2.0 * q[2].cos(), q[1] - l / 2.0 * q[2].sin()];
            err_r = err_r.max(((rear[0] - centre[0]).hypot(rear[1] - centre[1]) - radius).abs());
            err_w = err_w.max((v[2] - omega).abs());
            let m = sim.measure();
            worst = worst.max(m.phi.abs().max(m.phi_dot));
        }
        println!("bicycle {name:8} radius error {err_r:.3e}  turning rate error {err_w:.3e}  max |Φ|, |Φ̇| {worst:.3e}");
        assert!(err_r < 1e-9 && err_w < 1e-9 && worst < 1e-9, "{name}: {err_r:.3e} {err_w:.3e} {worst:.3e}");
    }
}
