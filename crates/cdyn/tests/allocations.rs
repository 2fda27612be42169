//! No allocation inside a step: a counting global allocator watches 200
//! steps after warm-up, for every scheme, control law and application, on
//! Example 1 and on a mechanism with every kind of element.

use cdyn::control::{Application, Control, Energy, EnergyGain, Gain, Geometric};
use cdyn::models::{PendulumParams, andrews, cartesian_pendulum};
use cdyn::{Scheme, Settings, Simulation};
use std::alloc::{GlobalAlloc, Layout, System};
use std::sync::atomic::{AtomicUsize, Ordering};

struct Counting;

static ALLOCATIONS: AtomicUsize = AtomicUsize::new(0);

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        ALLOCATIONS.fetch_add(1, Ordering::Relaxed);
        unsafe { System.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        unsafe { System.dealloc(ptr, layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        ALLOCATIONS.fetch_add(1, Ordering::Relaxed);
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

fn controls() -> Vec<Control> {
    let mut out = Vec::new();
    for geometric in [Geometric::None, Geometric::Baumgarte { alpha: 12.6, beta: 40.0 }, Geometric::Gradient(Gain::Rate(40.0))] {
        for energy in [Energy::None, Energy::Gradient(EnergyGain::Rate { alpha_e: 40.0 }), Energy::Baumgarte { eta: 40.0 }] {
            for application in [Application::InRhs, Application::ForwardEuler, Application::BackwardEuler] {
                out.push(Control { geometric, energy, application });
            }
        }
    }
    out
}

/// Allocations during `steps` steps (and samples) after `warm_up` steps.
fn allocations_per_run(ex: &cdyn::models::Example, settings: Settings, warm_up: usize, steps: usize) -> usize {
    let mut sim = Simulation::new(&ex.model, settings, &ex.q0, &ex.v0).unwrap();
    for _ in 0..warm_up {
        sim.step().unwrap();
    }
    let before = ALLOCATIONS.load(Ordering::SeqCst);
    for _ in 0..steps {
        sim.step().unwrap();
        std::hint::black_box(sim.measure());
    }
    ALLOCATIONS.load(Ordering::SeqCst) - before
}

// One test function, so no other test thread allocates while we count.
#[test]
fn steps_do_not_allocate() {
    // The counter does count: building the models allocates.
    let before = ALLOCATIONS.load(Ordering::SeqCst);
    let pendulum = cartesian_pendulum(PendulumParams::default()).unwrap();
    let andrews = andrews().unwrap();
    assert!(ALLOCATIONS.load(Ordering::SeqCst) > before);
    for scheme in Scheme::ALL {
        for control in controls() {
            let n = allocations_per_run(&pendulum, Settings::new(scheme, 0.01, control), 5, 200);
            assert_eq!(n, 0, "pendulum, {scheme:?}, {control:?}: {n} allocations in 200 steps");
        }
        let control = Control {
            geometric: Geometric::Gradient(Gain::Rate(4e4)),
            energy: Energy::Gradient(EnergyGain::Rate { alpha_e: 4e4 }),
            application: Application::ForwardEuler,
        };
        let n = allocations_per_run(&andrews, Settings::new(scheme, 1e-5, control), 5, 200);
        assert_eq!(n, 0, "andrews, {scheme:?}: {n} allocations in 200 steps");
    }
}
