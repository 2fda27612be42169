//! Inputs set between steps ([`cdyn::model::input`]): a torque, a spring's
//! rest length and a drive's target on a planar pendulum, against runs with
//! the same values as constants and against a fine reference; the energy
//! balance across a change; the errors of a bad input.

use cdyn::model::input::Input;
use cdyn::model::timefn::TimeFn;
use cdyn::planar::{Body, BodyId, Element, Mechanism};
use cdyn::{Control, Scheme, Settings, Simulation};

/// A rigid pendulum pinned at the origin, turned by the input `tau`, pulled
/// by a spring to (1, −1) whose rest length is the input `length`.
fn pendulum(torque: Option<f64>, length: Option<f64>) -> cdyn::planar::Built {
    let mut m = Mechanism::new([0.0, -9.81]);
    let bob = m.push(Body::rigid("bob", 1.0, 0.1, [0.0, -1.0], 0.0));
    m.add(Element::Revolute { a: BodyId::Ground, pa: [0.0, 0.0], b: bob, pb: [0.0, 1.0], limit: None });
    m.add(Element::AppliedTorque { body: bob, f: TimeFn::constant(torque.unwrap_or(0.0)) });
    m.add(Element::Spring {
        a: bob,
        pa: [0.0, 0.0],
        b: BodyId::Ground,
        pb: [1.0, -1.0],
        stiffness: 20.0,
        rest_length: length.unwrap_or(0.5),
    });
    if torque.is_none() {
        m.drive(1, "torque", &Input::new("tau", 0.0));
    }
    if length.is_none() {
        m.drive(2, "rest_length", &Input::new("length", 0.5));
    }
    m.build().unwrap()
}

/// `(time, input, value)`: the changes of a run.
const SCHEDULE: [(f64, usize, f64); 3] = [(0.25, 0, 2.0), (0.5, 1, 0.8), (0.75, 0, -1.0)];

/// Runs the pendulum with inputs to t = 1 changing as [`SCHEDULE`] says;
/// returns the end state and the largest |Ψ| after each step.
fn run(scheme: Scheme, h: f64, control: Control) -> (Vec<f64>, f64) {
    let built = pendulum(None, None);
    let settings = Settings::new(scheme, h, control);
    let mut sim = Simulation::new(&built.model, settings, &built.q0, &built.v0).unwrap();
    let steps = (1.0 / h).round() as u64;
    let mut psi = 0.0_f64;
    for k in 0..steps {
        for &(t, input, value) in &SCHEDULE {
            if ((t / h).round() as u64) == k {
                sim.set_input(input, value).unwrap();
            }
        }
        sim.step().unwrap();
        psi = psi.max(sim.measure().psi.abs());
    }
    (sim.q().iter().chain(sim.v()).copied().collect(), psi)
}

fn max_diff(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).fold(0.0, |m, (x, y)| m.max((x - y).abs()))
}

/// The end-state error against RK-4 at h/64 (the schedule on the same
/// grid). Measured with the history kept instead of restarted at each
/// change: AB-3 1.2e-2 → 5.8e-3 and ABM-4 3.6e-3 → 1.6e-3 from h = 0.01 to
/// 0.005 (order 1: the old forces extrapolated across each jump); with the
/// restart, these (order 3 and 4, as without inputs):
#[test]
fn restarting_the_scheme_at_each_change_keeps_its_order() {
    let (reference, _) = run(Scheme::RungeKutta4, 0.01 / 64.0, Control::none());
    for (scheme, order, coarse) in [
        (Scheme::AdamsBashforth3, 2.9, 4e-4),
        (Scheme::AdamsBashforthMoulton4, 3.7, 2e-6),
        (Scheme::RungeKutta4, 3.8, 2e-7),
    ] {
        let e: Vec<f64> =
            [0.01, 0.005].iter().map(|&h| max_diff(&run(scheme, h, Control::none()).0, &reference)).collect();
        let observed = (e[0] / e[1]).log2();
        assert!(e[0] < coarse && observed > order, "{scheme:?}: errors {e:?}, order {observed:.2}");
    }
}

#[test]
fn an_input_set_before_the_first_step_runs_as_the_same_constants() {
    let constants = pendulum(Some(2.0), Some(0.8));
    let inputs = pendulum(None, None);
    let settings = Settings::new(Scheme::AdamsBashforthMoulton4, 0.01, Control::none());
    let mut a = Simulation::new(&constants.model, settings, &constants.q0, &constants.v0).unwrap();
    let mut b = Simulation::new(&inputs.model, settings, &inputs.q0, &inputs.v0).unwrap();
    b.set_input_named("tau", 2.0).unwrap();
    b.set_input_named("length", 0.8).unwrap();
    assert_eq!((b.input(0).unwrap(), b.input(1).unwrap()), (2.0, 0.8));
    for _ in 0..50 {
        a.step().unwrap();
        b.step().unwrap();
    }
    assert_eq!((a.q(), a.v()), (b.q(), b.v()));
    // Ψ is the same to round-off: E₀ differs by the jump of V, and ∫Ė by the same.
    assert!((a.measure().psi - b.measure().psi).abs() < 1e-13);
}

/// A rest length stepped from 0.5 to 0.8 makes V jump by about 1.4 (and a
/// torque stepped twice); with the jump moved into ∫Ė, `robust` keeps |Ψ|
/// at round-off (1.2e-14 measured) and no control at its integration error.
#[test]
fn a_changed_rest_length_leaves_the_energy_balance_as_it_was() {
    let (_, robust) = run(Scheme::AdamsBashforthMoulton4, 0.01, Control::robust());
    let (_, none) = run(Scheme::AdamsBashforthMoulton4, 0.01, Control::none());
    assert!(robust < 1e-12 && none < 1e-5, "max |Ψ|: robust {robust:.3e}, none {none:.3e}");
}

