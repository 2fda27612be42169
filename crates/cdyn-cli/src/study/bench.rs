//! `cdyn bench`: the cost of a step, measured in one run so that ratios
//! are meaningful on a shared machine.
//!
//! - Example 1, CVSGF + energy (Eq. 51, forward Euler control), AB-3:
//!   nanoseconds per step of cdyn — as a `SmallSystem` (sizes known at
//!   compile time) and as a general `Model` — and of the hand-written
//!   closed form (`cdyn::baseline`), interleaved trials, best of each; the
//!   ratio to the hand-written step is cdyn's abstraction overhead.
//! - The N-link Cartesian chain (unit point masses on rods of 1 m, g = 1,
//!   released at rest 0.3 rad from vertical; CVSGF + energy with
//!   hα_g = hα_e = 0.4, AB-3, h = 1e-3): microseconds per step, max |Φ|
//!   over the run, and the fitted exponent of cost against N.
//! - The spatial chain (`cdyn::spatial::chain`: N rods of 1 kg and 1 m in
//!   Euler parameters joined by spherical joints, released at rest 0.3 rad
//!   from vertical, g = 1) with the same control, scheme and step: the same
//!   figures; and against the same chain written out by hand
//!   (`cdyn::baseline::HandWrittenChain`: closed-form derivatives, `S`
//!   factored by 4 × 4 blocks), interleaved trials, best of each.
//! - The methods side by side, each on Example 1 (general `Model`, h = 0.01)
//!   and on the chain (h = 1e-3), AB-3: `cvsgf_energy` (the control timed
//!   above), the `robust` preset (automatic gains resolved when each
//!   simulation starts, outside the clock) and `projection` (with its mean
//!   Newton iterations per step). Trials alternate the methods, rotating
//!   their order; each figure is the median over the trials, and each
//!   ratio the median of the ratios within a trial, so that a slow spell
//!   of the machine, which hits the methods of one trial alike, cancels.
//! - Allocations per step, counted by the binary's global allocator.

use crate::io::alloc_count::allocations;
use anyhow::Result;
use cdyn::baseline::{HandWritten, HandWrittenChain};
use cdyn::control::methods::{self, MethodGains};
use cdyn::models::{ChainParams, Example, PendulumParams, cartesian_pendulum, chain, small_pendulum};
use cdyn::small::SmallSimulation;
use cdyn::{Application, Control, Energy, EnergyGain, Gain, Geometric, Scheme, Settings, Simulation};
use serde::Serialize;
use std::hint::black_box;
use std::time::Instant;

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

/// One size of the planar chain (`cvsgf_energy`, AB-3, h = 1e-3).
#[derive(Debug, Serialize)]
pub struct ChainRun {
    /// Bodies.
    pub n: usize,
    /// Steps timed.
    pub steps: u64,
    /// Time per step.
    pub us_per_step: f64,
    /// Largest `|Φ|` over the run.
    pub max_abs_phi: f64,
    /// Allocations per step (0 expected).
    pub allocations_per_step: f64,
    /// The factorization of `S` used: `dense` or `sparse`.
    pub solver: &'static str,
}

/// The spatial chain's step in cdyn against the same chain written out by hand.
#[derive(Debug, Serialize)]
pub struct SpatialBaseline {
    /// Bodies.
    pub n: usize,
    /// Every run starts afresh (set-up untimed) and lasts this many steps.
    pub steps_per_run: u64,
    /// Interleaved trials.
    pub trials: usize,
    /// Best over the interleaved trials.
    pub cdyn_us_per_step: f64,
    /// The hand-written step, best over the trials.
    pub handwritten_us_per_step: f64,
    /// cdyn / hand-written.
    pub overhead_ratio: f64,
}

