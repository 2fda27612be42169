//! Where an element's ends are in the coordinates it reads: on the ground, at
//! a point mass, or at a point of a rigid body. The constraint, potential and
//! force elements are written on these ends, generic over the scalar and
//! over how many coordinates they read.

use crate::ad::scalar::Scalar;

/// Runs `$body` with the const `$k` equal to `$idx.len()` (1 to 6: an
/// element reads at most two bodies): the elements are generic over how
/// many coordinates they read.
macro_rules! with_k {
    ($idx:expr, $k:ident, $body:expr) => {
        crate::with_const!($idx.len(), $k, [1, 2, 3, 4, 5, 6], $body)
    };
}
pub(super) use with_k;

pub(super) fn idx_array<const K: usize>(idx: &[usize]) -> [usize; K] {
    std::array::from_fn(|j| idx[j])
}

/// One end of an element: where its point is, given the element's local coordinates.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) enum End {
    Ground { point: [f64; 2] },
    Point { at: usize },
    Rigid { at: usize, local: [f64; 2] },
}

impl End {
    /// World position of the point.
    #[inline(always)]
    pub(super) fn position<D: Scalar, const K: usize>(&self, x: &[D; K]) -> [D; 2] {
        match *self {
            End::Ground { point } => [D::from(point[0]), D::from(point[1])],
            End::Point { at } => [pick(x, at), pick(x, at + 1)],
            End::Rigid { at, local: [lx, ly] } => {
                let phi = pick(x, at + 2);
                let (s, c) = (phi.sin(), phi.cos());
                [pick(x, at) + c * lx - s * ly, pick(x, at + 1) + s * lx + c * ly]
            }
        }
    }

    /// World velocity of the point.
    #[inline(always)]
    pub(super) fn velocity<D: Scalar>(&self, x: &[D], xd: &[D]) -> [D; 2] {
        match *self {
            End::Ground { .. } => [D::from(0.0); 2],
            End::Point { at } => [xd[at], xd[at + 1]],
            End::Rigid { at, local: [lx, ly] } => {
                let (s, c) = (x[at + 2].sin(), x[at + 2].cos());
                let (rx, ry) = (c * lx - s * ly, s * lx + c * ly);
                [xd[at] - xd[at + 2] * ry, xd[at + 1] + xd[at + 2] * rx]
            }
        }
    }

    /// Adds the generalized force of a world force `f` applied at the point.
    #[inline(always)]
    pub(super) fn apply<D: Scalar>(&self, x: &[D], f: [D; 2], out: &mut [D]) {
        match *self {
            End::Ground { .. } => {}
            End::Point { at } => {
                out[at] += f[0];
                out[at + 1] += f[1];
            }
            End::Rigid { at, local: [lx, ly] } => {
                let (s, c) = (x[at + 2].sin(), x[at + 2].cos());
                let (rx, ry) = (c * lx - s * ly, s * lx + c * ly);
                out[at] += f[0];
                out[at + 1] += f[1];
                out[at + 2] += rx * f[1] - ry * f[0];
            }
        }
    }

    /// The angle of the end's body (0 for the ground).
    #[inline(always)]
    pub(super) fn angle<D: Scalar, const K: usize>(&self, x: &[D; K]) -> D {
        match *self {
            End::Rigid { at, .. } => pick(x, at + 2),
            _ => D::from(0.0),
        }
    }
}

#[inline(always)]
pub(super) fn angle_of<D: Scalar, const K: usize>(at: Option<usize>, x: &[D; K]) -> D {
    at.map_or(D::from(0.0), |i| pick(x, i))
}

/// `x[i]`, written as a chain of constant-index selections. Indexing a
/// small array of dual numbers with a runtime index forces it onto the
/// stack, where every wide load stalls on the narrow stores that built it:
/// measured 4× slower derivative passes than this.
#[inline(always)]
fn pick<D: Copy, const K: usize>(x: &[D; K], i: usize) -> D {
    debug_assert!(i < K);
    let mut out = x[0];
    for (j, &xj) in x.iter().enumerate().skip(1) {
        if i == j {
            out = xj;
        }
    }
    out
}
