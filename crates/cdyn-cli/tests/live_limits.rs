//! Joint limits in a case stepped from outside (`Live`: Python's
//! `Simulation`, the C API, the FMU): the rod of
//! `examples/limited_pendulum.toml` falls onto its lower limit at
//! t* = 0.335 s and is held there. Stepped, its outputs are `cdyn run`'s
//! rows to the bit; a snapshot taken before the impact and restored after
//! it repeats the run to the bit; an input set survives the models rebuilt
//! at a hit and a release; a state set past a limit is refused.

use crate::common::{cdyn, path_str, scenario, table};
use cdyn_cli::case::live::Live;
use cdyn_cli::case::scenario;
use std::path::{Path, PathBuf};

fn example_path() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/limited_pendulum.toml")
}

fn live_of(text: &str, path: &Path) -> Live {
    let (parsed, _) = scenario::parse(text, &path.display().to_string()).unwrap();
    Live::from_scenario(&parsed, path).unwrap()
}

fn pendulum() -> Live {
    let path = example_path();
    live_of(&std::fs::read_to_string(&path).unwrap(), &path)
}

fn outputs(live: &mut Live) -> Vec<f64> {
    let mut out = vec![0.0; live.output_names().len()];
    live.outputs(&mut out);
    out
}

/// Outputs after each of `periods` periods of ten steps.
fn run(live: &mut Live, periods: usize) -> Vec<Vec<f64>> {
    (0..periods)
        .map(|_| {
            live.step(10).unwrap();
            outputs(live)
        })
        .collect()
}

#[test]
fn stepped_outputs_are_the_rows_cdyn_run_writes_to_the_bit() {
    let out = tempfile::tempdir().unwrap();
    let ran = cdyn(&["run", path_str(&example_path()), "--out", path_str(out.path())]);
    assert!(ran.status.success(), "{}", String::from_utf8_lossy(&ran.stderr));
    let (header, rows) = table(&out.path().join("limited_pendulum.csv"));
    let mut live = pendulum();
    assert_eq!(live.output_names(), &header[..]);
    assert_eq!(rows.len(), 101);
    for (k, row) in rows.iter().enumerate() {
        if k > 0 {
            live.step(10).unwrap();
        }
        let stepped = outputs(&mut live);
        let bits = |x: &[f64]| x.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        assert_eq!(bits(&stepped), bits(row), "row {k} (t = {})", row[0]);
    }
    // The report summary.json has: one impact, held; the velocity bound exceeded.
    let report = live.limits().unwrap();
    assert_eq!(report.events.len(), 1);
    let event = &report.events[0];
    assert_eq!((event.event, event.side, event.held), ("impact", "lower", Some(true)));
    assert!((event.t.0 - 0.33526414955).abs() < 1e-3, "{}", event.t.0);
    assert_eq!(report.velocity_exceeded.len(), 1);
}

#[test]
fn a_snapshot_before_the_impact_restored_after_it_repeats_the_run_to_the_bit() {
    let mut live = pendulum();
    live.step(300).unwrap();
    assert_eq!(live.limit_events(), 0);
    let (saved, at_save) = (live.snapshot(), outputs(&mut live));
    let first = run(&mut live, 20);
    assert_eq!(live.limit_events(), 1, "the impact at 0.335 s is among the steps");
    live.restore(&saved).unwrap();
    assert_eq!((live.steps(), live.limit_events()), (300, 0));
    assert_eq!(outputs(&mut live), at_save);
    assert_eq!(run(&mut live, 20), first);
    // And back again from before the impact to after it.
    let after = live.snapshot();
    let later = run(&mut live, 5);
    live.restore(&saved).unwrap();
    live.restore(&after).unwrap();
    assert_eq!((live.steps(), live.limit_events()), (500, 1));
    assert_eq!(run(&mut live, 5), later);
    // A snapshot restores only the run it was taken of.
    let refused = pendulum().restore(&saved).unwrap_err().to_string();
    assert!(refused.contains("restores the run with stops it was taken of"), "{refused}");
}

