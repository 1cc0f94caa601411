//! Sparse factorization of the Newton matrix with the symbolic analysis done once per analysis.
//!
//! * symmetric (Ju–Rowlands) matrix: LDLᵀ (`faer`'s supernodal/simplicial symbolic analysis,
//!   AMD ordering, nested dissection from 100 k equations: `ordering.rs`; a supernodal one is
//!   factorized multifrontally, sibling subtrees on separate threads: `multifrontal.rs`),
//!   which also handles the indefinite matrices of compressed films;
//! * the consistent tangent `A` (full pattern): one pass over its lower triangle forms the
//!   symmetric part `S = (A + Aᵀ)/2` through a transpose map built once, the row sums of `|A|`
//!   and the entries of the skew part `K = (A − Aᵀ)/2` above `1e-12` of the largest entry; then
//!   the LDLᵀ of `S` (issue 11 items 1 and 2):
//!   - no skew entry (no slipping gap, no follower pressure, no slipping curved contact): that
//!     LDLᵀ solves `A x = b`;
//!   - skew entries on at most [`LinearSolver::woodbury_limit`] DOFs `C` (a few slipping gaps):
//!     the Woodbury identity `A⁻¹b = y − W (I + K_CC W_C)⁻¹ K_CC y_C` with `[W y] = S⁻¹ [I_C b]`,
//!     one solve with `|C| + 1` right-hand sides (the factor is read once for all of them);
//!   - more (follower pressures, many slipping gaps), or a Woodbury solution that fails the
//!     accuracy check: GMRES (no restart, at most [`KRYLOV_DIMENSION`](gmres::KRYLOV_DIMENSION) vectors, to
//!     `‖b − A x‖₂ ≤ 1e-12 ‖b‖₂`) right-preconditioned by the same LDLᵀ;
//!
//!   so a Newton iteration costs one LDLᵀ and a block solve and keeps its quadratic convergence;
//! * every solution is checked, `‖A x − b‖∞ ≤ 1e-9 (‖A‖∞‖x‖∞ + ‖b‖∞)` in every row; one that
//!   fails (an indefinite matrix the unpivoted LDLᵀ cannot take, a Krylov space too small) is
//!   redone by LU (counted in [`LinearSolver::counts`]): on a structurally symmetric pattern
//!   the multifrontal LU with pivoting inside its fronts (`frontal_lu.rs`), its solution
//!   checked the same way, and where a front refuses a pivot or the check fails `faer`'s LU
//!   with global partial pivoting (`SymbolicLu`, counted in [`SolveProfile::lu_pivoted`]).
//!   The LU's symbolic analysis is built at its first use, and the fast paths usually never
//!   need it.
//!
//! The factor of the last factorization is held: [`LinearSolver::solve_held`] solves another
//! right-hand side with it (the same path, the Woodbury block `W` reused, every solution
//! checked), which is how each seed of a directional derivative costs one solve
//! (`sensitivity.rs`). [`LinearSolver::factor_id`] names the factor held, so that a caller can
//! tell that no factorization has replaced it since. [`LinearSolver::solve_held_transpose`]
//! solves `Aᵀ x = b` with the same factor (an adjoint's solve, issue 45): the LU's transpose
//! solve, or on the symmetric part's LDLᵀ the same path with `Aᵀ = S − K` (the Woodbury block
//! reused with the skew part negated, GMRES on `Aᵀ` with the same preconditioner), checked
//! against `Aᵀ` in every row and redone by an LU's transpose solve when the check fails.
//!
//! Buffers (factor values, scratch) are allocated once and reused every iteration; where the
//! time goes is summed in [`SolveProfile`].
//!
//! | file | what |
//! |---|---|
//! | `mod.rs` | [`LinearSolver`]: the choice of path, the accuracy check, counts and profile |
//! | `ldlt` | LDLᵀ of the symmetric part and the dispatch of a solve on it |
//! | `woodbury` | the Woodbury correction for a skew part on few DOFs |
//! | `gmres` | GMRES right-preconditioned by that LDLᵀ |
//! | `lu` | the LU, the checked fallback: frontal, else with global partial pivoting |
//! | `frontal_lu` | the multifrontal LU on the symmetric pattern's tree, pivoting inside its fronts |
//! | `ordering` | the fill-reducing ordering of the LDLᵀ analyses: AMD, or nested dissection from 100 k equations |
//! | `pool` | the LDLᵀ numeric factorization on a scoped thread pool ([`LinearSolver::set_threads`]) |
//! | `tests` | the solver's tests |

