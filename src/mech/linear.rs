//! Sparse factorization of the Newton matrix with the symbolic analysis done once per analysis.
//!
//! * symmetric (Ju–Rowlands) matrix: LDLᵀ (`faer` supernodal/simplicial Cholesky structure,
//!   AMD ordering), which also handles the indefinite matrices of compressed films;
//! * the consistent tangent when it happens to be symmetric (no slipping gap, no follower
//!   pressure, no slipping curved contact: checked on the assembled values, entry by entry
//!   against its transpose to 1e-12 of the largest): LDLᵀ of its lower triangle, with both
//!   symbolic analyses done once (issue 11 item 1);
//! * an unsymmetric consistent tangent `A`: GMRES (no restart, at most [`KRYLOV_DIMENSION`]
//!   vectors, to `‖b − A x‖₂ ≤ 1e-12 ‖b‖₂`) right-preconditioned by the LDLᵀ of its symmetric
//!   part `(A + Aᵀ)/2` (issue 11 item 2): the unsymmetric part comes from the slipping gaps and
//!   loaded triangles only, a local perturbation that GMRES resolves in a few iterations, so a
//!   Newton iteration costs one LDLᵀ and a few solves and keeps its quadratic convergence;
//! * every other case, and every LDLᵀ or GMRES solution that fails the accuracy check
//!   `‖A x − b‖∞ ≤ 1e-9 (‖A‖∞‖x‖∞ + ‖b‖∞)` (an indefinite matrix the unpivoted LDLᵀ cannot
//!   take, a Krylov space too small): LU with partial pivoting (`faer` `SymbolicLu`) on the
//!   same system (counted, [`LinearSolver::counts`]).
//!
//! Buffers (factor values, scratch) are allocated once and reused every iteration.

use std::sync::Arc;

use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::cholesky::ldlt::factor::LdltRegularization;
use faer::sparse::SparseColMatRef;
use faer::sparse::linalg::SupernodalThreshold;
use faer::sparse::linalg::cholesky::{SymbolicCholesky, factorize_symbolic_cholesky};
use faer::sparse::linalg::lu::{LuSymbolicParams, NumericLu, SymbolicLu, factorize_symbolic_lu};
use faer::{Conj, MatMut, Par, Side};

use super::assembly::{Dof, System};

/// A factorization failure (singular or non-finite matrix); the message names the nodes.
#[derive(Clone, Debug, PartialEq)]
pub struct FactorizationError(pub String);

enum Kind {
    Ldlt {
        symbolic: Arc<SymbolicCholesky<usize>>,
        factor: Vec<f64>,
    },
    Lu {
        symbolic: Arc<SymbolicLu<usize>>,
        numeric: NumericLu<usize, f64>,
        /// The LDLᵀ of the same pattern's lower triangle, for symmetric matrices.
        symmetric: Option<Box<SymmetricPart>>,
    },
}

/// LDLᵀ of the lower triangle of a full-pattern matrix, and the slot of each entry's
/// transpose (to see whether the values are symmetric).
struct SymmetricPart {
    symbolic: Arc<SymbolicCholesky<usize>>,
    /// Allocated at the first symmetric factorization.
    factor: Vec<f64>,
    transpose: Arc<[usize]>,
    /// The right-hand side kept for the accuracy check and the LU fallback.
    rhs: Vec<f64>,
    /// Values of the symmetric part `(A + Aᵀ)/2` of an unsymmetric matrix.
    symmetric_values: Vec<f64>,
}

impl SymmetricPart {
    fn new(
        pattern: faer::sparse::SymbolicSparseColMatRef<'_, usize>,
    ) -> Result<Self, faer::sparse::FaerError> {
        let symbolic = factorize_symbolic_cholesky(
            pattern,
            Side::Lower,
            Default::default(),
            Default::default(),
        )?;
        let (ptr, rows) = (pattern.col_ptr(), pattern.row_idx());
        let mut transpose = Vec::with_capacity(rows.len());
        for j in 0..pattern.ncols() {
            for &i in &rows[ptr[j]..ptr[j + 1]] {
                let column = &rows[ptr[i]..ptr[i + 1]];
                // A structurally symmetric pattern (element blocks are square): (j, i) exists.
                let k = column.binary_search(&j).map_or(usize::MAX, |k| ptr[i] + k);
                transpose.push(k);
            }
        }
        Ok(Self {
            symbolic: Arc::new(symbolic),
            factor: Vec::new(),
            transpose: transpose.into(),
            rhs: Vec::new(),
            symmetric_values: Vec::new(),
        })
    }

