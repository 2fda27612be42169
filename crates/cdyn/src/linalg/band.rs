//! `S = Φ_q M⁻¹ Φ_qᵀ` factored as `L D Lᵀ` in a band: every row of `L`
//! holds the `W` entries left of its diagonal, zeros included, with `W`
//! known at compile time, so the elimination and the substitutions are
//! unrolled loops with no index read and no bookkeeping per entry.
//!
//! Fill stays inside the band, so it is fixed once, with the rows in
//! reverse Cuthill–McKee order, which keeps it narrow for chains and robot
//! arms. There the sparse column kernel ([`crate::linalg::Schur`]) spends
//! an index read, a scattered update and a short loop's control on each of
//! a few entries a row, more than the arithmetic of the band's zeros; a
//! chain of spatial bodies (a joint's three rows and a normalization row
//! each) has a band of 6. Wider patterns (nets) keep the column kernel:
//! the caller chooses by [`Band::width`] and [`Band::entries`].
//!
//! Same pivot test and handling of dependent rows as the other kernels
//! ([`inverse_pivot`]): a dropped row's `D⁻¹` is 0, hence every later
//! row's entry in its column, and its multiplier is 0.
//!
//! May import: `linalg`'s other files.

use super::ldl::{Breakdown, DependentRows, inverse_pivot};
use super::schur::MAX_RIGHT_HAND_SIDES;

/// The widest band compiled.
pub(crate) const MAX_WIDTH: usize = 16;

/// `S` in a band, factored as `L D Lᵀ` with unit lower `L`.
#[derive(Clone)]
pub(crate) struct Band {
    m: usize,
    /// `W`: the entries of each row of `L` left of its diagonal.
    width: usize,
    /// `order[i]` is the original row eliminated `i`-th.
    order: Vec<u32>,
    /// `L` by rows of `W`, entry `t` of row `i` in column `i − W + t`,
    /// after `W` rows of zeros (the columns before the first).
    lower: Vec<f64>,
    /// `D⁻¹` and the forward substitution's values, after `W` zeros.
    inv_d: Vec<f64>,
    work: Vec<f64>,
    dependent: DependentRows,
    dropped: usize,
    tolerance: f64,
}

impl Band {
    /// The band of an `m × m` symmetric `S` whose off-diagonal entries
    /// can be non-zero at `pairs` (original rows, either order).
    pub fn new(m: usize, pairs: impl Iterator<Item = (usize, usize)>) -> Self {
        let mut neighbours = vec![Vec::new(); m];
        for (a, b) in pairs.filter(|(a, b)| a != b) {
            neighbours[a].push(b);
            neighbours[b].push(a);
        }
        neighbours.iter_mut().for_each(|n| {
            n.sort_unstable();
            n.dedup();
        });
        let order = reverse_cuthill_mckee(&neighbours);
        let mut position = vec![0; m];
        order.iter().enumerate().for_each(|(i, &row)| position[row] = i);
        let position = &position;
        let reach = |i: usize| neighbours[order[i]].iter().map(move |&r| i.saturating_sub(position[r]));
        let width = (0..m).flat_map(reach).max().unwrap_or(0).max(1);
        Self {
            m,
            width,
            order: order.into_iter().map(|r| r as u32).collect(),
            lower: vec![0.0; (m + width) * width],
            inv_d: vec![0.0; m + width],
            work: vec![0.0; m + width],
            dependent: DependentRows::Error,
            dropped: 0,
            tolerance: DependentRows::Error.tolerance(),
        }
    }

    /// `W`.
    pub fn width(&self) -> usize {
        self.width
    }

    /// Entries of `L` below the diagonal the band holds, zeros included.
    pub fn entries(&self) -> usize {
        self.m * self.width
    }

    /// Entries of `S` the factorization reads: `m` diagonal ones (by
    /// elimination position), then `W` a row (zero where `S` has none).
    pub fn slots(&self) -> usize {
        self.m * (1 + self.width)
    }

