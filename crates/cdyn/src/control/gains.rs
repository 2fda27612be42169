//! Automatic gains: rates chosen from the scheme, the step size, how the
//! control is applied and how strongly the constraints are coupled.
//!
//! A feedback term with rate `α` adds, to the linearization of the
//! violation it controls, an eigenvalue `−α μ` for every mode `μ` of its
//! operator. The step is stable when `h α μ` lies inside the stability
//! interval of whatever integrates the term: the scheme's real interval
//! when the term is in the right-hand side (AB-3: 6/11, RK-4: 2.785), and
//! `(0, 2)` for a separate Euler step, which removes the mode in one step at
//! `h α μ = 1`. The rate chosen is `target / (h μ_max)` with the target
//! half the interval in the right-hand side and 1 for an Euler step.
//!
//! * The coupled forms ([`Geometric::Newton`], [`Velocity::Gradient`],
//!   [`Energy::Projected`]) have `μ = 1` for every mode: their gain matrix
//!   is `(Φ_q M⁻¹ Φ_qᵀ)⁻¹` (or the scalar `1/N`), so their rate is exact.
//! * The paper's CVSGF with `ζᵢ = α_g / (2|∇Φᵢ|²)` has the operator
//!   `Φ_q Φ_qᵀ D⁻¹`, `D = diag |∇Φᵢ|²`, whose modes lie in `(0, μ_max]` with
//!   `1 ≤ μ_max ≤ m`: coupled rows (the four-bar's loop, a chain) push the
//!   fastest mode above `α_g`. `μ_max` is estimated by power iteration on
//!   `D^{-1/2} Φ_q Φ_qᵀ D^{-1/2}` at the initial state.
//! * The automatic energy term (`Energy::Projected` with `alpha_e =
//!   auto`, `robust`'s) holds `T + V` to `E₀` plus the work of the
//!   non-conservative forces as the scheme integrated it. Where those
//!   forces damp a motion fast against the step (`h λ_d` above
//!   [`STIFF_DISSIPATION_H`], `λ_d` the largest rate of `P M⁻¹ C`, `C =
//!   −∂Q/∂v`, `P` the projection onto the motions the constraints allow),
//!   that integral carries more error than the state: the stiff flyball
//!   governor's dampers (`h λ_d` = 0.2–0.8 at h = 2.5e-5 … 1e-4) leave
//!   1e-7 J in it at h = 1e-4 against 4e-9 J in the state's energy, and
//!   the term, moving the state to match, made robust 1.3–40× worse than
//!   no control. There the automatic energy term is left out (an explicit
//!   rate is kept), and so is the projection of `Ψ` (the `projection`
//!   method was 37× worse than none on the flyball governor, and 2× on
//!   the damped pendulum at AB-3 with `h λ_d` = 0.018).
//! * Two more figures say whether the step is stiff for an explicit
//!   scheme, for the hint a run gets: `h λ_d` against the scheme's real
//!   stability interval, and `h ω`, `ω` the fastest oscillation of the
//!   springs, potentials and constraint forces (`ω²` the largest
//!   eigenvalue of `P M⁻¹ K`, `K` the stiffness of Newton's matrix in
//!   generalized-α), against its interval on the imaginary axis
//!   ([`imaginary_stability_interval`]).

use crate::control::evaluation::Evaluation;
use crate::control::{Control, Energy, EnergyGain, Gain, Geometric, Rate, Velocity};
use crate::integrate::{Application, Formula, Scheme};
use crate::linalg::mass::MassMatrix;

/// `h λ_d` above which the automatic energy term is left out: the
/// dissipation resolved to 1 % per step. Measured on the damped pendulum
/// (`tests/stabilization.rs`): the term still helps at 0.006 and makes
/// AB-3 worse than no control from 0.018 on; the flyball governor sits at
/// 0.2–0.8.
pub const STIFF_DISSIPATION_H: f64 = 0.01;