    /// Whether `values` equal their transpose to `1e-12` of the largest entry.
    fn is_symmetric(&self, values: &[f64]) -> bool {
        let scale = values.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
        let tolerance = 1e-12 * scale;
        values
            .iter()
            .zip(self.transpose.iter())
            .all(|(&v, &t)| t != usize::MAX && (v - values[t]).abs() <= tolerance)
    }
}

/// Factorization of the free–free Newton matrix with a reusable symbolic analysis.
pub struct LinearSolver {
    kind: Kind,
    scratch: MemBuffer,
    /// Global DOF (`3 × node + axis`) of each equation, to name nodes in errors.
    equation_dofs: Arc<[u32]>,
    /// Solves: LU, LDLᵀ of a symmetric consistent tangent, LDLᵀ or Krylov rejected and redone
    /// by LU, GMRES preconditioned by the symmetric part's LDLᵀ.
    counts: [usize; 4],
    /// Krylov work space (basis vectors, Hessenberg matrix), reused.
    krylov: Krylov,
    /// Whether the LDLᵀ and Krylov paths may be taken (else LU for full patterns).
    fast: bool,
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
    row_norms: Vec<f64>,
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
            Kind::Lu { .. } => "LU",
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
            Kind::Lu {
                symbolic,
                symmetric,
                ..
            } => Kind::Lu {
                symbolic: symbolic.clone(),
                numeric: NumericLu::new(),
                symmetric: symmetric.as_ref().map(|p| {
                    Box::new(SymmetricPart {
                        symbolic: p.symbolic.clone(),
                        factor: Vec::new(),
                        transpose: p.transpose.clone(),
                        rhs: Vec::new(),
                        symmetric_values: Vec::new(),
                    })
                }),
            },
        };
        let scratch = MemBuffer::new(Self::scratch_req(&kind_ref(&kind)));
        Self {
            kind,
            scratch,
            equation_dofs: self.equation_dofs.clone(),
            counts: [0; 4],
            krylov: Krylov::default(),
            fast: true,
        }
    }
}

enum KindRef<'a> {
    Ldlt(&'a SymbolicCholesky<usize>),
    Lu(&'a SymbolicLu<usize>, Option<&'a SymbolicCholesky<usize>>),
}

fn kind_ref(k: &Kind) -> KindRef<'_> {
    match k {
        Kind::Ldlt { symbolic, .. } => KindRef::Ldlt(symbolic),
        Kind::Lu {
            symbolic,
            symmetric,
            ..
        } => KindRef::Lu(symbolic, symmetric.as_ref().map(|p| &*p.symbolic)),
    }
}

