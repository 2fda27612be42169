//! The checks of one group, from its runs' numbers.

use super::*;

/// The checks of [`CHECKS`] on one group. A robust run that stopped fails
/// every check that applies.
pub(super) fn verdicts(runs: &[Run], none: usize, robust: usize, projection: usize, free_motion: bool) -> Vec<Verdict> {
    let (none, robust, projection) = (&runs[none], &runs[robust], &runs[projection]);
    let ok = robust.error.is_none();
    let (r, n, p) = (robust.max_error, none.max_error, projection.max_error);
    let verdict =
        |applies: bool, pass: bool, numbers: String| Verdict { applies, pass: !applies || ok && pass, numbers };
    let phi = none.max_abs_phi > 1e-8;
    // Ψ is not robust's to hold where its energy term was left out.
    let psi = free_motion && !robust.energy_left_out && none.max_abs_psi > 1e-8;
    vec![
        verdict(true, r <= 2.0 * p, format!("robust {r:.3e}, projection {p:.3e}")),
        verdict(p <= n, r <= n, format!("robust {r:.3e}, none {n:.3e}, projection {p:.3e}")),
        verdict(n > 1e-4, r <= n / 10.0, format!("robust {r:.3e}, none {n:.3e}")),
        verdict(
            phi || psi,
            (!phi || robust.max_abs_phi <= none.max_abs_phi / 10.0)
                && (!psi || robust.max_abs_psi <= none.max_abs_psi / 10.0),
            format!(
                "max|phi| robust {:.3e}, none {:.3e}; max|psi| robust {:.3e}, none {:.3e}",
                robust.max_abs_phi, none.max_abs_phi, robust.max_abs_psi, none.max_abs_psi
            ),
        ),
        {
            let worst =
                runs.iter().filter(|r| r.error.is_none()).filter_map(|r| r.linear_momentum_drift.map(|d| (d, r)));
            let worst = worst.max_by(|a, b| a.0.total_cmp(&b.0));
            let numbers = worst.map_or(String::new(), |(d, r)| format!("largest {d:.3e} of its scale ({})", r.method));
            let applies = none.linear_momentum_drift.is_some();
            verdict(applies, worst.is_none_or(|(d, _)| d <= cdyn::dynamics::momentum::ROUND_OFF), numbers)
        },
        match (robust.momentum_drift, none.momentum_drift) {
            (Some(r), Some(n)) => verdict(
                true,
                r <= n.max(cdyn::dynamics::momentum::ROUND_OFF),
                format!("robust {r:.3e}, none {n:.3e} of the scale"),
            ),
            _ => verdict(false, true, String::new()),
        },
    ]
}