use std::sync::Arc;
use std::sync::atomic::{AtomicU64, Ordering};
use std::time::{Duration, Instant};

use faer::dyn_stack::{MemBuffer, MemStack, StackReq};
use faer::sparse::SparseColMatRef;
use faer::sparse::linalg::cholesky::LdltRef;
use faer::{Conj, MatMut, Par};

use crate::mech::solve::assembly::{Dof, System};

mod frontal_lu;
mod gmres;
mod ldlt;
mod lu;
mod multifrontal;
pub mod ordering;
mod pool;
mod woodbury;

pub use ordering::FillOrdering;
pub use pool::PARALLEL_MIN_FACTOR;

use gmres::{Krylov, gmres};
use ldlt::SymmetricPart;
use lu::LuPart;
use multifrontal::Analysed;

/// A factorization failure (singular or non-finite matrix); the message names the nodes.
#[derive(Clone, Debug, PartialEq)]
pub struct FactorizationError(pub String);

/// How an unsymmetric consistent tangent is solved on the LDLᵀ of its symmetric part.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum UnsymmetricMethod {
    /// Woodbury when the skew part touches at most [`LinearSolver::woodbury_limit`] DOFs, else
    /// GMRES (the default).
    #[default]
    Auto,
    /// GMRES preconditioned by the LDLᵀ always.
    Gmres,
    /// The Woodbury correction whenever the skew part is confined to few enough DOFs to be
    /// stored (else GMRES).
    Woodbury,
}

/// Wall-clock time and work of the solves so far, by part (see the module doc).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SolveProfile {
    /// Symbolic analyses (LDLᵀ at creation, LU at its first use).
    pub symbolic: Duration,
    /// The pass forming the symmetric part, the row norms and the skew entries.
    pub symmetric_part: Duration,
    /// LDLᵀ numeric factorizations.
    pub ldlt: Duration,
    /// Number of LDLᵀ numeric factorizations.
    pub ldlt_count: usize,
    /// Single right-hand-side LDLᵀ solves of symmetric systems.
    pub ldlt_solve: Duration,
    /// Woodbury corrections (block solve and the small dense system).
    pub woodbury: Duration,
    /// Woodbury solves.
    pub woodbury_count: usize,
    /// Total right-hand sides of the Woodbury block solves (`|C| + 1` each).
    pub woodbury_columns: usize,
    /// GMRES solves (preconditioner solves, products, orthogonalization).
    pub gmres: Duration,
    /// GMRES solves started.
    pub gmres_count: usize,
    /// GMRES iterations in all.
    pub gmres_iterations: usize,
    /// Most GMRES iterations in one solve.
    pub gmres_max: usize,
    /// Accuracy checks of the fast paths' solutions.
    pub accuracy: Duration,
    /// LU numeric factorizations and solves (symbolic analysis in `symbolic`).
    pub lu: Duration,
    /// Number of LU factorizations.
    pub lu_count: usize,
    /// Of these, the ones redone with global partial pivoting after the frontal LU refused a
    /// pivot or its solution failed the check.
    pub lu_pivoted: usize,
    /// Solves with a held factor ([`LinearSolver::solve_held`]), no factorization.
    pub held_solves: usize,
}

impl SolveProfile {
    /// Time of every part together.
    pub fn total(&self) -> Duration {
        self.symbolic
            + self.symmetric_part
            + self.ldlt
            + self.ldlt_solve
            + self.woodbury
            + self.gmres
            + self.accuracy
            + self.lu
    }
}

/// Time `f` into `slot`.
fn timed<T>(slot: &mut Duration, f: impl FnOnce() -> T) -> T {
    let start = Instant::now();
    let out = f();
    *slot += start.elapsed();
    out
}

/// Which factor the last factorization left for [`LinearSolver::solve_held`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Held {
    None,
    /// The LDLᵀ of a lower-triangle (Ju–Rowlands) matrix.
    Ldlt,
    /// The LDLᵀ of the symmetric part, solved along its path (`ldlt::Path`).
    Symmetric,
    /// The LU.
    Lu,
}

/// Source of [`LinearSolver::factor_id`] (0: none).
static FACTORS: AtomicU64 = AtomicU64::new(1);

enum Kind {
    Ldlt {
        symbolic: Arc<Analysed>,
        factor: Vec<f64>,
    },
    Full {
        /// Built at creation without a symmetric part, else at the first fallback.
        lu: Option<Box<LuPart>>,
        /// The LDLᵀ of the same pattern's symmetric part, when the fast paths are allowed.
        symmetric: Option<Box<SymmetricPart>>,
    },
}