impl LinearSolver {
    /// Symbolic analysis of the system's pattern: LDLᵀ if it stores the lower triangle, else LU
    /// and, with `symmetric_when_possible`, LDLᵀ of its lower triangle for symmetric values.
    pub fn new(system: &System, symmetric_when_possible: bool) -> Result<Self, FactorizationError> {
        let err =
            |e: faer::sparse::FaerError| FactorizationError(format!("symbolic analysis: {e:?}"));
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
        } else {
            // faer's simplicial LU (its pick for small systems) was 5× slower than the supernodal
            // one on the 363-DOF specimen; the supernodal one is as fast on large systems.
            let params = LuSymbolicParams {
                supernodal_flop_ratio_threshold: SupernodalThreshold::FORCE_SUPERNODAL,
                ..Default::default()
            };
            let symbolic = factorize_symbolic_lu(system.pattern(), params).map_err(err)?;
            let symmetric = if symmetric_when_possible {
                Some(Box::new(SymmetricPart::new(system.pattern()).map_err(err)?))
            } else {
                None
            };
            Kind::Lu {
                symbolic: Arc::new(symbolic),
                numeric: NumericLu::new(),
                symmetric,
            }
        };
        let scratch = MemBuffer::new(Self::scratch_req(&kind_ref(&kind)));
        let equation_dofs = system
            .dofs
            .iter()
            .enumerate()
            .filter(|(_, d)| matches!(d, Dof::Free(_)))
            .map(|(i, _)| u32::try_from(i))
            .collect::<Result<Arc<[u32]>, _>>()
            .map_err(|_| FactorizationError("more than 2^32 DOFs".into()))?;
        Ok(Self {
            kind,
            scratch,
            equation_dofs,
            counts: [0; 4],
            krylov: Krylov::default(),
            fast: true,
        })
    }

    fn scratch_req(kind: &KindRef<'_>) -> faer::dyn_stack::StackReq {
        match kind {
            KindRef::Ldlt(s) => faer::dyn_stack::StackReq::any_of(&[
                s.factorize_numeric_ldlt_scratch::<f64>(Par::Seq, Default::default()),
                s.solve_in_place_scratch::<f64>(1, Par::Seq),
            ]),
            KindRef::Lu(s, c) => faer::dyn_stack::StackReq::any_of(&[
                s.factorize_numeric_lu_scratch::<f64>(Par::Seq, Default::default()),
                s.solve_in_place_scratch::<f64>(1, Par::Seq),
                c.map_or(faer::dyn_stack::StackReq::EMPTY, |c| {
                    faer::dyn_stack::StackReq::any_of(&[
                        c.factorize_numeric_ldlt_scratch::<f64>(Par::Seq, Default::default()),
                        c.solve_in_place_scratch::<f64>(1, Par::Seq),
                    ])
                }),
            ]),
        }
    }

    /// Allows (true, the default) or forbids the LDLᵀ and Krylov paths for full patterns.
    pub fn set_fast(&mut self, fast: bool) {
        self.fast = fast;
    }

    /// Solves so far: `[LU, LDLᵀ of a symmetric consistent tangent, LDLᵀ or GMRES rejected and
    /// redone by LU, GMRES preconditioned by the symmetric part's LDLᵀ]`.
    pub fn counts(&self) -> [usize; 4] {
        self.counts
    }

    /// Number of stored values of the factor (LDLᵀ) or 0 when unknown before factorization (LU).
    pub fn factor_len(&self) -> usize {
        match &self.kind {
            Kind::Ldlt { factor, .. } => factor.len(),
            Kind::Lu { .. } => 0,
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
        let stack = MemStack::new(&mut self.scratch);
        match &mut self.kind {
            Kind::Ldlt { symbolic, factor } => {
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
                let x = MatMut::from_column_major_slice_mut(rhs, n, 1);
                ldlt.solve_in_place_with_conj(Conj::No, x, Par::Seq, stack);
            }
            Kind::Lu {
                symbolic,
                numeric,
                symmetric,
            } => {
                let symmetric = if self.fast { symmetric } else { &mut None };
                if let Some(part) = symmetric.as_mut()
                    && part.is_symmetric(matrix.val())
                {
                    if part.factor.is_empty() {
                        part.factor = vec![0.0; part.symbolic.len_val()];
                    }
                    part.rhs.clear();
                    part.rhs.extend_from_slice(rhs);
                    let factored = part.symbolic.factorize_numeric_ldlt(
                        &mut part.factor,
                        matrix,
                        Side::Lower,
                        LdltRegularization::default(),
                        Par::Seq,
                        &mut *stack,
                        Default::default(),
                    );
                    if let Ok(ldlt) = factored {
                        let x = MatMut::from_column_major_slice_mut(rhs, n, 1);
                        ldlt.solve_in_place_with_conj(Conj::No, x, Par::Seq, &mut *stack);
                        if accurate(matrix, rhs, &part.rhs, &mut self.krylov) {
                            self.counts[1] += 1;
                            return Ok(());
                        }
                    }
                    self.counts[2] += 1;
                    rhs.copy_from_slice(&part.rhs);
                } else if let Some(part) = symmetric.as_mut()
                    && part.transpose.iter().all(|&t| t != usize::MAX)
                {
                    // Unsymmetric: GMRES preconditioned by the LDLᵀ of the symmetric part.
                    if part.factor.is_empty() {
                        part.factor = vec![0.0; part.symbolic.len_val()];
                    }
                    let values = matrix.val();
                    part.symmetric_values.clear();
                    part.symmetric_values.extend(
                        values
                            .iter()
                            .zip(part.transpose.iter())
                            .map(|(&v, &t)| 0.5 * (v + values[t])),
                    );
                    part.rhs.clear();
                    part.rhs.extend_from_slice(rhs);
                    let symmetric_matrix =
                        SparseColMatRef::new(matrix.symbolic(), &part.symmetric_values);
                    let factored = part.symbolic.factorize_numeric_ldlt(
                        &mut part.factor,
                        symmetric_matrix,
                        Side::Lower,
                        LdltRegularization::default(),
                        Par::Seq,
                        &mut *stack,
                        Default::default(),
                    );
                    if let Ok(ldlt) = factored {
                        let mut precondition = |v: &mut [f64]| {
                            let x = MatMut::from_column_major_slice_mut(v, n, 1);
                            ldlt.solve_in_place_with_conj(Conj::No, x, Par::Seq, &mut *stack);
                        };
                        let solved =
                            gmres(matrix, &part.rhs, rhs, &mut precondition, &mut self.krylov);
                        if solved && accurate(matrix, rhs, &part.rhs, &mut self.krylov) {
                            self.counts[3] += 1;
                            return Ok(());
                        }
                    }
                    self.counts[2] += 1;
                    rhs.copy_from_slice(&part.rhs);
                }
                self.counts[0] += 1;
                let lu = symbolic
                    .factorize_numeric_lu(numeric, matrix, Par::Seq, stack, Default::default())
                    .map_err(|e| FactorizationError(format!("LU: {e:?}")))?;
                let x = MatMut::from_column_major_slice_mut(rhs, n, 1);
                lu.solve_in_place_with_conj(Conj::No, x, Par::Seq, stack);
            }
        }
        Ok(())
    }
}

