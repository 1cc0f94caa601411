//! The whole pattern: each strip flattened ([`conformal_map`] then [`relax_strains`]), turned
//! to its long axis, its distortion measured, then shrunk by its compensation.

use super::compensate::{align, prestress_compensation, shrink};
use super::distortion::{Distortion, distortion};
use super::flatten::conformal_map;
use super::relax::relax_strains;
use super::{Strip, outline::bounds};
use crate::mech::model::Model;

/// How the strips are compensated.
#[derive(Clone, Debug, PartialEq)]
pub enum Compensation {
    /// The same `[c_x, c_y]` (along and across each strip) for every strip.
    Uniform([f64; 2]),
    /// The strain of the model's target prestress along each strip's axes ([`prestress_compensation`]).
    Prestress,
    /// `[c_x, c_y]` of each strip (the friction-aware iteration's, [`super::erection`]).
    PerStrip(Vec<[f64; 2]>),
}

/// A cut strip.
#[derive(Clone, Debug, PartialEq)]
pub struct CutStrip {
    /// The strip, its `flat` positions compensated, long axis along `x`.
    pub strip: Strip,
    /// The distortion of the flat strip (before compensation) against the 3-D strip.
    pub distortion: Distortion,
    /// The compensation applied `[c_x, c_y]`.
    pub compensation: [f64; 2],
    /// Length and width of the compensated strip's bounding box (m).
    pub size: [f64; 2],
}

/// Cuts the film of `model` into the strips of `triangles` (one list per strip) and flattens,
/// measures and compensates each (Lévy et al. 2002 eq. 4, then the relaxation of `relax`).
pub fn cut_pattern(
    model: &Model,
    triangles: Vec<Vec<usize>>,
    compensation: Compensation,
) -> Result<Vec<CutStrip>, String> {
    let x = &model.nodes;
    triangles
        .into_iter()
        .enumerate()
        .map(|(k, tris)| {
            let mut strip = Strip::new(model, tris);
            let elements = strip
                .elements(model, x)
                .map_err(|e| format!("strip {k}: {e}"))?;
            conformal_map(&mut strip, &elements, x)
                .map_err(|e| format!("strip {k}: flattening: {e}"))?;
            relax_strains(&mut strip, &elements, 100)
                .map_err(|e| format!("strip {k}: relaxation: {e}"))?;
            let local: Vec<[usize; 3]> = elements.iter().map(|e| e.local).collect();
            align(&mut strip.flat, &local);
            let measured = distortion(&elements, &strip.flat);
            let c = match &compensation {
                Compensation::Uniform(c) => *c,
                Compensation::PerStrip(c) => c[k],
                Compensation::Prestress => prestress_compensation(
                    &model.material,
                    model.material.prestress,
                    &elements,
                    &strip.flat,
                ),
            };
            shrink(&mut strip.flat, c);
            let b = bounds(&strip.flat);
            Ok(CutStrip {
                strip,
                distortion: measured,
                compensation: c,
                size: [b[2] - b[0], b[3] - b[1]],
            })
        })
        .collect()
}
