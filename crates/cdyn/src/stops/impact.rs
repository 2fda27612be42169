//! An impact located within the step that closed a stop: the step taken
//! again in parts, to the crossing and on from it, and Newton's impact
//! law there (the module's head, [`super`], says what it does to the
//! state).

use super::start::START_SLACK;
use super::stepping::StopSimulation;
use super::turns::read_following;
use super::unilateral::{Change, Event, Unilateral};
use crate::dynamics::assemble::assemble;
use crate::dynamics::{Breakdown, Dynamics};
use crate::error::Result;
use crate::model::Model;
use crate::simulate::{Settings, Simulation};
use std::ops::Deref;
use std::sync::Arc;

impl<S: Deref<Target: Unilateral>> StopSimulation<S> {
    /// The step to `t` (number `step`) closed the stops `hits`: it is
    /// taken again from its start in parts, to the earliest crossing (the
    /// root of the cubic through `(g, ġ)` at the two ends), where the stops
    /// crossing then are hit, and on from the impact to the step's end,
    /// where any stop closed since is found the same way. The impact acts
    /// at the stop, at the joint's rate there, not up to `h` late from a
    /// state past the stop, whose projection back would move the bodies
    /// by as much, and differently in each formulation of a mechanism.
    pub(super) fn hit_within(&mut self, hits: &[usize], step: u64, t: f64) -> Result<()> {
        let n = self.model.n();
        // What is left of the step: from `(q, v)` at `t_from`, where the
        // gaps are `from`, to the step's end, where the state is `end` and
        // the gaps `to`.
        let (mut q, mut v) = (self.start[..n].to_vec(), self.start[n..2 * n].to_vec());
        let mut t_from = t - self.settings.h;
        let mut end = (self.sim.q().to_vec(), self.sim.v().to_vec());
        let (mut from, mut to, mut hits) = (self.before.clone(), self.after.clone(), hits.to_vec());
        let (mut model, mut changed, mut at) = (Arc::clone(&self.model), false, from.clone());
        for round in 0..=MOST_IMPACTS_IN_A_STEP {
            let left = t - t_from;
            // −g̈ over what is left of the step: how hard the load presses on.
            let pressing: Vec<f64> = hits.iter().map(|&k| (from[k][1] - to[k][1]) / left).collect();
            let (crossed, t_hit, hit, pressing) = if round < MOST_IMPACTS_IN_A_STEP {
                let crossings: Vec<f64> = hits.iter().map(|&k| crossing(from[k], to[k], left)).collect();
                let first = crossings.iter().copied().fold(1.0, f64::min);
                // Stops crossing with the first are hit with it; the others
                // are found again after it.
                let with_first: Vec<usize> =
                    (0..hits.len()).filter(|&i| crossings[i] <= first + SAME_CROSSING).collect();
                // The run's own ∫Ė where the part starts from the step's start.
                let e = (round == 0).then(|| self.start[2 * n]);
                let crossed = self.part_step(&model, (q, v), e, t_from, first * left)?;
                let hit = with_first.iter().map(|&i| hits[i]).collect();
                (crossed, t_from + first * left, hit, with_first.iter().map(|&i| pressing[i]).collect())
            } else {
                // Impacts without end within one step: the last at its end.
                (end.clone(), t, hits.clone(), pressing)
            };
            read_following(&*self.system, &crossed.0, &crossed.1, &from, &mut at)?;
            let held_more;
            (q, v, held_more) = self.impact(&model, &hit, &pressing, crossed, step, t_hit)?;
            t_from = t_hit;
            if held_more {
                model = Arc::new(self.system.model_holding(&self.held)?);
                changed = true;
            }
            if round == MOST_IMPACTS_IN_A_STEP {
                break;
            }
            read_following(&*self.system, &q, &v, &at, &mut from)?;
            end = self.part_step(&model, (q.clone(), v.clone()), None, t_from, t - t_from)?;
            read_following(&*self.system, &end.0, &end.1, &from, &mut to)?;
            let (held, implied) = (&self.held, &self.implied);
            hits = (0..to.len())
                .filter(|k| !held.contains(k) && !implied.contains(k) && to[*k][0] < -START_SLACK)
                .collect();
            if hits.is_empty() {
                (q, v) = end;
                break;
            }
        }
        self.restart_with(&q, &v, model, changed)
    }

