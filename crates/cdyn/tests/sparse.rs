//! The sparse factorization gives the dense one's answers, detects
//! dependent constraints the same way, and does not allocate per step.

use cdyn::dynamics::{Dynamics, LinearSolver};
use cdyn::planar::{BodyId, Element, Mechanism};
use cdyn::{Control, Energy, EnergyGain, Error, Gain, Geometric, Scheme, Settings, Simulation};

/// A chain of `n` point masses on rods, hanging from the origin, bent into
/// an arc and moving (so that every term of the dynamics is non-zero).
fn chain(n: usize, duplicate_last: bool) -> (cdyn::Model, Vec<f64>, Vec<f64>) {
    let mut m = Mechanism::new([0.0, -9.81]);
    let mut prev = BodyId::Ground;
    let mut prev_pos = [0.0, 0.0];
    let mut pos = [0.0, 0.0];
    for i in 0..n {
        let a = -1.2 + 0.9 * (i as f64 / n as f64);
        pos = [pos[0] + 0.1 * a.cos(), pos[1] + 0.1 * a.sin()];
        let body = m.point(&format!("m{i}"), 1.0 + 0.1 * (i % 3) as f64, pos);
        m.add(Element::Distance { a: prev, pa: [0.0; 2], b: body, pb: [0.0; 2], length: 0.1 });
        if duplicate_last && i == n - 1 {
            m.add(Element::Distance { a: prev, pa: [0.0; 2], b: body, pb: [0.0; 2], length: 0.1 });
        }
        prev = body;
        prev_pos = pos;
    }
    let _ = prev_pos;
    let built = m.build().unwrap();
    let v: Vec<f64> = (0..built.q0.len()).map(|i| 0.3 * ((i as f64) * 0.7).sin()).collect();
    (built.model, built.q0, v)
}

#[test]
fn sparse_and_dense_solvers_agree() {
    let (model, q, v) = chain(120, false);
    let mut dense = Dynamics::with_solver(&model, LinearSolver::Dense);
    let mut sparse = Dynamics::with_solver(&model, LinearSolver::Sparse);
    dense.evaluate(&model, &q, &v, 0.0).unwrap();
    sparse.evaluate(&model, &q, &v, 0.0).unwrap();
    let scale = dense.lambda().iter().fold(0.0_f64, |a, l| a.max(l.abs()));
    for (a, b) in dense.lambda().iter().zip(sparse.lambda()) {
        assert!((a - b).abs() <= 1e-10 * scale, "λ: {a} vs {b}");
    }
    for (a, b) in dense.acc().iter().zip(sparse.acc()) {
        assert!((a - b).abs() <= 1e-9 * (1.0 + a.abs()), "A: {a} vs {b}");
    }
    // The Baumgarte response uses the same factorization.
    let (mut bd, mut bs) = (vec![0.0; model.m()], vec![0.0; model.m()]);
    let (mut od, mut os) = (vec![0.0; model.n()], vec![0.0; model.n()]);
    for (i, (x, y)) in bd.iter_mut().zip(bs.iter_mut()).enumerate() {
        *x = (i as f64).cos();
        *y = *x;
    }
    dense.add_constraint_response(&model, &mut bd, &mut od);
    sparse.add_constraint_response(&model, &mut bs, &mut os);
    for (a, b) in od.iter().zip(&os) {
        assert!((a - b).abs() <= 1e-9 * (1.0 + a.abs()), "response: {a} vs {b}");
    }
}

#[test]
fn sparse_solver_reports_a_dependent_row() {
    let (model, q, v) = chain(60, true);
    for solver in [LinearSolver::Dense, LinearSolver::Sparse] {
        let mut d = Dynamics::with_solver(&model, solver);
        let err = d.evaluate(&model, &q, &v, 0.0).unwrap_err();
        // Rows 59 and 60 are the same rod: one of them is named.
        assert!(matches!(err, cdyn::dynamics::Breakdown::Singular(59 | 60)), "{solver:?}: {err:?}");
    }
}

#[test]
fn a_long_chain_stays_on_its_constraints_with_the_sparse_path() {
    let (model, q, _) = chain(300, false);
    let v = vec![0.0; q.len()];
    let control = Control::none()
        .with_geometric(Geometric::Gradient(Gain::Rate(400.0)))
        .with_energy(Energy::Gradient(EnergyGain::Rate { alpha_e: 400.0 }))
        .with_application(cdyn::Application::ForwardEuler);
    let mut settings = Settings::new(Scheme::AdamsBashforth3, 1e-3, control);
    settings.solver = LinearSolver::Sparse;
    let mut sim = Simulation::new(&model, settings, &q, &v).unwrap();
    let mut worst = 0.0_f64;
    sim.run::<Error>(0.5, 10, |s| {
        worst = worst.max(s.measure().phi.abs());
        Ok(())
    })
    .unwrap();
    assert!(worst < 1e-8, "max |Φ| = {worst:e}");
}
