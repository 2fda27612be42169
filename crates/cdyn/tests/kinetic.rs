//! Configuration-dependent mass matrices from a kinetic energy `T(q, q̇)`:
//! `M(q)`, `∂T/∂q` and `Ṁq̇` by automatic differentiation against finite
//! differences and the closed form of the double pendulum in angles; the
//! double pendulum in angles against the same pendulum in Cartesian
//! coordinates (trajectory, observed order of RK-4, the energy constraint).

use cdyn::control::{Control, Energy, POSITION_WEIGHT, Rate};
use cdyn::integrate::Rhs;
use cdyn::linalg::mass::DenseMass;
use cdyn::model::kinetic::local;
use cdyn::models::{
    DoublePendulumKinetic, DoublePendulumParams, Example, FourBarParams, LoadPendulum, double_pendulum,
    double_pendulum_angles, four_bar, four_bar_angles,
};
use cdyn::simulate::system::ControlledSystem;
use cdyn::{Error, Model, Scheme, Settings, Simulation};
use proptest::prelude::*;

fn params(theta1: f64, theta2: f64) -> DoublePendulumParams {
    DoublePendulumParams::default()
        .with_m1(1.3)
        .with_m2(0.7)
        .with_l1(1.1)
        .with_l2(0.8)
        .with_theta1(theta1)
        .with_theta2(theta2)
        .with_omega1(0.4)
        .with_omega2(-0.9)
}

fn element(p: &DoublePendulumParams) -> DoublePendulumKinetic {
    DoublePendulumKinetic { m1: p.m1, m2: p.m2, l1: p.l1, l2: p.l2 }
}

/// `x` with `s` added to entry `k`. (A function, not a closure: with rustc
/// 1.95 at this profile's opt-level, the nested closure call
/// `shift(shift(v, 0, h), 0, -h)` returned `[h, 0]`, not `[0, 0]`.)
fn shift(x: [f64; 2], k: usize, s: f64) -> [f64; 2] {
    let mut y = x;
    y[k] += s;
    y
}

fn close(a: f64, b: f64, tol: f64) -> bool {
    (a - b).abs() <= tol * (1.0 + a.abs().max(b.abs()))
}

proptest! {
    #[test]
    fn mass_matrix_and_velocity_terms_from_t_agree_with_closed_form_and_differences(
        q in proptest::array::uniform2(-4.0..4.0f64),
        v in proptest::array::uniform2(-3.0..3.0f64),
    ) {
        let p = params(q[0], q[1]);
        let t = element(&p);
        let l = local(&t, q, v);
        // Closed form: M = [[(m₁+m₂)l₁², m₂l₁l₂c], [m₂l₁l₂c, m₂l₂²]], c = cos(θ₁ − θ₂).
        let c = (q[0] - q[1]).cos();
        let closed = [[(p.m1 + p.m2) * p.l1 * p.l1, p.m2 * p.l1 * p.l2 * c], [p.m2 * p.l1 * p.l2 * c, p.m2 * p.l2 * p.l2]];
        for i in 0..2 {
            for j in 0..2 {
                prop_assert!(close(l.mass[i][j], closed[i][j], 1e-14), "M[{i}][{j}]: AD {} vs {}", l.mass[i][j], closed[i][j]);
            }
        }
        // T = ½ vᵀ M v.
        let tv = 0.5 * (0..2).map(|i| (0..2).map(|j| v[i] * closed[i][j] * v[j]).sum::<f64>()).sum::<f64>();
        prop_assert!(close(l.energy, tv, 1e-14), "T {} vs ½vᵀMv {tv}", l.energy);
        // Finite differences of T: M_ij = ∂²T/∂v_i∂v_j, ∂T/∂q, and Ṁv = (d/ds) M(q + s v) v.
        let f = |q: [f64; 2], v: [f64; 2]| cdyn::Kinetic::energy(&t, q, v);
        let h = 1e-4;
        for i in 0..2 {
            for j in 0..2 {
                let fd = (f(q, shift(shift(v, i, h), j, h)) - f(q, shift(shift(v, i, h), j, -h))
                    - f(q, shift(shift(v, i, -h), j, h)) + f(q, shift(shift(v, i, -h), j, -h))) / (4.0 * h * h);
                prop_assert!(close(l.mass[i][j], fd, 1e-6), "M[{i}][{j}]: AD {} vs FD {fd}", l.mass[i][j]);
            }
            let fd = (f(shift(q, i, h), v) - f(shift(q, i, -h), v)) / (2.0 * h);
            prop_assert!(close(l.grad_q[i], fd, 1e-7), "∂T/∂q[{i}]: AD {} vs FD {fd}", l.grad_q[i]);
        }
        let along = |s: f64| local(&t, [q[0] + s * v[0], q[1] + s * v[1]], v).mass;
        let (plus, minus) = (along(h), along(-h));
        for i in 0..2 {
            let fd: f64 = (0..2).map(|j| (plus[i][j] - minus[i][j]) / (2.0 * h) * v[j]).sum();
            prop_assert!(close(l.mdot_v[i], fd, 1e-7), "(Ṁv)[{i}]: AD {} vs FD {fd}", l.mdot_v[i]);
        }
    }
}