    /// The slot of `S`'s entry `(a, b)` (original rows). Panics outside the band.
    pub fn slot_finder(&self) -> impl Fn(usize, usize) -> usize + '_ {
        let mut position = vec![0; self.m];
        self.order.iter().enumerate().for_each(|(i, &row)| position[row as usize] = i);
        move |a, b| {
            let (i, j) = (position[a].max(position[b]), position[a].min(position[b]));
            if i == j {
                return i;
            }
            assert!(i - j <= self.width, "S's pattern lies inside its band");
            self.m + i * self.width + self.width - (i - j)
        }
    }

    /// Sets what a dependent row does in the next factorizations.
    pub fn set_dependent_rows(&mut self, dependent: DependentRows) {
        (self.dependent, self.tolerance) = (dependent, dependent.tolerance());
    }

    /// Rows the last factorization dropped as dependent (0 unless tolerated).
    pub fn dependent_rows(&self) -> usize {
        self.dropped
    }

    /// Factors `S`, given by slot ([`slot_finder`](Self::slot_finder)), and
    /// solves `S x = b` in place.
    pub fn factor_and_solve_assembled(&mut self, s: &[f64], b: &mut [f64]) -> Result<(), Breakdown> {
        assert!(s.len() == self.slots() && b.len() == self.m, "entries or right-hand side of the wrong length");
        crate::with_const!(self.width, W, [1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15, 16], {
            self.factor::<W>(s, b)
        })
    }

    /// Row by row (up-looking): row `i`'s `L D` entries are `S`'s less
    /// their dot products with the finished rows; the forward substitution
    /// joins it.
    fn factor<const W: usize>(&mut self, s: &[f64], b: &mut [f64]) -> Result<(), Breakdown> {
        let m = self.m;
        let (dependent, tolerance) = (self.dependent, self.tolerance);
        let mut count = 0;
        self.dropped = 0;
        // The zeros before the first column; a non-finite `x` of the last
        // solve may have reached them.
        self.work[..W].fill(0.0);
        let rows = self.lower.as_chunks_mut::<W>().0;
        let (s_diagonal, s_rows) = s.split_at(m);
        for (i, s_row) in s_rows.as_chunks::<W>().0.iter().enumerate() {
            // Row `i` is `rows[i + W]`; column `i − W + t`'s row is `rows[i + t]`.
            let (before, row) = rows[i..].split_at_mut(W);
            let mut u = [0.0; W];
            for t in 0..W {
                let mut sum = 0.0;
                for k in 0..t {
                    sum += u[k] * before[t][k + W - t];
                }
                u[t] = s_row[t] - sum;
            }
            // `u` holds `(L D)_ij`; `L_ij` and the pivot from it.
            let inv_before: &[f64; W] = self.inv_d[i..i + W].try_into().expect("W entries");
            let s_ii = s_diagonal[i];
            let mut d = s_ii;
            for t in 0..W {
                let l = u[t] * inv_before[t];
                d -= u[t] * l;
                row[0][t] = l;
            }
            let order = &self.order;
            let inv = inverse_pivot(d, s_ii, tolerance, s, dependent, &mut count, || order[i] as usize)?;
            self.inv_d[i + W] = inv;
            let z: &[f64; W] = self.work[i..i + W].try_into().expect("W entries");
            let sum: f64 = (0..W).map(|t| row[0][t] * z[t]).sum();
            self.work[i + W] = b[order[i] as usize] - sum;
        }
        self.dropped = count;
        self.work.iter_mut().zip(&self.inv_d).for_each(|(z, inv)| *z *= inv);
        for i in (0..m).rev() {
            let x = self.work[i + W];
            let l = &rows[i + W];
            let z: &mut [f64; W] = (&mut self.work[i..i + W]).try_into().expect("W entries");
            for t in 0..W {
                z[t] -= l[t] * x;
            }
            b[self.order[i] as usize] = x;
        }
        Ok(())
    }

    /// Solves `S x = b` in place for up to [`MAX_RIGHT_HAND_SIDES`] vectors
    /// in one pass over `L`, with the last factorization (each vector sees
    /// exactly the operations of a lone solve).
    pub fn solve_many(&self, bs: &mut [&mut [f64]]) {
        assert!(bs.iter().all(|b| b.len() == self.m), "right-hand side of the wrong length");
        crate::with_const!(self.width, W, [1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15, 16], {
            match bs {
                [] => {}
                [a] => self.solve::<W, 1>([&mut **a]),
                [a, b] => self.solve::<W, 2>([&mut **a, &mut **b]),
                [a, b, c] => self.solve::<W, 3>([&mut **a, &mut **b, &mut **c]),
                [a, b, c, d] => self.solve::<W, 4>([&mut **a, &mut **b, &mut **c, &mut **d]),
                _ => panic!("at most {MAX_RIGHT_HAND_SIDES} right-hand sides"),
            }
        })
    }

    /// `L⁻¹`, `D⁻¹`, then `L⁻ᵀ` on `K` vectors of length `m` at once, in
    /// place by original rows. The first `W` rows reach back to the zeros
    /// before the first column, which the vectors do not hold: their loops
    /// start later.
    fn solve<const W: usize, const K: usize>(&self, bs: [&mut [f64]; K]) {
        let (m, rows, order) = (self.m, self.lower.as_chunks::<W>().0, &self.order);
        assert!(bs.iter().all(|b| b.len() == m) && rows.len() == m + W && order.len() == m);
        let b = bs.map(|b| b.as_mut_ptr());
        // SAFETY: `order` holds rows < m (a permutation, made in `new`), the
        // vectors have m values and are distinct borrows, and `rows` has
        // `m + W` rows, as asserted. Unchecked: the loops are a few entries
        // long, and their checks cost as much.
        unsafe {
            let at = |i: usize| *order.get_unchecked(i) as usize;
            for i in 0..m {
                let l = rows.get_unchecked(i + W);
                let mut sum = [0.0; K];
                let mut add = |t: usize| {
                    let r = at(i + t - W);
                    for k in 0..K {
                        sum[k] += l[t] * *b[k].add(r);
                    }
                };
                // Whole rows apart, so that their loop is unrolled.
                if i >= W {
                    (0..W).for_each(&mut add);
                } else {
                    (W - i..W).for_each(&mut add);
                }
                let r = at(i);
                for k in 0..K {
                    *b[k].add(r) -= sum[k];
                }
            }
            for i in 0..m {
                let (r, inv) = (at(i), *self.inv_d.get_unchecked(i + W));
                for k in 0..K {
                    *b[k].add(r) *= inv;
                }
            }
            for i in (0..m).rev() {
                let (l, r) = (rows.get_unchecked(i + W), at(i));
                let x: [f64; K] = std::array::from_fn(|k| *b[k].add(r));
                let subtract = |t: usize| {
                    let r = at(i + t - W);
                    for k in 0..K {
                        *b[k].add(r) -= l[t] * x[k];
                    }
                };
                if i >= W {
                    (0..W).for_each(subtract);
                } else {
                    (W - i..W).for_each(subtract);
                }
            }
        }
    }
}

