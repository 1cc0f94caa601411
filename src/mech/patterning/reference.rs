//! The compensated reference geometry of the whole film, for an erection model: the 3-D
//! positions `X` whose triangles fit their compensated cut shapes best, `min Σ_T A_T ‖E_T‖²_F`
//! with `E_T` the Green strain of the map from the cut (flat, compensated) triangle onto `X`
//! ([`least_strain`] with `D = 3`, started from the found shape and held near it by a small pull
//! `p = 1e-6 ⟨A |∇N|²⟩` against a membrane's unresisted bending). The erection model has that
//! geometry, no prestress (the cut film is stress-free), and every node the found model holds
//! (supports, boundary groups) driven by a group of its own from `X` back to its found place.
//! A seam is welded: its node takes one position for the strips on both sides, so the fit
//! spreads what the strips' distortion leaves; that residual is not kept as a prestress.

use super::cut::CutStrip;
use super::relax::{StrainTerm, least_strain};
use crate::mech::model::restraint::held_axes;
use crate::mech::model::{Axis, BoundaryGroup, Model};

/// The stress-free shapes of every cut triangle on the model's nodes.
fn cut_terms(model: &Model, cut: &[CutStrip]) -> Result<Vec<StrainTerm>, String> {
    let mut terms = Vec::new();
    for c in cut {
        let local = c.strip.local_index();
        for &t in &c.strip.triangles {
            let element = c.strip.flat_element(model, &local, t)?;
            terms.push(StrainTerm {
                nodes: model.triangles[t],
                gradients: element.shape_gradients(),
                area: element.area(),
            });
        }
    }
    Ok(terms)
}

/// The 3-D positions whose triangles best fit their cut shapes (least strain, started from the
/// found shape `model.nodes`).
pub fn reference_geometry(model: &Model, cut: &[CutStrip]) -> Result<Vec<[f64; 3]>, String> {
    let terms = cut_terms(model, cut)?;
    let stiffness: f64 = terms
        .iter()
        .map(|t| t.area * t.gradients.iter().map(|g| g.norm_squared()).sum::<f64>())
        .sum();
    let pull = 1e-6 * stiffness / terms.len().max(1) as f64;
    let mut x = model.nodes.clone();
    let held = vec![[false; 3]; x.len()];
    least_strain(&terms, &mut x, &held, pull, 50)?;
    Ok(x)
}

/// The erection model: the `reference` geometry, no prestress, every node `found` holds
/// driven by its own group `node<k>` to its found place (the held components only).
pub fn erection_model(found: &Model, reference: Vec<[f64; 3]>) -> Model {
    // Supports, symmetry planes and groups become one group per node: the cut film's nodes
    // start off those planes and lines, and are driven onto them.
    let held = held_axes(found);
    let mut model = found.clone();
    model.symmetry.clear();
    model.name = format!("{}Erection", found.name);
    model.material.prestress = [0.0; 3];
    model.supports.clear();
    let mut groups = Vec::new();
    for (k, h) in held
        .iter()
        .enumerate()
        .filter(|(_, h)| h.iter().any(|&b| b))
    {
        let target: [f64; 3] = std::array::from_fn(|c| {
            if h[c] {
                found.nodes[k][c] - reference[k][c]
            } else {
                0.0
            }
        });
        let components = [Axis::X, Axis::Y, Axis::Z]
            .into_iter()
            .filter(|a| h[a.index()])
            .collect();
        groups.push(BoundaryGroup {
            name: format!("node{k}"),
            nodes: vec![k],
            target,
            components: Some(components),
            hinge: None,
        });
    }
    model.groups = groups;
    model.nodes = reference;
    model
}
