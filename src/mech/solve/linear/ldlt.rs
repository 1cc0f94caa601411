//! LDLᵀ of the symmetric part `S = (A + Aᵀ)/2` of a full-pattern matrix on its lower triangle,
//! and the dispatch of a solve on it: directly, by Woodbury or by GMRES, each checked.

use std::sync::Arc;
use std::time::Instant;

use crate::mech::solve::linear::Context;
use crate::mech::solve::linear::gmres;
use crate::mech::solve::linear::multifrontal::Analysed;
use crate::mech::solve::linear::ordering::{self, FillOrdering};
use crate::mech::solve::linear::pool;
use crate::mech::solve::linear::timed;
use crate::mech::solve::linear::woodbury::woodbury_correction;
use crate::mech::solve::linear::{accurate, accurate_transpose};
use faer::dyn_stack::{MemBuffer, MemStack, StackReq};
use faer::sparse::linalg::cholesky::LdltRef;
use faer::sparse::{SparseColMatRef, SymbolicSparseColMat};
use faer::{Conj, MatMut, Par};

/// LDLᵀ of the symmetric part of a full-pattern matrix, stored on the pattern's lower triangle
/// (what a symmetric matrix's LDLᵀ reads), the slot of each lower entry's transpose, and the
/// buffers of the Woodbury correction.
pub(super) struct SymmetricPart {
    /// The lower triangle of the pattern (the Ju–Rowlands matrix's pattern: same analysis).
    pub(super) lower: Arc<SymbolicSparseColMat<usize>>,
    pub(super) symbolic: Arc<Analysed>,
    /// Allocated at the first factorization.
    pub(super) factor: Vec<f64>,
    /// Slot in the full pattern of the transpose of each lower entry (`u32::MAX`: none).
    pub(super) transpose: Arc<[u32]>,
    /// Whether every entry's transpose is in the pattern (else no fast path).
    pub(super) structural: bool,
    /// The right-hand side kept for the accuracy check and the fallbacks.
    pub(super) rhs: Vec<f64>,
    /// `(A + Aᵀ)/2` on the lower pattern.
    pub(super) symmetric_values: Vec<f64>,
    /// Row sums of `|A|`.
    pub(super) row_norms: Vec<f64>,
    /// Skew entries below the diagonal: (row, column, `(a_ij − a_ji)/2`).
    pub(super) skew: Vec<(usize, usize, f64)>,
    /// More skew entries than [`SKEW_ENTRIES`] (then none are kept).
    pub(super) skew_overflow: bool,
    /// Woodbury: the DOFs `C`, the block `[W y]` (column-major, `n × (|C| + 1)`), its scratch.
    pub(super) dofs: Vec<usize>,
    pub(super) block: Vec<f64>,
    pub(super) block_scratch: MemBuffer,
    pub(super) block_columns: usize,
    pub(super) scratch: MemBuffer,
    /// How the last factorization's system was solved (what a held solve repeats).
    pub(super) path: Path,
    /// Threads of the numeric factorization.
    pub(super) threads: usize,
}

/// How a system is solved on the symmetric part's LDLᵀ.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Path {
    /// The LDLᵀ alone (no skew part).
    Direct,
    /// Woodbury: the block `W = S⁻¹ I_C` is kept, a new right-hand side costs one solve.
    Woodbury,
    /// GMRES preconditioned by the LDLᵀ.
    Gmres,
}

/// Skew entries kept for the Woodbury correction at most (beyond: GMRES).
pub(super) const SKEW_ENTRIES: usize = 1 << 14;