/// Factorization of the free–free Newton matrix with a reusable symbolic analysis.
pub struct LinearSolver {
    kind: Kind,
    scratch: MemBuffer,
    /// Global DOF (`3 × node + axis`) of each equation, to name nodes in errors.
    equation_dofs: Arc<[u32]>,
    /// Solves: LU, LDLᵀ of a symmetric consistent tangent, LDLᵀ or Krylov rejected and redone
    /// by LU, GMRES or Woodbury on the symmetric part's LDLᵀ.
    counts: [usize; 4],
    /// Krylov work space (basis vectors, Hessenberg matrix), reused.
    krylov: Krylov,
    /// Whether the LDLᵀ and Krylov paths may be taken (else LU for full patterns).
    fast: bool,
    /// When LU is affordable, the fast paths are skipped after they failed ([`FastBackoff`]).
    backoff: FastBackoff,
    method: UnsymmetricMethod,
    profile: SolveProfile,
    /// The factor the last factorization left, and its identity (0: none).
    held: Held,
    factor_id: u64,
    /// Threads of the numeric LDLᵀ factorizations (resolved: at least 1).
    threads: usize,
}

impl std::fmt::Debug for LinearSolver {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let name = match self.kind {
            Kind::Ldlt { .. } => "LDLt",
            Kind::Full { .. } => "LU",
        };
        write!(f, "LinearSolver({name})")
    }
}

impl Clone for LinearSolver {
    fn clone(&self) -> Self {
        let kind = match &self.kind {
            Kind::Ldlt { symbolic, factor } => Kind::Ldlt {
                symbolic: symbolic.clone(),
                factor: vec![0.0; factor.len()],
            },
            Kind::Full { lu, symmetric } => Kind::Full {
                lu: lu.as_ref().map(|l| Box::new(l.fresh_copy())),
                symmetric: symmetric.as_ref().map(|p| Box::new(p.fresh_copy())),
            },
        };
        Self {
            kind,
            scratch: MemBuffer::new(self.scratch_req()),
            equation_dofs: self.equation_dofs.clone(),
            counts: [0; 4],
            krylov: Krylov::default(),
            fast: true,
            backoff: FastBackoff::default(),
            method: self.method,
            profile: SolveProfile::default(),
            // The copy's factor values are not copied: it holds none.
            held: Held::None,
            factor_id: 0,
            threads: self.threads,
        }
    }
}

impl LinearSolver {
    /// Symbolic analysis of the system's pattern: LDLᵀ if it stores the lower triangle; else,
    /// with `symmetric_when_possible`, LDLᵀ of its symmetric part (LU analysed when first
    /// needed), without it LU.
    pub fn new(system: &System, symmetric_when_possible: bool) -> Result<Self, FactorizationError> {
        Self::with_ordering(system, symmetric_when_possible, FillOrdering::Auto)
    }

    /// [`Self::new`] with the LDLᵀ and frontal LU analyses under `ordering` (faer's LU with
    /// global pivoting keeps its COLAMD).
    pub fn with_ordering(
        system: &System,
        symmetric_when_possible: bool,
        ordering: FillOrdering,
    ) -> Result<Self, FactorizationError> {
        let err =
            |e: faer::sparse::FaerError| FactorizationError(format!("symbolic analysis: {e:?}"));
        let started = Instant::now();
        let kind = if system.is_lower_only() {
            let symbolic = ordering::analyse(system.pattern(), ordering).map_err(err)?;
            let symbolic = Analysed::new(symbolic, system.pattern());
            let factor = vec![0.0; symbolic.len_val()];
            Kind::Ldlt {
                symbolic: Arc::new(symbolic),
                factor,
            }
        } else if symmetric_when_possible {
            Kind::Full {
                lu: None,
                symmetric: Some(Box::new(
                    SymmetricPart::new(system.pattern(), ordering)
                        .map_err(|e| FactorizationError(format!("symbolic analysis: {e}")))?,
                )),
            }
        } else {
            Kind::Full {
                lu: Some(Box::new(LuPart::analyse(system.pattern(), ordering)?)),
                symmetric: None,
            }
        };
        let equation_dofs = system
            .dofs
            .iter()
            .enumerate()
            .filter(|(_, d)| matches!(d, Dof::Free(_)))
            .map(|(i, _)| u32::try_from(i))
            .collect::<Result<Arc<[u32]>, _>>()
            .map_err(|_| FactorizationError("more than 2^32 DOFs".into()))?;
        let mut solver = Self {
            kind,
            scratch: MemBuffer::new(StackReq::EMPTY),
            equation_dofs,
            counts: [0; 4],
            krylov: Krylov::default(),
            fast: true,
            backoff: FastBackoff::default(),
            method: UnsymmetricMethod::Auto,
            profile: SolveProfile::default(),
            held: Held::None,
            factor_id: 0,
            threads: 1,
        };
        solver.scratch = MemBuffer::new(solver.scratch_req());
        solver.profile.symbolic = started.elapsed();
        Ok(solver)
    }

