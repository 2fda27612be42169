//! What `summary.json` says of a spatial run's joint space: the range and
//! last value of every joint column (`NAME.q`, `NAME.v`, `NAME.tau`) over
//! the samples written, and of each actuator how hard it pushed and how
//! often against its effort bound. Read off the samples as they pass to
//! the CSV (or memory), so it agrees with what the rows hold.

use cdyn::json_float::JsonFloat;
use cdyn::record::{Sample, Sink};
use serde::Serialize;

/// Where a case's joint columns are among its observables.
#[derive(Debug, Clone, Default)]
pub struct JointColumns {
    /// The observable of the first joint column; the joint columns run to
    /// the last observable, the actuators' torques last.
    pub first: usize,
    /// Each actuator's effort bound (infinite where none), in the order of
    /// its `NAME.tau` column.
    pub efforts: Vec<f64>,
}

/// One joint column over the samples.
#[derive(Debug, Clone, Serialize)]
pub struct JointColumn {
    /// As the CSV names it.
    pub column: String,
    /// Its smallest value.
    pub min: JsonFloat,
    /// Its largest value.
    pub max: JsonFloat,
    /// Its value at the last sample.
    #[serde(rename = "final")]
    pub last: JsonFloat,
}

/// One actuator over the samples.
#[derive(Debug, Clone, Serialize)]
pub struct ActuatorStats {
    /// Its torque column (`NAME.tau`).
    pub column: String,
    /// The largest `|τ|` applied.
    pub max_abs: JsonFloat,
    /// Its effort bound (`null` if it has none).
    pub effort: Option<JsonFloat>,
    /// The samples at which it pushed at its bound (clamped), of `samples`.
    pub saturated_samples: u64,
    /// The samples seen.
    pub samples: u64,
}

/// The joint space of a run, as `summary.json` reports it.
#[derive(Debug, Clone, Default, Serialize)]
pub struct JointStats {
    /// Every joint column.
    pub joints: Vec<JointColumn>,
    /// Every actuator.
    pub actuators: Vec<ActuatorStats>,
}

impl JointStats {
    /// Empty statistics of the joint columns `at` of `observables`.
    pub fn new(observables: &[String], at: &JointColumns) -> Self {
        let column = |name: &String| JointColumn {
            column: name.clone(),
            min: JsonFloat(f64::INFINITY),
            max: JsonFloat(f64::NEG_INFINITY),
            last: JsonFloat(f64::NAN),
        };
        let torques = &observables[observables.len() - at.efforts.len()..];
        let actuator = |(name, &effort): (&String, &f64)| ActuatorStats {
            column: name.clone(),
            max_abs: JsonFloat(0.0),
            effort: effort.is_finite().then_some(JsonFloat(effort)),
            saturated_samples: 0,
            samples: 0,
        };
        JointStats {
            joints: observables[at.first..].iter().map(column).collect(),
            actuators: torques.iter().zip(&at.efforts).map(actuator).collect(),
        }
    }

    /// Takes in one sample's observables.
    fn add(&mut self, observables: &[f64]) {
        let values = &observables[observables.len() - self.joints.len()..];
        for (c, &x) in self.joints.iter_mut().zip(values) {
            (c.min.0, c.max.0, c.last.0) = (c.min.0.min(x), c.max.0.max(x), x);
        }
        let torques = &observables[observables.len() - self.actuators.len()..];
        for (a, &tau) in self.actuators.iter_mut().zip(torques) {
            a.max_abs.0 = a.max_abs.0.max(tau.abs());
            // The clamp gives the bound itself; a torque within a few
            // ulps of it is at the bound.
            let at_bound = a.effort.is_some_and(|e| tau.abs() >= e.0 * (1.0 - 4.0 * f64::EPSILON));
            a.saturated_samples += u64::from(at_bound);
            a.samples += 1;
        }
    }
}

/// A sink that passes every sample on to `inner` after taking it into `stats`.
pub(super) struct Watching<'s, K> {
    pub(super) inner: K,
    pub(super) stats: &'s mut JointStats,
}

impl<K: Sink> Sink for Watching<'_, K> {
    type Error = K::Error;
    fn sample(&mut self, s: &Sample<'_>) -> Result<(), K::Error> {
        self.stats.add(s.observables);
        self.inner.sample(s)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ranges_last_values_and_samples_at_the_bound() {
        let names: Vec<String> = ["a.x", "j.q", "j.v", "j.tau"].map(String::from).to_vec();
        let mut stats = JointStats::new(&names, &JointColumns { first: 1, efforts: vec![2.0] });
        for row in [[9.0, 0.5, -1.0, 1.0], [9.0, 0.7, 1.5, -2.0], [9.0, 0.6, 0.0, 2.0 * (1.0 - f64::EPSILON)]] {
            stats.add(&row);
        }
        let q = &stats.joints[0];
        assert_eq!((q.column.as_str(), q.min.0, q.max.0, q.last.0), ("j.q", 0.5, 0.7, 0.6));
        assert_eq!((stats.joints[1].min.0, stats.joints[1].max.0), (-1.0, 1.5));
        assert_eq!(stats.joints.len(), 3);
        let a = &stats.actuators[0];
        assert_eq!((a.column.as_str(), a.max_abs.0, a.saturated_samples, a.samples), ("j.tau", 2.0, 2, 3));
    }
}
