//! Generalized-α (`Scheme::GeneralizedAlpha`): one step of a linear
//! oscillator against the scheme's recurrence solved by hand, the damping
//! of a mode far above `1/h` per step equal to `ρ∞`, `Φ` at the Newton
//! tolerance on fixed, driven and nonholonomic mechanisms, the fixed
//! iteration count, Newton damped across a friction law's knee, and the
//! errors it gives. (Order 2: `convergence.rs`;
//! the stiff flyball governor at h = 1e-3: `spatial.rs`.)

use cdyn::models::{ChainParams, FourBarParams, chain, four_bar};
use cdyn::simulate::generalized_alpha::{GeneralizedAlpha, Newton};
use cdyn::{Control, Error, Force, Model, Potential, Scalar, Scheme, Settings, Simulation, methods};

/// `V = ½ k x²`.
struct Spring(f64);
impl Potential<1> for Spring {
    fn energy<D: Scalar>(&self, [x]: [D; 1]) -> D {
        x * x * (0.5 * self.0)
    }
}

/// `f = −c ẋ`.
struct Damper(f64);
impl Force<1> for Damper {
    fn force<D: Scalar>(&self, _x: [D; 1], [xd]: [D; 1], _t: D) -> [D; 1] {
        [xd * (-self.0)]
    }
}

/// A constant push `f₀` against regularized Coulomb friction:
/// `f = f₀ − μ ẋ / √(ẋ² + s²)`, the law of a URDF joint's `friction`.
struct PushedAgainstFriction {
    push: f64,
    mu: f64,
    slip: f64,
}
impl Force<1> for PushedAgainstFriction {
    fn force<D: Scalar>(&self, _x: [D; 1], [xd]: [D; 1], _t: D) -> [D; 1] {
        [-(xd / (xd * xd + self.slip * self.slip).sqrt() * self.mu) + self.push]
    }
}

fn alpha(h: f64, rho_inf: f64) -> Settings {
    Settings::new(Scheme::GeneralizedAlpha, h, Control::none())
        .with_generalized_alpha(GeneralizedAlpha::new().with_rho_inf(rho_inf))
}

fn oscillator(m: f64, k: f64, c: f64) -> Model {
    Model::builder(vec![m]).potential(Spring(k), [0]).force(Damper(c), [0]).build().unwrap()
}

#[test]
fn one_step_of_a_damped_oscillator_is_the_recurrence_solved_by_hand() {
    // m ẍ + c ẋ + k x = 0 is linear: Newton's matrix is exact, and the
    // step is the solution of the scheme's linear equations for q̈₁.
    let (m, k, c, h, rho) = (2.0, 50.0, 3.0, 0.1, 0.7);
    let model = oscillator(m, k, c);
    let (x0, v0) = (0.3, -1.1);
    let mut sim = Simulation::new(&model, alpha(h, rho), &[x0], &[v0]).unwrap();
    sim.step().unwrap();
    let alpha_m = (2.0 * rho - 1.0) / (rho + 1.0);
    let alpha_f = rho / (rho + 1.0);
    let gamma = 0.5 + alpha_f - alpha_m;
    let beta = 0.25 * (gamma + 0.5) * (gamma + 0.5);
    let acc0 = -(c * v0 + k * x0) / m;
    // a₁ = ((1−α_f) q̈₁ + α_f q̈₀ − α_m q̈₀)/(1−α_m), x₁, v₁ linear in q̈₁.
    let a1 = |acc1: f64| ((1.0 - alpha_f) * acc1 + (alpha_f - alpha_m) * acc0) / (1.0 - alpha_m);
    let x1 = |acc1: f64| x0 + h * v0 + h * h * ((0.5 - beta) * acc0 + beta * a1(acc1));
    let v1 = |acc1: f64| v0 + h * ((1.0 - gamma) * acc0 + gamma * a1(acc1));
    let residual = |acc1: f64| m * acc1 + c * v1(acc1) + k * x1(acc1);
    // Linear in q̈₁: the root from two values.
    let (r0, r1) = (residual(0.0), residual(1.0));
    let acc1 = -r0 / (r1 - r0);
    assert!((sim.q()[0] - x1(acc1)).abs() < 1e-14, "{} against {}", sim.q()[0], x1(acc1));
    assert!((sim.v()[0] - v1(acc1)).abs() < 1e-13, "{} against {}", sim.v()[0], v1(acc1));
    assert_eq!(sim.newton_iterations(), 1, "a linear problem converges in one correction");
}