    fn scratch_req(&self) -> StackReq {
        match &self.kind {
            Kind::Ldlt { symbolic, .. } => StackReq::any_of(&[
                symbolic.factorize_numeric_ldlt_scratch::<f64>(
                    pool::par(self.threads),
                    Default::default(),
                ),
                symbolic.solve_in_place_scratch::<f64>(1, Par::Seq),
            ]),
            // The parts hold their own.
            Kind::Full { .. } => StackReq::EMPTY,
        }
    }

    /// Sets the threads of the numeric LDLᵀ factorizations: `requested` when positive, else
    /// automatic (the available cores for factors of [`PARALLEL_MIN_FACTOR`] values or more,
    /// else 1). Each factorization starts its threads and joins them before it returns.
    pub fn set_threads(&mut self, requested: usize) {
        let threads = pool::resolve(requested, self.factor_len());
        if threads == self.threads {
            return;
        }
        self.threads = threads;
        self.scratch = MemBuffer::new(self.scratch_req());
        if let Kind::Full {
            symmetric: Some(part),
            ..
        } = &mut self.kind
        {
            part.set_threads(self.threads);
        }
    }

    /// Threads of the numeric LDLᵀ factorizations.
    pub fn threads(&self) -> usize {
        self.threads
    }

    /// Allows (true, the default) or forbids the LDLᵀ and Krylov paths for full patterns.
    pub fn set_fast(&mut self, fast: bool) {
        self.fast = fast;
    }

    /// Chooses how unsymmetric matrices are solved on the symmetric part's LDLᵀ.
    pub fn set_method(&mut self, method: UnsymmetricMethod) {
        self.method = method;
    }

    /// Solves so far: `[LU, LDLᵀ of a symmetric consistent tangent, LDLᵀ, Woodbury or GMRES
    /// rejected and redone by LU, Woodbury or GMRES on the symmetric part's LDLᵀ]`.
    pub fn counts(&self) -> [usize; 4] {
        self.counts
    }

    /// Where the solves' time went so far.
    pub fn profile(&self) -> SolveProfile {
        self.profile
    }

    /// Whether the LU's symbolic analysis has been built.
    pub fn has_lu(&self) -> bool {
        matches!(&self.kind, Kind::Full { lu: Some(_), .. })
    }

    /// Number of stored values of the LDLᵀ factor (0 for LU only).
    pub fn factor_len(&self) -> usize {
        match &self.kind {
            Kind::Ldlt { factor, .. } => factor.len(),
            Kind::Full {
                symmetric: Some(p), ..
            } => p.symbolic.len_val(),
            Kind::Full { .. } => 0,
        }
    }

    /// Largest number of DOFs the skew part may touch for the Woodbury correction under
    /// [`UnsymmetricMethod::Auto`]: its block `[W y]` (`n × (|C| + 1)` values) within a quarter
    /// of the LDLᵀ factor (then its block solve costs a fraction of the factorization) or
    /// within [`WOODBURY_SMALL`] values, and at most [`WOODBURY_MOST`] DOFs. Measured: GMRES
    /// took 7 iterations on average (25 at most) on the 76 k-DOF specimen with its 5 skew DOFs,
    /// 4× the time of the Woodbury block solve; on the 38-gap strip (97 skew DOFs of 114) it
    /// never converged within [`KRYLOV_DIMENSION`](gmres::KRYLOV_DIMENSION) iterations, where Woodbury does.
    pub fn woodbury_limit(&self) -> usize {
        let n = self.equation_dofs.len().max(1);
        let values = (self.factor_len() / 4).max(WOODBURY_SMALL);
        (values / n).saturating_sub(1).min(WOODBURY_MOST)
    }

    /// Whether an LU of this system is cheap enough to replace the fast paths after they failed
    /// ([`FastBackoff`]): the symmetric part's LDLᵀ factor holds at most [`LU_AFFORDABLE`]
    /// values (faer's LU of the unsymmetric pattern was measured at about 6× the LDLᵀ's memory
    /// and 4–6× its time on the refined specimens; the frontal LU holds about twice the
    /// supernodal LDLᵀ's values).
    pub fn lu_affordable(&self) -> bool {
        self.factor_len() <= LU_AFFORDABLE
    }

