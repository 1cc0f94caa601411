//! Sparse factorization of the Newton matrix with the symbolic analysis done once per analysis.
//!
//! * symmetric (Ju–Rowlands) matrix: LDLᵀ (`faer` supernodal/simplicial Cholesky structure,
//!   AMD ordering), which also handles the indefinite matrices of compressed films;
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
//!     accuracy check: GMRES (no restart, at most [`KRYLOV_DIMENSION`] vectors, to
//!     `‖b − A x‖₂ ≤ 1e-12 ‖b‖₂`) right-preconditioned by the same LDLᵀ;
//!
//!   so a Newton iteration costs one LDLᵀ and a block solve and keeps its quadratic convergence;
//! * every solution is checked, `‖A x − b‖∞ ≤ 1e-9 (‖A‖∞‖x‖∞ + ‖b‖∞)` in every row; one that
//!   fails (an indefinite matrix the unpivoted LDLᵀ cannot take, a Krylov space too small) is
//!   redone by LU with partial pivoting (`faer` `SymbolicLu`, counted in
//!   [`LinearSolver::counts`]). The LU's symbolic analysis is built at its first use: at 1 M DOF
//!   it alone is larger than the LDLᵀ factor, and the fast paths usually never need it.
//!
//! Buffers (factor values, scratch) are allocated once and reused every iteration; where the
//! time goes is summed in [`SolveProfile`].

use std::sync::Arc;
use std::time::{Duration, Instant};

use faer::dyn_stack::{MemBuffer, MemStack, StackReq};
use faer::linalg::cholesky::ldlt::factor::LdltRegularization;
use faer::sparse::linalg::SupernodalThreshold;
use faer::sparse::linalg::cholesky::{SymbolicCholesky, factorize_symbolic_cholesky};
use faer::sparse::linalg::lu::{LuSymbolicParams, NumericLu, SymbolicLu, factorize_symbolic_lu};
use faer::sparse::{SparseColMatRef, SymbolicSparseColMat};
use faer::{Conj, MatMut, Par, Side};
use nalgebra::{DMatrix, DVector};

use super::assembly::{Dof, System};

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

enum Kind {
    Ldlt {
        symbolic: Arc<SymbolicCholesky<usize>>,
        factor: Vec<f64>,
    },
    Full {
        /// Built at creation without a symmetric part, else at the first fallback.
        lu: Option<Box<LuPart>>,
        /// The LDLᵀ of the same pattern's symmetric part, when the fast paths are allowed.
        symmetric: Option<Box<SymmetricPart>>,
    },
}

struct LuPart {
    symbolic: Arc<SymbolicLu<usize>>,
    numeric: NumericLu<usize, f64>,
    scratch: MemBuffer,
}

impl LuPart {
    fn new(symbolic: Arc<SymbolicLu<usize>>) -> Self {
        let scratch = MemBuffer::new(StackReq::any_of(&[
            symbolic.factorize_numeric_lu_scratch::<f64>(Par::Seq, Default::default()),
            symbolic.solve_in_place_scratch::<f64>(1, Par::Seq),
        ]));
        Self {
            symbolic,
            numeric: NumericLu::new(),
            scratch,
        }
    }

    fn analyse(
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
}

/// LDLᵀ of the symmetric part of a full-pattern matrix, stored on the pattern's lower triangle
/// (what a symmetric matrix's LDLᵀ reads), the slot of each lower entry's transpose, and the
/// buffers of the Woodbury correction.
struct SymmetricPart {
    /// The lower triangle of the pattern (the Ju–Rowlands matrix's pattern: same analysis).
    lower: Arc<SymbolicSparseColMat<usize>>,
    symbolic: Arc<SymbolicCholesky<usize>>,
    /// Allocated at the first factorization.
    factor: Vec<f64>,
    /// Slot in the full pattern of the transpose of each lower entry (`u32::MAX`: none).
    transpose: Arc<[u32]>,
    /// Whether every entry's transpose is in the pattern (else no fast path).
    structural: bool,
    /// The right-hand side kept for the accuracy check and the fallbacks.
    rhs: Vec<f64>,
    /// `(A + Aᵀ)/2` on the lower pattern.
    symmetric_values: Vec<f64>,
    /// Row sums of `|A|`.
    row_norms: Vec<f64>,
    /// Skew entries below the diagonal: (row, column, `(a_ij − a_ji)/2`).
    skew: Vec<(usize, usize, f64)>,
    /// More skew entries than [`SKEW_ENTRIES`] (then none are kept).
    skew_overflow: bool,
    /// Woodbury: the DOFs `C`, the block `[W y]` (column-major, `n × (|C| + 1)`), its scratch.
    dofs: Vec<usize>,
    block: Vec<f64>,
    block_scratch: MemBuffer,
    block_columns: usize,
    scratch: MemBuffer,
}

/// Skew entries kept for the Woodbury correction at most (beyond: GMRES).
const SKEW_ENTRIES: usize = 1 << 14;

impl SymmetricPart {
    fn new(pattern: faer::sparse::SymbolicSparseColMatRef<'_, usize>) -> Result<Self, String> {
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
        let symbolic = factorize_symbolic_cholesky(
            lower.as_ref(),
            Side::Lower,
            Default::default(),
            Default::default(),
        )
        .map_err(|e| format!("{e:?}"))?;
        Ok(Self::with_analysis(
            Arc::new(lower),
            Arc::new(symbolic),
            transpose.into(),
            structural,
        ))
    }

