//! Newton–Raphson analysis with friction gaps (paper §2.3, eqs. 2.11–2.12, procedure §3).
//!
//! Prescribed boundary displacements and external loads ([`crate::mech::elements::load`]) are applied in
//! increments. Each increment runs Newton on
//! `(K_m + K_g) ΔU = −(R_m + R_g)` over the free DOFs; it converges when both the displacement
//! correction (the paper's step (g)) and the residual force are small. A failed increment is
//! halved, up to [`SolverSettings::max_cutbacks`] times; a step that still fails returns an error
//! and leaves the last converged state untouched. A model without free DOFs (every node held or
//! prescribed: how single elements are verified) converges at the first assembly of each
//! increment: forces, stresses, the gaps' return mapping and the reactions at the prescribed
//! configuration, without a linear solve.

use nalgebra::{Vector2, Vector3};

use crate::mech::elements::cable::Cables;
use crate::mech::elements::curved_contact::{ContactHistory, ContactResponse, SurfaceContacts};
use crate::mech::elements::gap::{GapLaw, GapResponse, IterationMatrix};
use crate::mech::elements::load::{LoadLevels, Loads};
use crate::mech::model::bounding_diagonal;
use crate::mech::model::{Hinge, Model};
use crate::mech::solve::assembly::{System, node_vector};
use crate::mech::solve::linear::{LinearSolver, SolveProfile, UnsymmetricMethod};
use crate::mech::solve::report::SetupError;
use crate::mech::solve::report::StepError;
use crate::mech::solve::report::StepReport;
use crate::mech::solve::settings::SolverSettings;
use crate::mech::solve::state::AnalysisState;
use crate::mech::solve::state::GroupMotion;

/// A model under analysis: the system, its factorization and the last converged state.
#[derive(Clone, Debug)]
pub struct Analysis {
    pub(crate) model: Model,
    pub(crate) system: System,
    pub(crate) laws: Vec<GapLaw>,
    pub(crate) settings: SolverSettings,
    pub(crate) linear: LinearSolver,
    pub(crate) loads: Loads,
    /// Tension-only edge cables.
    pub(crate) cables: Cables,
    /// Node-to-surface contacts on curved supports.
    pub(crate) surfaces: SurfaceContacts,
    pub(crate) state: AnalysisState,
    pub(crate) work: Workspace,

    /// Bounding-box diagonal `L` of the model (m): the length scale of the tolerances and of
    /// the input check.
    pub(crate) length_scale: f64,
    /// `1e-6·E·t·L` (N): the force scale of an unloaded film.
    pub(crate) force_floor: f64,
}

/// Buffers reused by every iteration.
#[derive(Clone, Debug)]
pub(crate) struct Workspace {
    /// Whether the line search may keep full steps that raise the residual (its watchdog):
    /// until an increment of the step has been cut back.
    pub(crate) watchdog: bool,
    pub(crate) internal: Vec<f64>,
    pub(crate) values: Vec<f64>,
    pub(crate) rhs: Vec<f64>,
    pub(crate) responses: Vec<GapResponse>,
    /// Gaps latched in slip for the rest of the Newton loop (§3(f)) with their slip direction.
    pub(crate) latched: Vec<Option<Vector2<f64>>>,
    /// Gaps found closed at some iteration of the current Newton loop.
    pub(crate) closed: Vec<bool>,
    /// Slot of each free DOF's diagonal entry in `values` (for the Levenberg–Marquardt shift).
    pub(crate) diagonal: Vec<usize>,
    /// Curved-support contact histories at the start of the increment, and the responses at
    /// the last assembled iterate.
    pub(crate) contact_start: Vec<ContactHistory>,
    pub(crate) contact_responses: Vec<ContactResponse>,
}

