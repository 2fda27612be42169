//! Real-time figures: each step timed on its own over a long run, and the
//! median, 99.9th percentile and maximum of those times — a real-time
//! user needs every step within budget, not the mean. The planar chain at
//! N = 10, 100, 1000 (AB-3 with the chain's control, h = 1e-3) and the
//! flyball governor (RK-4 at its scenario's h = 5e-5); then a
//! co-simulation step of the pendulum of `examples/pd_pendulum.toml` as
//! `fmi2DoStep` makes it — the input set (which restarts the scheme when
//! it changes), one step, the outputs read, through the case stepped
//! from outside that the FMU and the C API step — against a bare step.
//! (The FMI functions themselves are timed by the example
//! `crates/cdyn-capi/examples/fmi_overhead.rs`: that crate depends on this one.)

use super::{chain_control, chain_example};
use crate::case::live::Live;
use crate::case::scenario;
use crate::io::alloc_count::allocations;
use anyhow::Result;
use cdyn::{Scheme, Settings, Simulation};
use serde::Serialize;
use std::path::Path;
use std::time::Instant;

/// The times of the steps of one run, by two clocks.
#[derive(Debug, Serialize)]
pub struct StepTimes {
    /// What was stepped.
    pub case: String,
    /// Steps timed, each on its own.
    pub steps: usize,
    /// Elapsed (wall-clock) time: what a loop on this machine sees, the
    /// scheduler's preemptions included (on a shared machine, gaps of 4 ms
    /// and more in the maximum and, for steps above ~30 µs, the 99.9th
    /// percentile).
    pub wall: Percentiles,
    /// This thread's CPU time: the step's own cost, page faults included,
    /// preemptions not — the tail a real-time core given to the loop would
    /// see. Each reading costs a system call, counted in (see the `empty
    /// step` row).
    pub cpu: Percentiles,
    /// The first step's CPU time: what lazy initialisation and first
    /// touches of memory add to it.
    pub first_step_cpu_us: f64,
    /// Allocations over the run (0 expected).
    pub allocations: u64,
}

/// The median, the 99.9th percentile and the maximum of a run's step times.
#[derive(Debug, Serialize)]
pub struct Percentiles {
    /// Median time of a step.
    pub median_us: f64,
    /// 99.9th percentile.
    pub p999_us: f64,
    /// The slowest step.
    pub max_us: f64,
    /// Which step was the slowest (0: the first).
    pub slowest_step: usize,
}

impl Percentiles {
    fn of(mut times: Vec<f64>) -> Percentiles {
        let (slowest_step, &max_us) = times.iter().enumerate().max_by(|a, b| a.1.total_cmp(b.1)).unwrap_or((0, &0.0));
        times.sort_by(f64::total_cmp);
        let n = times.len();
        let at = |p: f64| times[((p * n as f64).ceil() as usize).clamp(1, n) - 1];
        Percentiles { median_us: at(0.5), p999_us: at(0.999), max_us, slowest_step }
    }
}

/// This thread's CPU time in µs (`CLOCK_THREAD_CPUTIME_ID`).
fn thread_cpu_us() -> f64 {
    let mut now = libc::timespec { tv_sec: 0, tv_nsec: 0 };
    // SAFETY: `now` is a valid timespec to write; the clock exists on Linux.
    unsafe { libc::clock_gettime(libc::CLOCK_THREAD_CPUTIME_ID, &mut now) };
    now.tv_sec as f64 * 1e6 + now.tv_nsec as f64 * 1e-3
}

/// Times each of `steps` calls of `step` on its own, by both clocks.
pub fn per_step(case: String, steps: usize, mut step: impl FnMut() -> Result<()>) -> Result<StepTimes> {
    let (mut wall, mut cpu) = (vec![0.0_f64; steps], vec![0.0_f64; steps]);
    let before = allocations();
    for (w, c) in wall.iter_mut().zip(cpu.iter_mut()) {
        let (clock, cpu_start) = (Instant::now(), thread_cpu_us());
        step()?;
        *c = thread_cpu_us() - cpu_start;
        *w = clock.elapsed().as_secs_f64() * 1e6;
    }
    let allocations = allocations() - before;
    let first_step_cpu_us = cpu.first().copied().unwrap_or(0.0);
    Ok(StepTimes {
        case,
        steps,
        wall: Percentiles::of(wall),
        cpu: Percentiles::of(cpu),
        first_step_cpu_us,
        allocations,
    })
}

