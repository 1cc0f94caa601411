//! The symmetric positive definite solves of form finding and flattening: a scalar matrix given
//! as triplets, factored once by sparse Cholesky (`faer`), several right-hand sides.

use faer::Side;
use faer::linalg::solvers::Solve;
use faer::sparse::{SparseColMat, Triplet};

/// Solves `A X = B` for a symmetric positive definite `A` of order `n` given by its triplets
/// (duplicates summed); each column of `B` is one `Vec` of `rhs`, overwritten by its solution.
pub fn solve_spd(
    n: usize,
    triplets: &[(usize, usize, f64)],
    rhs: &mut [Vec<f64>],
) -> Result<(), String> {
    if n == 0 || rhs.is_empty() {
        return Ok(());
    }
    let entries: Vec<Triplet<usize, usize, f64>> = triplets
        .iter()
        .filter(|&&(i, j, _)| i >= j)
        .map(|&(i, j, v)| Triplet::new(i, j, v))
        .collect();
    let a = SparseColMat::<usize, f64>::try_new_from_triplets(n, n, &entries)
        .map_err(|e| format!("the matrix cannot be built: {e:?}"))?;
    let llt = a
        .as_ref()
        .sp_cholesky(Side::Lower)
        .map_err(|e| format!("the matrix is not positive definite ({e:?})"))?;
    let b = faer::Mat::<f64>::from_fn(n, rhs.len(), |i, j| rhs[j][i]);
    let x = llt.solve(&b);
    for (j, column) in rhs.iter_mut().enumerate() {
        for (i, v) in column.iter_mut().enumerate() {
            *v = x[(i, j)];
        }
    }
    if rhs.iter().flatten().all(|v| v.is_finite()) {
        Ok(())
    } else {
        Err("the solution is not finite".into())
    }
}
