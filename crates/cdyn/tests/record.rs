//! The recorder: which states are sampled, what the statistics are, the
//! series flag, and what a failing run keeps.

use cdyn::control::{Control, Gain, Geometric};
use cdyn::models::{Example, PendulumParams, cartesian_pendulum};
use cdyn::record::{Recorder, Sample};
use cdyn::{Error, Scheme, Settings, Simulation};
use std::convert::Infallible;

/// What a sink saw of one sample.
#[derive(Debug, Clone, PartialEq)]
struct Seen {
    step: u64,
    t: f64,
    observables: Vec<f64>,
    phi: f64,
    psi: f64,
    coupling: f64,
    error: Option<f64>,
}

fn seen(s: &Sample<'_>) -> Seen {
    Seen {
        step: s.step,
        t: s.t,
        observables: s.observables.to_vec(),
        phi: s.measures.phi,
        psi: s.measures.psi,
        coupling: s.measures.coupling,
        error: s.error,
    }
}

fn pendulum() -> Example {
    cartesian_pendulum(PendulumParams::default()).unwrap()
}

/// Baumgarte-free CVSGF at rate `alpha_g`.
fn cvsgf(alpha_g: f64) -> Control {
    Control::none().with_geometric(Geometric::Gradient(Gain::Rate(alpha_g)))
}

#[test]
fn every_kth_step_and_the_last_are_sampled() {
    let ex = pendulum();
    let settings = Settings::new(Scheme::RungeKutta4, 0.01, cvsgf(10.0));
    let mut sim = Simulation::new(&ex.model, settings, &ex.q0, &ex.v0).unwrap();
    let mut samples = Vec::new();
    // 10 steps, sampled every 3: the last step is not a multiple of 3.
    let record = Recorder::coordinates()
        .sink(|s: &Sample<'_>| -> Result<(), Infallible> {
            samples.push(seen(s));
            Ok(())
        })
        .run(&mut sim, 0.1, 3)
        .unwrap();
    let steps: Vec<u64> = samples.iter().map(|s| s.step).collect();
    assert_eq!(steps, [0, 3, 6, 9, 10]);
    assert_eq!(record.steps, 10);
    let last = samples.last().unwrap();
    assert_eq!(last.t, record.t_final);
    // A bare model observes its coordinates.
    assert_eq!(last.observables, record.q_end);
    assert_eq!(record.q_end, sim.q());
    assert_eq!(record.v_end, sim.v());
    assert_eq!(record.evaluations, sim.evaluations());
    assert!(record.error.is_none() && record.max_abs_error.is_none() && record.final_error.is_none());
}

#[test]
fn statistics_are_the_largest_over_the_samples() {
    let ex = pendulum();
    let settings = Settings::new(Scheme::AdamsBashforth3, 0.05, Control::none());
    let mut sim = Simulation::new(&ex.model, settings, &ex.q0, &ex.v0).unwrap();
    let mut samples = Vec::new();
    let record = Recorder::example(&ex)
        .sink(|s: &Sample<'_>| -> Result<(), Infallible> {
            samples.push(seen(s));
            Ok(())
        })
        .run(&mut sim, 2.0, 4)
        .unwrap();
    assert_eq!(samples.len(), 11); // 40 steps: 0, 4, …, 40
    // Each sample against the example's own (allocating) observe and error.
    let mut check = Simulation::new(&ex.model, settings, &ex.q0, &ex.v0).unwrap();
    let mut max_phi_dot = 0.0_f64;
    for s in &samples {
        while check.steps() < s.step {
            check.step().unwrap();
        }
        assert_eq!(s.observables, ex.observe(check.t(), check.q(), check.v()));
        assert_eq!(s.error, ex.error(check.q(), check.v(), s.t));
        let m = check.measure();
        assert_eq!((s.phi, s.psi, s.coupling), (m.phi, m.psi, m.coupling));
        max_phi_dot = max_phi_dot.max(m.phi_dot);
    }
    assert!(max_phi_dot > 0.0);
    assert_eq!(record.max_abs_phi_dot, max_phi_dot);
    let max = |f: fn(&Seen) -> f64| samples.iter().map(f).fold(0.0, f64::max);
    assert_eq!(record.max_abs_phi, max(|s| s.phi.abs()));
    assert_eq!(record.max_abs_psi, max(|s| s.psi.abs()));
    assert_eq!(record.max_abs_coupling, max(|s| s.coupling));
    assert_eq!(record.max_abs_error, Some(max(|s| s.error.unwrap().abs())));
    assert_eq!(record.final_error, samples.last().unwrap().error);
    // Without control the drift is visible: the statistics are not trivially zero.
    assert!(record.max_abs_phi > 0.0 && record.max_abs_error.unwrap() > 0.0);
}

