//! The exported `fmi2…` functions of co-simulation. Each checks its
//! instance and arguments, runs guarded (a panic is logged and returned as
//! `fmi2Fatal`), and logs a refusal as one line with `fmi2Error`.

use super::instance::{Instance, Mode, Refusal, Saved, log, refuse};
use super::{
    Boolean, CO_SIMULATION, CallbackFunctions, DISCARD, ERROR, FATAL, FmiString, LAST_SUCCESSFUL_TIME, OK, Status,
    TERMINATED, ValueReference,
};
use crate::guard::guarded;
use std::ffi::{CStr, c_char, c_int, c_void};

/// `fmi2Component`: an `Instance` behind a pointer.
pub type Component = *mut c_void;
/// `fmi2FMUstate`: a saved instance behind a pointer.
pub type FmuState = *mut c_void;

/// Runs `body` on the instance at `c`; logs and returns a refusal or a panic.
fn with(c: Component, body: impl FnOnce(&mut Instance) -> Result<(), Refusal>) -> Status {
    // SAFETY: `c` is null or an instance from fmi2Instantiate (the importer's contract).
    let Some(instance) = (unsafe { c.cast::<Instance>().as_mut() }) else { return ERROR };
    let mut status = OK;
    let outcome = guarded(|| {
        body(instance).map_err(|(s, message)| {
            status = s;
            message
        })
    });
    match outcome {
        Ok(()) => OK,
        Err(message) => {
            let status = if status == OK { FATAL } else { status };
            // SAFETY: as above; the body is over.
            if let Some(instance) = unsafe { c.cast::<Instance>().as_ref() } {
                instance.log(status, &message);
            }
            status
        }
    }
}

/// The string at `s` (empty for null).
fn text<'a>(s: FmiString) -> &'a str {
    // SAFETY: null or a NUL-terminated string (the importer's contract).
    if s.is_null() { "" } else { unsafe { CStr::from_ptr(s) }.to_str().unwrap_or("") }
}

/// `n` items at `p` (empty for `n = 0`), or a refusal for null.
fn items<'a, T>(p: *const T, n: usize) -> Result<&'a [T], Refusal> {
    match (p.is_null(), n) {
        (_, 0) => Ok(&[]),
        (true, _) => refuse("an array argument is null"),
        // SAFETY: `n` items at `p` (the importer's contract).
        (false, _) => Ok(unsafe { std::slice::from_raw_parts(p, n) }),
    }
}

fn items_mut<'a, T>(p: *mut T, n: usize) -> Result<&'a mut [T], Refusal> {
    match (p.is_null(), n) {
        (_, 0) => Ok(&mut []),
        (true, _) => refuse("an array argument is null"),
        // SAFETY: `n` writable items at `p` (the importer's contract).
        (false, _) => Ok(unsafe { std::slice::from_raw_parts_mut(p, n) }),
    }
}

/// `"default"`
#[unsafe(no_mangle)]
pub extern "C" fn fmi2GetTypesPlatform() -> FmiString {
    c"default".as_ptr()
}

/// `"2.0"`
#[unsafe(no_mangle)]
pub extern "C" fn fmi2GetVersion() -> FmiString {
    c"2.0".as_ptr()
}

/// Accepted; errors are logged whatever it says.
///
/// # Safety
/// The arguments as FMI 2.0 defines them.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2SetDebugLogging(
    c: Component,
    _on: Boolean,
    _n: usize,
    _categories: *const FmiString,
) -> Status {
    with(c, |_| Ok(()))
}

