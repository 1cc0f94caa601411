//! The Woodbury correction for a low-rank skew part on top of the symmetric part's LDLᵀ.

use nalgebra::{DMatrix, DVector};

/// `x = y − W (I + K_CC W_C)⁻¹ K_CC y_C` from the block `[W y] = S⁻¹ [I_C b]` (column-major,
/// `n` rows) and the skew entries `(i, j, k_ij)` below the diagonal (`k_ji = −k_ij`): the
/// solution of `(S + K) x = b` (Woodbury's identity with `K = I_C K_CC I_Cᵀ`). False when the
/// small matrix is singular. With `sign = −1` the skew part is negated: the solution of
/// `Aᵀ x = (S − K) x = b` from the same block (`S` is symmetric, so `W` serves both).
pub(super) fn woodbury_correction(
    dofs: &[usize],
    (skew, sign): (&[(usize, usize, f64)], f64),
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
        k[(a, b)] += sign * h;
        k[(b, a)] -= sign * h;
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
