//! Gaps on a circular arc and the grid helpers the scenario meshes share.

use nalgebra::Vector3;

use crate::mech::elements::gap::{FrictionLaw, GapFrame};
use crate::mech::elements::material::Material;
use crate::mech::model::{GapSpec, GapSupport, Model};
use crate::specimens::parallel_arch::ParallelArch;

// ------------------------------------------------------------------- gaps on a circular arc

/// A circular support: an arch (a circle arc in the plane through `centre` normal to `axis`) or
/// a cylinder (the same circle swept along `axis`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CircularSupport {
    /// Centre of curvature (m).
    pub centre: [f64; 3],
    /// Unit normal of the circle's plane (the cylinder's axis).
    pub axis: [f64; 3],
    /// Radius (m).
    pub radius: f64,
}

/// Penalties and friction of generated gaps.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GapConstants {
    /// `k_n` (N/m).
    pub normal_stiffness: f64,
    /// `k_s` (N/m).
    pub tangential_stiffness: f64,
    /// `μ`.
    pub friction: f64,
    /// Friction law of every generated gap.
    pub friction_law: FrictionLaw,
}

impl GapConstants {
    /// The specimen's rule (`k_n = 1000 E t`, `k_s = 0.1 k_n`, see `parallel_arch.rs`) for a film.
    pub fn for_film(material: &Material, friction: f64) -> Self {
        let spec = ParallelArch::default();
        let kn = spec.normal_penalty_factor * material.membrane_stiffness();
        Self {
            normal_stiffness: kn,
            tangential_stiffness: spec.tangential_penalty_ratio * kn,
            friction,
            friction_law: FrictionLaw::default(),
        }
    }
}

/// Gaps from film nodes to a circular support with the paper's §4.3 frames: for each node, `z`
/// points from the axis (the centre of curvature) towards the node, the support point is on the
/// circle (cylinder) along that radius at the node's axial position, `x = z × axis` is the
/// tangent of the circle (the sliding direction), `y = z × x` (along the axis), and the initial
/// gap `g0` is the node's distance from the support along `z`. Gaps are named
/// `<prefix><k+1>` in the order of `film_nodes`.
///
/// Errors name the node: unknown index, on the axis, or inside the support (penetrating by more
/// than rounding). `ParallelArch` builds its gaps the same way (axis `+X`).
pub fn gaps_on_arc(
    nodes: &[[f64; 3]],
    film_nodes: &[usize],
    support: &CircularSupport,
    constants: GapConstants,
    prefix: &str,
) -> Result<Vec<GapSpec>, String> {
    let axis = Vector3::from(support.axis);
    let (length, radius) = (axis.norm(), support.radius);
    if length == 0.0 || !length.is_finite() || radius <= 0.0 || !radius.is_finite() {
        return Err("circular support: axis must be non-zero and radius > 0".into());
    }
    let axis = axis.normalize();
    let centre = Vector3::from(support.centre);
    film_nodes
        .iter()
        .enumerate()
        .map(|(k, &node)| {
            let name = format!("{prefix}{}", k + 1);
            let p = Vector3::from(
                *nodes
                    .get(node)
                    .ok_or_else(|| format!("gap {name}: node {node} does not exist"))?,
            );
            let along = (p - centre).dot(&axis);
            let radial = p - centre - axis * along;
            let distance = radial.norm();
            if distance < 1e-9 * support.radius {
                return Err(format!(
                    "gap {name}: node {node} lies on the support's axis"
                ));
            }
            let z = radial / distance;
            let g0 = distance - support.radius;
            if g0 < -1e-9 * support.radius {
                return Err(format!(
                    "gap {name}: node {node} lies {:.3e} m inside the support",
                    -g0
                ));
            }
            Ok(GapSpec {
                name,
                film_node: node,
                support: GapSupport::Point((centre + axis * along + z * support.radius).into()),
                frame: GapFrame::from_x_and_z(z.cross(&axis), z),
                initial_gap: g0.max(0.0),
                normal_stiffness: constants.normal_stiffness,
                tangential_stiffness: constants.tangential_stiffness,
                friction: constants.friction,
                friction_law: constants.friction_law,
            })
        })
        .collect()
}

/// Node index of grid point `(i, j)` in a row-major grid with `nx + 1` nodes per row.
pub(super) fn grid_id(nx: usize, i: usize, j: usize) -> usize {
    j * (nx + 1) + i
}

/// Triangles of an `nx × ny` structured grid (two per cell, diagonal from `(i, j)` to `(i+1, j+1)`).
pub(super) fn grid_triangles(nx: usize, ny: usize) -> Vec<[usize; 3]> {
    let id = |i, j| grid_id(nx, i, j);
    let mut triangles = Vec::with_capacity(2 * nx * ny);
    for j in 0..ny {
        for i in 0..nx {
            triangles.push([id(i, j), id(i + 1, j), id(i + 1, j + 1)]);
            triangles.push([id(i, j), id(i + 1, j + 1), id(i, j + 1)]);
        }
    }
    triangles
}

/// Grid index of coordinate `x` on a grid of spacing `dx`, if `x` falls on a grid line.
pub(super) fn grid_line(x: f64, dx: f64, n: usize) -> Option<usize> {
    let i = (x / dx).round();
    ((x / dx - i).abs() < 1e-9 && i >= 0.0 && i <= n as f64).then_some(i as usize)
}

/// Radius of a circular arch from its rise and span.
pub(super) fn arch_radius(rise: f64, span: f64) -> f64 {
    (rise * rise + span * span / 4.0) / (2.0 * rise)
}

pub(super) fn check_positive(items: &[(&str, f64)]) -> Result<(), String> {
    for (name, v) in items {
        if !(*v > 0.0 && v.is_finite()) {
            return Err(format!("{name} = {v} must be > 0"));
        }
    }
    Ok(())
}

pub(super) fn validated(model: Model) -> Result<Model, String> {
    model.validate().map_err(|e| e.to_string())?;
    Ok(model)
}
