//! Newton–Raphson analysis with friction gaps (paper §2.3, eqs. 2.11–2.12, procedure §3).
//!
//! Prescribed boundary displacements and external loads ([`super::load`]) are applied in
//! increments. Each increment runs Newton on
//! `(K_m + K_g) ΔU = −(R_m + R_g)` over the free DOFs; it converges when both the displacement
//! correction (the paper's step (g)) and the residual force are small. A failed increment is
//! halved, up to [`SolverSettings::max_cutbacks`] times; a step that still fails returns an error
//! and leaves the last converged state untouched. A model without free DOFs (every node held or
//! prescribed: how single elements are verified) converges at the first assembly of each
//! increment: forces, stresses, the gaps' return mapping and the reactions at the prescribed
//! configuration, without a linear solve.

use std::fmt;

use nalgebra::{Vector2, Vector3};
use serde::{Deserialize, Serialize};

use super::assembly::{Dof, PatternError, System, node_dofs, node_vector};
use super::cable::{CableResult, Cables};
use super::contact::{GapLaw, GapResponse, GapStatus, IterationMatrix};
use super::element::{ElementStress, ElementVector, MembraneTriangle};
use super::linear::{LinearSolver, SolveProfile, UnsymmetricMethod};
use super::load::{ExternalLoad, LoadLevels, Loads};
use super::material::Wrinkling;
use super::model::{Hinge, Model, ModelError};
use super::summary::{FieldSummary, summarize};
use super::surface::{ContactHistory, ContactResponse, SurfaceContactResult, SurfaceContacts};

/// Newton and increment-control settings.
///
/// Convergence (every criterion on the residual of the true friction law, never of a frozen or
/// modified one) needs both
/// * `‖ΔU‖∞ ≤ displacement_tolerance · U_ref`, `U_ref = max(‖U − U_start‖∞, ‖U‖∞, 1e-9·L)`: the
///   last correction is small against the displacements (paper §3(g)); `L` is the model's
///   bounding-box diagonal;
/// * `‖R_free‖∞ ≤ residual_tolerance · F_ref`, `F_ref = max(‖R_all‖∞, 1e-6·E·t·L)`: the largest
///   out-of-balance force is small against the largest nodal force of the model (the reactions
///   and gap forces; the floor is the membrane's own force scale, for unloaded states).
///
/// Both are scaled by the model, so the same defaults serve a 1 N strip and a 10 kN roof.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct SolverSettings {
    /// Which matrix drives the iterations.
    pub iteration_matrix: IterationMatrix,
    /// Relative tolerance of the last displacement correction (see the type's doc).
    pub displacement_tolerance: f64,
    /// Relative tolerance of the out-of-balance force (see the type's doc).
    pub residual_tolerance: f64,
    /// Newton iterations per increment before the increment is cut back. A stalled or
    /// diverging iteration is cut back earlier (see [`IncrementFailure`]).
    pub max_iterations: usize,
    /// How many times an increment may be halved before the step fails.
    pub max_cutbacks: usize,
    /// Backtracking on `‖R‖₂` along each Newton correction (see `Analysis::line_search`).
    pub line_search: bool,
    /// Factorize a consistent tangent that is symmetric (no slipping gap, no follower pressure)
    /// by LDLᵀ instead of LU (`linear.rs`); false: always LU.
    pub symmetric_factorization: bool,
    /// Threads of the element assembly (scoped: none outlives a call); 0 = automatic (one
    /// below [`super::assembly::PARALLEL_MIN_TRIANGLES`] triangles, else up to two). Results
    /// are bit-identical for every count.
    pub threads: usize,
}

/// Default number of increments a step is split into (the largest increment is this fraction
/// of a step): the CLI's `--increments` and the FMU's `solver.incrementsPerStep` both start
/// from it, so that a CLI check predicts an FMU run with default parameters. Ten keeps a
/// master's coarse communication step robust; on the specimens it changes the CLI's slips by
/// at most 0.001 mm against one increment per step.
pub const DEFAULT_INCREMENTS_PER_STEP: usize = 10;

impl Default for SolverSettings {
    fn default() -> Self {
        Self {
            iteration_matrix: IterationMatrix::default(),
            displacement_tolerance: 1e-5,
            residual_tolerance: 1e-5,
            max_iterations: 100,
            max_cutbacks: 12,
            line_search: true,
            symmetric_factorization: true,
            threads: 0,
        }
    }
}

impl SolverSettings {
    /// Checks the settings (tolerances in (0, 1), at least one iteration).
    pub fn validate(&self) -> Result<(), String> {
        let ok = |v: f64| v > 0.0 && v < 1.0;
        if !ok(self.displacement_tolerance) || !ok(self.residual_tolerance) {
            return Err(format!(
                "tolerances ({:e}, {:e}) must lie in (0, 1): they are relative to the model's displacement and force scales",
                self.displacement_tolerance, self.residual_tolerance
            ));
        }
        if self.max_iterations == 0 {
            return Err("max_iterations must be at least 1".into());
        }
        if self.max_cutbacks > 60 {
            return Err("max_cutbacks must be at most 60".into());
        }
        if self.threads > MAX_THREADS {
            return Err(format!(
                "threads = {} must be at most {MAX_THREADS} (0: automatic)",
                self.threads
            ));
        }
        Ok(())
    }
}

/// Most assembly threads [`SolverSettings::threads`] accepts.
pub const MAX_THREADS: usize = 256;

/// Where the boundary groups are at one point of a step: translation and hinge angle of each.
#[derive(Clone, Debug)]
struct GroupMotion {
    translation: Vec<[f64; 3]>,
    angles: Vec<f64>,
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
    /// History of each curved-support contact ([`super::surface`]): anchor, angle, status, μ.
    #[serde(default)]
    pub contacts: Vec<ContactHistory>,
    /// Displacement change of the last converged increment (empty before the first): the
    /// predictor of the next increment when the boundary keeps moving the same way.
    #[serde(default)]
    pub last_increment: Vec<f64>,
}

impl AnalysisState {
    /// Whether every number of the state is finite.
    pub fn is_finite(&self) -> bool {
        self.displacement
            .iter()
            .chain(self.plastic_slip.iter().flatten())
            .chain(self.boundary.iter().flatten())
            .chain(&self.angles)
            .chain(&self.friction)
            .chain(&self.last_increment)
            .all(|v| v.is_finite())
            && self.contacts.iter().all(|c| {
                [c.anchor[0], c.anchor[1], c.angle, c.origin, c.friction]
                    .iter()
                    .all(|v| v.is_finite())
            })
            && self.loads.is_finite()
    }
}

