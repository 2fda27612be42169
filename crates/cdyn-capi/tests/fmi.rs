//! The FMI 2.0 functions through the C ABI, as an importer calls them:
//! an instance reads its scenario from resources/ and checks the GUID;
//! refused calls return fmi2Error with one line logged, never a crash;
//! two instances stay apart; FMU states repeat the run bit for bit;
//! parameters set before initialization rebuild the case; a communication
//! step (fmi2SetReal, fmi2DoStep, fmi2GetReal) allocates nothing.

use cdyn_capi::fmi::*;
use cdyn_cli::io::alloc_count::{Counting, thread_allocations};
use std::ffi::{CStr, CString, c_char, c_int, c_void};
use std::sync::Mutex;

/// Counts allocations by thread (`thread_allocations`): the harness's other threads do not count.
#[global_allocator]
static GLOBAL: Counting = Counting;

const SCENARIO: &str = include_str!("../../../examples/pd_pendulum.toml");

/// The messages an instance logged.
type Log = Mutex<Vec<(c_int, String)>>;

/// A logger with the logger's fixed arguments and the one the library
/// passes for its `"%s"` format: called through the variadic type, it
/// reads what the caller passed (the x86-64 and AArch64 C calling
/// conventions place these arguments alike).
extern "C" fn capture(
    env: *mut c_void,
    _name: FmiString,
    status: Status,
    _category: FmiString,
    _format: FmiString,
    message: *const c_char,
) {
    let log = unsafe { &*(env as *const Log) };
    log.lock().unwrap().push((status, unsafe { CStr::from_ptr(message) }.to_string_lossy().into_owned()));
}

/// A folder with resources/scenario.toml holding `text`.
fn resources(text: &str) -> (tempfile::TempDir, CString) {
    let dir = tempfile::tempdir().unwrap();
    std::fs::create_dir(dir.path().join("resources")).unwrap();
    std::fs::write(dir.path().join("resources/scenario.toml"), text).unwrap();
    let uri = CString::new(format!("file://{}", dir.path().join("resources").display())).unwrap();
    (dir, uri)
}

fn guid(text: &str) -> CString {
    let (_, table) = cdyn_cli::case::scenario::parse(text, "x").unwrap();
    CString::new(cdyn_cli::export::variables::guid(&table, None)).unwrap()
}

struct Fmu {
    c: Component,
    log: Box<Log>,
    _callbacks: Box<CallbackFunctions>,
}

fn instantiate(uri: &CStr, guid: &CStr) -> Fmu {
    let log: Box<Log> = Box::default();
    let logger: Logger = unsafe { std::mem::transmute(capture as extern "C" fn(_, _, _, _, _, _)) };
    let callbacks = Box::new(CallbackFunctions {
        logger: Some(logger),
        allocate_memory: None,
        free_memory: None,
        step_finished: None,
        component_environment: (&*log as *const Log).cast_mut().cast(),
    });
    let c = unsafe { fmi2Instantiate(c"pd".as_ptr(), 1, guid.as_ptr(), uri.as_ptr(), &*callbacks, 0, 0) };
    Fmu { c, log, _callbacks: callbacks }
}

impl Fmu {
    fn start(&self) {
        unsafe {
            assert_eq!(fmi2SetupExperiment(self.c, 0, 0.0, 0.0, 0, 0.0), OK);
            assert_eq!(fmi2EnterInitializationMode(self.c), OK);
            assert_eq!(fmi2ExitInitializationMode(self.c), OK);
        }
    }
    fn get(&self, vr: u32) -> f64 {
        let mut x = 0.0;
        assert_eq!(unsafe { fmi2GetReal(self.c, &vr, 1, &mut x) }, OK);
        x
    }
    fn set(&self, vr: u32, x: f64) -> Status {
        unsafe { fmi2SetReal(self.c, &vr, 1, &x) }
    }
    fn last(&self) -> (c_int, String) {
        self.log.lock().unwrap().last().cloned().unwrap()
    }
}

impl Drop for Fmu {
    fn drop(&mut self) {
        unsafe { fmi2FreeInstance(self.c) };
    }
}

