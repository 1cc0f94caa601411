//! LU of a structurally symmetric matrix on its symmetric pattern's supernodal elimination tree:
//! a multifrontal factorization (Duff & Reid 1984, the unsymmetric-valued case on a symmetric
//! pattern; Amestoy, Duff & L'Excellent 2000) whose pivots are chosen by partial pivoting among
//! the fully summed rows of each front only. Row interchanges then stay inside a supernode, so
//! the factor has the pattern the symbolic analysis gave (twice the LDLᵀ's values) and no
//! structure is computed while factorizing. A pivot smaller than [`PIVOT_THRESHOLD`] of the
//! largest entry of its column in the front's other rows would need a row from outside the
//! supernode (a delayed pivot): the factorization then refuses, and the caller factorizes with
//! global partial pivoting (`lu.rs`).

use faer::linalg::matmul::matmul;
use faer::reborrow::*;
use faer::sparse::linalg::cholesky::SymbolicCholesky;
use faer::sparse::linalg::cholesky::SymbolicCholeskyRaw;
use faer::sparse::linalg::cholesky::supernodal::SymbolicSupernodalCholesky;
use faer::sparse::{SparseColMatRef, SymbolicSparseColMatRef};
use faer::{Accum, MatMut, MatRef, Par};
use std::sync::Arc;

use super::multifrontal::{node, supernodes};

/// Threshold partial pivoting's `u`: a pivot is taken where it is at least this share of the
/// largest entry of its column below it, else the front refuses: UMFPACK's default for its
/// symmetric strategy (Davis 2004), which bounds the growth of each step by `1/u`; the
/// solution's accuracy check decides the rest.
pub(super) const PIVOT_THRESHOLD: f64 = 1e-3;

/// Why a numeric factorization refused: the pivot at this permuted column was too small.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) struct Refused {
    pub(super) column: usize,
}

/// The analysis of one pattern, built once and shared by the copies of a solver.
pub(super) struct FrontalAnalysis {
    symbolic: SymbolicCholesky<usize>,
    /// Each supernode's children (ascending).
    children: Vec<Vec<usize>>,
    /// Per supernode (`relative_ptr`), its pattern's places in its parent's front.
    relative_ptr: Vec<usize>,
    relative: Vec<u32>,
    /// Per supernode (`gather_ptr`), each matrix entry's index in the values and its place in
    /// the supernode's front (column-major).
    gather_ptr: Vec<usize>,
    gather: Vec<(u32, u32)>,
    /// Per supernode, the start of its factor: the `r × k` panel (`L₁₁\U₁₁` over `L₂₁`), then
    /// `U₁₂` (`k × m`), `r = k + m`.
    factor_ptr: Vec<usize>,
}

/// The factor of the last numeric factorization on a [`FrontalAnalysis`], and work space.
pub(super) struct FrontalLu {
    analysis: Arc<FrontalAnalysis>,
    factor: Vec<f64>,
    /// The row of its supernode's block each pivot step swapped its own with (local index).
    swaps: Vec<usize>,
    /// The update matrices waiting for their parents, spare buffers, and the permuted
    /// right-hand side.
    updates: Vec<Vec<f64>>,
    spare: Vec<Vec<f64>>,
    work: Vec<f64>,
}

impl FrontalAnalysis {
    /// The analysis of the full, structurally symmetric `pattern` from `symbolic`, a supernodal
    /// analysis of its lower triangle; None for a simplicial analysis or an index beyond 32 bits.
    pub(super) fn new(
        symbolic: SymbolicCholesky<usize>,
        pattern: SymbolicSparseColMatRef<'_, usize>,
    ) -> Option<Self> {
        let (sym, of_column) = supernodes(&symbolic)?;
        let count = sym.n_supernodes();
        let mut children = vec![Vec::new(); count];
        let mut relative = Vec::with_capacity(sym.row_idx().len());
        let mut relative_ptr = Vec::with_capacity(count + 1);
        let (mut factor_ptr, mut factor_len) = (Vec::with_capacity(count + 1), 0usize);
        for s in 0..count {
            let nd = node(sym, s);
            let (k, m) = (nd.end - nd.begin, nd.pattern.len());
            factor_ptr.push(factor_len);
            relative_ptr.push(relative.len());
            factor_len += (k + m) * k + k * m;
            let Some(&first) = nd.pattern.first() else {
                continue;
            };
            let parent = node(sym, of_column[first]);
            children[of_column[first]].push(s);
            for &row in nd.pattern {
                let place = if row < parent.end {
                    row - parent.begin
                } else {
                    parent.end - parent.begin + parent.pattern.binary_search(&row).ok()?
                };
                relative.push(u32::try_from(place).ok()?);
            }
        }
        factor_ptr.push(factor_len);
        relative_ptr.push(relative.len());
        let (gather_ptr, gather) = gather_map(sym, &of_column, symbolic.perm(), pattern)?;
        Some(Self {
            children,
            relative_ptr,
            relative,
            gather_ptr,
            gather,
            factor_ptr,
            symbolic,
        })
    }

