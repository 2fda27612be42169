//! One step `x_k → x_{k+1}` of a right-hand side by a scheme's formula:
//! multistep, predictor-corrector or Runge–Kutta, the start-up scheme while
//! the history fills, and the control term either in the right-hand side or
//! integrated by a separate Euler step (Eqs. 54–59).

use super::rhs::{Buffer, Rhs};
use super::scheme::{Application, Formula, Scheme};

/// Steps a state with one scheme and one way of applying the control.
/// All buffers are allocated here, none in [`step`](Self::step).
#[derive(Clone)]
pub struct Integrator<B = Vec<f64>> {
    scheme: Scheme,
    /// The formulas of the scheme and of its start-up scheme (the scheme's
    /// own without one), looked up once: a step only chooses between them.
    formula: Formula,
    startup: Formula,
    application: Application,
    /// Past evaluations, a ring: the newest at `newest`, older ones after it.
    history: Vec<B>,
    newest: usize,
    filled: usize,
    stages: Vec<B>,
    stage_x: B,
    u: B,
    scratch: B,
    /// The newest history entry is `f` at the state before the last
    /// post-step correction ([`Application::PostStep`]), to be used as is.
    evaluated: bool,
}

impl Integrator {
    /// An integrator of `scheme` for states of length `len`, in vectors.
    pub fn new(scheme: Scheme, application: Application, len: usize) -> Self {
        Self::with_zero(scheme, application, vec![0.0; len])
    }
}

impl<B: Buffer> Integrator<B> {
    /// With buffers shaped like `zero`.
    pub fn with_zero(scheme: Scheme, application: Application, zero: B) -> Self {
        let info = scheme.info();
        let stages = [Some(scheme), info.startup]
            .into_iter()
            .flatten()
            .map(|s| match s.info().formula {
                Formula::RungeKutta { b, .. } => b.len(),
                // The evaluation at the predicted state.
                Formula::Multistep(_)
                | Formula::PredictorCorrector { .. }
                | Formula::Rattle
                | Formula::GeneralizedAlpha => 1,
            })
            .max()
            .unwrap_or(1);
        Self {
            scheme,
            formula: info.formula,
            startup: info.startup.map_or(info.formula, |s| s.info().formula),
            application,
            history: vec![zero.clone(); info.history],
            newest: 0,
            filled: 0,
            stages: vec![zero.clone(); stages],
            stage_x: zero.clone(),
            u: zero.clone(),
            scratch: zero,
            evaluated: false,
        }
    }

    /// Forgets the past evaluations: the next steps are the start-up
    /// scheme's until the history is filled again (after an input changed
    /// the right-hand side, whose past values no longer describe it).
    pub fn restart(&mut self) {
        self.filled = 0;
        self.evaluated = false;
    }

    /// The scheme the next step uses: the start-up one until enough history exists.
    pub fn active_scheme(&self) -> Scheme {
        let info = self.scheme.info();
        if self.filled + 1 < info.history { info.startup.unwrap_or(self.scheme) } else { self.scheme }
    }

    /// The evaluation `j` steps back (0: the newest).
    #[inline(always)]
    fn past(&self, j: usize) -> &[f64] {
        self.history[ring(self.newest, j, self.history.len())].as_slice()
    }

