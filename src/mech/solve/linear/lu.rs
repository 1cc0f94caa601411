//! The LU of the full Newton matrix: the checked fallback of every fast path, and the only path
//! for full patterns without the symmetric option.
//!
//! On a structurally symmetric pattern (every element and contact block is square) it is the
//! multifrontal LU with pivoting inside the fronts (`frontal_lu.rs`), its solution checked
//! like the fast paths'; a front that refuses a pivot, or a solution that fails the check, is
//! redone by `faer`'s supernodal LU with global partial pivoting (`SymbolicLu`, COLAMD), whose
//! analysis is built at its first use. faer's LU finds its pattern while it factorizes; on
//! the 3.5 k-equation suction panel it took 6.4 ms a factorization against the frontal LU's
//! 2.7 ms.

use std::sync::Arc;

use crate::mech::solve::linear::FactorizationError;
use crate::mech::solve::linear::frontal_lu::{FrontalAnalysis, FrontalLu};
use crate::mech::solve::linear::ordering::{self, FillOrdering};
use faer::dyn_stack::MemStack;
use faer::dyn_stack::{MemBuffer, StackReq};
use faer::sparse::linalg::SupernodalThreshold;
use faer::sparse::linalg::cholesky::SymbolicCholesky;
use faer::sparse::linalg::lu::LuRef;
use faer::sparse::linalg::lu::{LuSymbolicParams, NumericLu, SymbolicLu, factorize_symbolic_lu};
use faer::sparse::{SparseColMatRef, SymbolicSparseColMat, SymbolicSparseColMatRef};
use faer::{Conj, MatMut, Par};

/// faer's LU with global partial pivoting.
pub(super) struct PivotingLu {
    pub(super) symbolic: Arc<SymbolicLu<usize>>,
    numeric: NumericLu<usize, f64>,
    scratch: MemBuffer,
}

/// Which LU factored the last matrix.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Factored {
    None,
    Frontal,
    Pivoting,
}

/// Both LUs of one pattern and the one that factored the last matrix.
pub(super) struct LuPart {
    frontal: Option<FrontalLu>,
    pivoting: Option<PivotingLu>,
    factored: Factored,
    /// The right-hand side kept for the frontal solution's check, and the check's buffers.
    original: Vec<f64>,
    residual: Vec<f64>,
    row_sums: Vec<f64>,
    /// Factorizations by global pivoting after the frontal LU refused.
    pub(super) pivoted: usize,
}

impl PivotingLu {
    fn new(symbolic: Arc<SymbolicLu<usize>>) -> Self {
        let scratch = MemBuffer::new(StackReq::any_of(&[
            symbolic.factorize_numeric_lu_scratch::<f64>(Par::Seq, Default::default()),
            symbolic.solve_in_place_scratch::<f64>(1, Par::Seq),
            symbolic.solve_transpose_in_place_scratch::<f64>(1, Par::Seq),
        ]));
        Self {
            symbolic,
            numeric: NumericLu::new(),
            scratch,
        }
    }

    fn analyse(pattern: SymbolicSparseColMatRef<'_, usize>) -> Result<Self, FactorizationError> {
        // faer's simplicial LU (its pick for small systems) was 5× slower than the supernodal
        // one on the 363-DOF specimen; the supernodal one is as fast on large systems.
        let params = LuSymbolicParams {
            supernodal_flop_ratio_threshold: SupernodalThreshold::FORCE_SUPERNODAL,
            ..Default::default()
        };
        let symbolic = factorize_symbolic_lu(pattern, params)
            .map_err(|e| FactorizationError(format!("symbolic analysis: {e:?}")))?;
        Ok(Self::new(Arc::new(symbolic)))
    }