/// Newton statistics of one step.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct StepReport {
    /// Newton iterations of each converged increment.
    pub iterations: Vec<usize>,
    /// Increments halved.
    pub cutbacks: usize,
    /// Increments made larger than `1/increments` of the step because every smaller one had
    /// failed (see `Analysis::step_to`).
    #[serde(default)]
    pub enlarged: usize,
    /// Final residual `‖R_free‖∞` (N).
    pub residual: f64,
    /// `‖R_free‖∞` at every iteration of the last converged increment (N).
    pub residual_history: Vec<f64>,
}

impl StepReport {
    /// Total Newton iterations (converged increments only).
    pub fn total_iterations(&self) -> usize {
        self.iterations.iter().sum()
    }
}

/// The convergence figures of one Newton iteration: its residual and the correction that led to
/// it, each with the tolerance it had to meet at that iteration (both tolerances scale with the
/// iterate). A refusal quotes one such record, so its numbers never mix iterations.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct IterationRecord {
    /// Iteration number (0 = the predictor, before any correction).
    pub iteration: usize,
    /// `‖R_free‖∞` at this iterate (N).
    pub residual: f64,
    /// The residual tolerance at this iterate (N).
    pub residual_tolerance: f64,
    /// `‖Δu‖∞` of the correction that led to this iterate (m; infinite at iteration 0).
    pub correction: f64,
    /// The correction tolerance at this iterate (m).
    pub correction_tolerance: f64,
}

impl IterationRecord {
    /// How far this iterate is from convergence: the larger of the residual's and the
    /// correction's ratio to its tolerance (converged iterates have at most 1).
    fn distance(&self) -> f64 {
        (self.residual / self.residual_tolerance).max(self.correction / self.correction_tolerance)
    }

    /// Which of the two criteria this iterate failed, in words.
    fn verdict(&self) -> &'static str {
        match (
            self.residual <= self.residual_tolerance,
            self.correction <= self.correction_tolerance,
        ) {
            (true, false) => "the residual met its tolerance, the correction did not",
            (false, true) => "the correction met its tolerance, the residual did not",
            (false, false) => "neither met its tolerance",
            (true, true) => "both met their tolerances",
        }
    }
}

impl fmt::Display for IterationRecord {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "correction {:.3e} m (tolerance {:.3e} m), residual {:.3e} N (tolerance {:.3e} N)",
            self.correction, self.correction_tolerance, self.residual, self.residual_tolerance
        )
    }
}

/// What a front end calls the settings that failure advice points to: the core names no
/// command-line option or FMU parameter, each front end passes its own names
/// ([`SettingNames::CORE`] names the [`SolverSettings`] fields).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SettingNames {
    /// The iteration limit per increment.
    pub max_iterations: &'static str,
    /// How to make each increment smaller (an imperative: "raise --increments").
    pub finer_increments: &'static str,
    /// The residual tolerance.
    pub residual_tolerance: &'static str,
    /// The displacement (correction) tolerance.
    pub displacement_tolerance: &'static str,
    /// How to choose the consistent tangent over the Ju–Rowlands matrix.
    pub consistent_tangent: &'static str,
}

impl SettingNames {
    /// The names of the [`SolverSettings`] fields.
    pub const CORE: Self = Self {
        max_iterations: "max_iterations",
        finer_increments: "raise the increments per step",
        residual_tolerance: "residual_tolerance",
        displacement_tolerance: "displacement_tolerance",
        consistent_tangent: "iteration_matrix = Consistent",
    };
}

/// Why one increment failed.
#[derive(Clone, Debug, PartialEq)]
pub enum IncrementFailure {
    /// No convergence within the iteration limit (with the consistent tangent: while the
    /// residual was still decreasing, or the stall test would have stopped it earlier).
    MaxIterations {
        /// `‖R_free‖∞` at iteration 0 (N).
        first_residual: f64,
        /// The last iteration (the limit).
        last: IterationRecord,
        /// The iteration matrix that ran out of iterations.
        matrix: IterationMatrix,
        /// Gaps whose status changed in the last iterations.
        chattering: Vec<String>,
        /// Film elements whose tension-field state (taut, wrinkled, slack) differs between the
        /// last two iterates.
        flipping: Vec<usize>,
    },
    /// Neither the residual nor the correction improved for a while (a cycle between states or
    /// a plateau).
    Stalled {
        /// Iteration at which the stall was detected.
        iteration: usize,
        /// The iteration closest to convergence (smallest [`IterationRecord::distance`]).
        closest: IterationRecord,
        /// Gaps whose status changed in the last iterations.
        chattering: Vec<String>,
        /// Film elements whose tension-field state differs between the last two iterates.
        flipping: Vec<usize>,
    },
    /// NaN/Inf or runaway corrections.
    Diverged { iteration: usize },
    /// The Newton matrix could not be factorized.
    Singular { message: String },
}

/// `names` as a short list: the first few, then how many more.
fn name_list(names: &[String]) -> String {
    const SHOWN: usize = 6;
    let mut text = names
        .iter()
        .take(SHOWN)
        .cloned()
        .collect::<Vec<_>>()
        .join(", ");
    if names.len() > SHOWN {
        text += &format!(" and {} more", names.len() - SHOWN);
    }
    text
}

