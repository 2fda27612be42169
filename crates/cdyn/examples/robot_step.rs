//! Times a URDF robot's step in cdyn, for the cost columns of
//! docs/robots.md (`tools/robot-costs.sh`): `robot_step ROBOT.urdf [STEPS]`
//! prints one JSON line with microseconds per step (best of 5 trials) of
//! AB-3 without control (one evaluation of the dynamics a step), AB-3
//! with `robust`, RK-4 without control (four evaluations) and
//! generalized-α (implicit: Newton corrections, one factorization a step
//! unless the corrections slow down),
//! at h = 1e-4 from the zero pose under gravity. Runs restart every 100 steps,
//! and where a step fails: the failed step's time is on the clock but it is
//! not counted as a step, so that a robot whose friction makes these steps
//! unstable (Z1, xArm7) is timed on finite states only (a failure adds the
//! cost of one step to the run, never a step to the count).

use cdyn::control::methods;
use cdyn::{Control, Scheme, Settings, Simulation};
use std::time::Instant;

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let Some(path) = args.first() else {
        eprintln!("usage: robot_step ROBOT.urdf [STEPS]");
        std::process::exit(2);
    };
    let steps: usize = args.get(1).map_or(Ok(5000), |s| s.parse()).unwrap_or_else(|e| {
        eprintln!("robot_step: STEPS: {e}");
        std::process::exit(2)
    });
    let text = std::fs::read_to_string(path).unwrap_or_else(|e| {
        eprintln!("robot_step: {path}: {e}");
        std::process::exit(1)
    });
    let built = cdyn::spatial::read_urdf(&text, [0.0, 0.0, -9.81])
        .and_then(|robot| robot.mechanism.build())
        .unwrap_or_else(|e| {
            eprintln!("robot_step: {path}: {e}");
            std::process::exit(1)
        });
    let time = |scheme: Scheme, control: Control| -> f64 {
        let settings = Settings::new(scheme, 1e-4, control);
        let mut best = f64::INFINITY;
        for _ in 0..5 {
            let (mut elapsed, mut done) = (0.0, 0);
            while done < steps {
                let mut sim = Simulation::new(&built.model, settings, &built.q0, &built.v0).expect("a simulation");
                let start = Instant::now();
                // Only steps that end on a finite state are counted.
                while done < steps && sim.steps() < 100 && sim.step().is_ok() {
                    done += 1;
                }
                elapsed += start.elapsed().as_secs_f64();
            }
            best = best.min(elapsed / steps as f64 * 1e6);
        }
        best
    };
    let ab3 = time(Scheme::AdamsBashforth3, Control::none());
    let robust = time(Scheme::AdamsBashforth3, methods::robust());
    let rk4 = time(Scheme::RungeKutta4, Control::none());
    let alpha = time(Scheme::GeneralizedAlpha, Control::none());
    println!(
        "{{\"n\": {}, \"m\": {}, \"ab3_us\": {ab3:.3}, \"ab3_robust_us\": {robust:.3}, \"rk4_us\": {rk4:.3}, \"alpha_us\": {alpha:.3}}}",
        built.model.n(),
        built.model.m()
    );
}