    fn sym(&self) -> &SymbolicSupernodalCholesky<usize> {
        match self.symbolic.raw() {
            SymbolicCholeskyRaw::Supernodal(sym) => sym,
            SymbolicCholeskyRaw::Simplicial(_) => unreachable!("checked in `new`"),
        }
    }
}

impl FrontalLu {
    /// Buffers for factorizations on `analysis`.
    pub(super) fn new(analysis: Arc<FrontalAnalysis>) -> Self {
        let n = analysis.sym().nrows();
        let count = analysis.children.len();
        Self {
            factor: vec![0.0; analysis.factor_ptr[count]],
            swaps: vec![0; n],
            updates: vec![Vec::new(); count],
            spare: Vec::new(),
            work: vec![0.0; n],
            analysis,
        }
    }

    /// The analysis it factorizes on.
    pub(super) fn analysis(&self) -> Arc<FrontalAnalysis> {
        self.analysis.clone()
    }

    /// Stored values of the factor.
    pub(super) fn factor_len(&self) -> usize {
        self.factor.len()
    }

    /// Factorizes `a` (the pattern of [`Self::new`]) front by front, children before parents;
    /// refuses at the first pivot below the threshold (or zero, or not finite).
    pub(super) fn factorize(&mut self, a: SparseColMatRef<'_, usize, f64>) -> Result<(), Refused> {
        let analysis = self.analysis.clone();
        for s in 0..analysis.children.len() {
            let nd = node(analysis.sym(), s);
            let (k, m) = (nd.end - nd.begin, nd.pattern.len());
            let r = k + m;
            // The front's first `k` columns (the panel) are the factor's own values; the other
            // `m` columns (`U₁₂` over the Schur complement) become the update matrix.
            let at = analysis.factor_ptr[s];
            let panel = &mut self.factor[at..at + r * k];
            panel.fill(0.0);
            let mut rest = self.spare.pop().unwrap_or_default();
            rest.clear();
            rest.resize(r * m, 0.0);
            let span = analysis.gather_ptr[s]..analysis.gather_ptr[s + 1];
            for &(e, place) in &analysis.gather[span] {
                let (place, value) = (place as usize, a.val()[e as usize]);
                match place.checked_sub(r * k) {
                    None => panel[place] += value,
                    Some(p) => rest[p] += value,
                }
            }
            for &child in &analysis.children[s] {
                let places = &analysis.relative
                    [analysis.relative_ptr[child]..analysis.relative_ptr[child + 1]];
                let update = std::mem::take(&mut self.updates[child]);
                extend_add(places, &update, (panel, &mut rest), r, k);
                self.spare.push(update);
            }
            let swaps = &mut self.swaps[nd.begin..nd.begin + k];
            if let Err(j) = factor_panel(panel, r, k, swaps) {
                self.spare.push(rest);
                self.release_updates();
                return Err(Refused {
                    column: nd.begin + j,
                });
            }
            eliminate(panel, &mut rest, (r, k), swaps);
            let u12 = &mut self.factor[at + r * k..analysis.factor_ptr[s + 1]];
            for c in 0..m {
                u12[c * k..(c + 1) * k].copy_from_slice(&rest[c * r..c * r + k]);
            }
            if m > 0 {
                self.updates[s] = rest;
            } else {
                self.spare.push(rest);
            }
        }
        Ok(())
    }

    /// Returns the update matrices of an abandoned factorization to the spare buffers.
    fn release_updates(&mut self) {
        for u in &mut self.updates {
            if u.capacity() > 0 {
                self.spare.push(std::mem::take(u));
            }
        }
    }