    /// Advances `x` from `t` to `t + h`.
    ///
    /// # Panics
    ///
    /// For [`Scheme::Rattle`], which steps a model, not a right-hand side
    /// (a [`Simulation`](crate::simulate::Simulation) takes it).
    #[inline]
    pub fn step<R: Rhs>(&mut self, rhs: &mut R, x: &mut [f64], t: f64, h: f64) -> Result<(), R::Error> {
        let formula = if self.filled + 1 < self.history.len() { self.startup } else { self.formula };
        let control = rhs.has_control();
        let split = control && self.application != Application::InRhs;
        // F(x_k): f + U in the right-hand side, f alone when split; U(x_k) kept for forward Euler.
        self.newest = ring(self.newest, self.history.len() - 1, self.history.len());
        if !std::mem::take(&mut self.evaluated) {
            self.evaluate_first(rhs, x, t, control)?;
        }
        self.filled = (self.filled + 1).min(self.history.len());
        let mut control_pending = true;
        match formula {
            Formula::Multistep(w) => {
                // The forward Euler control step joins the same pass over memory.
                let joined = split && self.application == Application::ForwardEuler;
                let f: [&[f64]; 3] = std::array::from_fn(|j| self.past(if j < w.len() { j } else { 0 }));
                advance(x, h, w, f, joined.then_some(self.u.as_slice()));
                control_pending = !joined;
            }
            Formula::PredictorCorrector { predictor, corrector } => {
                let (history, newest) = (&self.history, self.newest);
                let past = |j: usize| history[ring(newest, j, history.len())].as_slice();
                let f = [past(0), past(1), past(2), past(3)];
                let stage_x = self.stage_x.as_mut_slice();
                stage_x.copy_from_slice(x);
                accumulate(stage_x, h, predictor, f);
                let predicted = self.stages[0].as_mut_slice();
                if control && !split {
                    rhs.eval(self.stage_x.as_slice(), t + h, predicted, Some(self.u.as_mut_slice()))?;
                    add(predicted, self.u.as_slice());
                } else {
                    // U(x_k) stays in `u` for the forward Euler control step.
                    rhs.eval(self.stage_x.as_slice(), t + h, predicted, None)?;
                }
                let past = |j: usize| self.history[ring(self.newest, j, self.history.len())].as_slice();
                let f = [self.stages[0].as_slice(), past(0), past(1), past(2)];
                accumulate(x, h, corrector, f);
            }
            Formula::Rattle | Formula::GeneralizedAlpha => {
                panic!("RATTLE and generalized-α step a model's positions and velocities, not a right-hand side")
            }
            Formula::RungeKutta { a, b, c } => {
                self.stages[0].as_mut_slice().copy_from_slice(self.history[self.newest].as_slice());
                for i in 1..b.len() {
                    let stage_x = self.stage_x.as_mut_slice();
                    stage_x.copy_from_slice(x);
                    for (j, &aij) in a[i].iter().enumerate() {
                        if aij != 0.0 {
                            for (s, k) in stage_x.iter_mut().zip(self.stages[j].as_slice()) {
                                *s += h * aij * k;
                            }
                        }
                    }
                    let ki = self.stages[i].as_mut_slice();
                    if control && !split {
                        rhs.eval(self.stage_x.as_slice(), t + c[i] * h, ki, Some(self.u.as_mut_slice()))?;
                        add(ki, self.u.as_slice());
                    } else {
                        rhs.eval(self.stage_x.as_slice(), t + c[i] * h, ki, None)?;
                    }
                }
                for (i, &bi) in b.iter().enumerate() {
                    for (xi, k) in x.iter_mut().zip(self.stages[i].as_slice()) {
                        *xi += h * bi * k;
                    }
                }
            }
        }
        if split && control_pending {
            match self.application {
                Application::BackwardEuler => {
                    rhs.eval(x, t + h, self.scratch.as_mut_slice(), Some(self.u.as_mut_slice()))?;
                }
                Application::PostStep => {
                    // f(x̂_{k+1}) goes where the next step reads its newest evaluation.
                    let next = ring(self.newest, self.history.len() - 1, self.history.len());
                    rhs.eval(x, t + h, self.history[next].as_mut_slice(), Some(self.u.as_mut_slice()))?;
                    self.evaluated = true;
                }
                _ => {}
            }
            for (xi, ui) in x.iter_mut().zip(self.u.as_slice()) {
                *xi += h * ui;
            }
        }
        Ok(())
    }

