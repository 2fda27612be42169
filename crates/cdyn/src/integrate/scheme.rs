//! The schemes as data: each one's name, order, cost per step, history,
//! start-up scheme and formula, and where the control term is integrated.

/// A fixed-step scheme. In scenario files it is written by its
/// [`SchemeInfo::name`]: `euler`, `ab2`, `ab3`, `rk4`, `abm4`, `rattle`,
/// `generalized_alpha`.
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
    /// Adams–Bashforth–Moulton, order 4, in PECE mode: the four-step
    /// Adams–Bashforth predictor, one evaluation there, the three-step
    /// Adams–Moulton corrector, and the evaluation at the corrected state
    /// that starts the next step: two evaluations a step, half of RK-4's,
    /// with an error constant about 19/270 of AB-4's (RK-4 start-up).
    AdamsBashforthMoulton4,
    /// RATTLE: velocity Verlet with constraint forces, order 2, one
    /// evaluation a step; `Φ = 0` and `Φ̇ = 0` hold to round-off after every
    /// step, and with a constant `M` and conservative forces the energy
    /// stays in a bounded band for all time (symplectic). It steps the
    /// positions and velocities apart, so it needs the model's constraints,
    /// not a right-hand side: a [`Simulation`](crate::simulate::Simulation)
    /// takes it ([`crate::simulate::rattle`]), with no control law in the
    /// right-hand side (`projection` may follow it).
    Rattle,
    /// Generalized-α (Chung–Hulbert) on the index-3 equations: implicit,
    /// order 2, unconditionally stable on linear problems, with numerical
    /// damping of the modes far above `1/h` set by `ρ∞`; `Φ = 0` holds to
    /// the Newton tolerance after every step. For stiff springs and
    /// dampers at steps an explicit scheme cannot take. Like RATTLE it
    /// steps a model ([`crate::simulate::generalized_alpha`]), configured
    /// by [`Settings::generalized_alpha`](crate::simulate::Settings::generalized_alpha).
    GeneralizedAlpha,
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
    /// Predict `x* = x_k + h Σ_j p_j F_{k−j}`, evaluate `F* = F(x*, t_{k+1})`,
    /// correct `x_{k+1} = x_k + h (c_0 F* + Σ_j c_{j+1} F_{k−j})` (PECE).
    PredictorCorrector {
        /// Predictor weights, newest first.
        predictor: &'static [f64],
        /// Corrector weights: `F*`'s, then the past evaluations', newest first.
        corrector: &'static [f64],
    },
    /// Velocity Verlet with constraint forces ([`Scheme::Rattle`]): not a
    /// combination of right-hand sides, stepped by the simulation itself.
    Rattle,
    /// Generalized-α ([`Scheme::GeneralizedAlpha`]): implicit, stepped by
    /// the simulation itself with a Newton iteration.
    GeneralizedAlpha,
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
    /// Its name in scenario files and outputs: `euler`, `ab2`, `ab3`, `rk4`, `abm4`, `rattle`, `generalized_alpha`.
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
    pub const ALL: [Scheme; 7] = [
        Scheme::Euler,
        Scheme::AdamsBashforth2,
        Scheme::AdamsBashforth3,
        Scheme::RungeKutta4,
        Scheme::AdamsBashforthMoulton4,
        Scheme::Rattle,
        Scheme::GeneralizedAlpha,
    ];

    /// The schemes that step any right-hand side `ẋ = f + U` with an
    /// [`Integrator`], under every control law: all but RATTLE and generalized-α.
    pub const GENERAL: [Scheme; 5] = [
        Scheme::Euler,
        Scheme::AdamsBashforth2,
        Scheme::AdamsBashforth3,
        Scheme::RungeKutta4,
        Scheme::AdamsBashforthMoulton4,
    ];

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
            Scheme::AdamsBashforthMoulton4 => SchemeInfo {
                name: "abm4",
                order: 4,
                evaluations: 2,
                history: 4,
                startup: Some(Scheme::RungeKutta4),
                formula: Formula::PredictorCorrector {
                    predictor: &[55.0 / 24.0, -59.0 / 24.0, 37.0 / 24.0, -9.0 / 24.0],
                    corrector: &[9.0 / 24.0, 19.0 / 24.0, -5.0 / 24.0, 1.0 / 24.0],
                },
            },
            Scheme::Rattle => SchemeInfo {
                name: "rattle",
                order: 2,
                evaluations: 1,
                history: 1,
                startup: None,
                formula: Formula::Rattle,
            },
            Scheme::GeneralizedAlpha => SchemeInfo {
                name: "generalized_alpha",
                order: 2,
                // At least two: the predictor's and one correction's (more as Newton needs).
                evaluations: 2,
                history: 1,
                startup: None,
                formula: Formula::GeneralizedAlpha,
            },
        }
    }

    /// Whether the scheme steps a model's positions and velocities itself
    /// (RATTLE, generalized-α) rather than a right-hand side: such schemes
    /// hold `Φ = 0` themselves and take no control law in the right-hand
    /// side, only `projection` after the step.
    pub fn steps_model(self) -> bool {
        matches!(self.info().formula, Formula::Rattle | Formula::GeneralizedAlpha)
    }

    /// The scheme with this name (`euler`, `ab2`, `ab3`, `rk4`, `abm4`, `rattle`, `generalized_alpha`).
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
