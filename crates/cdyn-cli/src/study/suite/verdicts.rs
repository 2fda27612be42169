//! The checks of one group, from its runs' numbers.

use super::*;

/// The checks of [`CHECKS`] on one group: a–d and f judge `robust`; a
/// group without one is of a scheme that steps the model (RATTLE,
/// generalized-α), where g judges its uncontrolled run instead. A run
/// judged that stopped fails every check that applies to it.
pub(super) fn verdicts(
    runs: &[Run],
    none: usize,
    robust: Option<usize>,
    projection: usize,
    free_motion: bool,
) -> Vec<Verdict> {
    let (none, projection) = (&runs[none], &runs[projection]);
    let verdict = |applies: bool, ok: bool, pass: bool, numbers: String| Verdict {
        applies,
        pass: !applies || ok && pass,
        numbers,
    };
    let held = verdict(
        robust.is_none(),
        none.error.is_none(),
        none.max_abs_phi <= HELD_PHI,
        format!("max|phi| none {:.3e}", none.max_abs_phi),
    );
    let Some(robust) = robust.map(|r| &runs[r]) else {
        let not_robust = || verdict(false, true, true, String::new());
        return vec![not_robust(), not_robust(), not_robust(), not_robust(), momenta(runs, none), not_robust(), held];
    };
    let ok = robust.error.is_none();
    let (r, n, p) = (robust.max_error, none.max_error, projection.max_error);
    let phi = none.max_abs_phi > 1e-8;
    // Ψ is not robust's to hold where its energy term was left out.
    let psi = free_motion && !robust.energy_left_out && none.max_abs_psi > 1e-8;
    vec![
        verdict(true, ok, r <= 2.0 * p, format!("robust {r:.3e}, projection {p:.3e}")),
        verdict(p <= n, ok, r <= n, format!("robust {r:.3e}, none {n:.3e}, projection {p:.3e}")),
        verdict(n > 1e-4, ok, r <= n / 10.0, format!("robust {r:.3e}, none {n:.3e}")),
        verdict(
            phi || psi,
            ok,
            (!phi || robust.max_abs_phi <= none.max_abs_phi / 10.0)
                && (!psi || robust.max_abs_psi <= none.max_abs_psi / 10.0),
            format!(
                "max|phi| robust {:.3e}, none {:.3e}; max|psi| robust {:.3e}, none {:.3e}",
                robust.max_abs_phi, none.max_abs_phi, robust.max_abs_psi, none.max_abs_psi
            ),
        ),
        momenta(runs, none),
        match (robust.momentum_drift, none.momentum_drift) {
            (Some(r), Some(n)) => verdict(
                true,
                ok,
                r <= n.max(cdyn::dynamics::momentum::ROUND_OFF),
                format!("robust {r:.3e}, none {n:.3e} of the scale"),
            ),
            _ => verdict(false, true, true, String::new()),
        },
        held,
    ]
}

/// Check e: every run that went through keeps each linear momentum the model keeps.
fn momenta(runs: &[Run], none: &Run) -> Verdict {
    let worst = runs.iter().filter(|r| r.error.is_none()).filter_map(|r| r.linear_momentum_drift.map(|d| (d, r)));
    let worst = worst.max_by(|a, b| a.0.total_cmp(&b.0));
    let numbers = worst.map_or(String::new(), |(d, r)| format!("largest {d:.3e} of its scale ({})", r.method));
    let applies = none.linear_momentum_drift.is_some();
    let pass = worst.is_none_or(|(d, _)| d <= cdyn::dynamics::momentum::ROUND_OFF);
    Verdict { applies, pass: !applies || pass, numbers }
}