    /// `(q, v)` stepped on by `dt`, a part of a step, from time `t0`, in
    /// the segment of `model`: by a copy of the run's simulation where that
    /// is its model, else of one started there (`Simulation::part_step`:
    /// the run's scheme, a multistep one's start-up). `∫Ė` starts at `e`,
    /// the run's own; without one, from an impact, whose changes to the
    /// energy and momenta the control laws must not undo. A part shorter
    /// than round-off of `h` is not taken.
    fn part_step(
        &mut self,
        model: &Arc<Model>,
        (q, v): (Vec<f64>, Vec<f64>),
        e: Option<f64>,
        t0: f64,
        dt: f64,
    ) -> Result<(Vec<f64>, Vec<f64>)> {
        if dt <= SAME_CROSSING * self.settings.h {
            return Ok((q, v));
        }
        let part = |sim: &Simulation<'_>| -> Result<(Vec<f64>, Vec<f64>, u64)> {
            let part = sim.part_step(&q, &v, e, t0, dt)?;
            Ok((part.q().to_vec(), part.v().to_vec(), part.evaluations() - sim.evaluations()))
        };
        let (q, v, evaluations) = if Arc::ptr_eq(model, &self.model) {
            part(&self.sim)?
        } else {
            let settings = Settings { consistency_tolerance: None, ..self.settings };
            part(&Simulation::new(model, settings, &q, &v)?)?
        };
        // Counted by the run's simulation, which the next segment continues.
        self.sim.count_evaluations(evaluations);
        Ok((q, v))
    }

    /// Hits the stops `hits` at `(q, v)` and time `t`, where they close, in
    /// the segment of `model`: Newton's impact, and the stops held if
    /// plastic. `pressing` is each one's `−g̈` over the step. Returns the
    /// state after it and whether more stops are held.
    fn impact(
        &mut self,
        model: &Model,
        hits: &[usize],
        pressing: &[f64],
        (mut q, v): (Vec<f64>, Vec<f64>),
        step: u64,
        t: f64,
    ) -> Result<(Vec<f64>, Vec<f64>, bool)> {
        let h = self.settings.h;
        let (rows, implied) = self.split_implied(model, hits, &q, &v, t)?;
        // The positions onto every row, stops hit included, and the
        // velocities there with (v̂) and without (v_p) the stops hit
        // moving: v_p is Newton's plastic impact; v̂ + (1 + e)(v_p − v̂)
        // meets the other rows and leaves the stops at −e times v̂'s rate.
        let mut impact = self.system.model_holding(&rows)?;
        let mut plastic = v.clone();
        assemble(&impact, &mut q, &mut plastic, t, ASSEMBLY_TOLERANCE)?;
        let mut free = v;
        assemble(model, &mut q.clone(), &mut free, t, ASSEMBLY_TOLERANCE)?;
        // Only the rates are read from these: a periodic gap's turn does not matter.
        let mut rates = vec![[0.0; 2]; self.before.len()];
        self.system.gaps(&q, &free, &mut rates)?;
        // A stop whose gap is opening again at the stop crossed and turned
        // within the step (a graze): its position is put back, and the
        // impact is of the stops still closing. Held on the sign of ġ
        // alone, Panda's joint 6 lost 0.16 J grazing its lower limit.
        // At rest on the stop and pressed into it (as at a start there),
        // or leaving it too slowly to get clear within a step, it closes.
        let pressed = |k: usize| hits.iter().position(|&j| j == k).map_or(0.0, |i| pressing[i]);
        let closing = |k: &usize| rates[*k][1] < 0.0 || rates[*k][1] < 0.5 * pressed(*k) * h;
        let held = self.held.len();
        let rows: Vec<usize> = rows[..held].iter().chain(rows[held..].iter().filter(|k| closing(k))).copied().collect();
        let implied: Vec<usize> = implied.into_iter().filter(closing).collect();
        if rows.len() < impact.m() - (model.m() - held) {
            // M-orthogonal projections nest: onto fewer rows from v̂.
            impact = self.system.model_holding(&rows)?;
            plastic.clone_from(&free);
            assemble(&impact, &mut q.clone(), &mut plastic, t, ASSEMBLY_TOLERANCE)?;
        }
        // One coefficient for stops hit at once: the largest of theirs. A
        // rebound that the load pressing into the stop (g̈ < 0, over the
        // step) would end within a step, `2 e |ġ| < |g̈| h`, is a plastic
        // impact: bounces shrinking by e each would otherwise come at every
        // step without end (Zeno), each a hit.
        let bounces = |&(k, pressing): &(usize, f64)| {
            closing(&k) && 2.0 * self.system.restitution(k) * -rates[k][1] >= pressing * h
        };
        let bouncing = hits.iter().copied().zip(pressing.iter().copied()).filter(bounces);
        let e = bouncing.map(|(k, _)| self.system.restitution(k)).fold(0.0, f64::max);
        // v_p + e (v_p − v̂): the stops' rate −e ġ.
        let v: Vec<f64> = free.iter().zip(&plastic).map(|(f, p)| p + e * (p - f)).collect();
        let kinetic_lost = impact.kinetic(&q, &free) - impact.kinetic(&q, &v);
        let held_more = e == 0.0 && rows.len() > held;
        for &stop in hits {
            let held = held_more && closing(&stop);
            let change = Change::Impact { rate: rates[stop][1], kinetic_lost, held };
            self.report.events.push(Event { stop, step, t, change });
        }
        if held_more {
            self.held = rows;
            self.implied.extend(implied);
        }
        Ok((q, v, held_more))
    }

    /// The stops to hold as rows after hitting `hits` at `(q, v)` — the
    /// held ones and each hit whose row is independent of the model's rows
    /// and of those before it — and the hits left out, which the rows
    /// already hold: a row that depends on the others would make the
    /// constraints singular. Panda's two fingers, one a `<mimic>` of the
    /// other, reach their lower bound together; with the first finger's
    /// stop and the mimic row held, the second's stop holds nothing more.
    fn split_implied(
        &self,
        model: &Model,
        hits: &[usize],
        q: &[f64],
        v: &[f64],
        t: f64,
    ) -> Result<(Vec<usize>, Vec<usize>)> {
        let (mut rows, mut implied) = (self.held.clone(), Vec::new());
        let others = model.m() - self.held.len();
        for &stop in hits {
            // More rows than coordinates cannot be independent.
            let independent = others + rows.len() < q.len() && {
                rows.push(stop);
                let model = self.system.model_holding(&rows)?;
                rows.pop();
                !matches!(Dynamics::new(&model).evaluate(&model, q, v, t), Err(Breakdown::Singular(_)))
            };
            if independent { rows.push(stop) } else { implied.push(stop) }
        }
        Ok((rows, implied))
    }
}

/// How closely an impact's projection meets the rows.
const ASSEMBLY_TOLERANCE: f64 = 1e-12;

/// Stops whose crossings lie closer than this fraction of a step are hit
/// together; a part step shorter than it is not taken.
const SAME_CROSSING: f64 = 1e-9;

/// Impacts located within one step before the rest, if any, is taken at
/// its end (bounces that shrink without end would go on forever).
const MOST_IMPACTS_IN_A_STEP: usize = 8;

/// Where in a step of `h` (a fraction of it) the cubic through `(g, ġ)` at
/// both ends crosses zero (`g ≥ 0` at the start, `< 0` at the end), by
/// bisection.
fn crossing([g0, r0]: [f64; 2], [g1, r1]: [f64; 2], h: f64) -> f64 {
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
    0.5 * (lo + hi)
}