    /// The part over an analysed pattern, with empty work arrays (one place lists them).
    fn with_analysis(
        lower: Arc<SymbolicSparseColMat<usize>>,
        symbolic: Arc<SymbolicCholesky<usize>>,
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
        };
        part.scratch = MemBuffer::new(part.scratch_req());
        part
    }

    fn scratch_req(&self) -> StackReq {
        StackReq::any_of(&[
            self.symbolic
                .factorize_numeric_ldlt_scratch::<f64>(Par::Seq, Default::default()),
            self.symbolic.solve_in_place_scratch::<f64>(1, Par::Seq),
        ])
    }

    fn fresh_copy(&self) -> Self {
        Self::with_analysis(
            self.lower.clone(),
            self.symbolic.clone(),
            self.transpose.clone(),
            self.structural,
        )
    }

    /// One pass over the lower triangle of `a`: the symmetric part, the row sums of `|A|` and
    /// the skew entries above `1e-12` of the largest entry. Returns whether there are none
    /// (the values are symmetric).
    fn split(&mut self, a: SparseColMatRef<'_, usize, f64>) -> bool {
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
    fn skew_dofs(&mut self, limit: usize) -> Option<usize> {
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
    method: UnsymmetricMethod,
    profile: SolveProfile,
}

/// Buffers of [`gmres`] and [`accurate`], allocated once.
#[derive(Clone, Debug, Default)]
struct Krylov {
    basis: Vec<Vec<f64>>,
    work: Vec<f64>,
    product: Vec<f64>,
    hessenberg: Vec<f64>,
    rotations: Vec<f64>,
    residual: Vec<f64>,
    /// Iterations of the last solve.
    last_iterations: usize,
}

/// Largest Krylov dimension before GMRES gives up (then LU solves): the unsymmetric part of a
/// Newton matrix is a few slipping gaps or loaded triangles, a perturbation of low rank that a
/// preconditioned GMRES resolves in about as many iterations.
const KRYLOV_DIMENSION: usize = 40;
/// Right-preconditioned GMRES (no restart) for `A x = b` from `x = 0`, to `‖b − A x‖₂ ≤ 1e-12 ‖b‖₂`;
/// `x` receives the solution. False when it does not get there within [`KRYLOV_DIMENSION`].
fn gmres(
    a: SparseColMatRef<'_, usize, f64>,
    b: &[f64],
    x: &mut [f64],
    precondition: &mut dyn FnMut(&mut [f64]),
    k: &mut Krylov,
) -> bool {
    let n = b.len();
    let m = KRYLOV_DIMENSION;
    let norm = |v: &[f64]| v.iter().map(|x| x * x).sum::<f64>().sqrt();
    let beta = norm(b);
    x.iter_mut().for_each(|v| *v = 0.0);
    if beta == 0.0 {
        return true;
    }
    if k.basis.len() < m + 1 {
        k.basis.resize_with(m + 1, Vec::new);
    }
    k.basis[0].clear();
    k.basis[0].extend(b.iter().map(|v| v / beta));
    k.hessenberg.clear();
    k.hessenberg.resize((m + 1) * m, 0.0);
    k.rotations.clear();
    k.rotations.resize(4 * m + 1, 0.0);
    let h = &mut k.hessenberg;
    let (cs, rest) = k.rotations.split_at_mut(m);
    let (sn, rest) = rest.split_at_mut(m);
    let (g, y) = rest.split_at_mut(m + 1);
    g[0] = beta;
    let (ptr, rows, values) = (a.col_ptr(), a.row_idx(), a.val());
    let mut used = 0;
    let mut converged = false;
    for j in 0..m {
        // w = A M⁻¹ v_j
        k.work.clear();
        k.work.extend_from_slice(&k.basis[j]);
        precondition(&mut k.work);
        k.product.clear();
        k.product.resize(n, 0.0);
        let w = &mut k.product;
        for c in 0..n {
            let z = k.work[c];
            if z != 0.0 {
                for p in ptr[c]..ptr[c + 1] {
                    w[rows[p]] += values[p] * z;
                }
            }
        }
        for i in 0..=j {
            let hij: f64 = w.iter().zip(&k.basis[i]).map(|(a, b)| a * b).sum();
            h[i * m + j] = hij;
            w.iter_mut()
                .zip(&k.basis[i])
                .for_each(|(a, b)| *a -= hij * b);
        }
        let hn = norm(w);
        h[(j + 1) * m + j] = hn;
        for i in 0..j {
            let (a, b) = (h[i * m + j], h[(i + 1) * m + j]);
            h[i * m + j] = cs[i] * a + sn[i] * b;
            h[(i + 1) * m + j] = -sn[i] * a + cs[i] * b;
        }
        let (a, b) = (h[j * m + j], h[(j + 1) * m + j]);
        let r = a.hypot(b);
        if r == 0.0 || !r.is_finite() {
            break;
        }
        cs[j] = a / r;
        sn[j] = b / r;
        h[j * m + j] = r;
        h[(j + 1) * m + j] = 0.0;
        g[j + 1] = -sn[j] * g[j];
        g[j] *= cs[j];
        used = j + 1;
        if g[j + 1].abs() <= 1e-12 * beta {
            converged = true;
            break;
        }
        if hn == 0.0 {
            converged = true;
            break;
        }
        k.basis[j + 1].clear();
        k.basis[j + 1].extend(w.iter().map(|v| v / hn));
    }
    k.last_iterations = used;
    if !converged || used == 0 {
        return false;
    }
    // y = H⁻¹ g (upper triangular), x = M⁻¹ V y.
    let y = &mut y[..used];
    for i in (0..used).rev() {
        let s: f64 = (i + 1..used).map(|l| h[i * m + l] * y[l]).sum();
        y[i] = (g[i] - s) / h[i * m + i];
    }
    for (i, yi) in y.iter().enumerate() {
        x.iter_mut()
            .zip(&k.basis[i])
            .for_each(|(a, b)| *a += yi * b);
    }
    precondition(x);
    x.iter().all(|v| v.is_finite())
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
                lu: lu
                    .as_ref()
                    .map(|l| Box::new(LuPart::new(l.symbolic.clone()))),
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
            method: self.method,
            profile: SolveProfile::default(),
        }
    }
}

