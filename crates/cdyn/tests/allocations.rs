//! No allocation inside a step: a counting global allocator watches 200
//! steps after warm-up, for every scheme, control law and application, on
//! Example 1 (as a general model and as a small system) and on a mechanism
//! with every kind of element (also with a redundant row, tolerated); the
//! robust preset after its automatic gains are chosen, and the projection
//! method (general models only); a tractor with a trailer on knife edges
//! (nonholonomic rows); the models whose `M(q)` comes from a kinetic
//! energy (the double pendulum and the loaded four-bar in angles); and an
//! arm in joint coordinates (its `M(θ)` and gravity in closed form).

use cdyn::control::methods;
use cdyn::control::projection::{OnFailure, Projection};
use cdyn::control::{Control, Energy, EnergyGain, Gain, Geometric, POSITION_WEIGHT, Rate, Velocity};
use cdyn::dynamics::{DependentRows, LinearSolver};
use cdyn::integrate::Application;
use cdyn::model::timefn::TimeFn;
use cdyn::models::{
    DoublePendulumParams, Example, FourBarParams, LoadPendulum, PendulumParams, andrews, cartesian_pendulum,
    double_pendulum_angles, four_bar_angles, small_pendulum,
};
use cdyn::planar::{BodyId, Coordinate, Element, Mechanism};
use cdyn::simulate::Stepper;
use cdyn::simulate::system::System as Controlled;
use cdyn::small::SmallSimulation;
use cdyn::{Scheme, Settings, Simulation};
use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;

struct Counting;

thread_local! {
    /// Allocations made by this thread: other threads of the test harness do not count.
    static ALLOCATIONS: Cell<usize> = const { Cell::new(0) };
}

