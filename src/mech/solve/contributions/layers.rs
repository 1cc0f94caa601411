//! Film-to-film contacts between layers as a contribution: the contact search at every
//! evaluation (each slave node keeps its history's triangle while it projects in it, else takes
//! the nearest candidate), the anchors carried from the
//! increment's start (moved to the new triangle when the node has slid onto another one), the
//! pairs' responses and the histories committed from them.

use nalgebra::{Vector2, Vector3};

use super::{Contribution, Evaluation};
use crate::mech::elements::gap::GapStatus;
use crate::mech::elements::layer_contact::{
    EXTEND, LayerContactHistory, LayerContactResult, PairLaw, PairResponse, SlaveNode,
    closest_point, inside, plane_coordinates, respond,
};
use crate::mech::model::Model;
use crate::mech::results::Results;
use crate::mech::solve::assembly::System;
use crate::mech::solve::state::AnalysisState;

/// Each slave node's response at the last evaluation.
#[derive(Clone, Copy, Debug)]
struct NodeResponse {
    /// The candidate (index in the node's list) it was projected on, if any.
    candidate: Option<usize>,
    /// Its triangle (model index).
    triangle: Option<usize>,
    response: PairResponse,
}

/// The layer contacts with their trial history.
#[derive(Clone, Debug, Default)]
pub struct LayerContacts {
    /// `(k_n, k_s, μ, search distance)` of each layer contact.
    laws: Vec<(f64, f64, f64, f64)>,
    /// Each slave node's name in messages: `<contact>.<node>` or `<contact>.back.<node>`.
    names: Vec<String>,
    /// Histories at the start of the increment.
    start: Vec<LayerContactHistory>,
    /// Displacements at the start of the increment (where anchors are moved between triangles).
    start_u: Vec<f64>,
    /// Responses at the last evaluation.
    responses: Vec<NodeResponse>,
    /// Statuses imposed until the next restore ([`Contribution::hold`]; empty: none).
    held: Vec<Option<GapStatus>>,
    /// Reference node positions.
    reference: Vec<Vector3<f64>>,
}

impl LayerContacts {
    /// The layer contacts of `model` on `system` (whose setup holds the slave nodes).
    pub fn new(model: &Model, system: &System) -> Self {
        let names = system
            .layer_contacts
            .slaves
            .iter()
            .map(|s| {
                let name = &model.layer_contacts[s.contact].name;
                let back = if s.reverse { ".back" } else { "" };
                format!("{name}{back}.{}", s.node)
            })
            .collect();
        Self {
            laws: model
                .layer_contacts
                .iter()
                .map(|c| {
                    (
                        c.normal_stiffness,
                        c.tangential_stiffness,
                        c.friction,
                        c.search_distance,
                    )
                })
                .collect(),
            names,
            reference: model.nodes.iter().map(|&p| Vector3::from(p)).collect(),
            ..Self::default()
        }
    }

    fn position(&self, u: &[f64], v: usize) -> Vector3<f64> {
        self.reference[v] + Vector3::new(u[3 * v], u[3 * v + 1], u[3 * v + 2])
    }

    fn corners(&self, system: &System, u: &[f64], t: usize) -> [Vector3<f64>; 3] {
        system.triangles[t].0.map(|v| self.position(u, v))
    }

    /// The candidate the slave at `u` is projected on and the node's `ξ` on it: the triangle
    /// `keep` (the history's) while the projection stays in it (within [`EXTEND`]), else the
    /// nearest; None where the projection falls outside that one by more than [`EXTEND`].
    /// Keeping the triangle keeps the residual smooth within an increment where a node sits
    /// over an edge or a vertex of a curved master, whose triangles' normals differ: choosing
    /// the nearest afresh there flips between them at round-off, and Newton stalls.
    fn nearest(
        &self,
        system: &System,
        slave: &SlaveNode,
        u: &[f64],
        keep: Option<usize>,
    ) -> Option<(usize, Vector2<f64>)> {
        let x = self.position(u, slave.node);
        let kept = keep.and_then(|t| slave.candidates.iter().position(|c| c.triangle == t));
        if let Some(k) = kept {
            let t = self.corners(system, u, slave.candidates[k].triangle);
            let xi = plane_coordinates(&x, &t);
            if inside(&xi) >= -EXTEND {
                return Some((k, xi));
            }
        }
        let (k, (_, xi)) = slave
            .candidates
            .iter()
            .map(|c| closest_point(&x, &self.corners(system, u, c.triangle)))
            .enumerate()
            .min_by(|a, b| a.1.0.total_cmp(&b.1.0))?;
        (inside(&xi) >= -EXTEND).then_some((k, xi))
    }

    /// The histories of the reference configuration: each node anchored where it projects.
    pub fn initial_histories(&self, system: &System) -> Vec<LayerContactHistory> {
        let u = vec![0.0; self.reference.len() * 3];
        system
            .layer_contacts
            .slaves
            .iter()
            .map(|s| match self.nearest(system, s, &u, None) {
                Some((k, xi)) => LayerContactHistory {
                    triangle: Some(s.candidates[k].triangle),
                    anchor: xi.into(),
                    ..LayerContactHistory::default()
                },
                None => LayerContactHistory::default(),
            })
            .collect()
    }

