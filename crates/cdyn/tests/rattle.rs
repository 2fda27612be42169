//! RATTLE (`Scheme::Rattle`): one step against the pendulum's closed-form
//! SHAKE root, `Φ` and `Φ̇` at round-off after every step on fixed, driven
//! and nonholonomic mechanisms, order 2 where the mass depends on `q`, the
//! energy in a bounded band over long runs where AB-3's drifts, and the
//! combinations it refuses.

use cdyn::models::{
    ChainParams, DampedPendulumParams, Example, FourBarParams, PendulumParams, SliderCrankParams, cartesian_pendulum,
    chain, damped_pendulum, four_bar, slider_crank, small_pendulum,
};
use cdyn::small::SmallSimulation;
use cdyn::{Control, Error, Model, Scheme, Settings, Simulation, methods};

fn rattle(h: f64) -> Settings {
    Settings::new(Scheme::Rattle, h, Control::none())
}

/// `E − E₀` (with the work of non-conservative forces) of a state.
fn energy_error(model: &Model, sim: &Simulation) -> f64 {
    model.kinetic(sim.q(), sim.v()) + model.potential(sim.q(), None) - sim.initial_energy() - sim.energy_input()
}

#[test]
fn one_step_of_the_pendulum_is_the_closed_form_shake_root_then_the_tangent_velocity() {
    // Unit mass on a rod of length L from the origin, gravity g along −y:
    // M⁻¹Φ_qᵀ ∝ q, so the position step moves q̃ = q₀ + h v₀ + h²/2 g
    // along q₀ to the circle, and the velocity step removes the radial part.
    let p = PendulumParams::default().with_theta0(-0.4).with_omega0(1.3).with_gravity(9.81).with_length(0.7);
    let ex = cartesian_pendulum(p).unwrap();
    let h = 0.05;
    let mut sim = Simulation::new(&ex.model, rattle(h), &ex.q0, &ex.v0).unwrap();
    sim.step().unwrap();
    let (q0, v0, g, l) = (&ex.q0, &ex.v0, [0.0, -p.gravity], p.length);
    let c: Vec<f64> = (0..2).map(|i| q0[i] + h * v0[i] + 0.5 * h * h * g[i]).collect();
    let cq = c[0] * q0[0] + c[1] * q0[1];
    let cc = c[0] * c[0] + c[1] * c[1];
    let s = (cq - (cq * cq - l * l * (cc - l * l)).sqrt()) / (l * l);
    let q1: Vec<f64> = (0..2).map(|i| c[i] - s * q0[i]).collect();
    let kicked: Vec<f64> = (0..2).map(|i| (q1[i] - q0[i]) / h + 0.5 * h * g[i]).collect();
    let radial = (kicked[0] * q1[0] + kicked[1] * q1[1]) / (l * l);
    let v1: Vec<f64> = (0..2).map(|i| kicked[i] - radial * q1[i]).collect();
    for i in 0..2 {
        assert!((sim.q()[i] - q1[i]).abs() < 1e-14, "q[{i}] = {} against {}", sim.q()[i], q1[i]);
        assert!((sim.v()[i] - v1[i]).abs() < 1e-13, "v[{i}] = {} against {}", sim.v()[i], v1[i]);
    }
    assert_eq!(sim.evaluations(), 2, "the first step evaluates at q₀ and at q₁");
    sim.step().unwrap();
    assert_eq!(sim.evaluations(), 3, "then one evaluation a step");
}

/// Largest `|Φ|` and `|Φ̇|` after any of `steps` steps.
fn worst_violations(ex: &Example, h: f64, steps: u64) -> (f64, f64) {
    let mut sim = Simulation::new(&ex.model, rattle(h), &ex.q0, &ex.v0).unwrap();
    let (mut phi, mut phi_dot) = (0.0_f64, 0.0_f64);
    for _ in 0..steps {
        sim.step().unwrap();
        let m = sim.measure();
        (phi, phi_dot) = (phi.max(m.phi.abs()), phi_dot.max(m.phi_dot));
    }
    (phi, phi_dot)
}

#[test]
fn constraints_hold_to_round_off_after_every_step_on_fixed_and_driven_mechanisms() {
    let cases = [
        ("chain of 20", chain(ChainParams::default().with_n(20).with_theta0(0.6)).unwrap(), 2e-3),
        ("driven four-bar", four_bar(FourBarParams::default()).unwrap(), 1e-3),
        ("driven slider-crank", slider_crank(SliderCrankParams::default()).unwrap(), 1e-3),
    ];
    for (name, ex, h) in cases {
        let (phi, phi_dot) = worst_violations(&ex, h, 2000);
        println!("{name}: max |Φ| {phi:.2e}, max |Φ̇| {phi_dot:.2e}");
        // The position step's tolerance is 256 ε × the largest coordinate (20 on the chain).
        assert!(phi < 2e-12 && phi_dot < 1e-13, "{name}: |Φ| {phi:.2e}, |Φ̇| {phi_dot:.2e}");
    }
}

/// Max |E − E₀| over steps `[from, to)`.
fn energy_band(ex: &Example, settings: Settings, windows: &[u64]) -> Vec<f64> {
    let mut sim = Simulation::new(&ex.model, settings, &ex.q0, &ex.v0).unwrap();
    windows
        .windows(2)
        .map(|w| {
            let mut worst = 0.0_f64;
            while sim.steps() < w[1] {
                sim.step().unwrap();
                if sim.steps() >= w[0] {
                    worst = worst.max(energy_error(&ex.model, &sim).abs());
                }
            }
            worst
        })
        .collect()
}

