//! Momenta the system keeps, and corrections that leave them alone.
//!
//! A constant direction `e` in the coordinates is a symmetry when moving
//! the whole state along it changes nothing the dynamics reads: the
//! constraints (`Φ_q e = 0`, and `A e = 0` for nonholonomic rows), the
//! energy (`∇V·e = 0`, `∂T/∂q·e = 0`) and the applied and damping forces
//! (`Q·e = 0`). Its generalized momentum `p = eᵀ M v` is then conserved:
//! `d/dt (∂T/∂v·e) = ∂T/∂q·e − ∇V·e + Q·e − λᵀΦ_q e = 0`. Rigid
//! translations of a free-floating system (its linear momentum) and cyclic
//! coordinates (a sled's heading rate) are such directions.
//!
//! Where `M e` is constant (`M` constant on the coordinates `e` moves)
//! `p` is linear in the state, `dp/dt = eᵀ M f_v(x) = 0` at every state,
//! and every explicit scheme keeps it to round-off; so does `eᵀ M q − p t`
//! (the centre of mass moves on a straight line). A control term `U`
//! keeps them too exactly when `Eᵀ M U_q = 0` and `Eᵀ M U_v = 0`: it is
//! M-orthogonal to the momentum directions. `Momenta::project` applies
//! the M-orthogonal projector `P_E = I − E (EᵀME)⁻¹ EᵀM` onto that
//! complement. Since `Φ_q E = 0`, `Φ_q P_E U = Φ_q U`: projecting a
//! correction changes nothing of what it does to the constraints.
//! The energy laws move the velocities along `P_E` of their direction,
//! with their gain set on what is left (`|P_E v|²_M = 2T − pᵀ(EᵀME)⁻¹p`,
//! the kinetic energy of the motion relative to the momenta), so that `Ψ`
//! still decays at its rate (docs: "Corrections that keep the momenta").

use crate::dynamics::Dynamics;
use crate::linalg::mass::MassMatrix;
use crate::linalg::{dot, norm};
use crate::model::Model;
use crate::model::angular::Generator;

/// The most momentum directions a run holds.
pub const MAX_MOMENTA: usize = 12;

/// Relative size below which a symmetry condition counts as met: `|r·e|`
/// against `|r| |e|` for a constraint row `r`, `|Ψ_q·e|` and `|Q·e|`
/// against `(|Ψ_q| + |Q|) |e|`.
pub const TOLERANCE: f64 = 1e-9;

/// How far a linear momentum may drift, relative to its [`Momentum::scale`],
/// and still count as kept to round-off: `10³ ε`.
pub const ROUND_OFF: f64 = 1e3 * f64::EPSILON;

pub use crate::model::Direction;

/// The most invariants a run holds beside the energy.
pub const MAX_HELD: usize = 6;

/// A momentum the system keeps, found when a run starts.
#[derive(Debug, Clone, PartialEq)]
pub struct Momentum {
    /// Its name: the direction's, or `momentum of sled.angle` for a cyclic
    /// coordinate by its name (`momentum of coordinate i` for a model
    /// without names).
    pub name: String,
    /// The direction `e`, one entry per coordinate.
    pub direction: Vec<f64>,
    /// The cyclic coordinate it is, if it is one.
    pub coordinate: Option<usize>,
    /// Declared by the user.
    pub declared: bool,
    /// `p = eᵀ M v` is linear in the state (`M e` constant): every explicit
    /// scheme keeps it to round-off. Otherwise it drifts at the scheme's
    /// truncation error, and the controls only do not add to that.
    pub linear: bool,
    /// `|e|_M |v₀|_M`: the largest `|p|` the initial kinetic energy allows,
    /// the size against which round-off in `p` is judged.
    pub scale: f64,
    /// What it is: a constant direction's momentum, a rotation's angular
    /// momentum (`direction` is then `ξ(q₀)`), or a declared invariant
    /// (`direction` is `M⁻¹ ∂I/∂v` at the initial state).
    pub kind: Kind,
    /// Its value at the initial state.
    pub initial: f64,
}

/// What a momentum is.
#[derive(Debug, Clone, PartialEq)]
pub enum Kind {
    /// `eᵀ M v` along a constant direction `e`.
    Constant,
    /// `ξ(q)ᵀ M v`, the angular momentum of a rigid rotation ([`crate::model::angular`]).
    Rotation(Generator),
    /// The model's declared invariant of this index ([`crate::model::invariant`]).
    Declared(usize),
}

