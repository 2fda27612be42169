//! The C API (`include/cdyn.h`, generated from this file by cbindgen): a
//! scenario's case created from a file or TOML text, its inputs set, its
//! steps taken, its outputs, its state read and written, saved and
//! restored, and freed.
//!
//! Every function returns a [`CdynStatus`] (or a value that cannot fail);
//! on failure [`cdyn_last_error`] holds the one-line message, worded as
//! `cdyn run` words it. A null or mismatched argument is an error, never a
//! crash; a panic inside is caught and reported as `CDYN_STATUS_INTERNAL`.
//! A simulation may be used from one thread at a time; different ones are
//! independent (each has its own model and inputs).

use crate::guard::{guarded, last_error, set_last_error};
use cdyn_cli::case::live::{Live, LiveSnapshot};
use cdyn_cli::case::scenario;
use std::ffi::{CStr, CString, c_char};
use std::path::Path;

/// What a call of the C API did.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CdynStatus {
    /// It succeeded.
    Ok = 0,
    /// The scenario cannot be read or run as written.
    Scenario = 1,
    /// A step failed (diverged, singular, …); the simulation stays where it stopped.
    Simulation = 2,
    /// An argument was refused: null, of the wrong length, an unknown input, a value that is not finite.
    Argument = 3,
    /// A bug of cdyn (a panic, caught).
    Internal = 4,
}

/// A scenario's case being stepped (opaque).
pub struct CdynSimulation {
    pub(crate) live: Live,
    inputs: Vec<CString>,
    outputs: Vec<CString>,
}

/// A saved simulation (opaque): [`cdyn_save_state`], [`cdyn_restore_state`], [`cdyn_free_state`].
pub struct CdynState {
    snapshot: LiveSnapshot,
}

impl CdynSimulation {
    /// `live`, with its names as C strings.
    pub(crate) fn new(live: Live) -> Self {
        let c = |s: &str| CString::new(s.replace('\0', "")).unwrap_or_default();
        let inputs = live.input_names().into_iter().map(c).collect();
        let outputs = live.output_names().iter().map(|s| c(s)).collect();
        CdynSimulation { live, inputs, outputs }
    }
}

/// A failure of kind `status` with its message.
type Failure = (CdynStatus, String);

fn argument(message: impl Into<String>) -> Failure {
    (CdynStatus::Argument, message.into())
}

/// Runs `body` guarded; returns its status and keeps a failure's message.
fn call(body: impl FnOnce() -> Result<(), Failure>) -> CdynStatus {
    let mut status = CdynStatus::Ok;
    let outcome = guarded(|| {
        body().map_err(|(s, message)| {
            status = s;
            message
        })
    });
    match outcome {
        Ok(()) => CdynStatus::Ok,
        Err(message) => {
            set_last_error(&message);
            if status == CdynStatus::Ok { CdynStatus::Internal } else { status }
        }
    }
}

/// The string at `text`, or an argument error naming `what`.
///
/// # Safety
/// `text` is null or a NUL-terminated string.
unsafe fn text<'a>(text: *const c_char, what: &str) -> Result<&'a str, Failure> {
    if text.is_null() {
        return Err(argument(format!("{what} is null")));
    }
    // SAFETY: the caller's contract.
    unsafe { CStr::from_ptr(text) }.to_str().map_err(|_| argument(format!("{what} is not UTF-8")))
}

/// The simulation at `sim`, or an argument error.
///
/// # Safety
/// `sim` is null or from [`cdyn_create_from_file`] / [`cdyn_create_from_toml`], not freed.
unsafe fn simulation<'a>(sim: *mut CdynSimulation) -> Result<&'a mut CdynSimulation, Failure> {
    // SAFETY: the caller's contract.
    unsafe { sim.as_mut() }.ok_or_else(|| argument("the simulation is null"))
}

/// Creates the case `build` makes, into `*out`.
fn create(out: *mut *mut CdynSimulation, build: impl FnOnce() -> anyhow::Result<Live>) -> CdynStatus {
    call(|| {
        if out.is_null() {
            return Err(argument("out is null"));
        }
        let live = build().map_err(|e| (CdynStatus::Scenario, format!("{e:#}")))?;
        // SAFETY: checked not null; the caller gives a place for a pointer.
        unsafe { *out = Box::into_raw(Box::new(CdynSimulation::new(live))) };
        Ok(())
    })
}

/// The message of the last failed call on this thread (empty if none);
/// valid until the next failing call on this thread.
#[unsafe(no_mangle)]
pub extern "C" fn cdyn_last_error() -> *const c_char {
    last_error()
}

/// Creates a simulation of the scenario file at `path` (as `cdyn run` reads
/// it; a URDF it names is read relative to its folder), at its initial state.
///
/// # Safety
/// `path` is a NUL-terminated string; `out` points to a place for the result.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn cdyn_create_from_file(path: *const c_char, out: *mut *mut CdynSimulation) -> CdynStatus {
    create(out, || {
        // SAFETY: the caller's contract.
        let path = Path::new(unsafe { text(path, "path") }.map_err(|(_, m)| anyhow::anyhow!(m))?);
        Live::from_scenario(&scenario::load(path)?, path)
    })
}

