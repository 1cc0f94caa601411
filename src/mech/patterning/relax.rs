//! Least-squares strain relaxation of a flat strip: the conformal map keeps angles but not
//! lengths; the flat positions `y` are then moved to minimize `Φ = Σ_T A_T ‖E_T‖²_F`
//! (`E = ½(FᵀF − I)` the Green strain of the map from the 3-D triangle onto the flat one,
//! Frobenius norm, Voigt rows `[Exx, Eyy, √2 Exy]`) by Gauss–Newton with step halving,
//! one node held and a second one held across the line between them (no rigid motion).
//! This is the energy-based flattening of a film with a unit, Poisson-free modulus.

use nalgebra::{Matrix2, SMatrix, SVector};

use super::{Strip, StripTriangle, flat_gradient, green};
use crate::mech::formfinding::solve_spd;

/// The residual `√A [Exx, Eyy, √2 Exy]` of one triangle and its Jacobian on the triangle's six
/// flat coordinates `[y_0x, y_0y, y_1x, …]` (`∂E/∂y_k` as in the element's strain operator, eq. 2.2).
pub fn strain_residual(t: &StripTriangle, y: &[[f64; 2]]) -> (SVector<f64, 3>, SMatrix<f64, 3, 6>) {
    let f = flat_gradient(t, y);
    let e: Matrix2<f64> = green(&f);
    let s = t.element.area().sqrt();
    let r = SVector::<f64, 3>::new(e[(0, 0)], e[(1, 1)], std::f64::consts::SQRT_2 * e[(0, 1)]) * s;
    let g = t.element.shape_gradients();
    let (f1, f2) = (f.column(0), f.column(1));
    let mut j = SMatrix::<f64, 3, 6>::zeros();
    for k in 0..3 {
        let (b, c) = (g[k].x, g[k].y);
        let shear = (f1 * c + f2 * b) * std::f64::consts::FRAC_1_SQRT_2;
        for a in 0..2 {
            j[(0, 2 * k + a)] = s * f1[a] * b;
            j[(1, 2 * k + a)] = s * f2[a] * c;
            j[(2, 2 * k + a)] = s * shear[a];
        }
    }
    (r, j)
}

/// `Φ = Σ_T ‖r_T‖²` of the flat positions `y`.
pub fn strain_measure(elements: &[StripTriangle], y: &[[f64; 2]]) -> f64 {
    elements
        .iter()
        .map(|t| strain_residual(t, y).0.norm_squared())
        .sum()
}

/// Relaxes `strip.flat` to the least `Φ` (at most `iterations` Gauss–Newton steps); returns `Φ`.
pub fn relax_strains(
    strip: &mut Strip,
    elements: &[StripTriangle],
    iterations: usize,
) -> Result<f64, String> {
    let n = strip.nodes.len();
    let (a, b) = pinned_pair(&strip.flat);
    // Held: both coordinates of a, and of b the one across the line a–b (its larger offset).
    let across = if (strip.flat[b][0] - strip.flat[a][0]).abs()
        >= (strip.flat[b][1] - strip.flat[a][1]).abs()
    {
        1
    } else {
        0
    };
    let mut index = vec![usize::MAX; 2 * n];
    let mut free = 0;
    for (i, slot) in index.iter_mut().enumerate() {
        if i / 2 != a && i != 2 * b + across {
            *slot = free;
            free += 1;
        }
    }
    let mut phi = strain_measure(elements, &strip.flat);
    for _ in 0..iterations {
        let (mut triplets, mut gradient) = (Vec::new(), vec![0.0; free]);
        for t in elements {
            let (r, j) = strain_residual(t, &strip.flat);
            let dofs: [usize; 6] = std::array::from_fn(|i| index[2 * t.local[i / 2] + i % 2]);
            let (jtj, jtr) = (j.transpose() * j, j.transpose() * r);
            for p in (0..6).filter(|&p| dofs[p] != usize::MAX) {
                gradient[dofs[p]] -= jtr[p];
                for q in (0..6).filter(|&q| dofs[q] != usize::MAX) {
                    triplets.push((dofs[p], dofs[q], jtj[(p, q)]));
                }
            }
        }
        let mut columns = [gradient];
        solve_spd(free, &triplets, &mut columns)?;
        let (mut step, start) = (1.0, strip.flat.clone());
        let trial = loop {
            for (i, y) in strip.flat.iter_mut().enumerate() {
                for c in (0..2).filter(|&c| index[2 * i + c] != usize::MAX) {
                    y[c] = start[i][c] + step * columns[0][index[2 * i + c]];
                }
            }
            let trial = strain_measure(elements, &strip.flat);
            if trial <= phi {
                break trial;
            }
            step *= 0.5;
            if step < 1e-6 {
                strip.flat = start;
                return Ok(phi);
            }
        };
        let gain = phi - trial;
        phi = trial;
        if gain <= 1e-14 * (phi + gain) {
            break;
        }
    }
    Ok(phi)
}

/// The two flat nodes farthest apart along the flat strip's longer bounding-box side.
fn pinned_pair(flat: &[[f64; 2]]) -> (usize, usize) {
    let extent = |c: usize| {
        let (lo, hi) = flat
            .iter()
            .fold((f64::MAX, f64::MIN), |(l, h), p| (l.min(p[c]), h.max(p[c])));
        hi - lo
    };
    let c = if extent(0) >= extent(1) { 0 } else { 1 };
    let (a, _) = flat
        .iter()
        .enumerate()
        .min_by(|p, q| p.1[c].total_cmp(&q.1[c]))
        .unwrap();
    let (b, _) = flat
        .iter()
        .enumerate()
        .max_by(|p, q| p.1[c].total_cmp(&q.1[c]))
        .unwrap();
    (a, b)
}