/// One method's cost on one model, over the interleaved trials of a [`MethodComparison`].
#[derive(Debug, Serialize)]
pub struct MethodCost {
    /// `cvsgf_energy`, `robust` or `projection`.
    pub method: &'static str,
    /// Median over the trials.
    pub us_per_step: f64,
    /// Median over the trials of this method's time over `cvsgf_energy`'s in the same trial.
    pub ratio_to_cvsgf_energy: f64,
    /// Newton iterations of the projection per step (`projection` only).
    pub projection_iterations_per_step: Option<f64>,
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
    /// Step size, AB-3.
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

/// What `bench.json` holds.
#[derive(Debug, Serialize)]
pub struct Report {
    /// A `--light` run: few steps, figures that mean little.
    pub light: bool,
    /// Example 1 against hand-written code.
    pub example1: Example1,
    /// The planar chain at each size.
    pub chain: Vec<ChainRun>,
    /// Least-squares slope of log(cost) against log(N) over N ≥ 100.
    pub chain_cost_exponent: Option<f64>,
    /// The spatial chain, by N.
    pub spatial_chain: Vec<ChainRun>,
    /// Least-squares slope of log(cost) against log(N) over N ≥ 100.
    pub spatial_chain_cost_exponent: Option<f64>,
    /// The spatial chain against the hand-written one, by N.
    pub spatial_handwritten: Vec<SpatialBaseline>,
    /// `cvsgf_energy`, `robust` and `projection` on Example 1, then on the chain by N.
    pub methods: Vec<MethodComparison>,
    /// Over every run above, the methods' included.
    pub max_allocations_per_step: f64,
}

/// Seconds for `runs` fresh runs of `steps` steps each (set-up untimed), and the allocations while stepping.
fn timed_runs<T>(
    runs: u64,
    steps: u64,
    mut start: impl FnMut() -> Result<T>,
    mut step: impl FnMut(&mut T) -> Result<()>,
) -> Result<(f64, u64)> {
    let (mut seconds, mut allocs) = (0.0, 0);
    for _ in 0..runs {
        let mut state = start()?;
        let before = allocations();
        let clock = Instant::now();
        for _ in 0..steps {
            step(&mut state)?;
        }
        seconds += clock.elapsed().as_secs_f64();
        allocs += allocations() - before;
        black_box(&mut state);
    }
    Ok((seconds, allocs))
}

fn example1(light: bool) -> Result<Example1> {
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

fn chain_run(n: usize, t_end: f64) -> Result<ChainRun> {
    let ex = chain_example(n)?;
    timed_chain(n, &ex.model, &ex.q0, &ex.v0, t_end)
}

fn spatial_chain_run(n: usize, t_end: f64) -> Result<ChainRun> {
    let built = cdyn::spatial::chain(n, 0.3, 1.0).build()?;
    timed_chain(n, &built.model, &built.q0, &built.v0, t_end)
}

/// The spatial chain of `n` rods in cdyn and hand-written, in interleaved
/// trials of fresh runs (from rest, the benchmark's control and step).
fn spatial_baseline(n: usize, steps: u64, trials: usize) -> Result<SpatialBaseline> {
    let built = cdyn::spatial::chain(n, 0.3, 1.0).build()?;
    let h = 1e-3;
    let hand_written = || HandWrittenChain::new(n, 0.3, 1.0, h, 0.4 / h, 0.4 / h);
    // The same control as `chain_control`, as the hand-written chain writes it out.
    let settings = hand_written().settings();
    let (mut cdyn, mut hand) = (f64::INFINITY, f64::INFINITY);
    for _ in 0..trials {
        let start = || Ok(Simulation::new(&built.model, settings, &built.q0, &built.v0)?);
        cdyn = cdyn.min(timed_runs(1, steps, start, |s| Ok(s.step()?))?.0);
        let step = |c: &mut HandWrittenChain| {
            c.step();
            Ok(())
        };
        hand = hand.min(timed_runs(1, steps, || Ok(hand_written()), step)?.0);
    }
    let us = |seconds: f64| seconds / steps as f64 * 1e6;
    Ok(SpatialBaseline {
        n,
        steps_per_run: steps,
        trials,
        cdyn_us_per_step: us(cdyn),
        handwritten_us_per_step: us(hand),
        overhead_ratio: cdyn / hand,
    })
}

/// A chain's run at h = 1e-3, AB-3, with [`chain_control`].
fn timed_chain(n: usize, model: &cdyn::Model, q0: &[f64], v0: &[f64], t_end: f64) -> Result<ChainRun> {
    let h = 1e-3;
    let settings = Settings::new(Scheme::AdamsBashforth3, h, chain_control(h));
    let mut sim = Simulation::new(model, settings, q0, v0)?;
    let steps = cdyn::simulate::steps_to(t_end, h)?;
    let mut phi = vec![0.0; model.m()];
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
        model.constraint_values(sim.q(), sim.t(), &mut phi);
        worst = phi.iter().fold(worst, |a, p| a.max(p.abs()));
    }
    let solver = if model.m() >= cdyn::dynamics::SPARSE_FROM { "sparse" } else { "dense" };
    Ok(ChainRun {
        n,
        steps,
        us_per_step: elapsed / steps as f64 * 1e6,
        max_abs_phi: worst,
        allocations_per_step: allocs as f64 / steps as f64,
        solver,
    })
}

/// The methods compared, by name; the first is the one ratios are taken to.
pub const METHODS: [&str; 3] = ["cvsgf_energy", "robust", "projection"];

/// Steps between samples of `|Φ|` in a [`MethodComparison`]: the clock is
/// read this often, which costs well under 1 % even of Example 1's step.
pub const PHI_EVERY: u64 = 100;

/// The middle value (the mean of the two middle ones for an even count).
fn median(mut x: Vec<f64>) -> f64 {
    x.sort_by(f64::total_cmp);
    let k = x.len();
    if k % 2 == 1 { x[k / 2] } else { 0.5 * (x[k / 2 - 1] + x[k / 2]) }
}

/// What one fresh run of a method measured.
struct MethodRun {
    seconds: f64,
    allocations: u64,
    max_abs_phi: f64,
    projection_iterations: u64,
}

/// One fresh run of `steps` steps of `ex` (set-up, including the automatic
/// gains, untimed), `|Φ|` sampled outside the clock.
fn method_run(ex: &Example, settings: Settings, steps: u64, phi: &mut [f64]) -> Result<MethodRun> {
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
        projection_iterations: sim.projection_iterations(),
    })
}

