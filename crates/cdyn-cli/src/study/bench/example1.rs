//! Example 1 through cdyn (small and general) against hand-written code.

use super::*;
use anyhow::Result;
use cdyn::baseline::HandWritten;
use cdyn::control::methods::MethodGains;
use cdyn::models::{PendulumParams, cartesian_pendulum, small_pendulum};
use cdyn::small::SmallSimulation;
use cdyn::{Scheme, Settings, Simulation};
use serde::Serialize;
use std::hint::black_box;

/// Example 1 (`cvsgf_energy`, AB-3): cdyn as a `SmallSimulation` and as a general model against hand-written code.
#[derive(Debug, Serialize)]
pub struct Example1 {
    /// Every run starts afresh and lasts this many steps (100 s of motion:
    /// after some hundreds of seconds these gains let the pendulum drift
    /// into a spurious equilibrium, which would no longer be a benchmark
    /// of the motion).
    pub steps_per_run: u64,
    /// Runs per trial.
    pub runs_per_trial: u64,
    /// Interleaved trials; each figure is the best over them.
    pub trials: usize,
    /// cdyn's [`SmallSimulation`]: the system's size known at compile time.
    pub cdyn_ns_per_step: f64,
    /// cdyn's general [`Simulation`] of a [`cdyn::Model`] (run-time sizes, element blocks).
    pub general_ns_per_step: f64,
    /// The same step written out by hand ([`cdyn::baseline`]).
    pub handwritten_ns_per_step: f64,
    /// cdyn / hand-written.
    pub overhead_ratio: f64,
    /// general / hand-written.
    pub general_overhead_ratio: f64,
    /// The most allocations per step of any run (0 expected).
    pub allocations_per_step: f64,
}

pub(super) fn example1(light: bool) -> Result<Example1> {
    let (steps, runs, trials) = if light { (10_000, 2, 2) } else { (10_000, 50, 7) };
    let ex = cartesian_pendulum(PendulumParams::default())?;
    let (small, q0, v0) = small_pendulum(PendulumParams::default())?;
    let control = MethodGains::paper().cvsgf_energy();
    let settings = Settings::new(Scheme::AdamsBashforth3, 0.01, control);
    let [cdyn, general, hand] = [0, 1, 2];
    let (mut best, mut allocs) = ([f64::INFINITY; 3], 0);
    for _ in 0..trials {
        // Interleaved, so that a slow spell of the machine hits all three.
        let (seconds, a) =
            timed_runs(runs, steps, || Ok(SmallSimulation::new(small, settings, q0, v0)?), |s| Ok(s.step()?))?;
        best[cdyn] = best[cdyn].min(seconds);
        allocs = allocs.max(a);
        let (seconds, a) =
            timed_runs(runs, steps, || Ok(Simulation::new(&ex.model, settings, &ex.q0, &ex.v0)?), |s| Ok(s.step()?))?;
        best[general] = best[general].min(seconds);
        allocs = allocs.max(a);
        let start = || Ok(HandWritten::new([1.0, 0.0, 0.0, 2.0], 0.01, 20.0, 40.0));
        let (seconds, _) = timed_runs(runs, steps, start, |h| {
            h.step();
            black_box(&h.x);
            Ok(())
        })?;
        best[hand] = best[hand].min(seconds);
    }
    let ns = best.map(|s| s / (runs * steps) as f64 * 1e9);
    Ok(Example1 {
        steps_per_run: steps,
        runs_per_trial: runs,
        trials,
        cdyn_ns_per_step: ns[cdyn],
        general_ns_per_step: ns[general],
        handwritten_ns_per_step: ns[hand],
        overhead_ratio: ns[cdyn] / ns[hand],
        general_overhead_ratio: ns[general] / ns[hand],
        allocations_per_step: allocs as f64 / (runs * steps) as f64,
    })
}