impl IncrementFailure {
    /// What a user can change to get past this failure, naming the settings as `names` does.
    /// It states what was observed; a cause is named only where the solver established it.
    pub fn advice(&self, names: &SettingNames) -> String {
        let SettingNames {
            max_iterations,
            finer_increments: finer,
            residual_tolerance,
            displacement_tolerance,
            consistent_tangent,
        } = names;
        match self {
            Self::MaxIterations {
                matrix: IterationMatrix::JuRowlands,
                ..
            } => format!(
                "the Ju–Rowlands matrix converges linearly (hundreds to thousands of iterations per increment \
                 once a gap slips, docs/mechanics.md): use the consistent tangent ({consistent_tangent}) or raise \
                 the iteration limit a lot ({max_iterations})"
            ),
            Self::MaxIterations {
                first_residual,
                last,
                ..
            } if last.residual < *first_residual => format!(
                "the residual was still falling: raise the iteration limit ({max_iterations}) or move the inputs \
                 by less per step ({finer})"
            ),
            Self::MaxIterations { .. } => format!(
                "the residual did not fall below its start: move the inputs by less per step ({finer})"
            ),
            Self::Stalled { chattering, .. } if !chattering.is_empty() => format!(
                "gaps {} kept changing status (open/closed or stick/slip) between iterations: move the inputs by \
                 less per step ({finer})",
                name_list(chattering)
            ),
            Self::Stalled { flipping, .. } if !flipping.is_empty() => format!(
                "{} film elements switched between taut, wrinkled and slack between the last iterations \
                 (a region on the verge of wrinkling): move the inputs by less per step ({finer}); more \
                 prestress keeps a film taut",
                flipping.len()
            ),
            Self::Stalled { closest, .. } if closest.residual <= closest.residual_tolerance => {
                format!(
                    "the forces balanced but the corrections did not settle (seen both with increments too large \
                 and with a part held by too little, such as a flat film without prestress): move the inputs \
                 by less per step ({finer}); if that does not help, hold the film by supports or prestress, or \
                 loosen {displacement_tolerance} if the corrections reached are acceptable for your model"
                )
            }
            Self::Stalled { .. } => format!(
                "Newton stopped making progress: move the inputs by less per step ({finer}), or loosen \
                 {residual_tolerance} if the residual reached is acceptable for your model"
            ),
            Self::Diverged { .. } => format!(
                "the residual ran away or became non-finite: move the inputs by less per step ({finer})"
            ),
            Self::Singular { .. } => format!(
                "the Newton matrix of an iterate had a direction with no stiffness (a slack film without \
                 prestress, a part held only by open gaps, or an iterate that a smaller increment does not \
                 reach): add prestress, supports or wrinkling-aware material, or move the inputs by less per \
                 step ({finer})"
            ),
        }
    }
}

impl fmt::Display for IncrementFailure {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let chatter = |f: &mut fmt::Formatter<'_>, names: &[String], elements: &[usize]| {
            if !names.is_empty() {
                write!(f, "; gaps changing status: {}", name_list(names))?;
            }
            if !elements.is_empty() {
                let numbers: Vec<String> = elements.iter().map(|e| e.to_string()).collect();
                write!(
                    f,
                    "; film elements changing wrinkling state: {}",
                    name_list(&numbers)
                )?;
            }
            Ok(())
        };
        match self {
            Self::MaxIterations {
                first_residual,
                last,
                chattering,
                flipping,
                ..
            } => {
                write!(
                    f,
                    "no convergence within the iteration limit: at iteration {} (the last): {last}, {}; \
                     the residual was {first_residual:.3e} N at iteration 0",
                    last.iteration,
                    last.verdict()
                )?;
                chatter(f, chattering, flipping)
            }
            Self::Stalled {
                iteration,
                closest,
                chattering,
                flipping,
            } => {
                write!(
                    f,
                    "no progress (stopped at iteration {iteration}); closest to convergence at iteration {} \
                     of {iteration}: {closest}, {}",
                    closest.iteration,
                    closest.verdict()
                )?;
                chatter(f, chattering, flipping)
            }
            Self::Diverged { iteration } => {
                write!(
                    f,
                    "diverged (non-finite or runaway residual) at iteration {iteration}"
                )
            }
            Self::Singular { message } => write!(f, "singular Newton matrix ({message})"),
        }
    }
}

/// Why a step failed. The analysis keeps its last converged state.
#[derive(Clone, Debug, PartialEq)]
pub enum StepError {
    /// A target that is not finite, has the wrong length or lies far outside the model's scale.
    InvalidInput { message: String },
    /// The increment could not converge even after the allowed cut-backs.
    NotConverged {
        fraction_done: f64,
        cutbacks: usize,
        last: IncrementFailure,
    },
}

impl StepError {
    /// The message, its advice naming the settings as `names` does (`Display` uses
    /// [`SettingNames::CORE`]).
    pub fn message(&self, names: &SettingNames) -> String {
        match self {
            Self::InvalidInput { message } => format!("invalid step input: {message}"),
            Self::NotConverged {
                fraction_done,
                cutbacks,
                last,
            } => format!(
                "step did not converge after {cutbacks} cut-backs ({:.1}% of it reached; last increment: {last}); \
                 the last converged state is kept. What to change: {}",
                100.0 * fraction_done,
                last.advice(names)
            ),
        }
    }
}

impl fmt::Display for StepError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.message(&SettingNames::CORE))
    }
}

impl std::error::Error for StepError {}

/// Why an analysis cannot be set up.
#[derive(Clone, Debug, PartialEq)]
pub enum SetupError {
    /// The model is invalid.
    Model(ModelError),
    /// The settings are invalid.
    Settings(String),
    /// The system could not be built or analysed.
    System(String),
}

impl fmt::Display for SetupError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Model(e) => write!(f, "{e}"),
            Self::Settings(m) => write!(f, "solver settings: {m}"),
            Self::System(m) => write!(f, "{m}"),
        }
    }
}

impl std::error::Error for SetupError {}

impl From<PatternError> for SetupError {
    fn from(e: PatternError) -> Self {
        Self::System(e.0)
    }
}

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
    /// Total reaction of each named support set (N), global axes, over its fixed components.
    pub support_reactions: Vec<[f64; 3]>,
    /// Sum of all restraint forces on the film (N): supports, symmetry planes and groups (the
    /// gaps' forces on their support points are reported per gap, not here).
    pub total_reaction: [f64; 3],
    /// Restraint force on each node (N), global axes: `f_int − f_ext` at its supported,
    /// symmetry-fixed and prescribed components, 0 at its free ones (the nodal reactions that
    /// [`super::lines`] spreads along groups and support sets).
    #[serde(default)]
    pub node_reactions: Vec<[f64; 3]>,
    /// Stress state of each triangle.
    pub elements: Vec<ElementStress>,
    /// Displacement of each output point of the model (m).
    pub points: Vec<[f64; 3]>,
    /// Field summary of each element set of the model.
    pub sets: Vec<FieldSummary>,
}

impl Results {
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

/// A model under analysis: the system, its factorization and the last converged state.
#[derive(Clone, Debug)]
pub struct Analysis {
    model: Model,
    system: System,
    laws: Vec<GapLaw>,
    settings: SolverSettings,
    linear: LinearSolver,
    loads: Loads,
    /// Tension-only edge cables.
    cables: Cables,
    /// Node-to-surface contacts on curved supports.
    surfaces: SurfaceContacts,
    state: AnalysisState,
    work: Workspace,