fn show(x: &[f64]) -> String {
    x.iter().map(|x| format!("{x:.3e}")).collect::<Vec<_>>().join(", ")
}

#[test]
fn the_energy_stays_in_a_band_where_ab3s_drifts() {
    // Example 1 at h = 0.01 over 100 000 steps (1 000 s, about 300 periods)
    // and a chain of 10 at h = 0.01 over 20 000: RATTLE's largest |E − E₀|
    // in the last window is that of the first (a band set by h², not by
    // the time), while AB-3's without control grows with the time.
    let pendulum = cartesian_pendulum(PendulumParams::default()).unwrap();
    let chain = chain(ChainParams::default().with_n(10).with_theta0(0.8)).unwrap();
    for (name, ex, windows) in
        [("Example 1", &pendulum, [0, 10_000, 90_000, 100_000]), ("chain", &chain, [0, 2_000, 18_000, 20_000])]
    {
        let ab3 = Settings::new(Scheme::AdamsBashforth3, 0.01, Control::none());
        let (band, ab3) = (energy_band(ex, rattle(0.01), &windows), energy_band(ex, ab3, &windows));
        println!("{name}: max |E − E₀| by window, RATTLE {}, AB-3 {}", show(&band), show(&ab3));
        assert!(band[2] < 1.5 * band[0] && band[0] > 0.0, "{name}: RATTLE's band grows: {}", show(&band));
        assert!(ab3[2] > 3.0 * ab3[0], "{name}: AB-3 drifts, as the comparison assumes: {}", show(&ab3));
    }
}

#[test]
fn rattle_refuses_control_laws_in_the_right_hand_side_and_small_systems() {
    let ex = cartesian_pendulum(PendulumParams::default()).unwrap();
    let robust = Settings::new(Scheme::Rattle, 0.01, methods::robust());
    let e = Simulation::new(&ex.model, robust, &ex.q0, &ex.v0).err().unwrap();
    assert!(matches!(e, Error::Unsupported(m) if m.contains("rattle")), "{e}");
    let projection = Settings::new(Scheme::Rattle, 0.01, methods::projection());
    let mut sim = Simulation::new(&ex.model, projection, &ex.q0, &ex.v0).unwrap();
    for _ in 0..100 {
        sim.step().unwrap();
    }
    assert!(sim.measure().psi.abs() < 1e-10, "projection holds the energy after RATTLE's steps");
    let (small, q0, v0) = small_pendulum(PendulumParams::default()).unwrap();
    let e = SmallSimulation::new(small, rattle(0.01), q0, v0).err().unwrap();
    assert!(matches!(e, Error::Unsupported(m) if m.contains("SmallSimulation")), "{e}");
}

/// Max |q − q_ref| at `t_end` of a run with step `h`.
fn end_error(model: &Model, q0: &[f64], v0: &[f64], h: f64, t_end: f64, reference: &[f64]) -> f64 {
    let mut sim = Simulation::new(model, rattle(h), q0, v0).unwrap();
    sim.run::<Error>(t_end, u64::MAX, |_| Ok(())).unwrap();
    sim.q().iter().zip(reference).fold(0.0, |a, (q, r)| a.max((q - r).abs()))
}

#[test]
fn order_two_with_a_damper_against_the_fine_reference() {
    // The damper's force depends on v, so it is evaluated with the predicted velocity.
    let ex = damped_pendulum(DampedPendulumParams::default()).unwrap();
    let worst = |h: f64| {
        let mut sim = Simulation::new(&ex.model, rattle(h), &ex.q0, &ex.v0).unwrap();
        let mut worst = 0.0_f64;
        sim.run::<Error>(2.0, 1, |s| {
            worst = worst.max(ex.error(s.q(), s.v(), s.t()).unwrap().abs());
            Ok(())
        })
        .unwrap();
        worst
    };
    let errors = [worst(4e-3), worst(2e-3), worst(1e-3)];
    for w in errors.windows(2) {
        let order = (w[0] / w[1]).log2();
        assert!((order - 2.0).abs() < 0.15, "damped pendulum: errors {}, order {order:.2}", show(&errors));
    }
}

#[test]
fn order_two_where_the_mass_depends_on_q() {
    // A spatial chain in Euler parameters (block M(q), velocity-dependent
    // Lagrange terms): against RATTLE at h/64, halving h divides the error by 4.
    let cdyn::spatial::Built { model, q0, v0, .. } = cdyn::spatial::chain(3, 0.3, 1.0).build().unwrap();
    let (h, t_end) = (0.01, 0.4);
    let mut fine = Simulation::new(&model, rattle(h / 64.0), &q0, &v0).unwrap();
    fine.run::<Error>(t_end, u64::MAX, |_| Ok(())).unwrap();
    let errors: Vec<f64> =
        [h, h / 2.0, h / 4.0].iter().map(|&h| end_error(&model, &q0, &v0, h, t_end, fine.q())).collect();
    for w in errors.windows(2) {
        let order = (w[0] / w[1]).log2();
        assert!((order - 2.0).abs() < 0.2, "spatial chain: errors {}, order {order:.2}", show(&errors));
    }
}