impl Analysis {
    /// Validates the model and settings, builds the pattern and the symbolic factorization.
    pub fn new(model: Model, settings: SolverSettings) -> Result<Self, SetupError> {
        model.validate().map_err(SetupError::Model)?;
        settings.validate().map_err(SetupError::Settings)?;
        let lower_only = settings.iteration_matrix == IterationMatrix::JuRowlands;
        let mut system = System::new(&model, lower_only)?;
        system.set_threads(settings.threads);
        let linear = LinearSolver::new(&system, settings.symmetric_factorization)
            .map_err(|e| SetupError::System(e.0))?;
        let laws: Vec<GapLaw> = model.gaps.iter().map(|g| g.law()).collect();
        let state = AnalysisState {
            displacement: vec![0.0; model.dof_count()],
            plastic_slip: vec![[0.0; 2]; model.gaps.len()],
            boundary: vec![[0.0; 3]; model.groups.len()],
            angles: vec![0.0; model.groups.len()],
            loads: LoadLevels::zero(&model),
            friction: laws.iter().map(|l| l.friction).collect(),
            status: laws
                .iter()
                .map(|l| l.evaluate(Vector3::zeros(), Vector2::zeros()).status)
                .collect(),
            last_increment: Vec::new(),
            contacts: Vec::new(),
        };
        let surfaces = SurfaceContacts::new(&model);
        let mut state = state;
        state.contacts = surfaces.initial_histories(&model);
        let idle = laws
            .first()
            .map(|l| l.evaluate(Vector3::zeros(), Vector2::zeros()));
        let work = Workspace {
            internal: vec![0.0; model.dof_count()],
            values: vec![0.0; system.nonzeros()],
            rhs: vec![0.0; system.free_count],
            responses: idle.map_or_else(Vec::new, |r| vec![r; laws.len()]),
            latched: vec![None; laws.len()],
            closed: vec![false; laws.len()],
            diagonal: diagonal_slots(&system),
            contact_start: state.contacts.clone(),
            contact_responses: Vec::new(),
            watchdog: true,
        };
        let loads = Loads::new(&model, &system);
        let cables = Cables::new(&model);
        let length_scale = bounding_diagonal(&model.nodes).max(f64::MIN_POSITIVE);
        let force_floor = 1e-6 * model.material.membrane_stiffness() * length_scale;
        Ok(Self {
            model,
            system,
            laws,
            settings,
            linear,
            loads,
            cables,
            surfaces,
            state,
            work,
            length_scale,
            force_floor,
        })
    }

    /// Solves so far: `[LU, LDLᵀ of a symmetric consistent tangent, LDLᵀ or GMRES redone by
    /// LU, GMRES preconditioned by the symmetric part's LDLᵀ]` (the Ju–Rowlands matrix's LDLᵀ is
    /// not counted).
    pub fn factorization_counts(&self) -> [usize; 4] {
        self.linear.counts()
    }

    /// Where the linear solves' time went so far (see [`SolveProfile`]).
    pub fn solve_profile(&self) -> SolveProfile {
        self.linear.profile()
    }

    /// The linear solver (its memory, limits and whether the LU was ever analysed).
    pub fn linear_solver(&self) -> &LinearSolver {
        &self.linear
    }

    /// Chooses how unsymmetric consistent tangents are solved (Woodbury or GMRES on the
    /// symmetric part's LDLᵀ; [`UnsymmetricMethod::Auto`] by default).
    pub fn set_unsymmetric_method(&mut self, method: UnsymmetricMethod) {
        self.linear.set_method(method);
    }

    /// The model.
    pub fn model(&self) -> &Model {
        &self.model
    }

    /// The discretized system.
    pub fn system(&self) -> &System {
        &self.system
    }

    /// Bounding-box diagonal of the model's nodes (m).
    pub fn length_scale(&self) -> f64 {
        self.length_scale
    }

    /// The settings.
    pub fn settings(&self) -> &SolverSettings {
        &self.settings
    }

    /// Changes tolerances, limits and threads (not the iteration matrix, which fixes the
    /// pattern).
    pub fn set_limits(&mut self, settings: SolverSettings) -> Result<(), String> {
        settings.validate()?;
        if settings.iteration_matrix != self.settings.iteration_matrix {
            return Err("the iteration matrix is fixed when the analysis is created".into());
        }
        self.system.set_threads(settings.threads);
        self.settings = settings;
        Ok(())
    }

    /// The last converged state.
    pub fn state(&self) -> &AnalysisState {
        &self.state
    }