/// A declared direction whose momentum the model does not keep.
#[derive(Debug, Clone, PartialEq)]
pub struct Broken {
    /// The direction's name.
    pub name: String,
    /// What breaks it, in a few words ("constraint row 3", "a force").
    pub reason: String,
    /// The direction `e`, one entry per coordinate (as [`Momentum::direction`]).
    pub direction: Vec<f64>,
    /// What it is.
    pub kind: Kind,
}

/// What [`detect`] found.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Symmetries {
    /// The momenta kept, linearly independent, declared ones first.
    pub kept: Vec<Momentum>,
    /// Declared directions the model breaks (not held).
    pub broken: Vec<Broken>,
}

impl Symmetries {
    /// None found.
    pub const NONE: Symmetries = Symmetries { kept: Vec::new(), broken: Vec::new() };

    /// The direction and kind of momentum `j`: the kept ones, then the
    /// broken declared ones.
    pub fn direction(&self, j: usize) -> (&[f64], &Kind) {
        match self.kept.get(j) {
            Some(m) => (&m.direction, &m.kind),
            None => {
                let b = &self.broken[j - self.kept.len()];
                (&b.direction, &b.kind)
            }
        }
    }
}

/// A small deterministic generator for the sample states.
struct Lcg(u64);

impl Lcg {
    /// Uniform in `[−1, 1)`.
    fn next(&mut self) -> f64 {
        self.0 = self.0.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        ((self.0 >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0
    }
}

/// Times at which the random samples are taken (time-dependent forces
/// and drives are seen there).
const SAMPLE_TIMES: [f64; 3] = [0.613, 1.37, 3.1];

/// One evaluated sample state: its data the checks read.
struct Sample {
    /// The state.
    q: Vec<f64>,
    v: Vec<f64>,
    t: f64,
    /// `Φ_q` in the model's pattern order.
    jac: Vec<f64>,
    /// `Ψ_q = ∇V + ∂T/∂q`.
    psi_q: Vec<f64>,
    /// The non-conservative forces `Q`.
    force: Vec<f64>,
    /// `M v`.
    mass_v: Vec<f64>,
    /// The uncontrolled acceleration `v̇`.
    acc: Vec<f64>,
}

/// The consistent states the symmetry conditions are checked at: the
/// initial one, and random ones around it projected onto `Φ = 0` and
/// `Φ̇ = 0` (a sample whose projection fails is left out).
fn sample_states(model: &Model, q0: &[f64], v0: &[f64]) -> Vec<(Vec<f64>, Vec<f64>, f64)> {
    let mut states = vec![(q0.to_vec(), v0.to_vec(), 0.0)];
    let mut d = Dynamics::new(model);
    let mut work = crate::dynamics::manifold::Work::new(model);
    let mut rng = Lcg(0x5eed_cafe);
    let q_scale = 0.05 * (1.0 + q0.iter().fold(0.0_f64, |a, x| a.max(x.abs())));
    let v_scale = 0.5 * (1.0 + v0.iter().fold(0.0_f64, |a, x| a.max(x.abs())));
    for t in SAMPLE_TIMES {
        let mut q: Vec<f64> = q0.iter().map(|x| x + q_scale * rng.next()).collect();
        let mut v: Vec<f64> = v0.iter().map(|x| x + v_scale * rng.next()).collect();
        if crate::dynamics::manifold::positions(model, &mut d, &mut q, &mut v, t, 1e-12, 30, &mut work).is_err() {
            continue;
        }
        crate::dynamics::manifold::velocities(model, &d, &mut v, &mut work);
        states.push((q, v, t));
    }
    states
}

/// What breaks the symmetry along `e` (dense) at sample `s`, if anything.
/// `lifted` is what the velocities' own change adds to the energy's rate
/// (`(M v)·(B v)` for a rotation, [`crate::model::angular`]; 0 for a constant `e`)
/// and the size its round-off is judged against (`|M v| |B v|`).
fn breaks(model: &Model, s: &Sample, e: &[f64], [lifted, lifted_size]: [f64; 2]) -> Option<String> {
    let size = norm(e);
    let pattern = model.pattern();
    for r in 0..model.m() {
        let range = pattern.row(r);
        let (jac, cols) = (&s.jac[range.clone()], &pattern.cols[range]);
        let along: f64 = jac.iter().zip(cols).map(|(j, &c)| j * e[c as usize]).sum();
        if along.abs() > TOLERANCE * norm(jac) * size {
            return Some(format!("constraint row {r}"));
        }
    }
    let scale = TOLERANCE * ((norm(&s.psi_q) + norm(&s.force)) * size + lifted_size);
    if (dot(&s.psi_q, e) + lifted).abs() > scale {
        return Some("the potential or kinetic energy".into());
    }
    if dot(&s.force, e).abs() > scale {
        return Some("a force".into());
    }
    None
}

/// What breaks the symmetry under the rotation `g` at sample `s`, if
/// anything: `Φ_q ξ`, the energy's change under the rotation lifted to
/// the velocities, `Ψ_q·ξ + (M v)·(B v)`, or `Q·ξ`. `xi` has `n` entries.
fn breaks_rotation(model: &Model, s: &Sample, g: &Generator, xi: &mut [f64]) -> Option<String> {
    g.turn(&s.v, xi);
    let lifted = [dot(&s.mass_v, xi), norm(&s.mass_v) * norm(xi)];
    g.at(&s.q, xi);
    breaks(model, s, xi, lifted)
}

/// Whether the uncontrolled motion moves declared invariant `i` at
/// sample `s`: `dI/dt = ∂I/∂q·v + ∂I/∂v·v̇` against the size of its terms.
fn breaks_declared(model: &Model, s: &Sample, i: usize) -> Option<String> {
    let n = model.n();
    let (mut grad_q, mut grad_v) = (vec![0.0; n], vec![0.0; n]);
    model.declared_invariants()[i].block.gradients(&s.q, &s.v, &mut grad_q, &mut grad_v);
    let rate = dot(&grad_q, &s.v) + dot(&grad_v, &s.acc);
    let size = norm(&grad_q) * norm(&s.v) + norm(&grad_v) * norm(&s.acc);
    if size == 0.0 {
        return Some("it reads nothing that moves".into());
    }
    (rate.abs() > TOLERANCE * size).then(|| format!("the motion changes it (dI/dt = {rate:.3e} at t = {})", s.t))
}

/// Finds the momenta `model` keeps: its declared and mechanism directions
/// and every single coordinate (a cyclic one), checked at the initial state
/// `(q0, v0)` and at random consistent states around it. A direction that
/// one constraint row, the energy or a force breaks at any sample is not
/// kept; the kept ones are made linearly independent in the metric `M`
/// (a coordinate that is also a translation is named once), at most
/// [`MAX_MOMENTA`]. Memory and work are linear in the model's size: a
/// coordinate is checked from its column, and only a direction that passes
/// is formed densely.
pub fn detect(model: &Model, q0: &[f64], v0: &[f64]) -> Symmetries {
    let n = model.n();
    let named: Vec<Direction> = model.momentum_directions().to_vec();
    let mut d = Dynamics::new(model);
    let mut samples = Vec::new();
    for (q, v, t) in sample_states(model, q0, v0) {
        if d.evaluate(model, &q, &v, t).is_err() {
            continue;
        }
        let mut force = vec![0.0; n];
        model.add_forces(&q, &v, t, &mut force);
        let mut mass_v = vec![0.0; n];
        d.mass(model).mul(&v, &mut mass_v);
        let (jac, psi_q, acc) = (d.jac().to_vec(), d.psi_q().to_vec(), d.acc().to_vec());
        samples.push(Sample { jac, psi_q, force, mass_v, acc, q, v, t });
    }
    let mut found = Symmetries::default();
    if samples.is_empty() {
        return found;
    }
    // A coordinate breaks when its column of Φ_q is not negligible in some
    // row, or the energy or a force acts on it: found for all coordinates
    // in one pass over each sample.
    let pattern = model.pattern();
    let mut coordinate_broken: Vec<Option<String>> = vec![None; n];
    for s in &samples {
        for r in 0..model.m() {
            let range = pattern.row(r);
            let jac = &s.jac[range.clone()];
            let limit = TOLERANCE * norm(jac);
            for (j, &c) in jac.iter().zip(&pattern.cols[range]) {
                if j.abs() > limit && coordinate_broken[c as usize].is_none() {
                    coordinate_broken[c as usize] = Some(format!("constraint row {r}"));
                }
            }
        }
        let scale = TOLERANCE * (norm(&s.psi_q) + norm(&s.force));
        for i in 0..n {
            if coordinate_broken[i].is_none() && (s.psi_q[i].abs() > scale || s.force[i].abs() > scale) {
                coordinate_broken[i] = Some("the energy or a force".into());
            }
        }
    }
    let names = model.coordinate_names();
    let coordinates = (0..n).filter(|&i| coordinate_broken[i].is_none()).map(|i| {
        let name = match names {
            Some(names) => format!("momentum of {}", names[i]),
            None => format!("momentum of coordinate {i}"),
        };
        (Direction { name, entries: vec![(i as u32, 1.0)], declared: false }, Some(i))
    });
    let rotations: Vec<Generator> = model.rotations().to_vec();
    // What the user declared first (its name wins over a builder's
    // proposal of the same momentum), then the builder's, then the cyclic
    // coordinates.
    let (declared_directions, proposed): (Vec<_>, Vec<_>) = named.into_iter().partition(|d| d.declared);
    let (declared_rotations, proposed_rotations): (Vec<_>, Vec<_>) = rotations.into_iter().partition(|g| g.declared);
    let candidates = declared_directions
        .into_iter()
        .map(|d| Candidate::Direction(d, None))
        .chain(declared_rotations.into_iter().map(Candidate::Rotation))
        .chain((0..model.declared_invariants().len()).map(Candidate::Declared))
        .chain(proposed.into_iter().map(|d| Candidate::Direction(d, None)))
        .chain(coordinates.map(|(d, i)| Candidate::Direction(d, i)))
        .chain(proposed_rotations.into_iter().map(Candidate::Rotation));
    // The kept directions, made independent by Gram–Schmidt in the metric
    // `M` at the first sample: each basis vector stored as (e_b, M e_b),
    // normalized. A rotation takes part with ξ(q₀), a declared invariant
    // with M⁻¹ ∂I/∂v at the initial state.
    let mut basis: Vec<Vec<f64>> = Vec::new();
    let mut work = vec![0.0; n];
    let mut held = 0;
    for candidate in candidates {
        let mut e = vec![0.0; n];
        let (name, declared, coordinate, kind) = match candidate {
            Candidate::Direction(direction, coordinate) => {
                direction.entries.iter().for_each(|&(c, w)| e[c as usize] += w);
                (direction.name, direction.declared, coordinate, Kind::Constant)
            }
            Candidate::Rotation(g) => (g.name.clone(), g.declared, None, Kind::Rotation(g)),
            Candidate::Declared(i) => (model.declared_invariants()[i].name.clone(), true, None, Kind::Declared(i)),
        };
        let broken = match (&kind, coordinate) {
            (Kind::Rotation(g), _) => samples.iter().find_map(|s| breaks_rotation(model, s, g, &mut work)),
            (Kind::Declared(i), _) => samples.iter().find_map(|s| breaks_declared(model, s, *i)),
            (Kind::Constant, None) => samples.iter().find_map(|s| breaks(model, s, &e, [0.0; 2])),
            // Checked from its column above.
            (Kind::Constant, Some(_)) => None,
        };
        let initial = match &kind {
            Kind::Rotation(g) => {
                g.at(q0, &mut e);
                value(model, q0, v0, &e, &mut work)
            }
            Kind::Declared(i) => {
                let mut grad_q = vec![0.0; n];
                let block = &model.declared_invariants()[*i].block;
                let initial = block.gradients(q0, v0, &mut grad_q, &mut work);
                if d.evaluate(model, q0, v0, 0.0).is_ok() {
                    d.mass(model).solve(&work, &mut e);
                }
                initial
            }
            Kind::Constant => value(model, q0, v0, &e, &mut work),
        };
        if let Some(reason) = broken {
            if declared {
                found.broken.push(Broken { name, reason, direction: e, kind });
            }
            continue;
        }
        let full = match kind {
            Kind::Constant => found.kept.len() - held == MAX_MOMENTA,
            _ => held == MAX_HELD,
        };
        if full {
            continue;
        }
        // `M e` and `M v` at every sample.
        let mut mass_e = Vec::with_capacity(samples.len());
        let mut mass_v = vec![0.0; n];
        for (k, s) in samples.iter().enumerate() {
            if d.evaluate(model, &s.q, &s.v, s.t).is_err() {
                continue;
            }
            let mass = d.mass(model);
            let mut out = vec![0.0; n];
            mass.mul(&e, &mut out);
            mass_e.push(out);
            if k == 0 {
                mass.mul(v0, &mut mass_v);
            }
        }
        let Some(first) = mass_e.first() else { continue };
        let mut residual_m = first.clone();
        let mut residual = e.clone();
        for b in &basis {
            let (be, bm) = b.split_at(n);
            let c = dot(be, &residual_m);
            residual.iter_mut().zip(be).for_each(|(r, x)| *r -= c * x);
            residual_m.iter_mut().zip(bm).for_each(|(r, x)| *r -= c * x);
        }
        let size = dot(&e, first);
        let left = dot(&residual, &residual_m);
        if left.is_nan() || left <= 1e-16 * size {
            continue;
        }
        let scale = left.sqrt();
        basis.push(residual.iter().chain(&residual_m).map(|x| x / scale).collect());
        let tolerance = 1e-12 * norm(first);
        let constant = kind == Kind::Constant;
        let linear = constant && mass_e.iter().all(|m| m.iter().zip(first).all(|(a, b)| (a - b).abs() <= tolerance));
        held += usize::from(!constant);
        found.kept.push(Momentum {
            name,
            coordinate,
            declared,
            linear,
            scale: (size * dot(v0, &mass_v)).max(0.0).sqrt(),
            initial,
            direction: e,
            kind,
        });
    }
    found
}

/// A direction, a rotation or a declared invariant to check.
enum Candidate {
    /// A constant direction; a single coordinate's index when it is one.
    Direction(Direction, Option<usize>),
    Rotation(Generator),
    Declared(usize),
}

/// `p = eᵀ M(q) v` for a dense direction `e`: exact for a constant `M`;
/// otherwise `(T(q, v + s e) − T(q, v − s e)) / 2s`, exact for a quadratic
/// `T`, with `s = |v|_M / |e|_M` so both terms are of the size of `T`.
/// `work` has `n` entries.
pub fn value(model: &Model, q: &[f64], v: &[f64], e: &[f64], work: &mut [f64]) -> f64 {
    if let Some(mass) = model.mass() {
        return mass.diagonal().iter().zip(e).zip(v).map(|((m, e), v)| m * e * v).sum();
    }
    let (tv, te) = (model.kinetic(q, v), model.kinetic(q, e));
    if te == 0.0 {
        return 0.0;
    }
    let s = if tv > 0.0 { (tv / te).sqrt() } else { 1.0 };
    let mut at = |sign: f64| {
        work.iter_mut().zip(v).zip(e).for_each(|((w, v), e)| *w = v + sign * s * e);
        model.kinetic(q, work)
    };
    (at(1.0) - at(-1.0)) / (2.0 * s)
}

/// The kept momentum directions at run time: `E`, `M E` at the latest
/// evaluation and the inverse of `EᵀME`, so that a correction is made
/// M-orthogonal to them with `k` dot products and `k` updates.
#[derive(Debug, Clone, Default)]
pub(crate) struct Momenta {
    /// `k × n`: the directions, row by row.
    e: Vec<f64>,
    /// `k × n`: `M e_j`.
    mass_e: Vec<f64>,
    /// `k × k`: `(EᵀME)⁻¹`.
    gram_inverse: Vec<f64>,
    /// `M e` is the same at every state: set once.
    constant: bool,
    /// `M E` has been formed.
    ready: bool,
    n: usize,
}

impl Momenta {
    /// No directions: every operation is a no-op.
    pub(crate) const NONE: Momenta =
        Momenta { e: Vec::new(), mass_e: Vec::new(), gram_inverse: Vec::new(), constant: true, ready: true, n: 0 };

    /// The constant directions of `kept` (not the rotations), for a model of `n` coordinates; `M e` is
    /// set by [`update`](Self::update).
    pub(crate) fn new(kept: &[Momentum], n: usize, constant: bool) -> Self {
        let constant_directions = || kept.iter().filter(|m| m.kind == Kind::Constant);
        let k = constant_directions().count();
        Self {
            e: constant_directions().flat_map(|m| m.direction.iter().copied()).collect(),
            mass_e: vec![0.0; k * n],
            gram_inverse: vec![0.0; k * k],
            constant,
            ready: k == 0,
            n,
        }
    }

    /// Number of directions.
    #[inline(always)]
    pub(crate) fn len(&self) -> usize {
        self.gram_inverse.len().isqrt()
    }

    /// Whether there are none.
    #[inline(always)]
    pub(crate) fn is_empty(&self) -> bool {
        self.gram_inverse.is_empty()
    }

    /// Whether `M E` must be formed (again) at the current state.
    #[inline(always)]
    pub(crate) fn stale(&self) -> bool {
        !self.is_empty() && (!self.ready || !self.constant)
    }

    /// `M E` and `(EᵀME)⁻¹` from the mass matrix at the current state.
    pub(crate) fn update(&mut self, mass: &impl MassMatrix) {
        let (k, n) = (self.len(), self.n);
        for j in 0..k {
            mass.mul(&self.e[j * n..(j + 1) * n], &mut self.mass_e[j * n..(j + 1) * n]);
        }
        let mut gram = [0.0; MAX_MOMENTA * MAX_MOMENTA];
        for a in 0..k {
            for b in 0..k {
                gram[a * k + b] = dot(&self.e[a * n..(a + 1) * n], &self.mass_e[b * n..(b + 1) * n]);
            }
        }
        invert(&mut gram[..k * k], k, &mut self.gram_inverse);
        self.ready = true;
    }

    /// `a = (EᵀME)⁻¹ Eᵀ M x`: the coefficients of `x`'s part along the
    /// momentum directions.
    #[inline]
    pub(crate) fn coefficients(&self, x: &[f64]) -> [f64; MAX_MOMENTA] {
        let (k, n) = (self.len(), self.n);
        let mut p = [0.0; MAX_MOMENTA];
        for j in 0..k {
            p[j] = dot(&self.mass_e[j * n..(j + 1) * n], x);
        }
        let mut a = [0.0; MAX_MOMENTA];
        for i in 0..k {
            a[i] = (0..k).map(|j| self.gram_inverse[i * k + j] * p[j]).sum();
        }
        a
    }

    /// `out += scale · E a`.
    #[inline]
    pub(crate) fn add_directions(&self, a: &[f64; MAX_MOMENTA], scale: f64, out: &mut [f64]) {
        let n = self.n;
        for (j, &aj) in a.iter().enumerate().take(self.len()) {
            let s = scale * aj;
            out.iter_mut().zip(&self.e[j * n..(j + 1) * n]).for_each(|(o, e)| *o += s * e);
        }
    }

    /// `x ← P_E x = x − E (EᵀME)⁻¹ EᵀM x`: no part left along any momentum
    /// direction in the metric `M`.
    #[inline]
    pub(crate) fn project(&self, x: &mut [f64]) {
        if self.is_empty() {
            return;
        }
        let a = self.coefficients(x);
        self.add_directions(&a, -1.0, x);
    }

    /// `x`'s coefficients `a` along the momentum directions and the part
    /// of `|x|²_M` along them, `(EᵀMx)ᵀ (EᵀME)⁻¹ (EᵀMx) = aᵀ EᵀMx`.
    #[inline]
    pub(crate) fn split(&self, x: &[f64]) -> ([f64; MAX_MOMENTA], f64) {
        if self.is_empty() {
            return ([0.0; MAX_MOMENTA], 0.0);
        }
        let a = self.coefficients(x);
        let n = self.n;
        (a, (0..self.len()).map(|j| a[j] * dot(&self.mass_e[j * n..(j + 1) * n], x)).sum())
    }
}

/// `out = a⁻¹` for a symmetric positive definite `k × k` matrix `a`
/// (overwritten), by Gauss–Jordan elimination; `k` is small.
fn invert(a: &mut [f64], k: usize, out: &mut [f64]) {
    out.fill(0.0);
    for i in 0..k {
        out[i * k + i] = 1.0;
    }
    for c in 0..k {
        let pivot = a[c * k + c];
        for j in 0..k {
            a[c * k + j] /= pivot;
            out[c * k + j] /= pivot;
        }
        for r in (0..k).filter(|&r| r != c) {
            let f = a[r * k + c];
            if f != 0.0 {
                for j in 0..k {
                    a[r * k + j] -= f * a[c * k + j];
                    out[r * k + j] -= f * out[c * k + j];
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_inverse_of_a_small_gram_matrix() {
        let mut a = [4.0, 1.0, 0.5, 1.0, 3.0, 0.2, 0.5, 0.2, 2.0];
        let original = a;
        let mut inv = [0.0; 9];
        invert(&mut a, 3, &mut inv);
        for i in 0..3 {
            for j in 0..3 {
                let x: f64 = (0..3).map(|l| original[i * 3 + l] * inv[l * 3 + j]).sum();
                assert!((x - if i == j { 1.0 } else { 0.0 }).abs() < 1e-14);
            }
        }
    }
}
