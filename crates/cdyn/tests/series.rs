//! The series kept for figures: exact up to `SERIES_BUCKETS` samples, then a
//! bounded number of min/max buckets that keep every spike, whatever the
//! length of the run; the record's statistics stay exact.

use cdyn::models::{PendulumParams, cartesian_pendulum};
use cdyn::record::{Recorder, SERIES_BUCKETS, Series};
use cdyn::{Control, Scheme, Settings, Simulation};

/// A wave with one spike of each sign in `phi`, an error that changes sign.
fn sample(i: u64) -> (f64, f64, f64, f64) {
    let t = i as f64 * 1e-3;
    let phi = match i {
        777_777 => 5.0,
        1_234_567 => -7.0,
        _ => 1e-3 * (t * 3.0).sin(),
    };
    (t, phi, 1e-6 * t.cos(), 1e-4 * (t - 600.0))
}

#[test]
fn a_short_series_is_kept_exactly() {
    let mut s = Series::new();
    for i in 0..SERIES_BUCKETS as u64 {
        let (t, phi, psi, e) = sample(i);
        s.push(t, phi, psi, Some(e));
    }
    s.finish();
    assert_eq!(s.t.len(), SERIES_BUCKETS);
    for (i, &t) in s.t.iter().enumerate() {
        let (t0, phi, psi, e) = sample(i as u64);
        assert_eq!((t, s.phi[i], s.psi[i], s.error[i]), (t0, phi, psi, e));
    }
}

#[test]
fn a_long_series_stays_bounded_and_keeps_its_spikes() {
    let mut s = Series::new();
    let n = 2_000_003u64;
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for i in 0..n {
        let (t, phi, psi, e) = sample(i);
        (lo, hi) = (lo.min(phi), hi.max(phi));
        s.push(t, phi, psi, Some(e));
        assert!(s.t.len() <= 2 * SERIES_BUCKETS, "{} entries after {i} samples", s.t.len());
    }
    s.finish();
    assert_eq!(s.samples(), n);
    let len = s.t.len();
    assert!((SERIES_BUCKETS..=2 * SERIES_BUCKETS + 2).contains(&len), "{len} entries");
    assert_eq!((s.phi.len(), s.psi.len(), s.error.len()), (len, len, len));
    // The whole time span, in order.
    assert_eq!(s.t[0], 0.0);
    assert_eq!(*s.t.last().unwrap(), sample(n - 1).0);
    assert!(s.t.windows(2).all(|w| w[0] <= w[1]));
    // Both spikes are there, and the extremes are exact.
    assert!(s.phi.contains(&5.0) && s.phi.contains(&-7.0));
    let fold = |v: &[f64]| v.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &x| (a.min(x), b.max(x)));
    assert_eq!(fold(&s.phi), (lo, hi));
    // The error's sign change: its smallest and largest values are kept too.
    let (elo, ehi) = fold(&s.error);
    assert_eq!((elo, ehi), (sample(0).3, sample(n - 1).3));
}

#[test]
fn the_statistics_stay_exact_when_the_series_is_decimated() {
    let ex = cartesian_pendulum(PendulumParams::default()).unwrap();
    let run = |keep: bool| {
        let settings = Settings::new(Scheme::AdamsBashforth3, 0.001, Control::none());
        let mut sim = Simulation::new(&ex.model, settings, &ex.q0, &ex.v0).unwrap();
        let Ok(record) = Recorder::example(&ex).keep_series(keep).run(&mut sim, 20.0, 1);
        record
    };
    let (with, without) = (run(true), run(false));
    let series = with.series.as_ref().unwrap();
    assert_eq!(series.samples(), 20_001);
    assert!(series.t.len() <= 2 * SERIES_BUCKETS, "{}", series.t.len());
    // Every statistic as without a series; the series' extreme is the record's.
    assert_eq!(
        (with.max_abs_phi, with.max_abs_psi, with.max_abs_error),
        (without.max_abs_phi, without.max_abs_psi, without.max_abs_error)
    );
    let max_phi = series.phi.iter().fold(0f64, |m, p| m.max(p.abs()));
    assert_eq!(max_phi, with.max_abs_phi);
    let max_err = series.error.iter().fold(0f64, |m, p| m.max(p.abs()));
    assert_eq!(Some(max_err), with.max_abs_error);
}