impl SymmetricPart {
    pub(super) fn new(
        pattern: faer::sparse::SymbolicSparseColMatRef<'_, usize>,
        ordering: FillOrdering,
    ) -> Result<Self, String> {
        let (ptr, rows) = (pattern.col_ptr(), pattern.row_idx());
        let n = pattern.ncols();
        if rows.len() >= u32::MAX as usize {
            return Err(format!("{} nonzeros: more than 2^32", rows.len()));
        }
        let mut lower_ptr = Vec::with_capacity(n + 1);
        let mut lower_rows = Vec::new();
        let mut transpose = Vec::new();
        lower_ptr.push(0);
        for j in 0..n {
            for &i in &rows[ptr[j]..ptr[j + 1]] {
                if i < j {
                    continue;
                }
                let column = &rows[ptr[i]..ptr[i + 1]];
                // A structurally symmetric pattern (element blocks are square): (j, i) exists.
                let k = column
                    .binary_search(&j)
                    .map_or(u32::MAX, |k| (ptr[i] + k) as u32);
                lower_rows.push(i);
                transpose.push(k);
            }
            lower_ptr.push(lower_rows.len());
        }
        // Upper entries without a lower twin make the pattern unsymmetric too.
        let lower_count = lower_rows.len();
        let structural =
            transpose.iter().all(|&t| t != u32::MAX) && 2 * lower_count - n == rows.len();
        let lower = SymbolicSparseColMat::new_checked(n, n, lower_ptr, None, lower_rows);
        let symbolic = ordering::analyse(lower.as_ref(), ordering).map_err(|e| format!("{e:?}"))?;
        let symbolic = Analysed::new(symbolic, lower.as_ref());
        Ok(Self::with_analysis(
            Arc::new(lower),
            Arc::new(symbolic),
            transpose.into(),
            structural,
        ))
    }

    /// The part over an analysed pattern, with empty work arrays (one place lists them).
    pub(super) fn with_analysis(
        lower: Arc<SymbolicSparseColMat<usize>>,
        symbolic: Arc<Analysed>,
        transpose: Arc<[u32]>,
        structural: bool,
    ) -> Self {
        let mut part = Self {
            lower,
            symbolic,
            factor: Vec::new(),
            transpose,
            structural,
            rhs: Vec::new(),
            symmetric_values: Vec::new(),
            row_norms: Vec::new(),
            skew: Vec::new(),
            skew_overflow: false,
            dofs: Vec::new(),
            block: Vec::new(),
            block_scratch: MemBuffer::new(StackReq::EMPTY),
            block_columns: 0,
            scratch: MemBuffer::new(StackReq::EMPTY),
            path: Path::Direct,
            threads: 1,
        };
        part.scratch = MemBuffer::new(part.scratch_req());
        part
    }

    /// Sets the threads of the numeric factorization (resolved: at least 1).
    pub(super) fn set_threads(&mut self, threads: usize) {
        self.threads = threads;
        self.scratch = MemBuffer::new(self.scratch_req());
    }

    pub(super) fn scratch_req(&self) -> StackReq {
        StackReq::any_of(&[
            self.symbolic
                .factorize_numeric_ldlt_scratch::<f64>(pool::par(self.threads), Default::default()),
            self.symbolic.solve_in_place_scratch::<f64>(1, Par::Seq),
        ])
    }

    pub(super) fn fresh_copy(&self) -> Self {
        let mut copy = Self::with_analysis(
            self.lower.clone(),
            self.symbolic.clone(),
            self.transpose.clone(),
            self.structural,
        );
        copy.set_threads(self.threads);
        copy
    }

