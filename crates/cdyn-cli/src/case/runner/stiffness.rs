//! A step against the scheme's stability limit: the fastest damping
//! (`h λ_d`) and oscillation (`h ω`) the library estimated at the initial
//! state ([`Tuning`]), the one nearer its scheme's limit, the note a run
//! gets when it comes within half of it, and the refusal when it passes it.

use cdyn::Scheme;
use cdyn::control::gains::{Tuning, imaginary_stability_interval, real_stability_interval};

/// Damping or springs this close to an explicit scheme's stability limit
/// (as a fraction of its interval) are named with the way out, and a step
/// this fraction of the limit is the one proposed.
pub const NEAR_STABILITY_LIMIT: f64 = 0.5;

/// The stiffest motion of a case against its scheme's limit.
pub struct Stiffness {
    /// "the damping", "the springs".
    pub what: &'static str,
    /// "is", "are".
    pub verb: &'static str,
    /// `h λ_d` or `h ω`.
    pub figure: &'static str,
    /// Its value.
    pub value: f64,
    /// The scheme's stability limit for it.
    pub limit: f64,
    /// What that limit is called.
    pub kind: &'static str,
    /// A step that works: [`NEAR_STABILITY_LIMIT`] of the limit.
    pub h_max: f64,
}

/// For an explicit scheme (or RATTLE) at step `h`, the damping or the
/// springs nearer the scheme's stability limit, where within
/// [`NEAR_STABILITY_LIMIT`] of it. Euler and AB-2 grow on any oscillation,
/// and an infinite `h λ` (a step of 1e308) has no step to name: neither counts.
pub fn stiffest(scheme: Scheme, h: f64, t: &Tuning) -> Option<Stiffness> {
    if scheme == Scheme::GeneralizedAlpha {
        return None;
    }
    let candidates = [
        (("the damping", "is"), "h λ_d", t.dissipation_h, real_stability_interval(scheme), "stability limit"),
        (
            ("the springs", "are"),
            "h ω",
            t.oscillation_h,
            imaginary_stability_interval(scheme),
            "stability limit on oscillations",
        ),
    ];
    let ((what, verb), figure, value, limit, kind) = candidates
        .into_iter()
        .filter(|&(_, _, x, limit, _)| limit > 0.0 && x > NEAR_STABILITY_LIMIT * limit && x.is_finite())
        .max_by(|a, b| (a.2 / a.3).total_cmp(&(b.2 / b.3)))?;
    Some(Stiffness { what, verb, figure, value, limit, kind, h_max: NEAR_STABILITY_LIMIT * limit * h / value })
}

/// The refusal of a case whose step is past its scheme's stability limit:
/// the element behind the damping where the library names one (its entry
/// in `forces`), the figure, the limit and what works instead. `None` when
/// the step is within the limit.
pub fn refusal(scheme: Scheme, h: f64, t: &Tuning, forces: &[String]) -> Option<String> {
    let s = stiffest(scheme, h, t).filter(|s| s.value > s.limit)?;
    let element = match (s.figure, t.dissipating.and_then(|k| forces.get(k))) {
        ("h λ_d", Some(entry)) => format!(" of {entry}"),
        _ => String::new(),
    };
    let name = scheme.info().name;
    Some(format!(
        "{}{element} {} too stiff for the step: {} = {:.3} is above {name}'s {} {:.3}, so the run would diverge or be wrong; set [integrator] scheme = \"generalized_alpha\" (no such limit), or h ≤ {:.2e}",
        s.what, s.verb, s.figure, s.value, s.kind, s.limit, s.h_max
    ))
}