/// A co-simulation instance of the scenario in `resources`; null, with the reason logged, when it cannot be made.
///
/// # Safety
/// The arguments as FMI 2.0 defines them.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2Instantiate(
    name: FmiString,
    kind: c_int,
    guid: FmiString,
    resources: FmiString,
    callbacks: *const CallbackFunctions,
    _visible: Boolean,
    _logging: Boolean,
) -> Component {
    // SAFETY: null or the importer's callbacks.
    let Some(callbacks) = (unsafe { callbacks.as_ref() }) else { return std::ptr::null_mut() };
    let made = guarded(|| {
        if kind != CO_SIMULATION {
            return Err("cdyn's FMUs are for co-simulation (fmi2CoSimulation) only".to_string());
        }
        Instance::new(text(name), text(guid), text(resources), callbacks).map_err(|(_, m)| m)
    });
    match made {
        Ok(instance) => Box::into_raw(Box::new(instance)).cast(),
        Err(message) => {
            log(callbacks.logger, callbacks.component_environment, name, ERROR, &message);
            std::ptr::null_mut()
        }
    }
}

/// Frees an instance (null is ignored).
///
/// # Safety
/// `c` is null or from fmi2Instantiate, not freed before.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2FreeInstance(c: Component) {
    if !c.is_null() {
        // SAFETY: the importer's contract: a Box made by fmi2Instantiate.
        let _ = guarded(|| {
            drop(unsafe { Box::from_raw(c.cast::<Instance>()) });
            Ok(())
        });
    }
}

/// Start time 0 only (cdyn's runs start there); tolerance and stop time are not used.
///
/// # Safety
/// The arguments as FMI 2.0 defines them.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2SetupExperiment(
    c: Component,
    _tol_defined: Boolean,
    _tol: f64,
    start: f64,
    _stop_defined: Boolean,
    _stop: f64,
) -> Status {
    with(c, |_| if start == 0.0 { Ok(()) } else { refuse(format!("startTime = {start}: cdyn's runs start at t = 0")) })
}

/// Parameters set so far rebuild the case from the scenario.
///
/// # Safety
/// The arguments as FMI 2.0 defines them.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2EnterInitializationMode(c: Component) -> Status {
    with(c, |i| {
        i.apply_parameters()?;
        i.mode = Mode::Initialization;
        Ok(())
    })
}

/// Ready to step.
///
/// # Safety
/// The arguments as FMI 2.0 defines them.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2ExitInitializationMode(c: Component) -> Status {
    with(c, |i| {
        i.apply_parameters()?;
        i.mode = Mode::Stepping;
        Ok(())
    })
}

/// Ends the run.
///
/// # Safety
/// The arguments as FMI 2.0 defines them.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2Terminate(c: Component) -> Status {
    with(c, |i| {
        i.mode = Mode::Terminated;
        Ok(())
    })
}

/// Back to the scenario as shipped, instantiated.
///
/// # Safety
/// The arguments as FMI 2.0 defines them.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2Reset(c: Component) -> Status {
    with(c, |i| i.reset())
}

/// Reals by value reference: parameters, inputs, outputs.
///
/// # Safety
/// The arguments as FMI 2.0 defines them.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2GetReal(c: Component, vr: *const ValueReference, n: usize, values: *mut f64) -> Status {
    with(c, |i| i.get_reals(items(vr, n)?, items_mut(values, n)?))
}

/// Sets parameters (before initialization) and inputs (finite).
///
/// # Safety
/// The arguments as FMI 2.0 defines them.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2SetReal(c: Component, vr: *const ValueReference, n: usize, values: *const f64) -> Status {
    with(c, |i| items(vr, n)?.iter().zip(items(values, n)?).try_for_each(|(&r, &x)| i.set_real(r, x)))
}

/// A refusal for any value reference of a type the FMU has no variables of.
fn none_of(kind: &str, vr: &[ValueReference]) -> Result<(), Refusal> {
    match vr.first() {
        Some(r) => refuse(format!("no {kind} variable has value reference {r}: a cdyn FMU has Real variables only")),
        None => Ok(()),
    }
}

/// No Integer variables.
///
/// # Safety
/// The arguments as FMI 2.0 defines them.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2GetInteger(
    c: Component,
    vr: *const ValueReference,
    n: usize,
    _values: *mut c_int,
) -> Status {
    with(c, |_| none_of("Integer", items(vr, n)?))
}

