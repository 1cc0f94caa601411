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

use crate::mech::elements::gap::IterationMatrix;
use crate::mech::elements::load::{LoadLevels, Loads};
use crate::mech::model::{Model, bounding_diagonal};
use crate::mech::solve::assembly::{System, node_vector};
use crate::mech::solve::continuation::pseudo_mass;
use crate::mech::solve::contributions::{Contributions, Evaluation};
use crate::mech::solve::linear::{LinearSolver, SolveProfile, UnsymmetricMethod};
use crate::mech::solve::progress::IncrementObserver;
use crate::mech::solve::report::{SetupError, StepError, StepReport};
use crate::mech::solve::sensitivity::HeldTangent;
use crate::mech::solve::settings::SolverSettings;
use crate::mech::solve::state::AnalysisState;

/// A model under analysis: the system, its factorization, its contributions and the last
/// converged state.
#[derive(Clone, Debug)]
pub struct Analysis {
    pub(in crate::mech) model: Model,
    pub(in crate::mech) system: System,
    pub(in crate::mech) settings: SolverSettings,
    pub(super) linear: LinearSolver,
    /// Everything that adds force and stiffness, in assembly order.
    pub(in crate::mech) parts: Contributions,
    pub(in crate::mech) state: AnalysisState,
    pub(in crate::mech) work: Workspace,
    /// The state the last converged increment started from (None before the first step and
    /// after [`Analysis::set_state`]): what its linear response holds (`sensitivity`).
    pub(in crate::mech) increment_start: Option<AnalysisState>,
    /// The factorized tangent of the derivatives, held between seeds (`sensitivity`).
    pub(in crate::mech) held_tangent: Option<Box<HeldTangent>>,
    /// Solves with the held tangent so far (`Analysis::tangent_solves`).
    pub(in crate::mech) tangent_solves: usize,

    /// Bounding-box diagonal `L` of the model (m): the length scale of the tolerances and of
    /// the input check.
    pub(super) length_scale: f64,
    /// `1e-6·E·t·L` (N): the force scale of an unloaded film.
    pub(super) force_floor: f64,
    /// Who is told of each increment as it ends ([`Analysis::observe_increments`]).
    pub(super) observer: IncrementObserver,
}

/// Buffers reused by every iteration.
#[derive(Clone, Debug)]
pub(in crate::mech) struct Workspace {
    /// Residual `f_int − f_ext` of every DOF at the last evaluation.
    pub(in crate::mech) internal: Vec<f64>,
    /// Newton matrix values at the last evaluation with a tangent.
    pub(super) values: Vec<f64>,
    /// Right-hand side, then the Newton correction, over the free DOFs.
    pub(super) rhs: Vec<f64>,
    /// Slot of each free DOF's diagonal entry in `values` (for the pseudo-time shift).
    pub(super) diagonal: Vec<usize>,
    /// Pseudo-mass of each free equation (`continuation::pseudo_mass`).
    pub(super) pseudo_mass: Vec<f64>,
    /// Work of the pseudo-time term over the current step's iterations (J).
    pub(super) pseudo_time_work: f64,
}