// Value references of pd_pendulum.toml: 8 parameters (gravity, mass,
// inertia, position, point_b), the input tau, then t, link.angle, link.x, link.y, psi.
const GRAVITY_Y: u32 = 1;
const TAU: u32 = 8;
const T: u32 = 9;
const ANGLE: u32 = 10;

#[test]
fn refused_calls_return_an_error_with_one_line_logged() {
    let (_dir, uri) = resources(SCENARIO);
    let fmu = instantiate(&uri, &guid(SCENARIO));
    assert!(!fmu.c.is_null());
    fmu.start();
    assert_eq!(fmu.set(TAU, f64::NAN), ERROR);
    assert_eq!(fmu.last(), (ERROR, "tau = NaN: must be finite".into()));
    assert_eq!(unsafe { fmi2GetReal(fmu.c, &99, 1, &mut 0.0) }, ERROR);
    assert_eq!(fmu.last().1, "no Real variable has value reference 99 (there are 14)");
    assert_eq!(unsafe { fmi2DoStep(fmu.c, 0.0, 0.0015, 1) }, ERROR);
    assert_eq!(fmu.last().1, "communication step 0.0015 is not a whole number of the scenario's steps h = 0.001");
    assert_eq!(unsafe { fmi2DoStep(fmu.c, 0.5, 0.001, 1) }, ERROR);
    assert_eq!(fmu.set(GRAVITY_Y, 0.0), ERROR);
    assert!(fmu.last().1.contains("set before initialization only"));
    assert_eq!(unsafe { fmi2GetInteger(fmu.c, &0, 1, &mut 0) }, ERROR);
    assert_eq!(fmu.set(T, 1.0), ERROR);
    assert!(fmu.log.lock().unwrap().iter().all(|(s, m)| *s == ERROR && !m.contains('\n')));
    // Still usable after each refusal.
    assert_eq!(unsafe { fmi2DoStep(fmu.c, 0.0, 0.01, 1) }, OK);
    assert_eq!(fmu.get(T), 0.01);
}

#[test]
fn a_missing_or_wrong_resource_or_guid_logs_why_and_gives_no_instance() {
    let (dir, uri) = resources(SCENARIO);
    let wrong_guid = instantiate(&uri, c"{00000000-0000-0000-0000-000000000000}");
    assert!(wrong_guid.c.is_null());
    assert!(wrong_guid.last().1.starts_with("GUID {00000000-0000-0000-0000-000000000000} is not that of the scenario"));
    std::fs::remove_file(dir.path().join("resources/scenario.toml")).unwrap();
    let missing = instantiate(&uri, &guid(SCENARIO));
    assert!(missing.c.is_null() && missing.last().1.contains("cannot read"), "{:?}", missing.last());
    let bad = SCENARIO.replace("mass = 1.0", "mas = 1.0");
    let (_bad_dir, bad_uri) = resources(&bad);
    let broken = instantiate(&bad_uri, &guid(SCENARIO));
    assert!(broken.c.is_null() && broken.last().1.contains("bodies[0]"), "{:?}", broken.last());
}

#[test]
fn two_instances_stay_apart_and_states_repeat_the_run_bit_for_bit() {
    let (_dir, uri) = resources(SCENARIO);
    let (a, b) = (instantiate(&uri, &guid(SCENARIO)), instantiate(&uri, &guid(SCENARIO)));
    a.start();
    b.start();
    assert_eq!(a.set(TAU, 5.0), OK);
    let step = |f: &Fmu, n: usize| (0..n).for_each(|_| assert_eq!(unsafe { fmi2DoStep(f.c, f.get(T), 0.01, 1) }, OK));
    step(&a, 10);
    step(&b, 10);
    assert!(a.get(ANGLE) > b.get(ANGLE) + 1e-3 && b.get(TAU) == 0.0);
    let mut state: FmuState = std::ptr::null_mut();
    assert_eq!(unsafe { fmi2GetFMUstate(a.c, &mut state) }, OK);
    let run = |f: &Fmu| {
        (0..10)
            .map(|k| {
                f.set(TAU, (k as f64).sin());
                step(f, 1);
                f.get(ANGLE).to_bits()
            })
            .collect::<Vec<u64>>()
    };
    let first = run(&a);
    assert_eq!(unsafe { fmi2SetFMUstate(a.c, state) }, OK);
    assert_eq!((a.get(T), a.get(TAU)), (0.1, 5.0));
    assert_eq!(run(&a), first);
    assert_eq!(unsafe { fmi2SetFMUstate(b.c, state) }, ERROR);
    assert_eq!(unsafe { fmi2FreeFMUstate(a.c, &mut state) }, OK);
    assert!(state.is_null());
}