/// No Integer variables.
///
/// # Safety
/// The arguments as FMI 2.0 defines them.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2SetInteger(
    c: Component,
    vr: *const ValueReference,
    n: usize,
    _values: *const c_int,
) -> Status {
    with(c, |_| none_of("Integer", items(vr, n)?))
}

/// No Boolean variables.
///
/// # Safety
/// The arguments as FMI 2.0 defines them.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2GetBoolean(
    c: Component,
    vr: *const ValueReference,
    n: usize,
    _values: *mut Boolean,
) -> Status {
    with(c, |_| none_of("Boolean", items(vr, n)?))
}

/// No Boolean variables.
///
/// # Safety
/// The arguments as FMI 2.0 defines them.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2SetBoolean(
    c: Component,
    vr: *const ValueReference,
    n: usize,
    _values: *const Boolean,
) -> Status {
    with(c, |_| none_of("Boolean", items(vr, n)?))
}

/// No String variables.
///
/// # Safety
/// The arguments as FMI 2.0 defines them.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2GetString(
    c: Component,
    vr: *const ValueReference,
    n: usize,
    _values: *mut FmiString,
) -> Status {
    with(c, |_| none_of("String", items(vr, n)?))
}

/// No String variables.
///
/// # Safety
/// The arguments as FMI 2.0 defines them.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2SetString(
    c: Component,
    vr: *const ValueReference,
    n: usize,
    _values: *const FmiString,
) -> Status {
    with(c, |_| none_of("String", items(vr, n)?))
}

/// Saves the instance into `*state` (replacing a state given there).
///
/// # Safety
/// The arguments as FMI 2.0 defines them.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2GetFMUstate(c: Component, state: *mut FmuState) -> Status {
    with(c, |i| {
        // SAFETY: null or a place for a state (the importer's contract).
        let Some(place) = (unsafe { state.as_mut() }) else { return refuse("FMUstate is null") };
        let saved = Box::into_raw(Box::new(i.save())).cast();
        if !place.is_null() {
            // SAFETY: a state this library made, being replaced.
            drop(unsafe { Box::from_raw(place.cast::<Saved>()) });
        }
        *place = saved;
        Ok(())
    })
}

/// Restores a state saved of this instance.
///
/// # Safety
/// The arguments as FMI 2.0 defines them.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2SetFMUstate(c: Component, state: FmuState) -> Status {
    with(c, |i| {
        // SAFETY: null or a state from fmi2GetFMUstate (the importer's contract).
        let Some(saved) = (unsafe { state.cast::<Saved>().as_ref() }) else { return refuse("FMUstate is null") };
        i.restore(saved)
    })
}

/// Frees a saved state and sets `*state` to null.
///
/// # Safety
/// The arguments as FMI 2.0 defines them.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2FreeFMUstate(c: Component, state: *mut FmuState) -> Status {
    with(c, |_| {
        // SAFETY: null or a place holding a state from fmi2GetFMUstate.
        if let Some(place) = unsafe { state.as_mut() }
            && !place.is_null()
        {
            // SAFETY: a state this library made.
            drop(unsafe { Box::from_raw(place.cast::<Saved>()) });
            *place = std::ptr::null_mut();
        }
        Ok(())
    })
}

/// Not offered (`canSerializeFMUstate = false`).
///
/// # Safety
/// The arguments as FMI 2.0 defines them.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2SerializedFMUstateSize(c: Component, _state: FmuState, _size: *mut usize) -> Status {
    with(c, |_| refuse("serializing FMU states is not offered (canSerializeFMUstate = false)"))
}

/// Not offered.
///
/// # Safety
/// The arguments as FMI 2.0 defines them.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2SerializeFMUstate(
    c: Component,
    _state: FmuState,
    _bytes: *mut c_char,
    _size: usize,
) -> Status {
    with(c, |_| refuse("serializing FMU states is not offered (canSerializeFMUstate = false)"))
}

/// Not offered.
///
/// # Safety
/// The arguments as FMI 2.0 defines them.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2DeSerializeFMUstate(
    c: Component,
    _bytes: *const c_char,
    _size: usize,
    _state: *mut FmuState,
) -> Status {
    with(c, |_| refuse("serializing FMU states is not offered (canSerializeFMUstate = false)"))
}