/// The pendulum with a torque on its joint, the input `tau`, which lifts
/// the rod off its limit when above its weight's moment there
/// (m g L sin 0.3 = 2.9 N m).
fn actuated() -> Live {
    let path = example_path();
    let text = std::fs::read_to_string(&path).unwrap()
        + "\n[[actuators]]\njoint = \"joints[0]\"\n\n[[inputs]]\nname = \"tau\"\ndrives = \"actuators[0].torque\"\nstart = 0.0\n";
    let (_, path) = scenario("actuated.toml", &text);
    live_of(&text, &path)
}

#[test]
fn an_input_set_survives_the_hit_and_the_release_and_a_snapshot_across_them() {
    let mut live = actuated();
    assert_eq!(live.input_names(), ["tau"]);
    let angle = live.output_names().iter().position(|n| n == "joints[0].q").unwrap();
    live.step(500).unwrap();
    assert_eq!(live.limit_events(), 1, "held at its limit");
    let held = outputs(&mut live)[angle];
    assert!((held + 0.9).abs() < 1e-9, "{held}");
    let saved = live.snapshot();
    live.set_input_named("tau", 10.0).unwrap();
    let lifted = run(&mut live, 10);
    let report = live.limits().unwrap();
    assert_eq!(report.events.iter().map(|e| e.event).collect::<Vec<_>>(), ["impact", "release"]);
    assert_eq!(live.input(0).unwrap(), 10.0, "the input is the rebuilt model's too");
    assert!(lifted[9][angle] > held + 0.01, "lifted off its limit: {}", lifted[9][angle]);
    // Set to nothing, the rod falls back onto its limit: a second impact.
    live.set_input(0, 0.0).unwrap();
    live.step(1000).unwrap();
    let events = live.limits().unwrap().events;
    assert_eq!(events.iter().map(|e| e.event).collect::<Vec<_>>(), ["impact", "release", "impact"], "{events:?}");
    // From the snapshot, the input set again: the same lift to the bit.
    live.restore(&saved).unwrap();
    assert_eq!((live.input(0).unwrap(), live.limit_events()), (0.0, 1));
    live.set_input_named("tau", 10.0).unwrap();
    assert_eq!(run(&mut live, 10), lifted);
}

#[test]
fn a_state_set_past_a_limit_is_refused_and_one_away_from_a_held_limit_lets_it_go() {
    let mut live = pendulum();
    let (q0, v0) = (live.q().to_vec(), live.v().to_vec());
    live.step(500).unwrap();
    assert_eq!(live.limit_events(), 1);
    // The held state, read and set again: still held, no new event.
    let (q, v, e) = (live.q().to_vec(), live.v().to_vec(), live.energy_input());
    live.set_state(&q, &v, e).unwrap();
    live.step(100).unwrap();
    assert_eq!(live.limit_events(), 1);
    // The rod without its limit, 15 ms after it would have met it: past it.
    let path = example_path();
    let text = std::fs::read_to_string(&path).unwrap();
    let limit = text.lines().find(|l| l.starts_with("limit =")).unwrap();
    let mut free = live_of(&text.replace(limit, ""), &path);
    free.step(350).unwrap();
    let message = live.set_state(free.q(), free.v(), 0.0).unwrap_err().to_string();
    assert!(message.contains("joint 0's lower limit is passed by"), "{message}");
    assert_eq!(live.steps(), 600);
    // Back at the start, away from the limit: let go, and it falls onto it again.
    live.set_state(&q0, &v0, 0.0).unwrap();
    live.step(400).unwrap();
    let events = live.limits().unwrap().events;
    assert_eq!(events.iter().map(|e| e.event).collect::<Vec<_>>(), ["impact", "impact"]);
    assert!((events[1].t.0 - (0.6 + 0.33526414955)).abs() < 1e-3, "{}", events[1].t.0);
}