    /// Replaces the state (e.g. a restored FMU state) after checking its sizes.
    pub fn set_state(&mut self, state: AnalysisState) -> Result<(), String> {
        let s = &self.state;
        if state.displacement.len() != s.displacement.len()
            || state.plastic_slip.len() != s.plastic_slip.len()
            || state.boundary.len() != s.boundary.len()
            || state.angles.len() != s.angles.len()
            || state.contacts.len() != s.contacts.len()
            || state.friction.len() != s.friction.len()
            || state.status.len() != s.status.len()
            || !(state.last_increment.is_empty()
                || state.last_increment.len() == s.displacement.len())
            || !state.loads.fits(&self.model)
        {
            return Err("state does not match this model's sizes".into());
        }
        let finite = state
            .displacement
            .iter()
            .chain(state.plastic_slip.iter().flatten())
            .chain(state.boundary.iter().flatten())
            .chain(&state.angles)
            .chain(&state.friction)
            .all(|v| v.is_finite())
            && state.loads.is_finite();
        if !finite || state.friction.iter().any(|&m| m < 0.0) {
            return Err("state holds non-finite values or a negative friction coefficient".into());
        }
        self.state = state;
        Ok(())
    }

    /// Sets the friction coefficient `μ` of every gap and curved-support contact for the
    /// following steps.
    pub fn set_friction(&mut self, mu: f64) -> Result<(), String> {
        if !(mu >= 0.0 && mu.is_finite()) {
            return Err(format!("friction coefficient {mu} must be finite and ≥ 0"));
        }
        self.state.friction.iter_mut().for_each(|m| *m = mu);
        self.state.contacts.iter_mut().for_each(|c| c.friction = mu);
        Ok(())
    }

    /// Largest boundary target accepted, as a multiple of the model's size.
    pub const MAX_TARGET_PER_SIZE: f64 = 10.0;

    /// Moves every boundary group to `target` (m) with the loads kept at their current levels;
    /// see [`Self::step_to_with_loads`].
    pub fn step_to(
        &mut self,
        target: &[[f64; 3]],
        increments: usize,
    ) -> Result<StepReport, StepError> {
        let loads = self.state.loads.clone();
        self.step_to_with_loads(target, &loads, increments)
    }

    /// Moves every boundary group to `target` (m) and the loads to `loads`, both interpolated
    /// linearly between the converged state and the targets, in increments of at most
    /// `1/increments` of the step (eq. 2.11–2.12 in each). The increment size adapts: it is
    /// halved when an increment fails (up to [`SolverSettings::max_cutbacks`] times below the
    /// largest size) or needs many iterations, and doubled again, up to the largest, after easy
    /// ones.
    ///
    /// When even the smallest increment fails, larger ones are tried from the same converged
    /// state before the step is given up (twice the largest, four times, …, up to the rest of
    /// the step; counted in [`StepReport::enlarged`]). A film whose start is a mechanism (slack
    /// across, tensioned only once the boundary has moved far enough) converges in a larger
    /// increment and in no smaller one: issue 7's arch edge lowered in 80 steps was refused in
    /// its first step with 10 increments per step and passes in one increment per step. The
    /// answer is still the converged equilibrium at the target; only the path between two
    /// converged states is coarser, which friction may feel. On error the state (displacements
    /// and load levels) is unchanged.
    pub fn step_to_with_loads(
        &mut self,
        target: &[[f64; 3]],
        loads: &LoadLevels,
        increments: usize,
    ) -> Result<StepReport, StepError> {
        let angles = self.state.angles.clone();
        self.step_to_motion(target, &angles, loads, increments)
    }

    /// Refuses targets of the wrong length, non-finite or beyond
    /// [`Self::MAX_TARGET_PER_SIZE`] times the model's size.
    pub(crate) fn check_targets(&self, target: &[[f64; 3]]) -> Result<(), StepError> {
        let invalid = |message| Err(StepError::InvalidInput { message });
        if target.len() != self.state.boundary.len() {
            return invalid(format!(
                "{} group targets given, the model has {}",
                target.len(),
                self.state.boundary.len()
            ));
        }
        let limit = Self::MAX_TARGET_PER_SIZE * self.length_scale;
        for (g, t) in target.iter().enumerate() {
            let name = &self.model.groups[g].name;
            if t.iter().any(|v| !v.is_finite()) {
                return invalid(format!(
                    "the target of group '{name}' {t:?} is NaN or infinite"
                ));
            }
            if let Some(v) = t.iter().find(|v| v.abs() > limit) {
                return invalid(format!(
                    "the target of group '{name}' ({v:e} m) is more than {} times the model's size ({:.4} m): \
                     refused before solving",
                    Self::MAX_TARGET_PER_SIZE,
                    self.length_scale
                ));
            }
        }
        Ok(())
    }

