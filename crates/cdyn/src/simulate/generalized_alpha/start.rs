//! The scheme's buffers, made once per model, and its start: consistent
//! accelerations and multipliers, and the first Newton matrix.

use super::newton::newton_matrix;
use super::*;

impl Work {
    /// For `model`, with the mass matrix as `d` holds it, what a dependent
    /// constraint row does (as `d` is set to), and whether a projection
    /// follows every step.
    pub(crate) fn new(
        model: &Model,
        d: &Dynamics,
        settings: GeneralizedAlpha,
        dependent: DependentRows,
        projected: bool,
    ) -> Self {
        let (n, m) = (model.n(), model.m());
        let mut entries = Vec::new();
        d.mass(model).entries(&mut entries);
        let mass_entries = entries.len();
        model.iteration_entries(&mut entries);
        let force_entries = entries.len() - mass_entries;
        model.curvature_entries(&mut entries);
        let element_entries = entries.len() - mass_entries;
        let pattern = model.pattern();
        for r in 0..m {
            for j in pattern.row(r) {
                entries.push(((n + r) as u32, pattern.cols[j]));
            }
        }
        for r in 0..m {
            for j in pattern.row(r) {
                entries.push((pattern.cols[j], (n + r) as u32));
            }
        }
        // The zero block's diagonal, listed for the pivoting's sake.
        entries.extend((n..n + m).map(|i| (i as u32, i as u32)));
        Self {
            settings,
            holonomic: model.holonomic_rows(),
            tolerate: dependent == DependentRows::Tolerate,
            dropped: vec![false; m],
            any_dropped: false,
            probe: vec![0.0; m],
            mass_entries,
            force_entries,
            element_entries,
            values: vec![0.0; entries.len()],
            lu: Lu::new(n + m, n, &entries),
            acc: vec![0.0; n],
            aux: vec![0.0; n],
            lambda: vec![0.0; m],
            started: false,
            power: 0.0,
            projected,
            acc_new: vec![0.0; n],
            aux_new: vec![0.0; n],
            lambda_new: vec![0.0; m],
            q0: vec![0.0; n],
            v0: vec![0.0; n],
            rhs: vec![0.0; n + m],
            base: vec![0.0; n + m],
            along: vec![0.0; n + m],
            terms: vec![0.0; n],
        }
    }
}

impl Work {
    pub(super) fn scaling(&self, h: f64) -> Scaling {
        let [alpha_m, alpha_f, gamma, beta] = self.settings.coefficients();
        let beta_prime = (1.0 - alpha_m) / (h * h * beta * (1.0 - alpha_f));
        let gamma_prime = gamma / (h * beta);
        Scaling { beta_prime, gamma_prime, c_q: 1.0 / beta_prime, c_v: gamma_prime / beta_prime }
    }

    /// Consistent accelerations and multipliers at `(q, v, t)`, `a_0 =
    /// q̈_0`; and one factorization of the Newton matrix there, which sizes
    /// the factors' storage for the pivoting of the steps to come.
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn start(
        &mut self,
        model: &Model,
        d: &mut Dynamics,
        q: &[f64],
        v: &[f64],
        t: f64,
        h: f64,
        evaluations: &mut u64,
    ) -> std::result::Result<(), Failure> {
        self.restart(model, d, q, v, t, evaluations)?;
        let Scaling { c_q, c_v, .. } = self.scaling(h);
        newton_matrix(model, d, q, v, t, c_q, c_v, self);
        self.lu.reserve(&self.values);
        Ok(())
    }

    /// Starts again at `(q, v, t)` from the accelerations there, as after
    /// an input changed the forces: `q̈`, `a`, `λ` and `Ė` of one evaluation.
    pub(crate) fn restart(
        &mut self,
        model: &Model,
        d: &mut Dynamics,
        q: &[f64],
        v: &[f64],
        t: f64,
        evaluations: &mut u64,
    ) -> std::result::Result<(), Failure> {
        *evaluations += 1;
        d.evaluate(model, q, v, t).map_err(|b| Failure::Breakdown(b, t))?;
        self.find_dropped(d);
        self.acc.copy_from_slice(d.acc());
        self.aux.copy_from_slice(d.acc());
        self.lambda.copy_from_slice(d.lambda());
        self.lambda_new.copy_from_slice(d.lambda());
        self.power = d.energy_input();
        self.started = true;
        Ok(())
    }

    /// After a full evaluation with [`DependentRows::Tolerate`], marks the
    /// rows it dropped: their multipliers are exactly 0 in every solve with
    /// its factorization (see `linalg::schur`), so a solve of a right-hand
    /// side with no zero entry finds them. Their multipliers are set to 0.
    pub(super) fn find_dropped(&mut self, d: &Dynamics) {
        if !self.tolerate || (d.dependent_rows() == 0 && !self.any_dropped) {
            return;
        }
        self.any_dropped = d.dependent_rows() > 0;
        if self.any_dropped {
            // Generic values, none zero, so that no independent row's solution is 0 by chance.
            for (r, p) in self.probe.iter_mut().enumerate() {
                *p = 1.0 + (r as f64 * 0.618_033_988_749_895).fract();
            }
            d.solve_many(&mut [&mut self.probe]);
        }
        for ((dropped, p), l) in self.dropped.iter_mut().zip(&self.probe).zip(&mut self.lambda_new) {
            *dropped = self.any_dropped && *p == 0.0;
            if *dropped {
                *l = 0.0;
            }
        }
    }
}
