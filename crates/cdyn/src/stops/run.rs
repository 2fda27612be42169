//! The run of a system with stops: segments of ordinary [`Simulation`]s,
//! one per set of held stops, joined by impacts and releases (see the
//! module's head).

use crate::dynamics::assemble::assemble;
use crate::dynamics::{Breakdown, Dynamics};
use crate::error::{Error, Part, Problem, Result};
use crate::model::Model;
use crate::simulate::{Settings, Simulation, steps_to};

/// A system with stops, for [`run_with_stops`].
pub trait Unilateral {
    /// How many stops it has.
    fn stops(&self) -> usize;
    /// Its model with the stops `held` (indices, in this order) as its last
    /// rows, each `g = 0`.
    fn model_holding(&self, held: &[usize]) -> Result<Model>;
    /// Each stop's gap `g` (`≥ 0` allowed) and its rate `ġ` at `(q, v)`.
    fn gaps(&self, q: &[f64], v: &[f64]) -> Result<Vec<[f64; 2]>>;
    /// Newton's coefficient of restitution of a stop.
    fn restitution(&self, stop: usize) -> f64;
    /// How messages name a stop (`"joint 2's upper limit"`).
    fn name(&self, stop: usize) -> String;
    /// The coordinates moving faster than their velocity bound at `(q, v)`:
    /// `(index, |rate| / bound)` with the ratio above 1. Reported, not enforced.
    fn overspeed(&self, _q: &[f64], _v: &[f64]) -> Result<Vec<(usize, f64)>> {
        Ok(Vec::new())
    }
}

/// What a run with stops did besides its states.
#[derive(Debug, Clone, PartialEq, Default)]
#[non_exhaustive]
pub struct Report {
    /// The stops hit and released, in order.
    pub events: Vec<Event>,
    /// Each coordinate that exceeded its velocity bound at a step's end:
    /// `(index, largest |rate| / bound, first time)`, by index.
    pub overspeed: Vec<(usize, f64, f64)>,
}

/// What happened at a stop.
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub enum Change {
    /// Hit with the gap's rate `rate` (< 0); the impact took `kinetic_lost`
    /// of kinetic energy; `held` unless it rebounded (`e > 0`).
    Impact {
        /// `ġ` just before the impact, at the stop (the positions projected
        /// onto it, the velocities onto the other rows there).
        rate: f64,
        /// `T⁻ − T⁺` across the impact, at the stop: `(1 − e²) ġ² / (2 g_q M⁻¹ g_qᵀ)`
        /// for one stop, the kinetic energy of the velocity along it.
        kinetic_lost: f64,
        /// Whether the stop is held now.
        held: bool,
    },
    /// Released: the row's multiplier turned to pulling.
    Release {
        /// `λ` of the row `g = 0` (> 0).
        multiplier: f64,
    },
}

/// A stop hit or released.
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub struct Event {
    /// Which stop (see [`Unilateral::stops`]).
    pub stop: usize,
    /// The step after which it was seen (`t = step · h`).
    pub step: u64,
    /// When: for an impact, the crossing time within that step; for a
    /// release, the step's end.
    pub t: f64,
    /// What happened.
    pub change: Change,
}