#[test]
fn the_model_assembles_the_elements_mass_and_refuses_a_singular_one() {
    let ex = double_pendulum_angles(params(0.3, -0.2)).unwrap();
    let (q, v) = ([0.3, -0.2], [0.4, -0.9]);
    let mut mass = DenseMass::new(2);
    let (mut grad, mut mdot) = ([0.0; 2], [0.0; 2]);
    let energy = ex.model.mass_at(&q, &v, &mut mass, &mut grad, &mut mdot).unwrap();
    let l = local(&element(&params(0.3, -0.2)), q, v);
    assert_eq!(mass.matrix(), l.mass.as_flattened());
    assert_eq!((grad, mdot, energy), (l.grad_q, l.mdot_v, l.energy));
    assert_eq!(ex.model.kinetic(&q, &v), energy);
    // A coordinate with no inertia at all: M is singular, a typed error at the first step.
    struct OnlyFirst;
    impl cdyn::Kinetic<2> for OnlyFirst {
        fn energy<D: cdyn::Scalar>(&self, _q: [D; 2], v: [D; 2]) -> D {
            v[0] * v[0] * 0.5
        }
    }
    let model = Model::builder(vec![0.0, 0.0]).kinetic(OnlyFirst, [0, 1]).build().unwrap();
    let err = Simulation::new(&model, Settings::new(Scheme::RungeKutta4, 0.01, Control::none()), &[0.0; 2], &[0.0; 2])
        .and_then(|mut s| s.step())
        .unwrap_err();
    assert!(matches!(err, Error::MassNotPositive { coordinate: 1, .. }), "{err}");
    // Negative diagonal masses are refused when the model is built.
    let err = Model::builder(vec![-1.0, 0.0]).kinetic(OnlyFirst, [0, 1]).build().err().unwrap();
    assert!(err.to_string().contains("mass"), "{err}");
}

/// Every `SAMPLE` of time to `t_end`: the tip `(bob2.x, bob2.y)` and `|Ψ|`.
fn run(ex: &Example, h: f64, control: Control, t_end: f64) -> Vec<([f64; 2], f64)> {
    let mut sim = Simulation::new(&ex.model, Settings::new(Scheme::RungeKutta4, h, control), &ex.q0, &ex.v0).unwrap();
    let mut out = Vec::new();
    let every = (SAMPLE / h).round() as u64;
    sim.run::<Error>(t_end, every, |s| {
        let o = ex.observe(s.t(), s.q(), s.v());
        out.push(([o[0], o[1]], s.measure().psi.abs()));
        Ok(())
    })
    .unwrap();
    out
}

/// Sampling interval of [`run`].
const SAMPLE: f64 = 0.04;

/// The largest distance between the tips of two runs sampled alike.
fn max_gap(a: &[([f64; 2], f64)], b: &[([f64; 2], f64)]) -> f64 {
    assert_eq!(a.len(), b.len());
    a.iter().zip(b).map(|(a, b)| distance(a.0, b.0)).fold(0.0, f64::max)
}

fn distance(a: [f64; 2], b: [f64; 2]) -> f64 {
    (a[0] - b[0]).hypot(a[1] - b[1])
}