/// A symmetric order of the graph `neighbours` (sorted, without loops)
/// that keeps every row's neighbours close before it: breadth first from
/// a far end of each connected part, neighbours of fewer neighbours first,
/// then reversed (George & Liu, *Computer Solution of Large Sparse
/// Positive Definite Systems*, 1981, §4.3).
fn reverse_cuthill_mckee(neighbours: &[Vec<usize>]) -> Vec<usize> {
    let m = neighbours.len();
    let mut order = Vec::with_capacity(m);
    let mut placed = vec![false; m];
    let mut level = vec![usize::MAX; m];
    for seed in 0..m {
        if placed[seed] {
            continue;
        }
        // A far end: breadth first from the seed, then from a node of the
        // last level with the fewest neighbours, while that goes deeper.
        let (mut root, mut depth) = (seed, 0);
        loop {
            let reached = levels(neighbours, root, &mut level);
            let last = reached.iter().map(|&v| level[v]).max().unwrap_or(0);
            let far = reached.iter().copied().filter(|&v| level[v] == last).min_by_key(|&v| neighbours[v].len());
            reached.iter().for_each(|&v| level[v] = usize::MAX);
            match far {
                Some(far) if last > depth => (root, depth) = (far, last),
                _ => break,
            }
        }
        let begin = order.len();
        order.push(root);
        placed[root] = true;
        let mut next = begin;
        while next < order.len() {
            let v = order[next];
            next += 1;
            let mut fresh: Vec<usize> = neighbours[v].iter().copied().filter(|&w| !placed[w]).collect();
            fresh.sort_by_key(|&w| neighbours[w].len());
            for w in fresh {
                placed[w] = true;
                order.push(w);
            }
        }
    }
    order.reverse();
    order
}

