//! Compensation: the flat strip is cut smaller, so that stretched into place it carries the
//! prestress. The strip is first turned so that its long axis is `x` (principal axes of its
//! flat nodes); then `x' = x/(1 + c_x)`, `y' = y/(1 + c_y)`. Either `c` is given (uniform), or it is
//! the strain of the target prestress, `ε = D⁻¹σ` (for a biaxial `σ`: `ε = σ(1 − ν)/E`), along
//! each axis: per triangle `ε_d = dᵀ ε d` with `d` the 3-D direction (in the element frame) that
//! the flat axis comes from, `d ∝ F⁻¹ e`, averaged over the strip by area.

use nalgebra::{Matrix2, Vector2};

use super::{StripTriangle, flat_gradient};
use crate::mech::elements::material::Material;

/// Turns the flat strip about its centroid so that its long principal axis is `x`: the
/// centroid and the principal axes of its area (the flat `triangles`, local node indices), so
/// that they are the strip's shape's whatever its mesh (a strip split along a seam has more
/// nodes on that side).
pub fn align(flat: &mut [[f64; 2]], triangles: &[[usize; 3]]) {
    // ∫ x dA and ∫ x xᵀ dA of each triangle: A (a + b + c)/3 and A/12 (Σ v vᵀ + s sᵀ), s = a + b + c.
    let (mut area, mut first, mut second) = (0.0, Vector2::zeros(), Matrix2::zeros());
    for t in triangles {
        let [a, b, c] = t.map(|k| Vector2::from(flat[k]));
        let d = 0.5 * ((b - a).perp(&(c - a))).abs();
        let s = a + b + c;
        area += d;
        first += s * (d / 3.0);
        second += (a * a.transpose() + b * b.transpose() + c * c.transpose() + s * s.transpose())
            * (d / 12.0);
    }
    if area <= 0.0 {
        return;
    }
    let c = first / area;
    let m = second / area - c * c.transpose();
    let angle = 0.5 * (2.0 * m[(0, 1)]).atan2(m[(0, 0)] - m[(1, 1)]);
    let (s, co) = angle.sin_cos();
    for p in flat.iter_mut() {
        let (x, y) = (p[0] - c.x, p[1] - c.y);
        *p = [co * x + s * y, -s * x + co * y];
    }
}

/// The compensation `[c_x, c_y]` of an aligned flat strip from the target `prestress` (the
/// strain `ε = D⁻¹σ` of the film law, eq. 2.3, along each flat axis).
pub fn prestress_compensation(
    material: &Material,
    prestress: [f64; 3],
    elements: &[StripTriangle],
    flat: &[[f64; 2]],
) -> [f64; 2] {
    let d_inv = material
        .elasticity()
        .try_inverse()
        .expect("the film's D is invertible");
    let e = d_inv * nalgebra::Vector3::from(prestress);
    let strain = Matrix2::new(e.x, 0.5 * e.z, 0.5 * e.z, e.y);
    let (mut c, mut area) = ([0.0; 2], 0.0);
    for t in elements {
        let Some(f_inv) = flat_gradient(t, flat).try_inverse() else {
            continue;
        };
        for (axis, c) in c.iter_mut().enumerate() {
            let d = (f_inv * Vector2::ith(axis, 1.0)).normalize();
            *c += t.element.area() * (d.transpose() * strain * d)[0];
        }
        area += t.element.area();
    }
    c.map(|c| c / area)
}

/// Shrinks the aligned flat strip by the compensation `c`: `x/(1 + c_x)`, `y/(1 + c_y)`.
pub fn shrink(flat: &mut [[f64; 2]], c: [f64; 2]) {
    flat.iter_mut()
        .for_each(|p| *p = [p[0] / (1.0 + c[0]), p[1] / (1.0 + c[1])]);
}
