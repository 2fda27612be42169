//! Finding the symmetries at the start of a run: each candidate checked at
//! the initial state and at random consistent states against the
//! constraints, the energy and the forces.

use crate::dynamics::Dynamics;
use crate::linalg::mass::MassMatrix;
use crate::linalg::{dot, norm};
use crate::model::Model;
use crate::model::angular::Generator;
use crate::random::Lcg;

use super::*;

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