fn count() -> usize {
    ALLOCATIONS.with(|c| c.get())
}

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        ALLOCATIONS.with(|c| c.set(c.get() + 1));
        unsafe { System.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        unsafe { System.dealloc(ptr, layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        ALLOCATIONS.with(|c| c.set(c.get() + 1));
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

/// A chain of point masses on rods with a damper and a driven support: every
/// kind of element on the sparse path.
fn hanging_chain(n: usize) -> Example {
    Example::from_mechanism(chain_mechanism(n).build().unwrap(), None)
}

/// The hanging chain with its first rod entered twice: a dependent row at
/// every step, dropped with `dependent_rows = Tolerate`.
fn redundant_chain(n: usize) -> Example {
    let mut m = chain_mechanism(n);
    let (support, first) = (m.find("support").unwrap(), m.find("m0").unwrap());
    m.add(Element::Distance { a: support, pa: [0.0; 2], b: first, pb: [0.0; 2], length: 0.1 });
    Example::from_mechanism(m.build().unwrap(), None)
}

/// The mechanism of [`hanging_chain`].
fn chain_mechanism(n: usize) -> Mechanism {
    let mut m = Mechanism::new([0.0, -9.81]);
    let support = m.rigid("support", 1.0, 0.1, [0.0, 0.0], 0.0);
    // Everything starts moving with the support: ẋ = 0.3 at t = 0.
    m.bodies[0].velocity = [0.3, 0.0];
    m.add(Element::DriveCoordinate {
        body: support,
        coordinate: Coordinate::X,
        f: TimeFn::default().with_sines(vec![[0.1, 3.0, 0.0]]),
    });
    m.add(Element::DriveCoordinate { body: support, coordinate: Coordinate::Y, f: TimeFn::constant(0.0) });
    m.add(Element::DriveCoordinate { body: support, coordinate: Coordinate::Angle, f: TimeFn::constant(0.0) });
    let mut prev = support;
    for i in 0..n {
        let body = m.point(&format!("m{i}"), 1.0, [0.0, -0.1 * (i + 1) as f64]);
        m.bodies[i + 1].velocity = [0.3, 0.0];
        m.add(Element::Distance { a: prev, pa: [0.0; 2], b: body, pb: [0.0; 2], length: 0.1 });
        m.add(Element::Damper { a: prev, pa: [0.0; 2], b: body, pb: [0.0; 2], damping: 0.1 });
        prev = body;
    }
    m.add(Element::AppliedForce {
        body: prev,
        point: [0.0; 2],
        fx: TimeFn::linear(0.0, 1.0),
        fy: TimeFn::constant(0.0),
    });
    m
}

/// A tractor pulled by a spring, with a trailer on a pin: two knife edges
/// (nonholonomic rows) and a revolute joint, starting at rest.
fn tractor_trailer() -> Example {
    let mut m = Mechanism::new([0.0, 0.0]);
    let tractor = m.rigid("tractor", 2.0, 0.4, [0.0, 0.0], 0.0);
    let trailer = m.rigid("trailer", 1.0, 0.2, [-1.1, 0.0], 0.0);
    m.add(Element::KnifeEdge { body: tractor, point: [0.3, 0.0], blade: [1.0, 0.0] });
    m.add(Element::Revolute { a: tractor, pa: [-0.5, 0.0], b: trailer, pb: [0.6, 0.0], limit: None });
    m.add(Element::KnifeEdge { body: trailer, point: [-0.4, 0.0], blade: [1.0, 0.0] });
    m.add(Element::Spring {
        a: BodyId::Ground,
        pa: [3.0, 2.0],
        b: tractor,
        pb: [0.5, 0.0],
        stiffness: 4.0,
        rest_length: 0.0,
    });
    Example::from_mechanism(m.build().unwrap(), None)
}

fn controls() -> Vec<Control> {
    let mut out = Vec::new();
    for geometric in
        [Geometric::None, Geometric::Baumgarte { alpha: 12.6, beta: 40.0 }, Geometric::Gradient(Gain::Rate(40.0))]
    {
        for energy in
            [Energy::None, Energy::Gradient(EnergyGain::Rate { alpha_e: 40.0 }), Energy::Baumgarte { eta: 40.0 }]
        {
            for application in [Application::InRhs, Application::ForwardEuler, Application::BackwardEuler] {
                out.push(Control::none().with_geometric(geometric).with_energy(energy).with_application(application));
            }
        }
    }
    out
}

/// The laws of the robust stabilization alone and combined, with given and
/// automatic rates (chosen when the simulation starts), every application,
/// and the robust preset itself.
fn robust_controls() -> Vec<Control> {
    let rate = Rate::Given(40.0);
    let projected = |alpha_e, position_weight| Energy::Projected { alpha_e, position_weight };
    let mut out = Vec::new();
    for (geometric, velocity, energy) in [
        (Geometric::Newton(rate), Velocity::None, Energy::None),
        (Geometric::None, Velocity::Gradient(rate), Energy::None),
        (Geometric::None, Velocity::None, projected(rate, POSITION_WEIGHT)),
        (Geometric::None, Velocity::None, projected(rate, 0.0)),
        (Geometric::Gradient(Gain::Rate(40.0)), Velocity::Gradient(rate), projected(rate, POSITION_WEIGHT)),
        (Geometric::Newton(rate), Velocity::Gradient(rate), projected(rate, POSITION_WEIGHT)),
        (Geometric::Gradient(Gain::Auto), Velocity::Gradient(Rate::Auto), projected(Rate::Auto, POSITION_WEIGHT)),
    ] {
        for application in [Application::InRhs, Application::ForwardEuler, Application::BackwardEuler] {
            out.push(
                Control::none()
                    .with_geometric(geometric)
                    .with_velocity(velocity)
                    .with_energy(energy)
                    .with_application(application),
            );
        }
    }
    out.push(methods::robust());
    out
}

/// The projection method: as the preset sets it, and one that never
/// converges and goes on (its failure path must not allocate either).
fn projections() -> [Control; 2] {
    let failing =
        Projection::default().with_tolerance(1e-30).with_max_iterations(2).with_on_failure(OnFailure::Continue);
    [methods::projection(), Control::none().with_projection(Some(failing))]
}

/// Allocations during `steps` steps (and samples) after `warm_up` steps.
fn allocations_per_run(ex: &Example, settings: Settings, warm_up: usize, steps: usize) -> usize {
    allocations_stepping(Simulation::new(&ex.model, settings, &ex.q0, &ex.v0).unwrap(), warm_up, steps)
}

/// An arm in joint coordinates: two revolute joints, a prismatic one tied
/// to the second by a `<mimic>` row, a damped joint, a servo, a spring
/// with its damper to the ground and a rotary damper.
fn joint_tree() -> cdyn::spatial::InJoints {
    use cdyn::spatial::{Actuator, Body, Coupling, Joint, JointKind};
    let body = |name: &str, r: [f64; 3]| Body::new(name, 1.2, [0.02, 0.03, 0.025]).with_position(r);
    let joint = |kind, a, b, point, axis| Joint::new(kind, a, b, point).with_axis(axis);
    cdyn::spatial::Mechanism::new([0.0, 0.0, -9.81])
        .with_bodies(vec![body("a", [0.2, 0.0, -0.1]), body("b", [0.5, 0.1, -0.2]), body("c", [0.7, 0.1, -0.4])])
        .with_joints(vec![
            joint(JointKind::Revolute, 0, None, [0.0; 3], [0.0, 0.3, 1.0]),
            joint(JointKind::Revolute, 1, Some(0), [0.4, 0.0, -0.15], [1.0, 0.0, 0.2]).with_damping(0.3),
            joint(JointKind::Prismatic, 2, Some(1), [0.6, 0.1, -0.3], [0.0, 0.2, 1.0]),
        ])
        .with_couplings(vec![Coupling::new(2, 1, 0.1, 0.0)])
        .with_loads(vec![
            cdyn::spatial::Load::Spring {
                a: 2,
                b: None,
                point: [0.7, 0.1, -0.4],
                point_b: [0.9, 0.0, 0.0],
                stiffness: 30.0,
                damping: 0.5,
                length: None,
            },
            cdyn::spatial::Load::RotaryDamper { a: 1, b: Some(0), axis: [1.0, 0.0, 0.0], damping: 0.2 },
        ])
        .with_actuators(vec![Actuator::servo(0, TimeFn::linear(0.1, 0.5), 20.0, 2.0)])
        .in_joint_coordinates()
        .unwrap()
}

/// As [`allocations_per_run`], for the Example 1 pendulum as a small system.
fn small_allocations_per_run(settings: Settings, warm_up: usize, steps: usize) -> usize {
    let (system, q0, v0) = small_pendulum(PendulumParams::default()).unwrap();
    allocations_stepping(SmallSimulation::new(system, settings, q0, v0).unwrap(), warm_up, steps)
}

/// Allocations of any simulation during `steps` steps (and samples) after `warm_up` steps.
fn allocations_stepping<S: Controlled>(mut sim: Stepper<S>, warm_up: usize, steps: usize) -> usize {
    for _ in 0..warm_up {
        sim.step().unwrap();
    }
    let before = count();
    for _ in 0..steps {
        sim.step().unwrap();
        std::hint::black_box(sim.measure());
    }
    count() - before
}

// One test function, so no other test thread allocates while we count.
#[test]
fn steps_do_not_allocate() {
    // The counter does count: building the models allocates.
    let before = count();
    let pendulum = cartesian_pendulum(PendulumParams::default()).unwrap();
    let andrews = andrews().unwrap();
    let chain = hanging_chain(64);
    let trailer = tractor_trailer();
    let redundant = redundant_chain(64);
    let angles = double_pendulum_angles(DoublePendulumParams::default()).unwrap();
    let four_bar = four_bar_angles(FourBarParams::default().with_load(Some(LoadPendulum::default()))).unwrap();
    let cdyn::spatial::Built { model: spatial, q0: sq0, v0: sv0, .. } =
        cdyn::spatial::chain(40, 0.3, 1.0).build().unwrap();
    assert!(spatial.mass_blocks().is_some());
    let tree = joint_tree();
    assert!(count() > before);
    for scheme in Scheme::GENERAL {
        for control in controls() {
            let n = allocations_per_run(&pendulum, Settings::new(scheme, 0.01, control), 5, 200);
            assert_eq!(n, 0, "pendulum, {scheme:?}, {control:?}: {n} allocations in 200 steps");
            let n = small_allocations_per_run(Settings::new(scheme, 0.01, control), 5, 200);
            assert_eq!(n, 0, "small pendulum, {scheme:?}, {control:?}: {n} allocations in 200 steps");
        }
        for control in controls().into_iter().chain(robust_controls()).chain(projections()) {
            let n = allocations_per_run(&trailer, Settings::new(scheme, 0.01, control), 5, 200);
            assert_eq!(n, 0, "tractor and trailer, {scheme:?}, {control:?}: {n} allocations in 200 steps");
        }
        // Rates with hα = 0.4, as in the paper.
        let control = |h: f64| {
            Control::none()
                .with_geometric(Geometric::Gradient(Gain::Rate(0.4 / h)))
                .with_energy(Energy::Gradient(EnergyGain::Rate { alpha_e: 0.4 / h }))
                .with_application(Application::ForwardEuler)
        };
        let n = allocations_per_run(&andrews, Settings::new(scheme, 1e-5, control(1e-5)), 5, 200);
        assert_eq!(n, 0, "andrews, {scheme:?}: {n} allocations in 200 steps");
        for solver in [LinearSolver::Dense, LinearSolver::Sparse] {
            let mut settings = Settings::new(scheme, 1e-3, control(1e-3));
            settings.solver = solver;
            let n = allocations_per_run(&chain, settings, 5, 200);
            assert_eq!(n, 0, "chain, {scheme:?}, {solver:?}: {n} allocations in 200 steps");
        }

        // The robust stabilization: its laws on both paths, the preset on
        // the larger models, the projection method on the general path.
        for control in robust_controls() {
            let n = allocations_per_run(&pendulum, Settings::new(scheme, 0.01, control), 5, 200);
            assert_eq!(n, 0, "pendulum, {scheme:?}, {control:?}: {n} allocations in 200 steps");
            let n = small_allocations_per_run(Settings::new(scheme, 0.01, control), 5, 200);
            assert_eq!(n, 0, "small pendulum, {scheme:?}, {control:?}: {n} allocations in 200 steps");
        }
        // M(q) from kinetic energies: every law, the robust preset and the
        // projection; the spatial chain's on the block-diagonal path.
        for control in controls().into_iter().chain(robust_controls()).chain(projections()) {
            for (name, ex) in [("double pendulum in angles", &angles), ("four-bar in angles", &four_bar)] {
                let n = allocations_per_run(ex, Settings::new(scheme, 1e-3, control), 5, 200);
                assert_eq!(n, 0, "{name}, {scheme:?}, {control:?}: {n} allocations in 200 steps");
            }
            let sim = Simulation::new(&spatial, Settings::new(scheme, 1e-3, control), &sq0, &sv0).unwrap();
            let n = allocations_stepping(sim, 5, 200);
            assert_eq!(n, 0, "spatial chain, {scheme:?}, {control:?}: {n} allocations in 200 steps");
            let sim = Simulation::new(&tree.model, Settings::new(scheme, 1e-3, control), &tree.q0, &tree.v0).unwrap();
            let n = allocations_stepping(sim, 5, 200);
            assert_eq!(n, 0, "arm in joint coordinates, {scheme:?}, {control:?}: {n} allocations in 200 steps");
        }
        let n = allocations_per_run(&andrews, Settings::new(scheme, 1e-5, methods::robust()), 5, 200);
        assert_eq!(n, 0, "andrews, {scheme:?}, robust: {n} allocations in 200 steps");
        for control in projections() {
            let n = allocations_per_run(&pendulum, Settings::new(scheme, 0.01, control), 5, 200);
            assert_eq!(n, 0, "pendulum, {scheme:?}, {control:?}: {n} allocations in 200 steps");
        }
        for solver in [LinearSolver::Dense, LinearSolver::Sparse] {
            for control in [methods::robust()].into_iter().chain(projections()) {
                let settings = Settings::new(scheme, 1e-3, control).with_solver(solver);
                let n = allocations_per_run(&chain, settings, 5, 200);
                assert_eq!(n, 0, "chain, {scheme:?}, {solver:?}, {control:?}: {n} allocations in 200 steps");
                // A dependent row dropped at every step allocates nothing either.
                let settings = settings.with_dependent_rows(DependentRows::Tolerate);
                let n = allocations_per_run(&redundant, settings, 5, 200);
                assert_eq!(n, 0, "redundant chain, {scheme:?}, {solver:?}, {control:?}: {n} allocations in 200 steps");
            }
        }
    }
    // RATTLE and generalized-α, alone and followed by the projection, on constant, block and dense M(q).
    for (scheme, control) in [Scheme::Rattle, Scheme::GeneralizedAlpha]
        .into_iter()
        .flat_map(|s| [Control::none()].into_iter().chain(projections()).map(move |c| (s, c)))
    {
        let settings = |h| Settings::new(scheme, h, control);
        for (name, ex, h) in
            [("pendulum", &pendulum, 0.01), ("chain", &chain, 1e-3), ("four-bar in angles", &four_bar, 1e-3)]
        {
            let n = allocations_per_run(ex, settings(h), 5, 200);
            assert_eq!(n, 0, "{name}, {scheme:?}, {control:?}: {n} allocations in 200 steps");
        }
        let n = allocations_stepping(Simulation::new(&spatial, settings(1e-3), &sq0, &sv0).unwrap(), 5, 200);
        assert_eq!(n, 0, "spatial chain, {scheme:?}, {control:?}: {n} allocations in 200 steps");
        let n = allocations_stepping(Simulation::new(&tree.model, settings(1e-3), &tree.q0, &tree.v0).unwrap(), 5, 200);
        assert_eq!(n, 0, "arm in joint coordinates, {scheme:?}, {control:?}: {n} allocations in 200 steps");
    }
}
