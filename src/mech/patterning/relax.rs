//! Least-squares strain relaxation: positions `y` (flat, `D = 2`, or in space, `D = 3`) that
//! minimize `Φ = Σ_T A_T ‖E_T‖²_F + p Σ_i ‖y_i − y_i⁰‖²`, where `E = ½(FᵀF − I)` is the Green
//! strain of the map `F = Σ y_k ∇N_kᵀ` (D×2) from each triangle's stress-free shape (gradients
//! `∇N_k`, area `A_T`) onto its place, written as Voigt rows `√A [Exx, Eyy, √2 Exy]`; `p ≥ 0`
//! holds the modes no strain resists (a membrane's bending) near the start. Gauss–Newton with
//! step halving, some coordinates held. With `D = 2` this flattens a strip after the conformal
//! map ([`relax_strains`]): the energy-based flattening of a film with a unit, Poisson-free
//! modulus; with `D = 3` it fits the film to its cut pattern (`reference`).

use nalgebra::{SVector, Vector2, Vector3};

use super::{Strip, StripTriangle};
use crate::mech::formfinding::solve_spd;

/// One triangle of [`least_strain`]: its nodes, its stress-free shape gradients and area.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StrainTerm {
    /// The triangle's three nodes (indices into the positions).
    pub nodes: [usize; 3],
    /// `∇N_k` of its stress-free shape.
    pub gradients: [Vector2<f64>; 3],
    /// Its stress-free area `A_T`.
    pub area: f64,
}

impl From<&StripTriangle> for StrainTerm {
    fn from(t: &StripTriangle) -> Self {
        Self {
            nodes: t.local,
            gradients: t.element.shape_gradients(),
            area: t.element.area(),
        }
    }
}

/// The residual `√A [Exx, Eyy, √2 Exy]` of one triangle and its Jacobian `j[row][k] = ∂r_row/∂y_k`
/// (`∂E/∂y_k` as in the element's strain operator, eq. 2.2).
pub fn strain_residual<const D: usize>(
    t: &StrainTerm,
    y: &[[f64; D]],
) -> (Vector3<f64>, [[SVector<f64, D>; 3]; 3]) {
    let (mut f1, mut f2) = (SVector::<f64, D>::zeros(), SVector::<f64, D>::zeros());
    for k in 0..3 {
        let p = SVector::<f64, D>::from(y[t.nodes[k]]);
        f1 += p * t.gradients[k].x;
        f2 += p * t.gradients[k].y;
    }
    let s = t.area.sqrt();
    let root2 = std::f64::consts::SQRT_2;
    let r = Vector3::new(
        0.5 * (f1.dot(&f1) - 1.0),
        0.5 * (f2.dot(&f2) - 1.0),
        0.5 * root2 * f1.dot(&f2),
    ) * s;
    let j = [
        t.gradients.map(|g| f1 * (s * g.x)),
        t.gradients.map(|g| f2 * (s * g.y)),
        t.gradients.map(|g| (f1 * g.y + f2 * g.x) * (s / root2)),
    ];
    (r, j)
}

/// `Φ` of the positions `y` (pull `p` towards `start`).
pub fn strain_measure<const D: usize>(
    terms: &[StrainTerm],
    y: &[[f64; D]],
    pull: f64,
    start: &[[f64; D]],
) -> f64 {
    let strain: f64 = terms
        .iter()
        .map(|t| strain_residual(t, y).0.norm_squared())
        .sum();
    let moved: f64 = y
        .iter()
        .zip(start)
        .flat_map(|(a, b)| (0..D).map(move |c| (a[c] - b[c]).powi(2)))
        .sum();
    strain + pull * moved
}

/// Moves `y` (the coordinates `held` excepted) to the least `Φ`, at most `iterations`
/// Gauss–Newton steps; returns `Φ`.
pub fn least_strain<const D: usize>(
    terms: &[StrainTerm],
    y: &mut [[f64; D]],
    held: &[[bool; D]],
    pull: f64,
    iterations: usize,
) -> Result<f64, String> {
    let mut index = vec![[usize::MAX; D]; y.len()];
    let mut free = 0;
    for (i, h) in held.iter().enumerate() {
        for c in (0..D).filter(|&c| !h[c]) {
            index[i][c] = free;
            free += 1;
        }
    }
    let start = y.to_vec();
    let mut phi = strain_measure(terms, y, pull, &start);
    for _ in 0..iterations {
        let (mut triplets, mut gradient) = (Vec::new(), vec![0.0; free]);
        for (i, slots) in index.iter().enumerate() {
            for (c, &slot) in slots.iter().enumerate().filter(|(_, s)| **s != usize::MAX) {
                triplets.push((slot, slot, pull));
                gradient[slot] -= pull * (y[i][c] - start[i][c]);
            }
        }
        for t in terms {
            let (r, j) = strain_residual(t, y);
            for (k, p) in (0..3).flat_map(|k| (0..D).map(move |a| (k, a))) {
                let Some(row) = Some(index[t.nodes[k]][p]).filter(|&s| s != usize::MAX) else {
                    continue;
                };
                gradient[row] -= (0..3).map(|m| j[m][k][p] * r[m]).sum::<f64>();
                for (l, q) in (0..3).flat_map(|l| (0..D).map(move |b| (l, b))) {
                    let col = index[t.nodes[l]][q];
                    if col != usize::MAX {
                        triplets.push((row, col, (0..3).map(|m| j[m][k][p] * j[m][l][q]).sum()));
                    }
                }
            }
        }
        let mut columns = [gradient];
        solve_spd(free, &triplets, &mut columns)?;
        let (mut step, before) = (1.0, y.to_vec());
        let trial = loop {
            for (i, p) in y.iter_mut().enumerate() {
                for c in (0..D).filter(|&c| index[i][c] != usize::MAX) {
                    p[c] = before[i][c] + step * columns[0][index[i][c]];
                }
            }
            let trial = strain_measure(terms, y, pull, &start);
            if trial <= phi {
                break trial;
            }
            step *= 0.5;
            if step < 1e-6 {
                y.copy_from_slice(&before);
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

/// Relaxes `strip.flat` to the least strain against the 3-D strip (one node held, a second one
/// held across the line between them); returns `Φ`.
pub fn relax_strains(
    strip: &mut Strip,
    elements: &[StripTriangle],
    iterations: usize,
) -> Result<f64, String> {
    let (a, b) = pinned_pair(&strip.flat);
    let mut held = vec![[false; 2]; strip.flat.len()];
    held[a] = [true; 2];
    let (dx, dy) = (
        strip.flat[b][0] - strip.flat[a][0],
        strip.flat[b][1] - strip.flat[a][1],
    );
    held[b][if dx.abs() >= dy.abs() { 1 } else { 0 }] = true;
    let terms: Vec<StrainTerm> = elements.iter().map(StrainTerm::from).collect();
    least_strain(&terms, &mut strip.flat, &held, 0.0, iterations)
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
