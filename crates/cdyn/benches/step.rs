//! Cost of one step: Example 1 (cdyn as a small system and as a general
//! model, against the hand-written baseline; then the general model under
//! the `robust` preset and the `projection` method) and the N-link chain
//! under `cvsgf_energy`, `robust` and `projection`, one group each; and the
//! mechanisms whose `M(q)` comes from a kinetic energy (double pendulum,
//! loaded four-bar) in angles against the same in Cartesian coordinates.
//! `cargo bench -p cdyn` measures; `cargo test --benches`
//! (CI) runs each benchmark once as a smoke test. Set `CDYN_BENCH_FULL=1`
//! to add the 10 000-body chain. `cdyn bench` reports the same quantities
//! as JSON.

use cdyn::baseline::HandWritten;
use cdyn::control::methods::{self, MethodGains};
use cdyn::models::{
    ChainParams, DoublePendulumParams, Example, FourBarParams, LoadPendulum, PendulumParams, cartesian_pendulum, chain,
    double_pendulum, double_pendulum_angles, four_bar, four_bar_angles, small_pendulum,
};
use cdyn::small::SmallSimulation;
use cdyn::{Application, Control, Energy, EnergyGain, Gain, Geometric, Scheme, Settings, Simulation};
use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use std::hint::black_box;

fn example1(c: &mut Criterion) {
    let ex = cartesian_pendulum(PendulumParams::default()).unwrap();
    let control = MethodGains::paper().cvsgf_energy();
    let settings = Settings::new(Scheme::AdamsBashforth3, 0.01, control);
    let mut group = c.benchmark_group("example1_cvsgf_energy_ab3");
    // Every 10 000 steps (100 s) a run starts afresh: much later these gains
    // let the pendulum settle into a spurious equilibrium (tests/pendulum.rs),
    // which would no longer measure the motion. Restarts cost < 1 % here.
    const RUN: u64 = 10_000;
    let (small, q0, v0) = small_pendulum(PendulumParams::default()).unwrap();
    let fresh = || SmallSimulation::new(small, settings, q0, v0).unwrap();
    let mut sim = fresh();
    group.bench_function("cdyn_small_system", |b| {
        b.iter(|| {
            if sim.steps() == RUN {
                sim = fresh();
            }
            sim.step().unwrap()
        })
    });
    let fresh = || Simulation::new(&ex.model, settings, &ex.q0, &ex.v0).unwrap();
    let mut sim = fresh();
    group.bench_function("cdyn_general_model", |b| {
        b.iter(|| {
            if sim.steps() == RUN {
                sim = fresh();
            }
            sim.step().unwrap()
        })
    });
    let fresh = || HandWritten::new([1.0, 0.0, 0.0, 2.0], 0.01, 20.0, 40.0);
    let (mut hand, mut steps) = (fresh(), 0);
    group.bench_function("hand_written", |b| {
        b.iter(|| {
            if steps == RUN {
                (hand, steps) = (fresh(), 0);
            }
            hand.step();
            steps += 1;
            black_box(&hand.x);
        })
    });
    group.finish();
}

/// Example 1 as a general model under the methods that only it can run
/// (`projection`) or that resolve automatic gains (`robust`), next to the
/// `cdyn_general_model` figure of [`example1`].
fn example1_methods(c: &mut Criterion) {
    let ex = cartesian_pendulum(PendulumParams::default()).unwrap();
    let mut group = c.benchmark_group("example1_methods_ab3");
    for (name, control) in [("robust", methods::robust()), ("projection", methods::projection())] {
        let settings = Settings::new(Scheme::AdamsBashforth3, 0.01, control);
        // Restarts as in `example1`, for the same reason.
        let fresh = || Simulation::new(&ex.model, settings, &ex.q0, &ex.v0).unwrap();
        let mut sim = fresh();
        group.bench_function(name, |b| {
            b.iter(|| {
                if sim.steps() == 10_000 {
                    sim = fresh();
                }
                sim.step().unwrap()
            })
        });
    }
    group.finish();
}

/// One group per method over the chain sizes, `chain_<method>_ab3/<N>`.
fn chains(c: &mut Criterion) {
    let mut sizes = vec![10, 100, 1000];
    if std::env::var_os("CDYN_BENCH_FULL").is_some() {
        sizes.push(10_000);
    }
    let h = 1e-3;
    let cvsgf_energy = Control::none()
        .with_geometric(Geometric::Gradient(Gain::Rate(0.4 / h)))
        .with_energy(Energy::Gradient(EnergyGain::Rate { alpha_e: 0.4 / h }))
        .with_application(Application::ForwardEuler);
    let examples: Vec<_> = sizes
        .iter()
        .map(|&n| {
            chain(
                ChainParams::default()
                    .with_n(n)
                    .with_mass(1.0)
                    .with_length(1.0)
                    .with_gravity(1.0)
                    .with_theta0(0.3)
                    .with_omega0(0.0),
            )
            .unwrap()
        })
        .collect();
    for (name, control) in
        [("cvsgf_energy", cvsgf_energy), ("robust", methods::robust()), ("projection", methods::projection())]
    {
        let mut group = c.benchmark_group(format!("chain_{name}_ab3"));
        for (&n, ex) in sizes.iter().zip(&examples) {
            let settings = Settings::new(Scheme::AdamsBashforth3, h, control);
            // Automatic gains (robust) are resolved here, outside the timing.
            let start = || Simulation::new(&ex.model, settings, &ex.q0, &ex.v0).unwrap();
            let mut sim = start();
            group.bench_with_input(BenchmarkId::from_parameter(n), &n, |b, _| {
                b.iter(|| {
                    // Restart after 10 s of motion, the interval the chain is known to behave over.
                    if sim.steps() == 10_000 {
                        sim = start();
                    }
                    sim.step().unwrap()
                })
            });
        }
        group.finish();
    }
}

/// RK-4 steps, no control: what a configuration-dependent `M(q)` costs
/// (its AD, dense factor and dense `S`) against the constant diagonal one
/// of the same mechanism in more coordinates.
fn angles(c: &mut Criterion) {
    let mut group = c.benchmark_group("angles_vs_cartesian_rk4");
    let loaded = FourBarParams::default().with_load(Some(LoadPendulum::default()));
    let dp = DoublePendulumParams::default().with_theta1(1.0).with_theta2(0.5);
    let cases: [(&str, Example); 4] = [
        ("double_pendulum_cartesian", double_pendulum(dp).unwrap()),
        ("double_pendulum_angles", double_pendulum_angles(dp).unwrap()),
        ("four_bar_load_cartesian", four_bar(loaded).unwrap()),
        ("four_bar_load_angles", four_bar_angles(loaded).unwrap()),
    ];
    for (name, ex) in &cases {
        const RUN: u64 = 10_000;
        let settings = Settings::new(Scheme::RungeKutta4, 1e-3, Control::none());
        let fresh = || Simulation::new(&ex.model, settings, &ex.q0, &ex.v0).unwrap();
        let mut sim = fresh();
        group.bench_function(*name, |b| {
            b.iter(|| {
                if sim.steps() == RUN {
                    sim = fresh();
                }
                sim.step().unwrap()
            })
        });
    }
    group.finish();
}

criterion_group!(benches, example1, example1_methods, chains, angles);
criterion_main!(benches);
