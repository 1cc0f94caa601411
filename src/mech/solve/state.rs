//! The converged state of an analysis (what an FMU state serializes) and the boundary motion
//! of a point of a step.

use crate::mech::elements::curved_contact::ContactHistory;
use crate::mech::elements::gap::GapStatus;
use crate::mech::elements::load::LoadLevels;
use crate::mech::elements::plasticity::PlasticHistory;
use serde::{Deserialize, Serialize};

/// Where the boundary groups are at one point of a step: translation and hinge angle of each.
#[derive(Clone, Debug)]
pub(crate) struct GroupMotion {
    pub(crate) translation: Vec<[f64; 3]>,
    pub(crate) angles: Vec<f64>,
}

/// The converged state of an analysis: everything needed to continue it exactly.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct AnalysisState {
    /// Nodal displacements, three per node (m).
    pub displacement: Vec<f64>,
    /// Slip history `s_p` of each gap (local x, y) (m).
    pub plastic_slip: Vec<[f64; 2]>,
    /// Current imposed displacement of each boundary group (m).
    pub boundary: Vec<[f64; 3]>,
    /// Current hinge angle of each boundary group (rad; 0 for a group without a hinge).
    #[serde(default)]
    pub angles: Vec<f64>,
    /// Current level of each load (pressures, nodal forces, gravity).
    pub loads: LoadLevels,
    /// Friction coefficient of each gap.
    pub friction: Vec<f64>,
    /// Status of each gap at convergence.
    pub status: Vec<GapStatus>,
    /// History of each curved-support contact ([`crate::mech::elements::curved_contact`]): anchor, angle, status, μ.
    #[serde(default)]
    pub contacts: Vec<ContactHistory>,
    /// Displacement change of the last converged increment (empty before the first): the
    /// predictor of the next increment when the boundary keeps moving the same way.
    #[serde(default)]
    pub last_increment: Vec<f64>,
    /// Change of the load levels over the last converged increment ([`LoadLevels::path`]
    /// order; empty before the first): the predictor extrapolates a load path that keeps
    /// its direction like a boundary motion.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub last_load_increment: Vec<f64>,
    /// Plastic history of each triangle of an elasto-plastic film, committed only when an
    /// increment converges (empty for the elastic film).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub plastic: Vec<PlasticHistory>,
    /// History of each layer-contact slave node
    /// ([`crate::mech::elements::layer_contact`]): anchor, triangle, status, slip.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub layer_contacts: Vec<crate::mech::elements::layer_contact::LayerContactHistory>,
    /// The gas of each chamber ([`crate::mech::solve::contributions::ChamberState`]).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub chambers: Vec<crate::mech::solve::contributions::ChamberState>,
    /// The mass flow (kg/s, from → to) through each orifice over the last increment.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub orifices: Vec<f64>,
    /// The air mass (kg, from → to) each orifice has passed since the analysis started: a
    /// step's average flow is its change over the step (empty in a state written before it was
    /// kept: read as zeros).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub orifice_moved: Vec<f64>,
}

impl AnalysisState {
    /// Whether a path-dependent history differs from `start`'s: a gap's slip, a curved-support
    /// contact's (anchor, angle, status), a layer contact's or an element's plastic history.
    pub fn history_changed_from(&self, start: &AnalysisState) -> bool {
        self.plastic_slip != start.plastic_slip
            || self.contacts != start.contacts
            || self.plastic != start.plastic
            || self.layer_contacts != start.layer_contacts
    }

    /// Whether every number of the state is finite.
    pub fn is_finite(&self) -> bool {
        self.displacement
            .iter()
            .chain(self.plastic_slip.iter().flatten())
            .chain(self.boundary.iter().flatten())
            .chain(&self.angles)
            .chain(&self.friction)
            .chain(&self.last_increment)
            .chain(&self.last_load_increment)
            .chain(
                self.plastic
                    .iter()
                    .flat_map(|h| {
                        let [a, b, c] = h.inverse_plastic_metric;
                        [
                            a,
                            b,
                            c,
                            h.equivalent_plastic_strain,
                            h.unloaded_thickness_strain,
                        ]
                    })
                    .collect::<Vec<_>>()
                    .iter(),
            )
            .all(|v| v.is_finite())
            && self.contacts.iter().all(|c| {
                [c.anchor[0], c.anchor[1], c.angle, c.origin, c.friction]
                    .iter()
                    .all(|v| v.is_finite())
            })
            && self.layer_contacts.iter().all(|c| {
                [c.anchor[0], c.anchor[1], c.slip]
                    .iter()
                    .all(|v| v.is_finite())
            })
            && self.loads.is_finite()
    }
}
