//! Compensation by erection (issue 46, step 3): the cut is erected by the project's own analysis
//! (contacts, friction, plasticity: whatever the found model holds besides its film), the
//! prestress after erection is compared with the target, and each strip's compensation is
//! corrected by the strain of the difference, by fixed point:
//!
//! `c_a ← c_a + ⟨d_aᵀ D⁻¹ (σ_target − σ) d_a⟩_A`, `a` along and across the strip,
//!
//! with `d_a` the direction in each triangle's frame that the strip's flat axis `a` comes from
//! (through the fit of the reference geometry) and `⟨·⟩_A` the area mean over the strip. A
//! strip's two numbers are its reference lengths; what varies inside a strip (friction holding
//! the film on a support, the flattening's distortion) is left and reported element by element.

use nalgebra::{Matrix2, Vector2, Vector3};

use super::cut::{Compensation, CutStrip, cut_pattern};
use super::element_compensation::erect_with_contacts;
use super::reference::{erection_model, reference_geometry};
use crate::mech::elements::triangle::ElementStress;
use crate::mech::model::Model;

/// One erection of the iteration.
#[derive(Clone, Debug, PartialEq)]
pub struct ErectionIteration {
    /// The compensation `[c_x, c_y]` of each strip that was erected.
    pub compensation: Vec<[f64; 2]>,
    /// Largest `|σ − σ_target|/|σ_target|` over the elements (normal components).
    pub max_error: f64,
    /// Area-weighted mean of the same.
    pub mean_error: f64,
    /// The error of each element.
    pub element_errors: Vec<f64>,
}

/// Erects a model by the analysis and returns its element stresses.
pub type Erect<'a> = dyn FnMut(Model) -> Result<Vec<ElementStress>, String> + 'a;

/// The stress-deficit strain `⟨d_aᵀ D⁻¹ (σ_target − σ) d_a⟩_A` along each flat axis of a strip,
/// and the element errors (the correction of the fixed point above).
fn correction(
    found: &Model,
    reference: &[[f64; 3]],
    cut: &CutStrip,
    stresses: &[ElementStress],
    errors: &mut [f64],
) -> [f64; 2] {
    let d_inv = found
        .material
        .elasticity()
        .try_inverse()
        .expect("the film's D is invertible");
    let target = Vector3::from(found.material.prestress);
    let size = target.x.abs().max(target.y.abs()).max(f64::MIN_POSITIVE);
    let local = cut.strip.local_index();
    let (mut c, mut area) = ([0.0; 2], 0.0);
    for &t in &cut.strip.triangles {
        let tri = found.triangles[t];
        let Ok(element) = found.element_on(t, reference) else {
            continue;
        };
        let Ok(cut_element) = cut.strip.flat_element(found, &local, t) else {
            continue;
        };
        // F: the cut triangle (its frame) onto the reference; F (flat axis) in the element frame.
        let g = cut_element.shape_gradients();
        let f = (0..3).fold(nalgebra::Matrix3x2::zeros(), |f, k| {
            f + Vector3::from(reference[tri[k]]) * g[k].transpose()
        });
        let (e1, e2) = element.local_axes();
        let (c1, c2) = cut_element.local_axes();
        let s = Vector3::from(stresses[t].stress);
        let deficit = d_inv * (target - s);
        let strain = Matrix2::new(deficit.x, 0.5 * deficit.z, 0.5 * deficit.z, deficit.y);
        for (axis, c) in c.iter_mut().enumerate() {
            let flat_axis = Vector3::ith(axis, 1.0);
            let v = f * Vector2::new(flat_axis.dot(&c1), flat_axis.dot(&c2));
            let d = Vector2::new(v.dot(&e1), v.dot(&e2)).normalize();
            *c += element.area() * (d.transpose() * strain * d)[0];
        }
        area += element.area();
        errors[t] = (s.x - target.x).abs().max((s.y - target.y).abs()) / size;
    }
    c.map(|c| c / area.max(f64::MIN_POSITIVE))
}

/// Erects `model` by the project's analysis, every group to its target in `increments`.
pub fn erect_by_analysis(model: Model, increments: usize) -> Result<Vec<ElementStress>, String> {
    erect_with_contacts(model, increments).map(|e| e.elements)
}

/// Cuts, erects with `erect`, corrects each strip's compensation and repeats (at most
/// `iterations` erections, until the mean error is below `tolerance`), starting from `start`;
/// returns every erection.
pub fn compensate_by_erection(
    found: &Model,
    strips: Vec<Vec<usize>>,
    start: Compensation,
    (iterations, tolerance): (usize, f64),
    erect: &mut Erect<'_>,
) -> Result<Vec<ErectionIteration>, String> {
    let mut history = Vec::new();
    let mut compensation = start;
    for _ in 0..iterations {
        let cut = cut_pattern(found, strips.clone(), compensation)?;
        let reference = reference_geometry(found, &cut)?;
        let stresses = erect(erection_model(found, reference.clone()))?;
        let mut errors = vec![0.0; found.triangles.len()];
        let mut next = Vec::with_capacity(cut.len());
        for strip in &cut {
            let dc = correction(found, &reference, strip, &stresses, &mut errors);
            next.push([strip.compensation[0] + dc[0], strip.compensation[1] + dc[1]]);
        }
        let areas: Vec<f64> = found
            .triangles
            .iter()
            .map(|t| triangle_area(found, *t))
            .collect();
        let mean_error =
            errors.iter().zip(&areas).map(|(e, a)| e * a).sum::<f64>() / areas.iter().sum::<f64>();
        let max_error = errors.iter().fold(0.0, |m: f64, &e| m.max(e));
        history.push(ErectionIteration {
            compensation: cut.iter().map(|c| c.compensation).collect(),
            max_error,
            mean_error,
            element_errors: errors,
        });
        if mean_error <= tolerance {
            break;
        }
        compensation = Compensation::PerStrip(next);
    }
    Ok(history)
}

fn triangle_area(model: &Model, t: [usize; 3]) -> f64 {
    let p = t.map(|v| Vector3::from(model.nodes[v]));
    0.5 * (p[1] - p[0]).cross(&(p[2] - p[0])).norm()
}
