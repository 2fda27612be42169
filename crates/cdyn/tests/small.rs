//! Small systems (`SmallSimulation`, sizes known at compile time) against
//! the general path (`Simulation` of the same system as a `Model`): the
//! same trajectories, measures and errors, for every scheme and control.

use cdyn::control::{Control, Energy, EnergyGain, Gain, Geometric, Rate, Velocity};
use cdyn::dynamics::DependentRows;
use cdyn::integrate::Application;
use cdyn::models::{PendulumParams, small_pendulum};
use cdyn::small::{SmallSimulation, SmallSystem, to_model};
use cdyn::{Error, Scalar, Scheme, Settings, Simulation};

/// A double pendulum whose first rod is driven (`L₁ = 1 + 0.1 sin 2t`), with
/// linear drag: two rows, a rheonomic constraint (`Φ_t ≠ 0`), a potential and
/// a force, so every term of the small path is exercised.
#[derive(Clone, Copy)]
struct DrivenDouble;

impl SmallSystem<4, 2> for DrivenDouble {
    fn mass(&self) -> [f64; 4] {
        [1.0, 1.0, 0.5, 0.5]
    }
    fn constraints<D: Scalar>(&self, [x1, y1, x2, y2]: [D; 4], t: D) -> [D; 2] {
        let l1 = (t * 2.0).sin() * 0.1 + 1.0;
        let (dx, dy) = (x2 - x1, y2 - y1);
        [(x1 * x1 + y1 * y1 - l1 * l1) * 0.5, (dx * dx + dy * dy - 0.49) * 0.5]
    }
    fn potential<D: Scalar>(&self, [_, y1, _, y2]: [D; 4]) -> D {
        (y1 + y2 * 0.5) * 9.81
    }
    fn force<D: Scalar>(&self, _q: [D; 4], v: [D; 4], _t: D) -> [D; 4] {
        v.map(|v| v * -0.3)
    }
}

/// On both constraints and their rates at `t = 0` (`L̇₁ = 0.2`).
const DOUBLE_Q0: [f64; 4] = [1.0, 0.0, 1.7, 0.0];
const DOUBLE_V0: [f64; 4] = [0.2, 1.0, 0.2, 2.0];

fn controls() -> Vec<Control> {
    let mut out = Vec::new();
    for geometric in
        [Geometric::None, Geometric::Baumgarte { alpha: 12.6, beta: 40.0 }, Geometric::Gradient(Gain::Rate(40.0))]
    {
        for energy in [
            Energy::None,
            Energy::Gradient(EnergyGain::Rate { alpha_e: 40.0 }),
            Energy::Gradient(EnergyGain::Fixed { rho_q: 0.5, rho_v: 2.0 }),
            Energy::Baumgarte { eta: 40.0 },
        ] {
            for application in [Application::InRhs, Application::ForwardEuler, Application::BackwardEuler] {
                out.push(Control::none().with_geometric(geometric).with_energy(energy).with_application(application));
            }
        }
    }
    out
}

/// Largest difference of the states after `steps` steps of both paths, or
/// `None` if both stopped with the same error (a diverging combination).
fn divergence<S: SmallSystem<N, M> + Copy, const N: usize, const M: usize>(
    system: S,
    settings: Settings,
    q0: [f64; N],
    v0: [f64; N],
    steps: usize,
) -> Option<f64> {
    let model = to_model(system).unwrap();
    let mut general = Simulation::new(&model, settings, &q0, &v0).unwrap();
    let mut small = SmallSimulation::new(system, settings, q0, v0).unwrap();
    for _ in 0..steps {
        match (general.step(), small.step()) {
            (Ok(()), Ok(())) => {}
            (g, s) => {
                assert_eq!(format!("{g:?}"), format!("{s:?}"), "{settings:?}");
                return None;
            }
        }
    }
    assert_eq!(small.evaluations(), general.evaluations());
    let pairs = small.q().iter().zip(general.q()).chain(small.v().iter().zip(general.v()));
    let worst = pairs.fold(0.0_f64, |a, (s, g)| a.max((s - g).abs()));
    Some(worst.max((small.energy_input() - general.energy_input()).abs()))
}

