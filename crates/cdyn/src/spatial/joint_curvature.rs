//! A joint's curvature `Σ_r w_r ∇²Φ_r` in closed form, for the Newton
//! matrix of an implicit step: where one hyper-dual pass per pair of its
//! 14 coordinates (105 passes) took most of a generalized-α step.
//!
//! Every row of a joint without drives is a component of `x_b − x_a`, a
//! dot product `u_a · v_b` of vectors on the two sides, `u_a · (x_b − x_a)`
//! or `|x_b − x_a|²`, where each side's vector is `A(p)s` (plus `r` for a
//! point). `A(p)s` is a quadratic form in `p`, so its second derivatives
//! are the same at every pose ([`rotate_hessian`]). The product rule does
//! the rest: `∇²(u · v) = Σᵢ (vᵢ ∇²uᵢ + uᵢ ∇²vᵢ + ∇uᵢ ⊗ ∇vᵢ + ∇vᵢ ⊗ ∇uᵢ)`.

use super::joint::JointKind;
use super::joint_element::{Sided, SidedPlace};
use super::joint_rows::{F, G, H, JointRows};
use super::rotation::rotate_hessian;

/// Where a side's seven coordinates `(r, p)` start among the element's,
/// `None` for the ground.
pub(super) type At = Option<usize>;

/// A side vector's gradient over the element's `K` coordinates.
pub(super) fn wide<const K: usize>(u: &Sided, at: At) -> [[f64; K]; 3] {
    let mut g = [[0.0; K]; 3];
    if let Some(at) = at {
        for i in 0..3 {
            g[i][at..at + 7].copy_from_slice(&u.d[i]);
        }
    }
    g
}

/// `out += Σᵢ cᵢ ∇²uᵢ`, on the side's `p` alone (`r` enters linearly).
pub(super) fn curve<const K: usize>(out: &mut [[f64; K]; K], u: &Sided, at: At, c: [f64; 3]) {
    if let Some(at) = at {
        add_rotation_block(out, at, rotate_hessian(u.s, c));
    }
}

/// `out += h` on the `p` of the side whose seven coordinates start at `at`.
pub(super) fn add_rotation_block<const K: usize>(out: &mut [[f64; K]; K], at: usize, h: [[f64; 4]; 4]) {
    for k in 0..4 {
        for l in 0..4 {
            out[at + 3 + k][at + 3 + l] += h[k][l];
        }
    }
}

/// `out += w Σᵢ (gᵢ ⊗ hᵢ + hᵢ ⊗ gᵢ)` of two vectors' gradients.
pub(super) fn outer<const K: usize>(out: &mut [[f64; K]; K], g: &[[f64; K]; 3], h: &[[f64; K]; 3], w: f64) {
    for i in 0..K {
        for j in 0..K {
            out[i][j] += w * (0..3).map(|c| g[c][i] * h[c][j] + h[c][i] * g[c][j]).sum::<f64>();
        }
    }
}

/// `out += w (∇u ⊗ ∇v + ∇v ⊗ ∇u)` for a vector `u` of the side whose
/// coordinates start at `at_u` and `v` of the other side: only the two
/// blocks between the sides (a side's vector has no gradient on the
/// other's coordinates), where [`outer`] runs over every pair of the
/// element's (UR5: 4 % of a generalized-α step, nine tenths of it zeros).
fn outer_across<const K: usize>(out: &mut [[f64; K]; K], u: &Sided, at_u: At, v: &Sided, at_v: At, w: f64) {
    let (Some(at_u), Some(at_v)) = (at_u, at_v) else { return };
    for i in 0..7 {
        for j in 0..7 {
            let x = w * (0..3).map(|c| u.d[c][i] * v.d[c][j]).sum::<f64>();
            out[at_u + i][at_v + j] += x;
            out[at_v + j][at_u + i] += x;
        }
    }
}

impl<const R: usize> JointRows<R> {
    /// `Σ_r w_r ∇²Φ_r` of [`kinematic_rows`](Self::kinematic_rows) over the
    /// element's `K` coordinates, side `a`'s from `at[0]`, side `b`'s from
    /// `at[1]`; only for a joint without drives, whose rows these are.
    pub(super) fn kinematic_curvature<const K: usize>(
        &self,
        a: &impl SidedPlace,
        b: &impl SidedPlace,
        at: [At; 2],
        w: &[f64; R],
    ) -> [[f64; K]; K] {
        let mut out = [[0.0; K]; K];
        let (pa, pb) = (a.point(), b.point());
        let gap: [f64; 3] = std::array::from_fn(|i| pb.x[i] - pa.x[i]);
        let (ga, gb) = (wide::<K>(&pa, at[0]), wide::<K>(&pb, at[1]));
        let gap_g: [[f64; K]; 3] = std::array::from_fn(|c| std::array::from_fn(|j| gb[c][j] - ga[c][j]));
        let scaled = |x: [f64; 3], s: f64| x.map(|x| s * x);
        // Rows 0–2: x_b − x_a, weighted together.
        let spherical = |out: &mut [[f64; K]; K]| {
            let c = [w[0], w[1], w[2]];
            curve(out, &pb, at[1], c);
            curve(out, &pa, at[0], scaled(c, -1.0));
        };
        // u_a · v_b
        let across = |out: &mut [[f64; K]; K], u: &Sided, v: &Sided, w: f64| {
            curve(out, u, at[0], scaled(v.x, w));
            curve(out, v, at[1], scaled(u.x, w));
            outer_across(out, u, at[0], v, at[1], w);
        };
        // u_a · (x_b − x_a)
        let along_gap = |out: &mut [[f64; K]; K], u: &Sided, w: f64| {
            curve(out, u, at[0], scaled(gap, w));
            curve(out, &pb, at[1], scaled(u.x, w));
            curve(out, &pa, at[0], scaled(u.x, -w));
            outer(out, &wide(u, at[0]), &gap_g, w);
        };
        let o = &mut out;
        match self.kind {
            JointKind::Spherical => spherical(o),
            JointKind::Revolute => {
                let hb = b.axis(H);
                spherical(o);
                across(o, &a.axis(F), &hb, w[3]);
                across(o, &a.axis(G), &hb, w[4]);
            }
            JointKind::Universal => {
                spherical(o);
                across(o, &a.axis(H), &b.axis(H), w[3]);
            }
            JointKind::Cylindrical | JointKind::Prismatic => {
                let (fa, ga, hb) = (a.axis(F), a.axis(G), b.axis(H));
                across(o, &fa, &hb, w[0]);
                across(o, &ga, &hb, w[1]);
                along_gap(o, &fa, w[2]);
                along_gap(o, &ga, w[3]);
                if self.kind == JointKind::Prismatic {
                    across(o, &fa, &b.axis(G), w[4]);
                }
            }
            JointKind::Fixed => {
                spherical(o);
                across(o, &a.axis(F), &b.axis(G), w[3]);
                across(o, &a.axis(G), &b.axis(H), w[4]);
                across(o, &a.axis(H), &b.axis(F), w[5]);
            }
            JointKind::Distance => {
                // |x_b − x_a|² − ℓ²
                outer(o, &gap_g, &gap_g, w[0]);
                curve(o, &pb, at[1], scaled(gap, 2.0 * w[0]));
                curve(o, &pa, at[0], scaled(gap, -2.0 * w[0]));
            }
        }
        out
    }
}
