//! Scenario files: a built-in model and its parameters, the method, the
//! integrator and the output sampling, in TOML. Every mistake becomes one
//! line naming the file and the key.

use crate::runner::Case;
use anyhow::{Result, anyhow, bail};
use cdyn::models::{Example, PendulumParams, cartesian_pendulum, theta_pendulum};
use cdyn::{Application, Control, Energy, EnergyGain, Gain, Geometric, Scheme, Settings};
use serde::Deserialize;
use std::path::Path;

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Scenario {
    pub model: ModelSpec,
    #[serde(default)]
    pub initial: InitialSpec,
    #[serde(default)]
    pub method: MethodSpec,
    pub integrator: IntegratorSpec,
    #[serde(default)]
    pub output: OutputSpec,
}

#[derive(Debug, Deserialize, Clone, Copy, PartialEq)]
#[serde(rename_all = "snake_case")]
pub enum ModelKind {
    Pendulum,
    PendulumTheta,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ModelSpec {
    pub kind: ModelKind,
    pub mass: Option<f64>,
    pub length: Option<f64>,
    pub gravity: Option<f64>,
    pub theta0: Option<f64>,
    pub omega0: Option<f64>,
}

#[derive(Debug, Deserialize, Default)]
#[serde(deny_unknown_fields)]
pub struct InitialSpec {
    pub q: Option<Vec<f64>>,
    pub v: Option<Vec<f64>>,
    /// Start even if the initial state violates the constraints.
    #[serde(default)]
    pub off_constraint: bool,
    pub tolerance: Option<f64>,
}

#[derive(Debug, Deserialize, Clone, Copy, PartialEq, Default)]
#[serde(rename_all = "snake_case")]
pub enum GeometricKind {
    #[default]
    None,
    Baumgarte,
    Cvsgf,
}

#[derive(Debug, Deserialize, Clone, Copy, PartialEq, Default)]
#[serde(rename_all = "snake_case")]
pub enum EnergyKind {
    #[default]
    None,
    Gradient,
    Baumgarte,
}

#[derive(Debug, Deserialize, Clone, Copy, PartialEq, Default)]
#[serde(rename_all = "snake_case")]
pub enum Apply {
    #[default]
    Rhs,
    ForwardEuler,
    BackwardEuler,
}

#[derive(Debug, Deserialize, Default)]
#[serde(deny_unknown_fields)]
pub struct MethodSpec {
    #[serde(default)]
    pub geometric: GeometricKind,
    #[serde(default)]
    pub energy: EnergyKind,
    #[serde(default)]
    pub apply: Apply,
    pub zeta: Option<f64>,
    pub alpha_g: Option<f64>,
    pub alpha: Option<f64>,
    pub beta: Option<f64>,
    pub omega: Option<f64>,
    pub damping_ratio: Option<f64>,
    pub alpha_e: Option<f64>,
    pub rho_q: Option<f64>,
    pub rho_v: Option<f64>,
    pub eta: Option<f64>,
}

#[derive(Debug, Deserialize, Clone, Copy, PartialEq)]
#[serde(rename_all = "snake_case")]
pub enum SchemeName {
    Euler,
    Ab2,
    Ab3,
    Rk4,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct IntegratorSpec {
    pub scheme: SchemeName,
    pub h: f64,
    pub t_end: f64,
}

#[derive(Debug, Deserialize, Default)]
#[serde(deny_unknown_fields)]
pub struct OutputSpec {
    /// Write a sample every this many steps (default 1).
    pub every: Option<i64>,
    /// Name of the case and its CSV file (default: the scenario file's stem).
    pub name: Option<String>,
}

/// Reads and checks a scenario file.
pub fn load(path: &Path) -> Result<Scenario> {
    let file = path.display();
    let text = std::fs::read_to_string(path).map_err(|e| anyhow!("{file}: cannot read: {e}"))?;
    if text.trim().is_empty() {
        bail!("{file}: the scenario is empty");
    }
    toml::from_str(&text).map_err(|e| {
        let at = e.span().map_or(String::new(), |s| {
            let line = text[..s.start].matches('\n').count() + 1;
            let col = s.start - text[..s.start].rfind('\n').map_or(0, |i| i + 1) + 1;
            format!(":{line}:{col}")
        });
        anyhow!("{file}{at}: {}", e.message().trim().replace('\n', " "))
    })
}

/// Checks one number: finite and positive, or finite and not negative.
fn check(file: &str, key: &str, value: f64, positive: bool) -> Result<f64> {
    let ok = value.is_finite() && if positive { value > 0.0 } else { value >= 0.0 };
    if !ok {
        let what = if positive {
            "finite and positive"
        } else {
            "finite and not negative"
        };
        bail!("{file}: {key} = {value}: must be {what}");
    }
    Ok(value)
}

impl Scenario {
    /// The case this scenario describes; `path` names it in errors.
    pub fn case(&self, path: &Path) -> Result<Case> {
        let file = &path.display().to_string();
        let control = self.method.control(file)?;
        let i = &self.integrator;
        let h = check(file, "[integrator] h", i.h, true)?;
        let t_end = check(file, "[integrator] t_end", i.t_end, true)?;
        if t_end / h > 1e9 {
            bail!(
                "{file}: [integrator] t_end / h = {:e} steps is more than 1e9",
                t_end / h
            );
        }
        let scheme = match i.scheme {
            SchemeName::Euler => Scheme::Euler,
            SchemeName::Ab2 => Scheme::AdamsBashforth2,
            SchemeName::Ab3 => Scheme::AdamsBashforth3,
            SchemeName::Rk4 => Scheme::RungeKutta4,
        };
        let mut settings = Settings::new(scheme, h, control);
        let init = &self.initial;
        if let Some(tol) = init.tolerance {
            settings.consistency_tolerance = Some(check(file, "[initial] tolerance", tol, true)?);
        }
        if init.off_constraint {
            settings.consistency_tolerance = None;
        }
        let mut example = self.example(file)?;
        for (key, given, default) in [
            ("q", &init.q, &mut example.q0),
            ("v", &init.v, &mut example.v0),
        ] {
            if let Some(given) = given {
                if given.len() != default.len() {
                    bail!(
                        "{file}: [initial] {key} has {} values, the model has {} coordinates",
                        given.len(),
                        default.len()
                    );
                }
                if let Some(x) = given.iter().find(|x| !x.is_finite()) {
                    bail!("{file}: [initial] {key} contains {x}: must be finite");
                }
                default.clone_from(given);
            }
        }
        let every = match self.output.every {
            None => 1,
            Some(e) if e >= 1 => e as u64,
            Some(e) => bail!("{file}: [output] every = {e}: must be at least 1"),
        };
        let name = match &self.output.name {
            Some(n)
                if !n.is_empty()
                    && n.chars()
                        .all(|c| c.is_ascii_alphanumeric() || "_-.".contains(c)) =>
            {
                n.clone()
            }
            Some(n) => bail!("{file}: [output] name = {n:?}: use letters, digits, '_', '-', '.'"),
            None => path
                .file_stem()
                .map_or("run".into(), |s| s.to_string_lossy().into_owned()),
        };
        Ok(Case {
            name,
            example,
            settings,
            t_end,
            every,
        })
    }

