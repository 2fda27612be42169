//! Tick labels: fixed-point or scientific with the digits the step needs,
//! on linear and logarithmic axes.

use super::TICKS;
use plotters::coord::ranged1d::Ranged;
use plotters::coord::types::RangedCoordf64;

/// Tick labeller for a linear axis over `lo..hi`: scientific outside 1e-3..1e5 (so 1e-9 is not
/// "0.000000001"), else fixed-point; either way with just the digits the tick step needs.
pub(super) fn ticks((lo, hi): (f64, f64)) -> impl Fn(&f64) -> String {
    let keys = RangedCoordf64::from(lo..hi).key_points(TICKS);
    let step = match keys.as_slice() {
        [a, b, ..] => b - a,
        _ => (hi - lo) / TICKS as f64,
    };
    let k = (step.log10() + 1e-9).floor(); // decade of the step (a 1, 2 or 5 times 10^k)
    let sci_axis = !(1e-3..1e5).contains(&lo.abs().max(hi.abs()));
    move |&v| {
        let v = if v.abs() < 10f64.powf(k) / 2.0 { 0.0 } else { v };
        match (sci_axis, v == 0.0) {
            (true, true) => "0".into(),
            (true, false) => sci(v, (v.abs().log10().floor() - k).clamp(0.0, 15.0) as usize),
            (false, _) => format!("{v:.*}", (-k).clamp(0.0, 15.0) as usize),
        }
    }
}

/// Scientific notation without trailing zeros in the mantissa: "1.5e-9", "2e-10".
pub(super) fn sci(v: f64, decimals: usize) -> String {
    let s = format!("{v:.decimals$e}");
    let (m, e) = s.split_once('e').unwrap_or((&s, "0"));
    match m.contains('.') {
        true => format!("{}e{e}", m.trim_end_matches('0').trim_end_matches('.')),
        false => format!("{m}e{e}"),
    }
}

/// Tick label on the log axis; `v` is in shifted units (see `Data`). Plain numbers when the
/// whole axis lies within 1e-3..1e4, scientific otherwise.
pub(super) fn log_tick(v: f64, shift: i32, (lo, hi): (f64, f64)) -> String {
    let l = v.log10() + f64::from(shift);
    let (e, m) = (l.floor(), (10f64.powf(l - l.floor()) * 10.0).round() / 10.0);
    let (e, m) = if m >= 10.0 { (e + 1.0, 1.0) } else { (e, m) };
    let (alo, ahi) = (lo.log10() + f64::from(shift), hi.log10() + f64::from(shift));
    if alo >= -3.01 && ahi <= 4.01 {
        let decimals = (if m.fract() == 0.0 { -e } else { 1.0 - e }).max(0.0) as usize;
        format!("{:.*}", decimals, m * 10f64.powf(e))
    } else {
        sci(m * 10f64.powf(e), 1)
    }
}