/// What the automatic gains are chosen from, at the initial state.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
#[non_exhaustive]
pub struct Operators {
    /// `μ_max` of the paper's CVSGF operator (`coupling` in this module).
    pub coupling: f64,
    /// The largest `|∇Φᵢ|²`, for a fixed `ζ`.
    pub max_row_norm2: f64,
    /// `λ_d`, the fastest damping of the non-conservative forces
    /// (`dissipation_rate` in this module).
    pub dissipation: f64,
    /// `ω`, the fastest oscillation of the stiffness (`oscillation_frequency`
    /// in this module; 0 where it is not estimated).
    pub frequency: f64,
    /// The force element (in the order the model's builder took them) that
    /// dissipates most in the fastest damped motion, where known.
    pub dissipating: Option<usize>,
}

/// What the automatic gains were chosen from, and the resulting rate × h.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
#[non_exhaustive]
pub struct Tuning {
    /// Largest mode `μ_max` of the paper's CVSGF operator at the initial
    /// state (1 for uncoupled constraints; 0 without constraints).
    pub coupling: f64,
    /// The largest linearized rate × h of any active control term
    /// (including the coupling); `0` without control.
    pub rate_h: f64,
    /// The `h α μ` the automatic gains aim at.
    pub target: f64,
    /// `h λ_d`: the step against the fastest damping of the
    /// non-conservative forces (0 without them).
    pub dissipation_h: f64,
    /// `h ω`: the step against the fastest oscillation of the springs,
    /// potentials and constraint forces (0 where not estimated).
    pub oscillation_h: f64,
    /// Whether the automatic energy term, or the projection of `Ψ`, was
    /// left out because that damping is stiff (`dissipation_h >
    /// STIFF_DISSIPATION_H`).
    pub energy_left_out: bool,
    /// The force element behind `λ_d` ([`Operators::dissipating`]).
    pub dissipating: Option<usize>,
}

/// The negative real stability interval `[−x, 0]` of a scheme: the largest
/// `x = h λ` for which `ẏ = −λ y` does not grow.
pub fn real_stability_interval(scheme: Scheme) -> f64 {
    match scheme.info().formula {
        // Forward Euler: |1 − x| ≤ 1.
        Formula::Multistep(w) if w.len() == 1 => 2.0,
        // AB-2: x ≤ 1; AB-3: x ≤ 6/11.
        Formula::Multistep(w) if w.len() == 2 => 1.0,
        Formula::Multistep(_) => 6.0 / 11.0,
        // RK-4: the real root x > 0 of 1 − x + x²/2 − x³/6 + x⁴/24 = 1.
        Formula::RungeKutta { .. } => 2.785_293_563_405_282,
        // ABM-4 PECE: where a complex pair of roots of its characteristic
        // polynomial leaves the unit circle (not at ζ = −1; the test finds it).
        Formula::PredictorCorrector { .. } => 1.284_816_263_107_07,
        // RATTLE integrates no control term; velocity Verlet is stable for
        // an oscillation ẍ = −ω²x while h ω < 2.
        Formula::Rattle => 2.0,
        // Generalized-α is A-stable: no limit on h λ.
        Formula::GeneralizedAlpha => f64::INFINITY,
    }
}

/// The stability interval `[0, y]` of a scheme on the imaginary axis: the
/// largest `y = h ω` up to which an undamped oscillation `ẏ = iω y` does
/// not grow (0 where it grows at any step).
pub fn imaginary_stability_interval(scheme: Scheme) -> f64 {
    match scheme.info().formula {
        // Forward Euler and AB-2: |ζ| > 1 for every h ω > 0.
        Formula::Multistep(w) if w.len() <= 2 => 0.0,
        // AB-3: where its root leaves the unit circle (the test finds it).
        Formula::Multistep(_) => 0.723_627_226_987_110_9,
        // RK-4: |R(i y)| = 1 at y = 2√2.
        Formula::RungeKutta { .. } => 2.0 * std::f64::consts::SQRT_2,
        // ABM-4 PECE: where a spurious root leaves the unit circle. Below
        // it the principal root grows too, as 0.16 (h ω)⁶ a step (1e-5 at
        // h ω = 0.2, 0.7 % at 0.8): slowly, like the scheme's error.
        Formula::PredictorCorrector { .. } => 0.926_201_614_102_906,
        // Velocity Verlet: h ω < 2.
        Formula::Rattle => 2.0,
        Formula::GeneralizedAlpha => f64::INFINITY,
    }
}

