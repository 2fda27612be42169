//! Andrews' squeezing mechanism against the published values of the Test
//! Set for IVP Solvers: accelerations and multipliers at t = 0, and the
//! positions at t = 0.03.

use cdyn::dynamics::Dynamics;
use cdyn::models::andrews::{CLOSURE_ROWS, andrews, body_angles, constants, test_set_angles};
use cdyn::simulate::generalized_alpha::GeneralizedAlpha;
use cdyn::{Control, Error, Scheme, Settings, Simulation};

#[test]
fn initial_accelerations_and_multipliers_match_the_test_set() {
    let ex = andrews().unwrap();
    let mut d = Dynamics::new(&ex.model);
    d.evaluate(&ex.model, &ex.q0, &ex.v0, 0.0).unwrap();
    let acc = test_set_angles(body_angles(d.acc()));
    for (i, (a, r)) in acc.iter().zip(constants::ACC0).enumerate() {
        // Zeros are zero only to the round-off of a 1e4-sized solve.
        assert!((a - r).abs() <= 1e-12 * 14222.0, "q̈[{i}] = {a} vs published {r}");
    }
    for (i, (l, r)) in d.lambda()[CLOSURE_ROWS].iter().zip(constants::LAMBDA0).enumerate() {
        assert!((l - r).abs() <= 1e-12 * 98.6, "λ[{i}] = {l} vs published {r}");
    }
}

fn angles_at_end(scheme: Scheme, h: f64, control: Control) -> [f64; 7] {
    angles_with(Settings::new(scheme, h, control))
}

fn angles_with(settings: Settings) -> [f64; 7] {
    let ex = andrews().unwrap();
    let mut sim = Simulation::new(&ex.model, settings, &ex.q0, &ex.v0).unwrap();
    sim.run::<Error>(0.03, u64::MAX, |_| Ok(())).unwrap();
    assert!((sim.t() - 0.03).abs() < 1e-15);
    test_set_angles(body_angles(sim.q()))
}

fn relative_error(q: [f64; 7]) -> f64 {
    let r = constants::Q_REF_003;
    let num: f64 = q.iter().zip(r).map(|(a, b)| (a - b).powi(2)).sum::<f64>().sqrt();
    num / r.iter().map(|b| b * b).sum::<f64>().sqrt()
}

#[test]
fn positions_at_t_003_match_the_published_reference() {
    // RK-4, h = 1e-5 (3000 steps, no stabilization): the issue asks for a
    // relative error of 1e-6 or better; every component is far inside it
    // (measured: at most 2.7e-8 relative, on γ; 5e-10 in the norm).
    let q = angles_at_end(Scheme::RungeKutta4, 1e-5, Control::none());
    for (i, (a, b)) in q.iter().zip(constants::Q_REF_003).enumerate() {
        assert!(((a - b) / b).abs() < 1e-6, "q[{i}] = {a:.16e}, published {b:.16e}");
    }
    let err = relative_error(q);
    assert!(err < 1e-8, "relative error of the position vector {err:e}");
    // And the error is the scheme's: halving h divides it by about 2⁴.
    let coarse = relative_error(angles_at_end(Scheme::RungeKutta4, 2e-5, Control::none()));
    assert!((coarse / err).log2() > 3.5, "errors {coarse:e} (2e-5) and {err:e} (1e-5)");
}

#[test]
fn generalized_alpha_converges_at_order_2_with_the_trapezoidal_rules_error() {
    // Andrews' squeezer is fast (the motor turns body 1 at up to ~1000
    // rad/s) but not stiff for the explicit schemes: RK-4 runs up to h =
    // 1.5e-3 and diverges from 2e-3, while its accuracy asks far less
    // (relative error 4.5e-6 at 1e-4, 8e-5 at 2e-4). An order-2 scheme
    // cannot take larger steps than that here: generalized-α at 1e-5 is
    // 6.2e-6 off the published positions (1.5e-4 at 5e-5, 6.2e-4 at 1e-4).
    let alpha = |h, rho_inf| {
        Settings::new(Scheme::GeneralizedAlpha, h, Control::none())
            .with_generalized_alpha(GeneralizedAlpha::new().with_rho_inf(rho_inf))
    };
    let fine = relative_error(angles_with(alpha(1e-5, 0.9)));
    let coarse = relative_error(angles_with(alpha(2e-5, 0.9)));
    eprintln!("generalized-α ρ∞ = 0.9: relative error {fine:e} at 1e-5, {coarse:e} at 2e-5");
    assert!(fine < 1e-5, "{fine:e}");
    let order = (coarse / fine).log2();
    assert!((order - 2.0).abs() < 0.05, "observed order {order}");
    // Neither the numerical damping nor the start-up makes it: with ρ∞ = 1
    // (none, and α_m = α_f, so that a₀ = q̈₀ starts it exactly) the error
    // is within 2 % of it. It is the trapezoidal rule's (ρ∞ = 1 is
    // Newmark's average acceleration), whose period error (ωh)²/12 is twice
    // Störmer–Verlet's (ωh)²/24: RATTLE at the same step is 2.0× closer.
    let undamped = relative_error(angles_with(alpha(1e-5, 1.0)));
    let rattle = relative_error(angles_at_end(Scheme::Rattle, 1e-5, Control::none()));
    eprintln!("ρ∞ = 1: {undamped:e}; RATTLE: {rattle:e}");
    assert!((fine / undamped - 1.0).abs() < 0.02, "{fine:e} against {undamped:e}");
    let ratio = undamped / rattle;
    assert!((ratio - 2.0).abs() < 0.1, "generalized-α / RATTLE = {ratio}");
}
