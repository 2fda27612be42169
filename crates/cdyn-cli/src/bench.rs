//! `cdyn bench`: the cost of a step, measured in one run so that ratios
//! are meaningful on a shared machine.
//!
//! - Example 1, CVSGF + energy (Eq. 51, forward Euler control), AB-3:
//!   nanoseconds per step of cdyn and of the hand-written closed form
//!   (`cdyn::baseline`), interleaved trials, best of each; their ratio is
//!   cdyn's abstraction overhead.
//! - The N-link Cartesian chain (point masses on rods, total length 1 m,
//!   released at rest 0.5 rad from vertical; CVSGF + energy with
//!   hα_g = hα_e = 0.4, AB-3, h = 1e-3): microseconds per step, max |Φ|
//!   over the run, and the fitted exponent of cost against N.
//! - Allocations per step, counted by the binary's global allocator.

use crate::alloc_count::allocations;
use anyhow::Result;
use cdyn::baseline::HandWritten;
use cdyn::methods::{MethodGains, redundant_cases};
use cdyn::models::{ChainParams, PendulumParams, cartesian_pendulum, chain};
use cdyn::{Application, Control, Energy, EnergyGain, Gain, Geometric, Scheme, Settings, Simulation};
use serde::Serialize;
use std::hint::black_box;
use std::time::Instant;

#[derive(Debug, Serialize)]
pub struct Example1 {
    pub steps_per_trial: u64,
    pub trials: usize,
    pub cdyn_ns_per_step: f64,
    pub handwritten_ns_per_step: f64,
    /// cdyn / hand-written.
    pub overhead_ratio: f64,
    pub allocations_per_step: f64,
}

#[derive(Debug, Serialize)]
pub struct ChainRun {
    pub n: usize,
    pub steps: u64,
    pub us_per_step: f64,
    pub max_abs_phi: f64,
    pub allocations_per_step: f64,
    pub solver: &'static str,
}

#[derive(Debug, Serialize)]
pub struct Report {
    pub light: bool,
    pub example1: Example1,
    pub chain: Vec<ChainRun>,
    /// Least-squares slope of log(cost) against log(N) over N ≥ 100.
    pub chain_cost_exponent: Option<f64>,
    pub max_allocations_per_step: f64,
}

fn example1(light: bool) -> Result<Example1> {
    let (steps, trials) = if light { (20_000, 2) } else { (1_000_000, 7) };
    let ex = cartesian_pendulum(PendulumParams::default())?;
    let control = redundant_cases(&MethodGains::paper()).into_iter().find(|(n, _)| *n == "cvsgf_energy").unwrap().1;
    let settings = Settings::new(Scheme::AdamsBashforth3, 0.01, control);
    let (mut best_cdyn, mut best_hand, mut allocs) = (f64::INFINITY, f64::INFINITY, 0);
    for _ in 0..trials {
        let mut sim = Simulation::new(&ex.model, settings, &ex.q0, &ex.v0)?;
        let before = allocations();
        let start = Instant::now();
        for _ in 0..steps {
            // The pendulum keeps rotating; the state stays bounded for any number of steps.
            sim.step()?;
        }
        best_cdyn = best_cdyn.min(start.elapsed().as_secs_f64() / steps as f64);
        allocs = allocs.max(allocations() - before);
        black_box(sim.q());

        let mut hand = HandWritten::new([1.0, 0.0, 0.0, 2.0], 0.01, 20.0, 40.0);
        let start = Instant::now();
        for _ in 0..steps {
            hand.step();
            black_box(&hand.x);
        }
        best_hand = best_hand.min(start.elapsed().as_secs_f64() / steps as f64);
    }
    Ok(Example1 {
        steps_per_trial: steps,
        trials,
        cdyn_ns_per_step: best_cdyn * 1e9,
        handwritten_ns_per_step: best_hand * 1e9,
        overhead_ratio: best_cdyn / best_hand,
        allocations_per_step: allocs as f64 / steps as f64,
    })
}