    /// Solves `A x = rhs` (`Aᵀ x = rhs` with `transpose`) in place with the last factor, which
    /// must have been completed by [`Self::factorize`].
    pub(super) fn solve(&mut self, rhs: &mut [f64], transpose: bool) {
        let mut y = std::mem::take(&mut self.work);
        let perm = self.analysis.symbolic.perm();
        let new_index = |i: usize| perm.map_or(i, |p| p.arrays().1[i]);
        for (i, b) in rhs.iter().enumerate() {
            y[new_index(i)] = *b;
        }
        if transpose {
            self.upper_transpose(&mut y);
            self.lower_transpose(&mut y);
        } else {
            self.lower(&mut y);
            self.upper(&mut y);
        }
        for (i, x) in rhs.iter_mut().enumerate() {
            *x = y[new_index(i)];
        }
        self.work = y;
    }

    /// The parts of supernode `s`'s factor: its columns' start, `k`, its pattern, the panel
    /// (`r × k`) and `U₁₂` (`k × m`).
    fn parts(&self, s: usize) -> (usize, usize, &[usize], &[f64], &[f64]) {
        let nd = node(self.analysis.sym(), s);
        let (k, r) = (nd.end - nd.begin, nd.end - nd.begin + nd.pattern.len());
        let at = self.analysis.factor_ptr[s];
        let panel = &self.factor[at..at + r * k];
        let u12 = &self.factor[at + r * k..self.analysis.factor_ptr[s + 1]];
        (nd.begin, k, nd.pattern, panel, u12)
    }

    /// `y ← L⁻¹ P y`, supernode by supernode: the front's row swaps, `L₁₁`, then `L₂₁`.
    fn lower(&self, y: &mut [f64]) {
        for s in 0..self.analysis.children.len() {
            let (b, k, pattern, panel, _) = self.parts(s);
            let r = k + pattern.len();
            for j in 0..k {
                y.swap(b + j, b + self.swaps[b + j]);
            }
            for j in 0..k {
                let yj = y[b + j];
                let column = &panel[j * r..(j + 1) * r];
                for i in j + 1..k {
                    y[b + i] -= column[i] * yj;
                }
                for (&row, l) in pattern.iter().zip(&column[k..]) {
                    y[row] -= l * yj;
                }
            }
        }
    }

    /// `y ← U⁻¹ y`, supernode by supernode from the root: `U₁₂`, then `U₁₁`.
    fn upper(&self, y: &mut [f64]) {
        for s in (0..self.analysis.children.len()).rev() {
            let (b, k, pattern, panel, u12) = self.parts(s);
            let r = k + pattern.len();
            for (c, &row) in pattern.iter().enumerate() {
                let x = y[row];
                for (i, u) in u12[c * k..(c + 1) * k].iter().enumerate() {
                    y[b + i] -= u * x;
                }
            }
            for j in (0..k).rev() {
                y[b + j] /= panel[j * r + j];
                let yj = y[b + j];
                for i in 0..j {
                    y[b + i] -= panel[j * r + i] * yj;
                }
            }
        }
    }

    /// `y ← U⁻ᵀ y`: `U₁₁ᵀ`, then `U₁₂ᵀ`, supernode by supernode.
    fn upper_transpose(&self, y: &mut [f64]) {
        for s in 0..self.analysis.children.len() {
            let (b, k, pattern, panel, u12) = self.parts(s);
            let r = k + pattern.len();
            for j in 0..k {
                let dot: f64 = (0..j).map(|i| panel[j * r + i] * y[b + i]).sum();
                y[b + j] = (y[b + j] - dot) / panel[j * r + j];
            }
            for (c, &row) in pattern.iter().enumerate() {
                let dot: f64 = (0..k).map(|i| u12[c * k + i] * y[b + i]).sum();
                y[row] -= dot;
            }
        }
    }

    /// `y ← Pᵀ L⁻ᵀ y`: from the root, `L₂₁ᵀ`, `L₁₁ᵀ`, then the swaps in reverse.
    fn lower_transpose(&self, y: &mut [f64]) {
        for s in (0..self.analysis.children.len()).rev() {
            let (b, k, pattern, panel, _) = self.parts(s);
            let r = k + pattern.len();
            for j in (0..k).rev() {
                let column = &panel[j * r..(j + 1) * r];
                let below: f64 = pattern
                    .iter()
                    .zip(&column[k..])
                    .map(|(&row, l)| l * y[row])
                    .sum();
                let inside: f64 = (j + 1..k).map(|i| column[i] * y[b + i]).sum();
                y[b + j] -= below + inside;
            }
            for j in (0..k).rev() {
                y.swap(b + j, b + self.swaps[b + j]);
            }
        }
    }
}