#[test]
fn parameters_set_before_initialization_rebuild_the_case_and_reset_undoes_them() {
    let (_dir, uri) = resources(SCENARIO);
    let fmu = instantiate(&uri, &guid(SCENARIO));
    assert_eq!(fmu.set(GRAVITY_Y, 0.0), OK);
    fmu.start();
    assert_eq!(fmu.get(GRAVITY_Y), 0.0);
    assert_eq!(unsafe { fmi2DoStep(fmu.c, 0.0, 0.1, 1) }, OK);
    assert_eq!(fmu.get(ANGLE), 0.0, "no gravity, no torque: the link stays");
    assert_eq!(unsafe { fmi2Reset(fmu.c) }, OK);
    fmu.start();
    assert_eq!(unsafe { fmi2DoStep(fmu.c, 0.0, 0.1, 1) }, OK);
    assert!(fmu.get(ANGLE) < -0.01 && fmu.get(GRAVITY_Y) == -9.81);
}

/// What an importer does every communication step — set the input, step
/// (10 steps of h), read every output — allocates nothing, from the first
/// step after initialization on, a changed input included.
#[test]
fn a_communication_step_allocates_nothing() {
    let (_dir, uri) = resources(SCENARIO);
    let fmu = instantiate(&uri, &guid(SCENARIO));
    fmu.start();
    let (vrs, mut outputs) = ([T, ANGLE, 11, 12, 13], [0.0; 5]);
    for k in 0..50 {
        let before = thread_allocations();
        assert_eq!(fmu.set(TAU, (k as f64 * 0.1).sin()), OK);
        assert_eq!(unsafe { fmi2DoStep(fmu.c, k as f64 * 0.01, 0.01, 1) }, OK);
        assert_eq!(unsafe { fmi2GetReal(fmu.c, vrs.as_ptr(), vrs.len(), outputs.as_mut_ptr()) }, OK);
        assert_eq!(thread_allocations() - before, 0, "communication step {k}");
    }
    assert!((outputs[0] - 0.5).abs() < 1e-12);
}

/// `examples/limited_pendulum.toml` as an FMU: its joint limit held as
/// `cdyn run` holds it (the angle each communication step equals the
/// CSV's to the bit), and a communication step allocates nothing but the
/// one with the impact at t = 0.335 s, which builds the model holding the
/// limit.
#[test]
fn a_limited_case_steps_as_cdyn_run_runs_it_allocating_only_at_its_impact() {
    let text = include_str!("../../../examples/limited_pendulum.toml");
    let (_, _, _, variables) = cdyn_cli::export::variables::load(text, std::path::Path::new("x.toml")).unwrap();
    let vr = |name: &str| variables.iter().position(|v| v.name == name).unwrap() as u32;
    let (parsed, _) = cdyn_cli::case::scenario::parse(text, "x").unwrap();
    let case = parsed.case(std::path::Path::new("x")).unwrap();
    let (_, rows) = cdyn_cli::case::runner::run_case_in_memory(&case, &|| false);
    let angle = rows.columns.iter().position(|c| c == "joints[0].q").unwrap();
    let (_dir, uri) = resources(text);
    let fmu = instantiate(&uri, &guid(text));
    fmu.start();
    let mut allocating = Vec::new();
    for (k, row) in rows.values.chunks(rows.columns.len()).enumerate().skip(1) {
        let before = thread_allocations();
        assert_eq!(unsafe { fmi2DoStep(fmu.c, (k - 1) as f64 * 0.01, 0.01, 1) }, OK);
        let q = fmu.get(vr("joints[0].q"));
        if thread_allocations() != before {
            allocating.push(k);
        }
        assert_eq!(q.to_bits(), row[angle].to_bits(), "joints[0].q at communication step {k}");
    }
    assert_eq!(allocating, [34], "the impact's step, to t = 0.34 s");
    assert!((fmu.get(vr("joints[0].q")) + 0.9).abs() < 1e-9);
}
