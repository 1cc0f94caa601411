//! Least-squares conformal map (Lévy, Petitjean, Ray & Maillot, SIGGRAPH 2002): the flat
//! positions `(u, v)` minimize `Σ_T A_T |∂u/∂x − ∂v/∂y|² + |∂u/∂y + ∂v/∂x|²` over the strip's
//! triangles (their eq. 4 written with the shape gradients of the 3-D triangle in its local frame:
//! zero exactly when each triangle is mapped by a rotation and a scale), two nodes pinned at
//! their 3-D distance apart. A linear least-squares problem: its normal equations are solved.

use super::{Strip, StripTriangle};
use crate::mech::formfinding::solve_spd;

/// The two nodes of the strip farthest apart (approximately: from the first node, the farthest
/// one, then the farthest from it) and their distance.
pub fn far_pair(x: &[[f64; 3]], nodes: &[usize]) -> (usize, usize, f64) {
    let distance = |a: usize, b: usize| {
        let (p, q) = (x[nodes[a]], x[nodes[b]]);
        (0..3).map(|c| (p[c] - q[c]).powi(2)).sum::<f64>().sqrt()
    };
    let farthest = |a: usize| {
        (0..nodes.len())
            .max_by(|&i, &j| distance(a, i).total_cmp(&distance(a, j)))
            .unwrap()
    };
    let a = farthest(0);
    let b = farthest(a);
    (a, b, distance(a, b))
}

/// The conformal rows of one triangle: `√A (Σ u_k g_kx − v_k g_ky)` and `√A (Σ u_k g_ky + v_k g_kx)`
/// as (unknown, coefficient) pairs, unknown `2i` being `u_i` and `2i + 1` being `v_i` (Lévy eq. 4).
fn conformal_rows(t: &StripTriangle) -> [[(usize, f64); 6]; 2] {
    let g = t.element.shape_gradients();
    let s = t.element.area().sqrt();
    let n = t.local;
    let row = |a: usize, b: usize, sign: f64| {
        std::array::from_fn(|i| {
            let k = i / 2;
            if i % 2 == 0 {
                (2 * n[k], s * g[k][a])
            } else {
                (2 * n[k] + 1, sign * s * g[k][b])
            }
        })
    };
    [row(0, 1, -1.0), row(1, 0, 1.0)]
}

/// Flattens the strip by the least-squares conformal map (Lévy et al. 2002, eq. 4): fills
/// `strip.flat`, the far pair pinned at `(0, 0)` and `(d, 0)`.
pub fn conformal_map(
    strip: &mut Strip,
    elements: &[StripTriangle],
    x: &[[f64; 3]],
) -> Result<(), String> {
    let n = strip.nodes.len();
    let (a, b, d) = far_pair(x, &strip.nodes);
    let mut pinned = vec![None; 2 * n];
    pinned[2 * a] = Some(0.0);
    pinned[2 * a + 1] = Some(0.0);
    pinned[2 * b] = Some(d);
    pinned[2 * b + 1] = Some(0.0);
    let mut index = vec![usize::MAX; 2 * n];
    let mut free = 0;
    for (i, p) in pinned.iter().enumerate() {
        if p.is_none() {
            index[i] = free;
            free += 1;
        }
    }
    let (mut triplets, mut rhs) = (Vec::new(), vec![0.0; free]);
    for row in elements.iter().flat_map(conformal_rows) {
        for &(i, ci) in &row {
            if index[i] == usize::MAX {
                continue;
            }
            for &(j, cj) in &row {
                match pinned[j] {
                    Some(value) => rhs[index[i]] -= ci * cj * value,
                    None => triplets.push((index[i], index[j], ci * cj)),
                }
            }
        }
    }
    let mut columns = [rhs];
    solve_spd(free, &triplets, &mut columns)?;
    for (i, flat) in strip.flat.iter_mut().enumerate() {
        let value = |k: usize| pinned[k].unwrap_or_else(|| columns[0][index[k]]);
        *flat = [value(2 * i), value(2 * i + 1)];
    }
    Ok(())
}
