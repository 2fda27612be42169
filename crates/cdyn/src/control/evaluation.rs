//! What the control laws read of one evaluation of the dynamics: the one
//! interface through which the laws ([`crate::control`]), the held
//! invariants ([`crate::control::held`]) and the automatic gains ([`crate::control::gains`])
//! see a general model's dynamics or a compile-time-sized system's.

use crate::dynamics::momentum::Momenta;
use crate::linalg::mass::MassMatrix;
use crate::model::unit_vector::UnitVector;

/// What the control laws read of one evaluation of the dynamics.
pub(crate) trait Evaluation {
    /// The kind of mass matrix.
    type Mass: MassMatrix;
    /// The mass matrix `M`.
    fn mass(&self) -> &Self::Mass;
    fn phi(&self) -> &[f64];
    fn phi_dot(&self) -> &[f64];
    /// `Ψ_q = ∇V + ∂T/∂q`: `∇V` when `M` is constant; with `M(q)` the
    /// energy's position gradient takes `∂T/∂q` too (the laws below read
    /// `Ψ_q` through this, never `∇V` alone).
    fn grad_potential(&self) -> &[f64];
    /// The uncontrolled acceleration `A`.
    fn acc(&self) -> &[f64];
    /// Row `r` of `Φ_q`: its entries and their coordinates.
    fn row(&self, r: usize) -> (&[f64], &[u32]);
    /// For a change `b` of the constraint right-hand side, adds the change
    /// of acceleration `−M⁻¹ Φ_qᵀ S⁻¹ b` to `out`; `b` is overwritten.
    fn add_constraint_response(&self, b: &mut [f64], out: &mut [f64]) {
        self.solve_many(&mut [b]);
        self.add_weighted_jt(b, -1.0, out);
    }

    /// Solves `S x = b` in place for every `b`, in one pass over the
    /// factorization of the last evaluation (`S = Φ_q M⁻¹ Φ_qᵀ`).
    fn solve_many(&self, b: &mut [&mut [f64]]);

    /// `out += scale · M⁻¹ Φ_qᵀ y`.
    fn add_weighted_jt(&self, y: &[f64], scale: f64, out: &mut [f64]);

    /// `out[k] −= M⁻¹ Φ_qᵀ y[k]` for two pairs, in one pass where the
    /// storage allows.
    fn add_weighted_jt_pair(&self, [y0, y1]: [&[f64]; 2], [out0, out1]: [&mut [f64]; 2]) {
        self.add_weighted_jt(y0, -1.0, out0);
        self.add_weighted_jt(y1, -1.0, out1);
    }

    /// `Φ_t`.
    fn phi_t(&self) -> &[f64];

    /// The model's unit vectors (see [`crate::model::unit_vector`]).
    fn unit_vectors(&self) -> &[UnitVector] {
        &[]
    }

    /// The momenta the run keeps, with `M E` at this state (see
    /// [`crate::dynamics::momentum`]): every correction is made M-orthogonal to them.
    fn momenta(&self) -> &Momenta {
        &NO_MOMENTA
    }

    /// `Φ_q w` for `w = M⁻¹Ψ_q`, where the evaluation has it from its own
    /// right-hand side (otherwise the laws form it with [`jac_mul`](Self::jac_mul)).
    fn kept_potential_rate(&self) -> Option<&[f64]> {
        None
    }

    /// `out = Φ_q w` for `w = M⁻¹Ψ_q`: the evaluation's own where it has it.
    fn potential_rate(&self, w: &[f64], out: &mut [f64]) {
        match self.kept_potential_rate() {
            Some(rate) => out.copy_from_slice(rate),
            None => self.jac_mul(w, out),
        }
    }

    /// `out = Φ_q x`.
    fn jac_mul(&self, x: &[f64], out: &mut [f64]) {
        for (r, o) in out.iter_mut().enumerate() {
            let (jac, cols) = self.row(r);
            *o = jac.iter().zip(cols).map(|(j, &c)| j * x[c as usize]).sum();
        }
    }
}

static NO_MOMENTA: Momenta = Momenta::NONE;