#[test]
fn small_and_general_paths_give_the_same_trajectories() {
    let (pendulum, q0, v0) = small_pendulum(PendulumParams::default()).unwrap();
    let (mut compared, mut stopped) = (0, Vec::new());
    for scheme in Scheme::GENERAL {
        for control in controls() {
            let cases = [
                ("pendulum", divergence(pendulum, Settings::new(scheme, 0.01, control), q0, v0, 300), 1e-12),
                (
                    "double pendulum",
                    divergence(DrivenDouble, Settings::new(scheme, 0.005, control), DOUBLE_Q0, DOUBLE_V0, 300),
                    1e-10,
                ),
            ];
            for (name, d, tolerance) in cases {
                match d {
                    Some(d) => assert!(d < tolerance, "{name}, {scheme:?}, {control:?}: states differ by {d:e}"),
                    None => stopped.push(format!("{name}, {scheme:?}, {control:?}")),
                }
                compared += 1;
            }
        }
    }
    // Both paths stopping identically is agreement too, but most runs must complete.
    assert!(stopped.len() * 10 < compared, "{} of {compared} runs stopped: {stopped:#?}", stopped.len());
}

#[test]
fn the_double_pendulum_moves_and_its_drive_puts_energy_in() {
    // Guards the comparison above against two paths that agree by doing nothing.
    let control = Control::default().with_geometric(Geometric::Gradient(Gain::Rate(40.0)));
    let mut sim =
        SmallSimulation::new(DrivenDouble, Settings::new(Scheme::RungeKutta4, 0.005, control), DOUBLE_Q0, DOUBLE_V0)
            .unwrap();
    for _ in 0..400 {
        sim.step().unwrap();
    }
    assert!((sim.q()[0] - DOUBLE_Q0[0]).abs() > 0.1, "{:?}", sim.q());
    assert!(sim.energy_input().abs() > 1e-3, "drive and drag do work: {}", sim.energy_input());
    let m = sim.measure();
    assert!(m.phi.abs() < 1e-6 && m.psi.abs() < 1e-4, "{m:?}");
}

#[test]
fn measures_agree_with_the_general_probe() {
    let model = to_model(DrivenDouble).unwrap();
    let settings = Settings::new(Scheme::AdamsBashforth3, 0.02, Control::none());
    let mut general = Simulation::new(&model, settings, &DOUBLE_Q0, &DOUBLE_V0).unwrap();
    let mut small = SmallSimulation::new(DrivenDouble, settings, DOUBLE_Q0, DOUBLE_V0).unwrap();
    for _ in 0..50 {
        general.step().unwrap();
        small.step().unwrap();
    }
    let (s, g) = (small.measure(), general.measure());
    // Uncontrolled at a coarse step: the violations are well above round-off.
    assert!(g.phi.abs() > 1e-8 && g.psi.abs() > 1e-8, "{g:?}");
    for (a, b) in [(s.phi, g.phi), (s.phi_dot, g.phi_dot), (s.psi, g.psi), (s.coupling, g.coupling)] {
        assert!((a - b).abs() <= 1e-12 * b.abs().max(1.0), "{s:?} vs {g:?}");
    }
}

/// Two copies of the same rod: `S` is singular at every state.
#[derive(Clone, Copy)]
struct DoubledRod;

impl SmallSystem<2, 2> for DoubledRod {
    fn mass(&self) -> [f64; 2] {
        [1.0, 1.0]
    }
    fn constraints<D: Scalar>(&self, [x, y]: [D; 2], _t: D) -> [D; 2] {
        let phi = (x * x + y * y - 1.0) * 0.5;
        [phi, phi]
    }
}

/// More rows than coordinates.
#[derive(Clone, Copy)]
struct Overconstrained;

impl SmallSystem<1, 2> for Overconstrained {
    fn mass(&self) -> [f64; 1] {
        [1.0]
    }
    fn constraints<D: Scalar>(&self, [x]: [D; 1], _t: D) -> [D; 2] {
        [x, x * x]
    }
}

/// A free particle of mass `m`: no constraints at all.
#[derive(Clone, Copy)]
struct Free(f64);

impl SmallSystem<1, 0> for Free {
    fn mass(&self) -> [f64; 1] {
        [self.0]
    }
    fn constraints<D: Scalar>(&self, _q: [D; 1], _t: D) -> [D; 0] {
        []
    }
}

