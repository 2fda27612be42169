//! Fixed-step schemes as data (Eqs. 54–59): their weights, order and
//! start-up, and one step `x_k → x_{k+1}` with the control term either in
//! the right-hand side or integrated by a separate Euler step.
//!
//! The integrator knows nothing of models: it sees a right-hand side split
//! into `f` (what the scheme integrates) and the control term `U`.

/// A fixed-step scheme. In scenario files it is written by its
/// [`SchemeInfo::name`]: `euler`, `ab2`, `ab3`, `rk4`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(serde::Deserialize, serde::Serialize))]
#[cfg_attr(feature = "serde", serde(try_from = "String", into = "&'static str"))]
#[non_exhaustive]
pub enum Scheme {
    /// Forward Euler, order 1.
    Euler,
    /// Adams–Bashforth, two steps, order 2 (Euler start-up).
    AdamsBashforth2,
    /// Adams–Bashforth, three steps, order 3 (RK-4 start-up, as in the paper).
    AdamsBashforth3,
    /// The classical Runge–Kutta method, order 4.
    RungeKutta4,
}

/// Where the control term is integrated (Eqs. 54–59). Scenario files write
/// `rhs`, `forward_euler` or `backward_euler`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Deserialize, serde::Serialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "snake_case"))]
#[non_exhaustive]
pub enum Application {
    /// `U` is part of the right-hand side the scheme integrates.
    #[default]
    #[cfg_attr(feature = "serde", serde(rename = "rhs"))]
    InRhs,
    /// The scheme integrates `f`; `U(x_k)` is added with one forward Euler step (Eq. 58).
    ForwardEuler,
    /// The scheme integrates `f`; `U(x̂_{k+1})` is added with one backward Euler step (Eq. 59).
    BackwardEuler,
    /// As [`BackwardEuler`](Self::BackwardEuler), `x_{k+1} = x̂_{k+1} + h U(x̂_{k+1})`,
    /// but at the cost of forward Euler: the evaluation at `x̂_{k+1}` that
    /// gives `U` also starts the next step, so the scheme's history holds
    /// `f(x̂_{k+1})` instead of `f(x_{k+1})`. They differ by `O(h |U|)`, the
    /// size of the violation just removed (the drift of one step), so the
    /// scheme's order is kept. With `h α = 1` the control is one Gauss–Newton
    /// step onto the invariants at the stepped state, measured after the step.
    PostStep,
}

/// How a scheme combines evaluations.
#[derive(Debug, Clone, Copy)]
#[non_exhaustive]
pub enum Formula {
    /// `x_{k+1} = x_k + h Σ_j w_j F_{k−j}`
    Multistep(&'static [f64]),
    /// An explicit Butcher tableau: `a` is strictly lower-triangular, row by row.
    RungeKutta {
        /// Stage coefficients `a_ij`, one row per stage.
        a: &'static [&'static [f64]],
        /// Weights `b_i`.
        b: &'static [f64],
        /// Nodes `c_i`.
        c: &'static [f64],
    },
}

/// Everything that distinguishes one scheme from another.
#[derive(Debug, Clone, Copy)]
pub struct SchemeInfo {
    /// Its name in scenario files and outputs: `euler`, `ab2`, `ab3`, `rk4`.
    pub name: &'static str,
    /// Order of accuracy.
    pub order: u32,
    /// Right-hand-side evaluations per step once started.
    pub evaluations: usize,
    /// Past evaluations the formula reads (1 for one-step schemes).
    pub history: usize,
    /// The scheme used while the history fills up.
    pub startup: Option<Scheme>,
    /// The formula: multistep weights or a Butcher tableau.
    pub formula: Formula,
}

const RK4_A: &[&[f64]] = &[&[], &[0.5], &[0.0, 0.5], &[0.0, 0.0, 1.0]];
const RK4_B: &[f64] = &[1.0 / 6.0, 1.0 / 3.0, 1.0 / 3.0, 1.0 / 6.0];
const RK4_C: &[f64] = &[0.0, 0.5, 0.5, 1.0];

impl Scheme {
    /// Every scheme.
    pub const ALL: [Scheme; 4] = [Scheme::Euler, Scheme::AdamsBashforth2, Scheme::AdamsBashforth3, Scheme::RungeKutta4];