/// A slider whose x is driven by the input `target`, with a pendulum
/// hanging from it: the drive does work when its target moves.
fn driven_slider() -> cdyn::planar::Built {
    let mut m = Mechanism::new([0.0, -9.81]);
    let slider = m.push(Body::rigid("slider", 2.0, 0.1, [0.0, 0.0], 0.0));
    let bob = m.push(Body::point("bob", 1.0, [0.0, -1.0]));
    m.add(Element::DriveCoordinate { body: slider, coordinate: cdyn::planar::Coordinate::Y, f: TimeFn::constant(0.0) });
    m.add(Element::DriveCoordinate { body: slider, coordinate: cdyn::planar::Coordinate::X, f: TimeFn::constant(0.0) });
    m.add(Element::Distance { a: slider, pa: [0.0, 0.0], b: bob, pb: [0.0, 0.0], length: 1.0 });
    m.drive(1, "function", &Input::new("target", 0.0));
    m.build().unwrap()
}

/// A drive's target jumps: (q, v) are put on the constraints at once and ∫Ė
/// takes the change of T + V, so Φ and Φ̇ are at round-off and Ψ as it was, for
/// a control law and without one; after it `robust` holds them there.
#[test]
fn a_changed_drive_target_is_met_at_once_and_its_work_counted() {
    for control in [Control::robust(), Control::none()] {
        let built = driven_slider();
        let settings = Settings::new(Scheme::AdamsBashforthMoulton4, 0.01, control);
        let mut sim = Simulation::new(&built.model, settings, &built.q0, &built.v0).unwrap();
        for k in 0..100 {
            if k == 10 || k == 40 {
                let (before, psi) = (sim.energy_input(), sim.measure().psi);
                sim.set_input(0, 0.1 * k as f64 / 10.0).unwrap();
                let m = sim.measure();
                assert!(m.phi.abs() < 1e-14 && m.phi_dot < 1e-14 && (m.psi - psi).abs() < 1e-14, "after: {m:?}");
                assert!(sim.energy_input() != before, "the drive's work is counted");
                assert_eq!(sim.q()[0], 0.1 * k as f64 / 10.0);
            }
            sim.step().unwrap();
            if control.is_active() {
                let m = sim.measure();
                assert!(m.phi.abs() < 1e-12 && m.psi.abs() < 1e-12, "step {k}: {m:?}");
            }
        }
    }
}

#[test]
fn a_bad_input_value_or_name_is_refused_with_what_exists() {
    let built = pendulum(None, None);
    let settings = Settings::new(Scheme::RungeKutta4, 0.01, Control::none());
    let mut sim = Simulation::new(&built.model, settings, &built.q0, &built.v0).unwrap();
    let nan = sim.set_input(0, f64::NAN).unwrap_err();
    assert_eq!(nan.to_string(), "input \"tau\": NaN: must be finite");
    assert_eq!(sim.input(0).unwrap(), 0.0, "a refused value is not set");
    let unknown = sim.set_input_named("torque", 1.0).unwrap_err();
    assert_eq!(unknown.to_string(), "input \"torque\": no such input; the model has the inputs tau, length");
    assert!(sim.set_input(2, 1.0).is_err());
    let mut m = Mechanism::new([0.0, -9.81]);
    let bob = m.push(Body::rigid("bob", 1.0, 0.1, [0.0, -1.0], 0.0));
    m.add(Element::Revolute { a: BodyId::Ground, pa: [0.0, 0.0], b: bob, pb: [0.0, 1.0], limit: None });
    m.drive(0, "length", &Input::new("l", 1.0));
    let e = m.build().err().unwrap().to_string();
    assert!(
        e.contains("input \"l\" on length: a revolute has no key an input drives by that name (it has: none)"),
        "{e}"
    );
}

/// A snapshot taken mid-run, restored after more steps and input changes,
/// repeats the run from there to the bit, for every scheme (its history,
/// RATTLE's kept evaluation, generalized-α's accelerations, the gains).
#[test]
fn a_restored_snapshot_repeats_the_run_bit_for_bit() {
    let built = pendulum(None, None);
    for scheme in [
        Scheme::AdamsBashforth3,
        Scheme::AdamsBashforthMoulton4,
        Scheme::RungeKutta4,
        Scheme::Rattle,
        Scheme::GeneralizedAlpha,
    ] {
        let control = if scheme.steps_model() { Control::none() } else { Control::robust() };
        let settings = Settings::new(scheme, 0.01, control);
        let mut sim = Simulation::new(&built.model, settings, &built.q0, &built.v0).unwrap();
        let steps = |sim: &mut Simulation<'_>, from: u64| -> Vec<f64> {
            let mut trace = Vec::new();
            for k in from..from + 30 {
                sim.set_input(0, (k as f64 * 0.37).sin()).unwrap();
                sim.step().unwrap();
                trace.extend(sim.q().iter().chain(sim.v()).chain([&sim.energy_input()]));
            }
            trace
        };
        steps(&mut sim, 0);
        let snapshot = sim.snapshot();
        let first = steps(&mut sim, 30);
        sim.set_input(1, 0.9).unwrap();
        steps(&mut sim, 60);
        sim.restore(&snapshot).unwrap();
        assert_eq!((sim.steps(), sim.input(1).unwrap()), (30, 0.5));
        let again = steps(&mut sim, 30);
        assert!(first.iter().zip(&again).all(|(a, b)| a.to_bits() == b.to_bits()), "{scheme:?}");
    }
}