    fn factorize_and_solve(
        &mut self,
        matrix: SparseColMatRef<'_, usize, f64>,
        rhs: &mut [f64],
    ) -> Result<(), FactorizationError> {
        let n = rhs.len();
        let stack = MemStack::new(&mut self.scratch);
        let factored = self
            .symbolic
            .factorize_numeric_lu(
                &mut self.numeric,
                matrix,
                Par::Seq,
                stack,
                Default::default(),
            )
            .map_err(|e| FactorizationError(format!("LU: {e:?}")))?;
        let x = MatMut::from_column_major_slice_mut(rhs, n, 1);
        factored.solve_in_place_with_conj(Conj::No, x, Par::Seq, stack);
        Ok(())
    }

    fn solve(&mut self, rhs: &mut [f64], transpose: bool) {
        let n = rhs.len();
        // The numeric part is the output of `factorize_numeric_lu` on this symbolic analysis
        // (the caller's `Factored::Pivoting`): what `new_unchecked` asks.
        let factored = LuRef::new_unchecked(&self.symbolic, &self.numeric);
        let x = MatMut::from_column_major_slice_mut(rhs, n, 1);
        let stack = MemStack::new(&mut self.scratch);
        if transpose {
            factored.solve_transpose_in_place_with_conj(Conj::No, x, Par::Seq, stack);
        } else {
            factored.solve_in_place_with_conj(Conj::No, x, Par::Seq, stack);
        }
    }
}

impl LuPart {
    fn with(frontal: Option<FrontalLu>, pivoting: Option<PivotingLu>) -> Self {
        Self {
            frontal,
            pivoting,
            factored: Factored::None,
            original: Vec::new(),
            residual: Vec::new(),
            row_sums: Vec::new(),
            pivoted: 0,
        }
    }

    /// The analysis of `pattern`: the frontal LU's under `ordering` where the pattern is
    /// structurally symmetric, else faer's.
    pub(super) fn analyse(
        pattern: SymbolicSparseColMatRef<'_, usize>,
        ordering: FillOrdering,
    ) -> Result<Self, FactorizationError> {
        if let Some(lower) = lower_of_symmetric(pattern) {
            let symbolic = ordering::analyse_supernodal(lower.as_ref(), ordering)
                .map_err(|e| FactorizationError(format!("symbolic analysis: {e:?}")))?;
            return Self::frontal_or_pivoting(symbolic, pattern);
        }
        Self::pivoting_only(pattern)
    }

    /// The analysis of the structurally symmetric `pattern` whose lower triangle `lower` an
    /// LDLᵀ analysis `ordered` already ordered: the frontal LU's under the same ordering (no
    /// second fill-reducing ordering of the same pattern).
    pub(super) fn analyse_ordered(
        pattern: SymbolicSparseColMatRef<'_, usize>,
        lower: SymbolicSparseColMatRef<'_, usize>,
        ordered: &SymbolicCholesky<usize>,
    ) -> Result<Self, FactorizationError> {
        let symbolic = ordering::analyse_supernodal_with(lower, ordered.perm())
            .map_err(|e| FactorizationError(format!("symbolic analysis: {e:?}")))?;
        Self::frontal_or_pivoting(symbolic, pattern)
    }

    /// The frontal LU on `symbolic` where it is supernodal and its indices fit, else faer's.
    fn frontal_or_pivoting(
        symbolic: SymbolicCholesky<usize>,
        pattern: SymbolicSparseColMatRef<'_, usize>,
    ) -> Result<Self, FactorizationError> {
        match FrontalAnalysis::new(symbolic, pattern) {
            Some(analysis) => Ok(Self::with(Some(FrontalLu::new(Arc::new(analysis))), None)),
            None => Self::pivoting_only(pattern),
        }
    }

    /// faer's LU alone (a pattern that is not structurally symmetric).
    fn pivoting_only(
        pattern: SymbolicSparseColMatRef<'_, usize>,
    ) -> Result<Self, FactorizationError> {
        Ok(Self::with(None, Some(PivotingLu::analyse(pattern)?)))
    }

    /// A part on the same analyses, holding no factor.
    pub(super) fn fresh_copy(&self) -> Self {
        Self::with(
            self.frontal.as_ref().map(|f| FrontalLu::new(f.analysis())),
            self.pivoting
                .as_ref()
                .map(|p| PivotingLu::new(p.symbolic.clone())),
        )
    }