    /// Bounding-box diagonal `L` of the model (m): the length scale of the tolerances and of
    /// the input check.
    length_scale: f64,
    /// `1e-6·E·t·L` (N): the force scale of an unloaded film.
    force_floor: f64,
}

/// Buffers reused by every iteration.
#[derive(Clone, Debug)]
struct Workspace {
    /// Whether the line search may keep full steps that raise the residual (its watchdog):
    /// until an increment of the step has been cut back.
    watchdog: bool,
    internal: Vec<f64>,
    values: Vec<f64>,
    rhs: Vec<f64>,
    responses: Vec<GapResponse>,
    /// Gaps latched in slip for the rest of the Newton loop (§3(f)) with their slip direction.
    latched: Vec<Option<Vector2<f64>>>,
    /// Gaps found closed at some iteration of the current Newton loop.
    closed: Vec<bool>,
    /// Slot of each free DOF's diagonal entry in `values` (for the Levenberg–Marquardt shift).
    diagonal: Vec<usize>,
    /// Curved-support contact histories at the start of the increment, and the responses at
    /// the last assembled iterate.
    contact_start: Vec<ContactHistory>,
    contact_responses: Vec<ContactResponse>,
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

    /// Moves every boundary group to the translation `target` (m) and the hinge angle
    /// `angles` (rad, one per group: 0 for a group without a hinge), and the loads to `loads`;
    /// see [`Self::step_to_with_loads`]. The angles are interpolated linearly like the
    /// translations, so a group turns about its hinge along the arc, not along the chord.
    pub fn step_to_motion(
        &mut self,
        target: &[[f64; 3]],
        angles: &[f64],
        loads: &LoadLevels,
        increments: usize,
    ) -> Result<StepReport, StepError> {
        self.check_targets(target)?;
        self.check_angles(angles)?;
        self.check_loads(loads)?;
        if increments == 0 {
            return Err(StepError::InvalidInput {
                message: "increments must be at least 1".into(),
            });
        }
        let base = self.state.boundary.clone();
        let base_angles = self.state.angles.clone();
        let base_loads = self.state.loads.clone();
        let mut current = self.state.clone();
        let mut report = StepReport::default();
        let largest = 1.0 / increments as f64;
        let smallest = largest / 2f64.powi(self.settings.max_cutbacks as i32);
        let (mut done, mut size) = (0.0_f64, largest);
        // Ju–Rowlands iterations converge linearly whatever the increment: never "hard".
        let hard = match self.settings.iteration_matrix {
            IterationMatrix::Consistent => {
                Self::HARD_ITERATIONS.min(self.settings.max_iterations / 2 + 1)
            }
            IterationMatrix::JuRowlands => usize::MAX,
        };
        // The group translations and angles at the fraction `f` of the step.
        let at = |f: f64| -> GroupMotion {
            GroupMotion {
                translation: base
                    .iter()
                    .zip(target)
                    .map(|(b, t)| std::array::from_fn(|c| b[c] + (t[c] - b[c]) * f))
                    .collect(),
                angles: base_angles
                    .iter()
                    .zip(angles)
                    .map(|(b, t)| b + (t - b) * f)
                    .collect(),
            }
        };
        while done < 1.0 {
            let next = if done + size > 1.0 - 1e-12 {
                1.0
            } else {
                done + size
            };
            let levels = base_loads.interpolate(loads, next);
            // Once an increment of this step has been cut back, the rest of the step is solved
            // by LU where the LU is cheap: the unpivoted LDLᵀ and its Woodbury or Krylov solves
            // are fast on ordinary iterations, but on the edge of a mechanism (a film slack
            // across, gaps opening) LU's pivoting was measured to converge where they stall
            // (robustness bench: arch-edge family with GMRES, two strip paths with Woodbury).
            // On large meshes the LU is not affordable (10 GiB at 1 M DOF): the fast paths stay,
            // every solution still checked.
            let lu_after_cutback = self.linear.lu_affordable();
            self.linear
                .set_fast(report.cutbacks == 0 || !lu_after_cutback);
            // Likewise the watchdog: after a cut-back, monotone backtracking only (a failed
            // excursion per halved increment was measured to turn a hard path into a failure).
            self.work.watchdog = report.cutbacks == 0;
            match self.solve_increment(&current, &at(next), &levels) {
                Ok((state, history)) => {
                    current = state;
                    done = next;
                    let iterations = history.len() - 1;
                    report.iterations.push(iterations);
                    report.residual = *history.last().unwrap_or(&0.0);
                    report.residual_history = history;
                    // Easy increments let the size grow back; hard ones shrink it before a
                    // failure does.
                    if iterations <= Self::EASY_ITERATIONS {
                        size = (2.0 * size).min(largest);
                    } else if iterations >= hard && size / 2.0 >= smallest {
                        size /= 2.0;
                    }
                }
                Err(last) => {
                    if size / 2.0 >= smallest * (1.0 - 1e-9) {
                        report.cutbacks += 1;
                        size /= 2.0;
                        continue;
                    }
                    // Every smaller increment failed: try larger ones before giving up.
                    let mut larger = 2.0 * largest;
                    let mut reached = None;
                    while reached.is_none() && larger < 2.0 * (1.0 - done) {
                        let next = (done + larger).min(1.0);
                        let levels = base_loads.interpolate(loads, next);
                        self.linear.set_fast(!lu_after_cutback);
                        if let Ok(converged) = self.solve_increment(&current, &at(next), &levels) {
                            reached = Some((next, converged));
                        }
                        larger *= 2.0;
                    }
                    let Some((next, (state, history))) = reached else {
                        return Err(StepError::NotConverged {
                            fraction_done: done,
                            cutbacks: report.cutbacks,
                            last,
                        });
                    };
                    report.enlarged += 1;
                    current = state;
                    done = next;
                    report.iterations.push(history.len() - 1);
                    report.residual = *history.last().unwrap_or(&0.0);
                    report.residual_history = history;
                    size = largest;
                }
            }
        }
        self.state = current;
        self.linear.set_fast(true);
        Ok(report)
    }

    /// Converged increments with at most this many iterations let the increment grow.
    const EASY_ITERATIONS: usize = 5;
    /// Converged increments with at least this many iterations (or half the limit) shrink the
    /// next one (consistent tangent only).
    const HARD_ITERATIONS: usize = 15;