impl LinearSolver {
    /// Symbolic analysis of the system's pattern: LDLᵀ if it stores the lower triangle; else,
    /// with `symmetric_when_possible`, LDLᵀ of its symmetric part (LU analysed when first
    /// needed), without it LU.
    pub fn new(system: &System, symmetric_when_possible: bool) -> Result<Self, FactorizationError> {
        let err =
            |e: faer::sparse::FaerError| FactorizationError(format!("symbolic analysis: {e:?}"));
        let started = Instant::now();
        let kind = if system.is_lower_only() {
            let symbolic = factorize_symbolic_cholesky(
                system.pattern(),
                Side::Lower,
                Default::default(),
                Default::default(),
            )
            .map_err(err)?;
            let factor = vec![0.0; symbolic.len_val()];
            Kind::Ldlt {
                symbolic: Arc::new(symbolic),
                factor,
            }
        } else if symmetric_when_possible {
            Kind::Full {
                lu: None,
                symmetric: Some(Box::new(
                    SymmetricPart::new(system.pattern())
                        .map_err(|e| FactorizationError(format!("symbolic analysis: {e}")))?,
                )),
            }
        } else {
            Kind::Full {
                lu: Some(Box::new(LuPart::analyse(system.pattern())?)),
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
            method: UnsymmetricMethod::Auto,
            profile: SolveProfile::default(),
        };
        solver.scratch = MemBuffer::new(solver.scratch_req());
        solver.profile.symbolic = started.elapsed();
        Ok(solver)
    }

    fn scratch_req(&self) -> StackReq {
        match &self.kind {
            Kind::Ldlt { symbolic, .. } => StackReq::any_of(&[
                symbolic.factorize_numeric_ldlt_scratch::<f64>(Par::Seq, Default::default()),
                symbolic.solve_in_place_scratch::<f64>(1, Par::Seq),
            ]),
            // The parts hold their own.
            Kind::Full { .. } => StackReq::EMPTY,
        }
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
    /// never converged within [`KRYLOV_DIMENSION`] iterations, where Woodbury does.
    pub fn woodbury_limit(&self) -> usize {
        let n = self.equation_dofs.len().max(1);
        let values = (self.factor_len() / 4).max(WOODBURY_SMALL);
        (values / n).saturating_sub(1).min(WOODBURY_MOST)
    }

    /// Whether an LU of this system is cheap enough to replace the fast paths for the rest of
    /// a cut-back step: the symmetric part's LDLᵀ factor holds at most [`LU_AFFORDABLE`]
    /// values (the LU of the unsymmetric pattern was measured at about 6× the LDLᵀ's memory
    /// and 4–6× its time on the refined specimens).
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
                Kind::Full { symmetric, .. } => symmetric.as_ref().map_or(0, |p| {
                    (p.factor.len() + p.symmetric_values.len() + p.block.len()) * f
                        + p.transpose.len() * std::mem::size_of::<u32>()
                        + (p.lower.col_ptr().len() + p.lower.row_idx().len())
                            * std::mem::size_of::<usize>()
                }),
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
        let solved = self.factorize_and_solve_unchecked(matrix, rhs);
        if solved.is_ok() && rhs.iter().all(|v| v.is_finite()) {
            return solved;
        }
        let why = solved
            .err()
            .map_or(String::new(), |e| format!(" ({})", e.0));
        Err(FactorizationError(format!(
            "{}{why}",
            self.diagnose(matrix, rhs)
        )))
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
        const LISTED: usize = 6;
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
        let n = rhs.len();
        let limit = match self.method {
            UnsymmetricMethod::Auto => self.woodbury_limit(),
            UnsymmetricMethod::Gmres => 0,
            UnsymmetricMethod::Woodbury => WOODBURY_MOST,
        };
        match &mut self.kind {
            Kind::Ldlt { symbolic, factor } => {
                let stack = MemStack::new(&mut self.scratch);
                let start = Instant::now();
                let ldlt = symbolic
                    .factorize_numeric_ldlt(
                        factor,
                        matrix,
                        Side::Lower,
                        LdltRegularization::default(),
                        Par::Seq,
                        stack,
                        Default::default(),
                    )
                    .map_err(|e| FactorizationError(format!("LDLᵀ: {e:?}")))?;
                self.profile.ldlt += start.elapsed();
                self.profile.ldlt_count += 1;
                let x = MatMut::from_column_major_slice_mut(rhs, n, 1);
                timed(&mut self.profile.ldlt_solve, || {
                    ldlt.solve_in_place_with_conj(Conj::No, x, Par::Seq, stack)
                });
            }
            Kind::Full { lu, symmetric } => {
                if self.fast
                    && let Some(part) = symmetric.as_mut()
                    && part.structural
                {
                    let mut ctx = Context {
                        krylov: &mut self.krylov,
                        profile: &mut self.profile,
                        counts: &mut self.counts,
                    };
                    if part.solve(matrix, rhs, limit, &mut ctx) {
                        return Ok(());
                    }
                    self.counts[2] += 1;
                    rhs.copy_from_slice(&part.rhs);
                }
                if lu.is_none() {
                    let analysed = timed(&mut self.profile.symbolic, || {
                        LuPart::analyse(matrix.symbolic())
                    })?;
                    *lu = Some(Box::new(analysed));
                }
                let lu = lu.as_mut().expect("analysed above");
                self.counts[0] += 1;
                self.profile.lu_count += 1;
                let start = Instant::now();
                let stack = MemStack::new(&mut lu.scratch);
                let factored = lu
                    .symbolic
                    .factorize_numeric_lu(
                        &mut lu.numeric,
                        matrix,
                        Par::Seq,
                        stack,
                        Default::default(),
                    )
                    .map_err(|e| FactorizationError(format!("LU: {e:?}")))?;
                let x = MatMut::from_column_major_slice_mut(rhs, n, 1);
                factored.solve_in_place_with_conj(Conj::No, x, Par::Seq, stack);
                self.profile.lu += start.elapsed();
            }
        }
        Ok(())
    }
}

/// Most DOFs of the skew part for the Woodbury correction (its dense `|C| × |C|` system).
const WOODBURY_MOST: usize = 512;

/// LDLᵀ factors of up to this many values (32 MiB; the refined specimen up to ≈ 30 k DOF)
/// let a cut-back step fall back to LU (see [`LinearSolver::lu_affordable`]).
const LU_AFFORDABLE: usize = 1 << 22;

/// Woodbury blocks of up to this many values are always affordable (512 KiB).
const WOODBURY_SMALL: usize = 1 << 16;

/// The solver's counters, lent to a fast solve.
struct Context<'a> {
    krylov: &'a mut Krylov,
    profile: &'a mut SolveProfile,
    counts: &'a mut [usize; 4],
}