#[test]
fn a_mode_far_above_one_over_h_is_damped_by_rho_inf_per_step() {
    // h ω = 1000: the amplification matrix's spectral radius is ρ∞ to
    // O(1/(hω)). For ρ∞ < 1 its eigenvalue there is −ρ∞, double with one
    // eigenvector, so the amplitude (energy^½) after k steps is ∝ k ρ∞ᵏ:
    // from step 5 to 15 it falls by 3 ρ∞¹⁰ (measured while it stays far
    // above the Newton tolerance, 1e-10). With ρ∞ = 1 the roots are a
    // distinct pair on the unit circle: no decay.
    for rho in [0.0, 0.3, 0.5, 0.9, 1.0] {
        let (h, omega) = (0.01, 1e5);
        let model = oscillator(1.0, omega * omega, 0.0);
        let mut sim = Simulation::new(&model, alpha(h, rho), &[1.0], &[0.0]).unwrap();
        let amplitude = |s: &Simulation| (s.v()[0].powi(2) / (omega * omega) + s.q()[0].powi(2)).sqrt();
        for _ in 0..5 {
            sim.step().unwrap();
        }
        let a5 = amplitude(&sim);
        if rho == 0.0 {
            // Annihilated: what is left is O(1/(h ω)) of the start.
            assert!(a5 < 1e-3, "ρ∞ = 0: amplitude {a5:e} after 5 steps");
            continue;
        }
        for _ in 0..10 {
            sim.step().unwrap();
        }
        let ratio = (amplitude(&sim) / a5).powf(1.0 / 10.0);
        let expected = if rho < 1.0 { rho * 3f64.powf(0.1) } else { 1.0 };
        println!("ρ∞ = {rho}: amplitude ratio per step {ratio:.4}, expected {expected:.4}");
        assert!((ratio - expected).abs() < 2e-3, "ρ∞ = {rho}: {ratio} against {expected}");
    }
    // A mode well below 1/h (h ω = 0.05) keeps its energy to O(h³) a step.
    let model = oscillator(1.0, 1.0, 0.0);
    let mut sim = Simulation::new(&model, alpha(0.05, 0.9), &[1.0], &[0.0]).unwrap();
    sim.run::<Error>(10.0, 1, |_| Ok(())).unwrap();
    let energy = 0.5 * (sim.q()[0].powi(2) + sim.v()[0].powi(2));
    assert!((energy - 0.5).abs() < 1e-4, "E = {energy}");
}

#[test]
fn constraints_hold_to_the_newton_tolerance_after_every_step() {
    let cases = [
        ("chain of 20", chain(ChainParams::default().with_n(20).with_theta0(0.6)).unwrap(), 2e-3),
        ("driven four-bar", four_bar(FourBarParams::default()).unwrap(), 1e-3),
    ];
    for (name, ex, h) in cases {
        let mut sim = Simulation::new(&ex.model, alpha(h, 0.9), &ex.q0, &ex.v0).unwrap();
        let (mut phi, mut phi_dot) = (0.0_f64, 0.0_f64);
        for _ in 0..1000 {
            sim.step().unwrap();
            let m = sim.measure();
            (phi, phi_dot) = (phi.max(m.phi.abs()), phi_dot.max(m.phi_dot));
        }
        let per_step = sim.newton_iterations() as f64 / sim.steps() as f64;
        println!(
            "{name}: max |Φ| {phi:.2e}, max |Φ̇| {phi_dot:.2e}, {per_step:.2} corrections a step, left {:.1e}",
            sim.newton_correction()
        );
        // Positions to the tolerance (1e-10 × the largest coordinate); the
        // velocities follow the index-3 scheme, Φ̇ = O(h²) without drift.
        assert!(phi < 1e-9, "{name}: |Φ| {phi:.2e}");
        assert!(phi_dot < 1e-2, "{name}: |Φ̇| {phi_dot:.2e}");
        assert!(sim.newton_correction() < 1e-9 * 20.0, "{name}");
    }
}

#[test]
fn a_fixed_count_of_corrections_costs_the_same_every_step() {
    let ex = chain(ChainParams::default().with_n(10).with_theta0(0.6)).unwrap();
    let settings = alpha(2e-3, 0.9).with_generalized_alpha(GeneralizedAlpha::new().with_newton(Newton::fixed(2)));
    let mut sim = Simulation::new(&ex.model, settings, &ex.q0, &ex.v0).unwrap();
    sim.step().unwrap();
    let first = sim.evaluations();
    for _ in 0..99 {
        sim.step().unwrap();
    }
    assert_eq!(sim.newton_iterations(), 200);
    // Three evaluations a step (the predictor's, two corrections'), one more at the start.
    assert_eq!(sim.evaluations() - first, 99 * 3);
    assert!(sim.newton_correction() > 0.0 && sim.newton_correction() < 1e-8, "{}", sim.newton_correction());
}

