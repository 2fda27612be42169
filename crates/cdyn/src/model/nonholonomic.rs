//! Nonholonomic constraints `A(q, t) q̇ + b(q, t) = 0` as small local
//! elements, written once generic over the scalar like the holonomic ones.
//!
//! A nonholonomic row is stored as a constraint row whose position-level
//! value is identically zero, so that every consumer of the row data works
//! on it unchanged:
//!
//! | row data | holonomic `Φ(q, t)` | nonholonomic `g = A v + b` |
//! |---|---|---|
//! | `Φ` | `Φ` | `0` |
//! | `Φ̇` | `Φ_q v + Φ_t` | `A v + b` |
//! | Jacobian | `Φ_q` | `A` |
//! | `Φ_t` | `∂Φ/∂t` | `b` |
//! | `γ` | `−(Φ_q v)_q v − 2Φ_qt v − Φ_tt` | `−(Ȧ v + ḃ)` |
//!
//! What that means for each consumer:
//!
//! * the multiplier solve (Eqs. 6–8) enforces `A q̈ = γ`, the derivative of
//!   `A v + b = 0`, in the same Schur complement as the holonomic rows;
//! * the energy balance `Ė = F·v + λᵀ Φ_t` gets `λᵀ b`: the power of the
//!   constraint force `−Aᵀλ` on a motion with `A v = −b`. An ideal
//!   constraint (`b = 0`) does no work, and its `Φ_t` is exactly zero;
//! * Baumgarte's `α Φ̇ + β Φ` acts on `A v + b` through `α` alone;
//!   the velocity feedback ([`Velocity::Gradient`](crate::control::Velocity::Gradient)) is the
//!   gradient of `½ (Av + b)ᵀ Z_v (Av + b)` with respect to `v`;
//! * position-level controls (CVSGF, its coupled form) see `Φ = 0`: there is
//!   nothing to correct in `q`, and since `A` is a row of the Jacobian their
//!   corrections `Δq` satisfy `A Δq = 0`, a displacement the constraint
//!   allows;
//! * the constraint-respecting energy control moves `v` in the null space of
//!   `A` as well, so it does not push the state off `A v + b = 0`;
//! * the exact projection and assembly do the same: the Newton step on
//!   positions leaves these rows at zero (its correction respects `A Δq = 0`),
//!   and the velocity step removes `A v + b`;
//! * the automatic gains' coupling estimate of the paper's CVSGF counts the
//!   rows too; they only make it more cautious (larger `μ_max`).

use crate::ad::scalar::Scalar;
use crate::model::constraint::{ConstraintBlock, ConstraintValues, Local, columns_of, evaluate_items, group_layout};
use num_dual::Dual64;
use std::any::Any;

/// `R` nonholonomic constraints `A(q, t) v + b(q, t) = 0` on `K` coordinates
/// `q` with velocities `v`.
///
/// `eval` must be affine in `v` (no products of velocities, no functions of
/// them other than linear ones): the library reads `A` as the derivative
/// with respect to `v` and `b` as the value at `v = 0`.
///
/// A point mass on a plane that may only move along a heading turning with
/// time, `−sin(t) ẋ + cos(t) ẏ = 0`:
///
/// ```
/// use cdyn::{Control, Model, Nonholonomic, Scalar, Scheme, Settings, Simulation};
///
/// struct Heading;
/// impl Nonholonomic<2, 1> for Heading {
///     fn eval<D: Scalar>(&self, _q: [D; 2], [vx, vy]: [D; 2], t: D) -> [D; 1] {
///         [-t.sin() * vx + t.cos() * vy]
///     }
/// }
///
/// let model = Model::builder(vec![1.0, 1.0]).nonholonomic(Heading, [0, 1]).build()?;
/// let settings = Settings::new(Scheme::RungeKutta4, 1e-3, Control::none());
/// let mut sim = Simulation::new(&model, settings, &[0.0, 0.0], &[1.0, 0.0])?;
/// for _ in 0..1000 {
///     sim.step()?;
/// }
/// // The constraint force turns the velocity with the heading, at constant speed.
/// let (v, t) = (sim.v(), sim.t());
/// assert!((v[0] - t.cos()).abs() < 1e-9 && (v[1] - t.sin()).abs() < 1e-9);
/// # Ok::<(), cdyn::Error>(())
/// ```
pub trait Nonholonomic<const K: usize, const R: usize>: Send + Sync + 'static {
    /// `A(q, t) v + b(q, t)`; written once for every scalar type.
    fn eval<D: Scalar>(&self, q: [D; K], v: [D; K], t: D) -> [D; R];
}

/// A run of nonholonomic elements of one type.
pub(crate) struct NonholonomicGroup<C, const K: usize, const R: usize> {
    pub items: Vec<(C, [usize; K])>,
}

impl<C: Nonholonomic<K, R>, const K: usize, const R: usize> ConstraintBlock for NonholonomicGroup<C, K, R> {
    group_layout!();

    /// Nonholonomic rows have no position-level value.
    fn values(&self, _q: &[f64], _t: f64, phi: &mut [f64]) {
        phi.fill(0.0);
    }
    fn holonomic(&self) -> bool {
        false
    }
}

/// Differentiates one element at positions `x`, velocities `v`, free
/// accelerations `a` and time `t`: `K` dual passes in the velocities give
/// the columns of `A` (at `v = 0`, so that their values are `b` exactly),
/// one along `s ↦ g(x + s v, v, t + s)` gives `g` and `Ȧ v + ḃ = −γ`.
#[inline(always)]
pub(crate) fn local<C: Nonholonomic<K, R>, const K: usize, const R: usize>(
    c: &C,
    x: [f64; K],
    v: [f64; K],
    a: [f64; K],
    t: f64,
) -> Local<K, R> {
    let fixed = |s: &[f64; K]| s.map(Dual64::from);
    let along = c.eval(std::array::from_fn(|j| Dual64::new(x[j], v[j])), fixed(&v), Dual64::new(t, 1.0));
    let mut jac = [[0.0; K]; R];
    let mut b = [0.0; R];
    let mut ja = [0.0; R];
    for j in 0..K {
        let unit = std::array::from_fn(|i| Dual64::new(0.0, if i == j { 1.0 } else { 0.0 }));
        let rows = c.eval(fixed(&x), unit, Dual64::from(t));
        for r in 0..R {
            jac[r][j] = rows[r].eps;
            ja[r] += rows[r].eps * a[j];
            b[r] = rows[r].re;
        }
    }
    Local {
        phi: [0.0; R],
        phi_dot: along.map(|d| d.re),
        phi_t: b,
        gamma: along.map(|d| -d.eps),
        rhs: std::array::from_fn(|r| ja[r] + along[r].eps),
        jac,
    }
}
