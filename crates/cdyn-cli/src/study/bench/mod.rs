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
//!   `rattle` and `generalized_alpha` (no control) beside them.
//! - The planar chain by N (h = 1e-3) with the other schemes: ABM-4 with
//!   the same control, RATTLE and generalized-α without; each one's cost
//!   exponent.
//! - The stiff flyball governor (IFToMM A05) over 1 s: RK-4 at h = 5e-5
//!   (its step in the IFToMM files), RK-4 at 2.5e-4 (about its largest
//!   stable step; 4e-4 stops), ABM-4 and RATTLE at 1e-4 (theirs: 2e-4
//!   stops ABM-4 and RATTLE is 1 m off there), generalized-α at 1e-3:
//!   microseconds per step and milliseconds per simulated second.
//! - Real-time figures (`realtime`): each step timed on its own over 1e5
//!   steps — median, 99.9th percentile, maximum — for the chain at N = 10,
//!   100, 1000 and the flyball, and a co-simulation step against a bare one.
//! - Allocations per step, counted by the binary's global allocator.
//!
//! May import: `io`, `case`, and the rest of `study`.

use crate::io::alloc_count::allocations;
use anyhow::Result;
use cdyn::models::{ChainParams, Example, chain};
use cdyn::{Application, Control, Energy, EnergyGain, Gain, Geometric, Scheme};
use serde::Serialize;
use std::hint::black_box;
use std::time::Instant;

mod chains;
mod example1;
mod flyball;
mod method_costs;
mod realtime;
mod table;

pub use chains::{ChainRun, SpatialBaseline};
use chains::{chain_run, spatial_baseline, spatial_chain_run};
pub use example1::Example1;
use example1::example1;
pub use flyball::FlyballRun;
use flyball::flyball_runs;
use method_costs::method_comparisons;
pub use method_costs::{METHODS, MethodComparison, MethodCost, PHI_EVERY};
pub use realtime::{Percentiles, Realtime, StepTimes, per_step, run_realtime};
pub use table::{realtime_table, table};

/// The layout of `bench.json` this code writes. 2: `schema_version`
/// itself, `abm4_chain` and `rattle_chain` with their cost exponents, ABM-4
/// and RATTLE on the flyball, and the methods' `iterations_per_step` (was
/// `projection_iterations_per_step`). 3: `realtime`.
pub const SCHEMA_VERSION: u32 = 3;

/// What `bench.json` holds.
#[derive(Debug, Serialize)]
pub struct Report {
    /// [`SCHEMA_VERSION`].
    pub schema_version: u32,
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
    /// Generalized-α on the planar chain, by N.
    pub generalized_alpha_chain: Vec<ChainRun>,
    /// Least-squares slope of log(cost) against log(N) over N ≥ 100.
    pub generalized_alpha_chain_cost_exponent: Option<f64>,
    /// ABM-4 with the chain's control on the planar chain, by N.
    pub abm4_chain: Vec<ChainRun>,
    /// Least-squares slope of log(cost) against log(N) over N ≥ 100.
    pub abm4_chain_cost_exponent: Option<f64>,
    /// RATTLE on the planar chain, by N.
    pub rattle_chain: Vec<ChainRun>,
    /// Least-squares slope of log(cost) against log(N) over N ≥ 100.
    pub rattle_chain_cost_exponent: Option<f64>,
    /// The flyball governor at each scheme and step.
    pub flyball: Vec<FlyballRun>,
    /// Over every run above, the methods' included.
    pub max_allocations_per_step: f64,
    /// Each step timed on its own, and a co-simulation step.
    pub realtime: Realtime,
}

/// Seconds for `runs` fresh runs of `steps` steps each (set-up untimed), and the allocations while stepping.
pub(super) fn timed_runs<T>(
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

/// The chain of the figures above: `n` links, released at rest.
pub(super) fn chain_example(n: usize) -> Result<Example> {
    Ok(chain(ChainParams::default().with_n(n).with_gravity(1.0).with_theta0(0.3))?)
}

/// The chain's control: CVSGF + energy with hα_g = hα_e = 0.4, by forward Euler.
pub(super) fn chain_control(h: f64) -> Control {
    Control::none()
        .with_geometric(Geometric::Gradient(Gain::Rate(0.4 / h)))
        .with_energy(Energy::Gradient(EnergyGain::Rate { alpha_e: 0.4 / h }))
        .with_application(Application::ForwardEuler)
}

/// Slope of `ln y` against `ln x`.
pub(super) fn fitted_exponent(points: &[(f64, f64)]) -> Option<f64> {
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
    let chains = |scheme, t_end| sizes.iter().map(|&n| chain_run(n, t_end, scheme)).collect::<Result<Vec<_>>>();
    let chain = chains(Scheme::AdamsBashforth3, t_end)?;
    // Generalized-α's step costs several of AB-3's: a tenth of the run;
    // ABM-4's two evaluations and RATTLE's position step, half.
    let generalized_alpha_chain = chains(Scheme::GeneralizedAlpha, t_end / 10.0)?;
    let abm4_chain = chains(Scheme::AdamsBashforthMoulton4, t_end / 2.0)?;
    let rattle_chain = chains(Scheme::Rattle, t_end / 2.0)?;
    let flyball = flyball_runs(light)?;
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
    let realtime = run_realtime(light)?;
    let max_allocations_per_step = chain
        .iter()
        .chain(&spatial_chain)
        .chain(&generalized_alpha_chain)
        .chain(&abm4_chain)
        .chain(&rattle_chain)
        .map(|c| c.allocations_per_step)
        .chain(flyball.iter().map(|f| f.allocations_per_step))
        .chain(methods.iter().flat_map(|m| m.methods.iter().map(|c| c.allocations_per_step)))
        .fold(example1.allocations_per_step, f64::max);
    Ok(Report {
        schema_version: SCHEMA_VERSION,
        light,
        example1,
        chain_cost_exponent: fit(&chain),
        chain,
        spatial_chain_cost_exponent: fit(&spatial_chain),
        spatial_chain,
        spatial_handwritten,
        methods,
        generalized_alpha_chain_cost_exponent: fit(&generalized_alpha_chain),
        generalized_alpha_chain,
        abm4_chain_cost_exponent: fit(&abm4_chain),
        abm4_chain,
        rattle_chain_cost_exponent: fit(&rattle_chain),
        rattle_chain,
        flyball,
        max_allocations_per_step,
        realtime,
    })
}