    /// One pass over the lower triangle of `a`: the symmetric part, the row sums of `|A|` and
    /// the skew entries above `1e-12` of the largest entry. Returns whether there are none
    /// (the values are symmetric).
    pub(super) fn split(&mut self, a: SparseColMatRef<'_, usize, f64>) -> bool {
        let (ptr, v) = (a.col_ptr(), a.val());
        let (lower_ptr, lower_rows) = (self.lower.col_ptr(), self.lower.row_idx());
        let n = a.ncols();
        self.symmetric_values.resize(lower_rows.len(), 0.0);
        self.row_norms.clear();
        self.row_norms.resize(n, 0.0);
        self.skew.clear();
        self.skew_overflow = false;
        let mut scale = 0.0_f64;
        for j in 0..n {
            let (start, end) = (lower_ptr[j], lower_ptr[j + 1]);
            // The lower entries end each column of the full pattern.
            let first = ptr[j + 1] - (end - start);
            for (k, p) in (start..end).zip(first..) {
                let i = lower_rows[k];
                let (x, y) = (v[p], v[self.transpose[k] as usize]);
                self.symmetric_values[k] = 0.5 * (x + y);
                self.row_norms[i] += x.abs();
                if i != j {
                    self.row_norms[j] += y.abs();
                }
                scale = scale.max(x.abs()).max(y.abs());
                // Entries at or below the running tolerance are below the final one too.
                let d = x - y;
                if d.abs() > 1e-12 * scale {
                    if self.skew.len() < SKEW_ENTRIES {
                        self.skew.push((i, j, 0.5 * d));
                    } else {
                        self.skew_overflow = true;
                    }
                }
            }
        }
        let tolerance = 1e-12 * scale;
        self.skew.retain(|&(_, _, h)| 2.0 * h.abs() > tolerance);
        if self.skew_overflow {
            // Many entries passed the running tolerance: is any above the final one?
            let any = (0..n).any(|j| {
                let (start, end) = (lower_ptr[j], lower_ptr[j + 1]);
                let first = ptr[j + 1] - (end - start);
                (start..end)
                    .zip(first..)
                    .any(|(k, p)| (v[p] - v[self.transpose[k] as usize]).abs() > tolerance)
            });
            self.skew_overflow = any;
            if !any {
                self.skew.clear();
            }
        }
        self.skew.is_empty() && !self.skew_overflow
    }

    /// The DOFs the skew part touches (sorted), or `None` when more than `limit`.
    pub(super) fn skew_dofs(&mut self, limit: usize) -> Option<usize> {
        if self.skew_overflow {
            return None;
        }
        self.dofs.clear();
        for &(i, j, _) in &self.skew {
            self.dofs.push(i);
            self.dofs.push(j);
        }
        self.dofs.sort_unstable();
        self.dofs.dedup();
        (self.dofs.len() <= limit).then_some(self.dofs.len())
    }
}

impl SymmetricPart {
    /// Solves `a x = rhs` on the LDLᵀ of the symmetric part (directly, by Woodbury with at most
    /// `limit` DOFs, or by GMRES). False when the factorization fails or no solution passes the
    /// accuracy check; `self.rhs` then holds the right-hand side.
    pub(super) fn solve(
        &mut self,
        a: SparseColMatRef<'_, usize, f64>,
        rhs: &mut [f64],
        limit: usize,
        ctx: &mut Context<'_>,
    ) -> bool {
        let symmetric = timed(&mut ctx.profile.symmetric_part, || self.split(a));
        let woodbury = !symmetric && self.skew_dofs(limit).is_some();
        if self.factor.is_empty() {
            self.factor = vec![0.0; self.symbolic.len_val()];
        }
        let s = SparseColMatRef::new(self.lower.as_ref().as_ref(), &self.symmetric_values);
        let start = Instant::now();
        let factored = pool::factorize_ldlt(
            &self.symbolic,
            &mut self.factor,
            s,
            self.threads,
            &mut self.scratch,
        );
        ctx.profile.ldlt += start.elapsed();
        ctx.profile.ldlt_count += 1;
        if factored.is_err() {
            self.rhs.clear();
            self.rhs.extend_from_slice(rhs);
            return false;
        }
        self.path = if symmetric {
            Path::Direct
        } else if woodbury {
            Path::Woodbury
        } else {
            Path::Gmres
        };
        self.solve_factored(a, rhs, (true, false), ctx)
    }

