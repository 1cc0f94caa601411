//! The membrane triangles as a contribution: forces and tangents through the system's triangle
//! loop (serial or owner-computes threads), the film's stresses and set summaries as results.

use super::{Contribution, Evaluation};
use crate::mech::elements::material::Wrinkling;
use crate::mech::elements::triangle::{ElementVector, MembraneTriangle};
use crate::mech::model::Model;
use crate::mech::results::Results;
use crate::mech::results::summary::summarize;
use crate::mech::solve::assembly::{System, node_dofs};
use crate::mech::solve::state::AnalysisState;

/// The membrane triangles (their geometry and material live in the [`System`]); no history yet.
#[derive(Clone, Debug)]
pub struct Triangles;

impl Contribution for Triangles {
    fn add(&mut self, at: &Evaluation<'_>, residual: &mut [f64], values: Option<&mut [f64]>) {
        at.system.add_triangles(at.u, residual, values);
    }

    /// Film elements whose tension-field state differs between `a` and `b` (none without
    /// wrinkling).
    fn flipping(&self, system: &System, a: &[f64], b: &[f64], out: &mut Vec<usize>) {
        if system.material.wrinkling == Wrinkling::None {
            return;
        }
        let state = |u: &[f64], nodes: &[usize; 3], tri: &MembraneTriangle| {
            let dofs = node_dofs(nodes);
            let ue = ElementVector::from_fn(|i, _| u[dofs[i]]);
            tri.stress_state(&system.material, &ue).state
        };
        out.extend(
            system
                .triangles
                .iter()
                .enumerate()
                .filter(|(_, (nodes, tri))| state(a, nodes, tri) != state(b, nodes, tri))
                .map(|(e, _)| e),
        );
    }

    /// Element stresses and the summaries of the model's element sets.
    fn results(
        &self,
        at: &Evaluation<'_>,
        _state: &AnalysisState,
        model: &Model,
        out: &mut Results,
    ) {
        let (system, u) = (at.system, at.u);
        let elements = system
            .triangles
            .iter()
            .map(|(nodes, tri)| {
                let ue = ElementVector::from_fn(|i, _| u[3 * nodes[i / 3] + i % 3]);
                tri.stress_state(&system.material, &ue)
            })
            .collect::<Vec<_>>();
        let outputs = &model.outputs;
        out.sets = if outputs.element_sets.is_empty() {
            vec![]
        } else {
            let areas: Vec<f64> = system.triangles.iter().map(|(_, t)| t.area()).collect();
            outputs
                .element_sets
                .iter()
                .map(|set| {
                    let triangles = model.selected_triangles(&set.elements);
                    summarize(&elements, &areas, &triangles)
                })
                .collect()
        };
        out.elements = elements;
    }
}
