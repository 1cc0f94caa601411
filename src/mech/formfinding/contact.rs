//! Form finding against contact supports (issue 46, step 1): the updated reference strategy
//! with a homotopy `λ > 0` (Bletzinger & Ramm 1999, eq. 12), each step solved by the project's
//! own analysis with the model's curved supports frictionless.
//!
//! Step `k` is the equilibrium of the film on the reference `X_k` with the stress
//! `S = σ* + λ D E(x)` (the target as the film's prestress, the film's elasticity scaled by `λ`),
//! its boundary held where the model puts it and its curved supports in contact with `μ = 0`
//! (the analysis's penalty contact: unilateral, frictionless; `docs/mechanics.md`, "Contact on
//! curved supports"); then `X_{k+1} = x`. At the fixed point `x = X`, so `E = 0` and the film
//! carries exactly `σ*` in equilibrium with its boundary and the supports' contact forces. With
//! `λ = 0` (the strategy of [`super::update_reference`]) the step is a net of zero-length springs
//! for an isotropic stress, and nodes free to slide over a frictionless support gather at its
//! side and let an element pass through it (tried on the drum, `docs/mechanics.md`); the scaled
//! elasticity resists that distortion while the reference moves, and vanishes from the result.
//! Converged when the stress of a step's equilibrium is within the tolerance of the target in
//! every element (`max |S − σ*|/|σ*|`, what the elastic share still adds): the reference then
//! carries the target within that tolerance. (The nodes need not stop: over a frictionless drum
//! a uniform stress has no exact discrete equilibrium where the film leaves the support, and the
//! mesh keeps sliding by a fraction of an edge per step, 1e-3 after 3000 steps.)

use nalgebra::Vector3;

use super::force_density::bars;
use crate::mech::model::Model;
use crate::mech::{Analysis, SolverSettings};

/// Settings of [`find_shape_with_contact`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ContactSettings {
    /// Largest stress deviation `|S − σ*|/|σ*|` of a step's equilibrium accepted.
    pub tolerance: f64,
    /// Most reference updates.
    pub max_steps: usize,
    /// The homotopy factor `λ`: the share of the film's elasticity kept in each step.
    pub homotopy: f64,
    /// Load increments of each step's analysis.
    pub increments: usize,
}

impl Default for ContactSettings {
    fn default() -> Self {
        Self {
            tolerance: 1e-3,
            max_steps: 200,
            homotopy: 0.01,
            increments: 1,
        }
    }
}

/// A shape found against the supports.
#[derive(Clone, Debug, PartialEq)]
pub struct FoundOnSupports {
    /// Node positions of the shape (m).
    pub nodes: Vec<[f64; 3]>,
    /// Largest node move of each step, relative to the mean edge length.
    pub moves: Vec<f64>,
    /// Largest `|S − σ*|/|σ*|` of each step's equilibrium (what the elastic share adds).
    pub deviations: Vec<f64>,
    /// The film nodes in contact with a curved support at the end.
    pub touching: Vec<usize>,
}

/// Why a shape against the supports was not found.
#[derive(Clone, Debug, PartialEq)]
pub enum ContactFormFindingError {
    /// The analysis of step `step` failed (its message).
    Analysis {
        /// The reference update.
        step: usize,
        /// What the analysis said.
        reason: String,
    },
    /// The steps were spent before the stress came within the tolerance of the target.
    NotConverged {
        /// Steps made.
        steps: usize,
        /// Largest stress deviation of the last step.
        deviation: f64,
    },
}

impl std::fmt::Display for ContactFormFindingError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::Analysis { step, reason } => {
                write!(f, "form finding on supports: step {step}: {reason}")
            }
            Self::NotConverged { steps, deviation } => write!(
                f,
                "form finding on supports: the stress still deviates {deviation:.3e} of the target after {steps} steps"
            ),
        }
    }
}

impl std::error::Error for ContactFormFindingError {}

/// One step: the film on the reference `x` with the target `prestress`, its elasticity scaled by
/// `λ`, supports frictionless, boundary held in place; the new positions and the touching nodes.
fn step(
    model: &Model,
    x: &[[f64; 3]],
    prestress: [f64; 3],
    settings: &ContactSettings,
) -> Result<(Vec<[f64; 3]>, Vec<usize>, f64), String> {
    let mut m = model.clone();
    m.nodes = x.to_vec();
    m.material.prestress = prestress;
    m.material.youngs_modulus *= settings.homotopy;
    m.curved_supports.iter_mut().for_each(|s| s.friction = 0.0);
    let held = vec![[0.0; 3]; m.groups.len()];
    let mut analysis = Analysis::new(m, SolverSettings::default()).map_err(|e| e.to_string())?;
    analysis
        .step_to(&held, settings.increments)
        .map_err(|e| e.to_string())?;
    let next = (0..x.len())
        .map(|v| (Vector3::from(x[v]) + analysis.node_displacement(v)).into())
        .collect();
    let results = analysis.results();
    let size = prestress.iter().fold(0.0f64, |m, s| m.max(s.abs()));
    let deviation = results
        .elements
        .iter()
        .flat_map(|e| (0..3).map(move |i| (e.stress[i] - prestress[i]).abs()))
        .fold(0.0, f64::max)
        / size;
    let nodes = model.curved_supports.iter().flat_map(|s| s.nodes.iter());
    let touching = nodes
        .zip(&results.surface_contacts)
        .filter(|(_, c)| c.normal_force > 0.0)
        .map(|(&v, _)| v)
        .collect();
    Ok((next, touching, deviation))
}

/// Updates the reference from `start` until the target `prestress` (Voigt, element frame) is in
/// equilibrium with the held boundary and the frictionless curved supports (module doc).
pub fn find_shape_with_contact(
    model: &Model,
    start: Vec<[f64; 3]>,
    prestress: [f64; 3],
    settings: ContactSettings,
) -> Result<FoundOnSupports, ContactFormFindingError> {
    let edges = bars(model);
    let length = edges
        .iter()
        .map(|&[a, b]| (Vector3::from(start[a]) - Vector3::from(start[b])).norm())
        .sum::<f64>()
        / edges.len().max(1) as f64;
    let (mut x, mut moves, mut deviations) = (start, Vec::new(), Vec::new());
    for k in 0..settings.max_steps {
        let (next, touching, deviation) = step(model, &x, prestress, &settings)
            .map_err(|reason| ContactFormFindingError::Analysis { step: k, reason })?;
        let moved = next
            .iter()
            .zip(&x)
            .map(|(p, q)| (Vector3::from(*p) - Vector3::from(*q)).norm())
            .fold(0.0, f64::max)
            / length;
        moves.push(moved);
        deviations.push(deviation);
        x = next;
        if deviation <= settings.tolerance {
            return Ok(FoundOnSupports {
                nodes: x,
                moves,
                deviations,
                touching,
            });
        }
    }
    Err(ContactFormFindingError::NotConverged {
        steps: settings.max_steps,
        deviation: deviations.last().copied().unwrap_or(f64::INFINITY),
    })
}
