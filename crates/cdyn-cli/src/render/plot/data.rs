//! The points of a figure as drawn, computed once for both files: runs of
//! usable points, the log axis's shift, and which line another covers.

use super::{Figure, HUGE, Scale};

/// What gets drawn, computed once for both outputs. Each series is split into runs of usable
/// points, so a skipped point leaves a gap instead of a line bridging it. For `LogAbs`, y is
/// stored as |y| / 10^shift: plotters' log axis drops ticks below f64::EPSILON, so values
/// are shifted to start at 1 and the tick labels shift them back.
pub(super) struct Data {
    pub(super) runs: Vec<Vec<Vec<(f64, f64)>>>,
    /// For each series, a later series drawn over it along (almost) all its length: the
    /// legend says so, since the lower one cannot be seen but for its markers.
    pub(super) under: Vec<Option<usize>>,
    pub(super) x: (f64, f64),
    pub(super) y: (f64, f64),
    pub(super) shift: i32,
}

pub(super) fn prepare(fig: &Figure) -> Data {
    let log = matches!(fig.scale, Scale::LogAbs);
    let usable = |x: f64, y: f64| x.abs() < HUGE && y.abs() < HUGE && !(log && y == 0.0);
    let mut runs: Vec<Vec<Vec<(f64, f64)>>> = fig
        .series
        .iter()
        .map(|s| {
            let (mut out, mut cur) = (Vec::new(), Vec::new());
            for &(x, y) in &s.points {
                if usable(x, y) {
                    cur.push((x, if log { y.abs().log10() } else { y }));
                } else if !cur.is_empty() {
                    out.push(std::mem::take(&mut cur));
                }
            }
            out.extend((!cur.is_empty()).then_some(cur));
            out
        })
        .collect();
    let extent = |f: fn(&(f64, f64)) -> f64| {
        runs.iter()
            .flatten()
            .flatten()
            .map(f)
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| (a.min(v), b.max(v)))
    };
    let (x, (ylo, yhi)) = (pad(extent(|p| p.0), 0.0), extent(|p| p.1));
    let under = coincident(&runs, (yhi - ylo) * COINCIDENT);
    if !log {
        return Data { y: pad((ylo, yhi), 0.05), x, runs, under, shift: 0 };
    }
    // Whole decades, so the axis always has labelled powers of ten.
    let (lo, hi) = if ylo > yhi { (-1.0, 1.0) } else { (ylo.floor(), yhi.ceil().max(ylo.floor() + 1.0)) };
    let shift = lo.max(hi - 300.0);
    for p in runs.iter_mut().flatten().flatten() {
        p.1 = 10f64.powf((p.1 - shift).max(0.0));
    }
    Data { runs, x, y: (10f64.powf((lo - shift).max(0.0)), 10f64.powf(hi - shift)), under, shift: shift as i32 }
}

/// Two curves closer than this fraction of the y axis draw as one line.
pub(super) const COINCIDENT: f64 = 0.01;

/// For each series, the first later one that covers it: same times, and
/// within `tol` (in the drawn units: log10 |y| or y) at 95 % of them.
pub(super) fn coincident(runs: &[Vec<Vec<(f64, f64)>>], tol: f64) -> Vec<Option<usize>> {
    let flat: Vec<Vec<(f64, f64)>> = runs.iter().map(|r| r.iter().flatten().copied().collect()).collect();
    let covers = |a: &[(f64, f64)], b: &[(f64, f64)]| {
        let close = a.iter().zip(b).filter(|(p, q)| p.0 == q.0 && (p.1 - q.1).abs() <= tol).count();
        !a.is_empty() && a.len() == b.len() && close as f64 >= 0.95 * a.len() as f64
    };
    (0..flat.len()).map(|a| (a + 1..flat.len()).find(|&b| covers(&flat[a], &flat[b]))).collect()
}

/// Widens a range by `frac` of its span each side. A flat range (all values equal, up to
/// rounding noise) opens to ±10 % of its value (±1 around 0), an empty one becomes 0..1,
/// so plotters never gets a degenerate axis.
pub(super) fn pad((lo, hi): (f64, f64), frac: f64) -> (f64, f64) {
    if lo > hi {
        return (0.0, 1.0);
    }
    if hi - lo <= lo.abs().max(hi.abs()) * 1e-9 {
        let c = (lo + hi) / 2.0;
        let h = if c == 0.0 { 1.0 } else { c.abs() * 0.1 };
        return (c - h, c + h);
    }
    let d = (hi - lo) * frac;
    (lo - d, hi + d)
}