    /// Bytes held for the solves beyond the symbolic analyses: factor values, the symmetric
    /// part's values, the Woodbury block and the Krylov basis.
    pub fn memory_bytes(&self) -> usize {
        let f = std::mem::size_of::<f64>();
        let krylov = self.krylov.basis.iter().map(Vec::len).sum::<usize>() * f;
        krylov
            + match &self.kind {
                Kind::Ldlt { factor, .. } => factor.len() * f,
                Kind::Full { symmetric, lu } => {
                    lu.as_ref().map_or(0, |l| l.factor_len() * f)
                        + symmetric.as_ref().map_or(0, |p| {
                            (p.factor.len() + p.symmetric_values.len() + p.block.len()) * f
                                + p.transpose.len() * std::mem::size_of::<u32>()
                                + (p.lower.col_ptr().len() + p.lower.row_idx().len())
                                    * std::mem::size_of::<usize>()
                        })
                }
            }
    }

    /// Numeric factorization of `matrix` (same pattern as the symbolic analysis), then the
    /// solution of `matrix · x = rhs` in place. A singular or non-finite matrix (a zero pivot
    /// gives Inf/NaN in `rhs`) is an error naming the nodes involved, never a NaN solution.
    pub fn factorize_and_solve(
        &mut self,
        matrix: SparseColMatRef<'_, usize, f64>,
        rhs: &mut [f64],
    ) -> Result<(), FactorizationError> {
        self.held = Held::None;
        self.factor_id = 0;
        let solved = self.factorize_and_solve_unchecked(matrix, rhs);
        if solved.is_ok() && rhs.iter().all(|v| v.is_finite()) {
            self.factor_id = FACTORS.fetch_add(1, Ordering::Relaxed);
            return solved;
        }
        self.held = Held::None;
        self.finish_failure(matrix, rhs, solved)
    }

    /// The error of a failed solve, naming the DOFs behind it.
    fn finish_failure(
        &self,
        matrix: SparseColMatRef<'_, usize, f64>,
        rhs: &[f64],
        solved: Result<(), FactorizationError>,
    ) -> Result<(), FactorizationError> {
        let why = solved
            .err()
            .map_or(String::new(), |e| format!(" ({})", e.0));
        Err(FactorizationError(format!(
            "{}{why}",
            self.diagnose(matrix, rhs)
        )))
    }

    /// The identity of the factor held (unique in the process; 0 when none is held): it
    /// changes with every factorization, so a caller that noted it knows whether
    /// [`Self::solve_held`] still solves with the matrix it factorized.
    pub fn factor_id(&self) -> u64 {
        self.factor_id
    }

    /// Solves `matrix · x = rhs` in place with the factor held from the last
    /// [`Self::factorize_and_solve`], which must have been given the same `matrix` (same
    /// values): one solve along the same path, no factorization, the solution checked as
    /// always. A solution that fails the check, or no factor held, falls back to
    /// [`Self::factorize_and_solve`] (a new factor, a new [`Self::factor_id`]).
    pub fn solve_held(
        &mut self,
        matrix: SparseColMatRef<'_, usize, f64>,
        rhs: &mut [f64],
    ) -> Result<(), FactorizationError> {
        let original = rhs.to_vec();
        if self.solve_on_held(matrix, rhs, false) {
            return Ok(());
        }
        rhs.copy_from_slice(&original);
        self.factorize_and_solve(matrix, rhs)
    }

    /// Solves `matrixᵀ · x = rhs` in place with the factor held from the last
    /// [`Self::factorize_and_solve`] of the same `matrix` (an adjoint's solve): the LU's
    /// transpose solve; on the symmetric part's LDLᵀ, directly, by Woodbury with the skew part
    /// negated (`Aᵀ = S − K`, the block `W` reused) or by GMRES on `Aᵀ` with the same
    /// preconditioner, the solution checked against `Aᵀ` in every row. A solution that fails
    /// the check, or no factor held, is redone by an LU of `matrix` (a new factor, a new
    /// [`Self::factor_id`]) and its transpose solve.
    pub fn solve_held_transpose(
        &mut self,
        matrix: SparseColMatRef<'_, usize, f64>,
        rhs: &mut [f64],
    ) -> Result<(), FactorizationError> {
        if matches!(self.kind, Kind::Ldlt { .. }) {
            // A lower-triangle (Ju–Rowlands) matrix is symmetric: its own transpose.
            return self.solve_held(matrix, rhs);
        }
        let original = rhs.to_vec();
        if self.solve_on_held(matrix, rhs, true) {
            return Ok(());
        }
        rhs.copy_from_slice(&original);
        self.lu_transpose(matrix, rhs)
    }