    fn example(&self, file: &str) -> Result<Example> {
        let m = &self.model;
        let d = PendulumParams::default();
        let p = PendulumParams {
            mass: check(file, "[model] mass", m.mass.unwrap_or(d.mass), true)?,
            length: check(file, "[model] length", m.length.unwrap_or(d.length), true)?,
            gravity: check(
                file,
                "[model] gravity",
                m.gravity.unwrap_or(d.gravity),
                false,
            )?,
            theta0: m.theta0.unwrap_or(d.theta0),
            omega0: m.omega0.unwrap_or(d.omega0),
        };
        for (key, x) in [("theta0", p.theta0), ("omega0", p.omega0)] {
            if !x.is_finite() {
                bail!("{file}: [model] {key} = {x}: must be finite");
            }
        }
        Ok(match m.kind {
            ModelKind::Pendulum => cartesian_pendulum(p)?,
            ModelKind::PendulumTheta => theta_pendulum(p)?,
        })
    }
}

impl MethodSpec {
    /// The control law, refusing gains that the chosen methods do not use.
    fn control(&self, file: &str) -> Result<Control> {
        let used = |key: &str, value: Option<f64>, by: bool, method: &str| -> Result<()> {
            if value.is_some() && !by {
                bail!("{file}: [method] {key} is only used with {method}");
            }
            Ok(())
        };
        let g = self.geometric;
        used(
            "zeta",
            self.zeta,
            g == GeometricKind::Cvsgf,
            "geometric = \"cvsgf\"",
        )?;
        used(
            "alpha_g",
            self.alpha_g,
            g == GeometricKind::Cvsgf,
            "geometric = \"cvsgf\"",
        )?;
        for (key, value) in [
            ("alpha", self.alpha),
            ("beta", self.beta),
            ("omega", self.omega),
            ("damping_ratio", self.damping_ratio),
        ] {
            used(
                key,
                value,
                g == GeometricKind::Baumgarte,
                "geometric = \"baumgarte\"",
            )?;
        }
        let e = self.energy;
        for (key, value) in [
            ("alpha_e", self.alpha_e),
            ("rho_q", self.rho_q),
            ("rho_v", self.rho_v),
        ] {
            used(
                key,
                value,
                e == EnergyKind::Gradient,
                "energy = \"gradient\"",
            )?;
        }
        used(
            "eta",
            self.eta,
            e == EnergyKind::Baumgarte,
            "energy = \"baumgarte\"",
        )?;
        let num = |key: &str, v: f64| check(file, &format!("[method] {key}"), v, false);

        let geometric = match g {
            GeometricKind::None => Geometric::None,
            GeometricKind::Cvsgf => match (self.zeta, self.alpha_g) {
                (Some(z), None) => Geometric::Gradient(Gain::Fixed(num("zeta", z)?)),
                (None, Some(a)) => Geometric::Gradient(Gain::Rate(num("alpha_g", a)?)),
                _ => bail!(
                    "{file}: [method] geometric = \"cvsgf\" needs exactly one of zeta, alpha_g"
                ),
            },
            GeometricKind::Baumgarte => {
                match (self.alpha, self.beta, self.omega, self.damping_ratio) {
                    (Some(a), Some(b), None, None) => Geometric::Baumgarte {
                        alpha: num("alpha", a)?,
                        beta: num("beta", b)?,
                    },
                    (None, None, Some(w), ratio) => {
                        let w = check(file, "[method] omega", w, true)?;
                        Geometric::baumgarte_from(w, num("damping_ratio", ratio.unwrap_or(1.0))?)?
                    }
                    _ => bail!(
                        "{file}: [method] geometric = \"baumgarte\" needs alpha and beta, or omega (and damping_ratio, default 1)"
                    ),
                }
            }
        };
        let energy = match e {
            EnergyKind::None => Energy::None,
            EnergyKind::Baumgarte => match self.eta {
                Some(eta) => Energy::Baumgarte {
                    eta: num("eta", eta)?,
                },
                None => bail!("{file}: [method] energy = \"baumgarte\" needs eta"),
            },
            EnergyKind::Gradient => match (self.alpha_e, self.rho_q, self.rho_v) {
                (Some(a), None, None) => Energy::Gradient(EnergyGain::Rate {
                    alpha_e: num("alpha_e", a)?,
                }),
                (None, q, Some(v)) => Energy::Gradient(EnergyGain::Fixed {
                    rho_q: num("rho_q", q.unwrap_or(0.0))?,
                    rho_v: num("rho_v", v)?,
                }),
                _ => bail!(
                    "{file}: [method] energy = \"gradient\" needs alpha_e, or rho_v (and rho_q, default 0)"
                ),
            },
        };
        let application = match self.apply {
            Apply::Rhs => Application::InRhs,
            Apply::ForwardEuler => Application::ForwardEuler,
            Apply::BackwardEuler => Application::BackwardEuler,
        };
        Ok(Control {
            geometric,
            energy,
            application,
        })
    }
}