    /// The anchor of history `h` in triangle `t`: its own, or the anchor's point at the
    /// increment's start expressed in `t` there (the node slid onto `t`); the node's `xi` where
    /// it has none.
    fn anchor_in(
        &self,
        system: &System,
        h: &LayerContactHistory,
        t: usize,
        xi: Vector2<f64>,
    ) -> Vector2<f64> {
        match h.triangle {
            Some(own) if own == t => Vector2::from(h.anchor),
            Some(own) => {
                let x = self.corners(system, &self.start_u, own);
                let point = x[0] + (x[1] - x[0]) * h.anchor[0] + (x[2] - x[0]) * h.anchor[1];
                plane_coordinates(&point, &self.corners(system, &self.start_u, t))
            }
            None => xi,
        }
    }

    /// The response of slave `k` at `u` (open with no triangle where it projects on none).
    fn respond_node(&self, system: &System, k: usize, u: &[f64]) -> NodeResponse {
        let slave = &system.layer_contacts.slaves[k];
        let h = &self.start[k];
        let Some((c, xi)) = self.nearest(system, slave, u, h.triangle) else {
            // Nothing within reach: open, its gap as large as the search's reach.
            return NodeResponse {
                candidate: None,
                triangle: None,
                response: PairResponse::open(self.laws[slave.contact].3, Vector2::zeros()),
            };
        };
        let candidate = &slave.candidates[c];
        let (kn, ks, mu, _) = self.laws[slave.contact];
        let law = PairLaw {
            kn,
            ks,
            mu,
            sign: candidate.sign,
        };
        let t = self.corners(system, u, candidate.triangle);
        let x = [self.position(u, slave.node), t[0], t[1], t[2]];
        let anchor = self.anchor_in(system, h, candidate.triangle, xi);
        let held = self.held.get(k).copied().flatten();
        NodeResponse {
            candidate: Some(c),
            triangle: Some(candidate.triangle),
            response: respond(&x, anchor, &law, held),
        }
    }
}

impl Contribution for LayerContacts {
    fn restore(&mut self, start: &AnalysisState) {
        self.start.clone_from(&start.layer_contacts);
        self.start_u.clone_from(&start.displacement);
        self.held.clear();
    }

    fn hold(&mut self, held: &[Option<GapStatus>]) {
        self.held = held.to_vec();
    }

    fn status_names(&self, out: &mut Vec<String>) {
        out.extend(self.names.iter().cloned());
    }

    fn add(&mut self, at: &Evaluation<'_>, residual: &mut [f64], mut values: Option<&mut [f64]>) {
        let system = at.system;
        let slaves = &system.layer_contacts.slaves;
        if self.start.len() != slaves.len() {
            self.start = self.initial_histories(system);
            self.start_u = vec![0.0; at.u.len()];
        }
        self.responses.clear();
        for (k, slave) in slaves.iter().enumerate() {
            let r = self.respond_node(system, k, at.u);
            self.responses.push(r);
            let Some(c) = r.candidate else { continue };
            let candidate = &slave.candidates[c];
            let tri = system.triangles[candidate.triangle].0;
            for (i, v) in [slave.node, tri[0], tri[1], tri[2]].into_iter().enumerate() {
                for j in 0..3 {
                    residual[3 * v + j] += r.response.residual[3 * i + j];
                }
            }
            if let Some(values) = values.as_deref_mut()
                && r.response.status != GapStatus::Open
            {
                system.add_pair_matrix(candidate.block, &r.response.tangent, values);
            }
        }
    }

    fn commit(&self, start: &AnalysisState, state: &mut AnalysisState) {
        state.layer_contacts = self
            .responses
            .iter()
            .zip(&start.layer_contacts)
            .map(|(r, h)| LayerContactHistory {
                triangle: r.triangle,
                anchor: r.response.next_anchor.into(),
                status: r.response.status,
                slip: h.slip + r.response.slip,
            })
            .collect();
    }

    fn statuses(&self, out: &mut Vec<GapStatus>) {
        out.extend(self.responses.iter().map(|r| r.response.status));
    }

    fn gaps(&self, out: &mut Vec<f64>) {
        out.extend(self.responses.iter().map(|r| r.response.gap));
    }

