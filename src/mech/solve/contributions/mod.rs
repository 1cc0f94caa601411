//! The contract of everything that adds force and stiffness to the system, and the list of
//! them in assembly order. The Newton loop, the line search and the results see only
//! [`Contribution`]s: they never match on kinds.
//!
//! A contribution adds its residual `f_int − f_ext` and, when asked, its part of the Newton
//! matrix through the system's precomputed slots ([`System::add_element_matrix`]). Its history
//! (a gap's slip, a curved contact's anchor; a plastic material's internal variables) follows
//! the trial/commit/restore cycle of an increment:
//!
//! * [`Contribution::restore`]: the trial history is reset to the converged state `start` at
//!   the start of every increment, so a cut-back or an enlarged retry starts from the same
//!   history, and a restored FMU state continues from its own;
//! * [`Contribution::add`]: evaluated (and trial history updated) at each iterate;
//! * [`Contribution::commit`]: written into the next converged [`AnalysisState`] only when
//!   the increment converges (a failed increment commits nothing).
//!
//! A material with history variables plugs in here: its per-element history goes into
//! [`AnalysisState`] (serialized with FMU states), [`Triangles`] reads it in `restore`, updates
//! a trial copy in `add` and writes it in `commit`; the loop stays as it is.
//!
//! The order of [`Contributions::all_mut`] is the order of the floating-point sums into the
//! residual and the matrix: triangles, gaps, loads, cables, curved contacts, layer contacts,
//! chambers, and last the viscous stabilization (off unless a step needs it; it sizes itself
//! from the others' matrix).
//!
//! | file | what |
//! |---|---|
//! | `triangles` | the membrane triangles (and the film's stresses in the results) |
//! | `gaps` | the friction gaps: trial laws and slip history, Ju–Rowlands latching |
//! | `loads` | external loads and edge cables |
//! | `curved` | node-to-surface contacts on curved supports |
//! | `layers` | film-to-film contacts between layers (node to triangle, friction) |
//! | `stabilization` | the viscous stabilization of a step whose equilibrium is not unique |

mod chambers;
mod curved;
mod gaps;
mod layers;
mod loads;
mod stabilization;
mod triangles;

pub use chambers::{ChamberResult, ChamberState, Chambers, LowRank, OrificeResult};
pub use curved::CurvedContacts;
pub use gaps::Gaps;
pub use layers::LayerContacts;
pub use stabilization::ViscousStabilization;
pub use triangles::Triangles;

use crate::mech::elements::cable::Cables;
use crate::mech::elements::gap::{GapStatus, IterationMatrix};
use crate::mech::elements::load::{LoadLevels, Loads};
use crate::mech::model::Model;
use crate::mech::results::Results;
use crate::mech::solve::assembly::System;
use crate::mech::solve::state::AnalysisState;

/// Where a contribution is evaluated.
#[derive(Clone, Copy, Debug)]
pub struct Evaluation<'a> {
    /// The discretized system (DOF map, slots, triangles).
    pub system: &'a System,
    /// Displacements, three per node (m).
    pub u: &'a [f64],
    /// Load levels.
    pub levels: &'a LoadLevels,
    /// The Newton iteration this evaluation serves (`None`: the residual alone, for results).
    pub iteration: Option<usize>,
    /// Which matrix drives the iterations.
    pub matrix: IterationMatrix,
}

/// Something that adds force and stiffness: see the module doc for its history cycle.
pub trait Contribution {
    /// Resets the trial history to the converged `start` (start of an increment or a retry).
    fn restore(&mut self, _start: &AnalysisState) {}