/// The `h α μ_max` automatic gains aim at.
pub fn target(scheme: Scheme, application: Application) -> f64 {
    match application {
        Application::InRhs => 0.5 * real_stability_interval(scheme),
        Application::ForwardEuler | Application::BackwardEuler | Application::PostStep => 1.0,
    }
}

/// A start for power iteration with no symmetry, so that it is not
/// orthogonal to the top mode.
fn power_iteration_start(len: usize) -> Vec<f64> {
    (0..len).map(|i| 1.0 + 0.5 * ((i as f64) * 0.618_033_988_75).fract()).collect()
}

/// `μ_max` of `D^{-1/2} Φ_q Φ_qᵀ D^{-1/2}` by power iteration (the
/// operator is symmetric positive semi-definite, so the Rayleigh quotient
/// converges from below). Allocates: called once per simulation.
pub(crate) fn coupling<E: Evaluation>(d: &E, n: usize) -> f64 {
    let m = d.phi().len();
    if m == 0 {
        return 0.0;
    }
    let inv_sqrt: Vec<f64> = (0..m)
        .map(|r| {
            let g2: f64 = d.row(r).0.iter().map(|j| j * j).sum();
            if g2 > 0.0 { 1.0 / g2.sqrt() } else { 0.0 }
        })
        .collect();
    let mut x = power_iteration_start(m);
    let mut y = vec![0.0; n];
    let mut mu = 0.0;
    for _ in 0..60 {
        let norm = x.iter().map(|a| a * a).sum::<f64>().sqrt();
        if norm == 0.0 || !norm.is_finite() {
            return 1.0;
        }
        x.iter_mut().for_each(|a| *a /= norm);
        // y = Φ_qᵀ D^{-1/2} x, then x' = D^{-1/2} Φ_q y; μ ≈ x·x' = |y|².
        y.fill(0.0);
        for r in 0..m {
            let (jac, cols) = d.row(r);
            for (j, &c) in jac.iter().zip(cols) {
                y[c as usize] += j * inv_sqrt[r] * x[r];
            }
        }
        let next = y.iter().map(|a| a * a).sum::<f64>();
        let converged = (next - mu).abs() <= 1e-6 * next;
        mu = next;
        for r in 0..m {
            let (jac, cols) = d.row(r);
            x[r] = inv_sqrt[r] * jac.iter().zip(cols).map(|(j, &c)| j * y[c as usize]).sum::<f64>();
        }
        if converged {
            break;
        }
    }
    mu.max(1.0)
}

/// `λ_d`: the largest rate at which the non-conservative forces damp a
/// motion the constraints allow — the spectral radius of `P M⁻¹ C`, with
/// `C w = −∂Q/∂v · w` from `damping(w, out)` and `P` the `M`-orthogonal
/// projection onto `Φ_q w = 0` — by power iteration. 0 without
/// velocity-dependent forces. Allocates: called once per simulation.
pub(crate) fn dissipation_rate<E: Evaluation>(d: &E, n: usize, damping: impl FnMut(&[f64], &mut [f64])) -> f64 {
    constrained_mode(d, n, damping).0
}

/// [`dissipation_rate`] and its motion `w` (unit in the `M`-norm).
pub(crate) fn dissipation_mode<E: Evaluation>(
    d: &E,
    n: usize,
    damping: impl FnMut(&[f64], &mut [f64]),
) -> (f64, Vec<f64>) {
    constrained_mode(d, n, damping)
}