    /// Order, cost, history, start-up and formula of this scheme.
    pub fn info(self) -> SchemeInfo {
        match self {
            Scheme::Euler => SchemeInfo {
                name: "euler",
                order: 1,
                evaluations: 1,
                history: 1,
                startup: None,
                formula: Formula::Multistep(&[1.0]),
            },
            Scheme::AdamsBashforth2 => SchemeInfo {
                name: "ab2",
                order: 2,
                evaluations: 1,
                history: 2,
                startup: Some(Scheme::RungeKutta4),
                formula: Formula::Multistep(&[1.5, -0.5]),
            },
            Scheme::AdamsBashforth3 => SchemeInfo {
                name: "ab3",
                order: 3,
                evaluations: 1,
                history: 3,
                startup: Some(Scheme::RungeKutta4),
                formula: Formula::Multistep(&[23.0 / 12.0, -16.0 / 12.0, 5.0 / 12.0]),
            },
            Scheme::RungeKutta4 => SchemeInfo {
                name: "rk4",
                order: 4,
                evaluations: 4,
                history: 1,
                startup: None,
                formula: Formula::RungeKutta { a: RK4_A, b: RK4_B, c: RK4_C },
            },
        }
    }

    /// The scheme with this name (`euler`, `ab2`, `ab3`, `rk4`).
    pub fn from_name(name: &str) -> Option<Scheme> {
        Scheme::ALL.into_iter().find(|s| s.info().name == name)
    }
}

impl TryFrom<String> for Scheme {
    type Error = String;

    /// The scheme of this name, or a message listing the names.
    fn try_from(name: String) -> std::result::Result<Self, String> {
        Scheme::from_name(&name).ok_or_else(|| {
            let names: Vec<&str> = Scheme::ALL.iter().map(|s| s.info().name).collect();
            format!("unknown scheme `{name}`; expected one of {}", names.join(", "))
        })
    }
}

impl From<Scheme> for &'static str {
    fn from(scheme: Scheme) -> Self {
        scheme.info().name
    }
}

/// A state equation `ẋ = f(x, t) + U(x, t)`.
pub trait Rhs {
    /// Why an evaluation can fail.
    type Error;
    /// Length of the state `x`.
    fn state_len(&self) -> usize;
    /// Whether `U` can be non-zero.
    fn has_control(&self) -> bool;
    /// Writes `f(x, t)` and, when `u` is given, `U(x, t)`.
    fn eval(&mut self, x: &[f64], t: f64, f: &mut [f64], u: Option<&mut [f64]>) -> Result<(), Self::Error>;
}

/// Storage of a state or of a derivative: a vector, or a fixed-size
/// array when the size is known at compile time (so that a small system's
/// step keeps its numbers in registers).
pub trait Buffer: Clone {
    /// The numbers.
    fn as_slice(&self) -> &[f64];
    /// The numbers, to write.
    fn as_mut_slice(&mut self) -> &mut [f64];
}

impl Buffer for Vec<f64> {
    #[inline(always)]
    fn as_slice(&self) -> &[f64] {
        self
    }
    #[inline(always)]
    fn as_mut_slice(&mut self) -> &mut [f64] {
        self
    }
}

/// Steps a state with one scheme and one way of applying the control.
/// All buffers are allocated here, none in [`step`](Self::step).
pub struct Integrator<B = Vec<f64>> {
    scheme: Scheme,
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
                Formula::Multistep(_) => 1,
            })
            .max()
            .unwrap_or(1);
        Self {
            scheme,
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

    /// The scheme the next step uses: the start-up one until enough history exists.
    pub fn active_scheme(&self) -> Scheme {
        let info = self.scheme.info();
        if self.filled + 1 < info.history { info.startup.unwrap_or(self.scheme) } else { self.scheme }
    }

    /// The evaluation `j` steps back (0: the newest).
    #[inline(always)]
    fn past(&self, j: usize) -> &[f64] {
        self.history[(self.newest + j) % self.history.len()].as_slice()
    }

    /// Advances `x` from `t` to `t + h`.
    #[inline]
    pub fn step<R: Rhs>(&mut self, rhs: &mut R, x: &mut [f64], t: f64, h: f64) -> Result<(), R::Error> {
        let active = self.active_scheme().info();
        let control = rhs.has_control();
        let split = control && self.application != Application::InRhs;
        // F(x_k): f + U in the right-hand side, f alone when split; U(x_k) kept for forward Euler.
        self.newest = (self.newest + self.history.len() - 1) % self.history.len();
        if !std::mem::take(&mut self.evaluated) {
            self.evaluate_first(rhs, x, t, control)?;
        }
        self.filled = (self.filled + 1).min(self.history.len());
        let mut control_pending = true;
        match active.formula {
            Formula::Multistep(w) => {
                // The forward Euler control step joins the same pass over memory.
                let joined = split && self.application == Application::ForwardEuler;
                let f: [&[f64]; 3] = std::array::from_fn(|j| self.past(if j < w.len() { j } else { 0 }));
                advance(x, h, w, f, joined.then_some(self.u.as_slice()));
                control_pending = !joined;
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
                    let next = (self.newest + self.history.len() - 1) % self.history.len();
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

fn add(a: &mut [f64], b: &[f64]) {
    for (a, b) in a.iter_mut().zip(b) {
        *a += b;
    }
}
