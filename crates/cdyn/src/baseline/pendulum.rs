//! Example 1 with CVSGF + energy control (Eq. 51, forward Euler control,
//! Eqs. 57–58), AB-3 with RK-4 start-up, written out by hand: closed-form
//! accelerations, no buffers. It is what the benchmark measures cdyn's
//! abstraction overhead against, and a test holds it to cdyn's trajectory.

/// State `(X, Y, V_X, V_Y)`.
pub type State = [f64; 4];

/// The hand-written integrator.
#[derive(Debug, Clone)]
pub struct HandWritten {
    /// The current state.
    pub x: State,
    /// The step.
    pub h: f64,
    zeta: f64,
    alpha_e: f64,
    e0: f64,
    /// `f` at the last three corrected states, newest first.
    history: [State; 3],
    steps: u64,
}

const G: f64 = 1.0;

impl HandWritten {
    /// From `x0` with step `h`, CVSGF gain `ζ` and energy rate `α_e`.
    pub fn new(x0: State, h: f64, zeta: f64, alpha_e: f64) -> Self {
        let e0 = 0.5 * (x0[2] * x0[2] + x0[3] * x0[3]) + G * x0[1];
        Self { x: x0, h, zeta, alpha_e, e0, history: [[0.0; 4]; 3], steps: 0 }
    }

    /// Eq. 60 with `λ = (|v|² − gY)/(X² + Y²)`.
    #[inline(always)]
    fn f(x: &State) -> State {
        let lambda = (x[2] * x[2] + x[3] * x[3] - G * x[1]) / (x[0] * x[0] + x[1] * x[1]);
        [x[2], x[3], -x[0] * lambda, -G - x[1] * lambda]
    }

    /// `U = (−2ζΦ(X, Y), −α_e Ψ v/|v|²)`.
    #[inline(always)]
    fn u(&self, x: &State) -> State {
        let phi = 0.5 * (x[0] * x[0] + x[1] * x[1] - 1.0);
        let v2 = x[2] * x[2] + x[3] * x[3];
        let psi = 0.5 * v2 + G * x[1] - self.e0;
        let k = if v2 > 1e-30 { self.alpha_e * psi / v2 } else { 0.0 };
        [-2.0 * self.zeta * phi * x[0], -2.0 * self.zeta * phi * x[1], -k * x[2], -k * x[3]]
    }

    /// Advances [`x`](Self::x) by one step `h`.
    pub fn step(&mut self) {
        let h = self.h;
        let x = self.x;
        let f0 = Self::f(&x);
        let u0 = self.u(&x);
        self.history = [f0, self.history[0], self.history[1]];
        let mut next = [0.0; 4];
        if self.steps < 2 {
            // RK-4 start-up on f.
            let at = |k: &State, c: f64| std::array::from_fn::<f64, 4, _>(|i| x[i] + c * h * k[i]);
            let k2 = Self::f(&at(&f0, 0.5));
            let k3 = Self::f(&at(&k2, 0.5));
            let k4 = Self::f(&at(&k3, 1.0));
            for i in 0..4 {
                next[i] = x[i] + h * (f0[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]) / 6.0;
            }
        } else {
            let [a, b, c] = &self.history;
            for i in 0..4 {
                next[i] = x[i] + h * (23.0 * a[i] - 16.0 * b[i] + 5.0 * c[i]) / 12.0;
            }
        }
        for i in 0..4 {
            self.x[i] = next[i] + h * u0[i];
        }
        self.steps += 1;
    }
}