/// [`METHODS`] on one model, interleaved: `trials` rounds, each running
/// every method `runs` times, the order rotated from one round to the next.
#[allow(clippy::too_many_arguments)]
fn compare_methods(
    model: &'static str,
    n: usize,
    ex: &Example,
    h: f64,
    cvsgf_energy: Control,
    steps: u64,
    runs: u64,
    trials: usize,
) -> Result<MethodComparison> {
    let controls = [cvsgf_energy, methods::robust(), methods::projection()];
    let k = controls.len();
    let mut phi = vec![0.0; ex.model.m()];
    let (mut seconds, mut ratios) = (vec![vec![0.0; trials]; k], vec![vec![0.0; trials]; k]);
    let (mut allocs, mut worst, mut iterations) = (vec![0_u64; k], vec![0.0_f64; k], vec![0_u64; k]);
    for trial in 0..trials {
        for i in 0..k {
            let c = (i + trial) % k;
            let settings = Settings::new(Scheme::AdamsBashforth3, h, controls[c]);
            for _ in 0..runs {
                let r = method_run(ex, settings, steps, &mut phi)?;
                seconds[c][trial] += r.seconds;
                allocs[c] = allocs[c].max(r.allocations);
                worst[c] = worst[c].max(r.max_abs_phi);
                iterations[c] += r.projection_iterations;
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
            projection_iterations_per_step: controls[c]
                .projection
                .map(|_| iterations[c] as f64 / (total_steps * trials as f64)),
            max_abs_phi: worst[c],
            allocations_per_step: allocs[c] as f64 / steps as f64,
        })
        .collect();
    Ok(MethodComparison { model, n, h, steps_per_run: steps, runs_per_trial: runs, trials, methods })
}

/// The chain of the figures above: `n` links, released at rest.
fn chain_example(n: usize) -> Result<Example> {
    Ok(chain(ChainParams { n, mass: 1.0, length: 1.0, gravity: 1.0, theta0: 0.3, omega0: 0.0 })?)
}

/// The chain's control: CVSGF + energy with hα_g = hα_e = 0.4, by forward Euler.
fn chain_control(h: f64) -> Control {
    Control::none()
        .with_geometric(Geometric::Gradient(Gain::Rate(0.4 / h)))
        .with_energy(Energy::Gradient(EnergyGain::Rate { alpha_e: 0.4 / h }))
        .with_application(Application::ForwardEuler)
}

/// [`compare_methods`] on Example 1 and on the chain.
fn method_comparisons(light: bool) -> Result<Vec<MethodComparison>> {
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
    // The spatial chain's step costs about 20 times the planar one's: its
    // light run stops at N = 100 (the full one takes minutes at N = 10 000).
    let (spatial_sizes, spatial_t_end): (&[usize], f64) =
        if light { (&[10, 100], 0.01) } else { (&[10, 100, 1000, 10_000], 10.0) };
    let spatial_chain =
        spatial_sizes.iter().map(|&n| spatial_chain_run(n, spatial_t_end)).collect::<Result<Vec<_>>>()?;
    let baselines: &[(usize, u64)] =
        if light { &[(10, 20), (100, 10)] } else { &[(10, 5000), (100, 500), (1000, 100)] };
    let trials = if light { 1 } else { 7 };
    let spatial_handwritten =
        baselines.iter().map(|&(n, steps)| spatial_baseline(n, steps, trials)).collect::<Result<Vec<_>>>()?;
    let fit = |runs: &[ChainRun]| {
        let points: Vec<(f64, f64)> = runs.iter().filter(|c| c.n >= 100).map(|c| (c.n as f64, c.us_per_step)).collect();
        fitted_exponent(&points)
    };
    let methods = method_comparisons(light)?;
    let max_allocations_per_step = chain
        .iter()
        .chain(&spatial_chain)
        .map(|c| c.allocations_per_step)
        .chain(methods.iter().flat_map(|m| m.methods.iter().map(|c| c.allocations_per_step)))
        .fold(example1.allocations_per_step, f64::max);
    Ok(Report {
        light,
        example1,
        chain_cost_exponent: fit(&chain),
        chain,
        spatial_chain_cost_exponent: fit(&spatial_chain),
        spatial_chain,
        spatial_handwritten,
        methods,
        max_allocations_per_step,
    })
}

/// The table printed on the terminal.
pub fn table(r: &Report) -> String {
    let e = &r.example1;
    let mut out = format!(
        "Example 1, cvsgf_energy, AB-3 ({} runs of {} steps, best of {}):\n",
        e.runs_per_trial, e.steps_per_run, e.trials
    );
    out += &format!("  cdyn (SmallSystem)   {:>8.1} ns/step  overhead {:.2}×\n", e.cdyn_ns_per_step, e.overhead_ratio);
    out += &format!(
        "  cdyn (general Model) {:>8.1} ns/step  overhead {:.2}×\n",
        e.general_ns_per_step, e.general_overhead_ratio
    );
    out += &format!("  hand-written         {:>8.1} ns/step\n", e.handwritten_ns_per_step);
    for (title, runs, exponent) in [
        ("N-link chain", &r.chain, r.chain_cost_exponent),
        ("spatial chain (rods in Euler parameters, spherical joints)", &r.spatial_chain, r.spatial_chain_cost_exponent),
    ] {
        out += &format!("{title}, CVSGF + energy, AB-3, h = 1e-3:\n");
        out += &format!("  {:>6} {:>8} {:>12} {:>12} {:>8}\n", "N", "steps", "µs/step", "max|Φ|", "solver");
        for c in runs {
            out += &format!(
                "  {:>6} {:>8} {:>12.2} {:>12.3e} {:>8}\n",
                c.n, c.steps, c.us_per_step, c.max_abs_phi, c.solver
            );
        }
        if let Some(p) = exponent {
            out += &format!("  cost exponent (N ≥ 100): {p:.3}\n");
        }
    }
    if let Some(b) = r.spatial_handwritten.first() {
        out += &format!(
            "spatial chain, cdyn against hand-written (fresh runs of the steps shown, best of {} interleaved trials):\n",
            b.trials
        );
        out += &format!("  {:>6} {:>8} {:>12} {:>14} {:>9}\n", "N", "steps", "cdyn µs", "hand µs", "ratio");
        for b in &r.spatial_handwritten {
            out += &format!(
                "  {:>6} {:>8} {:>12.2} {:>14.2} {:>8.2}×\n",
                b.n, b.steps_per_run, b.cdyn_us_per_step, b.handwritten_us_per_step, b.overhead_ratio
            );
        }
    }
    if let Some(m) = r.methods.first() {
        out += &format!(
            "Methods, AB-3 (median of {} interleaved trials; ratio to cvsgf_energy within a trial, median):\n",
            m.trials
        );
    }
    out += &format!(
        "  {:>8} {:>6} {:>7} {:>8} {:>13} {:>12} {:>7} {:>10} {:>10}\n",
        "model", "N", "h", "steps", "method", "µs/step", "ratio", "iter/step", "max|Φ|"
    );
    for m in &r.methods {
        for c in &m.methods {
            let iterations = c.projection_iterations_per_step.map_or("-".into(), |i| format!("{i:.3}"));
            out += &format!(
                "  {:>8} {:>6} {:>7} {:>8} {:>13} {:>12.3} {:>6.2}× {:>10} {:>10.2e}\n",
                m.model,
                m.n,
                m.h,
                m.steps_per_run * m.runs_per_trial,
                c.method,
                c.us_per_step,
                c.ratio_to_cvsgf_energy,
                iterations,
                c.max_abs_phi
            );
        }
    }
    out += &format!("allocations per step (max): {}\n", r.max_allocations_per_step);
    out
}
