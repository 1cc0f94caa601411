//! Node-to-surface contacts on curved supports as a contribution: the history (anchor, angle,
//! origin, status, μ) of each contact at the increment's start, the responses of the last
//! evaluation, and the histories committed from them.

use super::{Contribution, Evaluation};
use crate::mech::elements::curved_contact::{ContactHistory, ContactResponse, SurfaceContacts};
use crate::mech::elements::gap::GapStatus;
use crate::mech::model::Model;
use crate::mech::results::Results;
use crate::mech::solve::assembly::{Dof, System};
use crate::mech::solve::state::AnalysisState;

/// The curved-support contacts with their trial history.
#[derive(Clone, Debug)]
pub struct CurvedContacts {
    /// The contacts.
    pub contacts: SurfaceContacts,
    /// Histories at the start of the increment (the trial's starting point).
    start: Vec<ContactHistory>,
    /// Responses at the last evaluation.
    responses: Vec<ContactResponse>,
    /// Each contact's name in messages: `<support>.<k>` (k-th node of the support).
    pub names: Vec<String>,
    /// Statuses imposed until the next restore ([`Contribution::hold`]; empty: none).
    held: Vec<Option<GapStatus>>,
}

impl CurvedContacts {
    /// The contacts of `model`, starting from their reference histories.
    pub fn new(model: &Model) -> Self {
        let contacts = SurfaceContacts::new(model);
        Self {
            start: contacts.initial_histories(model),
            contacts,
            responses: Vec::new(),
            held: Vec::new(),
            names: model
                .curved_supports
                .iter()
                .flat_map(|s| (0..s.nodes.len()).map(move |k| format!("{}.{k}", s.name)))
                .collect(),
        }
    }

    /// The histories of the reference configuration (an analysis's first state).
    pub fn initial_histories(&self, model: &Model) -> Vec<ContactHistory> {
        self.contacts.initial_histories(model)
    }
}

impl CurvedContacts {
    /// Whether the model has any curved-support contact.
    pub fn is_empty(&self) -> bool {
        self.contacts.contacts.is_empty()
    }
}

impl Contribution for CurvedContacts {
    fn restore(&mut self, start: &AnalysisState) {
        self.start.clone_from(&start.contacts);
        self.held.clear();
    }

    fn hold(&mut self, held: &[Option<GapStatus>]) {
        self.held = held.to_vec();
    }

    fn status_names(&self, out: &mut Vec<String>) {
        out.extend(self.names.iter().cloned());
    }

    fn add(&mut self, at: &Evaluation<'_>, residual: &mut [f64], values: Option<&mut [f64]>) {
        self.contacts.add_to(
            at.system,
            at.u,
            (&self.start, &self.held),
            residual,
            values,
            &mut self.responses,
        );
    }

    fn commit(&self, start: &AnalysisState, state: &mut AnalysisState) {
        state.contacts = SurfaceContacts::commit(&self.responses, &start.contacts);
    }

    fn correct_prediction(&self, system: &System, start: &AnalysisState, u: &mut [f64]) {
        let free = |node: usize| (0..3).all(|k| matches!(system.dofs[3 * node + k], Dof::Free(_)));
        self.contacts
            .keep_gaps(&start.displacement, &start.contacts, free, u);
    }

    // `at_converged` keeps the histories of the last increment's start: the converged
    // responses are those of that trial (the reactions at the results include their forces).

    fn statuses(&self, out: &mut Vec<GapStatus>) {
        out.extend(self.responses.iter().map(|r| r.status));
    }

    fn gaps(&self, out: &mut Vec<f64>) {
        out.extend(self.responses.iter().map(|r| r.gap));
    }

    fn results(
        &self,
        at: &Evaluation<'_>,
        state: &AnalysisState,
        _model: &Model,
        out: &mut Results,
    ) {
        out.surface_contacts = self.contacts.results(at.u, &state.contacts);
    }
}
