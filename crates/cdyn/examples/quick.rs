use cdyn::*;
fn main() {
    let ex = models::cartesian_pendulum(Default::default()).unwrap();
    for (name, control) in [
        ("none", Control::none()),
        (
            "cvsgf_energy",
            Control {
                geometric: Geometric::Gradient(Gain::Fixed(20.0)),
                energy: Energy::Gradient(EnergyGain::Rate { alpha_e: 40.0 }),
                application: Application::ForwardEuler,
            },
        ),
        (
            "baumgarte",
            Control { geometric: Geometric::Baumgarte { alpha: 2.0 * 40f64.sqrt(), beta: 40.0 }, ..Control::none() },
        ),
    ] {
        let mut sim =
            Simulation::new(&ex.model, Settings::new(Scheme::AdamsBashforth3, 0.01, control), &ex.q0, &ex.v0).unwrap();
        let (mut mphi, mut mpsi) = (0.0f64, 0.0f64);
        sim.run::<Error>(20.0, 1, |s| {
            let m = s.measure();
            mphi = mphi.max(m.phi.abs());
            mpsi = mpsi.max(m.psi.abs());
            Ok(())
        })
        .unwrap();
        println!(
            "{name}: steps {} evals {} max phi {mphi:.3e} max psi {mpsi:.3e} q {:?}",
            sim.steps(),
            sim.evaluations(),
            sim.q()
        );
    }
}
