//! RATTLE's energy over long runs: the largest `|E − E₀|` in each decade
//! of steps, on Example 1 and on hanging chains, beside AB-3 without
//! control and AB-3 with `robust`, with the wall time per step of each.
//!
//! `cargo run --release -p cdyn --example rattle_energy [STEPS]` (default 10⁶;
//! the chain of 1 000 runs a tenth of them).

use cdyn::models::{ChainParams, Example, PendulumParams, cartesian_pendulum, chain};
use cdyn::{Control, Scheme, Settings, Simulation, methods};
use std::time::Instant;

/// Max |E − E₀| in each decade of steps (1–10, 10–100, …), and µs per step.
fn bands(ex: &Example, settings: Settings, steps: u64) -> (Vec<f64>, f64) {
    let mut sim = Simulation::new(&ex.model, settings, &ex.q0, &ex.v0).unwrap();
    let (mut out, mut worst, mut next, mut stepping) = (Vec::new(), 0.0_f64, 10, 0.0);
    while sim.steps() < steps {
        let clock = Instant::now();
        sim.step().unwrap();
        stepping += clock.elapsed().as_secs_f64();
        let e = ex.model.kinetic(sim.q(), sim.v()) + ex.model.potential(sim.q(), None) - sim.initial_energy();
        worst = worst.max((e - sim.energy_input()).abs());
        if sim.steps() == next {
            out.push(std::mem::take(&mut worst));
            next *= 10;
        }
    }
    (out, stepping / steps as f64 * 1e6)
}

fn main() {
    let steps: u64 = std::env::args().nth(1).map_or(1_000_000, |s| s.parse().expect("STEPS: a whole number"));
    let pendulum = cartesian_pendulum(PendulumParams::default()).unwrap();
    let chain_of = |n| chain(ChainParams::default().with_n(n).with_theta0(0.8)).unwrap();
    let cases = [("Example 1", pendulum, 0.01, steps), ("chain 100", chain_of(100), 1e-3, steps)];
    let cases = cases.into_iter().chain([("chain 1000", chain_of(1000), 1e-3, steps / 10)]);
    for (name, ex, h, steps) in cases {
        println!("{name}, h = {h}, {steps} steps: max |E − E₀| per decade of steps");
        for (label, settings) in [
            ("rattle", Settings::new(Scheme::Rattle, h, Control::none())),
            ("ab3 none", Settings::new(Scheme::AdamsBashforth3, h, Control::none())),
            ("ab3 robust", Settings::new(Scheme::AdamsBashforth3, h, methods::robust())),
        ] {
            let (band, us) = bands(&ex, settings, steps);
            let band: Vec<String> = band.iter().map(|e| format!("{e:.2e}")).collect();
            println!("  {label:11} {us:9.3} µs/step  {}", band.join(" "));
        }
    }
}