    fn results(
        &self,
        at: &Evaluation<'_>,
        state: &AnalysisState,
        _model: &Model,
        out: &mut Results,
    ) {
        let mut me = self.clone();
        me.start.clone_from(&state.layer_contacts);
        me.start_u.clone_from(&state.displacement);
        me.held.clear();
        let slaves = &at.system.layer_contacts.slaves;
        out.layer_contacts = (0..slaves.len())
            .map(|k| {
                let r = me.respond_node(at.system, k, at.u);
                let s = &slaves[k];
                let h = &state.layer_contacts[k];
                LayerContactResult {
                    name: me.names[k].clone(),
                    contact: s.contact,
                    node: s.node,
                    triangle: r.triangle,
                    gap: r.response.gap,
                    normal_force: r.response.normal_force,
                    pressure: r.response.normal_force / s.area.max(f64::MIN_POSITIVE),
                    friction: r.response.friction.into(),
                    slip: h.slip,
                    status: h.status,
                }
            })
            .collect();
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mech::elements::gap::IterationMatrix;
    use crate::mech::elements::layer_contact::{LayerContactSpec, LayerSurface, Side};
    use crate::mech::elements::load::LoadLevels;
    use crate::mech::solve::assembly::Dof;

    /// A unit square of two master triangles and one slave triangle over it, pressed in.
    fn model() -> Model {
        let json = serde_json::json!({
            "name": "Touch",
            "nodes": [[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0],
                      [0.3, 0.2, 0.01], [0.7, 0.3, 0.01], [0.4, 0.7, 0.01]],
            "triangles": [[0, 1, 2], [0, 2, 3], [4, 5, 6]],
            "material": crate::specimens::ParallelArch::default().material,
            "layer_contacts": [{
                "name": "T", "slave": [2], "master": [0, 1], "normal_stiffness": 1e5,
                "tangential_stiffness": 1e4, "friction": 0.3, "search_distance": 1.0
            }]
        });
        let model: Model = serde_json::from_value(json).unwrap();
        assert_eq!(model.layer_contacts[0].side, Side::Front);
        assert_eq!(
            model.layer_contacts[0].master,
            LayerSurface::Triangles(vec![0, 1])
        );
        let _ = LayerContactSpec::triangles(&model, &model.layer_contacts[0].slave).unwrap();
        model
    }

    /// Residual and matrix (dense, free DOFs) of the layer contacts at `u`.
    fn assemble(lc: &mut LayerContacts, system: &System, u: &[f64]) -> (Vec<f64>, Vec<f64>) {
        let levels = LoadLevels::default();
        let at = Evaluation {
            system,
            u,
            levels: &levels,
            iteration: Some(1),
            matrix: IterationMatrix::Consistent,
        };
        let mut residual = vec![0.0; u.len()];
        let mut values = vec![0.0; system.nonzeros()];
        lc.add(&at, &mut residual, Some(&mut values));
        let n = system.free_count;
        let mut dense = vec![0.0; n * n];
        let pattern = system.pattern();
        let (col_ptr, row_idx) = (pattern.col_ptr(), pattern.row_idx());
        for j in 0..n {
            for s in col_ptr[j]..col_ptr[j + 1] {
                dense[row_idx[s] * n + j] += values[s];
            }
        }
        (residual, dense)
    }

    #[test]
    fn assembled_tangent_matches_central_differences_across_triangles_and_statuses() {
        let model = model();
        let system = System::new(&model, false).unwrap();
        let mut lc = LayerContacts::new(&model, &system);
        // Slave nodes pressed 10 mm in; the master's far corner lifted (a fold between its
        // triangles). Node 4 sticks 5 mm from its anchor, node 5 slides 0.1 m from its own, and
        // node 6 slid from triangle 0 onto triangle 1 (its anchor moved across the fold).
        let mut u = vec![0.0; 21];
        u[3 * 2 + 2] = 0.003;
        for v in 4..7 {
            u[3 * v + 2] = -0.02;
        }
        // Anchors in triangle 0 (a1 = x̂, a2 = x̂ + ŷ): ξ = (px − py, py).
        let anchor = |px: f64, py: f64| [px - py, py];
        lc.start = vec![
            LayerContactHistory {
                triangle: Some(0),
                anchor: anchor(0.305, 0.2),
                status: GapStatus::Stick,
                slip: 0.0,
            },
            LayerContactHistory {
                triangle: Some(0),
                anchor: anchor(0.6, 0.3),
                status: GapStatus::Stick,
                slip: 0.0,
            },
            LayerContactHistory {
                triangle: Some(0),
                anchor: anchor(0.42, 0.69),
                status: GapStatus::Stick,
                slip: 0.0,
            },
        ];
        lc.start_u = vec![0.0; 21];
        let (_, k) = assemble(&mut lc, &system, &u);
        let statuses: Vec<_> = lc.responses.iter().map(|r| r.response.status).collect();
        assert_eq!(
            statuses,
            [GapStatus::Stick, GapStatus::Slip, GapStatus::Stick]
        );
        assert_eq!(lc.responses[2].triangle, Some(1));
        let n = system.free_count;
        let h = 1e-7;
        let mut worst: f64 = 0.0;
        for (gj, dof) in system.dofs.iter().enumerate() {
            let Dof::Free(j) = *dof else { continue };
            let (mut plus, mut minus) = (u.clone(), u.clone());
            plus[gj] += h;
            minus[gj] -= h;
            let (rp, _) = assemble(&mut lc, &system, &plus);
            let (rm, _) = assemble(&mut lc, &system, &minus);
            for (gi, row) in system.dofs.iter().enumerate() {
                let Dof::Free(i) = *row else { continue };
                let fd = (rp[gi] - rm[gi]) / (2.0 * h);
                worst = worst.max((fd - k[i * n + j]).abs());
            }
        }
        let scale = k.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        assert!(worst < 1e-6 * scale, "worst {worst:e} of {scale:e}");
    }
}