/// The real-time figures (`cdyn bench --realtime`, and part of `bench.json`).
#[derive(Debug, Serialize)]
pub struct Realtime {
    /// A `--light` run: few steps, figures that mean little.
    pub light: bool,
    /// Each step timed on its own: an empty step, the chain by N, the
    /// flyball and a rod falling onto a joint limit.
    pub step_times: Vec<StepTimes>,
    /// A bare step of the pendulum, then a co-simulation step of it.
    pub cosimulation: [StepTimes; 2],
    /// Median co-simulation step over median bare step (CPU time).
    pub cosimulation_ratio: f64,
}

/// The real-time figures: 1e5 steps each (`light`: 200, for CI).
pub fn run_realtime(light: bool) -> Result<Realtime> {
    let steps = if light { 200 } else { 100_000 };
    // What the clocks themselves cost: a step that does nothing.
    let mut runs = vec![per_step("empty step (the clocks' own cost)".into(), steps, || Ok(()))?];
    for n in [10, 100, 1000] {
        let ex = chain_example(n)?;
        let settings = Settings::new(Scheme::AdamsBashforth3, 1e-3, chain_control(1e-3));
        let mut sim = Simulation::new(&ex.model, settings, &ex.q0, &ex.v0)?;
        runs.push(per_step(format!("chain N = {n}, AB-3, cvsgf_energy, h = 1e-3"), steps, || Ok(sim.step()?))?);
    }
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples");
    let flyball = root.join("suite/flyball_governor.toml");
    let case = scenario::load(&flyball)?.case(&flyball)?;
    let ex = &case.example;
    let mut sim = Simulation::new(&ex.model, case.settings, &ex.q0, &ex.v0)?;
    let name = format!("flyball governor, {}, h = {}", case.settings.scheme.info().name, case.settings.h);
    runs.push(per_step(name, steps, || Ok(sim.step()?))?);
    // A joint limit's impact, located within its step: a rod falls onto
    // its stop at step 336 and is held there; that step is the slowest.
    let limited = root.join("limited_pendulum.toml");
    let mut live = Live::from_scenario(&scenario::load(&limited)?, &limited)?;
    let name = "limited pendulum onto its stop at step 336, rk4, h = 0.001 (the impact's step the max)";
    runs.push(per_step(name.into(), steps.max(1000), || Ok(live.step(1)?))?);
    // Co-simulation against bare steps, on the same case.
    let pendulum = root.join("pd_pendulum.toml");
    let parsed = scenario::load(&pendulum)?;
    let case = parsed.case(&pendulum)?;
    let ex = &case.example;
    let mut sim = Simulation::new(&ex.model, case.settings, &ex.q0, &ex.v0)?;
    let bare = per_step("pendulum, bare step".into(), steps, || Ok(sim.step()?))?;
    let mut live = Live::from_scenario(&parsed, &pendulum)?;
    let mut outputs = vec![0.0; live.output_names().len()];
    let mut k = 0_usize;
    let cosim = per_step("pendulum, co-simulation step (input, step, outputs)".into(), steps, || {
        // A torque that changes every 10 steps, as a controller at 100 Hz sets it.
        k += 1;
        live.set_input(0, ((k / 10) as f64 * 0.1).sin())?;
        live.step(1)?;
        live.outputs(&mut outputs);
        Ok(())
    })?;
    let cosimulation_ratio = cosim.cpu.median_us / bare.cpu.median_us;
    Ok(Realtime { light, step_times: runs, cosimulation: [bare, cosim], cosimulation_ratio })
}