/// `ω`: the fastest oscillation of the motions the constraints allow —
/// the square root of the spectral radius of `P M⁻¹ K`, `K w` from
/// `stiffness(w, out)` (the potentials' Hessians, `−∂Q/∂q`, and the
/// constraints' curvatures weighted by the multipliers) — by power
/// iteration. Allocates: called once per simulation.
pub(crate) fn oscillation_frequency<E: Evaluation>(d: &E, n: usize, stiffness: impl FnMut(&[f64], &mut [f64])) -> f64 {
    constrained_mode(d, n, stiffness).0.sqrt()
}

/// The spectral radius of `P M⁻¹ A`, `A w` from `apply(w, out)`, by power
/// iteration in the `M`-norm, and the last iterate (its mode).
fn constrained_mode<E: Evaluation>(d: &E, n: usize, mut apply: impl FnMut(&[f64], &mut [f64])) -> (f64, Vec<f64>) {
    let m = d.phi().len();
    let mass = d.mass();
    let (mut force, mut b, mut mw) = (vec![0.0; n], vec![0.0; m], vec![0.0; n]);
    // w ← P M⁻¹ f: the acceleration of f alone, its constraint part removed.
    let mut constrained = |f: &[f64], w: &mut [f64]| {
        mass.solve(f, w);
        d.jac_mul(w, &mut b);
        d.add_constraint_response(&mut b, w);
    };
    let start = power_iteration_start(n);
    let mut w = vec![0.0; n];
    constrained(&start, &mut w);
    let mut rate = 0.0;
    for _ in 0..60 {
        mass.mul(&w, &mut mw);
        let norm = w.iter().zip(&mw).map(|(a, b)| a * b).sum::<f64>().sqrt();
        if norm == 0.0 || !norm.is_finite() {
            return (rate, w);
        }
        w.iter_mut().for_each(|a| *a /= norm);
        apply(&w, &mut force);
        constrained(&force, &mut w);
        mass.mul(&w, &mut mw);
        let next = w.iter().zip(&mw).map(|(a, b)| a * b).sum::<f64>().sqrt();
        let converged = (next - rate).abs() <= 1e-6 * next;
        rate = next;
        if converged {
            break;
        }
    }
    (rate, w)
}

/// `control` with every automatic gain replaced by the chosen rate, and
/// what they were chosen from.
pub fn resolve(control: Control, scheme: Scheme, h: f64, operators: Operators) -> (Control, Tuning) {
    let Operators { coupling, max_row_norm2, dissipation, frequency, dissipating } = operators;
    let target = target(scheme, control.application);
    let mut c = control;
    let exact = |r: Rate| {
        Rate::Given(match r {
            Rate::Given(a) => a,
            Rate::Auto => target / h,
        })
    };
    let mu = coupling.max(1.0);
    let mut rate: f64 = 0.0;
    c.geometric = match control.geometric {
        Geometric::Gradient(gain) => {
            let gain = match gain {
                Gain::Auto => Gain::Rate(target / (h * mu)),
                g => g,
            };
            rate = rate.max(match gain {
                Gain::Rate(a) => a * mu,
                Gain::Fixed(z) => 2.0 * z * max_row_norm2 * mu,
                Gain::Auto => 0.0,
            });
            Geometric::Gradient(gain)
        }
        Geometric::Newton(r) => {
            let r = exact(r);
            rate = rate.max(r.value());
            Geometric::Newton(r)
        }
        Geometric::Baumgarte { alpha, beta } => {
            // The faster root of s² + α s + β.
            let disc = alpha * alpha - 4.0 * beta;
            rate = rate.max(if disc >= 0.0 { 0.5 * (alpha + disc.sqrt()) } else { beta.sqrt() });
            control.geometric
        }
        Geometric::None => Geometric::None,
    };
    if let Velocity::Gradient(r) = control.velocity {
        let r = exact(r);
        rate = rate.max(r.value());
        c.velocity = Velocity::Gradient(r);
    }
    let dissipation_h = dissipation * h;
    let stiff = dissipation_h > STIFF_DISSIPATION_H;
    let term_left_out = stiff && matches!(control.energy, Energy::Projected { alpha_e: Rate::Auto, .. });
    let projection_left_out = stiff && control.projection.is_some_and(|p| p.energy);
    if let Some(p) = &mut c.projection {
        p.energy &= !projection_left_out;
    }
    let energy_left_out = term_left_out || projection_left_out;
    c.energy = match control.energy {
        _ if term_left_out => Energy::None,
        Energy::Projected { alpha_e, position_weight } => {
            let alpha_e = exact(alpha_e);
            rate = rate.max(alpha_e.value());
            Energy::Projected { alpha_e, position_weight }
        }
        Energy::Gradient(EnergyGain::Rate { alpha_e }) => {
            rate = rate.max(alpha_e);
            control.energy
        }
        Energy::Baumgarte { eta } => {
            rate = rate.max(eta);
            control.energy
        }
        e => e,
    };
    let oscillation_h = frequency * h;
    (c, Tuning { coupling, rate_h: rate * h, target, dissipation_h, oscillation_h, energy_left_out, dissipating })
}