/// Not offered (`providesDirectionalDerivative = false`).
///
/// # Safety
/// The arguments as FMI 2.0 defines them.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2GetDirectionalDerivative(
    c: Component,
    _unknown: *const ValueReference,
    _n_unknown: usize,
    _known: *const ValueReference,
    _n_known: usize,
    _dv_known: *const f64,
    _dv_unknown: *mut f64,
) -> Status {
    with(c, |_| refuse("directional derivatives are not offered (providesDirectionalDerivative = false)"))
}

/// Not offered (`canInterpolateInputs = false`).
///
/// # Safety
/// The arguments as FMI 2.0 defines them.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2SetRealInputDerivatives(
    c: Component,
    _vr: *const ValueReference,
    _n: usize,
    _order: *const c_int,
    _values: *const f64,
) -> Status {
    with(c, |_| {
        refuse(
            "input derivatives are not used: inputs are held over a communication step (canInterpolateInputs = false)",
        )
    })
}

/// Not offered (`maxOutputDerivativeOrder = 0`).
///
/// # Safety
/// The arguments as FMI 2.0 defines them.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2GetRealOutputDerivatives(
    c: Component,
    _vr: *const ValueReference,
    _n: usize,
    _order: *const c_int,
    _values: *mut f64,
) -> Status {
    with(c, |_| refuse("output derivatives are not offered (maxOutputDerivativeOrder = 0)"))
}

/// One communication step: a whole number of the scenario's steps `h`.
///
/// # Safety
/// The arguments as FMI 2.0 defines them.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2DoStep(c: Component, t: f64, step: f64, _no_set_state_before: Boolean) -> Status {
    with(c, |i| i.do_step(t, step))
}

/// Steps are never asynchronous: nothing to cancel.
///
/// # Safety
/// The arguments as FMI 2.0 defines them.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2CancelStep(c: Component) -> Status {
    with(c, |_| refuse("fmi2CancelStep: steps are synchronous, none is pending"))
}

/// Nothing is ever pending.
///
/// # Safety
/// The arguments as FMI 2.0 defines them.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2GetStatus(c: Component, _kind: c_int, _value: *mut Status) -> Status {
    with(c, |_| Err((DISCARD, "fmi2GetStatus: no step is pending".into())))
}

/// `fmi2LastSuccessfulTime`: the time reached.
///
/// # Safety
/// The arguments as FMI 2.0 defines them.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2GetRealStatus(c: Component, kind: c_int, value: *mut f64) -> Status {
    with(c, |i| match (kind, items_mut(value, 1)?) {
        (LAST_SUCCESSFUL_TIME, [v]) => {
            *v = i.time();
            Ok(())
        }
        _ => Err((DISCARD, format!("fmi2GetRealStatus: no Real status of kind {kind}"))),
    })
}

/// No Integer status.
///
/// # Safety
/// The arguments as FMI 2.0 defines them.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2GetIntegerStatus(c: Component, kind: c_int, _value: *mut c_int) -> Status {
    with(c, |_| Err((DISCARD, format!("fmi2GetIntegerStatus: no Integer status of kind {kind}"))))
}

/// `fmi2Terminated`: never by the FMU itself (false).
///
/// # Safety
/// The arguments as FMI 2.0 defines them.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2GetBooleanStatus(c: Component, kind: c_int, value: *mut Boolean) -> Status {
    with(c, |_| match (kind, items_mut(value, 1)?) {
        (TERMINATED, [v]) => {
            *v = 0;
            Ok(())
        }
        _ => Err((DISCARD, format!("fmi2GetBooleanStatus: no Boolean status of kind {kind}"))),
    })
}

/// No String status.
///
/// # Safety
/// The arguments as FMI 2.0 defines them.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2GetStringStatus(c: Component, kind: c_int, _value: *mut FmiString) -> Status {
    with(c, |_| Err((DISCARD, format!("fmi2GetStringStatus: no String status of kind {kind}"))))
}