    /// `matrix x = rhs` (`matrixᵀ x = rhs` with `transpose`) in place along the held factor's
    /// path; false when none is held or the solution fails its check or is not finite.
    fn solve_on_held(
        &mut self,
        matrix: SparseColMatRef<'_, usize, f64>,
        rhs: &mut [f64],
        transpose: bool,
    ) -> bool {
        let n = rhs.len();
        let solved = match &mut self.kind {
            _ if self.factor_id == 0 => false,
            Kind::Ldlt { symbolic, factor } if self.held == Held::Ldlt => {
                let ldlt = LdltRef::new(&**symbolic, factor);
                let x = MatMut::from_column_major_slice_mut(rhs, n, 1);
                timed(&mut self.profile.ldlt_solve, || {
                    ldlt.solve_in_place_with_conj(
                        Conj::No,
                        x,
                        Par::Seq,
                        MemStack::new(&mut self.scratch),
                    )
                });
                true
            }
            Kind::Full {
                symmetric: Some(part),
                ..
            } if self.held == Held::Symmetric => {
                let mut ctx = Context {
                    krylov: &mut self.krylov,
                    profile: &mut self.profile,
                    counts: &mut self.counts,
                };
                part.solve_factored(matrix, rhs, (false, transpose), &mut ctx)
            }
            Kind::Full { lu: Some(lu), .. } if self.held == Held::Lu => {
                // `held` is `Lu` only after its numeric factorization succeeded.
                timed(&mut self.profile.lu, || lu.solve(rhs, transpose));
                true
            }
            _ => false,
        };
        let solved = solved && rhs.iter().all(|v| v.is_finite());
        if solved {
            self.profile.held_solves += 1;
        }
        solved
    }

    /// `matrixᵀ x = rhs` by a new LU of `matrix` (the fast paths skipped), then held.
    fn lu_transpose(
        &mut self,
        matrix: SparseColMatRef<'_, usize, f64>,
        rhs: &mut [f64],
    ) -> Result<(), FactorizationError> {
        let fast = std::mem::replace(&mut self.fast, false);
        let mut forward = rhs.to_vec();
        let factored = self.factorize_and_solve(matrix, &mut forward);
        self.fast = fast;
        factored?;
        let Kind::Full { lu: Some(lu), .. } = &mut self.kind else {
            return Err(FactorizationError("no LU for the transpose solve".into()));
        };
        timed(&mut self.profile.lu, || lu.solve(rhs, true));
        if rhs.iter().all(|v| v.is_finite()) {
            return Ok(());
        }
        self.finish_failure(matrix, rhs, Ok(()))
    }

    /// Names the DOFs behind a failed solution: non-finite matrix entries, then DOFs without any
    /// stiffness (a zero column: a node held only by open gaps), then the non-finite entries of
    /// the solution (a singular matrix: a rigid-body mode, a mechanism).
    fn diagnose(&self, matrix: SparseColMatRef<'_, usize, f64>, rhs: &[f64]) -> String {
        let columns = |keep: &dyn Fn(usize) -> bool| -> Vec<usize> {
            (0..matrix.ncols()).filter(|&j| keep(j)).collect()
        };
        let non_finite = columns(&|j| matrix.val_of_col(j).iter().any(|v| !v.is_finite()));
        if !non_finite.is_empty() {
            return format!(
                "the Newton matrix holds non-finite entries at {}",
                self.name_dofs(&non_finite)
            );
        }
        let empty = columns(&|j| matrix.val_of_col(j).iter().all(|&v| v == 0.0));
        if !empty.is_empty() {
            return format!(
                "singular Newton matrix: no stiffness at {} (held only by open gaps, or by nothing)",
                self.name_dofs(&empty)
            );
        }
        let bad: Vec<usize> = (0..rhs.len()).filter(|&i| !rhs[i].is_finite()).collect();
        format!(
            "singular Newton matrix (zero pivot): the solution is not finite at {} (a rigid-body \
             mode or mechanism that no restraint holds)",
            self.name_dofs(&bad)
        )
    }