/// Per supernode (pointers, then entries), where each entry of `pattern` goes: its index in the
/// values and its place in the front of the supernode holding the smaller of its permuted row
/// and column.
fn gather_map(
    sym: &SymbolicSupernodalCholesky<usize>,
    of_column: &[usize],
    perm: Option<faer::perm::PermRef<'_, usize>>,
    pattern: SymbolicSparseColMatRef<'_, usize>,
) -> Option<(Vec<usize>, Vec<(u32, u32)>)> {
    let new_index = |i: usize| perm.map_or(i, |p| p.arrays().1[i]);
    let count = sym.n_supernodes();
    let mut placed: Vec<(usize, u32, u32)> = Vec::with_capacity(pattern.row_idx().len());
    for j in 0..pattern.ncols() {
        let span = pattern.col_ptr()[j]..pattern.col_ptr()[j + 1];
        for (e, &i) in span.clone().zip(&pattern.row_idx()[span]) {
            let (row, col) = (new_index(i), new_index(j));
            let s = of_column[row.min(col)];
            let nd = node(sym, s);
            let local = |g: usize| -> Option<usize> {
                if g < nd.end {
                    Some(g - nd.begin)
                } else {
                    Some(nd.end - nd.begin + nd.pattern.binary_search(&g).ok()?)
                }
            };
            let r = nd.end - nd.begin + nd.pattern.len();
            let place = local(col)? * r + local(row)?;
            placed.push((s, u32::try_from(e).ok()?, u32::try_from(place).ok()?));
        }
    }
    placed.sort_unstable_by_key(|&(s, _, _)| s);
    let mut ptr = vec![0; count + 1];
    for &(s, _, _) in &placed {
        ptr[s + 1] += 1;
    }
    for s in 0..count {
        ptr[s + 1] += ptr[s];
    }
    Some((ptr, placed.into_iter().map(|(_, e, p)| (e, p)).collect()))
}

/// Adds a child's update matrix over the front places `places` into the front of `r` rows whose
/// first `k` columns are `panel` and the others `rest`. The update is the child's `rest`: its
/// columns hold `U₁₂` in their first rows, the Schur complement below (`mc` of `rc` rows).
fn extend_add(
    places: &[u32],
    update: &[f64],
    (panel, rest): (&mut [f64], &mut [f64]),
    r: usize,
    k: usize,
) {
    let mc = places.len();
    let rc = update.len() / mc.max(1);
    let kc = rc - mc;
    for (q, &col) in places.iter().enumerate() {
        let col = col as usize;
        let target = if col < k {
            &mut panel[col * r..(col + 1) * r]
        } else {
            &mut rest[(col - k) * r..(col - k + 1) * r]
        };
        let source = &update[q * rc + kc..(q + 1) * rc];
        for (&row, v) in places.iter().zip(source) {
            target[row as usize] += v;
        }
    }
}

/// The LU of the panel (`r × k`, column-major: the front's fully summed columns) in place:
/// pivots by partial pivoting among rows `j..k` (row `j`'s swap recorded in `swaps[j]`, the
/// rows swapped across the panel), `L₁₁\U₁₁` over `L₂₁`. Err(j) where the pivot of column `j`
/// is below [`PIVOT_THRESHOLD`] of its column's largest entry below the block, or zero, or not
/// finite.
fn factor_panel(f: &mut [f64], r: usize, k: usize, swaps: &mut [usize]) -> Result<(), usize> {
    for j in 0..k {
        let column = &f[j * r..(j + 1) * r];
        let (mut p, mut largest) = (j, column[j].abs());
        for (i, v) in column.iter().enumerate().take(k).skip(j + 1) {
            if v.abs() > largest {
                (p, largest) = (i, v.abs());
            }
        }
        let below = column[k..].iter().fold(0.0f64, |m, v| m.max(v.abs()));
        if !(largest > 0.0 && largest.is_finite() && largest >= PIVOT_THRESHOLD * below) {
            return Err(j);
        }
        swaps[j] = p;
        if p != j {
            for c in 0..k {
                f.swap(c * r + j, c * r + p);
            }
        }
        let inverse = f[j * r + j].recip();
        for v in &mut f[j * r + j + 1..(j + 1) * r] {
            *v *= inverse;
        }
        let (done, later) = f.split_at_mut((j + 1) * r);
        let l = &done[j * r + j + 1..];
        for column in later.chunks_exact_mut(r) {
            let factor = column[j];
            if factor != 0.0 {
                for (v, li) in column[j + 1..].iter_mut().zip(l) {
                    *v -= li * factor;
                }
            }
        }
    }
    Ok(())
}