impl Analysis {
    /// Validates the model and settings, builds the pattern and the symbolic factorization.
    pub fn new(model: Model, settings: SolverSettings) -> Result<Self, SetupError> {
        model.validate().map_err(SetupError::Model)?;
        settings.validate().map_err(SetupError::Settings)?;
        // The Ju–Rowlands matrix is symmetric, stored as its lower triangle; without gaps or
        // curved supports it is the consistent tangent, stored whole (a follower pressure's
        // load stiffness is unsymmetric).
        let contacts = !model.gaps.is_empty()
            || !model.curved_supports.is_empty()
            || !model.layer_contacts.is_empty();
        let lower_only = settings.iteration_matrix == IterationMatrix::JuRowlands && contacts;
        let mut system = System::new(&model, lower_only)?;
        system.set_threads(settings.threads);
        let mut linear = LinearSolver::new(&system, settings.symmetric_factorization)
            .map_err(|e| SetupError::System(e.0))?;
        linear.set_threads(settings.threads);
        // Computed once: the continuation and the viscous stabilization both use them.
        let (diagonal, mass) = (diagonal_slots(&system), pseudo_mass(&system));
        let parts = Contributions::new(&model, &system, diagonal.clone(), mass.clone());
        let laws = parts.gaps.laws();
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
            last_load_increment: Vec::new(),
            contacts: parts.curved.initial_histories(&model),
            chambers: parts.chambers.initial_states(&model),
            orifices: vec![0.0; model.orifices.len()],
            orifice_moved: vec![0.0; model.orifices.len()],
            layer_contacts: parts.layers.initial_histories(&system),
            plastic: system
                .material
                .plastic_film()
                .map(|f| vec![f.initial_history(model.material.prestress); model.triangles.len()])
                .unwrap_or_default(),
        };
        let work = Workspace {
            internal: vec![0.0; model.dof_count()],
            values: vec![0.0; system.nonzeros()],
            rhs: vec![0.0; system.free_count],
            diagonal,
            pseudo_mass: mass,
            pseudo_time_work: 0.0,
        };
        let length_scale = bounding_diagonal(&model.nodes).max(f64::MIN_POSITIVE);
        let force_floor = 1e-6 * system.material.membrane_stiffness() * length_scale;
        Ok(Self {
            model,
            system,
            settings,
            linear,
            parts,
            state,
            work,
            increment_start: None,
            held_tangent: None,
            tangent_solves: 0,
            length_scale,
            force_floor,
            observer: IncrementObserver::default(),
        })
    }

    /// Tells `observer` of every increment of the following steps as it ends (converged or
    /// refused); [`IncrementObserver::default`] tells no one.
    pub fn observe_increments(&mut self, observer: IncrementObserver) {
        self.observer = observer;
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
        self.linear.set_threads(settings.threads);
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
            || state.layer_contacts.len() != s.layer_contacts.len()
            || state.friction.len() != s.friction.len()
            || state.status.len() != s.status.len()
            || !(state.last_increment.is_empty()
                || state.last_increment.len() == s.displacement.len())
            || !(state.last_load_increment.is_empty()
                || state.last_load_increment.len() == s.loads.path().count())
            || !state.loads.fits(&self.model)
        {
            return Err("state does not match this model's sizes".into());
        }
        if state.plastic.len() != s.plastic.len() {
            return Err(format!(
                "state holds the plastic history of {} triangles; this model's film needs {} \
                 (a state of an elastic film does not fit a plastic one, nor the reverse)",
                state.plastic.len(),
                s.plastic.len()
            ));
        }
        let finite = state
            .displacement
            .iter()
            .chain(state.plastic_slip.iter().flatten())
            .chain(state.boundary.iter().flatten())
            .chain(&state.angles)
            .chain(&state.friction)
            .all(|v| v.is_finite())
            && state.loads.is_finite()
            && state.is_finite();
        if !finite || state.friction.iter().any(|&m| m < 0.0) {
            return Err("state holds non-finite values or a negative friction coefficient".into());
        }
        self.state = state;
        self.increment_start = None;
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
    /// `1/increments` of the step (eq. 2.11–2.12 in each), sized by the controller of
    /// [`Self::step_to_motion`]. On error the state (displacements and load levels) is
    /// unchanged.
    pub fn step_to_with_loads(
        &mut self,
        target: &[[f64; 3]],
        loads: &LoadLevels,
        increments: usize,
    ) -> Result<StepReport, StepError> {
        let angles = self.state.angles.clone();
        self.step_to_motion(target, &angles, loads, increments)
    }

    /// The model's external loads.
    pub fn loads(&self) -> &Loads {
        &self.parts.loads
    }

    /// The out-of-balance force of every DOF at displacements `u` (three per node; prescribed
    /// ones as given) and the Newton matrix there (column-major values of the system's
    /// pattern), iterating from the converged state with the load levels `levels`: what one
    /// Newton iteration assembles. For checking the assembled tangent against finite
    /// differences of the assembled residual.
    #[doc(hidden)]
    pub fn residual_and_matrix(&mut self, u: &[f64], levels: &LoadLevels) -> (Vec<f64>, Vec<f64>) {
        let start = self.state.clone();
        for c in self.parts.all_mut() {
            c.restore(&start);
        }
        self.assemble_at(u, levels, Some(1));
        (self.work.internal.clone(), self.work.values.clone())
    }

    /// Evaluates every contribution at `u` with the loads at `levels`: the residual
    /// `f_int − f_ext` over all DOFs, and the Newton matrix when `iteration` is given; returns
    /// `‖R_free‖∞`.
    pub(in crate::mech) fn assemble_at(
        &mut self,
        u: &[f64],
        levels: &LoadLevels,
        iteration: Option<usize>,
    ) -> f64 {
        let at = Evaluation {
            system: &self.system,
            u,
            levels,
            iteration,
            matrix: self.settings.iteration_matrix,
        };
        let values = iteration.map(|_| self.work.values.as_mut_slice());
        self.parts.assemble(&at, &mut self.work.internal, values);
        self.free_norm_inf()
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