/// The nodes reached from `root`, breadth first, with their distance in `level`
/// (which must be `usize::MAX` everywhere on entry).
fn levels(neighbours: &[Vec<usize>], root: usize, level: &mut [usize]) -> Vec<usize> {
    let mut reached = vec![root];
    level[root] = 0;
    let mut next = 0;
    while next < reached.len() {
        let v = reached[next];
        next += 1;
        for &w in &neighbours[v] {
            if level[w] == usize::MAX {
                level[w] = level[v] + 1;
                reached.push(w);
            }
        }
    }
    reached
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::linalg::DenseLdl;

    /// Rows (each a list of coordinates) with values of `J`: `S = J Jᵀ`
    /// densely, and the band of its pattern with `S` placed by slot.
    struct Case {
        j: Vec<Vec<f64>>,
        s: Vec<Vec<f64>>,
        band: Band,
        slots: Vec<f64>,
    }

    /// `copies` (row, original): rows given the values of an earlier one.
    fn case(rows: &[Vec<usize>], n: usize, seed: f64, copies: &[(usize, usize)]) -> Case {
        let m = rows.len();
        let value = |r: usize, c: usize| {
            (seed + 1.3 * r as f64 + 0.7 * c as f64).sin() + if c % 3 == r % 3 { 1.5 } else { 0.0 }
        };
        let mut j: Vec<Vec<f64>> =
            (0..m).map(|r| (0..n).map(|c| if rows[r].contains(&c) { value(r, c) } else { 0.0 }).collect()).collect();
        for &(copy, original) in copies {
            j[copy] = j[original].clone();
        }
        let s: Vec<Vec<f64>> =
            (0..m).map(|a| (0..m).map(|b| (0..n).map(|c| j[a][c] * j[b][c]).sum()).collect()).collect();
        let pairs = (0..m)
            .flat_map(|a| (0..m).map(move |b| (a, b)))
            .filter(|&(a, b)| rows[a].iter().any(|c| rows[b].contains(c)));
        let band = Band::new(m, pairs);
        let mut slots = vec![0.0; band.slots()];
        let slot = band.slot_finder();
        for a in 0..m {
            for b in 0..=a {
                if rows[a].iter().any(|c| rows[b].contains(c)) {
                    slots[slot(a, b)] = s[a][b];
                }
            }
        }
        drop(slot);
        Case { j, s, band, slots }
    }

    /// A chain of bodies of 7 coordinates (a position and Euler
    /// parameters): a joint's three rows on a body and the next, and each
    /// body's normalization row on its last four, numbered joints first.
    fn spatial_chain(bodies: usize) -> (Vec<Vec<usize>>, usize) {
        let body = |b: usize| (7 * b..7 * b + 7).collect::<Vec<_>>();
        let mut rows = Vec::new();
        for b in 0..bodies {
            let mut both = if b == 0 { Vec::new() } else { body(b - 1) };
            both.extend(body(b));
            rows.extend([both.clone(), both.clone(), both]);
        }
        rows.extend((0..bodies).map(|b| (7 * b + 3..7 * b + 7).collect()));
        (rows, 7 * bodies)
    }

    /// Rows coupling coordinates `r` and `r + 1`, numbered `r · 7 mod m`:
    /// a tridiagonal `S` in a scrambled order.
    fn scrambled_chain(m: usize) -> (Vec<Vec<usize>>, usize) {
        ((0..m).map(|i| (i * 7) % m).map(|r| vec![r, r + 1]).collect(), m + 1)
    }

    /// Arms of `len` rows from a hub row: a tree.
    fn star(arms: usize, len: usize) -> (Vec<Vec<usize>>, usize) {
        let mut rows = vec![vec![0]];
        for a in 0..arms {
            let coordinate = |k: usize| 1 + a * len + k;
            rows.extend((0..len).map(|k| vec![if k == 0 { 0 } else { coordinate(k - 1) }, coordinate(k)]));
        }
        (rows, 1 + arms * len)
    }

    fn dense_solve(s: &[Vec<f64>], b: &[f64]) -> Vec<f64> {
        let m = s.len();
        let mut ldl = DenseLdl::new(m);
        ldl.matrix_mut().copy_from_slice(&s.concat());
        ldl.factor(&s.concat()).expect("S is positive definite");
        let mut x = b.to_vec();
        ldl.solve(&mut x);
        x
    }

    #[test]
    fn the_reverse_cuthill_mckee_order_finds_the_narrow_band() {
        let width = |(rows, n): (Vec<Vec<usize>>, usize)| case(&rows, n, 0.1, &[]).band.width();
        assert_eq!(width(scrambled_chain(40)), 1);
        // A joint's rows reach the previous joint's and the normalization
        // rows of both bodies: 6, as for the library's spatial chain.
        assert_eq!(width(spatial_chain(30)), 6);
        // A hub with five arms: the hub's row and the arms' first rows
        // share the hub, a clique of six, so no order does better than 5.
        assert_eq!(width(star(5, 6)), 5);
    }

    #[test]
    fn factors_and_solves_as_the_dense_ldl_does() {
        for (name, (rows, n)) in
            [("spatial chain", spatial_chain(12)), ("scrambled chain", scrambled_chain(30)), ("star", star(4, 5))]
        {
            let Case { s, mut band, slots, .. } = case(&rows, n, 0.4, &[]);
            let m = rows.len();
            let b: Vec<f64> = (0..m).map(|i| (2.0 + 0.9 * i as f64).cos()).collect();
            let expected = dense_solve(&s, &b);
            let mut x = b.clone();
            band.factor_and_solve_assembled(&slots, &mut x).unwrap();
            let scale = expected.iter().fold(0.0_f64, |a, x| a.max(x.abs()));
            let error = x.iter().zip(&expected).fold(0.0_f64, |a, (x, e)| a.max((x - e).abs())) / scale;
            assert!(error < 1e-12, "{name}: relative error {error:e}");
            // Solved again with the factorization: the same operations.
            let mut again = b.clone();
            band.solve_many(&mut [&mut again]);
            assert_eq!(again, x, "{name}");
            let (mut first, mut second) = (b.clone(), b.iter().map(|x| 2.0 * x).collect::<Vec<_>>());
            band.solve_many(&mut [&mut first, &mut second]);
            assert_eq!(first, x, "{name}");
            assert!(second.iter().zip(&x).all(|(s, x)| (s - 2.0 * x).abs() <= 1e-14 * scale), "{name}");
        }
    }

    #[test]
    fn a_dependent_row_is_an_error_or_dropped_and_the_reaction_is_the_same() {
        // The spatial chain with its second joint row given twice.
        let (mut rows, n) = spatial_chain(6);
        rows.push(rows[1].clone());
        let copy = rows.len() - 1;
        let Case { j, s, mut band, mut slots } = case(&rows, n, 0.4, &[(copy, 1)]);
        assert!(matches!(
            band.factor_and_solve_assembled(&slots, &mut vec![1.0; rows.len()]),
            Err(Breakdown::Singular(_))
        ));
        band.set_dependent_rows(DependentRows::Tolerate);
        // A consistent right-hand side, S y: solved, one row dropped, and
        // Jᵀx (the constraint force) is Jᵀy, whichever row carries it.
        let y: Vec<f64> = (0..rows.len()).map(|i| (1.0 + i as f64).sin()).collect();
        let b: Vec<f64> = s.iter().map(|row| row.iter().zip(&y).map(|(s, y)| s * y).sum()).collect();
        let mut x = b.clone();
        band.factor_and_solve_assembled(&slots, &mut x).unwrap();
        assert_eq!(band.dependent_rows(), 1);
        assert!(x[1] == 0.0 || x[copy] == 0.0, "the dropped row's multiplier is 0: {} {}", x[1], x[copy]);
        let force = |x: &[f64]| (0..n).map(|c| (0..x.len()).map(|r| j[r][c] * x[r]).sum::<f64>()).collect::<Vec<_>>();
        let (got, expected) = (force(&x), force(&y));
        let error = got.iter().zip(&expected).fold(0.0_f64, |a, (g, e)| a.max((g - e).abs()));
        assert!(error < 1e-10, "Jᵀx against Jᵀy: {error:e}");
        // A non-finite entry is told apart from a dependent row; neither it
        // nor a non-finite right-hand side spoils the next solve.
        let good = slots.clone();
        slots[0] = f64::NAN;
        assert_eq!(band.factor_and_solve_assembled(&slots, &mut vec![1.0; rows.len()]), Err(Breakdown::NonFinite));
        band.factor_and_solve_assembled(&good, &mut vec![f64::NAN; rows.len()]).unwrap();
        let mut again = b.clone();
        band.factor_and_solve_assembled(&good, &mut again).unwrap();
        assert_eq!(again, x);
    }
}
