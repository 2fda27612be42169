//! What `cdyn precision` measured (precision.json's records), its table
//! and its CSV.

use super::*;

/// One run: a scheme and method at one step.
#[derive(Debug, Clone, Serialize)]
pub struct Point {
    /// The step.
    #[serde(serialize_with = "cdyn::json_float::serialize")]
    pub h: f64,
    /// Steps taken.
    pub steps: u64,
    /// Evaluations of the dynamics per simulated second.
    #[serde(serialize_with = "cdyn::json_float::serialize")]
    pub evaluations_per_second: f64,
    /// Wall-clock seconds per simulated second (the fastest of the repeats of a short run).
    #[serde(serialize_with = "cdyn::json_float::serialize")]
    pub wall_per_second: f64,
    /// Largest `|q_i − q_ref,i|` over the samples; infinite if the run stopped.
    #[serde(serialize_with = "cdyn::json_float::serialize")]
    pub max_error: f64,
    /// Largest `|Φ|` over the samples (read outside the clock).
    #[serde(serialize_with = "cdyn::json_float::serialize")]
    pub max_abs_phi: f64,
    /// Why it stopped, if it did.
    pub error: Option<String>,
}

/// One line of the diagram: a scheme and method at every step.
#[derive(Debug, Clone, Serialize)]
pub struct Line {
    /// The scheme's name.
    pub scheme: &'static str,
    /// The method's name in `cdyn compare`.
    pub method: String,
    /// The slope of log error against log h over the points above the
    /// reference's error bound (`None` with fewer than two).
    #[serde(serialize_with = "cdyn::json_float::serialize")]
    pub observed_order: Option<f64>,
    /// Coarsest step first.
    pub points: Vec<Point>,
}

/// The reference the errors are measured against.
#[derive(Debug, Clone, Serialize)]
pub struct Reference {
    /// `"closed form"` or `"rk4"`.
    pub kind: &'static str,
    /// The RK-4 reference's step (`None` for a closed form).
    #[serde(serialize_with = "cdyn::json_float::serialize")]
    pub h: Option<f64>,
    /// Largest difference between the RK-4 reference and RK-4 at twice its
    /// step: an upper bound on its own error (0 for a closed form, which is
    /// good to about 1e-12).
    #[serde(serialize_with = "cdyn::json_float::serialize")]
    pub error_bound: f64,
}

/// The cheapest line that reaches an error.
#[derive(Debug, Clone, Serialize)]
pub struct Cheapest {
    /// The error.
    #[serde(serialize_with = "cdyn::json_float::serialize")]
    pub target: f64,
    /// The line's scheme.
    pub scheme: &'static str,
    /// The line's method.
    pub method: String,
    /// Its wall-clock seconds per simulated second there, interpolated
    /// log-log between its points.
    #[serde(serialize_with = "cdyn::json_float::serialize")]
    pub wall_per_second: f64,
}

/// Everything `cdyn precision` measured.
#[derive(Debug, Clone, Serialize)]
pub struct Precision {
    /// The scenario file.
    pub scenario: String,
    /// The end time of every run (a whole number of the coarsest step).
    #[serde(serialize_with = "cdyn::json_float::serialize")]
    pub t_end: f64,
    /// Interval of the samples compared with the reference: the coarsest step.
    #[serde(serialize_with = "cdyn::json_float::serialize")]
    pub sample_interval: f64,
    /// What the errors are measured against.
    pub reference: Reference,
    /// One per scheme × method.
    pub lines: Vec<Line>,
    /// For each of [`TARGETS`] some line reaches (and ten times above the
    /// reference's error bound), the cheapest there.
    pub cheapest: Vec<Cheapest>,
}

/// The table `cdyn precision` prints.
pub fn table(p: &Precision) -> String {
    let mut out = format!(
        "{}: t_end {}, errors at multiples of {}; reference {}{}\n",
        p.scenario,
        p.t_end,
        p.sample_interval,
        p.reference.kind,
        match p.reference.h {
            Some(h) => format!(" at h = {h:e} (its error below {:.1e})", p.reference.error_bound),
            None => String::new(),
        }
    );
    out += &format!(
        "{:<18} {:<22} {:>10} {:>11} {:>11} {:>11}  order\n",
        "scheme", "method", "h", "max error", "evals/s", "wall s/s"
    );
    for line in &p.lines {
        for (k, pt) in line.points.iter().enumerate() {
            let order = match (k, line.observed_order) {
                (0, Some(o)) => format!("  {o:.2}"),
                _ => String::new(),
            };
            let error = match &pt.error {
                Some(_) => "stopped".to_string(),
                None => format!("{:.3e}", pt.max_error),
            };
            out += &format!(
                "{:<18} {:<22} {:>10.3e} {:>11} {:>11.4e} {:>11.3e}{order}\n",
                line.scheme, line.method, pt.h, error, pt.evaluations_per_second, pt.wall_per_second
            );
        }
    }
    for c in &p.cheapest {
        out += &format!(
            "cheapest to {:.0e}: {} {} ({:.3e} s per simulated s)\n",
            c.target, c.scheme, c.method, c.wall_per_second
        );
    }
    out
}

/// `precision.csv`: one row per point.
pub fn csv(p: &Precision) -> String {
    let mut out =
        String::from("scheme,method,h,steps,evaluations_per_second,wall_per_second,max_error,max_abs_phi,error\n");
    for line in &p.lines {
        for pt in &line.points {
            let error = pt.error.as_deref().map_or(String::new(), |e| format!("\"{}\"", e.replace('"', "'")));
            out += &format!(
                "{},{},{:e},{},{:e},{:e},{:e},{:e},{error}\n",
                line.scheme,
                line.method,
                pt.h,
                pt.steps,
                pt.evaluations_per_second,
                pt.wall_per_second,
                pt.max_error,
                pt.max_abs_phi
            );
        }
    }
    out
}
