//! A general model of a few coordinates, evaluated in arrays: the step of
//! a [`SmallSystem`](crate::small::SmallSystem) for a model built at run
//! time. Its elements are still read through the model (one call each),
//! but `S`, `λ`, `A` and the control terms are formed in arrays of sizes
//! known at compile time, behind one dispatch on `(n, m)`: a pendulum's
//! general step otherwise runs a dozen passes whose set-up costs more than
//! their two or three values.

use super::EvalError;
use super::arrays::{ArrayDynamics, ArrayWork};
use crate::control::{Control, Invariants};
use crate::dynamics::momentum::Symmetries;
use crate::linalg::DependentRows;
use crate::linalg::mass::DiagonalMass;
use crate::model::Model;

/// The controlled right-hand side of a small model in arrays.
pub(super) trait InArrays: Send + Sync {
    /// As [`Rhs::eval`](crate::integrate::Rhs::eval) of the model with `control`.
    #[allow(clippy::too_many_arguments)]
    fn eval(
        &mut self,
        model: &Model,
        control: &Control,
        e0: f64,
        x: &[f64],
        t: f64,
        f: &mut [f64],
        u: Option<&mut [f64]>,
    ) -> Result<(), EvalError>;
    /// The largest `|Φ|` of the last evaluation.
    fn last_violation(&self) -> f64;
    /// The most rows a factorization dropped since the last call.
    fn take_dropped(&mut self) -> usize;
    fn clone_box(&self) -> Box<dyn InArrays>;
}

impl Clone for Box<dyn InArrays> {
    fn clone(&self) -> Self {
        self.clone_box()
    }
}

#[derive(Clone)]
struct ModelInArrays<const N: usize, const M: usize> {
    d: ArrayDynamics<N, M>,
    work: ArrayWork<N, M>,
    /// The row and column of each Jacobian entry, in the pattern's order;
    /// `None` where the pattern is every row over every coordinate in order.
    places: Option<Vec<(u32, u32)>>,
}

impl<const N: usize, const M: usize> InArrays for ModelInArrays<N, M> {
    fn eval(
        &mut self,
        model: &Model,
        control: &Control,
        e0: f64,
        x: &[f64],
        t: f64,
        f: &mut [f64],
        u: Option<&mut [f64]>,
    ) -> Result<(), EvalError> {
        let places = self.places.as_deref();
        let evaluate = |d: &mut ArrayDynamics<N, M>, q, v| d.evaluate_model(model, places, q, v, t);
        self.d.controlled_rhs(control, e0, &mut self.work, (x, t), f, u, evaluate)
    }
    fn last_violation(&self) -> f64 {
        self.d.max_violation()
    }
    fn take_dropped(&mut self) -> usize {
        std::mem::take(&mut self.d.dropped)
    }
    fn clone_box(&self) -> Box<dyn InArrays> {
        Box::new(self.clone())
    }
}