impl SymmetricPart {
    /// Solves `a x = rhs` on the LDLᵀ of the symmetric part (directly, by Woodbury with at most
    /// `limit` DOFs, or by GMRES). False when the factorization fails or no solution passes the
    /// accuracy check; `self.rhs` then holds the right-hand side.
    fn solve(
        &mut self,
        a: SparseColMatRef<'_, usize, f64>,
        rhs: &mut [f64],
        limit: usize,
        ctx: &mut Context<'_>,
    ) -> bool {
        let n = rhs.len();
        let symmetric = timed(&mut ctx.profile.symmetric_part, || self.split(a));
        let woodbury = !symmetric && self.skew_dofs(limit).is_some();
        if self.factor.is_empty() {
            self.factor = vec![0.0; self.symbolic.len_val()];
        }
        self.rhs.clear();
        self.rhs.extend_from_slice(rhs);
        let s = SparseColMatRef::new(self.lower.as_ref().as_ref(), &self.symmetric_values);
        let stack = MemStack::new(&mut self.scratch);
        let start = Instant::now();
        let factored = self.symbolic.factorize_numeric_ldlt(
            &mut self.factor,
            s,
            Side::Lower,
            LdltRegularization::default(),
            Par::Seq,
            &mut *stack,
            Default::default(),
        );
        ctx.profile.ldlt += start.elapsed();
        ctx.profile.ldlt_count += 1;
        let Ok(ldlt) = factored else {
            return false;
        };
        let check = |x: &[f64], ctx: &mut Context<'_>| {
            timed(&mut ctx.profile.accuracy, || {
                accurate(a, x, &self.rhs, &self.row_norms, ctx.krylov)
            })
        };
        if symmetric {
            let x = MatMut::from_column_major_slice_mut(rhs, n, 1);
            timed(&mut ctx.profile.ldlt_solve, || {
                ldlt.solve_in_place_with_conj(Conj::No, x, Par::Seq, &mut *stack)
            });
            if check(rhs, ctx) {
                ctx.counts[1] += 1;
                return true;
            }
            return false;
        }
        if woodbury {
            let start = Instant::now();
            let c = self.dofs.len();
            let m = c + 1;
            self.block.clear();
            self.block.resize(n * m, 0.0);
            for (k, &d) in self.dofs.iter().enumerate() {
                self.block[k * n + d] = 1.0;
            }
            self.block[c * n..].copy_from_slice(&self.rhs);
            if self.block_columns < m {
                self.block_scratch =
                    MemBuffer::new(self.symbolic.solve_in_place_scratch::<f64>(m, Par::Seq));
                self.block_columns = m;
            }
            ldlt.solve_in_place_with_conj(
                Conj::No,
                MatMut::from_column_major_slice_mut(&mut self.block, n, m),
                Par::Seq,
                MemStack::new(&mut self.block_scratch),
            );
            let solved = woodbury_correction(&self.dofs, &self.skew, &self.block, rhs);
            ctx.profile.woodbury += start.elapsed();
            ctx.profile.woodbury_count += 1;
            ctx.profile.woodbury_columns += m;
            if solved && check(rhs, ctx) {
                ctx.counts[3] += 1;
                return true;
            }
        }
        let start = Instant::now();
        let mut precondition = |v: &mut [f64]| {
            let x = MatMut::from_column_major_slice_mut(v, n, 1);
            ldlt.solve_in_place_with_conj(Conj::No, x, Par::Seq, &mut *stack);
        };
        let solved = gmres(a, &self.rhs, rhs, &mut precondition, ctx.krylov);
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

/// `x = y − W (I + K_CC W_C)⁻¹ K_CC y_C` from the block `[W y] = S⁻¹ [I_C b]` (column-major,
/// `n` rows) and the skew entries `(i, j, k_ij)` below the diagonal (`k_ji = −k_ij`): the
/// solution of `(S + K) x = b` (Woodbury's identity with `K = I_C K_CC I_Cᵀ`). False when the
/// small matrix is singular.
fn woodbury_correction(
    dofs: &[usize],
    skew: &[(usize, usize, f64)],
    block: &[f64],
    x: &mut [f64],
) -> bool {
    let (c, n) = (dofs.len(), x.len());
    let index = |d: usize| {
        dofs.binary_search(&d)
            .expect("skew DOFs collected from skew")
    };
    let mut k = DMatrix::<f64>::zeros(c, c);
    for &(i, j, h) in skew {
        let (a, b) = (index(i), index(j));
        k[(a, b)] += h;
        k[(b, a)] -= h;
    }
    let w_c = DMatrix::from_fn(c, c, |r, l| block[l * n + dofs[r]]);
    let y = &block[c * n..];
    let y_c = DVector::from_fn(c, |r, _| y[dofs[r]]);
    let m = DMatrix::<f64>::identity(c, c) + &k * w_c;
    let Some(z) = m.lu().solve(&(&k * y_c)) else {
        return false;
    };
    x.copy_from_slice(y);
    for (l, &zl) in z.iter().enumerate() {
        if zl != 0.0 {
            x.iter_mut()
                .zip(&block[l * n..(l + 1) * n])
                .for_each(|(a, w)| *a -= zl * w);
        }
    }
    true
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
    let xm = x.iter().fold(0.0_f64, |m, &v| m.max(v.abs()));
    let bm = b.iter().fold(0.0_f64, |m, &v| m.max(v.abs()));
    let limit = 1e-9 * (a * xm + bm);
    r.iter().all(|v| v.abs() <= limit)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mech::Model;

    /// A free 0.1 m square (two triangles, nodes 0..3) whose node 0 is fixed in x, y, z: nine
    /// equations, numbered node 1 (x, y, z), node 2, node 3.
    fn system(lower_only: bool) -> System {
        let model = Model::from_json(
            r#"{ "name": "Sq", "nodes": [[0,0,0], [0.1,0,0], [0.1,0.1,0], [0,0.1,0]],
                 "triangles": [[0,1,2], [0,2,3]],
                 "material": { "youngs_modulus": 1e9, "poisson_ratio": 0.43, "thickness": 250e-6,
                               "prestress": [5e5, 5e5, 0] },
                 "supports": [{ "node": 0, "fixed": ["x", "y", "z"] }, { "node": 1, "fixed": ["y", "z"] },
                              { "node": 3, "fixed": ["z"] }] }"#,
        )
        .unwrap();
        System::new(&model, lower_only).unwrap()
    }

