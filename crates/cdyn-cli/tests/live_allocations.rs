//! A co-simulation step allocates nothing after warm-up: the input set
//! (changed, which restarts the scheme), a step, the outputs read — what
//! `fmi2DoStep` with `fmi2SetReal`/`fmi2GetReal` and the C API do —
//! counted by a global allocator, on the pendulum of
//! `examples/pd_pendulum.toml` and that pendulum stepped by AB-3; and a
//! robot's step and outputs (joint angles among them), on `examples/arm_tethered.toml`,
//! and with actuators (their torques among the outputs) on `examples/arm_pd.toml`.

use cdyn_cli::case::live::Live;
use cdyn_cli::case::scenario;
use cdyn_cli::io::alloc_count::{Counting, thread_allocations};
use std::path::Path;

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

/// `examples/NAME` stepped from outside: refused, naming the first limited
/// joint (arm.urdf's limits are held by cdyn run, and a stepped case does
/// not hold them yet), then the same scenario beside a copy of arm.urdf
/// without its `<limit>`s (and so without their effort clamps).
fn live_without_limits(name: &str) -> Live {
    let examples = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples");
    let text = std::fs::read_to_string(examples.join(name)).unwrap();
    let (parsed, _) = scenario::parse(&text, name).unwrap();
    let refused = Live::from_scenario(&parsed, &examples.join(name)).err().unwrap().to_string();
    assert!(refused.contains("joint shoulder_yaw: limit: joint limits are held by cdyn run"), "{refused}");
    let dir = std::env::temp_dir().join(format!("cdyn-live-{name}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let urdf = std::fs::read_to_string(examples.join("arm.urdf")).unwrap();
    let unlimited: Vec<&str> = urdf.lines().filter(|l| !l.contains("<limit")).collect();
    std::fs::write(dir.join("arm.urdf"), unlimited.join("\n")).unwrap();
    let path = dir.join(name);
    std::fs::write(&path, &text).unwrap();
    Live::from_scenario(&parsed, &path).unwrap()
}

/// Twenty periods of ten steps, each followed by reading every output: no allocation.
fn steps_and_outputs_allocate_nothing(live: &mut Live) {
    let mut outputs = vec![0.0; live.output_names().len()];
    for k in 0..20 {
        let before = count();
        live.step(10).unwrap();
        let stepped = count();
        live.outputs(&mut outputs);
        assert_eq!([stepped - before, count() - stepped], [0, 0], "allocations by step, outputs at period {k}");
    }
}

#[test]
fn a_robots_step_and_outputs_with_its_joint_angles_allocate_nothing() {
    let mut live = live_without_limits("arm_tethered.toml");
    assert!(live.output_names().iter().any(|n| n == "wrist.q"), "{:?}", live.output_names());
    steps_and_outputs_allocate_nothing(&mut live);
}

#[test]
fn an_actuated_robots_step_and_its_torque_outputs_allocate_nothing() {
    let mut live = live_without_limits("arm_pd.toml");
    assert!(live.output_names().iter().any(|n| n == "shoulder_pitch.tau"), "{:?}", live.output_names());
    steps_and_outputs_allocate_nothing(&mut live);
}