    /// Adds the residual at `at` into `residual` (all DOFs) and, when `values` is given, the
    /// Newton matrix entries into it (the system's value array).
    fn add(&mut self, at: &Evaluation<'_>, residual: &mut [f64], values: Option<&mut [f64]>);

    /// Writes the trial history of a converged iterate into `state` (`start`: the increment's).
    fn commit(&self, _start: &AnalysisState, _state: &mut AnalysisState) {}

    /// Prepares an evaluation at the converged `state` for [`Contribution::results`].
    fn at_converged(&mut self, _state: &AnalysisState) {}

    /// Appends the contact statuses at the last evaluation (open, stick, slip of each gap and
    /// curved-support contact), in the order of [`Contribution::status_names`].
    fn statuses(&self, _out: &mut Vec<GapStatus>) {}

    /// Appends the signed gap of each contact at the last evaluation (m; negative: pressed
    /// in), in the order of [`Contribution::statuses`]: where along a Newton correction a
    /// contact opens or closes (the line search's event trial, `newton.rs`).
    fn gaps(&self, _out: &mut Vec<f64>) {}

    /// Imposes the friction statuses `held` on its contacts, in the order of
    /// [`Contribution::statuses`] (None: the law's own), until the next restore: the Newton
    /// loop's hold of contacts cycling between stick and slip (`newton.rs`).
    fn hold(&mut self, _held: &[Option<GapStatus>]) {}

    /// Appends the names of the items [`Contribution::statuses`] lists, in its order.
    fn status_names(&self, _out: &mut Vec<String>) {}

    /// Corrects the first iterate `u` of an increment predicted from the converged `start`
    /// (`increments.rs`) where the prediction leaves the item's constraint (a closed contact
    /// pushed into its support).
    fn correct_prediction(&self, _system: &System, _start: &AnalysisState, _u: &mut [f64]) {}

    /// Fills its part of `out` at the converged `state` (after an evaluation at it).
    fn results(
        &self,
        _at: &Evaluation<'_>,
        _state: &AnalysisState,
        _model: &Model,
        _out: &mut Results,
    ) {
    }
}

/// Every contribution of an analysis.
#[derive(Clone, Debug)]
pub struct Contributions {
    /// Membrane triangles.
    pub triangles: Triangles,
    /// Friction gaps.
    pub gaps: Gaps,
    /// External loads.
    pub loads: Loads,
    /// Tension-only edge cables.
    pub cables: Cables,
    /// Node-to-surface contacts on curved supports.
    pub curved: CurvedContacts,
    /// Film-to-film contacts between layers.
    pub layers: LayerContacts,
    /// Gas chambers.
    pub chambers: Chambers,
    /// The viscous stabilization of the current step (off unless a step turns it on).
    pub stabilization: ViscousStabilization,
}

impl Contributions {
    /// The contributions of `model` on `system` (`diagonal`: each free equation's diagonal slot;
    /// `mass`: its pseudo-mass, `continuation::pseudo_mass`).
    pub fn new(model: &Model, system: &System, diagonal: Vec<usize>, mass: Vec<f64>) -> Self {
        Self {
            triangles: Triangles::default(),
            gaps: Gaps::new(model),
            loads: Loads::new(model, system),
            cables: Cables::new(model),
            curved: CurvedContacts::new(model),
            layers: LayerContacts::new(model, system),
            chambers: Chambers::new(model),
            stabilization: ViscousStabilization::new(diagonal, mass),
        }
    }

    /// All of them, in assembly order (the order of the floating-point sums).
    pub fn all_mut(&mut self) -> [&mut dyn Contribution; 8] {
        [
            &mut self.triangles,
            &mut self.gaps,
            &mut self.loads,
            &mut self.cables,
            &mut self.curved,
            &mut self.layers,
            &mut self.chambers,
            &mut self.stabilization,
        ]
    }

    /// All of them, in assembly order.
    pub fn all(&self) -> [&dyn Contribution; 8] {
        [
            &self.triangles,
            &self.gaps,
            &self.loads,
            &self.cables,
            &self.curved,
            &self.layers,
            &self.chambers,
            &self.stabilization,
        ]
    }

    /// Zeroes `residual` (and `values`) and adds every contribution at `at`.
    pub fn assemble(
        &mut self,
        at: &Evaluation<'_>,
        residual: &mut [f64],
        mut values: Option<&mut [f64]>,
    ) {
        residual.fill(0.0);
        if let Some(v) = values.as_deref_mut() {
            v.fill(0.0);
        }
        for c in self.all_mut() {
            c.add(at, residual, values.as_deref_mut());
        }
    }

    /// The contact statuses at the last evaluation, of every contribution in order.
    pub fn statuses(&self) -> Vec<GapStatus> {
        let mut out = Vec::new();
        for c in self.all() {
            c.statuses(&mut out);
        }
        out
    }

    /// Imposes the statuses `held` (in the order of [`Self::statuses`]) on each contribution's
    /// contacts until the next restore ([`Contribution::hold`]).
    pub fn hold(&mut self, held: &[Option<GapStatus>]) {
        let mut from = 0;
        for c in self.all_mut() {
            let mut own = Vec::new();
            c.statuses(&mut own);
            let to = (from + own.len()).min(held.len());
            c.hold(&held[from.min(to)..to]);
            from += own.len();
        }
    }

    /// The signed gaps at the last evaluation, in the order of [`Self::statuses`].
    pub fn gaps(&self) -> Vec<f64> {
        let mut out = Vec::new();
        for c in self.all() {
            c.gaps(&mut out);
        }
        out
    }

    /// The names of the items of [`Self::statuses`], in its order.
    pub fn status_names(&self) -> Vec<String> {
        let mut out = Vec::new();
        for c in self.all() {
            c.status_names(&mut out);
        }
        out
    }
}