    #[inline(always)]
    fn evaluate_first<R: Rhs>(&mut self, rhs: &mut R, x: &[f64], t: f64, control: bool) -> Result<(), R::Error> {
        let (f, u) = (self.history[self.newest].as_mut_slice(), self.u.as_mut_slice());
        match (control, self.application) {
            (false, _) | (true, Application::BackwardEuler | Application::PostStep) => rhs.eval(x, t, f, None),
            (true, Application::ForwardEuler) => rhs.eval(x, t, f, Some(u)),
            (true, Application::InRhs) => {
                rhs.eval(x, t, f, Some(u))?;
                add(f, u);
                Ok(())
            }
        }
    }
}

/// `x += h Σ_j w_j f_j (+ h u)` in one pass (at most three past evaluations,
/// newest first; entries past `w` are not read).
/// Slot `newest + back` of a ring of `len` slots, for `newest, back < len`:
/// one comparison, not the division of `%` (four a step, each some 20–40
/// cycles of latency on the path of a small model's step).
#[inline(always)]
fn ring(newest: usize, back: usize, len: usize) -> usize {
    debug_assert!(newest < len && back < len, "a slot of the ring");
    let i = newest + back;
    if i >= len { i - len } else { i }
}

#[inline(always)]
fn advance(x: &mut [f64], h: f64, w: &[f64], f: [&[f64]; 3], u: Option<&[f64]>) {
    assert!(w.len() <= 3, "multistep formulas read at most three past evaluations");
    let hw = |j: usize| w.get(j).map_or(0.0, |w| h * w);
    let (w0, w1, w2) = (hw(0), hw(1), hw(2));
    let n = x.len();
    let (f0, f1, f2) = (&f[0][..n], &f[1][..n], &f[2][..n]);
    let (hu, u) = match u {
        Some(u) => (h, &u[..n]),
        None => (0.0, f0),
    };
    for i in 0..n {
        x[i] += w0 * f0[i] + w1 * f1[i] + w2 * f2[i] + hu * u[i];
    }
}

/// `x += h Σ_j w_j f_j` in one pass, for the four weights of a predictor
/// or a corrector.
#[inline(always)]
fn accumulate(x: &mut [f64], h: f64, w: &[f64], f: [&[f64]; 4]) {
    let [w0, w1, w2, w3] = [h * w[0], h * w[1], h * w[2], h * w[3]];
    let n = x.len();
    let (f0, f1, f2, f3) = (&f[0][..n], &f[1][..n], &f[2][..n], &f[3][..n]);
    for i in 0..n {
        x[i] += w0 * f0[i] + w1 * f1[i] + w2 * f2[i] + w3 * f3[i];
    }
}