    /// Matrix values with `entries` (row, column, value) and zeros elsewhere.
    fn values(system: &System, entries: &[(usize, usize, f64)]) -> Vec<f64> {
        let pattern = system.pattern();
        let mut v = vec![0.0; system.nonzeros()];
        for &(i, j, x) in entries {
            let rows = pattern.row_idx_of_col_raw(j);
            let k = rows
                .iter()
                .position(|&r| r == i)
                .expect("entry in the pattern");
            v[pattern.col_ptr()[j] + k] += x;
        }
        v
    }

    fn solve(lower_only: bool, entries: &[(usize, usize, f64)]) -> Result<Vec<f64>, String> {
        let system = system(lower_only);
        let mut solver = LinearSolver::new(&system, true).unwrap();
        let v = values(&system, entries);
        let mut rhs = vec![1.0; system.free_count];
        solver
            .factorize_and_solve(system.matrix(&v), &mut rhs)
            .map(|()| rhs)
            .map_err(|e| e.0)
    }

    fn diagonal_except(skip: &[usize]) -> Vec<(usize, usize, f64)> {
        (0..6)
            .filter(|i| !skip.contains(i))
            .map(|i| (i, i, 2.0))
            .collect()
    }

    #[test]
    fn regular_matrix_is_solved() {
        for lower_only in [false, true] {
            let x = solve(lower_only, &diagonal_except(&[])).unwrap();
            assert!(x.iter().all(|&v| v == 0.5), "{x:?}");
        }
    }

