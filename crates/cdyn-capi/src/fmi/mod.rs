//! FMI 2.0 co-simulation: the functions an importer (FMPy, OpenModelica,
//! Simulink, a HIL rig) calls on the binary of an FMU that `cdyn fmu`
//! wrote. One library serves every scenario: an instance reads the
//! scenario (and its URDF) from the FMU's `resources/`, checks the GUID,
//! and steps the case as [`Live`](cdyn_cli::case::live::Live) does.
//!
//! The types are those of the standard's `fmi2TypesPlatform.h` and
//! `fmi2FunctionTypes.h`, written out here (C enums as `int`).
//!
//! Here the types; `instance` an instance's life (variables, modes,
//! steps); `functions` the exported `fmi2…` functions.

mod functions;
mod instance;

pub use functions::*;

use std::ffi::{c_char, c_int, c_void};

/// `fmi2Status`.
pub type Status = c_int;
/// `fmi2OK`
pub const OK: Status = 0;
/// `fmi2Warning`
pub const WARNING: Status = 1;
/// `fmi2Discard`
pub const DISCARD: Status = 2;
/// `fmi2Error`
pub const ERROR: Status = 3;
/// `fmi2Fatal`
pub const FATAL: Status = 4;

/// `fmi2Type`: `fmi2CoSimulation`.
pub const CO_SIMULATION: c_int = 1;

/// `fmi2StatusKind`: `fmi2LastSuccessfulTime`.
pub const LAST_SUCCESSFUL_TIME: c_int = 2;
/// `fmi2StatusKind`: `fmi2Terminated`.
pub const TERMINATED: c_int = 3;

/// `fmi2Boolean`.
pub type Boolean = c_int;
/// `fmi2ValueReference`.
pub type ValueReference = u32;
/// `fmi2String`.
pub type FmiString = *const c_char;

/// `fmi2CallbackLogger`: printf-like, the message a format.
pub type Logger = unsafe extern "C" fn(
    env: *mut c_void,
    instance: FmiString,
    status: Status,
    category: FmiString,
    message: FmiString,
    ...
);

/// `fmi2CallbackFunctions`.
#[repr(C)]
pub struct CallbackFunctions {
    /// Where messages go.
    pub logger: Option<Logger>,
    /// Not used (`canNotUseMemoryManagementFunctions`).
    pub allocate_memory: Option<unsafe extern "C" fn(usize, usize) -> *mut c_void>,
    /// Not used.
    pub free_memory: Option<unsafe extern "C" fn(*mut c_void)>,
    /// Not used (no asynchronous steps).
    pub step_finished: Option<unsafe extern "C" fn(*mut c_void, Status)>,
    /// Handed back to the logger.
    pub component_environment: *mut c_void,
}