/// The front's other columns `rest` (`r × m`) after its panel's LU: the panel's row swaps,
/// `U₁₂ = L₁₁⁻¹ F₁₂` in their first `k` rows and the Schur complement `F₂₂ − L₂₁ U₁₂` below
/// (one dense product where the front is large enough for faer's kernels to pay, else a
/// column at a time).
fn eliminate(panel: &[f64], rest: &mut [f64], (r, k): (usize, usize), swaps: &[usize]) {
    let m = r - k;
    let product = k >= DENSE_PRODUCT && m >= DENSE_PRODUCT;
    let rows = if product { k } else { r };
    for column in rest.chunks_exact_mut(r) {
        for (j, &p) in swaps.iter().enumerate() {
            column.swap(j, p);
        }
        for j in 0..k {
            let factor = column[j];
            if factor != 0.0 {
                let l = &panel[j * r + j + 1..j * r + rows];
                for (v, li) in column[j + 1..rows].iter_mut().zip(l) {
                    *v -= li * factor;
                }
            }
        }
    }
    if product {
        let l21 = MatRef::from_column_major_slice_with_stride(&panel[k..], m, k, r);
        let front = MatMut::from_column_major_slice_with_stride_mut(rest, r, m, r);
        let (u12, f22) = front.split_at_row_mut(k);
        matmul(f22, Accum::Add, l21, u12.rb(), -1.0, Par::Seq);
    }
}