#[cfg(test)]
mod tests {
    use super::*;

    use nalgebra::Complex;

    /// The roots of `ζᵏ = Σⱼ aⱼ ζᵏ⁻¹⁻ʲ`, as the eigenvalues of its companion matrix.
    fn roots(a: &[Complex<f64>]) -> Vec<Complex<f64>> {
        let k = a.len();
        let mut m = nalgebra::DMatrix::<Complex<f64>>::zeros(k, k);
        for j in 0..k {
            m[(0, j)] = a[j];
        }
        for i in 1..k {
            m[(i, i - 1)] = Complex::new(1.0, 0.0);
        }
        m.schur().eigenvalues().expect("a complex Schur form is triangular").iter().copied().collect()
    }

    /// A PECE scheme on `ẏ = λ y` at `z = h λ`: `y_{k+1} = y_k + z (c_0 y* +
    /// Σ_j c_{j+1} y_{k−j})` with the prediction `y* = y_k + z Σ_j p_j
    /// y_{k−j}`, as `y_{k+1} = Σ_j a_j y_{k−j}`.
    fn pece(p: &[f64], c: &[f64], z: Complex<f64>) -> Vec<Complex<f64>> {
        let mut a = vec![Complex::new(0.0, 0.0); p.len()];
        a[0] = 1.0 + z * c[0];
        for j in 0..p.len() {
            a[j] += z * c[0] * z * p[j];
        }
        for (j, cj) in c[1..].iter().enumerate() {
            a[j] += z * *cj;
        }
        a
    }

    /// Adams–Bashforth with weights `w` at `z`: `y_{k+1} = y_k + z Σ_j w_j y_{k−j}`.
    fn multistep(w: &[f64], z: Complex<f64>) -> Vec<Complex<f64>> {
        let mut a: Vec<Complex<f64>> = w.iter().map(|w| z * *w).collect();
        a[0] += 1.0;
        a
    }

    fn radius(a: &[Complex<f64>]) -> f64 {
        roots(a).iter().map(|r| r.norm()).fold(0.0, f64::max)
    }

    /// The largest root modulus of a PECE scheme at a real `z`.
    fn pece_spectral_radius(p: &[f64], c: &[f64], z: f64) -> f64 {
        radius(&pece(p, c, Complex::new(z, 0.0)))
    }