#[test]
fn a_hand_checked_sequence() {
    // A free point mass (no constraints, no potential) moving at v = (1, -2):
    // q(t) = q0 + v t exactly under Euler, and Φ = Ψ = 0 throughout.
    let model = cdyn::Model::builder(vec![2.0, 2.0]).build().unwrap();
    let settings = Settings::new(Scheme::Euler, 0.25, Control::none());
    let mut sim = Simulation::new(&model, settings, &[1.0, 0.0], &[1.0, -2.0]).unwrap();
    let mut q = Vec::new();
    let record = Recorder::coordinates()
        .keep_series(true)
        .sink(|s: &Sample<'_>| -> Result<(), Infallible> {
            q.push(s.observables.to_vec());
            Ok(())
        })
        .run(&mut sim, 1.0, 2)
        .unwrap();
    assert_eq!(q, [vec![1.0, 0.0], vec![1.5, -1.0], vec![2.0, -2.0]]);
    let series = record.series.unwrap();
    assert_eq!(series.t, [0.0, 0.5, 1.0]);
    assert_eq!(series.phi, [0.0; 3]);
    assert_eq!(series.psi, [0.0; 3]);
    assert!(series.error.is_empty());
    assert_eq!((record.max_abs_phi, record.max_abs_psi, record.max_abs_coupling), (0.0, 0.0, 0.0));
    assert_eq!((record.steps, record.t_final), (4, 1.0));
    assert_eq!(record.q_end, [2.0, -2.0]);
    assert_eq!(record.v_end, [1.0, -2.0]);
}

#[test]
fn the_series_are_kept_only_when_asked_for() {
    let ex = pendulum();
    let settings = Settings::new(Scheme::RungeKutta4, 0.01, Control::none());
    let run = |keep| {
        let mut sim = Simulation::new(&ex.model, settings, &ex.q0, &ex.v0).unwrap();
        let Ok(record) = Recorder::example(&ex).keep_series(keep).run(&mut sim, 0.5, 5);
        record
    };
    let (with, without) = (run(true), run(false));
    assert!(without.series.is_none());
    let series = with.series.as_ref().unwrap();
    assert_eq!(series.t.len(), 11);
    assert_eq!((series.phi.len(), series.psi.len(), series.error.len()), (11, 11, 11));
    assert_eq!(series.error.last().copied(), with.final_error);
    // The statistics do not depend on the flag.
    assert_eq!(cdyn::record::Record { series: None, ..with }, without);
}

#[test]
fn a_failing_run_keeps_what_was_recorded() {
    let ex = pendulum();
    let mut settings = Settings::new(Scheme::Euler, 0.01, cvsgf(2e6));
    settings.consistency_tolerance = None;
    let mut sim = Simulation::new(&ex.model, settings, &[1.001, 0.0], &ex.v0).unwrap();
    let mut samples = Vec::new();
    let record = Recorder::example(&ex)
        .keep_series(true)
        .sink(|s: &Sample<'_>| -> Result<(), Infallible> {
            samples.push(seen(s));
            Ok(())
        })
        .run(&mut sim, 20.0, 1)
        .unwrap();
    let Some(Error::Diverged { step, .. }) = record.error else { panic!("expected divergence: {:?}", record.error) };
    assert!(samples.len() > 2, "samples before the failure are kept");
    assert_eq!(samples.last().unwrap().step, step - 1, "every step before the failure was sampled");
    assert_eq!(record.series.as_ref().unwrap().t.len(), samples.len());
    assert_eq!(record.steps, sim.steps());
    assert!(samples.iter().all(|s| s.observables.iter().all(|x| x.is_finite())));
    assert_eq!(record.final_error, samples.last().unwrap().error);
}

#[test]
fn a_sink_error_stops_the_run_and_is_returned() {
    let ex = pendulum();
    let settings = Settings::new(Scheme::RungeKutta4, 0.01, Control::none());
    let mut sim = Simulation::new(&ex.model, settings, &ex.q0, &ex.v0).unwrap();
    let result = Recorder::example(&ex)
        .sink(|s: &Sample<'_>| if s.step == 3 { Err("full") } else { Ok(()) })
        .run(&mut sim, 1.0, 1);
    assert_eq!(result, Err("full"));
    assert_eq!(sim.steps(), 3);
}
