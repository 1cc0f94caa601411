//! How far a flat strip is from its 3-D strip: the principal Green strains `ε1 ≥ ε2` of each
//! triangle's map onto the flat one (`E = ½(FᵀF − I)`), their largest magnitude and their
//! area-weighted root mean square `√(Σ A (ε1² + ε2²) / (2 Σ A))`.

use super::{StripTriangle, flat_gradient, green};

/// The distortion of a flat strip.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Distortion {
    /// Largest `|ε1|`, `|ε2|` over the strip's triangles.
    pub max_strain: f64,
    /// Area-weighted root mean square of the principal strains.
    pub rms_strain: f64,
}

/// Principal Green strains `[ε1, ε2]` of a symmetric 2×2 strain `E`.
pub fn principal(e: &nalgebra::Matrix2<f64>) -> [f64; 2] {
    let centre = 0.5 * (e[(0, 0)] + e[(1, 1)]);
    let radius = (0.25 * (e[(0, 0)] - e[(1, 1)]).powi(2) + e[(0, 1)] * e[(1, 0)]).sqrt();
    [centre + radius, centre - radius]
}

/// The distortion of the flat positions `y` against the 3-D triangles.
pub fn distortion(elements: &[StripTriangle], y: &[[f64; 2]]) -> Distortion {
    let (mut max, mut sum, mut area) = (0.0f64, 0.0, 0.0);
    for t in elements {
        let [e1, e2] = principal(&green(&flat_gradient(t, y)));
        max = max.max(e1.abs()).max(e2.abs());
        sum += t.element.area() * (e1 * e1 + e2 * e2);
        area += 2.0 * t.element.area();
    }
    Distortion {
        max_strain: max,
        rms_strain: (sum / area).sqrt(),
    }
}
