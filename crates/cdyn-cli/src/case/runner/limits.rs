//! The joint limits a case holds: the library's system of stops
//! ([`cdyn::stops`]), the names a report gives them, and what a run did at
//! them as `summary.json` and the terminal report it.

use cdyn::error::Problem;
use cdyn::json_float::JsonFloat;
use cdyn::stops::{Change, Report, Unilateral};
use serde::Serialize;
use std::sync::Arc;

/// A case's joint limits: the mechanism as a system of stops, and the
/// names of its stops and joints.
pub struct Limits {
    /// The mechanism, whose model with the stops held the run steps.
    pub system: Arc<dyn Unilateral + Send + Sync>,
    /// Each stop's joint (as the CSV's columns name it) and bound.
    pub stops: Vec<StopName>,
    /// Each joint's name, for the velocity bounds (indexed as the system's overspeed report).
    pub joints: Vec<String>,
}

/// How a report names one side of a joint's limit.
#[derive(Debug, Clone, PartialEq)]
pub struct StopName {
    /// The joint (`elbow`, `joints[0]`).
    pub joint: String,
    /// Its upper bound, else its lower.
    pub upper: bool,
    /// The bound's value.
    pub bound: f64,
}

/// What a run did at its joint limits, as `summary.json` reports it.
#[derive(Debug, Clone, Serialize)]
pub struct LimitsReport {
    /// The limits hit and released, in order.
    pub events: Vec<LimitEvent>,
    /// Each joint that exceeded its velocity bound.
    pub velocity_exceeded: Vec<Overspeed>,
}

/// A limit hit or released.
#[derive(Debug, Clone, Serialize)]
pub struct LimitEvent {
    /// The joint.
    pub joint: String,
    /// `"lower"` or `"upper"`.
    pub side: &'static str,
    /// The bound.
    pub bound: JsonFloat,
    /// `"impact"` or `"release"`.
    pub event: &'static str,
    /// When: an impact's crossing time within its step, a release's step end.
    pub t: JsonFloat,
    /// An impact's rate of the gap before it (`< 0`, joint units per second).
    pub rate: Option<JsonFloat>,
    /// The kinetic energy an impact took.
    pub kinetic_energy_lost: Option<JsonFloat>,
    /// Whether an impact left the joint held at the bound (restitution 0).
    pub held: Option<bool>,
    /// A release's multiplier of the bound's row (`> 0`: pulling away).
    pub multiplier: Option<JsonFloat>,
}

/// A joint faster than its velocity bound.
#[derive(Debug, Clone, Serialize)]
pub struct Overspeed {
    /// The joint.
    pub joint: String,
    /// The largest `|θ̇| / bound` seen at a step's end.
    pub ratio: JsonFloat,
    /// When it first exceeded it.
    pub t: JsonFloat,
}

impl Limits {
    /// Refuses a start past a limit ([`cdyn::stops::check_start`]) in one
    /// line naming the joint as the CSV does: `joint elbow: starts 2.000e-1
    /// past its upper limit 1 (…)`.
    pub fn check_start(&self, q0: &[f64], v0: &[f64]) -> Result<(), String> {
        match cdyn::stops::check_start(&*self.system, q0, v0) {
            Ok(()) => Ok(()),
            Err(cdyn::Error::InvalidModel {
                problem: Problem::StartsPastLimit { stop, upper, bound, by, .. }, ..
            }) => {
                let joint = format!("joint {}", self.stops[stop].joint);
                let problem = Problem::StartsPastLimit { stop, joint, upper, bound, by };
                Err(format!("{problem} (limits hold a joint within its range from the start)"))
            }
            Err(e) => Err(format!("[initial]: {e}")),
        }
    }

    /// The library's report of a run, in the names of the case's joints.
    pub fn report(&self, report: &Report) -> LimitsReport {
        let events = report
            .events
            .iter()
            .map(|e| {
                let stop = &self.stops[e.stop];
                let (event, rate, kinetic_energy_lost, held, multiplier) = match e.change {
                    Change::Impact { rate, kinetic_lost, held } => {
                        ("impact", Some(JsonFloat(rate)), Some(JsonFloat(kinetic_lost)), Some(held), None)
                    }
                    Change::Release { multiplier } => ("release", None, None, None, Some(JsonFloat(multiplier))),
                    _ => ("other", None, None, None, None),
                };
                LimitEvent {
                    joint: stop.joint.clone(),
                    side: if stop.upper { "upper" } else { "lower" },
                    bound: JsonFloat(stop.bound),
                    event,
                    t: JsonFloat(cdyn::error::tidy_time(e.t)),
                    rate,
                    kinetic_energy_lost,
                    held,
                    multiplier,
                }
            })
            .collect();
        let velocity_exceeded = report
            .overspeed
            .iter()
            .map(|&(k, ratio, t)| Overspeed { joint: self.joints[k].clone(), ratio: JsonFloat(ratio), t: JsonFloat(t) })
            .collect();
        LimitsReport { events, velocity_exceeded }
    }

    /// The joint the first stop belongs to, for a refusal to name.
    pub fn first_joint(&self) -> &str {
        self.stops.first().map_or_else(|| self.joints.first().map_or("", String::as_str), |s| s.joint.as_str())
    }
}

impl LimitsReport {
    /// One line for the terminal: `limits: 3 impacts, 2 releases; elbow
    /// exceeded its velocity bound 1.4× at t = 0.31 s`.
    pub fn line(&self) -> String {
        let count = |kind: &str| self.events.iter().filter(|e| e.event == kind).count();
        let plural = |n: usize, word: &str| format!("{n} {word}{}", if n == 1 { "" } else { "s" });
        let mut line =
            format!("limits: {}, {}", plural(count("impact"), "impact"), plural(count("release"), "release"));
        for o in &self.velocity_exceeded {
            line += &format!("; {} exceeded its velocity bound {:.2}× at t = {} s", o.joint, o.ratio.0, o.t.0);
        }
        line
    }
}
