//! The results of a converged state: gaps, reactions, hinge moments, cables, curved contacts,
//! element stresses, output points and set summaries.

use crate::mech::elements::cable::CableResult;
use crate::mech::elements::curved_contact::SurfaceContactResult;
use crate::mech::elements::gap::GapStatus;
use crate::mech::elements::triangle::ElementStress;
use crate::mech::model::Model;
use crate::mech::results::summary::FieldSummary;
use nalgebra::Vector3;
use serde::{Deserialize, Serialize};

/// Converged results of one gap.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct GapResult {
    /// Tangential displacement of A relative to B since the start, local x (m).
    pub slip_x: f64,
    /// … local y (m).
    pub slip_y: f64,
    /// Normal contact force `N ≥ 0` (N).
    pub normal_force: f64,
    /// Friction force magnitude `|t|` (N): `≤ μN` for the isotropic law; for the sliding-direction law only
    /// `|t_x| ≤ μN`, the elastic `t_y` is not bounded.
    pub friction_force: f64,
    /// Friction force components (local x, y) of the gap's internal force on node A (eq. 2.8):
    /// the force the film exerts on the support; the support acts on the film with the opposite (N).
    pub friction: [f64; 2],
    /// Status at convergence.
    pub status: GapStatus,
}

/// Results of the current converged state.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Results {
    /// One per gap.
    pub gaps: Vec<GapResult>,
    /// Total reaction of each boundary group (N), global axes: the force the group applies to the
    /// film, `Σ (f_int − f_ext)` over its DOFs (it balances the loads on its nodes too).
    pub reactions: Vec<[f64; 3]>,
    /// Moment of each boundary group's reaction about its hinge axis, through the hinge's
    /// current position (N·m, right-hand rule about the axis): the torque the drive of a
    /// rotating frame side applies to the film; 0 for a group without a hinge.
    pub moments: Vec<f64>,
    /// Largest axial force and slack segments of each cable.
    pub cables: Vec<CableResult>,
    /// Slip along the support, forces and status of each curved-support contact (model order:
    /// supports, then their nodes).
    pub surface_contacts: Vec<SurfaceContactResult>,
    /// Gap, contact pressure, friction and slip of each layer-contact slave node (model order:
    /// contacts, the forward pass's nodes, then the reverse pass's).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub layer_contacts: Vec<crate::mech::elements::layer_contact::LayerContactResult>,
    /// Pressure and volume of each gas chamber, model order.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub chambers: Vec<crate::mech::solve::contributions::ChamberResult>,
    /// Mass flow through each orifice over the last increment, model order.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub orifices: Vec<crate::mech::solve::contributions::OrificeResult>,
    /// Total reaction of each named support set (N), global axes, over its fixed components.
    pub support_reactions: Vec<[f64; 3]>,
    /// Sum of all restraint forces on the film (N): supports, symmetry planes and groups (the
    /// gaps' forces on their support points are reported per gap, not here).
    pub total_reaction: [f64; 3],
    /// Restraint force on each node (N), global axes: `f_int − f_ext` at its supported,
    /// symmetry-fixed and prescribed components, 0 at its free ones (the nodal reactions that
    /// [`crate::mech::results::lines`] spreads along groups and support sets).
    #[serde(default)]
    pub node_reactions: Vec<[f64; 3]>,
    /// Stress state of each triangle.
    pub elements: Vec<ElementStress>,
    /// Displacement of each output point of the model (m).
    pub points: Vec<[f64; 3]>,
    /// Field summary of each element set of the model.
    pub sets: Vec<FieldSummary>,
}

/// The plastic state of an elasto-plastic film over all its triangles.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PlasticSummary {
    /// Triangles with a positive equivalent plastic strain.
    pub yielded_elements: usize,
    /// Largest equivalent plastic strain `ε̄p`.
    pub max_plastic_strain: f64,
    /// Smallest current film thickness (m).
    pub min_thickness: f64,
}

impl Results {
    /// The film's plastic summary; None for the elastic film (no triangle has a plastic state).
    pub fn plastic_summary(&self) -> Option<PlasticSummary> {
        let mut plastic = self.elements.iter().filter_map(|e| e.plastic).peekable();
        plastic.peek()?;
        Some(plastic.fold(
            PlasticSummary {
                yielded_elements: 0,
                max_plastic_strain: 0.0,
                min_thickness: f64::INFINITY,
            },
            |s, p| PlasticSummary {
                yielded_elements: s.yielded_elements
                    + usize::from(p.equivalent_plastic_strain > 0.0),
                max_plastic_strain: nan_max(s.max_plastic_strain, p.equivalent_plastic_strain),
                min_thickness: -nan_max(-s.min_thickness, -p.thickness),
            },
        ))
    }

    /// The force of every contact on the film, summed in global axes (N): each gap's
    /// `Rᵀ(−t_x, −t_y, N)` (eq. 2.8, the gap's force on node A with the paper's sign reversed)
    /// and each curved-support contact's force.
    pub fn contact_force(&self, model: &Model) -> Vector3<f64> {
        let gaps = model.gaps.iter().zip(&self.gaps).map(|(g, r)| {
            let local = Vector3::new(-r.friction[0], -r.friction[1], r.normal_force);
            g.frame.rotation().transpose() * local
        });
        let curved = self.surface_contacts.iter().map(|c| Vector3::from(c.force));
        gaps.chain(curved).sum()
    }

    /// The force of everything that holds the film, summed (N): the reactions at its own
    /// constrained nodes (supports, symmetry planes, groups) and [`Self::contact_force`]; the
    /// contacts' share of it is what they carry of the film's load.
    pub fn film_support_force(&self, model: &Model) -> Vector3<f64> {
        let mut on_film = vec![false; model.nodes.len()];
        for t in &model.triangles {
            for &v in t {
                on_film[v] = true;
            }
        }
        let held: Vector3<f64> = self
            .node_reactions
            .iter()
            .zip(&on_film)
            .filter(|(_, on)| **on)
            .map(|(r, _)| Vector3::from(*r))
            .sum();
        held + self.contact_force(model)
    }

    /// Range `(min, max)` of the element von Mises stress (Pa).
    pub fn von_mises_range(&self) -> (f64, f64) {
        self.elements
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), e| {
                if e.von_mises.is_nan() || lo.is_nan() {
                    (f64::NAN, f64::NAN)
                } else {
                    (lo.min(e.von_mises), hi.max(e.von_mises))
                }
            })
    }
}

/// `a.max(b)`, NaN when either is (so that the finiteness check refuses a NaN field).
fn nan_max(a: f64, b: f64) -> f64 {
    if a.is_nan() || b.is_nan() {
        f64::NAN
    } else {
        a.max(b)
    }
}
