//! LU with partial pivoting (`faer` supernodal `SymbolicLu`): the fallback of every fast path,
//! and the only path for full patterns without the symmetric option.

use std::sync::Arc;

use crate::mech::solve::linear::FactorizationError;
use faer::dyn_stack::MemStack;
use faer::dyn_stack::{MemBuffer, StackReq};
use faer::sparse::linalg::SupernodalThreshold;
use faer::sparse::linalg::lu::LuRef;
use faer::sparse::linalg::lu::{LuSymbolicParams, NumericLu, SymbolicLu, factorize_symbolic_lu};
use faer::{Conj, MatMut, Par};

pub(super) struct LuPart {
    pub(super) symbolic: Arc<SymbolicLu<usize>>,
    pub(super) numeric: NumericLu<usize, f64>,
    pub(super) scratch: MemBuffer,
}

impl LuPart {
    pub(super) fn new(symbolic: Arc<SymbolicLu<usize>>) -> Self {
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

    pub(super) fn analyse(
        pattern: faer::sparse::SymbolicSparseColMatRef<'_, usize>,
    ) -> Result<Self, FactorizationError> {
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

    /// Solves `A x = rhs` (`Aᵀ x = rhs` with `transpose`) in place with the factor of the last
    /// numeric factorization, which must have succeeded (the caller's `Held::Lu`).
    pub(super) fn solve(&mut self, rhs: &mut [f64], transpose: bool) {
        let n = rhs.len();
        // The numeric part is the output of `factorize_numeric_lu` on this symbolic analysis:
        // what `new_unchecked` asks.
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