    #[test]
    fn dof_without_stiffness_is_named_by_node_and_axis() {
        // Equations: 0 = node 1 x, 1 = node 2 x, 2 = node 2 y, 3 = node 2 z, 4 = node 3 x, 5 = node 3 y.
        for lower_only in [false, true] {
            let err = solve(lower_only, &diagonal_except(&[2, 3])).unwrap_err();
            assert!(err.contains("no stiffness at node 2 (y, z)"), "{err}");
        }
    }

    #[test]
    fn zero_pivot_is_an_error_naming_nodes_not_a_nan_solution() {
        // Node 3's x and y are coupled by the singular block [[1, 1], [1, 1]].
        let mut entries = diagonal_except(&[4, 5]);
        entries.extend([(4, 4, 1.0), (5, 5, 1.0), (5, 4, 1.0), (4, 5, 1.0)]);
        let err = solve(false, &entries).unwrap_err();
        assert!(
            err.contains("zero pivot") && err.contains("node 3"),
            "{err}"
        );
    }

    #[test]
    fn symmetric_values_take_the_ldlt_and_others_the_lu() {
        let system = system(false);
        let mut solver = LinearSolver::new(&system, true).unwrap();
        let mut entries = diagonal_except(&[]);
        entries.extend([(4, 5, 0.5), (5, 4, 0.5)]);
        let mut rhs = vec![1.0; system.free_count];
        let v = values(&system, &entries);
        solver
            .factorize_and_solve(system.matrix(&v), &mut rhs)
            .unwrap();
        assert_eq!(solver.counts(), [0, 1, 0, 0]);
        assert!(
            (rhs[4] - 0.4).abs() < 1e-14 && (rhs[0] - 0.5).abs() < 1e-14,
            "{rhs:?}"
        );
        entries.push((4, 5, 0.25)); // unsymmetric now
        let v = values(&system, &entries);
        let mut rhs = vec![1.0; system.free_count];
        solver
            .factorize_and_solve(system.matrix(&v), &mut rhs)
            .unwrap();
        assert_eq!(
            solver.counts(),
            [0, 1, 0, 1],
            "GMRES on the unsymmetric one"
        );
    }

