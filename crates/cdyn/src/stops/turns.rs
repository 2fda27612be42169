//! Following the turns of periodic gaps ([`Unilateral::period`]): a
//! multi-turn joint's angle read from the state alone is its angle only up
//! to whole turns, so a run takes each new reading of such a gap as the
//! one nearest the stop's last. One step moves a joint far less than half
//! a turn, so the gaps follow the joint as it turns, and a stop at 6.28 rad
//! is met at 6.28, not at 6.28 − 2π.

use super::unilateral::Unilateral;
use crate::error::Result;

/// Reads the stops' gaps and rates at `(q, v)` into `gaps`, each periodic
/// gap the one nearest the stop's gap in `last`.
pub(super) fn read_following<U: Unilateral + ?Sized>(
    system: &U,
    q: &[f64],
    v: &[f64],
    last: &[[f64; 2]],
    gaps: &mut [[f64; 2]],
) -> Result<()> {
    system.gaps(q, v, gaps)?;
    for (k, ([g, _], [before, _])) in gaps.iter_mut().zip(last).enumerate() {
        if let Some(period) = system.period(k) {
            *g = nearest(*g, *before, period);
        }
    }
    Ok(())
}

/// `g + P k` nearest `reference`, for the whole `k`.
pub(super) fn nearest(g: f64, reference: f64, period: f64) -> f64 {
    g + period * ((reference - g) / period).round()
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::{PI, TAU};

    #[test]
    fn a_gap_is_moved_by_whole_periods_only_and_to_the_nearest() {
        assert_eq!(nearest(0.5, 0.4, TAU), 0.5);
        assert_eq!(nearest(0.5, 0.4 + 3.0 * TAU, TAU), 0.5 + 3.0 * TAU);
        assert_eq!(nearest(2.0, -1.0, 4.0), -2.0);
        assert_eq!(nearest(-3.0, 3.0, 2.0 * PI), -3.0 + TAU);
    }

    #[test]
    fn the_upper_gap_of_a_joint_turning_through_pi_stays_continuous() {
        // A joint of range −2.62 … 6.0 turning up from 2.5 to 5.9 rad, 0.01
        // rad a step: read in (−π, π] its angle jumps from π to −π at 3.14,
        // and its upper gap 6.0 − θ would jump from 2.86 to 9.14. Followed,
        // it is 6.0 − θ all the way, to round-off of the reading.
        let upper = 6.0;
        let mut last = upper - 2.5;
        for step in 0..=340 {
            let theta = 2.5 + 0.01 * f64::from(step);
            let read = (theta + PI).rem_euclid(TAU) - PI;
            let g = nearest(upper - read, last, TAU);
            assert!((g - (upper - theta)).abs() < 1e-12, "θ = {theta}: gap {g}");
            last = g;
        }
        assert!((last - 0.1).abs() < 1e-12, "{last}");
    }
}