#[test]
fn an_unconstrained_particle_moves_uniformly() {
    let settings = Settings::new(Scheme::AdamsBashforth2, 0.25, Control::none());
    let mut sim = SmallSimulation::new(Free(2.0), settings, [1.0], [3.0]).unwrap();
    for _ in 0..8 {
        sim.step().unwrap();
    }
    assert_eq!((sim.q()[0], sim.v()[0], sim.t()), (7.0, 3.0, 2.0));
}

#[test]
fn a_tolerated_doubled_row_is_the_circle_on_both_paths() {
    // The doubled constraint, tolerated: uniform motion on the unit circle
    // under every control law, the same on both paths, the row reported.
    let mut all = controls();
    all.push(Control::none().with_geometric(Geometric::Newton(Rate::Given(40.0))));
    all.push(Control::none().with_velocity(Velocity::Gradient(Rate::Given(40.0))));
    all.push(Control::none().with_energy(Energy::Projected { alpha_e: Rate::Given(40.0), position_weight: 16.0 }));
    all.push(cdyn::control::methods::robust());
    for control in all {
        let settings = Settings::new(Scheme::RungeKutta4, 0.01, control).with_dependent_rows(DependentRows::Tolerate);
        let d = divergence(DoubledRod, settings, [1.0, 0.0], [0.0, 1.0], 300);
        assert!(d.is_some_and(|d| d < 1e-12), "{control:?}: {d:?}");
        let mut sim = SmallSimulation::new(DoubledRod, settings, [1.0, 0.0], [0.0, 1.0]).unwrap();
        for _ in 0..300 {
            sim.step().unwrap();
        }
        let (q, t) = (sim.q(), sim.t());
        let off = (q[0] - t.cos()).abs().max((q[1] - t.sin()).abs());
        // RK-4 alone is 1e-9 off here; the energy laws add their own error (4e-8).
        assert!(off < 1e-6, "{control:?}: off the circle's motion by {off:e}");
        let loss = sim.rank_loss().copied().unwrap();
        assert_eq!((loss.max, loss.steps), (1, 300), "{control:?}");
    }
}

#[test]
fn errors_match_the_general_path() {
    let settings = Settings::new(Scheme::Euler, 0.01, Control::none());
    // A dependent row: the same typed error, naming the step, time and row.
    let model = to_model(DoubledRod).unwrap();
    let general = Simulation::new(&model, settings, &[1.0, 0.0], &[0.0, 1.0]).unwrap().step().unwrap_err();
    let small = SmallSimulation::new(DoubledRod, settings, [1.0, 0.0], [0.0, 1.0]).unwrap().step().unwrap_err();
    assert!(matches!(small, Error::SingularConstraints { step: 0, row: 1, .. }), "{small}");
    assert_eq!(small.to_string(), general.to_string());

    // Divergence: a huge step, uncontrolled; stopped at the same step.
    let (pendulum, q0, v0) = small_pendulum(PendulumParams::default()).unwrap();
    let model = to_model(pendulum).unwrap();
    let coarse = Settings::new(Scheme::Euler, 5.0, Control::none());
    let run_general = || -> Result<(), Error> {
        let mut sim = Simulation::new(&model, coarse, &q0, &v0)?;
        loop {
            sim.step()?;
        }
    };
    let run_small = || -> Result<(), Error> {
        let mut sim = SmallSimulation::new(pendulum, coarse, q0, v0)?;
        loop {
            sim.step()?;
        }
    };
    let (small, general) = (run_small().unwrap_err(), run_general().unwrap_err());
    assert!(matches!(small, Error::Diverged { .. }), "{small}");
    assert_eq!(small.to_string(), general.to_string());

    // Bad input, before any step.
    let err = |r: Result<SmallSimulation<_, 2, 1>, Error>| r.err().map(|e| e.to_string()).unwrap_or_default();
    assert!(err(SmallSimulation::new(pendulum, settings, [1.1, 0.0], v0)).contains("initial state"));
    assert!(err(SmallSimulation::new(pendulum, settings, [f64::NAN, 0.0], v0)).contains("NaN"));
    let massless = SmallSimulation::new(Free(0.0), settings, [0.0], [0.0]);
    assert!(massless.err().unwrap().to_string().contains("mass"));
    let over = SmallSimulation::new(Overconstrained, settings, [0.0], [0.0]);
    assert!(over.err().unwrap().to_string().contains("more constraints than coordinates"));
    assert!(to_model(Overconstrained).is_err());
}