    /// Stored values of the frontal factor (0 without one).
    pub(super) fn factor_len(&self) -> usize {
        self.frontal.as_ref().map_or(0, FrontalLu::factor_len)
    }

    /// Factorizes `matrix` and solves `matrix x = rhs` in place: the frontal LU where it takes
    /// every pivot and its solution passes the check, else global partial pivoting.
    pub(super) fn factorize_and_solve(
        &mut self,
        matrix: SparseColMatRef<'_, usize, f64>,
        rhs: &mut [f64],
    ) -> Result<(), FactorizationError> {
        self.factored = Factored::None;
        if let Some(frontal) = self.frontal.as_mut() {
            self.original.clear();
            self.original.extend_from_slice(rhs);
            if frontal.factorize(matrix).is_ok() {
                frontal.solve(rhs, false);
                if self.solves(matrix, rhs) {
                    self.factored = Factored::Frontal;
                    return Ok(());
                }
            }
            rhs.copy_from_slice(&self.original);
            self.pivoted += 1;
        }
        if self.pivoting.is_none() {
            self.pivoting = Some(PivotingLu::analyse(matrix.symbolic())?);
        }
        let pivoting = self.pivoting.as_mut().expect("analysed above");
        pivoting.factorize_and_solve(matrix, rhs)?;
        self.factored = Factored::Pivoting;
        Ok(())
    }

    /// Whether `x` solves `matrix x = original` within the fast paths' check.
    fn solves(&mut self, matrix: SparseColMatRef<'_, usize, f64>, x: &[f64]) -> bool {
        let n = x.len();
        self.residual.clear();
        self.residual.extend(self.original.iter().map(|v| -v));
        self.row_sums.clear();
        self.row_sums.resize(n, 0.0);
        let (ptr, rows, values) = (matrix.col_ptr(), matrix.row_idx(), matrix.val());
        for j in 0..n {
            for k in ptr[j]..ptr[j + 1] {
                self.residual[rows[k]] += values[k] * x[j];
                self.row_sums[rows[k]] += values[k].abs();
            }
        }
        let a = self.row_sums.iter().fold(0.0_f64, |m, &v| m.max(v));
        super::within(&self.residual, a, x, &self.original)
    }

    /// Solves `A x = rhs` (`Aᵀ x = rhs` with `transpose`) in place with the factor of the last
    /// [`Self::factorize_and_solve`], which must have succeeded (the caller's `Held::Lu`).
    pub(super) fn solve(&mut self, rhs: &mut [f64], transpose: bool) {
        match self.factored {
            Factored::Frontal => {
                let frontal = self.frontal.as_mut().expect("it factored");
                frontal.solve(rhs, transpose);
            }
            Factored::Pivoting => {
                let pivoting = self.pivoting.as_mut().expect("it factored");
                pivoting.solve(rhs, transpose);
            }
            Factored::None => rhs.fill(f64::NAN),
        }
    }
}

/// The lower triangle of `pattern` where it is structurally symmetric, else None.
fn lower_of_symmetric(
    pattern: SymbolicSparseColMatRef<'_, usize>,
) -> Option<SymbolicSparseColMat<usize>> {
    let (ptr, rows) = (pattern.col_ptr(), pattern.row_idx());
    let n = pattern.ncols();
    if pattern.nrows() != n {
        return None;
    }
    let mut lower_ptr = Vec::with_capacity(n + 1);
    let mut lower_rows = Vec::new();
    lower_ptr.push(0);
    for j in 0..n {
        for &i in &rows[ptr[j]..ptr[j + 1]] {
            rows[ptr[i]..ptr[i + 1]].binary_search(&j).ok()?;
            if i >= j {
                lower_rows.push(i);
            }
        }
        lower_ptr.push(lower_rows.len());
    }
    SymbolicSparseColMat::new_checked(n, n, lower_ptr, None, lower_rows).into()
}