    #[test]
    fn the_real_stability_intervals_end_where_the_amplification_reaches_the_unit_circle() {
        for scheme in Scheme::GENERAL {
            let x = real_stability_interval(scheme);
            let at_boundary = match scheme.info().formula {
                // R(−x) = 1 for the Runge–Kutta amplification factor (positive on the real axis).
                Formula::RungeKutta { .. } => 1.0 - x + x * x / 2.0 - x.powi(3) / 6.0 + x.powi(4) / 24.0 - 1.0,
                // ζᵏ − ζᵏ⁻¹ + x Σⱼ wⱼ ζᵏ⁻¹⁻ʲ at ζ = −1.
                Formula::Multistep(w) => {
                    let k = w.len() as i32;
                    let z = -1.0_f64;
                    z.powi(k) - z.powi(k - 1)
                        + x * w.iter().enumerate().map(|(j, w)| w * z.powi(k - 1 - j as i32)).sum::<f64>()
                }
                // Its roots leave the unit circle at ±i rather than −1: the largest
                // root's modulus is 1 there, below just inside and above just outside.
                Formula::PredictorCorrector { predictor, corrector } => {
                    let radius = |x: f64| pece_spectral_radius(predictor, corrector, -x);
                    assert!(radius(x * (1.0 - 1e-6)) <= 1.0 + 1e-12 && radius(x * (1.0 + 1e-6)) > 1.0, "{scheme:?}");
                    assert!((0..1000).all(|k| radius(x * k as f64 / 1000.0) <= 1.0 + 1e-12), "{scheme:?}");
                    radius(x) - 1.0
                }
                Formula::Rattle | Formula::GeneralizedAlpha => unreachable!("not among the general schemes"),
            };
            assert!(at_boundary.abs() < 1e-12, "{scheme:?}: {at_boundary}");
        }
    }

    #[test]
    fn the_imaginary_stability_intervals_end_where_an_oscillation_starts_to_grow() {
        let at = |y: f64| Complex::new(0.0, y);
        for scheme in Scheme::GENERAL {
            let y = imaginary_stability_interval(scheme);
            let (inside, outside) = (y * (1.0 - 1e-6), y * (1.0 + 1e-6));
            match scheme.info().formula {
                Formula::RungeKutta { .. } => {
                    let r = |y: f64| {
                        let z = at(y);
                        (1.0 + z + z * z / 2.0 + z * z * z / 6.0 + z * z * z * z / 24.0).norm()
                    };
                    assert!((r(y) - 1.0).abs() < 1e-12 && r(outside) > 1.0 && r(inside) < 1.0, "{scheme:?}");
                }
                Formula::Multistep(w) if y == 0.0 => {
                    // Euler and AB-2 grow at any step.
                    assert!(radius(&multistep(w, at(0.01))) > 1.0 + 1e-12, "{scheme:?}");
                }
                Formula::Multistep(w) => {
                    let r = |y: f64| radius(&multistep(w, at(y)));
                    assert!(r(inside) <= 1.0 + 1e-12 && r(outside) > 1.0, "{scheme:?}");
                    assert!((1..1000).all(|k| r(y * k as f64 / 1000.0) <= 1.0 + 1e-12), "{scheme:?}");
                }
                Formula::PredictorCorrector { predictor, corrector } => {
                    // The spurious roots (all but the one nearest e^{iy}) reach the circle at y.
                    let spurious = |y: f64| {
                        let mut r = roots(&pece(predictor, corrector, at(y)));
                        let principal = (0..r.len())
                            .min_by(|&a, &b| (r[a] - at(y).exp()).norm().total_cmp(&(r[b] - at(y).exp()).norm()))
                            .unwrap();
                        r.remove(principal);
                        r.iter().map(|r| r.norm()).fold(0.0, f64::max)
                    };
                    assert!(spurious(inside) < 1.0 && spurious(outside) > 1.0, "{scheme:?}");
                    // The principal root grows as about 0.16 y⁶ below it.
                    let growth = radius(&pece(predictor, corrector, at(0.2))) - 1.0;
                    assert!((growth / (0.16 * 0.2_f64.powi(6)) - 1.0).abs() < 0.1, "{scheme:?}: {growth:e}");
                }
                Formula::Rattle | Formula::GeneralizedAlpha => unreachable!("not among the general schemes"),
            }
        }
    }
}
