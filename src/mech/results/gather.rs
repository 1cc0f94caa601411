//! Gathers the results of an analysis's converged state.

use nalgebra::Vector3;

use crate::mech::results::Results;
use crate::mech::solve::Analysis;
use crate::mech::solve::assembly::{Dof, node_vector};
use crate::mech::solve::contributions::Evaluation;

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
        let u = std::mem::take(&mut self.state.displacement);
        let levels = self.state.loads.clone();
        for c in self.parts.all_mut() {
            c.at_converged(&self.state);
        }
        self.assemble_at(&u, &levels, None);
        self.state.displacement = u;
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
        let points = self
            .model
            .outputs
            .points
            .iter()
            .map(|p| node_vector(u, p.node).into())
            .collect();
        let mut results = Results {
            gaps: vec![],
            reactions,
            moments,
            cables: vec![],
            surface_contacts: vec![],
            layer_contacts: vec![],
            chambers: vec![],
            orifices: vec![],
            support_reactions,
            total_reaction,
            node_reactions,
            elements: vec![],
            points,
            sets: vec![],
        };
        let at = Evaluation {
            system: &self.system,
            u,
            levels: &levels,
            iteration: None,
            matrix: self.settings.iteration_matrix,
        };
        for c in self.parts.all() {
            c.results(&at, &self.state, &self.model, &mut results);
        }
        results
    }
}
