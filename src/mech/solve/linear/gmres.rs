//! Right-preconditioned GMRES (no restart) on the symmetric part's LDLᵀ.

use faer::sparse::SparseColMatRef;

/// Buffers of [`gmres`] and [`accurate`], allocated once.
#[derive(Clone, Debug, Default)]
pub(super) struct Krylov {
    pub(super) basis: Vec<Vec<f64>>,
    pub(super) work: Vec<f64>,
    pub(super) product: Vec<f64>,
    pub(super) hessenberg: Vec<f64>,
    pub(super) rotations: Vec<f64>,
    pub(super) residual: Vec<f64>,
    /// Iterations of the last solve.
    pub(super) last_iterations: usize,
}

/// Largest Krylov dimension before GMRES gives up (then LU solves): the unsymmetric part of a
/// Newton matrix is a few slipping gaps or loaded triangles, a perturbation of low rank that a
/// preconditioned GMRES resolves in about as many iterations.
pub(super) const KRYLOV_DIMENSION: usize = 40;
/// Right-preconditioned GMRES (no restart) for `A x = b` from `x = 0`, to `‖b − A x‖₂ ≤ 1e-12 ‖b‖₂`;
/// `x` receives the solution. False when it does not get there within [`KRYLOV_DIMENSION`].
/// With `transpose` the system is `Aᵀ x = b` (the products read `a`'s columns as rows; the
/// preconditioner, a symmetric part's LDLᵀ, serves both).
pub(super) fn gmres(
    (a, transpose): (SparseColMatRef<'_, usize, f64>, bool),
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
            let span = ptr[c]..ptr[c + 1];
            if transpose {
                w[c] = span.map(|p| values[p] * k.work[rows[p]]).sum();
                continue;
            }
            let z = k.work[c];
            if z != 0.0 {
                for p in span {
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
