//! The C API through the C ABI (the `extern "C"` functions called as C
//! calls them): a run equal to `cdyn run`'s rows, inputs, the state read,
//! written, saved and restored bit for bit, instances kept apart, and
//! every bad call an error code with a message, never a crash.

use cdyn_capi::api::*;
use std::ffi::{CStr, CString};
use std::ptr::null_mut;

const SCENARIO: &str = include_str!("../../../examples/pd_pendulum.toml");

fn last_error() -> String {
    unsafe { CStr::from_ptr(cdyn_last_error()) }.to_string_lossy().into_owned()
}

fn create(text: &str) -> Result<*mut CdynSimulation, (CdynStatus, String)> {
    let text = CString::new(text).unwrap();
    let mut sim = null_mut();
    match unsafe { cdyn_create_from_toml(text.as_ptr(), &mut sim) } {
        CdynStatus::Ok => Ok(sim),
        status => Err((status, last_error())),
    }
}

fn outputs(sim: *mut CdynSimulation) -> Vec<f64> {
    let n = unsafe { cdyn_output_count(sim) };
    let mut out = vec![0.0; n];
    assert_eq!(unsafe { cdyn_get_outputs(sim, out.as_mut_ptr(), n) }, CdynStatus::Ok);
    out
}

fn state(sim: *mut CdynSimulation) -> Vec<f64> {
    let n = unsafe { cdyn_state_size(sim) };
    let mut x = vec![0.0; n];
    assert_eq!(unsafe { cdyn_get_state(sim, x.as_mut_ptr(), n) }, CdynStatus::Ok);
    x
}

#[test]
fn a_stepped_run_gives_the_rows_cdyn_run_writes_to_the_bit() {
    let (parsed, _) = cdyn_cli::case::scenario::parse(SCENARIO, "<string>").unwrap();
    let case = parsed.case(std::path::Path::new("<string>")).unwrap();
    let (_, rows) = cdyn_cli::case::runner::run_case_in_memory(&case, &|| false);
    let sim = create(SCENARIO).unwrap();
    let names: Vec<String> = (0..unsafe { cdyn_output_count(sim) })
        .map(|i| unsafe { CStr::from_ptr(cdyn_output_name(sim, i)) }.to_string_lossy().into_owned())
        .collect();
    assert_eq!(names, ["t", "link.angle", "link.x", "link.y", "psi"]);
    assert!(unsafe { cdyn_output_name(sim, 5) }.is_null());
    let width = rows.columns.len();
    let column = |name: &str| rows.columns.iter().position(|c| c == name).unwrap();
    for (k, row) in rows.values.chunks(width).enumerate() {
        let out = outputs(sim);
        for (name, value) in names.iter().zip(&out) {
            assert_eq!(value.to_bits(), row[column(name)].to_bits(), "{name} at sample {k}");
        }
        assert_eq!(unsafe { cdyn_step(sim, 10) }, CdynStatus::Ok);
    }
    unsafe { cdyn_free(sim) };
}