/// Steps `system` from `(q0, v0)` to `t_end` with `settings`, its stops
/// hit, held and released as they come; `observe(t, q, v)` sees the
/// start, every `every`-th step and the last (after a change made at that
/// step). Returns the changes and the velocity bounds exceeded.
pub fn run_with_stops<U: Unilateral, E: From<Error>>(
    system: &U,
    settings: Settings,
    q0: &[f64],
    v0: &[f64],
    t_end: f64,
    every: u64,
    mut observe: impl FnMut(f64, &[f64], &[f64]) -> std::result::Result<(), E>,
) -> std::result::Result<Report, E> {
    let (steps, every, h) = (steps_to(t_end, settings.h)?, every.max(1), settings.h);
    let (mut q, mut v) = (q0.to_vec(), v0.to_vec());
    for (k, [g, _]) in system.gaps(&q, &v)?.into_iter().enumerate() {
        if g < 0.0 {
            let reason = format!("{} is passed by {:.3e} at the start", system.name(k), -g);
            return Err(Problem::Stop { reason }.at(Part::InitialState).into());
        }
    }
    let (mut held, mut events, mut step) = (Vec::<usize>::new(), Vec::new(), 0);
    let mut overspeed: Vec<(usize, f64, f64)> = Vec::new();
    observe(0.0, &q, &v)?;
    while step < steps {
        let model = system.model_holding(&held)?;
        let mut sim = Simulation::new(&model, settings, &q, &v)?;
        sim.resume_at(step);
        let mut dynamics = Dynamics::new(&model);
        let free_rows = model.m() - held.len();
        let mut before = system.gaps(&q, &v)?;
        loop {
            sim.step()?;
            step += 1;
            let t = sim.t();
            (q, v) = (sim.q().to_vec(), sim.v().to_vec());
            let gaps = system.gaps(&q, &v)?;
            for (index, ratio) in system.overspeed(&q, &v)? {
                match overspeed.iter_mut().find(|o| o.0 == index) {
                    Some(o) => o.1 = o.1.max(ratio),
                    None => overspeed.push((index, ratio, t)),
                }
            }
            let hits: Vec<usize> = (0..gaps.len()).filter(|k| !held.contains(k) && gaps[*k][0] < 0.0).collect();
            let mut changed = !hits.is_empty();
            if hits.is_empty() && !held.is_empty() {
                dynamics.evaluate(&model, &q, &v, t).map_err(|b| breakdown(b, step, t))?;
                let lambda = &dynamics.lambda()[free_rows..];
                let released: Vec<(usize, f64)> =
                    held.iter().copied().zip(lambda.iter().copied()).filter(|&(_, l)| l > 0.0).collect();
                for &(stop, multiplier) in &released {
                    events.push(Event { stop, step, t, change: Change::Release { multiplier } });
                }
                held.retain(|k| !released.iter().any(|(stop, _)| stop == k));
                changed = !released.is_empty();
            }
            if !hits.is_empty() {
                let with: Vec<usize> = held.iter().chain(&hits).copied().collect();
                let impact = system.model_holding(&with)?;
                // The positions onto every row, stops hit included, and the
                // velocities there with (v̂) and without (v_p) the stops hit
                // moving: v_p is Newton's plastic impact; v̂ + (1 + e)(v_p − v̂)
                // meets the other rows and leaves the stops at −e times v̂'s rate.
                let mut plastic = v.clone();
                assemble(&impact, &mut q, &mut plastic, t, ASSEMBLY_TOLERANCE)?;
                let mut free = v.clone();
                assemble(&model, &mut q.clone(), &mut free, t, ASSEMBLY_TOLERANCE)?;
                // One coefficient for stops hit at once: the largest of theirs.
                let e = hits.iter().map(|&k| system.restitution(k)).fold(0.0, f64::max);
                v = free.iter().zip(&plastic).map(|(f, p)| f + (1.0 + e) * (p - f)).collect();
                let kinetic_lost = impact.kinetic(&q, &free) - impact.kinetic(&q, &v);
                let rates = system.gaps(&q, &free)?;
                for &stop in &hits {
                    let t = crossing(before[stop], gaps[stop], t - h, h);
                    let change = Change::Impact { rate: rates[stop][1], kinetic_lost, held: e == 0.0 };
                    events.push(Event { stop, step, t, change });
                }
                if e == 0.0 {
                    held = with;
                }
            }
            if step.is_multiple_of(every) || step == steps {
                observe(t, &q, &v)?;
            }
            if changed || step == steps {
                break;
            }
            before = gaps;
        }
    }
    overspeed.sort_by_key(|o| o.0);
    Ok(Report { events, overspeed })
}

fn breakdown(b: Breakdown, step: u64, t: f64) -> Error {
    match b {
        Breakdown::Singular(row) => Error::SingularConstraints { step, t, row },
        Breakdown::NonFinite => Error::Diverged { step, t },
        Breakdown::Mass(coordinate) => Error::MassNotPositive { step, t, coordinate },
    }
}

/// How closely an impact's projection meets the rows.
const ASSEMBLY_TOLERANCE: f64 = 1e-12;

/// The time in `[t0, t0 + h]` where the cubic through `(g, ġ)` at both
/// ends crosses zero (`g ≥ 0` at `t0`, `< 0` at the end), by bisection.
fn crossing([g0, r0]: [f64; 2], [g1, r1]: [f64; 2], t0: f64, h: f64) -> f64 {
    let cubic = |s: f64| {
        let (s2, s3) = (s * s, s * s * s);
        g0 * (2.0 * s3 - 3.0 * s2 + 1.0)
            + r0 * h * (s3 - 2.0 * s2 + s)
            + g1 * (3.0 * s2 - 2.0 * s3)
            + r1 * h * (s3 - s2)
    };
    let (mut lo, mut hi) = (0.0, 1.0);
    for _ in 0..60 {
        let mid = 0.5 * (lo + hi);
        if cubic(mid) >= 0.0 { lo = mid } else { hi = mid }
    }
    t0 + h * 0.5 * (lo + hi)
}