    /// Node 3's x and y coupled as `[[0, 1], [1, 0]]` (symmetric, indefinite, zero diagonal),
    /// the identity elsewhere, and a right-hand side whose solution there is `(3, 1)`.
    fn indefinite_pair(system: &System) -> (Vec<f64>, Vec<f64>) {
        let mut entries = diagonal_except(&[4, 5]);
        entries.extend([(4, 5, 1.0), (5, 4, 1.0)]);
        let mut rhs = vec![1.0; system.free_count];
        rhs[5] = 3.0;
        (values(system, &entries), rhs)
    }

    #[test]
    fn symmetric_matrix_the_ldlt_cannot_pivot_is_solved_by_the_lu() {
        // Node 3's x and y: [[0, 1], [1, 0]] (symmetric, indefinite, zero diagonal).
        let system = system(false);
        let mut solver = LinearSolver::new(&system, true).unwrap();
        let (v, mut rhs) = indefinite_pair(&system);
        solver
            .factorize_and_solve(system.matrix(&v), &mut rhs)
            .unwrap();
        assert_eq!(solver.counts(), [1, 0, 1, 0]);
        assert_eq!((rhs[4], rhs[5]), (3.0, 1.0));
    }

    /// A diagonally dominant symmetric matrix on the six equations plus `skew` (row, column,
    /// value) added as `+v` at (row, column) and `−v` at (column, row).
    fn unsymmetric(skew: &[(usize, usize, f64)]) -> Vec<(usize, usize, f64)> {
        let mut entries: Vec<(usize, usize, f64)> =
            (0..6).map(|i| (i, i, 4.0 + i as f64)).collect();
        for (i, j) in [(1, 0), (2, 1), (3, 2), (4, 3), (5, 4), (5, 3)] {
            entries.extend([(i, j, 0.7), (j, i, 0.7)]);
        }
        for &(i, j, v) in skew {
            entries.extend([(i, j, v), (j, i, -v)]);
        }
        entries
    }

