//! One step: the Newton iteration on the accelerations and multipliers.

use super::newton::{newton_matrix, residual};
use super::*;

/// One step of `(q, v, e)` from `t` to `t + h`, counting the evaluations
/// of the dynamics in `evaluations`.
#[allow(clippy::too_many_arguments)]
pub(crate) fn step(
    model: &Model,
    d: &mut Dynamics,
    q: &mut [f64],
    v: &mut [f64],
    e: &mut f64,
    t: f64,
    h: f64,
    w: &mut Work,
    evaluations: &mut u64,
) -> std::result::Result<StepReport, Failure> {
    let n = model.n();
    if !w.started {
        w.start(model, d, q, v, t, h, evaluations)?;
    }
    let Scaling { beta_prime, gamma_prime, c_q, c_v } = w.scaling(h);
    let [alpha_m, alpha_f, gamma, beta] = w.settings.coefficients();
    w.q0.copy_from_slice(q);
    w.v0.copy_from_slice(v);
    // The predictor: the accelerations and multipliers of the last step.
    w.acc_new.copy_from_slice(&w.acc);
    w.lambda_new.copy_from_slice(&w.lambda);
    let states = |w: &mut Work, q: &mut [f64], v: &mut [f64]| {
        for i in 0..n {
            let aux = ((1.0 - alpha_f) * w.acc_new[i] + alpha_f * w.acc[i] - alpha_m * w.aux[i]) / (1.0 - alpha_m);
            w.aux_new[i] = aux;
            q[i] = w.q0[i] + h * w.v0[i] + h * h * ((0.5 - beta) * w.aux[i] + beta * aux);
            v[i] = w.v0[i] + h * ((1.0 - gamma) * w.aux[i] + gamma * aux);
        }
    };
    states(w, q, v);
    let scale = w.acc.iter().fold(1.0_f64, |a, x| a.max(x.abs()));
    // The accelerations' round-off: that of the positions, over h² β.
    let round_off = POSITION_ROUND_OFF * beta_prime * w.q0.iter().fold(1.0_f64, |a, x| a.max(x.abs())) / scale;
    let t1 = t + h;
    let (mut iterations, mut last) = (0, f64::INFINITY);
    let mut refactor = true;
    // Damped Newton (with `Newton::Converge`): an iterate whose residual is
    // no smaller than that of the last accepted one (`base`, from which the
    // correction `along` was taken) is not accepted. A correction from a
    // matrix of an earlier iterate is made again from the base's own
    // matrix; one from the base's matrix is taken in halves. Where Newton
    // converges the residuals shrink and every correction is taken whole,
    // as without damping; a force that saturates, as regularized friction
    // does, otherwise throws the iterates back and forth across its knee.
    let newton = w.settings.newton;
    let damps = matches!(newton, Newton::Converge { .. });
    let exhausted =
        |iterations| matches!(newton, Newton::Converge { max_iterations, .. } if iterations == max_iterations);
    let (mut damping, mut base_residual, mut exact): (f64, f64, bool) = (1.0, f64::INFINITY, true);
    // Whether a correction of this step was not accepted: from then on,
    // every iterate gets its own matrix (full Newton converges at once
    // where a stale matrix crawls, near the knee that needed the damping).
    let mut damped = false;
    let correction = loop {
        *evaluations += 1;
        // A fresh Newton matrix with tolerated dependent rows: the full
        // evaluation factors `Φ_q M⁻¹ Φ_qᵀ` at the iterate, which finds them.
        let rank_revealed = refactor && w.tolerate;
        let evaluated = if rank_revealed { d.evaluate(model, q, v, t1) } else { d.evaluate_forces(model, q, v, t1) };
        evaluated.map_err(|b| Failure::Breakdown(b, t1))?;
        if rank_revealed {
            w.find_dropped(d);
        }
        residual(model, d, w, c_q, gamma_prime);
        let size = w.rhs.iter().map(|x| x * x).sum::<f64>().sqrt();
        if damps && size >= base_residual && (!exact || damping > MIN_DAMPING) {
            if exhausted(iterations) {
                return Err(Failure::NotConverged { correction: last, iterations });
            }
            // Back to the base: half the step, or the base itself, whose
            // residual is evaluated again and accepted, for its own matrix.
            damped = true;
            if exact {
                (damping, refactor) = (0.5 * damping, false);
            } else {
                (damping, refactor, base_residual, exact) = (0.0, true, f64::INFINITY, true);
            }
            let (base, along) = (&w.base, &w.along);
            for (i, a) in w.acc_new.iter_mut().chain(w.lambda_new.iter_mut()).enumerate() {
                *a = base[i] + damping * along[i];
            }
            states(w, q, v);
            iterations += 1;
            continue;
        }
        // The last correction did not halve the one before. Where the
        // iterate already solves the equations (its residual), the
        // corrections are round-off magnified by a near-singular matrix (a
        // mechanism near a singular position), and no iteration improves
        // on it: the step ends, reporting the correction it could not make.
        if let Newton::Converge { tolerance, .. } = newton
            && refactor
            && iterations > 0
            && settled(model, d, w, q, v, c_q, gamma_prime, tolerance)
        {
            break last;
        }
        refactor |= damped;
        if refactor {
            newton_matrix(model, d, q, v, t1, c_q, c_v, w);
            if w.lu.factor(&w.values).is_err() {
                return Err(singular(model, d, q, v, t1, iterations));
            }
        }
        exact = refactor;
        w.lu.solve(&mut w.rhs);
        let correction = beta_prime * w.rhs[..n].iter().fold(0.0_f64, |a, x| a.max(x.abs())) / scale;
        // Converging slower than halving a correction: the matrix of the
        // step's start is too far from the iterate's (the multipliers and
        // the configuration moved), so the next correction gets a fresh
        // one. A fixed count keeps one factorization a step.
        refactor = damps && correction > SLOW_CONTRACTION * last;
        last = correction;
        if !correction.is_finite() || w.rhs[n..].iter().any(|x| !x.is_finite()) {
            return Err(singular(model, d, q, v, t1, iterations));
        }
        match newton {
            Newton::Converge { tolerance, .. } if correction <= tolerance + round_off => break correction,
            Newton::Converge { .. } if exhausted(iterations) => {
                return Err(Failure::NotConverged { correction, iterations });
            }
            Newton::Fixed { iterations: fixed } if iterations == fixed => break correction,
            _ => {}
        }
        (damping, base_residual) = (1.0, size);
        let (base, along) = (&mut w.base, &mut w.along);
        for (i, a) in w.acc_new.iter_mut().chain(w.lambda_new.iter_mut()).enumerate() {
            (base[i], along[i]) = (*a, beta_prime * w.rhs[i]);
            *a += along[i];
        }
        states(w, q, v);
        iterations += 1;
    };
    std::mem::swap(&mut w.acc, &mut w.acc_new);
    std::mem::swap(&mut w.aux, &mut w.aux_new);
    std::mem::swap(&mut w.lambda, &mut w.lambda_new);
    // Ė = F·v + λᵀΦ_t at the last evaluated iterate, with its λ. After a
    // projection of the velocities (by O(h²) across the constraints) the
    // next step's positions move by O(h³) across them, which the index-3
    // equations answer with an O(h) change of λ: the drives' work λᵀΦ_t
    // would then be integrated to O(h) only (measured: the driven
    // slider-crank's |Ψ| 2.5e-2 at h = 1e-3 and 1.3e-2 at 5e-4, the moving
    // support pendulum 40× farther from the truth than without). With a
    // projection Ė takes the multipliers of a full evaluation at the new
    // state, which the projection's own first evaluation then reuses.
    let power = if w.projected {
        *evaluations += 1;
        d.evaluate(model, q, v, t1).map_err(|b| Failure::Breakdown(b, t1))?;
        d.energy_input()
    } else {
        crate::dynamics::energy::power(d.force_power(), &w.lambda, d.phi_t())
    };
    *e += 0.5 * h * (w.power + power);
    w.power = power;
    Ok(StepReport { iterations, correction })
}