/// The model evaluated in arrays, where it can be: a constant diagonal
/// mass, 2 to 4 coordinates and fewer rows (at least one), no unit vectors, and a control whose terms read only what the arrays
/// hold: no projection (it reuses the general factorization), no momentum
/// or invariant of `symmetries` kept (the laws hold them on the general path).
pub(super) fn in_arrays(
    model: &Model,
    control: &Control,
    symmetries: &Symmetries,
    dependent: DependentRows,
) -> Option<Box<dyn InArrays>> {
    let mass = model.mass()?;
    let keeps_momenta = control.invariants == Invariants::Keep && !symmetries.kept.is_empty();
    let reads_more = control.projection.is_some() || keeps_momenta;
    let (n, m, pattern) = (model.n(), model.m(), model.pattern());
    if reads_more || !model.unit_vectors().is_empty() || pattern.nnz() > n * m {
        return None;
    }
    let every = (0..m).all(|r| pattern.row(r).map(|j| pattern.cols[j]).eq(0..n as u32));
    let places =
        (!every).then(|| (0..m).flat_map(|r| pattern.row(r).map(move |j| (r as u32, pattern.cols[j]))).collect());
    fn build<const N: usize, const M: usize>(
        diagonal: &[f64],
        places: Option<Vec<(u32, u32)>>,
        dependent: DependentRows,
    ) -> Option<Box<dyn InArrays>> {
        let mass = DiagonalMass::new(<[f64; N]>::try_from(diagonal).ok()?).ok()?;
        Some(Box::new(ModelInArrays {
            d: ArrayDynamics::<N, M>::new(mass, dependent),
            work: ArrayWork::default(),
            places,
        }))
    }
    let diagonal = mass.diagonal().as_slice();
    match (n, m) {
        (2, 1) => build::<2, 1>(diagonal, places, dependent),
        (3, 1) => build::<3, 1>(diagonal, places, dependent),
        (3, 2) => build::<3, 2>(diagonal, places, dependent),
        (4, 1) => build::<4, 1>(diagonal, places, dependent),
        (4, 2) => build::<4, 2>(diagonal, places, dependent),
        (4, 3) => build::<4, 3>(diagonal, places, dependent),
        _ => None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::control::methods::{MethodGains, redundant_cases};
    use crate::control::{Gain, Geometric, Rate, Velocity};
    use crate::linalg::LinearSolver;
    use crate::models::*;
    use crate::{Scheme, Settings, Simulation};

    /// Small models of each kind — a rod whose row reads every coordinate,
    /// rows that read some (the double pendulum), a driven support (`Φ_t`),
    /// a damper (forces), a knife edge (a nonholonomic row) — stepped in arrays and through
    /// the general path (a factorization asked for by name): the same
    /// trajectories to round-off, under every law the arrays hold, at AB-3,
    /// RK-4 and ABM-4.
    #[test]
    fn small_models_step_in_arrays_as_through_the_general_path() {
        let pendulum = cartesian_pendulum(PendulumParams::default()).unwrap();
        let double = double_pendulum(DoublePendulumParams::default()).unwrap();
        let support = moving_support_pendulum(MovingSupportParams::default()).unwrap();
        let damped = damped_pendulum(DampedPendulumParams::default()).unwrap();
        let sled = Example {
            model: Model::builder(vec![1.0, 1.0, 0.2]).nonholonomic(Blade, [0, 1, 2]).build().unwrap(),
            q0: vec![0.0, 0.0, 0.3],
            v0: vec![0.3_f64.cos(), 0.3_f64.sin(), 0.5],
            ..cartesian_pendulum(PendulumParams::default()).unwrap()
        };
        let g = MethodGains::paper();
        let mut controls: Vec<Control> = redundant_cases(&g).into_iter().map(|(_, c)| c).collect();
        controls.push(Control::none().with_velocity(Velocity::Gradient(Rate::Auto)));
        controls.push(g.cvsgf_energy().with_geometric(Geometric::Newton(Rate::Auto)));
        controls.push(Control::none().with_geometric(Geometric::Gradient(Gain::Auto)));
        controls.push(Control::robust());
        controls.push(Control::robust().with_energy(crate::control::Energy::None));
        for (name, ex) in
            [("pendulum", &pendulum), ("double", &double), ("support", &support), ("damped", &damped), ("sled", &sled)]
        {
            for &control in &controls {
                // The sled keeps its turning rate: in arrays only if free of it.
                let control = if name == "sled" { control.with_invariants(Invariants::Free) } else { control };
                for scheme in [Scheme::AdamsBashforth3, Scheme::RungeKutta4, Scheme::AdamsBashforthMoulton4] {
                    let settings = Settings::new(scheme, 1e-3, control);
                    let symmetries = crate::dynamics::momentum::detect(&ex.model, &ex.q0, &ex.v0);
                    let chosen = in_arrays(&ex.model, &settings.control, &symmetries, DependentRows::Error);
                    assert!(chosen.is_some(), "{name}: not in arrays");
                    let mut arrays = Simulation::new(&ex.model, settings, &ex.q0, &ex.v0).unwrap();
                    let general = settings.with_solver(LinearSolver::Dense);
                    let mut general = Simulation::new(&ex.model, general, &ex.q0, &ex.v0).unwrap();
                    for _ in 0..500 {
                        arrays.step().unwrap();
                        general.step().unwrap();
                    }
                    let gap = arrays.q().iter().chain(arrays.v()).zip(general.q().iter().chain(general.v()));
                    let gap = gap.fold(0.0_f64, |e, (a, b)| e.max((a - b).abs()));
                    assert!(gap <= 1e-12, "{name} {control:?} {scheme:?}: {gap:e}");
                    assert_eq!(arrays.evaluations(), general.evaluations());
                }
            }
        }
    }

    /// What the arrays cannot hold runs the general path: a projection, a
    /// run that keeps a momentum, models past the compiled sizes.
    #[test]
    fn the_general_path_keeps_what_arrays_do_not_hold() {
        let pendulum = cartesian_pendulum(PendulumParams::default()).unwrap();
        let none = crate::dynamics::momentum::Symmetries::default();
        let arrays = |ex: &crate::models::Example, control: Control, symmetries: &Symmetries| {
            in_arrays(&ex.model, &control, symmetries, DependentRows::Error).is_some()
        };
        assert!(arrays(&pendulum, Control::none(), &none));
        assert!(!arrays(&pendulum, Control::projection(), &none));
        assert!(arrays(&pendulum, Control::robust(), &none), "no momentum to hold");
        let chain = chain(ChainParams { n: 3, ..ChainParams::default() }).unwrap();
        assert!(!arrays(&chain, Control::none(), &none), "6 coordinates");
        let theta = theta_pendulum(PendulumParams::default()).unwrap();
        assert!(!arrays(&theta, Control::none(), &none), "no rows");
        // Two free masses on a rod keep their linear momenta: the general
        // path holds them, unless the control is told not to.
        let floating = Model::builder(vec![1.0; 4]).constrain(Rod, [0, 1, 2, 3]).momentum("p_x", &[(0, 1.0), (2, 1.0)]);
        let floating = floating.build().unwrap();
        let (q0, v0) = ([0.0, 0.0, 1.0, 0.0], [0.0, 0.0, 0.0, 1.0]);
        let kept = crate::dynamics::momentum::detect(&floating, &q0, &v0);
        assert!(!kept.kept.is_empty());
        assert!(in_arrays(&floating, &Control::none(), &kept, DependentRows::Error).is_none());
        assert!(in_arrays(&floating, &Control::robust(), &kept, DependentRows::Error).is_none());
        let free = Control::none().with_invariants(Invariants::Free);
        assert!(in_arrays(&floating, &free, &kept, DependentRows::Error).is_some());
    }

    /// RATTLE and generalized-α step the model themselves, not its
    /// right-hand side: their runs keep the general path, whose `Φ` the
    /// violation limit reads after every step.
    #[test]
    fn the_schemes_that_step_the_model_keep_the_general_path() {
        let ex = cartesian_pendulum(PendulumParams::default()).unwrap();
        for scheme in [Scheme::Rattle, Scheme::GeneralizedAlpha] {
            let settings = Settings::new(scheme, 1e-2, Control::none()).with_violation_limit(1e-300);
            let mut sim = Simulation::new(&ex.model, settings, &ex.q0, &ex.v0).unwrap();
            let stopped = (0..100).find_map(|_| sim.step().err());
            assert!(matches!(stopped, Some(crate::Error::ViolationLimit { .. })), "{scheme:?}: {stopped:?}");
        }
    }

    /// `|p_b − p_a|² = 1` on `(x_a, y_a, x_b, y_b)`, and `|p|² = 1` on `(x, y)`.
    struct Rod;
    impl crate::Constraint<4, 1> for Rod {
        fn eval<D: crate::Scalar>(&self, [xa, ya, xb, yb]: [D; 4], _t: D) -> [D; 1] {
            [((xb - xa) * (xb - xa) + (yb - ya) * (yb - ya) - 1.0) * 0.5]
        }
    }
    struct Anchored;
    impl crate::Constraint<2, 1> for Anchored {
        fn eval<D: crate::Scalar>(&self, [x, y]: [D; 2], _t: D) -> [D; 1] {
            [(x * x + y * y - 1.0) * 0.5]
        }
    }
    /// A knife edge on `(x, y, θ)`: no velocity across its blade.
    struct Blade;
    impl crate::model::nonholonomic::Nonholonomic<3, 1> for Blade {
        fn eval<D: crate::Scalar>(&self, [_, _, theta]: [D; 3], [vx, vy, _]: [D; 3], _t: D) -> [D; 1] {
            [vx * theta.sin() - vy * theta.cos()]
        }
    }

    /// A double pendulum whose lower rod is given twice: with dependent rows
    /// tolerated, both paths drop the second and move alike.
    #[test]
    fn a_dependent_row_is_dropped_in_arrays_as_in_the_general_path() {
        let model = Model::builder(vec![1.0; 4])
            .constrain(Anchored, [0, 1])
            .constrain(Rod, [0, 1, 2, 3])
            .constrain(Rod, [0, 1, 2, 3])
            .build()
            .unwrap();
        let (q0, v0) = ([0.0, -1.0, 0.0, -2.0], [1.0, 0.0, 2.0, 0.0]);
        let settings = Settings::new(Scheme::RungeKutta4, 1e-3, MethodGains::paper().cvsgf_energy())
            .with_dependent_rows(DependentRows::Tolerate);
        let symmetries = crate::dynamics::momentum::detect(&model, &q0, &v0);
        assert!(in_arrays(&model, &settings.control, &symmetries, DependentRows::Tolerate).is_some());
        let mut arrays = Simulation::new(&model, settings, &q0, &v0).unwrap();
        let mut general = Simulation::new(&model, settings.with_solver(LinearSolver::Dense), &q0, &v0).unwrap();
        for _ in 0..500 {
            arrays.step().unwrap();
            general.step().unwrap();
        }
        let gap = arrays.q().iter().zip(general.q()).fold(0.0_f64, |e, (a, b)| e.max((a - b).abs()));
        assert!(gap <= 1e-12, "{gap:e}");
        let (a, g) = (arrays.rank_loss().unwrap(), general.rank_loss().unwrap());
        assert_eq!((a.max, a.steps), (1, 500));
        assert_eq!((a.max, a.steps), (g.max, g.steps));
    }
}