/// Creates a simulation of the scenario given as TOML `text`; errors name it `<string>`.
///
/// # Safety
/// `toml` is a NUL-terminated string; `out` points to a place for the result.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn cdyn_create_from_toml(toml: *const c_char, out: *mut *mut CdynSimulation) -> CdynStatus {
    create(out, || {
        // SAFETY: the caller's contract.
        let toml = unsafe { text(toml, "toml") }.map_err(|(_, m)| anyhow::anyhow!(m))?;
        let (parsed, _) = scenario::parse(toml, "<string>")?;
        Live::from_scenario(&parsed, Path::new("<string>"))
    })
}

/// Frees a simulation (null is ignored).
///
/// # Safety
/// `sim` is null or from a create function, not freed before.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn cdyn_free(sim: *mut CdynSimulation) {
    if !sim.is_null() {
        // SAFETY: the caller's contract: a Box made by `create`.
        let _ = guarded(|| {
            drop(unsafe { Box::from_raw(sim) });
            Ok(())
        });
    }
}

/// Number of inputs (0 for null).
///
/// # Safety
/// `sim` is null or a live simulation.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn cdyn_input_count(sim: *const CdynSimulation) -> usize {
    // SAFETY: the caller's contract.
    unsafe { sim.as_ref() }.map_or(0, |s| s.inputs.len())
}

/// The name of input `index`, owned by the simulation; null when out of range.
///
/// # Safety
/// `sim` is null or a live simulation.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn cdyn_input_name(sim: *const CdynSimulation, index: usize) -> *const c_char {
    // SAFETY: the caller's contract.
    unsafe { sim.as_ref() }.and_then(|s| s.inputs.get(index)).map_or(std::ptr::null(), |n| n.as_ptr())
}

/// Sets input `index` to `value` (finite); takes effect from the next step.
///
/// # Safety
/// `sim` is null or a live simulation.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn cdyn_set_input(sim: *mut CdynSimulation, index: usize, value: f64) -> CdynStatus {
    call(|| {
        // SAFETY: the caller's contract.
        let sim = unsafe { simulation(sim) }?;
        sim.live.set_input(index, value).map_err(|e| argument(e.to_string()))
    })
}

/// Sets the input called `name` to `value` (finite).
///
/// # Safety
/// `sim` is null or a live simulation; `name` a NUL-terminated string.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn cdyn_set_input_by_name(
    sim: *mut CdynSimulation,
    name: *const c_char,
    value: f64,
) -> CdynStatus {
    call(|| {
        // SAFETY: the caller's contract.
        let (sim, name) = unsafe { (simulation(sim)?, text(name, "name")?) };
        sim.live.set_input_named(name, value).map_err(|e| argument(e.to_string()))
    })
}

/// Takes `steps` steps of the scenario's `h`; stops at the first that fails.
///
/// # Safety
/// `sim` is null or a live simulation.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn cdyn_step(sim: *mut CdynSimulation, steps: u64) -> CdynStatus {
    call(|| {
        // SAFETY: the caller's contract.
        let sim = unsafe { simulation(sim) }?;
        sim.live.step(steps).map_err(|e| (CdynStatus::Simulation, e.to_string()))
    })
}

/// The current time, steps × h (NaN for null).
///
/// # Safety
/// `sim` is null or a live simulation.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn cdyn_time(sim: *const CdynSimulation) -> f64 {
    // SAFETY: the caller's contract.
    unsafe { sim.as_ref() }.map_or(f64::NAN, |s| s.live.t())
}

/// The step size h of the scenario (NaN for null).
///
/// # Safety
/// `sim` is null or a live simulation.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn cdyn_step_size(sim: *const CdynSimulation) -> f64 {
    // SAFETY: the caller's contract.
    unsafe { sim.as_ref() }.map_or(f64::NAN, |s| s.live.h())
}

/// Number of outputs (0 for null).
///
/// # Safety
/// `sim` is null or a live simulation.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn cdyn_output_count(sim: *const CdynSimulation) -> usize {
    // SAFETY: the caller's contract.
    unsafe { sim.as_ref() }.map_or(0, |s| s.outputs.len())
}

/// The name of output `index` (a CSV column of `cdyn run`), owned by the simulation; null when out of range.
///
/// # Safety
/// `sim` is null or a live simulation.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn cdyn_output_name(sim: *const CdynSimulation, index: usize) -> *const c_char {
    // SAFETY: the caller's contract.
    unsafe { sim.as_ref() }.and_then(|s| s.outputs.get(index)).map_or(std::ptr::null(), |n| n.as_ptr())
}

/// Writes the outputs at the current state into `values` (`len` must be
/// [`cdyn_output_count`]).
///
/// # Safety
/// `sim` is null or a live simulation; `values` null or `len` writable doubles.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn cdyn_get_outputs(sim: *mut CdynSimulation, values: *mut f64, len: usize) -> CdynStatus {
    call(|| {
        // SAFETY: the caller's contract.
        let sim = unsafe { simulation(sim) }?;
        // SAFETY: the caller's contract, the length checked.
        let out = unsafe { buffer(values, len, sim.outputs.len(), "values") }?;
        sim.live.outputs(out);
        Ok(())
    })
}

