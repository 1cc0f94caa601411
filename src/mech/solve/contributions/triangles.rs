//! The membrane triangles as a contribution: forces and tangents through the system's triangle
//! loop (serial or owner-computes threads, the elastic and the plastic film alike), the film's
//! stresses and set summaries as results.

use super::{Contribution, Evaluation};
use crate::mech::elements::material::Wrinkling;
use crate::mech::elements::plasticity::PlasticHistory;
use crate::mech::elements::triangle::{ElementStress, ElementVector};
use crate::mech::model::Model;
use crate::mech::results::Results;
use crate::mech::results::summary::summarize;
use crate::mech::solve::assembly::{System, node_dofs};
use crate::mech::solve::state::AnalysisState;

/// The membrane triangles (their geometry and material live in the [`System`]) and, for an
/// elasto-plastic film, the plastic history of each.
#[derive(Clone, Debug, Default)]
pub struct Triangles {
    /// Converged plastic history the increment starts from (empty: elastic film).
    start: Vec<PlasticHistory>,
    /// Plastic history of the last evaluation (the trial).
    trial: Vec<PlasticHistory>,
}

/// What a failed increment names (called once when it fails, never per iteration).
impl Triangles {
    /// Film elements whose tension-field state differs between `a` and `b` (none without
    /// wrinkling).
    pub fn flipping(&self, system: &System, a: &[f64], b: &[f64]) -> Vec<usize> {
        if system.material.wrinkling == Wrinkling::None {
            return Vec::new();
        }
        let state = |u: &[f64], e: usize| stress_state(system, &self.start, e, u).state;
        (0..system.triangles.len())
            .filter(|&e| state(a, e) != state(b, e))
            .collect()
    }

    /// Elements in compression at `u` for a film without wrinkling: the elastic film's stress,
    /// or the plastic film's from the increment's start history (a film elongated by plastic
    /// flow and then unloaded goes into compression while its Green strain is still positive).
    pub fn compressed(&self, system: &System, u: &[f64]) -> Vec<usize> {
        if system.material.wrinkling != Wrinkling::None {
            return Vec::new();
        }
        (0..system.triangles.len())
            .filter(|&e| stress_state(system, &self.start, e, u).principal[1] < 0.0)
            .collect()
    }
}

impl Contribution for Triangles {
    fn restore(&mut self, start: &AnalysisState) {
        self.start.clone_from(&start.plastic);
        self.trial.clone_from(&start.plastic);
    }

    fn add(&mut self, at: &Evaluation<'_>, residual: &mut [f64], values: Option<&mut [f64]>) {
        let material = &at.system.material;
        match material.plastic_film() {
            None => at.system.add_triangles(at.u, residual, values),
            Some(film) => {
                let start = &self.start;
                at.system.add_triangles_keeping(
                    at.u,
                    residual,
                    values,
                    |e, tri, ue, tangent| {
                        let (r, k, response) = tri.force_and_tangent_plastic(
                            &at.system.material,
                            &film,
                            &start[e],
                            ue,
                            tangent,
                        );
                        (r, k, response.history)
                    },
                    &mut self.trial,
                );
            }
        }
    }

    fn commit(&self, _start: &AnalysisState, state: &mut AnalysisState) {
        state.plastic.clone_from(&self.trial);
    }

    fn at_converged(&mut self, state: &AnalysisState) {
        self.restore(state);
    }

    /// Element stresses and the summaries of the model's element sets.
    fn results(
        &self,
        at: &Evaluation<'_>,
        state: &AnalysisState,
        model: &Model,
        out: &mut Results,
    ) {
        let (system, u) = (at.system, at.u);
        let elements = (0..system.triangles.len())
            .map(|e| stress_state(system, &state.plastic, e, u))
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

/// Stresses of triangle `e` at `u`, from its plastic `history` (indexed by triangle) when the
/// film is elasto-plastic.
fn stress_state(system: &System, history: &[PlasticHistory], e: usize, u: &[f64]) -> ElementStress {
    let (nodes, tri) = &system.triangles[e];
    let dofs = node_dofs(nodes);
    let ue = ElementVector::from_fn(|i, _| u[dofs[i]]);
    match system.material.plastic_film() {
        None => tri.stress_state(&system.material, &ue),
        Some(film) => tri.stress_state_plastic(&system.material, &film, &history[e], &ue),
    }
}
