//! How violations are pushed back: the control laws of the paper as plain
//! data (Eqs. 13, 19, 20–27, 28–40, 48–53) and the control term `U(x, t)`
//! they add to the uncontrolled state equations.

use crate::error::{Result, non_negative, positive};
use crate::integrate::Application;
use crate::mass::MassMatrix;

/// A gain either fixed, or set at every evaluation from a target decay rate.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Gain {
    /// The gain itself (`ζ` for CVSGF).
    Fixed(f64),
    /// A target linearized decay rate (`α_g`, Eq. 40): `ζᵢ = α_g / (2|∇Φᵢ|²)`.
    Rate(f64),
}

/// Control of the holonomic constraints.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub enum Geometric {
    /// No geometric control (Eq. 8).
    #[default]
    None,
    /// Baumgarte's `Φ̈ + α Φ̇ + β Φ = 0` (Eqs. 13, 48).
    Baumgarte {
        /// Velocity gain `α`.
        alpha: f64,
        /// Position gain `β`.
        beta: f64,
    },
    /// CVSGF: `dq/dt = v − 2 Φ_qᵀ Z Φ` (Eqs. 28, 49).
    Gradient(Gain),
}

impl Gain {
    /// `ζᵢ` for a row with `|∇Φᵢ|² = g2`.
    #[inline(always)]
    fn zeta(self, g2: f64) -> f64 {
        match self {
            Gain::Fixed(z) => z,
            Gain::Rate(alpha_g) if g2 > 0.0 => alpha_g / (2.0 * g2),
            Gain::Rate(_) => 0.0,
        }
    }
}

impl Geometric {
    /// Baumgarte gains from a natural frequency `ω` and damping ratio:
    /// `α = 2 ratio ω`, `β = ω²`. Critical damping is ratio 1.
    pub fn baumgarte_from(omega: f64, damping_ratio: f64) -> Result<Self> {
        let (alpha, beta) = baumgarte_gains(omega, damping_ratio)?;
        Ok(Geometric::Baumgarte { alpha, beta })
    }
}

/// Baumgarte's `(α, β)` from a natural frequency and damping ratio.
pub(crate) fn baumgarte_gains(omega: f64, damping_ratio: f64) -> Result<(f64, f64)> {
    let omega = positive("omega", omega)?;
    let ratio = non_negative("damping_ratio", damping_ratio)?;
    Ok((2.0 * ratio * omega, omega * omega))
}

/// Gains of the gradient energy control.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum EnergyGain {
    /// `ρ_q`, `ρ_v` as given (Eq. 20).
    Fixed {
        /// Gain `ρ_q` of the position correction along `Ψ_q`.
        rho_q: f64,
        /// Gain `ρ_v` of the velocity correction along `Ψ_v`.
        rho_v: f64,
    },
    /// `ρ_q = 0` and `ρ_v = α_e / (2|Ψ_v|²)` at every evaluation (Eqs. 27, 44).
    Rate {
        /// Target linearized decay rate `α_e` of `Ψ`.
        alpha_e: f64,
    },
}

/// Control of the energy constraint `Ψ`.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub enum Energy {
    /// No energy control.
    #[default]
    None,
    /// Baumgarte-type `Ψ̇ + η Ψ = 0` through a second multiplier (Eqs. 14–19).
    Baumgarte {
        /// Decay rate `η` of `Ψ`.
        eta: f64,
    },
    /// Steepest descent on `Ψ²` (Eqs. 20, 22, 44).
    Gradient(EnergyGain),
}

/// A complete stabilization method: one row of the table in `equations.md`.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Control {
    /// Control of the holonomic constraints.
    pub geometric: Geometric,
    /// Control of the energy constraint.
    pub energy: Energy,
    /// Where the control term is integrated.
    pub application: Application,
}

/// What the control laws read of one evaluation of the dynamics.
pub(crate) trait Evaluation {
    /// The kind of mass matrix.
    type Mass: MassMatrix;
    /// The mass matrix `M`.
    fn mass(&self) -> &Self::Mass;
    fn phi(&self) -> &[f64];
    fn phi_dot(&self) -> &[f64];
    /// `∇V`, which is also `Ψ_q`.
    fn grad_potential(&self) -> &[f64];
    /// The uncontrolled acceleration `A`.
    fn acc(&self) -> &[f64];
    /// Row `r` of `Φ_q`: its entries and their coordinates.
    fn row(&self, r: usize) -> (&[f64], &[u32]);
    /// For a change `b` of the constraint right-hand side, adds the change
    /// of acceleration `−M⁻¹ Φ_qᵀ S⁻¹ b` to `out`; `b` is overwritten.
    fn add_constraint_response(&self, b: &mut [f64], out: &mut [f64]);
}

