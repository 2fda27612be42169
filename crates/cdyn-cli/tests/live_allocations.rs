//! A co-simulation step allocates nothing after warm-up: the input set
//! (changed, which restarts the scheme), a step, the outputs read — what
//! `fmi2DoStep` with `fmi2SetReal`/`fmi2GetReal` and the C API do —
//! counted by a global allocator, on the pendulum of
//! `examples/pd_pendulum.toml` and that pendulum stepped by AB-3; and a
//! robot's step and outputs (joint angles among them), on `examples/arm_tethered.toml`,
//! and with actuators (their torques among the outputs) on `examples/arm_pd.toml`,
//! both with arm.urdf's joint limits held; and the rod of
//! `examples/limited_pendulum.toml` falling onto its limit and held there,
//! every step but the impact's; and the same of planar mechanisms: the
//! block of `examples/limited_slider.toml` (a prismatic joint's limit) and
//! a planar rod swinging onto a revolute joint's limit.

use cdyn_cli::case::live::Live;
use cdyn_cli::case::scenario;
use cdyn_cli::io::alloc_count::{Counting, thread_allocations};
use std::path::Path;

#[path = "common/rod.rs"]
mod rod;

#[global_allocator]
static GLOBAL: Counting = Counting;

/// Allocations by this thread so far.
fn count() -> usize {
    thread_allocations() as usize
}

fn pendulum(scheme: &str) -> Live {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/pd_pendulum.toml");
    let text = std::fs::read_to_string(&path).unwrap().replace("scheme = \"rk4\"", &format!("scheme = \"{scheme}\""));
    let (parsed, _) = scenario::parse(&text, &path.display().to_string()).unwrap();
    Live::from_scenario(&parsed, &path).unwrap()
}

#[test]
fn a_cosimulation_step_allocates_nothing() {
    for scheme in ["rk4", "ab3"] {
        let mut live = pendulum(scheme);
        let mut outputs = vec![0.0; live.output_names().len()];
        let mut cosimulate = |k: usize, live: &mut Live| {
            let before = count();
            live.set_input(0, (k as f64 * 0.1).sin()).unwrap();
            let set = count();
            live.step(10).unwrap();
            let stepped = count();
            live.outputs(&mut outputs);
            [set - before, stepped - set, count() - stepped]
        };
        for k in 0..50 {
            assert_eq!(
                cosimulate(k, &mut live),
                [0, 0, 0],
                "{scheme}: allocations by set_input, step, outputs at period {k}"
            );
        }
    }
}

fn example(name: &str) -> Live {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples").join(name);
    live_of(&std::fs::read_to_string(&path).unwrap(), &path)
}

fn live_of(text: &str, path: &Path) -> Live {
    let (parsed, _) = scenario::parse(text, &path.display().to_string()).unwrap();
    Live::from_scenario(&parsed, path).unwrap()
}

/// Periods of ten steps, each followed by reading every output: no
/// allocation in a period that hit and released no limit (one that did
/// builds the model of the limits held then). Returns how many periods did.
fn steps_and_outputs_allocate_nothing(live: &mut Live, periods: usize) -> usize {
    let mut outputs = vec![0.0; live.output_names().len()];
    let mut changed = 0;
    for k in 0..periods {
        let (before, events) = (count(), live.limit_events());
        live.step(10).unwrap();
        let stepped = count();
        live.outputs(&mut outputs);
        let read = count() - stepped;
        if live.limit_events() == events {
            assert_eq!([stepped - before, read], [0, 0], "allocations by step, outputs at period {k}");
        } else {
            assert_eq!(read, 0, "allocations by outputs at period {k}");
            changed += 1;
        }
    }
    changed
}

#[test]
fn a_robots_step_and_outputs_with_its_joint_angles_allocate_nothing() {
    let mut live = example("arm_tethered.toml");
    assert!(live.output_names().iter().any(|n| n == "wrist.q"), "{:?}", live.output_names());
    assert!(live.limits().is_some(), "arm.urdf's limits are held");
    steps_and_outputs_allocate_nothing(&mut live, 20);
}

#[test]
fn an_actuated_robots_step_and_its_torque_outputs_allocate_nothing() {
    let mut live = example("arm_pd.toml");
    assert!(live.output_names().iter().any(|n| n == "shoulder_pitch.tau"), "{:?}", live.output_names());
    steps_and_outputs_allocate_nothing(&mut live, 20);
}

#[test]
fn a_limited_pendulums_steps_allocate_nothing_but_at_its_impact() {
    // Free until its impact at t = 0.335 s (its velocity bound exceeded on
    // the way: the report's entry has its place), then held to t = 1 s,
    // each of those steps checking whether to release it.
    let mut live = example("limited_pendulum.toml");
    assert_eq!(steps_and_outputs_allocate_nothing(&mut live, 100), 1);
    assert_eq!(live.limits().unwrap().velocity_exceeded.len(), 1);
}

#[test]
fn a_limited_planar_slider_steps_allocate_nothing_but_at_its_impact() {
    // Free until its impact at t = 0.412 s (its velocity bound of 1.5 m/s
    // exceeded on the way), then held to t = 1 s.
    let mut live = example("limited_slider.toml");
    assert_eq!(steps_and_outputs_allocate_nothing(&mut live, 100), 1);
    let limits = live.limits().unwrap();
    assert_eq!((limits.events.len(), limits.velocity_exceeded.len()), (1, 1));
    assert!((limits.events[0].t.0 - 0.41243).abs() < 1e-3, "{}", limits.events[0].t.0);
}

#[test]
fn a_limited_planar_rods_steps_allocate_nothing_but_at_its_impact() {
    // A rigid rod on a revolute joint to the ground, released at 1.2 rad
    // from hanging, swings down onto its lower limit of 0.3 rad (a relative
    // angle, read by dual numbers at every step) and is held there.
    let text = r#"
[model]
kind = "mechanism"
gravity = [0.0, -9.81]

[integrator]
scheme = "rk4"
h = 1e-3
t_end = 1.0

[[bodies]]
name = "rod"
mass = 2.0
inertia = 0.02
position = [0.46601954298361314, -0.1811788772383368]
angle = 1.2

[[joints]]
kind = "revolute"
a = "ground"
b = "rod"
point_b = [0.0, 0.5]
limit = { lower = 0.3, velocity = 2.0 }
"#;
    let mut live = live_of(text, Path::new("limited_rod.toml"));
    assert_eq!(steps_and_outputs_allocate_nothing(&mut live, 100), 1);
    let limits = live.limits().unwrap();
    assert_eq!((limits.events.len(), limits.velocity_exceeded.len()), (1, 1));
    assert_eq!((limits.events[0].event, limits.events[0].side), ("impact", "lower"));
}

#[test]
fn a_multi_turn_joints_steps_through_pi_allocate_nothing_but_at_its_impact() {
    // A rod turning freely at 2 rad/s from 0 through π (its stops' gaps
    // followed across the seam of (−π, π] at every step) to its upper
    // limit 6.28 of a range −2.62 … 6.28, more than a turn, at 3.14 s.
    let mut live = live_of(&rod::turning_finger(0.0, 3.5), Path::new("turning_finger.toml"));
    assert!(steps_and_outputs_allocate_nothing(&mut live, 350) >= 1);
    let first = &live.limits().unwrap().events[0];
    assert_eq!((first.event, first.side), ("impact", "upper"));
    let t_star = rod::FINGER_UPPER / 2.0;
    assert!((first.t.0 - t_star).abs() < 1e-9, "{} against {t_star} by hand", first.t.0);
}
