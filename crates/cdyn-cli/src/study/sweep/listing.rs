//! The printed table of a sweep: every point, or the best of a large one,
//! ranked by the worst error (or violation where there is no reference).

use super::{Point, Sweep};

/// Above this many points the printed table holds only the best
/// [`TOP_K`]: a million-line table helps nobody and cannot be read back.
pub const FULL_TABLE_LIMIT: usize = 1000;

/// Rows of the table of a large sweep.
pub const TOP_K: usize = 20;

/// How much of a sweep to print.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Listing {
    /// Only the summary line (`--quiet`).
    Summary,
    /// Every point up to [`FULL_TABLE_LIMIT`], the best [`TOP_K`] above it.
    Default,
    /// Every point (`--all`).
    All,
}

/// What the sweep is ranked by: the error against the reference where
/// there is one, else max |Φ|.
fn rank_key(sweep: &Sweep) -> (&'static str, fn(&Point) -> f64) {
    if sweep.points.iter().any(|p| p.max_abs_err.is_some()) {
        ("max|err|", |p| p.max_abs_err.unwrap_or(f64::INFINITY))
    } else {
        ("max|phi|", |p| p.max_abs_phi)
    }
}

/// Points ranked best first; failed runs and NaN last, ties by grid index.
fn ranked(sweep: &Sweep) -> Vec<&Point> {
    let (_, key) = rank_key(sweep);
    let value = |p: &Point| if p.error.is_some() || key(p).is_nan() { f64::INFINITY } else { key(p) };
    let mut points: Vec<&Point> = sweep.points.iter().collect();
    points.sort_by(|a, b| value(a).total_cmp(&value(b)).then(a.index.cmp(&b.index)));
    points
}

/// One line: how many points, how many failed, and the best one.
pub fn summary(sweep: &Sweep) -> String {
    let failed = sweep.points.iter().filter(|p| p.error.is_some()).count();
    let (what, key) = rank_key(sweep);
    let best = ranked(sweep).into_iter().next().filter(|p| p.error.is_none());
    let best = best.map_or(String::from("no point ran to the end"), |p| {
        let at: Vec<String> = sweep.axes.iter().zip(&p.values).map(|(a, v)| format!("{} = {v}", a.name)).collect();
        format!("best {what} {:.3e} at {}", key(p), at.join(", "))
    });
    format!("{} points, {failed} failed; {best}\n", sweep.points.len())
}

/// What to print of a sweep: the table as `listing` asks (with a line saying
/// when it is cut), then the summary line.
pub fn listing(sweep: &Sweep, listing: Listing) -> String {
    let n = sweep.points.len();
    match listing {
        Listing::Summary => summary(sweep),
        Listing::All => table(sweep, sweep.points.iter()) + &summary(sweep),
        Listing::Default if n <= FULL_TABLE_LIMIT => table(sweep, sweep.points.iter()) + &summary(sweep),
        Listing::Default => {
            let (what, _) = rank_key(sweep);
            table(sweep, ranked(sweep).into_iter().take(TOP_K))
                + &format!(
                    "the {TOP_K} best of {n} points by {what} (more than {FULL_TABLE_LIMIT}; --all prints every point, sweep.json holds them all)\n"
                )
                + &summary(sweep)
        }
    }
}

/// One line per given point.
fn table<'a>(sweep: &Sweep, points: impl Iterator<Item = &'a Point>) -> String {
    let mut out: String = sweep.axes.iter().map(|a| format!("{:>12}", a.name)).collect();
    out += &format!(" {:>11} {:>11} {:>11}\n", "max|phi|", "max|psi|", "max|err|");
    for p in points {
        out += &p.values.iter().map(|v| format!("{v:>12}")).collect::<String>();
        let err = p.max_abs_err.map_or("-".into(), |e| format!("{e:.3e}"));
        match &p.error {
            Some(e) => out += &format!(" failed: {e}\n"),
            None => out += &format!(" {:>11.3e} {:>11.3e} {err:>11}\n", p.max_abs_phi, p.max_abs_psi),
        }
    }
    out
}
