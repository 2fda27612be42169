//! What `fmi2DoStep` costs beyond the step it takes: the pendulum of
//! `examples/pd_pendulum.toml`, each call timed on its own over 1e5 steps
//! of h (wall clock and this thread's CPU time, as `cdyn bench --realtime`
//! times them), three ways — a bare step of the case stepped from outside;
//! that case's co-simulation step (input set, step, outputs read); and
//! the same through the FMI functions an importer calls (fmi2SetReal,
//! fmi2DoStep, fmi2GetReal of every output), with their checks and panic
//! guards. `cdyn bench` cannot call them (this crate depends on it), so
//! this example does:
//!
//!     cargo run --release -p cdyn-capi --example fmi_overhead [STEPS]

use anyhow::{Result, ensure};
use cdyn_capi::fmi::*;
use cdyn_cli::case::live::Live;
use cdyn_cli::case::scenario;
use cdyn_cli::study::bench::{StepTimes, per_step};
use std::ffi::CString;

#[global_allocator]
static GLOBAL: cdyn_cli::io::alloc_count::Counting = cdyn_cli::io::alloc_count::Counting;

// Value references of pd_pendulum.toml: 8 parameters, the input tau, then
// the outputs t, link.angle, link.x, link.y, psi.
const TAU: u32 = 8;
const OUTPUTS: [u32; 5] = [9, 10, 11, 12, 13];

/// The torque a controller at 100 Hz would set: a new value every 10 steps.
fn torque(k: usize) -> f64 {
    ((k / 10) as f64 * 0.1).sin()
}

fn main() -> Result<()> {
    let steps = std::env::args().nth(1).map_or(Ok(100_000), |s| s.parse())?;
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/pd_pendulum.toml");
    let text = std::fs::read_to_string(&path)?;
    let (parsed, table) = scenario::parse(&text, &path.display().to_string())?;

    let mut live = Live::from_scenario(&parsed, &path)?;
    let bare = per_step("bare step (Live::step)".into(), steps, || Ok(live.step(1)?))?;
    let mut live = Live::from_scenario(&parsed, &path)?;
    let mut outputs = vec![0.0; live.output_names().len()];
    let mut k = 0;
    let cosimulation = per_step("input, step, outputs (Live)".into(), steps, || {
        k += 1;
        live.set_input(0, torque(k))?;
        live.step(1)?;
        live.outputs(&mut outputs);
        Ok(())
    })?;

    let dir = tempfile::tempdir()?;
    std::fs::create_dir(dir.path().join("resources"))?;
    std::fs::write(dir.path().join("resources/scenario.toml"), &text)?;
    let uri = CString::new(format!("file://{}", dir.path().join("resources").display()))?;
    let guid = CString::new(cdyn_cli::export::variables::guid(&table, None))?;
    let callbacks = CallbackFunctions {
        logger: None,
        allocate_memory: None,
        free_memory: None,
        step_finished: None,
        component_environment: std::ptr::null_mut(),
    };
    // SAFETY: the arguments as FMI 2.0 defines them; `c` is freed below.
    let c = unsafe { fmi2Instantiate(c"pd".as_ptr(), 1, guid.as_ptr(), uri.as_ptr(), &callbacks, 0, 0) };
    ensure!(!c.is_null(), "fmi2Instantiate failed");
    unsafe {
        ensure!(fmi2SetupExperiment(c, 0, 0.0, 0.0, 0, 0.0) == OK, "fmi2SetupExperiment");
        ensure!(fmi2EnterInitializationMode(c) == OK && fmi2ExitInitializationMode(c) == OK, "initialization");
    }
    let (h, mut values, mut k) = (live.h(), [0.0; OUTPUTS.len()], 0);
    let fmi = per_step("fmi2SetReal, fmi2DoStep, fmi2GetReal".into(), steps, || {
        k += 1;
        // SAFETY: as above.
        let status = unsafe {
            fmi2SetReal(c, &TAU, 1, &torque(k)).max(fmi2DoStep(c, values[0], h, 1)).max(fmi2GetReal(
                c,
                OUTPUTS.as_ptr(),
                OUTPUTS.len(),
                values.as_mut_ptr(),
            ))
        };
        ensure!(status == OK, "an FMI call failed at step {k}");
        Ok(())
    })?;
    unsafe { fmi2FreeInstance(c) };
    ensure!(values[1] == outputs[1], "the FMU and Live end apart: {} and {}", values[1], outputs[1]);

    let row = |t: &StepTimes| {
        let (w, c) = (&t.wall, &t.cpu);
        println!(
            "  {:<40} {:>8.3} {:>8.2} {:>8.3} {:>8.2} {:>8.1} {:>6}",
            t.case, w.median_us, w.p999_us, c.median_us, c.p999_us, c.max_us, t.allocations
        );
    };
    println!("{steps} steps of the pendulum, each timed on its own, µs:");
    println!(
        "  {:<40} {:>8} {:>8} {:>8} {:>8} {:>8} {:>6}",
        "", "median", "99.9%", "cpu med", "cpu 99.9", "cpu max", "allocs"
    );
    [&bare, &cosimulation, &fmi].into_iter().for_each(row);
    println!(
        "CPU medians: FMI communication step / bare step {:.2}×, FMI / Live's co-simulation step {:.2}×",
        fmi.cpu.median_us / bare.cpu.median_us,
        fmi.cpu.median_us / cosimulation.cpu.median_us
    );
    Ok(())
}