fn add(a: &mut [f64], b: &[f64]) {
    for (a, b) in a.iter_mut().zip(b) {
        *a += b;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::integrate::{Application, Rhs, Scheme};

    /// `ẋ = λ x`, with the control term `U = μ x` when `mu` is given; counts evaluations.
    struct Linear {
        lambda: f64,
        mu: Option<f64>,
        evaluations: usize,
    }

    impl Rhs for Linear {
        type Error = ();
        fn state_len(&self) -> usize {
            1
        }
        fn has_control(&self) -> bool {
            self.mu.is_some()
        }
        fn eval(&mut self, x: &[f64], _: f64, f: &mut [f64], u: Option<&mut [f64]>) -> Result<(), ()> {
            self.evaluations += 1;
            f[0] = self.lambda * x[0];
            if let Some(u) = u {
                u[0] = self.mu.unwrap_or(0.0) * x[0];
            }
            Ok(())
        }
    }

    /// RK-4's step of `ẋ = λ x`: `x (1 + z + z²/2 + z³/6 + z⁴/24)`, `z = h λ`.
    fn rk4(x: f64, z: f64) -> f64 {
        x * (1.0 + z + z * z / 2.0 + z.powi(3) / 6.0 + z.powi(4) / 24.0)
    }

    /// ABM-4 PECE's step of `ẋ = λ x` from the states `y` (oldest first), by hand.
    fn abm4(y: [f64; 4], lambda: f64, h: f64) -> f64 {
        let f = y.map(|y| lambda * y);
        let predicted = y[3] + h / 24.0 * (55.0 * f[3] - 59.0 * f[2] + 37.0 * f[1] - 9.0 * f[0]);
        y[3] + h / 24.0 * (9.0 * lambda * predicted + 19.0 * f[3] - 5.0 * f[2] + f[1])
    }

    #[test]
    fn abm4_starts_with_three_rk4_steps_then_predicts_and_corrects_at_two_evaluations_a_step() {
        let (lambda, h) = (-1.3, 0.1);
        let mut rhs = Linear { lambda, mu: None, evaluations: 0 };
        let mut integrator = Integrator::new(Scheme::AdamsBashforthMoulton4, Application::InRhs, 1);
        let mut x = [1.0];
        let mut y = vec![1.0];
        for k in 0..3 {
            assert_eq!(integrator.active_scheme(), Scheme::RungeKutta4);
            integrator.step(&mut rhs, &mut x, k as f64 * h, h).unwrap();
            y.push(rk4(y[k], h * lambda));
            assert!((x[0] - y[k + 1]).abs() < 1e-15, "start-up step {k}: {} against {}", x[0], y[k + 1]);
        }
        assert_eq!(rhs.evaluations, 12);
        for k in 3..6 {
            assert_eq!(integrator.active_scheme(), Scheme::AdamsBashforthMoulton4);
            integrator.step(&mut rhs, &mut x, k as f64 * h, h).unwrap();
            y.push(abm4([y[k - 3], y[k - 2], y[k - 1], y[k]], lambda, h));
            assert!((x[0] - y[k + 1]).abs() < 1e-15, "step {k}: {} against {}", x[0], y[k + 1]);
        }
        assert_eq!(rhs.evaluations, 12 + 3 * 2);
    }

    #[test]
    fn abm4_applies_the_control_as_the_multistep_schemes_do() {
        let (lambda, mu, h) = (-0.7, -2.0, 0.05);
        // In the right-hand side: the scheme integrates ẋ = (λ + μ) x.
        let mut rhs = Linear { lambda, mu: Some(mu), evaluations: 0 };
        let mut integrator = Integrator::new(Scheme::AdamsBashforthMoulton4, Application::InRhs, 1);
        let mut alone = Linear { lambda: lambda + mu, mu: None, evaluations: 0 };
        let mut reference = Integrator::new(Scheme::AdamsBashforthMoulton4, Application::InRhs, 1);
        let (mut x, mut r) = ([1.0], [1.0]);
        for k in 0..6 {
            integrator.step(&mut rhs, &mut x, k as f64 * h, h).unwrap();
            reference.step(&mut alone, &mut r, k as f64 * h, h).unwrap();
            assert!((x[0] - r[0]).abs() < 1e-15, "step {k}");
        }
        // Split, forward Euler (Eq. 58): the scheme's step of ẋ = λ x, plus h U(x_k).
        let mut rhs = Linear { lambda, mu: Some(mu), evaluations: 0 };
        let mut integrator = Integrator::new(Scheme::AdamsBashforthMoulton4, Application::ForwardEuler, 1);
        let mut x = [1.0];
        let mut y = vec![1.0];
        for k in 0..6 {
            integrator.step(&mut rhs, &mut x, k as f64 * h, h).unwrap();
            let stepped =
                if k < 3 { rk4(y[k], h * lambda) } else { abm4([y[k - 3], y[k - 2], y[k - 1], y[k]], lambda, h) };
            y.push(stepped + h * mu * y[k]);
            assert!((x[0] - y[k + 1]).abs() < 1e-15, "step {k}: {} against {}", x[0], y[k + 1]);
        }
    }
}