/// Why the Newton matrix at `(q, v, t)` is singular: a dependent
/// constraint row (the dynamics' [`Breakdown::Singular`](crate::dynamics::Breakdown::Singular),
/// unless tolerated, where the rows were dropped), or else the rest of the
/// matrix.
fn singular(model: &Model, d: &mut Dynamics, q: &[f64], v: &[f64], t: f64, iterations: u32) -> Failure {
    match d.evaluate(model, q, v, t) {
        Err(b) => Failure::Breakdown(b, t),
        Ok(()) => Failure::Singular { iterations },
    }
}

/// Whether the iterate solves the step's equations as well as they can
/// be solved, judged by its residual in `w.rhs` (not by the correction
/// that residual would make): each constraint row at the round-off of
/// evaluating it, `100 ε` of `|Φ_q| |q|` (holonomic, in the row's own
/// units) or of `|A| |v|` (nonholonomic); the equations of motion within
/// `tolerance` of the size of their terms, `|M q̈| + |Φ_q|ᵀ|λ| + |G|`, the
/// largest residual against the largest term (a backward error of the
/// accelerations, where the correction is their forward error).
#[allow(clippy::too_many_arguments)]
fn settled(
    model: &Model,
    d: &Dynamics,
    w: &mut Work,
    q: &[f64],
    v: &[f64],
    c_q: f64,
    gamma_prime: f64,
    tolerance: f64,
) -> bool {
    let n = model.n();
    let (pattern, jac) = (model.pattern(), d.jac());
    let terms = &mut w.terms;
    d.mass(model).mul(&w.acc_new, terms);
    for (x, g) in terms.iter_mut().zip(d.force()) {
        *x = x.abs() + g.abs();
    }
    for (r, l) in w.lambda_new.iter().enumerate() {
        for j in pattern.row(r) {
            terms[pattern.cols[j] as usize] += (jac[j] * l).abs();
        }
    }
    let (top, rows) = w.rhs.split_at(n);
    let largest = |x: &[f64]| x.iter().fold(0.0_f64, |a, x| a.max(x.abs()));
    largest(top) <= c_q * tolerance * largest(terms)
        && rows.iter().enumerate().all(|(r, x)| {
            let (values, over) = if w.holonomic[r] { (q, 1.0) } else { (v, gamma_prime) };
            let size: f64 = pattern.row(r).map(|j| (jac[j] * values[pattern.cols[j] as usize]).abs()).sum();
            x.abs() <= POSITION_ROUND_OFF * size / over
        })
}
