//! Gathers the results of an analysis's converged state.

use nalgebra::Vector3;

use crate::mech::elements::triangle::ElementVector;
use crate::mech::results::GapResult;
use crate::mech::results::Results;
use crate::mech::results::summary::summarize;
use crate::mech::solve::analysis::Analysis;
use crate::mech::solve::assembly::{Dof, node_vector};

impl Analysis {
    /// The moment of each group's reaction about its hinge axis (see [`Results::moments`]).
    pub(crate) fn hinge_moments(&self) -> Vec<f64> {
        let u = &self.state.displacement;
        let mut moments = vec![0.0; self.model.groups.len()];
        for (i, d) in self.system.dofs.iter().enumerate() {
            let Dof::Prescribed { group, component } = *d else {
                continue;
            };
            let Some(h) = &self.model.groups[group].hinge else {
                continue;
            };
            let node = i / 3;
            let hinge = Vector3::from(h.point) + Vector3::from(self.state.boundary[group]);
            let arm = Vector3::from(self.model.nodes[node]) + node_vector(u, node) - hinge;
            let mut force = Vector3::zeros();
            force[component] = self.work.internal[i];
            moments[group] += arm.cross(&force).dot(&Vector3::from(h.axis).normalize());
        }
        moments
    }

    /// Gap results, group reactions and element stresses at the converged state.
    pub fn results(&mut self) -> Results {
        let (laws, history) = self.laws_and_history(&self.state);
        let u = std::mem::take(&mut self.state.displacement);
        let levels = self.state.loads.clone();
        self.assemble_at(&u, &laws, &history, &levels, None);
        self.state.displacement = u;
        // The law at the converged point with the updated history gives the same forces; the
        // status is the one found when the increment converged.
        let gaps = self
            .work
            .responses
            .iter()
            .zip(&self.state.status)
            .map(|(r, &status)| GapResult {
                slip_x: r.relative.x,
                slip_y: r.relative.y,
                normal_force: r.normal_force,
                friction_force: (r.force.x.powi(2) + r.force.y.powi(2)).sqrt(),
                friction: [r.force.x, r.force.y],
                status,
            })
            .collect();
        let mut reactions = vec![[0.0; 3]; self.model.groups.len()];
        let mut total_reaction = [0.0; 3];
        let mut node_reactions = vec![[0.0; 3]; self.model.nodes.len()];
        for (i, d) in self.system.dofs.iter().enumerate() {
            if let Dof::Prescribed { group, component } = d {
                reactions[*group][*component] += self.work.internal[i];
            }
            if !matches!(d, Dof::Free(_)) {
                total_reaction[i % 3] += self.work.internal[i];
                node_reactions[i / 3][i % 3] = self.work.internal[i];
            }
        }
        let moments = self.hinge_moments();
        let sets = self.model.support_sets();
        let mut support_reactions = vec![[0.0; 3]; sets.len()];
        for s in &self.model.supports {
            let Some(set) = s
                .name
                .as_ref()
                .and_then(|n| sets.iter().position(|m| m == n))
            else {
                continue;
            };
            for a in &s.fixed {
                let c = a.index();
                support_reactions[set][c] += self.work.internal[3 * s.node + c];
            }
        }
        let u = &self.state.displacement;
        let elements = self
            .system
            .triangles
            .iter()
            .map(|(nodes, tri)| {
                let ue = ElementVector::from_fn(|i, _| u[3 * nodes[i / 3] + i % 3]);
                tri.stress_state(&self.system.material, &ue)
            })
            .collect::<Vec<_>>();
        let outputs = &self.model.outputs;
        let points = outputs
            .points
            .iter()
            .map(|p| node_vector(u, p.node).into())
            .collect();
        let summaries = if outputs.element_sets.is_empty() {
            vec![]
        } else {
            let areas: Vec<f64> = self
                .system
                .triangles
                .iter()
                .map(|(_, t)| t.area())
                .collect();
            outputs
                .element_sets
                .iter()
                .map(|set| {
                    let triangles = self.model.selected_triangles(&set.elements);
                    summarize(&elements, &areas, &triangles)
                })
                .collect()
        };
        let cables = self.cables.results(u);
        Results {
            gaps,
            reactions,
            moments,
            cables,
            surface_contacts: self.surfaces.results(u, &self.state.contacts),
            support_reactions,
            total_reaction,
            node_reactions,
            elements,
            points,
            sets: summaries,
        }
    }
}