#[test]
fn inputs_act_and_saved_states_repeat_the_run_bit_for_bit() {
    let (a, b) = (create(SCENARIO).unwrap(), create(SCENARIO).unwrap());
    assert_eq!(unsafe { cdyn_input_count(a) }, 1);
    assert_eq!(unsafe { CStr::from_ptr(cdyn_input_name(a, 0)) }.to_str().unwrap(), "tau");
    assert_eq!(unsafe { cdyn_set_input(a, 0, 3.0) }, CdynStatus::Ok);
    unsafe { (cdyn_step(a, 100), cdyn_step(b, 100)) };
    // Two simulations of one scenario have inputs of their own.
    let (ta, tb) = (outputs(a)[1], outputs(b)[1]);
    assert!(ta > tb + 1e-3, "the torque turned a only: {ta} vs {tb}");
    let mut saved = null_mut();
    assert_eq!(unsafe { cdyn_save_state(a, &mut saved) }, CdynStatus::Ok);
    let run = |sim| {
        (0..20)
            .flat_map(|k| {
                unsafe { cdyn_set_input_by_name(sim, c"tau".as_ptr(), (k as f64).cos()) };
                unsafe { cdyn_step(sim, 7) };
                state(sim)
            })
            .collect::<Vec<f64>>()
    };
    let first = run(a);
    assert_eq!(unsafe { cdyn_restore_state(a, saved) }, CdynStatus::Ok);
    let again = run(a);
    assert!(first.iter().zip(&again).all(|(x, y)| x.to_bits() == y.to_bits()));
    // A state of another simulation is refused.
    assert_eq!(unsafe { cdyn_restore_state(b, saved) }, CdynStatus::Argument);
    assert!(last_error().contains("snapshot"), "{}", last_error());
    // The state written back is the state read.
    let x = state(b);
    unsafe { cdyn_step(b, 10) };
    assert_eq!(unsafe { cdyn_set_state(b, x.as_ptr(), x.len()) }, CdynStatus::Ok);
    assert_eq!(state(b), x);
    unsafe { (cdyn_free(a), cdyn_free(b)) };
    // A saved state outlives its simulation and is freed on its own.
    unsafe { cdyn_free_state(saved) };
}

#[test]
fn bad_calls_are_error_codes_with_one_line_never_a_crash() {
    let bad = SCENARIO.replace("mass = 1.0", "mass = 1.0\nmas = 2.0");
    let (status, message) = create(&bad).unwrap_err();
    assert_eq!(status, CdynStatus::Scenario);
    assert!(message.starts_with("<string>: bodies[0]") && message.contains("mas"), "{message}");
    let sim = create(SCENARIO).unwrap();
    assert_eq!(unsafe { cdyn_set_input(sim, 0, f64::NAN) }, CdynStatus::Argument);
    assert_eq!(last_error(), "input \"tau\": NaN: must be finite");
    assert_eq!(unsafe { cdyn_set_input_by_name(sim, c"torque".as_ptr(), 1.0) }, CdynStatus::Argument);
    assert!(last_error().contains("no such input; the model has the inputs tau"));
    let mut two = [0.0; 2];
    assert_eq!(unsafe { cdyn_get_outputs(sim, two.as_mut_ptr(), 2) }, CdynStatus::Argument);
    assert_eq!(last_error(), "values: expected 5 doubles, got 2");
    assert_eq!(unsafe { cdyn_step(null_mut(), 1) }, CdynStatus::Argument);
    assert_eq!(unsafe { cdyn_create_from_toml(std::ptr::null(), &mut null_mut()) }, CdynStatus::Scenario);
    assert_eq!(unsafe { cdyn_create_from_file(c"/no/such.toml".as_ptr(), &mut null_mut()) }, CdynStatus::Scenario);
    assert!(last_error().starts_with("/no/such.toml: cannot read"), "{}", last_error());
    assert!(unsafe { cdyn_time(null_mut()) }.is_nan() && unsafe { cdyn_output_count(null_mut()) } == 0);
    unsafe { (cdyn_free(sim), cdyn_free(null_mut()), cdyn_free_state(null_mut())) };
}

/// A rod on a revolute joint about −y, level at the start, its actuator's
/// torque the input `lift` (`TORQUE` is replaced by the torque's key).
const ACTUATED_ROD: &str = r#"
[model]
kind = "spatial"
gravity = [0.0, 0.0, -9.81]

[integrator]
scheme = "rk4"
h = 1e-3
t_end = 1.0

[[bodies]]
name = "rod"
mass = 1.0
inertia = [0.001, 0.02, 0.02]
position = [0.25, 0.0, 0.0]

[[joints]]
kind = "revolute"
a = "rod"
point = [0.0, 0.0, 0.0]
axis = [0.0, -1.0, 0.0]

[[actuators]]
joint = "joints[0]"
TORQUE
"#;