fn chain_run(n: usize, t_end: f64) -> Result<ChainRun> {
    let h = 1e-3;
    let ex = chain(ChainParams { n, mass: 1.0, length: 1.0, gravity: 1.0, theta0: 0.3, omega0: 0.0 })?;
    let control = Control {
        geometric: Geometric::Gradient(Gain::Rate(0.4 / h)),
        energy: Energy::Gradient(EnergyGain::Rate { alpha_e: 0.4 / h }),
        application: Application::ForwardEuler,
    };
    let settings = Settings::new(Scheme::AdamsBashforth3, h, control);
    let mut sim = Simulation::new(&ex.model, settings, &ex.q0, &ex.v0)?;
    let steps = cdyn::simulate::steps_to(t_end, h)?;
    let mut phi = vec![0.0; ex.model.m()];
    let (mut worst, mut elapsed, mut allocs) = (0.0_f64, 0.0, 0);
    // Time the steps only; measure |Φ| every 10 steps outside the clock.
    while sim.steps() < steps {
        let before = allocations();
        let start = Instant::now();
        for _ in 0..10.min(steps - sim.steps()) {
            sim.step()?;
        }
        elapsed += start.elapsed().as_secs_f64();
        allocs += allocations() - before;
        ex.model.constraint_values(sim.q(), sim.t(), &mut phi);
        worst = phi.iter().fold(worst, |a, p| a.max(p.abs()));
    }
    let solver = if ex.model.m() >= cdyn::dynamics::SPARSE_FROM { "sparse" } else { "dense" };
    Ok(ChainRun {
        n,
        steps,
        us_per_step: elapsed / steps as f64 * 1e6,
        max_abs_phi: worst,
        allocations_per_step: allocs as f64 / steps as f64,
        solver,
    })
}

/// Slope of `ln y` against `ln x`.
fn fitted_exponent(points: &[(f64, f64)]) -> Option<f64> {
    if points.len() < 2 {
        return None;
    }
    let k = points.len() as f64;
    let (mx, my) = points.iter().fold((0.0, 0.0), |(a, b), (x, y)| (a + x.ln() / k, b + y.ln() / k));
    let (num, den) =
        points.iter().fold((0.0, 0.0), |(a, b), (x, y)| (a + (x.ln() - mx) * (y.ln() - my), b + (x.ln() - mx).powi(2)));
    Some(num / den)
}

/// Runs every measurement; `light` for a quick smoke run (CI), not for numbers.
pub fn run(light: bool) -> Result<Report> {
    let example1 = example1(light)?;
    let (sizes, t_end): (&[usize], f64) =
        if light { (&[10, 100, 1000], 0.05) } else { (&[10, 100, 1000, 10_000], 10.0) };
    let chain = sizes.iter().map(|&n| chain_run(n, t_end)).collect::<Result<Vec<_>>>()?;
    let fit: Vec<(f64, f64)> = chain.iter().filter(|c| c.n >= 100).map(|c| (c.n as f64, c.us_per_step)).collect();
    let max_allocations_per_step =
        chain.iter().map(|c| c.allocations_per_step).fold(example1.allocations_per_step, f64::max);
    Ok(Report { light, example1, chain_cost_exponent: fitted_exponent(&fit), chain, max_allocations_per_step })
}

/// The table printed on the terminal.
pub fn table(r: &Report) -> String {
    let e = &r.example1;
    let mut out = format!(
        "Example 1, cvsgf_energy, AB-3 ({} steps, best of {}):\n  cdyn        {:>9.1} ns/step\n  hand-written {:>8.1} ns/step\n  overhead     {:>8.2}×\n",
        e.steps_per_trial, e.trials, e.cdyn_ns_per_step, e.handwritten_ns_per_step, e.overhead_ratio
    );
    out += "N-link chain, CVSGF + energy, AB-3, h = 1e-3:\n";
    out += &format!("  {:>6} {:>8} {:>12} {:>12} {:>8}\n", "N", "steps", "µs/step", "max|Φ|", "solver");
    for c in &r.chain {
        out +=
            &format!("  {:>6} {:>8} {:>12.2} {:>12.3e} {:>8}\n", c.n, c.steps, c.us_per_step, c.max_abs_phi, c.solver);
    }
    if let Some(p) = r.chain_cost_exponent {
        out += &format!("  cost exponent (N ≥ 100): {p:.3}\n");
    }
    out += &format!("allocations per step (max): {}\n", r.max_allocations_per_step);
    out
}