#[test]
fn angles_and_cartesian_coordinates_give_the_same_motion_at_order_four() {
    // A regular (not chaotic) motion: both rods released at moderate angles.
    let p = DoublePendulumParams::default().with_theta1(0.8).with_theta2(0.3).with_omega1(0.0).with_omega2(1.0);
    let (angles, cartesian) = (double_pendulum_angles(p).unwrap(), double_pendulum(p).unwrap());
    let t_end = 4.0;
    let steps = [0.04, 0.02, 0.01, 0.00125];
    let runs = |ex: &Example| steps.map(|h| run(ex, h, Control::none(), t_end));
    let (a, c) = (runs(&angles), runs(&cartesian));
    let mut errors = Vec::new();
    for (name, runs) in [("angles", &a), ("cartesian", &c)] {
        // Max error against the finest run (whose own error is 2¹² times
        // smaller than at h = 0.01): halving h divides it by 2⁴.
        let e: Vec<f64> = runs[..3].iter().map(|r| max_gap(r, &runs[3])).collect();
        for w in e.windows(2) {
            let order = (w[0] / w[1]).log2();
            assert!((order - 4.0).abs() < 0.25, "{name}: errors {e:?}, observed order {order:.3}");
        }
        println!("{name}: RK-4 max tip errors at h = 0.04, 0.02, 0.01: {e:?}");
        errors.push(e[2] / 512.0);
    }
    // The two descriptions agree to their integration errors: at the finest
    // step each is within (its error at h = 0.01)/8⁴·(a margin of 8) of the
    // exact motion.
    let gap = max_gap(&a[3], &c[3]);
    let bound = errors[0] + errors[1];
    assert!(gap < bound, "tips differ by {gap:e}; integration errors {bound:e}");
    println!("RK-4 h = 0.00125, t ≤ {t_end}: max tip gap {gap:e}, integration error bound {bound:e}");
}

/// `Ψ = T + V − E₀ − e` of a model at the state `x = (q, v, e)`.
fn psi(model: &Model, x: &[f64], e0: f64) -> f64 {
    let n = model.n();
    model.kinetic(&x[..n], &x[n..2 * n]) + model.potential(&x[..n], None) - e0 - x[2 * n]
}

#[test]
fn the_energy_controls_set_the_same_decay_of_psi_in_both_coordinates() {
    // With E₀ off by 0.05 the energy laws must give Ψ̇ = −α Ψ in both
    // descriptions: Ψ̇ by central differences of Ψ along the controlled
    // flow f + U, which checks Ψ_v = (M v)ᵀ and Ψ_q = ∇V + ∂T/∂q.
    let alpha = 7.0;
    let projected = Energy::Projected { alpha_e: Rate::Given(alpha), position_weight: POSITION_WEIGHT };
    for energy in [projected, Energy::Baumgarte { eta: alpha }] {
        for (theta1, theta2, omega1, omega2) in [(1.0, 0.5, 0.3, -1.2), (-0.4, 2.0, 1.5, 0.2)] {
            let p = DoublePendulumParams::default()
                .with_theta1(theta1)
                .with_theta2(theta2)
                .with_omega1(omega1)
                .with_omega2(omega2);
            let mut rates = Vec::new();
            for ex in [double_pendulum_angles(p).unwrap(), double_pendulum(p).unwrap()] {
                let model = &ex.model;
                let e0 = model.kinetic(&ex.q0, &ex.v0) + model.potential(&ex.q0, None) + 0.05;
                let mut system = ControlledSystem::new(model, Control::none().with_energy(energy), e0);
                let x: Vec<f64> = ex.q0.iter().chain(&ex.v0).copied().chain([0.0]).collect();
                let (mut f, mut u) = (vec![0.0; x.len()], vec![0.0; x.len()]);
                system.eval(&x, 0.0, &mut f, Some(&mut u)).unwrap();
                let eps = 1e-6;
                let at = |s: f64| -> Vec<f64> { x.iter().zip(&f).zip(&u).map(|((x, f), u)| x + s * (f + u)).collect() };
                let rate = (psi(model, &at(eps), e0) - psi(model, &at(-eps), e0)) / (2.0 * eps);
                let expected = -alpha * psi(model, &x, e0);
                assert!(close(rate, expected, 1e-6), "n = {}, {energy:?}: Ψ̇ = {rate}, −αΨ = {expected}", model.n());
                rates.push(rate);
            }
            assert!(close(rates[0], rates[1], 1e-6), "{energy:?}: angles {} vs cartesian {}", rates[0], rates[1]);
        }
    }
}