#[test]
fn an_actuators_input_set_through_the_c_api_moves_the_arm_as_the_same_constant_torque_does() {
    let input = ACTUATED_ROD.replace("TORQUE", "")
        + "[[inputs]]\nname = \"lift\"\ndrives = \"actuators[0].torque\"\nstart = 0.0\n";
    let (driven, constant, idle) = (
        create(&input).unwrap(),
        create(&ACTUATED_ROD.replace("TORQUE", "torque = 3.0")).unwrap(),
        create(&input).unwrap(),
    );
    let names: Vec<String> = (0..unsafe { cdyn_output_count(driven) })
        .map(|i| unsafe { CStr::from_ptr(cdyn_output_name(driven, i)) }.to_string_lossy().into_owned())
        .collect();
    let tau = names.iter().position(|n| n == "joints[0].tau").unwrap();
    assert_eq!(unsafe { cdyn_set_input_by_name(driven, c"lift".as_ptr(), 3.0) }, CdynStatus::Ok);
    for _ in 0..5 {
        unsafe { (cdyn_step(driven, 40), cdyn_step(constant, 40), cdyn_step(idle, 40)) };
        // The input's value is the torque: the same motion to the bit.
        assert_eq!(state(driven), state(constant));
        assert_eq!((outputs(driven)[tau], outputs(idle)[tau]), (3.0, 0.0));
    }
    // 3 N m against the weight's 2.45 N m lifts the rod; without it, it falls.
    let q = names.iter().position(|n| n == "joints[0].q").unwrap();
    assert!(outputs(driven)[q] > 0.0 && outputs(idle)[q] < -0.1, "{} {}", outputs(driven)[q], outputs(idle)[q]);
    unsafe { (cdyn_free(driven), cdyn_free(constant), cdyn_free(idle)) };
}

/// `examples/limited_pendulum.toml` through the C API: the rows `cdyn run`
/// writes to the bit, its limit held (one impact, counted by
/// `cdyn_limit_events`), and a state saved before the impact and restored
/// after it repeating the run to the bit.
#[test]
fn a_case_with_joint_limits_runs_as_cdyn_run_runs_it_and_restores_across_its_impact() {
    let text = include_str!("../../../examples/limited_pendulum.toml");
    let (parsed, _) = cdyn_cli::case::scenario::parse(text, "<string>").unwrap();
    let case = parsed.case(std::path::Path::new("<string>")).unwrap();
    let (_, rows) = cdyn_cli::case::runner::run_case_in_memory(&case, &|| false);
    let sim = create(text).unwrap();
    let bits = |x: &[f64]| x.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
    let mut saved = null_mut();
    for (k, row) in rows.values.chunks(rows.columns.len()).enumerate() {
        assert_eq!(bits(&outputs(sim)), bits(row), "sample {k}");
        if k == 30 {
            assert_eq!(unsafe { cdyn_save_state(sim, &mut saved) }, CdynStatus::Ok);
        }
        assert_eq!(unsafe { cdyn_step(sim, 10) }, CdynStatus::Ok);
    }
    assert_eq!(unsafe { cdyn_limit_events(sim) }, 1);
    assert_eq!(unsafe { cdyn_restore_state(sim, saved) }, CdynStatus::Ok);
    assert_eq!(unsafe { cdyn_limit_events(sim) }, 0);
    for (k, row) in rows.values.chunks(rows.columns.len()).enumerate().skip(30).take(20) {
        assert_eq!(bits(&outputs(sim)), bits(row), "sample {k} after the restore");
        assert_eq!(unsafe { cdyn_step(sim, 10) }, CdynStatus::Ok);
    }
    assert_eq!(unsafe { cdyn_limit_events(sim) }, 1);
    assert_eq!(unsafe { cdyn_limit_events(std::ptr::null()) }, 0);
    unsafe { cdyn_free_state(saved) };
    unsafe { cdyn_free(sim) };
}