    /// "node 12 (x, z), node 40 (y), … (7 DOFs)" for equation numbers.
    fn name_dofs(&self, equations: &[usize]) -> String {
        pub(super) const LISTED: usize = 6;
        let mut nodes: Vec<(u32, String)> = Vec::new();
        let mut covered = 0;
        for &eq in equations {
            let dof = self.equation_dofs[eq];
            let (node, axis) = (dof / 3, ["x", "y", "z"][dof as usize % 3]);
            let same = nodes.last().is_some_and(|(n, _)| *n == node);
            if same {
                let axes = &mut nodes.last_mut().expect("checked").1;
                axes.push_str(", ");
                axes.push_str(axis);
            } else if nodes.len() == LISTED {
                break;
            } else {
                nodes.push((node, axis.to_string()));
            }
            covered += 1;
        }
        let listed: Vec<String> = nodes
            .iter()
            .map(|(n, axes)| format!("node {n} ({axes})"))
            .collect();
        let more = if equations.len() > covered {
            format!(", … ({} DOFs)", equations.len())
        } else {
            String::new()
        };
        format!("{}{more}", listed.join(", "))
    }

    fn factorize_and_solve_unchecked(
        &mut self,
        matrix: SparseColMatRef<'_, usize, f64>,
        rhs: &mut [f64],
    ) -> Result<(), FactorizationError> {
        let limit = match self.method {
            UnsymmetricMethod::Auto => self.woodbury_limit(),
            UnsymmetricMethod::Gmres => 0,
            UnsymmetricMethod::Woodbury => WOODBURY_MOST,
        };
        let affordable = self.lu_affordable();
        match &mut self.kind {
            Kind::Ldlt { symbolic, factor } => {
                let start = Instant::now();
                pool::factorize_ldlt(symbolic, factor, matrix, self.threads, &mut self.scratch)
                    .map_err(|e| FactorizationError(format!("LDLᵀ: {e:?}")))?;
                self.profile.ldlt += start.elapsed();
                self.profile.ldlt_count += 1;
                self.held = Held::Ldlt;
                let threads = self.threads;
                timed(&mut self.profile.ldlt_solve, || {
                    pool::solve_ldlt(symbolic, factor, rhs, threads, &mut self.scratch)
                });
            }
            Kind::Full { lu, symmetric } => {
                if self.fast
                    && let Some(part) = symmetric.as_mut()
                    && part.structural
                    && self.backoff.tries(affordable)
                {
                    let mut ctx = Context {
                        krylov: &mut self.krylov,
                        profile: &mut self.profile,
                        counts: &mut self.counts,
                    };
                    ctx.krylov.last_iterations = 0;
                    let solved = part.solve(matrix, rhs, limit, &mut ctx);
                    self.backoff.note(solved, self.krylov.last_iterations);
                    if solved {
                        self.held = Held::Symmetric;
                        return Ok(());
                    }
                    self.counts[2] += 1;
                    rhs.copy_from_slice(&part.rhs);
                }
                if lu.is_none() {
                    // Without a symmetric part the LU was analysed at creation.
                    let part = symmetric.as_ref().expect("a symmetric part");
                    let analysed = timed(&mut self.profile.symbolic, || {
                        if part.structural {
                            let lower = part.lower.as_ref().as_ref();
                            LuPart::analyse_ordered(matrix.symbolic(), lower, &part.symbolic)
                        } else {
                            LuPart::analyse(matrix.symbolic(), FillOrdering::Auto)
                        }
                    })?;
                    *lu = Some(Box::new(analysed));
                }
                let lu = lu.as_mut().expect("analysed above");
                self.counts[0] += 1;
                self.profile.lu_count += 1;
                let pivoted = lu.pivoted;
                timed(&mut self.profile.lu, || lu.factorize_and_solve(matrix, rhs))?;
                self.profile.lu_pivoted += lu.pivoted - pivoted;
                self.held = Held::Lu;
            }
        }
        Ok(())
    }
}

/// The fast paths' record on an unsymmetric pattern whose LU is affordable: after `k` failures
/// in a row (a wrinkled film's skew part is too large for the Krylov space, and every attempt
/// costs an LDLᵀ and [`KRYLOV_DIMENSION`](gmres::KRYLOV_DIMENSION) preconditioned products
/// before the LU), the next `2^k − 1` solves (at most 31) go to LU directly; a success clears it.
/// A GMRES solution that took more than [`GMRES_AS_DEAR_AS_LU`] iterations counts as a failure:
/// it cost more than the LU would have.
#[derive(Clone, Copy, Debug, Default)]
struct FastBackoff {
    failures: u32,
    skip: u32,
}