#[test]
fn uncontrolled_energy_drift_is_the_integration_error_of_each() {
    // Ψ drifts only by the integration error: O(h⁴) with RK-4 in both.
    let p = DoublePendulumParams::default().with_theta1(1.0).with_theta2(0.5).with_omega1(0.0).with_omega2(0.0);
    for ex in [double_pendulum_angles(p).unwrap(), double_pendulum(p).unwrap()] {
        let worst = |h: f64| run(&ex, h, Control::none(), 4.0).iter().map(|s| s.1).fold(0.0, f64::max);
        let (coarse, fine) = (worst(0.02), worst(0.01));
        let order = (coarse / fine).log2();
        println!("n = {}: max |Ψ| over t ≤ 4 at h = 0.02, 0.01: {coarse:e}, {fine:e}", ex.model.n());
        // At least 4 (the angles' energy error is still partly O(h⁵) at these steps: 4.7 observed).
        assert!(order > 3.8, "n = {}: max |Ψ| {coarse:e}, {fine:e}: order {order:.2}", ex.model.n());
    }
}

/// Max |observable − reference| over a run for the first `k` observables,
/// and the observables at every `SAMPLE`.
fn against_reference(ex: &Example, h: f64, t_end: f64, k: usize) -> (f64, Vec<Vec<f64>>) {
    let settings = Settings::new(Scheme::RungeKutta4, h, Control::none());
    let mut sim = Simulation::new(&ex.model, settings, &ex.q0, &ex.v0).unwrap();
    let (mut worst, mut samples) = (0.0_f64, Vec::new());
    let every = (SAMPLE / h).round() as u64;
    let n = ex.model.n();
    let (mut qr, mut vr) = (vec![0.0; n], vec![0.0; n]);
    sim.run::<Error>(t_end, every, |s| {
        let reference = ex.reference.as_ref().unwrap();
        reference(s.t(), &mut qr, &mut vr);
        let (at, exact) = (ex.observe(s.t(), s.q(), s.v()), ex.observe(s.t(), &qr, &vr));
        worst = (0..k).map(|j| (at[j] - exact[j]).abs()).fold(worst, f64::max);
        samples.push(at);
        Ok(())
    })
    .unwrap();
    (worst, samples)
}

#[test]
fn four_bar_in_angles_follows_the_exact_kinematics_and_the_cartesian_model() {
    for load in [None, Some(LoadPendulum::default())] {
        let p = FourBarParams::default().with_load(load);
        let (angles, cartesian) = (four_bar_angles(p).unwrap(), four_bar(p).unwrap());
        assert_eq!((angles.model.n(), angles.model.m()), (3 + load.is_some() as usize, 3));
        let t_end = 3.0;
        let k = 3 + load.is_some() as usize;
        let mut finest = Vec::new();
        for (name, ex) in [("angles", &angles), ("cartesian", &cartesian)] {
            let runs: Vec<_> = [0.02, 0.01, 0.005].iter().map(|&h| against_reference(ex, h, t_end, k)).collect();
            let e: Vec<f64> = runs.iter().map(|r| r.0).collect();
            println!("four-bar {name}, load {}: max observable error at h = 0.02, 0.01, 0.005: {e:?}", load.is_some());
            // Order 4 against the exact kinematics and the load's fine reference.
            for w in e.windows(2) {
                let order = (w[0] / w[1]).log2();
                assert!(order > 3.75 || w[1] < 1e-11, "{name}: errors {e:?}, observed order {order:.2}");
            }
            finest.push((runs[2].1.clone(), e[2]));
        }
        // The observables of both (rocker angle, coupler angle, rocker rate,
        // load angle) agree within the sum of their errors at the finest step.
        let (a, c) = (&finest[0], &finest[1]);
        let gap = a.0.iter().zip(&c.0).flat_map(|(x, y)| (0..k).map(|j| (x[j] - y[j]).abs())).fold(0.0, f64::max);
        println!("four-bar, load {}: max observable gap {gap:e} (errors {:e}, {:e})", load.is_some(), a.1, c.1);
        assert!(gap <= a.1 + c.1, "gap {gap:e}, errors {:e} and {:e}", a.1, c.1);
    }
}