    /// Solves `entries` with `method` (or by LU when `None`); the solution and the solver.
    fn solve_with(
        entries: &[(usize, usize, f64)],
        method: Option<UnsymmetricMethod>,
    ) -> (Vec<f64>, LinearSolver) {
        let system = system(false);
        let mut solver = LinearSolver::new(&system, true).unwrap();
        match method {
            Some(m) => solver.set_method(m),
            None => solver.set_fast(false),
        }
        let v = values(&system, entries);
        let mut rhs: Vec<f64> = (0..system.free_count).map(|i| 1.0 + i as f64).collect();
        solver
            .factorize_and_solve(system.matrix(&v), &mut rhs)
            .unwrap();
        (rhs, solver)
    }

    #[test]
    fn woodbury_and_gmres_solve_an_unsymmetric_matrix_like_lu_to_1e_10() {
        // Skew entries on equations 1, 2 and 4 (as a slipping gap's μ k_n coupling would).
        let entries = unsymmetric(&[(2, 1, 1.5), (4, 1, -0.9), (4, 2, 0.4)]);
        let (lu, _) = solve_with(&entries, None);
        let scale = lu.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
        for method in [UnsymmetricMethod::Woodbury, UnsymmetricMethod::Gmres] {
            let (x, solver) = solve_with(&entries, Some(method));
            let p = solver.profile();
            let used = if method == UnsymmetricMethod::Woodbury {
                (p.woodbury_count, p.woodbury_columns, p.gmres_count)
            } else {
                (p.gmres_count, 0, p.woodbury_count)
            };
            assert_eq!(
                used,
                (
                    1,
                    if method == UnsymmetricMethod::Woodbury {
                        4
                    } else {
                        0
                    },
                    0
                ),
                "{method:?}: {p:?}"
            );
            assert_eq!(solver.counts(), [0, 0, 0, 1], "{method:?}");
            assert!(!solver.has_lu(), "{method:?}: the LU is never analysed");
            let difference = max_difference(&x, &lu);
            assert!(difference <= 1e-10 * scale, "{method:?}: {difference:e}");
        }
        // Auto takes Woodbury for three skew DOFs.
        let (_, solver) = solve_with(&entries, Some(UnsymmetricMethod::Auto));
        assert_eq!(solver.profile().woodbury_count, 1);
    }

    #[test]
    fn lu_is_analysed_only_when_a_fast_solution_fails_the_accuracy_check() {
        let system = system(false);
        let mut solver = LinearSolver::new(&system, true).unwrap();
        let mut rhs = vec![1.0; system.free_count];
        let v = values(&system, &unsymmetric(&[]));
        solver
            .factorize_and_solve(system.matrix(&v), &mut rhs)
            .unwrap();
        assert!(!solver.has_lu() && solver.counts() == [0, 1, 0, 0]);
        // Node 3's x and y: [[0, 1], [1, 0]] — the unpivoted LDLᵀ fails, the LU is built.
        let (v, mut rhs) = indefinite_pair(&system);
        solver
            .factorize_and_solve(system.matrix(&v), &mut rhs)
            .unwrap();
        assert!(solver.has_lu());
        assert_eq!(solver.counts(), [1, 1, 1, 0]);
        assert_eq!((rhs[4], rhs[5]), (3.0, 1.0));
        // Its analysis is kept and shared by a clone.
        assert!(solver.clone().has_lu());
    }

    #[test]
    fn rounding_sized_asymmetry_counts_as_symmetric() {
        let mut entries = unsymmetric(&[]);
        entries.push((2, 1, 1e-15)); // below 1e-12 of the largest entry (9)
        let (_, solver) = solve_with(&entries, Some(UnsymmetricMethod::Auto));
        assert_eq!(solver.counts(), [0, 1, 0, 0]);
        entries.push((2, 1, 1e-10)); // above
        let (_, solver) = solve_with(&entries, Some(UnsymmetricMethod::Auto));
        assert_eq!(solver.counts(), [0, 0, 0, 1]);
    }

    fn max_difference(a: &[f64], b: &[f64]) -> f64 {
        a.iter()
            .zip(b)
            .map(|(x, y)| (x - y).abs())
            .fold(0.0, f64::max)
    }

    #[test]
    fn non_finite_entry_is_named() {
        let mut entries = diagonal_except(&[]);
        entries.push((0, 0, f64::NAN));
        let err = solve(false, &entries).unwrap_err();
        assert!(err.contains("non-finite entries at node 1 (x)"), "{err}");
    }
}
