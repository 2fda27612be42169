//! The methods timed against each other, interleaved.

use super::*;
use crate::io::alloc_count::allocations;
use anyhow::Result;
use cdyn::control::methods::{self, MethodGains};
use cdyn::models::{Example, PendulumParams, cartesian_pendulum};
use cdyn::{Control, Scheme, Settings, Simulation};
use serde::Serialize;
use std::time::Instant;

/// One method's cost on one model, over the interleaved trials of a [`MethodComparison`].
#[derive(Debug, Serialize)]
pub struct MethodCost {
    /// `cvsgf_energy`, `robust` or `projection` (AB-3), or `rattle` /
    /// `generalized_alpha` (those schemes, no control).
    pub method: &'static str,
    /// Median over the trials.
    pub us_per_step: f64,
    /// Median over the trials of this method's time over `cvsgf_energy`'s in the same trial.
    pub ratio_to_cvsgf_energy: f64,
    /// Newton iterations per step of the projection (`projection`), of
    /// RATTLE's position step (`rattle`), or generalized-α's corrections.
    pub iterations_per_step: Option<f64>,
    /// Largest `|Φ|` seen, sampled (outside the clock) every [`PHI_EVERY`] steps and at the end.
    pub max_abs_phi: f64,
    /// The most allocations per step of any run.
    pub allocations_per_step: f64,
}

/// The methods timed against each other on one model.
#[derive(Debug, Serialize)]
pub struct MethodComparison {
    /// `example1` (the Cartesian pendulum as a general model) or `chain`.
    pub model: &'static str,
    /// Bodies: 1 for Example 1, `N` for the chain.
    pub n: usize,
    /// Step size.
    pub h: f64,
    /// Every run starts afresh (set-up untimed) and lasts this many steps.
    pub steps_per_run: u64,
    /// Runs per trial.
    pub runs_per_trial: u64,
    /// Interleaved trials.
    pub trials: usize,
    /// In the order of [`METHODS`].
    pub methods: Vec<MethodCost>,
}

/// The methods compared, by name; the first is the one ratios are taken
/// to. The first three step with AB-3; `rattle` and `generalized_alpha`
/// are those schemes with no control, which hold the constraints themselves.
pub const METHODS: [&str; 5] = ["cvsgf_energy", "robust", "projection", "rattle", "generalized_alpha"];

/// Steps between samples of `|Φ|` in a [`MethodComparison`]: the clock is
/// read this often, which costs well under 1 % even of Example 1's step.
pub const PHI_EVERY: u64 = 100;

/// The middle value (the mean of the two middle ones for an even count).
pub(super) fn median(mut x: Vec<f64>) -> f64 {
    x.sort_by(f64::total_cmp);
    let k = x.len();
    if k % 2 == 1 { x[k / 2] } else { 0.5 * (x[k / 2 - 1] + x[k / 2]) }
}

/// What one fresh run of a method measured.
pub(super) struct MethodRun {
    seconds: f64,
    allocations: u64,
    max_abs_phi: f64,
    /// Of the projection, of RATTLE's position step, or generalized-α's corrections.
    iterations: u64,
}

/// One fresh run of `steps` steps of `ex` (set-up, including the automatic
/// gains, untimed), `|Φ|` sampled outside the clock.
pub(super) fn method_run(ex: &Example, settings: Settings, steps: u64, phi: &mut [f64]) -> Result<MethodRun> {
    let mut sim = Simulation::new(&ex.model, settings, &ex.q0, &ex.v0)?;
    let (mut seconds, mut allocs, mut worst) = (0.0, 0, 0.0_f64);
    while sim.steps() < steps {
        let before = allocations();
        let clock = Instant::now();
        for _ in 0..PHI_EVERY.min(steps - sim.steps()) {
            sim.step()?;
        }
        seconds += clock.elapsed().as_secs_f64();
        allocs += allocations() - before;
        ex.model.constraint_values(sim.q(), sim.t(), phi);
        worst = phi.iter().fold(worst, |a, p| a.max(p.abs()));
    }
    Ok(MethodRun {
        seconds,
        allocations: allocs,
        max_abs_phi: worst,
        iterations: sim.projection_iterations() + sim.rattle_iterations() + sim.newton_iterations(),
    })
}

/// [`METHODS`] on one model, interleaved: `trials` rounds, each running
/// every method `runs` times, the order rotated from one round to the next.
#[allow(clippy::too_many_arguments)]
pub(super) fn compare_methods(
    model: &'static str,
    n: usize,
    ex: &Example,
    h: f64,
    cvsgf_energy: Control,
    steps: u64,
    runs: u64,
    trials: usize,
) -> Result<MethodComparison> {
    let ab3 = |control| Settings::new(Scheme::AdamsBashforth3, h, control);
    let settings = [
        ab3(cvsgf_energy),
        ab3(methods::robust()),
        ab3(methods::projection()),
        Settings::new(Scheme::Rattle, h, Control::none()),
        Settings::new(Scheme::GeneralizedAlpha, h, Control::none()),
    ];
    let controls = settings.map(|s| s.control);
    let k = controls.len();
    let mut phi = vec![0.0; ex.model.m()];
    let (mut seconds, mut ratios) = (vec![vec![0.0; trials]; k], vec![vec![0.0; trials]; k]);
    let (mut allocs, mut worst, mut iterations) = (vec![0_u64; k], vec![0.0_f64; k], vec![0_u64; k]);
    for trial in 0..trials {
        for i in 0..k {
            let c = (i + trial) % k;
            for _ in 0..runs {
                let r = method_run(ex, settings[c], steps, &mut phi)?;
                seconds[c][trial] += r.seconds;
                allocs[c] = allocs[c].max(r.allocations);
                worst[c] = worst[c].max(r.max_abs_phi);
                iterations[c] += r.iterations;
            }
        }
        for c in 0..k {
            ratios[c][trial] = seconds[c][trial] / seconds[0][trial];
        }
    }
    let total_steps = (runs * steps) as f64;
    let methods = (0..k)
        .map(|c| MethodCost {
            method: METHODS[c],
            us_per_step: median(seconds[c].clone()) / total_steps * 1e6,
            ratio_to_cvsgf_energy: median(ratios[c].clone()),
            iterations_per_step: (controls[c].projection.is_some() || settings[c].scheme.steps_model())
                .then(|| iterations[c] as f64 / (total_steps * trials as f64)),
            max_abs_phi: worst[c],
            allocations_per_step: allocs[c] as f64 / steps as f64,
        })
        .collect();
    Ok(MethodComparison { model, n, h, steps_per_run: steps, runs_per_trial: runs, trials, methods })
}

/// [`compare_methods`] on Example 1 and on the chain.
pub(super) fn method_comparisons(light: bool) -> Result<Vec<MethodComparison>> {
    let (steps, runs, trials) = if light { (1_000, 1, 3) } else { (10_000, 20, 7) };
    let ex = cartesian_pendulum(PendulumParams::default())?;
    let paper = MethodGains::paper().cvsgf_energy();
    let mut out = vec![compare_methods("example1", 1, &ex, 0.01, paper, steps, runs, trials)?];
    // Steps per run so that each run lasts tens of milliseconds at least.
    let sizes: &[(usize, u64)] =
        if light { &[(10, 10), (100, 10), (1000, 10)] } else { &[(10, 10_000), (100, 5_000), (1000, 1_000)] };
    let trials = if light { 3 } else { 7 };
    let h = 1e-3;
    for &(n, steps) in sizes {
        out.push(compare_methods("chain", n, &chain_example(n)?, h, chain_control(h), steps, 1, trials)?);
    }
    Ok(out)
}