#[test]
fn bad_settings_and_failed_iterations_are_errors_naming_the_cause() {
    let ex = chain(ChainParams::default().with_n(5).with_theta0(0.6)).unwrap();
    for rho in [-0.1, 1.5, f64::NAN] {
        let e = Simulation::new(&ex.model, alpha(1e-3, rho), &ex.q0, &ex.v0).err().unwrap();
        assert!(e.to_string().contains("rho_inf"), "{e}");
    }
    let e = Simulation::new(&ex.model, alpha(1e-3, 0.9).with_control(methods::robust()), &ex.q0, &ex.v0).err().unwrap();
    assert!(matches!(e, Error::Unsupported(_)), "{e}");
    // One correction allowed to an impossible tolerance: stops at the first step.
    let newton = Newton::converge(1e-300, 1);
    let settings = alpha(1e-2, 0.9).with_generalized_alpha(GeneralizedAlpha::new().with_newton(newton));
    let mut sim = Simulation::new(&ex.model, settings, &ex.q0, &ex.v0).unwrap();
    let e = sim.step().unwrap_err();
    assert!(matches!(e, Error::NewtonFailed { step: 1, iterations: 1, .. }), "{e}");
    assert!(e.to_string().contains("did not converge at step 1"), "{e}");
    // A Newton matrix singular with no constraint to blame: ρ∞ = 1 makes
    // c_q = h²β(1 − α_f)/(1 − α_m) = h²/4, so at h = 0.5 a spring of
    // k = −16 cancels a unit mass exactly: m + c_q k = 0.
    let model = oscillator(1.0, -16.0, 0.0);
    let mut sim = Simulation::new(&model, alpha(0.5, 1.0), &[0.1], &[0.0]).unwrap();
    let e = sim.step().unwrap_err();
    assert_eq!(e, Error::NewtonSingular { step: 1, t: 0.5, iterations: 0 });
    let text = e.to_string();
    assert!(text.contains("Newton matrix is singular at step 1, t = 0.5") && text.contains("take a smaller h"), "{e}");
    // A step of 0.25 is fine (the motion grows, as it should).
    let mut sim = Simulation::new(&model, alpha(0.25, 1.0), &[0.1], &[0.0]).unwrap();
    sim.step().unwrap();
    assert!(sim.q()[0] > 0.1);
    // Projection may follow it.
    let settings = alpha(2e-3, 0.9).with_control(methods::projection());
    let mut sim = Simulation::new(&ex.model, settings, &ex.q0, &ex.v0).unwrap();
    for _ in 0..100 {
        sim.step().unwrap();
    }
    let m = sim.measure();
    assert!(m.phi_dot < 1e-9 && m.psi.abs() < 1e-9, "projection holds Φ̇ and the energy after the steps: {m:?}");
}

/// A light body pushed against friction that holds it, from rest: the
/// first step's predictor (the push alone) throws the velocity far past
/// the friction law's knee, where its slope is ~0, and undamped Newton
/// went back and forth across the knee without converging (Z1's wrist
/// at h = 1e-4 stopped so at its second step). Damped, every step
/// converges, and the body creeps at the speed where friction balances the
/// push, `s f₀ / √(μ² − f₀²)`.
#[test]
fn newton_damps_its_corrections_across_a_friction_laws_knee() {
    let (push, mu, slip) = (0.5, 1.0, 0.01);
    let model = Model::builder(vec![1e-3]).force(PushedAgainstFriction { push, mu, slip }, [0]).build().unwrap();
    let mut sim = Simulation::new(&model, alpha(1e-3, 0.9), &[0.0], &[0.0]).unwrap();
    for _ in 0..200 {
        sim.step().unwrap();
    }
    let creep = slip * push / (mu * mu - push * push).sqrt();
    assert!((sim.v()[0] - creep).abs() < 1e-9 * creep, "{} against {creep}", sim.v()[0]);
}

#[test]
fn with_projection_a_driven_model_still_converges_at_order_2() {
    // The support is driven: the drives' work λᵀΦ_t enters the energy the
    // projection holds. Each projection moves the velocities across the
    // constraints by O(h²), which the next index-3 step answers with an
    // O(h) change of λ; integrated with that λ the energy input, and the
    // state held to it, were first order (the error halved with h).
    let ex = cdyn::models::moving_support_pendulum(cdyn::models::MovingSupportParams::default()).unwrap();
    // Positions every 10 ms over 2 s.
    let samples = |settings: Settings| {
        let mut sim = Simulation::new(&ex.model, settings, &ex.q0, &ex.v0).unwrap();
        let mut out = Vec::new();
        sim.run::<Error>(2.0, (0.01 / settings.h).round() as u64, |s| {
            out.push(s.q().to_vec());
            Ok(())
        })
        .unwrap();
        out
    };
    let reference = samples(Settings::new(Scheme::RungeKutta4, 1e-4, Control::none()));
    let error = |h: f64, control: Control| {
        let run = samples(alpha(h, 0.9).with_control(control));
        let far = |(a, b): (&Vec<f64>, &Vec<f64>)| a.iter().zip(b).fold(0.0_f64, |m, (x, y)| m.max((x - y).abs()));
        run.iter().zip(&reference).map(far).fold(0.0, f64::max)
    };
    let (coarse, fine) = (error(2e-3, methods::projection()), error(1e-3, methods::projection()));
    let none = error(1e-3, Control::none());
    println!("projection: {coarse:.2e} at 2e-3, {fine:.2e} at 1e-3; none {none:.2e} at 1e-3");
    // Measured: 8.5e-6 and 2.4e-6 (order 1.82), half of none's 5.1e-6;
    // before, 1.9e-3 and 9.7e-4 (order 0.93), 190× none's.
    let order = (coarse / fine).log2();
    assert!(order > 1.7, "observed order {order}");
    assert!(fine < none, "{fine:e} against none's {none:e}");
}