/// Below this `|Ψ_v|²` (or `vᵀMv`) the energy control has no direction to
/// act along — the system is at rest — and is skipped rather than divided by zero.
const REST: f64 = 1e-30;

impl Control {
    /// No control at all (Eq. 8).
    pub fn none() -> Self {
        Self::default()
    }

    /// Whether any control term can be non-zero.
    pub fn is_active(&self) -> bool {
        self.geometric != Geometric::None || self.energy != Energy::None
    }

    /// Checks every gain is finite and not negative.
    pub fn validate(&self) -> Result<()> {
        match self.geometric {
            Geometric::None => {}
            Geometric::Baumgarte { alpha, beta } => {
                non_negative("alpha", alpha)?;
                non_negative("beta", beta)?;
            }
            Geometric::Gradient(Gain::Fixed(z)) => _ = non_negative("zeta", z)?,
            Geometric::Gradient(Gain::Rate(a)) => _ = non_negative("alpha_g", a)?,
        }
        match self.energy {
            Energy::None => {}
            Energy::Baumgarte { eta } => _ = non_negative("eta", eta)?,
            Energy::Gradient(EnergyGain::Fixed { rho_q, rho_v }) => {
                non_negative("rho_q", rho_q)?;
                non_negative("rho_v", rho_v)?;
            }
            Energy::Gradient(EnergyGain::Rate { alpha_e }) => _ = non_negative("alpha_e", alpha_e)?,
        }
        Ok(())
    }

    /// Writes the control term `U = (U_q, U_v)` at a state whose dynamics
    /// `d` were just evaluated. `psi` and `e_dot` are `Ψ` and `Ė` there;
    /// `scratch` has length `m`.
    #[allow(clippy::too_many_arguments)]
    #[inline(always)]
    pub(crate) fn terms<E: Evaluation>(
        &self,
        d: &E,
        v: &[f64],
        psi: f64,
        e_dot: f64,
        u_q: &mut [f64],
        u_v: &mut [f64],
        scratch: &mut [f64],
    ) {
        u_q.fill(0.0);
        u_v.fill(0.0);
        let mass = d.mass();
        match self.geometric {
            Geometric::None => {}
            Geometric::Baumgarte { alpha, beta } => {
                // A_B − A for γ_B = γ − α Φ̇ − β Φ.
                for ((b, pd), p) in scratch.iter_mut().zip(d.phi_dot()).zip(d.phi()) {
                    *b = alpha * pd + beta * p;
                }
                d.add_constraint_response(scratch, u_v);
            }
            Geometric::Gradient(gain) => {
                // U_q = −2 Φ_qᵀ Z Φ
                for (r, &phi) in d.phi().iter().enumerate() {
                    let (jac, cols) = d.row(r);
                    let s = 2.0 * gain.zeta(jac.iter().map(|j| j * j).sum()) * phi;
                    for (j, &c) in jac.iter().zip(cols) {
                        u_q[c as usize] -= s * j;
                    }
                }
            }
        }
        match self.energy {
            Energy::None => {}
            Energy::Gradient(gain) => {
                let (rho_q, rho_v) = match gain {
                    EnergyGain::Fixed { rho_q, rho_v } => (rho_q, rho_v),
                    EnergyGain::Rate { alpha_e } => {
                        let g2 = mass.psi_v_norm2(v);
                        (0.0, if g2 > REST { alpha_e / (2.0 * g2) } else { 0.0 })
                    }
                };
                // U_q −= 2ρ_q Ψ Ψ_q,  U_v −= 2ρ_v Ψ Ψ_v,  Ψ_q = ∇V, Ψ_v = M v
                if rho_q != 0.0 {
                    for (u, g) in u_q.iter_mut().zip(d.grad_potential()) {
                        *u -= 2.0 * rho_q * psi * g;
                    }
                }
                mass.add_psi_v(v, -(2.0 * rho_v * psi), u_v);
            }
            Energy::Baumgarte { eta } => {
                // μ = [Ψ_v A_geo + Ψ_q v − Ė + η Ψ] / (Ψ_v M⁻¹ Ψ_vᵀ), with
                // A_geo = A + U_v so far and Ψ_v M⁻¹ Ψ_vᵀ = vᵀ M v = 2T (Eqs. 17–19).
                let two_t = 2.0 * mass.kinetic(v);
                if two_t > REST {
                    let (acc, grad) = (d.acc(), d.grad_potential());
                    let geometric = |i: usize| acc[i] + u_v[i];
                    let num = mass.psi_v_dot(v, geometric, |i| grad[i] * v[i], eta * psi - e_dot);
                    let mu = num / two_t;
                    // U_v −= μ M⁻¹ Ψ_vᵀ   (Eq. 19)
                    mass.add_inverse_psi_v(v, -mu, u_v);
                }
            }
        }
    }
}