    /// Solves `a x = rhs` on the LDLᵀ held (of `a`'s symmetric part) along [`Self::path`]:
    /// `fresh` when the factorization was just made (the Woodbury block `W` is then computed,
    /// else reused: one solve per right-hand side on every path but GMRES's iterations). A
    /// Woodbury solution that fails the check is tried again by GMRES, and the path follows.
    /// False when no solution passes the accuracy check; `self.rhs` then holds the right-hand
    /// side.
    ///
    /// With `transpose` (only on a held factor, `fresh` false) the system is `aᵀ x = rhs`:
    /// `aᵀ = S − K` has the same symmetric part, so the Woodbury block serves with the skew
    /// part negated, and GMRES runs on `aᵀ` with the same preconditioner; each solution is
    /// checked against `aᵀ`, and the path held is left as it was.
    pub(super) fn solve_factored(
        &mut self,
        a: SparseColMatRef<'_, usize, f64>,
        rhs: &mut [f64],
        (fresh, transpose): (bool, bool),
        ctx: &mut Context<'_>,
    ) -> bool {
        let n = rhs.len();
        self.rhs.clear();
        self.rhs.extend_from_slice(rhs);
        let ldlt = LdltRef::new(&*self.symbolic, &self.factor);
        let stack = MemStack::new(&mut self.scratch);
        let check = |x: &[f64], ctx: &mut Context<'_>| {
            timed(&mut ctx.profile.accuracy, || {
                if transpose {
                    accurate_transpose(a, x, &self.rhs, ctx.krylov)
                } else {
                    accurate(a, x, &self.rhs, &self.row_norms, ctx.krylov)
                }
            })
        };
        if self.path == Path::Direct {
            timed(&mut ctx.profile.ldlt_solve, || {
                pool::solve_ldlt(
                    &self.symbolic,
                    &self.factor,
                    rhs,
                    self.threads,
                    &mut self.scratch,
                )
            });
            if check(rhs, ctx) {
                ctx.counts[1] += 1;
                return true;
            }
            return false;
        }
        if self.path == Path::Woodbury {
            let start = Instant::now();
            let c = self.dofs.len();
            let m = c + 1;
            if fresh {
                self.block.clear();
                self.block.resize(n * m, 0.0);
                for (k, &d) in self.dofs.iter().enumerate() {
                    self.block[k * n + d] = 1.0;
                }
            }
            self.block[c * n..].copy_from_slice(&self.rhs);
            // A fresh block solves every column, a held one only the new right-hand side's.
            let (first, columns) = if fresh { (0, m) } else { (c, 1) };
            if self.block_columns < columns {
                self.block_scratch = MemBuffer::new(
                    self.symbolic
                        .solve_in_place_scratch::<f64>(columns, Par::Seq),
                );
                self.block_columns = columns;
            }
            ldlt.solve_in_place_with_conj(
                Conj::No,
                MatMut::from_column_major_slice_mut(&mut self.block[first * n..], n, columns),
                Par::Seq,
                MemStack::new(&mut self.block_scratch),
            );
            let sign = if transpose { -1.0 } else { 1.0 };
            let solved = woodbury_correction(&self.dofs, (&self.skew, sign), &self.block, rhs);
            ctx.profile.woodbury += start.elapsed();
            ctx.profile.woodbury_count += 1;
            ctx.profile.woodbury_columns += columns;
            if solved && check(rhs, ctx) {
                ctx.counts[3] += 1;
                return true;
            }
            if !transpose {
                self.path = Path::Gmres;
            }
        }
        let start = Instant::now();
        let mut precondition = |v: &mut [f64]| {
            let x = MatMut::from_column_major_slice_mut(v, n, 1);
            ldlt.solve_in_place_with_conj(Conj::No, x, Par::Seq, &mut *stack);
        };
        let solved = gmres(
            (a, transpose),
            &self.rhs,
            rhs,
            &mut precondition,
            ctx.krylov,
        );
        ctx.profile.gmres += start.elapsed();
        ctx.profile.gmres_count += 1;
        ctx.profile.gmres_iterations += ctx.krylov.last_iterations;
        ctx.profile.gmres_max = ctx.profile.gmres_max.max(ctx.krylov.last_iterations);
        if solved && check(rhs, ctx) {
            ctx.counts[3] += 1;
            return true;
        }
        false
    }
}