    /// Refuses targets of the wrong length, non-finite or beyond
    /// [`Self::MAX_TARGET_PER_SIZE`] times the model's size.
    fn check_targets(&self, target: &[[f64; 3]]) -> Result<(), StepError> {
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
    fn check_angles(&self, angles: &[f64]) -> Result<(), StepError> {
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
    fn prescribed_value(
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
    fn check_loads(&self, loads: &LoadLevels) -> Result<(), StepError> {
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

    /// Newton–Raphson for one increment from the converged `start` to the group motion
    /// `motion` and the load levels `levels`.
    fn solve_increment(
        &mut self,
        start: &AnalysisState,
        motion: &GroupMotion,
        levels: &LoadLevels,
    ) -> Result<(AnalysisState, Vec<f64>), IncrementFailure> {
        let mut u = start.displacement.clone();
        // Predictor: when the boundary keeps moving the same way, extrapolate the free DOFs
        // along the last converged increment (fewer iterations, same converged answer).
        let (mut dot, mut old, mut new) = (0.0, 0.0, 0.0);
        for (i, d) in self.system.dofs.iter().enumerate() {
            if let Dof::Prescribed { group, component } = d {
                let value = self.prescribed_value(i, *group, *component, motion);
                let step = value - start.displacement[i];
                let last = start.last_increment.get(i).copied().unwrap_or(0.0);
                (dot, old, new) = (dot + step * last, old + last * last, new + step * step);
                u[i] = value;
            }
        }
        if old > 0.0 && dot > 0.99 * (old * new).sqrt() {
            // Not beyond twice the last increment: an enlarged increment (see `step_to`) would
            // otherwise extrapolate the film far outside the range where the last one tells
            // anything (residuals of 1e11 N were measured at its first iterate).
            let ratio = (dot / old).min(Self::PREDICTOR_LIMIT);
            for (i, d) in self.system.dofs.iter().enumerate() {
                if let Dof::Free(_) = d {
                    u[i] += ratio * start.last_increment[i];
                }
            }
        }
        let (laws, history) = self.laws_and_history(start);
        self.work.contact_start.clone_from(&start.contacts);
        self.work.latched.iter_mut().for_each(|l| *l = None);
        self.work.closed.iter_mut().for_each(|c| *c = false);
        // A model without free DOFs (every node prescribed or fixed: how single elements are
        // verified) has nothing to solve: the first assembly evaluates the forces, the gaps'
        // return mapping and the reactions at the prescribed configuration, and converges.
        let mut correction_norm = if self.system.free_count == 0 {
            0.0
        } else {
            f64::INFINITY
        };
        // The iterate before the last correction (to name elements whose state flips).
        let mut previous_u = u.clone();
        let mut residuals = Vec::new();
        let mut assembled = false;
        // Status of every gap at the previous iteration and the last iteration it changed.
        let mut previous: Vec<GapStatus> = start.status.clone();
        let mut changed_at: Vec<Option<usize>> = vec![None; previous.len()];
        let (mut best, mut best_correction, mut best_at) = (f64::INFINITY, f64::INFINITY, 0);
        // The iterate closest to meeting both tolerances (quoted if the increment stalls).
        let mut closest: Option<IterationRecord> = None;
        // Levenberg–Marquardt shift of the free diagonal, relative to its mean.
        let mut damping = 0.0_f64;
        // The watchdog of the line search: non-monotone excursions until one fails.
        let mut watch = if self.work.watchdog {
            Watchdog::Ready
        } else {
            Watchdog::Used
        };
        let s = self.settings;
        for iteration in 0..=s.max_iterations {
            let residual = if assembled {
                self.free_norm_inf()
            } else {
                self.assemble_at(&u, &laws, &history, levels, Some(iteration))
            };
            if !residual.is_finite() {
                return Err(IncrementFailure::Diverged { iteration });
            }
            residuals.push(residual);
            for (g, r) in self.work.responses.iter().enumerate() {
                if r.status != previous[g] {
                    previous[g] = r.status;
                    changed_at[g] = Some(iteration);
                }
            }
            let moved = max_abs_difference(&u, &start.displacement);
            let displacement_scale = moved.max(max_abs(&u)).max(1e-9 * self.length_scale);
            let force_scale = max_abs(&self.work.internal).max(self.force_floor);
            let tolerance = s.residual_tolerance * force_scale;
            let record = IterationRecord {
                iteration,
                residual,
                residual_tolerance: tolerance,
                correction: correction_norm,
                correction_tolerance: s.displacement_tolerance * displacement_scale,
            };
            let converged = (iteration > 0 || self.system.free_count == 0)
                && record.correction <= record.correction_tolerance
                && residual <= tolerance;
            if converged {
                let state = AnalysisState {
                    plastic_slip: self
                        .work
                        .responses
                        .iter()
                        .map(|r| r.plastic_slip.into())
                        .collect(),
                    contacts: SurfaceContacts::commit(
                        &self.work.contact_responses,
                        &start.contacts,
                    ),
                    boundary: motion.translation.clone(),
                    angles: motion.angles.clone(),
                    loads: levels.clone(),
                    friction: start.friction.clone(),
                    status: self.work.responses.iter().map(|r| r.status).collect(),
                    last_increment: u
                        .iter()
                        .zip(&start.displacement)
                        .map(|(a, b)| a - b)
                        .collect(),
                    displacement: u,
                };
                if !state.is_finite() {
                    return Err(IncrementFailure::Diverged { iteration });
                }
                return Ok((state, residuals));
            }
            // Gaps that changed status in the last few iterations: the usual cause of a stall.
            let recent = iteration.saturating_sub(Self::STALL_PATIENCE / 2);
            let chattering = || -> Vec<String> {
                changed_at
                    .iter()
                    .enumerate()
                    .filter(|(_, c)| c.is_some_and(|c| c > 0 && c >= recent))
                    .map(|(g, _)| self.model.gaps[g].name.clone())
                    .collect()
            };
            if iteration > 0 && closest.is_none_or(|c| record.distance() < c.distance()) {
                closest = Some(record);
            }
            if iteration == s.max_iterations {
                return Err(IncrementFailure::MaxIterations {
                    first_residual: residuals[0],
                    last: record,
                    matrix: s.iteration_matrix,
                    chattering: chattering(),
                    flipping: self.flipping_elements(&previous_u, &u),
                });
            }
            if iteration > 3 && residual > 1e6 * residuals[0].max(force_scale) {
                return Err(IncrementFailure::Diverged { iteration });
            }
            // Progress is a residual or a correction 10 % below the best so far: a cycle between
            // two states repeats both to round-off and never makes it, while the slow approach
            // along a soft direction of the film (small residual, shrinking corrections) does. The Ju–Rowlands matrix converges
            // linearly and slowly by design (docs/mechanics.md): it is judged by the limit only.
            if residual < Self::PROGRESS * best
                || correction_norm < Self::PROGRESS * best_correction
            {
                best = best.min(residual);
                best_correction = best_correction.min(correction_norm);
                best_at = iteration;
            } else if s.iteration_matrix == IterationMatrix::Consistent
                && iteration >= best_at + Self::STALL_PATIENCE
            {
                return Err(IncrementFailure::Stalled {
                    iteration,
                    closest: closest.unwrap_or(record),
                    chattering: chattering(),
                    flipping: self.flipping_elements(&previous_u, &u),
                });
            }
            for (i, d) in self.system.dofs.iter().enumerate() {
                if let Dof::Free(eq) = d {
                    self.work.rhs[*eq] = -self.work.internal[i];
                }
            }
            if damping > 0.0 {
                let values = &mut self.work.values;
                let mean = self
                    .work
                    .diagonal
                    .iter()
                    .map(|&d| values[d].abs())
                    .sum::<f64>()
                    / self.work.diagonal.len() as f64;
                for &d in &self.work.diagonal {
                    values[d] += damping * mean;
                }
            }
            let matrix = self.system.matrix(&self.work.values);
            self.linear
                .factorize_and_solve(matrix, &mut self.work.rhs)
                .map_err(|e| IncrementFailure::Singular { message: e.0 })?;
            correction_norm = max_abs(&self.work.rhs);
            if !correction_norm.is_finite() {
                return Err(IncrementFailure::Diverged { iteration });
            }
            previous_u.clone_from(&u);
            let (step, with_tangent, decreased) =
                self.line_search(&mut u, &laws, &history, levels, iteration + 1, &mut watch);
            assembled = with_tangent;
            if step.is_infinite() {
                // The watchdog went back to where its excursion started: the iterations spent
                // on it are not a stall of the iteration from here.
                best_at = iteration + 1;
            }
            correction_norm *= step;
            // Levenberg–Marquardt: a direction that cannot lower the residual (a mechanism of an
            // unstressed film, an indefinite compressed one) gets a diagonal shift, raised until
            // steps succeed and lowered again after full ones. Only the iteration matrix changes,
            // never the residual: the converged state is the same, and with the shift gone the
            // last iterations are Newton's again.
            if s.iteration_matrix == IterationMatrix::Consistent {
                damping = if !decreased {
                    (4.0 * damping).max(Self::DAMPING_START)
                } else if step == 1.0 && damping > 0.0 {
                    let lower = damping / 4.0;
                    if lower < Self::DAMPING_START / 64.0 {
                        0.0
                    } else {
                        lower
                    }
                } else {
                    damping
                };
            }
        }
        unreachable!("the loop returns at max_iterations")
    }

    /// Film elements whose tension-field state differs between the displacements `a` and `b`
    /// (none without wrinkling). Called once when an increment fails, never per iteration.
    fn flipping_elements(&self, a: &[f64], b: &[f64]) -> Vec<usize> {
        if self.system.material.wrinkling == Wrinkling::None {
            return vec![];
        }
        let state = |u: &[f64], nodes: &[usize; 3], tri: &MembraneTriangle| {
            let dofs = node_dofs(nodes);
            let ue = ElementVector::from_fn(|i, _| u[dofs[i]]);
            tri.stress_state(&self.system.material, &ue).state
        };
        self.system
            .triangles
            .iter()
            .enumerate()
            .filter(|(_, (nodes, tri))| state(a, nodes, tri) != state(b, nodes, tri))
            .map(|(e, _)| e)
            .collect()
    }

    /// Largest ratio of the predictor's extrapolation to the last converged increment.
    const PREDICTOR_LIMIT: f64 = 2.0;

    /// First Levenberg–Marquardt shift (fraction of the mean diagonal of the Newton matrix).
    const DAMPING_START: f64 = 1e-4;
    /// A residual below this fraction of the best so far counts as progress.
    const PROGRESS: f64 = 0.9;
    /// Iterations without progress before an increment is declared stalled and cut back.
    const STALL_PATIENCE: usize = 8;

    /// Applies the Newton correction held in `work.rhs` to `u`, scaled by a backtracking line
    /// search on `φ(α) = ½‖R_free(u + αΔ)‖₂²` (the full step when line search is off). Returns
    /// the scale used, whether the workspace now holds the residual and Newton matrix at the
    /// new `u` (assembled for `next_iteration`), and whether the step decreased `φ` enough.
    ///
    /// Backtracking (Dennis & Schnabel, *Numerical Methods for Unconstrained Optimization*,
    /// §6.3.2): accept the first `α` with `φ(α) ≤ (1 − 2·10⁻⁴ α) φ(0)` (Armijo, with
    /// `φ'(0) = −‖R‖²` for a Newton direction); otherwise the next trial is the minimum of the
    /// parabola through `φ(0)`, `φ'(0)`, `φ(α)`, kept within `[α/10, α/2]`. A gap that opens or
    /// closes makes `R` only piecewise smooth: a closing penalty gap can raise `φ(1)` by orders of
    /// magnitude while the equilibrium lies at `α ≈ 10⁻³`, which the interpolation reaches in a
    /// few trials where plain halving would need ten. When no trial decreases `φ`, the best one
    /// is taken (with `α ≥ 1/8` for the Ju–Rowlands matrix); Newton continues from there and a
    /// cycle is caught by the stall test.
    fn line_search(
        &mut self,
        u: &mut [f64],
        laws: &[GapLaw],
        history: &[Vector2<f64>],
        levels: &LoadLevels,
        next_iteration: usize,
        watch: &mut Watchdog,
    ) -> (f64, bool, bool) {
        let apply = |u: &mut [f64], dofs: &[Dof], delta: &[f64], scale: f64| {
            for (i, d) in dofs.iter().enumerate() {
                if let Dof::Free(eq) = d {
                    u[i] += scale * delta[*eq];
                }
            }
        };
        let delta = std::mem::take(&mut self.work.rhs);
        if !self.settings.line_search {
            apply(u, &self.system.dofs, &delta, 1.0);
            self.work.rhs = delta;
            return (1.0, false, true);
        }
        let phi0 = 0.5 * self.free_norm2().powi(2);
        let consistent = self.settings.iteration_matrix == IterationMatrix::Consistent;
        // The contact statuses at this iterate: a full step that changes one crosses into
        // another branch of the piecewise law, where the watchdog's premise fails.
        let statuses = |w: &Workspace| -> Vec<GapStatus> {
            w.responses
                .iter()
                .map(|r| r.status)
                .chain(w.contact_responses.iter().map(|r| r.status))
                .collect()
        };
        if let Watchdog::Watching {
            start,
            phi,
            left,
            status,
        } = watch
        {
            // Full Newton steps while the excursion lasts; back to its start if it fails.
            apply(u, &self.system.dofs, &delta, 1.0);
            self.assemble_at(u, laws, history, levels, Some(next_iteration));
            let now = 0.5 * self.free_norm2().powi(2);
            self.work.rhs = delta;
            let same = *status == statuses(&self.work);
            if same && now <= (1.0 - 2e-4) * *phi {
                // It paid: the next full step that raises the residual may be kept again.
                *watch = Watchdog::Ready;
            } else if same && now.is_finite() && *left > 1 {
                *left -= 1;
            } else {
                u.copy_from_slice(start);
                self.assemble_at(u, laws, history, levels, Some(next_iteration));
                *watch = Watchdog::Used;
                // No correction measured: the restored iterate cannot pass for converged.
                return (f64::INFINITY, true, true);
            }
            return (1.0, true, true);
        }
        let (mut best, mut best_phi, mut applied) = (1.0, f64::INFINITY, 0.0);
        let mut scale: f64 = 1.0;
        let before = matches!(watch, Watchdog::Ready).then(|| statuses(&self.work));
        for trial in 0..Self::LINE_SEARCH_TRIALS {
            apply(u, &self.system.dofs, &delta, scale - applied);
            applied = scale;
            // The full step is usually accepted: assemble its tangent too, for the next iteration.
            let tangent = (trial == 0).then_some(next_iteration);
            self.assemble_at(u, laws, history, levels, tangent);
            let phi = 0.5 * self.free_norm2().powi(2);
            if phi <= (1.0 - 2e-4 * scale) * phi0 {
                self.work.rhs = delta;
                return (scale, trial == 0, true);
            }
            // Only with room to spare: a failed excursion must not eat the iteration limit.
            if trial == 0
                && consistent
                && phi.is_finite()
                && next_iteration + 2 * Self::WATCHDOG_STEPS <= self.settings.max_iterations
                && before.as_ref().is_some_and(|b| *b == statuses(&self.work))
            {
                // A full Newton step that raises the residual is often the way to a
                // solution that backtracking crawls to (a flat film taking its first load:
                // 18 damped iterations against 6 full ones): keep it for a few iterations and
                // return to this point if the residual has not fallen below it by then.
                let mut start = u.to_vec();
                apply(&mut start, &self.system.dofs, &delta, -1.0);
                *watch = Watchdog::Watching {
                    start,
                    phi: phi0,
                    left: Self::WATCHDOG_STEPS,
                    status: statuses(&self.work),
                };
                self.work.rhs = delta;
                return (1.0, true, true);
            }
            if phi < best_phi && (scale >= Self::SMALLEST_FALLBACK || consistent) {
                (best, best_phi) = (scale, phi);
            }
            // Minimum of q(α) = φ0 − 2φ0 α + (φ − φ0 + 2φ0 α0) α²/α0², clamped.
            let curvature = (phi - phi0 + 2.0 * phi0 * scale) / (scale * scale);
            let next = if curvature.is_finite() && curvature > 0.0 {
                phi0 / curvature
            } else {
                0.5 * scale
            };
            scale = next.clamp(0.1 * scale, 0.5 * scale);
        }
        apply(u, &self.system.dofs, &delta, best - applied);
        self.work.rhs = delta;
        (best, false, false)
    }

    /// Trials of the line search before it takes the best one.
    const LINE_SEARCH_TRIALS: usize = 8;
    /// Full Newton steps the watchdog allows beyond the one that raised the residual.
    const WATCHDOG_STEPS: usize = 6;
    /// Smallest scale the Ju–Rowlands iteration takes when no trial decreases `φ`: a tiny step
    /// would freeze it (its direction is not Newton's, it relies on moving on). With the
    /// consistent tangent the best trial is taken whatever its size: a full step that raised the
    /// residual by eight orders of magnitude was measured to wreck an increment that was one
    /// iteration from convergence.
    const SMALLEST_FALLBACK: f64 = 0.125;

    /// The moment of each group's reaction about its hinge axis (see [`Results::moments`]).
    fn hinge_moments(&self) -> Vec<f64> {
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

    /// `‖R_free‖∞` of the last assembly.
    fn free_norm_inf(&self) -> f64 {
        max_abs(
            self.system
                .dofs
                .iter()
                .zip(&self.work.internal)
                .filter(|(d, _)| matches!(d, Dof::Free(_)))
                .map(|(_, r)| r),
        )
    }

    /// `‖R_free‖₂` of the last assembly.
    fn free_norm2(&self) -> f64 {
        self.system
            .dofs
            .iter()
            .zip(&self.work.internal)
            .filter(|(d, _)| matches!(d, Dof::Free(_)))
            .map(|(_, r)| r * r)
            .sum::<f64>()
            .sqrt()
    }

    /// Assembles the residual `f_int − f_ext` over all DOFs (and the Newton matrix when
    /// `iteration` is given) at `u` with the loads at `levels`; returns `‖R_free‖∞`. Gap
    /// responses are left in the workspace.
    fn assemble_at(
        &mut self,
        u: &[f64],
        laws: &[GapLaw],
        history: &[Vector2<f64>],
        levels: &LoadLevels,
        iteration: Option<usize>,
    ) -> f64 {
        let mode = self.settings.iteration_matrix;
        let Workspace {
            internal,
            values,
            responses,
            latched,
            closed,
            contact_start,
            contact_responses,
            ..
        } = &mut self.work;
        let mut values = iteration.map(|_| values.as_mut_slice());
        self.system
            .assemble(u, internal, values.as_deref_mut(), |g, d| {
                let law = &laws[g];
                let response = law.evaluate(d, history[g]);
                responses[g] = response;
                let matrix = match mode {
                    IterationMatrix::Consistent => law.consistent_tangent(&response),
                    IterationMatrix::JuRowlands => {
                        // §3(b): stick in the first iteration; §3(f): once slipping, the slip matrix is
                        // kept, with the slip direction (and its sign) found when the gap started
                        // slipping, until the loop ends.
                        // A latched gap keeps the slip matrix even if the law finds it open, and a gap
                        // that has closed in this loop keeps at least the stick matrix: both stop the
                        // open ↔ closed chatter of a symmetric matrix that has no cone direction.
                        closed[g] |= response.status != GapStatus::Open;
                        if response.status == GapStatus::Slip
                            && iteration != Some(0)
                            && latched[g].is_none()
                        {
                            latched[g] = Some(response.direction);
                        }
                        match (latched[g], response.status, iteration) {
                            (Some(direction), _, _) => {
                                law.ju_rowlands_matrix(GapStatus::Slip, direction)
                            }
                            (None, GapStatus::Open, _) if !closed[g] => {
                                law.ju_rowlands_matrix(GapStatus::Open, response.direction)
                            }
                            (None, _, _) => {
                                law.ju_rowlands_matrix(GapStatus::Stick, response.direction)
                            }
                        }
                    }
                };
                (response.force, matrix)
            });
        self.loads
            .add_to(&self.system, levels, u, internal, values.as_deref_mut());
        self.cables
            .add_to(&self.system, levels, u, internal, values.as_deref_mut());
        self.surfaces.add_to(
            &self.system,
            u,
            contact_start,
            internal,
            values,
            contact_responses,
        );
        self.free_norm_inf()
    }

    /// Gap laws with the friction coefficients of `state`, and its slip history.
    fn laws_and_history(&self, state: &AnalysisState) -> (Vec<GapLaw>, Vec<Vector2<f64>>) {
        let laws = self
            .laws
            .iter()
            .zip(&state.friction)
            .map(|(l, &mu)| GapLaw { friction: mu, ..*l })
            .collect();
        let history = state
            .plastic_slip
            .iter()
            .map(|s| Vector2::from(*s))
            .collect();
        (laws, history)
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

/// The line search's watchdog (Chamberlain et al., 1982): a full Newton step that raised the
/// residual may be kept for a few more full steps; after an excursion that failed, the rest of
/// the increment backtracks monotonically.
enum Watchdog {
    /// May start an excursion (none yet in this increment, or the last one paid).
    Ready,
    /// Full steps since `start`, whose merit was `phi`; `left` of them remain while the
    /// contact statuses stay `status`.
    Watching {
        start: Vec<f64>,
        phi: f64,
        left: usize,
        status: Vec<GapStatus>,
    },
    /// An excursion failed: monotone backtracking for the rest of the increment.
    Used,
}

/// `max |v|`, NaN when any value is NaN (`f64::max` alone would skip a NaN and report the
/// rest: a NaN residual would then measure 0 and pass a convergence test).
pub fn max_abs<'a>(values: impl IntoIterator<Item = &'a f64>) -> f64 {
    values.into_iter().fold(0.0, |m, v| nan_max(m, v.abs()))
}

/// `max(m, v)` that keeps a NaN of either argument.
fn nan_max(m: f64, v: f64) -> f64 {
    if v.is_nan() || m.is_nan() {
        f64::NAN
    } else {
        m.max(v)
    }
}

/// `max |a − b|` over two equally long vectors, NaN-aware like [`max_abs`].
fn max_abs_difference(a: &[f64], b: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .fold(0.0, |m, (x, y)| nan_max(m, (x - y).abs()))
}

/// Slot of each equation's diagonal entry in the value array (the pattern keeps them all).
fn diagonal_slots(system: &System) -> Vec<usize> {
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

/// Diagonal of the axis-aligned bounding box of `nodes` (m).
pub fn bounding_diagonal(nodes: &[[f64; 3]]) -> f64 {
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for p in nodes {
        for c in 0..3 {
            lo[c] = lo[c].min(p[c]);
            hi[c] = hi[c].max(p[c]);
        }
    }
    (0..3).map(|c| (hi[c] - lo[c]).powi(2)).sum::<f64>().sqrt()
}

#[cfg(test)]
mod advice_tests {
    use super::*;

    fn record(residual: f64, correction: f64) -> IterationRecord {
        IterationRecord {
            iteration: 9,
            residual,
            residual_tolerance: 1.374e-4,
            correction,
            correction_tolerance: 1.0e-8,
        }
    }

    fn stall(closest: IterationRecord) -> IncrementFailure {
        IncrementFailure::Stalled {
            iteration: 17,
            closest,
            chattering: vec![],
            flipping: vec![],
        }
    }

    #[test]
    fn a_stall_quotes_one_iteration_and_says_which_criterion_failed() {
        let names = SettingNames::CORE;
        let within = stall(record(6.996e-5, 3.2e-6));
        let text = within.to_string();
        assert_eq!(
            text,
            "no progress (stopped at iteration 17); closest to convergence at iteration 9 of 17: \
             correction 3.200e-6 m (tolerance 1.000e-8 m), residual 6.996e-5 N (tolerance 1.374e-4 N), \
             the residual met its tolerance, the correction did not"
        );
        let advice = within.advice(&names);
        assert!(advice.contains("displacement_tolerance"), "{advice}");
        assert!(!advice.contains("almost no stiffness"), "{advice}");
        let above = stall(record(2.0e-4, 1.0e-9));
        assert!(
            above
                .to_string()
                .ends_with("the correction met its tolerance, the residual did not"),
            "{above}"
        );
        assert!(above.advice(&names).contains("residual_tolerance"));
        assert!(
            stall(record(2.0e-4, 3.2e-6))
                .to_string()
                .ends_with("neither met its tolerance")
        );
    }

    fn out_of_iterations(first: f64, last: f64, matrix: IterationMatrix) -> String {
        IncrementFailure::MaxIterations {
            first_residual: first,
            last: record(last, 1.0),
            matrix,
            chattering: vec![],
            flipping: vec![],
        }
        .advice(&SettingNames::CORE)
    }

    #[test]
    fn advice_to_raise_the_limit_only_while_the_residual_falls() {
        let consistent = IterationMatrix::Consistent;
        assert!(out_of_iterations(1.0, 1e-3, consistent).contains("still falling"));
        let rose = out_of_iterations(9.4e-3, 2.9e-2, consistent);
        assert!(
            !rose.contains("still falling") && rose.contains("less per step"),
            "{rose}"
        );
        let jr = out_of_iterations(4.9, 3.4, IterationMatrix::JuRowlands);
        assert!(jr.contains("consistent tangent"), "{jr}");
    }

    #[test]
    fn advice_names_the_settings_of_the_front_end_that_asks() {
        let cli = SettingNames {
            finer_increments: "raise --increments",
            ..SettingNames::CORE
        };
        let failure = stall(record(2.0e-4, 1.0e-9));
        assert!(failure.advice(&cli).contains("(raise --increments)"));
        assert!(!failure.advice(&SettingNames::CORE).contains("--"));
    }
}