impl FastBackoff {
    /// Whether this solve tries the fast paths (always where LU is not `affordable`).
    fn tries(&mut self, affordable: bool) -> bool {
        if !affordable || self.skip == 0 {
            return true;
        }
        self.skip -= 1;
        false
    }

    /// Notes the outcome of a fast attempt that took `gmres_iterations` (0 off GMRES's path).
    fn note(&mut self, solved: bool, gmres_iterations: usize) {
        if solved && gmres_iterations <= GMRES_AS_DEAR_AS_LU {
            *self = Self::default();
        } else {
            self.failures = (self.failures + 1).min(5);
            self.skip = (1 << self.failures) - 1;
        }
    }
}

/// GMRES iterations beyond which a solve on the symmetric part's LDLᵀ costs more than an LU of
/// the same matrix: the LDLᵀ was about half faer's LU, and each iteration (a preconditioner
/// solve, a product, the orthogonalization) about a twentieth of the LDLᵀ (the 3.5 k-equation
/// suction panel: faer's LU 6.3 ms, LDLᵀ 3.3 ms, 0.3 ms an iteration); the share of an
/// iteration falls with the size. The frontal LU (2.3 ms there) makes it an upper bound.
const GMRES_AS_DEAR_AS_LU: usize = 10;

/// Most DOFs of the skew part for the Woodbury correction (its dense `|C| × |C|` system).
const WOODBURY_MOST: usize = 512;

/// LDLᵀ factors of up to this many values (32 MiB; the refined specimen up to ≈ 30 k DOF)
/// let LU replace fast paths that fail (see [`LinearSolver::lu_affordable`]).
const LU_AFFORDABLE: usize = 1 << 22;

/// Woodbury blocks of up to this many values are always affordable (512 KiB).
const WOODBURY_SMALL: usize = 1 << 16;

/// The solver's counters, lent to a fast solve.
struct Context<'a> {
    krylov: &'a mut Krylov,
    profile: &'a mut SolveProfile,
    counts: &'a mut [usize; 4],
}

/// Whether `x` solves `matrix · x = b` to `1e-9 (‖A‖∞‖x‖∞ + ‖b‖∞)` in every row, with the row
/// sums of `|A|` given (`k`: buffers).
fn accurate(
    matrix: SparseColMatRef<'_, usize, f64>,
    x: &[f64],
    b: &[f64],
    row_norms: &[f64],
    k: &mut Krylov,
) -> bool {
    k.residual.clear();
    k.residual.extend(b.iter().map(|v| -v));
    let r = &mut k.residual;
    let (ptr, rows, values) = (matrix.col_ptr(), matrix.row_idx(), matrix.val());
    for j in 0..matrix.ncols() {
        let xj = x[j];
        for k in ptr[j]..ptr[j + 1] {
            r[rows[k]] += values[k] * xj;
        }
    }
    let a = row_norms.iter().fold(0.0_f64, |m, &v| m.max(v));
    within(r, a, x, b)
}

/// Whether `x` solves `matrixᵀ · x = b` to `1e-9 (‖Aᵀ‖∞‖x‖∞ + ‖b‖∞)` in every row (the
/// column sums of `|A|` are `Aᵀ`'s row sums; `k`: buffers).
fn accurate_transpose(
    matrix: SparseColMatRef<'_, usize, f64>,
    x: &[f64],
    b: &[f64],
    k: &mut Krylov,
) -> bool {
    k.residual.clear();
    let mut a = 0.0_f64;
    let (ptr, rows, values) = (matrix.col_ptr(), matrix.row_idx(), matrix.val());
    for j in 0..matrix.ncols() {
        let span = ptr[j]..ptr[j + 1];
        a = a.max(span.clone().map(|p| values[p].abs()).sum());
        k.residual
            .push(span.map(|p| values[p] * x[rows[p]]).sum::<f64>() - b[j]);
    }
    within(&k.residual, a, x, b)
}

/// Whether every entry of the residual `r` is within `1e-9 (a ‖x‖∞ + ‖b‖∞)`.
fn within(r: &[f64], a: f64, x: &[f64], b: &[f64]) -> bool {
    let xm = x.iter().fold(0.0_f64, |m, &v| m.max(v.abs()));
    let bm = b.iter().fold(0.0_f64, |m, &v| m.max(v.abs()));
    let limit = 1e-9 * (a * xm + bm);
    r.iter().all(|v| v.abs() <= limit)
}

#[cfg(test)]
mod tests;
