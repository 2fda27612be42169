//! The planar and spatial chains by N, and the spatial chain against hand-written code.

use super::*;
use crate::io::alloc_count::allocations;
use anyhow::Result;
use cdyn::baseline::HandWrittenChain;
use cdyn::{Scheme, Settings, Simulation};
use serde::Serialize;
use std::time::Instant;

/// One size of a chain at h = 1e-3: an explicit scheme with `cvsgf_energy`,
/// or RATTLE or generalized-α without control.
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

pub(super) fn chain_run(n: usize, t_end: f64, scheme: Scheme) -> Result<ChainRun> {
    let ex = chain_example(n)?;
    timed_chain(n, &ex.model, &ex.q0, &ex.v0, t_end, scheme)
}

pub(super) fn spatial_chain_run(n: usize, t_end: f64) -> Result<ChainRun> {
    let built = cdyn::spatial::chain(n, 0.3, 1.0).build()?;
    timed_chain(n, &built.model, &built.q0, &built.v0, t_end, Scheme::AdamsBashforth3)
}

/// The spatial chain of `n` rods in cdyn and hand-written, in interleaved
/// trials of fresh runs (from rest, the benchmark's control and step).
pub(super) fn spatial_baseline(n: usize, steps: u64, trials: usize) -> Result<SpatialBaseline> {
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

/// A chain's run at h = 1e-3: an explicit scheme with [`chain_control`],
/// or a scheme that steps the model (RATTLE, generalized-α) without control.
pub(super) fn timed_chain(
    n: usize,
    model: &cdyn::Model,
    q0: &[f64],
    v0: &[f64],
    t_end: f64,
    scheme: Scheme,
) -> Result<ChainRun> {
    let h = 1e-3;
    let control = if scheme.steps_model() { Control::none() } else { chain_control(h) };
    let settings = Settings::new(scheme, h, control);
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
    let solver = if cdyn::dynamics::Dynamics::new(model).sparse_factor() { "sparse" } else { "dense" };
    Ok(ChainRun {
        n,
        steps,
        us_per_step: elapsed / steps as f64 * 1e6,
        max_abs_phi: worst,
        allocations_per_step: allocs as f64 / steps as f64,
        solver,
    })
}