    /// Refuses angles of the wrong length, not finite, beyond [`Hinge::MAX_ANGLE`] or given to
    /// a group without a hinge.
    pub(crate) fn check_angles(&self, angles: &[f64]) -> Result<(), StepError> {
        let invalid = |message| Err(StepError::InvalidInput { message });
        if angles.len() != self.model.groups.len() {
            return invalid(format!(
                "{} group angles given, the model has {} groups",
                angles.len(),
                self.model.groups.len()
            ));
        }
        for (g, &a) in self.model.groups.iter().zip(angles) {
            if !a.is_finite() || a.abs() > Hinge::MAX_ANGLE {
                return invalid(format!(
                    "the angle of group '{}' ({a} rad) is not finite or beyond two full turns",
                    g.name
                ));
            }
            if g.hinge.is_none() && a != 0.0 {
                return invalid(format!(
                    "group '{}' has no hinge and cannot turn ({a} rad asked)",
                    g.name
                ));
            }
        }
        Ok(())
    }

    /// The prescribed value of global DOF `i` (node `i / 3`, component `component`) of group
    /// `group` under `motion`: its translation plus the turn about its hinge.
    pub(crate) fn prescribed_value(
        &self,
        i: usize,
        group: usize,
        component: usize,
        motion: &GroupMotion,
    ) -> f64 {
        let turn = self.model.groups[group].hinge.as_ref().map_or(0.0, |h| {
            h.displacement(self.model.nodes[i / 3], motion.angles[group])[component]
        });
        motion.translation[group][component] + turn
    }

    /// Refuses load targets of the wrong sizes or not finite.
    pub(crate) fn check_loads(&self, loads: &LoadLevels) -> Result<(), StepError> {
        let invalid = |message| Err(StepError::InvalidInput { message });
        if !loads.fits(&self.model) {
            return invalid(format!(
                "{} pressures and {} nodal forces given, the model has {} pressure sets and {} force sets",
                loads.pressure.len(),
                loads.force.len(),
                self.model.loads.pressures.len(),
                self.model.loads.forces.len()
            ));
        }
        for (p, set) in loads.pressure.iter().zip(&self.model.loads.pressures) {
            if !p.is_finite() {
                return invalid(format!(
                    "the pressure of set '{}' ({p}) is NaN or infinite",
                    set.name
                ));
            }
        }
        for (f, set) in loads.force.iter().zip(&self.model.loads.forces) {
            if f.iter().any(|v| !v.is_finite()) {
                return invalid(format!(
                    "the force of set '{}' {f:?} is NaN or infinite",
                    set.name
                ));
            }
        }
        if loads.gravity.iter().any(|v| !v.is_finite()) {
            return invalid(format!("gravity {:?} is NaN or infinite", loads.gravity));
        }
        Ok(())
    }

    /// The model's external loads.
    pub fn loads(&self) -> &Loads {
        &self.loads
    }

    /// The out-of-balance force of every DOF at displacements `u` (three per node; prescribed
    /// ones as given) and the Newton matrix there (column-major values of the system's
    /// pattern), iterating from the converged state with the load levels `levels`: what one
    /// Newton iteration assembles. For checking the assembled tangent against finite
    /// differences of the assembled residual.
    #[doc(hidden)]
    pub fn residual_and_matrix(&mut self, u: &[f64], levels: &LoadLevels) -> (Vec<f64>, Vec<f64>) {
        let start = self.state.clone();
        let (laws, history) = self.laws_and_history(&start);
        self.work.contact_start.clone_from(&start.contacts);
        self.work.latched.iter_mut().for_each(|l| *l = None);
        self.work.closed.iter_mut().for_each(|c| *c = false);
        self.assemble_at(u, &laws, &history, levels, Some(1));
        (self.work.internal.clone(), self.work.values.clone())
    }

    /// Displacement of node `v` (m).
    pub fn node_displacement(&self, v: usize) -> Vector3<f64> {
        node_vector(&self.state.displacement, v)
    }
}

/// Slot of each equation's diagonal entry in the value array (the pattern keeps them all).
pub(crate) fn diagonal_slots(system: &System) -> Vec<usize> {
    let pattern = system.pattern();
    let (col_ptr, row_idx) = (pattern.col_ptr(), pattern.row_idx());
    (0..system.free_count)
        .map(|j| {
            let rows = &row_idx[col_ptr[j]..col_ptr[j + 1]];
            col_ptr[j]
                + rows
                    .binary_search(&j)
                    .expect("the pattern keeps every diagonal")
        })
        .collect()
}
