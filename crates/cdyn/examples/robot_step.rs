//! Times a URDF robot's step in cdyn, for the cost columns of
//! docs/robots.md (`tools/robot-costs.sh`): `robot_step ROBOT.urdf [STEPS]`
//! prints one JSON line with microseconds per step (best of 5 trials) of
//! AB-3 without control (one evaluation of the dynamics a step), AB-3
//! with `robust`, RK-4 without control (four evaluations) and
//! generalized-α (implicit: Newton corrections, one factorization a step
//! unless the corrections slow down), in the robot's body coordinates and
//! then in joint coordinates,
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
    let fail = |e: cdyn::Error| -> ! {
        eprintln!("robot_step: {path}: {e}");
        std::process::exit(1)
    };
    let mechanism = cdyn::spatial::read_urdf(&text, [0.0, 0.0, -9.81]).unwrap_or_else(|e| fail(e)).mechanism;
    let built = mechanism.build().unwrap_or_else(|e| fail(e));
    let in_joints = mechanism.in_joint_coordinates().unwrap_or_else(|e| fail(e));
    let time = |model: &cdyn::Model, q0: &[f64], v0: &[f64], scheme: Scheme, control: Control| -> f64 {
        let settings = Settings::new(scheme, 1e-4, control);
        let mut best = f64::INFINITY;
        for _ in 0..5 {
            let (mut elapsed, mut done) = (0.0, 0);
            while done < steps {
                let mut sim = Simulation::new(model, settings, q0, v0).expect("a simulation");
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
    let (m, q, v) = (&built.model, &built.q0, &built.v0);
    let ab3 = time(m, q, v, Scheme::AdamsBashforth3, Control::none());
    let robust = time(m, q, v, Scheme::AdamsBashforth3, methods::robust());
    let rk4 = time(m, q, v, Scheme::RungeKutta4, Control::none());
    let alpha = time(m, q, v, Scheme::GeneralizedAlpha, Control::none());
    let (m, q, v) = (&in_joints.model, &in_joints.q0, &in_joints.v0);
    let joints_ab3 = time(m, q, v, Scheme::AdamsBashforth3, Control::none());
    let joints_robust = time(m, q, v, Scheme::AdamsBashforth3, methods::robust());
    let joints_rk4 = time(m, q, v, Scheme::RungeKutta4, Control::none());
    let joints_alpha = time(m, q, v, Scheme::GeneralizedAlpha, Control::none());
    println!(
        "{{\"n\": {}, \"m\": {}, \"ab3_us\": {ab3:.3}, \"ab3_robust_us\": {robust:.3}, \"rk4_us\": {rk4:.3}, \"alpha_us\": {alpha:.3}, \"joints_n\": {}, \"joints_m\": {}, \"joints_ab3_us\": {joints_ab3:.3}, \"joints_ab3_robust_us\": {joints_robust:.3}, \"joints_rk4_us\": {joints_rk4:.3}, \"joints_alpha_us\": {joints_alpha:.3}}}",
        built.model.n(),
        built.model.m(),
        in_joints.model.n(),
        in_joints.model.m()
    );
}