/// Whether `x` solves `matrix · x = b` to `1e-9 (‖A‖∞‖x‖∞ + ‖b‖∞)` in every row (`k`: buffers).
fn accurate(matrix: SparseColMatRef<'_, usize, f64>, x: &[f64], b: &[f64], k: &mut Krylov) -> bool {
    k.residual.clear();
    k.residual.extend(b.iter().map(|v| -v));
    k.row_norms.clear();
    k.row_norms.resize(b.len(), 0.0);
    let (r, norm_a) = (&mut k.residual, &mut k.row_norms);
    let (ptr, rows, values) = (matrix.col_ptr(), matrix.row_idx(), matrix.val());
    for j in 0..matrix.ncols() {
        for k in ptr[j]..ptr[j + 1] {
            r[rows[k]] += values[k] * x[j];
            norm_a[rows[k]] += values[k].abs();
        }
    }
    let a = norm_a.iter().fold(0.0_f64, |m, &v| m.max(v));
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

    #[test]
    fn symmetric_matrix_the_ldlt_cannot_pivot_is_solved_by_the_lu() {
        // Node 3's x and y: [[0, 1], [1, 0]] (symmetric, indefinite, zero diagonal).
        let system = system(false);
        let mut solver = LinearSolver::new(&system, true).unwrap();
        let mut entries = diagonal_except(&[4, 5]);
        entries.extend([(4, 5, 1.0), (5, 4, 1.0)]);
        let v = values(&system, &entries);
        let mut rhs = vec![1.0; system.free_count];
        rhs[5] = 3.0;
        solver
            .factorize_and_solve(system.matrix(&v), &mut rhs)
            .unwrap();
        assert_eq!(solver.counts(), [1, 0, 1, 0]);
        assert_eq!((rhs[4], rhs[5]), (3.0, 1.0));
    }

    #[test]
    fn non_finite_entry_is_named() {
        let mut entries = diagonal_except(&[]);
        entries.push((0, 0, f64::NAN));
        let err = solve(false, &entries).unwrap_err();
        assert!(err.contains("non-finite entries at node 1 (x)"), "{err}");
    }
}
