//! What a case produced, as `summary.json` reports it: the case, the
//! library's record of the run, and what its method did.

use super::Case;
use super::joint_stats::JointStats;
use super::limits::LimitsReport;
use crate::case::frames::Frames;
use cdyn::record::{Record, Series};
use cdyn::simulate::RankLoss;
use serde::Serialize;

/// What a case produced, as `summary.json` reports it: the case, then the
/// library's record of the run.
#[derive(Debug, Clone, Serialize)]
pub struct CaseResult {
    /// The case's name.
    pub name: String,
    /// The observable whose error against the reference is reported.
    pub error_observable: String,
    /// The scheme's name.
    pub scheme: &'static str,
    /// The step size.
    #[serde(serialize_with = "cdyn::json_float::serialize")]
    pub h: f64,
    /// The library's record of the run.
    #[serde(flatten)]
    pub record: Record,
    /// The method as it ran: its automatic gains chosen (`None` if it could not start).
    pub control: Option<cdyn::Control>,
    /// What the automatic gains were chosen from, and the largest rate × h.
    pub tuning: Option<cdyn::control::gains::Tuning>,
    /// Mean Newton iterations per step of the `projection` method.
    pub projection_iterations_per_step: Option<f64>,
    /// Mean iterations per step of RATTLE's position step (`scheme = "rattle"`).
    pub rattle_iterations_per_step: Option<f64>,
    /// Generalized-α's Newton iteration (`scheme = "generalized_alpha"`).
    pub newton: Option<NewtonReport>,
    /// Steps in which constraint rows were dropped as dependent
    /// (`dependent_rows = "tolerate"`): the most rows at once, how many
    /// steps, the first and last; `null` if none were.
    pub dependent_rows: Option<RankLoss>,
    /// What the run did at its joint limits (absent without limits).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub limits: Option<LimitsReport>,
    /// A spatial run's joint columns and actuators over the samples
    /// written (absent for other runs).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub joint_space: Option<JointStats>,
    /// `None` when the run finished; the error otherwise.
    pub error: Option<String>,
    /// Whether SIGINT or SIGTERM stopped the run (at `steps`, `t_final`).
    pub interrupted: bool,
    /// Positions at some samples, for the viewer (kept when the case has a drawing).
    #[serde(skip)]
    pub frames: Frames,
}

/// What generalized-α's Newton iteration did over a run.
#[derive(Debug, Clone, Copy, serde::Serialize)]
pub struct NewtonReport {
    /// Mean corrections per step.
    pub corrections_per_step: f64,
    /// The largest `|Δq|∞` a step left uncorrected: below the tolerance
    /// when it converges, what `newton_iterations` reached otherwise.
    pub newton_correction: f64,
}

/// What a run reports of its method besides the record.
#[derive(Default)]
pub(super) struct Method {
    pub(super) interrupted: bool,
    pub(super) control: Option<cdyn::Control>,
    pub(super) tuning: Option<cdyn::control::gains::Tuning>,
    pub(super) projection_iterations_per_step: Option<f64>,
    pub(super) rattle_iterations_per_step: Option<f64>,
    pub(super) newton: Option<NewtonReport>,
    pub(super) frames: Frames,
    pub(super) rank_loss: Option<RankLoss>,
    pub(super) limits: Option<LimitsReport>,
}

impl Method {
    /// What `sim`'s method did over its run.
    pub(super) fn of(sim: &cdyn::Simulation<'_>, interrupted: bool, frames: Frames) -> Self {
        let scheme = sim.settings().scheme;
        let per_step = |count: u64| count as f64 / sim.steps().max(1) as f64;
        Method {
            interrupted,
            control: Some(sim.settings().control),
            tuning: Some(*sim.tuning()),
            projection_iterations_per_step: sim
                .settings()
                .control
                .projection
                .is_some()
                .then(|| per_step(sim.projection_iterations())),
            rattle_iterations_per_step: (scheme == cdyn::Scheme::Rattle).then(|| per_step(sim.rattle_iterations())),
            newton: (scheme == cdyn::Scheme::GeneralizedAlpha).then(|| NewtonReport {
                corrections_per_step: per_step(sim.newton_iterations()),
                newton_correction: sim.newton_correction(),
            }),
            frames,
            rank_loss: sim.rank_loss().copied(),
            limits: None,
        }
    }
}

/// The series of a run that kept none (sweeps).
static NO_SERIES: Series = Series::new();

impl CaseResult {
    /// The summary of `case` from its record.
    pub(super) fn new(case: &Case, (record, method): (Record, Method)) -> Self {
        CaseResult {
            name: case.name.clone(),
            error_observable: case.example.observables[0].clone(),
            scheme: case.settings.scheme.info().name,
            h: case.settings.h,
            error: record.error.as_ref().map(|e| {
                let entry = e.row().and_then(|r| case.row_entries.get(r)).map_or(String::new(), |e| format!(" ({e})"));
                format!("case {}: {e}{entry}", case.name)
            }),
            record,
            control: method.control,
            tuning: method.tuning,
            projection_iterations_per_step: method.projection_iterations_per_step,
            rattle_iterations_per_step: method.rattle_iterations_per_step,
            newton: method.newton,
            dependent_rows: method.rank_loss,
            limits: method.limits,
            joint_space: None,
            interrupted: method.interrupted,
            frames: method.frames,
        }
    }

    /// With the joint-space statistics of a case that has joint columns.
    pub(super) fn with_joint_space(self, case: &Case, stats: JointStats) -> Self {
        Self { joint_space: case.joint_columns.is_some().then_some(stats), ..self }
    }

    /// Sampled time histories, for the figures (empty for sweeps).
    pub fn series(&self) -> &Series {
        self.record.series.as_ref().unwrap_or(&NO_SERIES)
    }
}
