//! Node-to-surface contacts on curved supports as a contribution: the history (anchor, angle,
//! origin, status, μ) of each contact at the increment's start, the responses of the last
//! evaluation, and the histories committed from them.

use super::{Contribution, Evaluation, LiftOff, StatusChanges};
use crate::mech::elements::curved_contact::{ContactHistory, ContactResponse, SurfaceContacts};
use crate::mech::elements::gap::{FrictionLaw, GapStatus};
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
    /// The statuses imposed on the contacts during an active-set iteration (`newton.rs`).
    pub frozen: Option<Vec<GapStatus>>,
    /// Whether the next increments hold the statuses fixed (active-set iteration, `newton.rs`).
    pub active_set: bool,
    /// The width (m) over which the contact law's corners are rounded in the smoothing
    /// homotopy (`curved_contact::smoothing`); 0: the law itself.
    pub smoothing: f64,
    /// Each contact's name in messages: `<support>.<k>` (k-th node of the support).
    pub names: Vec<String>,
    /// The law's status changes over the Newton iterations.
    changes: StatusChanges,
    /// Sliding-direction contacts lifting off with more than `μN` across ([`LiftOff`]).
    lift: LiftOff,
}

impl CurvedContacts {
    /// The contacts of `model`, starting from their reference histories.
    pub fn new(model: &Model) -> Self {
        let contacts = SurfaceContacts::new(model);
        Self {
            start: contacts.initial_histories(model),
            contacts,
            responses: Vec::new(),
            frozen: None,
            active_set: false,
            smoothing: 0.0,
            names: model
                .curved_supports
                .iter()
                .flat_map(|s| (0..s.nodes.len()).map(move |k| format!("{}.{k}", s.name)))
                .collect(),
            changes: StatusChanges::default(),
            lift: LiftOff::default(),
        }
    }

    /// The histories of the reference configuration (an analysis's first state).
    pub fn initial_histories(&self, model: &Model) -> Vec<ContactHistory> {
        self.contacts.initial_histories(model)
    }
}

impl CurvedContacts {
    /// The law's own status of each contact at the last evaluation (whatever was imposed).
    pub fn natural(&self) -> Vec<GapStatus> {
        self.responses.iter().map(|r| r.natural).collect()
    }

    /// The first width (m) of the smoothing homotopy from the converged `u`, `histories`: the
    /// larger of [`Self::SMOOTHING_START`] times the largest penetration of a closed contact
    /// (the scale of the penalty's forces, `λN/k_n`) and [`Self::SMOOTHING_FLOOR`] times the
    /// largest tube radius.
    pub fn smoothing_width(&self, u: &[f64], histories: &[ContactHistory]) -> f64 {
        let depth = self.contacts.largest_penetration(u, histories);
        let radius = self
            .contacts
            .contacts
            .iter()
            .map(|c| c.tube_radius())
            .fold(0.0, f64::max);
        (Self::SMOOTHING_START * depth).max(Self::SMOOTHING_FLOOR * radius)
    }

    /// The first smoothing width in penetrations.
    const SMOOTHING_START: f64 = 4.0;
    /// The least first smoothing width in tube radii.
    const SMOOTHING_FLOOR: f64 = 1e-3;

    /// Whether the model has any curved-support contact.
    pub fn is_empty(&self) -> bool {
        self.contacts.contacts.is_empty()
    }
}

impl Contribution for CurvedContacts {
    fn restore(&mut self, start: &AnalysisState) {
        self.start.clone_from(&start.contacts);
        self.changes.reset(start.contacts.iter().map(|h| h.status));
        self.lift.reset(self.start.len());
    }

    fn note_iteration(&mut self, iteration: usize) {
        self.changes
            .note(iteration, self.responses.iter().map(|r| r.natural));
    }

    fn chattering(&self, since: usize, out: &mut Vec<String>) {
        self.changes.changed_since(since, &self.names, out);
    }

    fn lifting_off(&self, out: &mut Vec<String>) {
        self.lift.lifted(&self.names, out);
    }

    fn add(&mut self, at: &Evaluation<'_>, residual: &mut [f64], values: Option<&mut [f64]>) {
        self.contacts.add_to(
            at.system,
            at.u,
            &self.start,
            self.frozen.as_deref(),
            self.smoothing,
            residual,
            values,
            &mut self.responses,
        );
        for (k, ((c, h), r)) in self
            .contacts
            .contacts
            .iter()
            .zip(&self.start)
            .zip(&self.responses)
            .enumerate()
        {
            if c.law() == FrictionLaw::SlidingDirection {
                let open = r.status == GapStatus::Open;
                self.lift
                    .note(k, open, r.friction.y, h.friction * r.normal_force);
            }
        }
    }

    fn release_lift_off(
        &mut self,
        names: &[String],
        start: &mut AnalysisState,
        out: &mut Vec<f64>,
    ) {
        for (k, name) in self.names.iter().enumerate() {
            let h = &mut start.contacts[k];
            if names.contains(name) && !h.lands {
                h.lands = true;
                out.push(self.lift.hold(k));
            }
        }
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