/// How many joint limits were hit and released so far (0 for null or a
/// case without limits): `cdyn run` lists these events in `summary.json`'s
/// `limits`.
///
/// # Safety
/// `sim` is null or a live simulation.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn cdyn_limit_events(sim: *const CdynSimulation) -> usize {
    // SAFETY: the caller's contract.
    unsafe { sim.as_ref() }.map_or(0, |s| s.live.limit_events())
}

/// `len` doubles at `values`, which must be `expected`.
///
/// # Safety
/// `values` is null or points to `len` writable doubles.
unsafe fn buffer<'a>(values: *mut f64, len: usize, expected: usize, what: &str) -> Result<&'a mut [f64], Failure> {
    if values.is_null() || len != expected {
        return Err(argument(format!(
            "{what}: expected {expected} doubles, got {len}{}",
            if values.is_null() { " at null" } else { "" }
        )));
    }
    // SAFETY: the caller's contract, checked not null.
    Ok(unsafe { std::slice::from_raw_parts_mut(values, len) })
}

/// Length of the full state: `2n + 1` (positions, velocities, ∫Ė); 0 for null.
///
/// # Safety
/// `sim` is null or a live simulation.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn cdyn_state_size(sim: *const CdynSimulation) -> usize {
    // SAFETY: the caller's contract.
    unsafe { sim.as_ref() }.map_or(0, |s| 2 * s.live.q().len() + 1)
}

/// Writes the full state `(q, v, ∫Ė)` into `x` (`len` must be [`cdyn_state_size`]).
///
/// # Safety
/// `sim` is null or a live simulation; `x` null or `len` writable doubles.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn cdyn_get_state(sim: *const CdynSimulation, x: *mut f64, len: usize) -> CdynStatus {
    call(|| {
        // SAFETY: the caller's contract.
        let sim = unsafe { sim.as_ref() }.ok_or_else(|| argument("the simulation is null"))?;
        let n = sim.live.q().len();
        // SAFETY: the caller's contract, the length checked.
        let x = unsafe { buffer(x, len, 2 * n + 1, "x") }?;
        x[..n].copy_from_slice(sim.live.q());
        x[n..2 * n].copy_from_slice(sim.live.v());
        x[2 * n] = sim.live.energy_input();
        Ok(())
    })
}

/// Puts the simulation at the full state `x` (as [`cdyn_get_state`] writes
/// it), at the same time; the scheme starts again from there.
///
/// # Safety
/// `sim` is null or a live simulation; `x` null or `len` readable doubles.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn cdyn_set_state(sim: *mut CdynSimulation, x: *const f64, len: usize) -> CdynStatus {
    call(|| {
        // SAFETY: the caller's contract.
        let sim = unsafe { simulation(sim) }?;
        let n = sim.live.q().len();
        // SAFETY: the caller's contract, the length checked (only read).
        let x = unsafe { buffer(x.cast_mut(), len, 2 * n + 1, "x") }?;
        sim.live.set_state(&x[..n], &x[n..2 * n], x[2 * n]).map_err(|e| argument(e.to_string()))
    })
}

/// Saves everything needed to come back to this point (the state, the
/// scheme's history, the gains, the inputs) into `*out`; restoring it
/// repeats the run from here bit for bit. Free it with [`cdyn_free_state`].
///
/// # Safety
/// `sim` is null or a live simulation; `out` points to a place for the result.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn cdyn_save_state(sim: *const CdynSimulation, out: *mut *mut CdynState) -> CdynStatus {
    call(|| {
        // SAFETY: the caller's contract.
        let sim = unsafe { sim.as_ref() }.ok_or_else(|| argument("the simulation is null"))?;
        if out.is_null() {
            return Err(argument("out is null"));
        }
        let state = Box::new(CdynState { snapshot: sim.live.snapshot() });
        // SAFETY: checked not null.
        unsafe { *out = Box::into_raw(state) };
        Ok(())
    })
}

/// Goes back to `state`, saved of this simulation (of another: an error).
///
/// # Safety
/// `sim` and `state` are null or live.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn cdyn_restore_state(sim: *mut CdynSimulation, state: *const CdynState) -> CdynStatus {
    call(|| {
        // SAFETY: the caller's contract.
        let (sim, state) = unsafe { (simulation(sim)?, state.as_ref().ok_or_else(|| argument("the state is null"))?) };
        sim.live.restore(&state.snapshot).map_err(|e| argument(e.to_string()))
    })
}

/// Frees a saved state (null is ignored); it may outlive its simulation.
///
/// # Safety
/// `state` is null or from [`cdyn_save_state`], not freed before.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn cdyn_free_state(state: *mut CdynState) {
    if !state.is_null() {
        // SAFETY: the caller's contract: a Box made by `cdyn_save_state`.
        let _ = guarded(|| {
            drop(unsafe { Box::from_raw(state) });
            Ok(())
        });
    }
}