/// Fronts whose block and pattern both have at least this many rows form their Schur
/// complement by faer's dense product.
const DENSE_PRODUCT: usize = 8;

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mech::solve::linear::ordering::{FillOrdering, analyse_supernodal};
    use faer::sparse::{SparseColMat, SymbolicSparseColMat, Triplet};

    /// An unsymmetric matrix on an `n × n` grid of 3-DOF nodes, each node coupled to its 8
    /// neighbours (a structurally symmetric pattern): `a_ij ≠ a_ji`, the diagonal
    /// `diagonal(dof)`, the entries between two DOFs of one node `inside`.
    fn grid(n: usize, diagonal: impl Fn(usize) -> f64, inside: f64) -> SparseColMat<usize, f64> {
        let mut entries = Vec::new();
        for v in 0..n * n {
            for w in 0..n * n {
                let (vi, vj, wi, wj) = (v % n, v / n, w % n, w / n);
                if vi.abs_diff(wi) > 1 || vj.abs_diff(wj) > 1 {
                    continue;
                }
                for a in 0..3 {
                    for b in 0..3 {
                        let (r, c) = (3 * v + a, 3 * w + b);
                        let value = if r == c {
                            diagonal(r)
                        } else if v == w {
                            inside
                        } else {
                            -1.0 + 0.3 * ((r + 2 * c) % 7) as f64
                        };
                        entries.push(Triplet::new(r, c, value));
                    }
                }
            }
        }
        let dofs = 3 * n * n;
        SparseColMat::try_new_from_triplets(dofs, dofs, &entries).unwrap()
    }

    /// The frontal LU of `a` on its lower triangle's supernodal analysis under `ordering`.
    fn frontal(a: &SparseColMat<usize, f64>, ordering: FillOrdering) -> FrontalLu {
        let n = a.ncols();
        let mut lower = Vec::new();
        for j in 0..n {
            for &i in a.row_idx_of_col_raw(j) {
                if i >= j {
                    lower.push(faer::sparse::Pair::new(i, j));
                }
            }
        }
        let lower = SymbolicSparseColMat::try_new_from_indices(n, n, &lower)
            .unwrap()
            .0;
        let symbolic = analyse_supernodal(lower.as_ref(), ordering).unwrap();
        FrontalLu::new(Arc::new(
            FrontalAnalysis::new(symbolic, a.symbolic()).unwrap(),
        ))
    }

    /// `A x` (`Aᵀ x` with `transpose`).
    fn product(a: &SparseColMat<usize, f64>, x: &[f64], transpose: bool) -> Vec<f64> {
        let mut b = vec![0.0; a.nrows()];
        for j in 0..a.ncols() {
            for (&i, v) in a.row_idx_of_col_raw(j).iter().zip(a.val_of_col(j)) {
                if transpose {
                    b[j] += v * x[i];
                } else {
                    b[i] += v * x[j];
                }
            }
        }
        b
    }

    /// Solves `A x = b` and `Aᵀ x = b` for a known `x`; the largest error of either.
    fn solve_error(lu: &mut FrontalLu, a: &SparseColMat<usize, f64>) -> f64 {
        let x: Vec<f64> = (0..a.ncols())
            .map(|i| ((i * 37) % 11) as f64 - 5.0)
            .collect();
        let mut worst = 0.0_f64;
        for transpose in [false, true] {
            let mut b = product(a, &x, transpose);
            lu.solve(&mut b, transpose);
            let error = b
                .iter()
                .zip(&x)
                .map(|(u, v)| (u - v).abs())
                .fold(0.0, f64::max);
            worst = worst.max(error);
        }
        worst
    }

    /// On a diagonally dominant unsymmetric grid, under both orderings, the frontal LU solves
    /// `A x = b` and `Aᵀ x = b` to rounding.
    #[test]
    fn frontal_lu_solves_an_unsymmetric_matrix_and_its_transpose_to_rounding() {
        let a = grid(9, |r| 40.0 + (r % 7) as f64, 0.5);
        for ordering in [FillOrdering::Amd, FillOrdering::NestedDissection] {
            let mut lu = frontal(&a, ordering);
            lu.factorize(a.as_ref()).unwrap();
            let error = solve_error(&mut lu, &a);
            assert!(error <= 1e-12, "{ordering:?}: {error:e}");
        }
    }

    /// A zero diagonal entry in every node's block: each front takes its pivot from another
    /// row of its block, and the solves stay exact to rounding.
    #[test]
    fn zero_diagonal_entries_are_pivoted_inside_their_supernodes() {
        let a = grid(9, |r| if r % 3 == 0 { 0.0 } else { 40.0 }, 30.0);
        let mut lu = frontal(&a, FillOrdering::Amd);
        lu.factorize(a.as_ref()).unwrap();
        let swapped = lu.swaps.iter().enumerate().filter(|(j, p)| j != *p).count();
        assert!(swapped > 0, "no row was swapped");
        let error = solve_error(&mut lu, &a);
        assert!(error <= 1e-11, "{error:e}");
    }

    /// A pivot below [`PIVOT_THRESHOLD`] of the largest entry of its column outside the block
    /// is refused; one at the threshold is taken, and a larger entry of the block is swapped
    /// in.
    #[test]
    fn a_pivot_below_the_threshold_of_the_rows_outside_its_block_is_refused() {
        let mut swaps = [0; 2];
        // One fully summed column, two rows of the pattern below it.
        let mut small = [0.5 * PIVOT_THRESHOLD, 0.0, 1.0];
        assert_eq!(factor_panel(&mut small, 3, 1, &mut swaps[..1]), Err(0));
        let mut at = [PIVOT_THRESHOLD, 0.0, -1.0];
        assert_eq!(factor_panel(&mut at, 3, 1, &mut swaps[..1]), Ok(()));
        assert_eq!(at, [PIVOT_THRESHOLD, 0.0, -1.0 / PIVOT_THRESHOLD]);
        // Two fully summed columns: the zero diagonal takes row 1's entry.
        let mut block = [0.0, 2.0, 1.0, 3.0, 4.0, 0.0];
        assert_eq!(factor_panel(&mut block, 3, 2, &mut swaps), Ok(()));
        assert_eq!(swaps, [1, 1]);
        assert_eq!(block[..3], [2.0, 0.0, 0.5]);
    }

    /// Where a column's entries in its own block are far below those of the other rows (tiny
    /// diagonals, no coupling inside a node), the pivots would have to come from outside their
    /// supernodes: the frontal LU refuses, and the LU part redoes the factorization with global
    /// partial pivoting, which solves it.
    #[test]
    fn a_matrix_the_fronts_cannot_pivot_is_solved_by_global_partial_pivoting() {
        let a = grid(9, |_| 1e-9, 0.0);
        let mut lu = frontal(&a, FillOrdering::Amd);
        let refused = lu.factorize(a.as_ref()).unwrap_err();
        assert!(refused.column < a.ncols());
        let mut part = super::super::lu::LuPart::analyse(a.symbolic(), FillOrdering::Amd).unwrap();
        let x: Vec<f64> = (0..a.ncols()).map(|i| i as f64).collect();
        let mut b = product(&a, &x, false);
        part.factorize_and_solve(a.as_ref(), &mut b).unwrap();
        assert_eq!(part.pivoted, 1);
        let error = b
            .iter()
            .zip(&x)
            .map(|(u, v)| (u - v).abs())
            .fold(0.0, f64::max);
        assert!(error <= 1e-8, "{error:e}");
    }
}
