//! What a step reports: Newton statistics, why an increment failed (with advice naming the
//! front end's settings), and the errors of a step and of setting an analysis up.

use crate::mech::elements::load::LoadLevels;
use std::fmt;

use crate::mech::elements::gap::IterationMatrix;
use crate::mech::model::ModelError;
use crate::mech::solve::assembly::PatternError;
use serde::{Deserialize, Serialize};

/// Newton statistics of one step, and its energy ledger.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct StepReport {
    /// Newton iterations of each converged increment.
    pub iterations: Vec<usize>,
    /// Increments halved.
    pub cutbacks: usize,
    /// Final residual `‖R_free‖∞` of the model (N); for an answer the viscous stabilization
    /// still acts on, the damped residual plus the largest damping force, which bound it.
    pub residual: f64,
    /// `‖R_free‖∞` at every iteration of the last converged increment (N).
    pub residual_history: Vec<f64>,
    /// Every increment tried, in order: the strategy table's row, the share of the step, the
    /// iterations and whether it converged.
    #[serde(default)]
    pub attempts: Vec<Attempt>,
    /// Increments solved with the viscous stabilization on (`contributions/stabilization.rs`).
    #[serde(default)]
    pub stabilized: usize,
    /// Work of the viscous stabilization's force over the step's last increment (J): the force
    /// the converged answer still carries (0 where the last increment was solved without it).
    #[serde(default)]
    pub stabilization_energy: f64,
    /// Work of the viscous stabilization over all the step's increments (J): what the damping
    /// took out on the way to the converged state (Abaqus' ALLSD), judged against the strain
    /// energy ([`Self::dissipation_warning`]).
    #[serde(default)]
    pub stabilization_dissipated: f64,
    /// Work of the pseudo-time term over the step's iterations (J): the continuation's path to
    /// each converged increment; the converged answers carry none of it.
    #[serde(default)]
    pub pseudo_time_work: f64,
    /// Elastic strain energy of the film at the end of the step (J), `Σ A t ½ (S − S0)·E`:
    /// the scale of [`Self::stabilization_ratio`].
    #[serde(default)]
    pub strain_energy: f64,
}

/// One increment tried by the controller (`increments.rs`).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Attempt {
    /// Its row of the strategy table ([`crate::mech::solve::STRATEGIES`]).
    pub strategy: usize,
    /// The share of the step at its start and at its end.
    pub from: f64,
    pub to: f64,
    /// Newton iterations, converged or refused (the cost of a refusal: [`IncrementFailure::iterations`]).
    pub iterations: usize,
    /// Whether it converged.
    pub converged: bool,
}

/// Largest ratio of the work the stabilization's force still does in the converged answer
/// ([`StepReport::stabilization_energy`]) to the strain energy that is reported as plain
/// success: the dissipated-energy fraction of Abaqus' automatic stabilization, 2e-4.
pub const STABILIZATION_BOUND: f64 = 2e-4;

/// Largest ratio of the stabilization's work over the whole step
/// ([`StepReport::stabilization_dissipated`]) to the strain energy that is reported without a
/// warning: Abaqus' accuracy tolerance of the adaptive stabilization (ALLSD/ALLIE), 0.05. A step
/// that took out more than the strain energy is refused.
pub const DISSIPATION_BOUND: f64 = 0.05;

impl StepReport {
    /// Notes an increment that converged with the residual `history` (one per iterate).
    pub(crate) fn note_converged(&mut self, history: Vec<f64>, damping_force: f64) {
        self.iterations.push(history.len().saturating_sub(1));
        self.residual = history.last().unwrap_or(&0.0) + damping_force;
        self.residual_history = history;
    }

    /// [`Self::stabilization_energy`] over [`Self::strain_energy`] (0 without stabilization).
    pub fn stabilization_ratio(&self) -> f64 {
        ratio(self.stabilization_energy, self.strain_energy)
    }

    /// [`Self::stabilization_dissipated`] over [`Self::strain_energy`] (0 without
    /// stabilization).
    pub fn dissipation_ratio(&self) -> f64 {
        ratio(self.stabilization_dissipated, self.strain_energy)
    }

    /// The warning of a step whose answer still carries more stabilization work than
    /// [`STABILIZATION_BOUND`] of the strain energy (None: within it, or no stabilization).
    pub fn stabilization_warning(&self) -> Option<String> {
        let ratio = self.stabilization_ratio();
        (ratio > STABILIZATION_BOUND).then(|| {
            format!(
                "the stabilization left an artificial energy of {:.3e} J, {ratio:.2e} of the \
                 strain energy {:.3e} J, above the bound {STABILIZATION_BOUND:.0e}: the step's equilibrium is \
                 not reached to the model's accuracy",
                self.stabilization_energy, self.strain_energy
            )
        })
    }

    /// The warning of a step whose stabilization took out more than [`DISSIPATION_BOUND`] of
    /// the strain energy over the whole step (Abaqus compares ALLSD with ALLIE over the step, not
    /// over its last increment): its path is the damped flow's, and where the damping took out
    /// more than the film stores, the state is the damping's choice rather than the model's
    /// (None: within the bound).
    pub fn dissipation_warning(&self) -> Option<String> {
        let ratio = self.dissipation_ratio();
        (ratio > DISSIPATION_BOUND).then(|| {
            let verdict = if ratio > 1.0 {
                "more than the film stores: the state reached is the damping's, not an equilibrium \
                 the model determines; check the inputs (a rail driven into a support, a target \
                 beyond the film's reach) and the reactions before using it"
            } else {
                "the path inside the step (slips, plastic flow) is the damped flow's, not a \
                 quasi-static one"
            };
            format!(
                "the viscous stabilization took out {:.3e} J over the step, {ratio:.2e} of the \
                 strain energy {:.3e} J (bound {DISSIPATION_BOUND}): {verdict}",
                self.stabilization_dissipated, self.strain_energy
            )
        })
    }

    /// Total Newton iterations (converged increments only).
    pub fn total_iterations(&self) -> usize {
        self.iterations.iter().sum()
    }

    /// The attempts beyond the first row of the strategy table, for a log line: "" where none,
    /// else "; increments " and how many each row solved.
    pub fn attempts(&self) -> String {
        let said: Vec<String> = (1..crate::mech::solve::STRATEGIES.len())
            .filter_map(|row| {
                let n = self
                    .attempts
                    .iter()
                    .filter(|a| a.converged && a.strategy == row)
                    .count();
                (n > 0).then(|| format!("{n} {}", crate::mech::solve::STRATEGIES[row].name))
            })
            .collect();
        if said.is_empty() {
            String::new()
        } else {
            format!("; increments {}", said.join(", "))
        }
    }
}

/// `part / whole`, 0 where `part` is 0.
fn ratio(part: f64, whole: f64) -> f64 {
    if part == 0.0 {
        0.0
    } else {
        part / whole.abs().max(f64::MIN_POSITIVE)
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
    pub(crate) fn distance(&self) -> f64 {
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
/// ([`SettingNames::CORE`] names the [`SolverSettings`](super::SolverSettings) fields).
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
    /// How to give the supports and gaps the isotropic friction law.
    pub isotropic_friction: &'static str,
}

impl SettingNames {
    /// The names of the [`SolverSettings`](super::SolverSettings) fields.
    pub const CORE: Self = Self {
        max_iterations: "max_iterations",
        finer_increments: "raise the increments per step",
        residual_tolerance: "residual_tolerance",
        displacement_tolerance: "displacement_tolerance",
        consistent_tangent: "iteration_matrix = Consistent",
        isotropic_friction: "\"friction_law\": \"isotropic\" on those supports or gaps in the model file",
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
        /// Elements of a linear film (`wrinkling: "none"`) in compression (`σ2 < 0`) at the last
        /// iterate.
        compressed: Vec<usize>,
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
        /// Film elements in compression (`σ2 < 0`, no wrinkling) at the last iterate.
        compressed: Vec<usize>,
    },
    /// Not converged after [`Controller`]'s `2 N*` iterations at an iterate that changes a
    /// history (friction slip, plastic flow): halved, so that the path-dependent answer follows
    /// the load path.
    ///
    /// [`Controller`]: crate::mech::solve::increments
    PathDependent { iteration: usize },
    /// NaN/Inf or runaway corrections.
    Diverged { iteration: usize },
    /// The Newton matrix could not be factorized.
    Singular { message: String },
}

impl IncrementFailure {
    /// The Newton iterations made before the failure (0 where the matrix was singular at once).
    pub fn iterations(&self) -> usize {
        match self {
            Self::MaxIterations { last, .. } => last.iteration,
            Self::Stalled { iteration, .. }
            | Self::PathDependent { iteration }
            | Self::Diverged { iteration } => *iteration,
            Self::Singular { .. } => 0,
        }
    }

    /// One phrase for a progress line (the [`fmt::Display`] text has the figures).
    pub fn phrase(&self) -> &'static str {
        match self {
            Self::MaxIterations { .. } => "iteration limit",
            Self::Stalled { .. } => "no progress",
            Self::PathDependent { .. } => "more than 2 N* iterations",
            Self::Diverged { .. } => "diverged",
            Self::Singular { .. } => "singular matrix",
        }
    }
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
            isotropic_friction: _,
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
            // No change is advised here: four times the increments per step, the advice this
            // class had, converged none of the six held-out paths that got it
            // (docs/benchmarks.md, "The refusals' advice followed"), and nothing else has been
            // measured to help yet (issue 19 item 3: advice measured on the case that produced it).
            Self::Stalled { chattering, .. } if !chattering.is_empty() => format!(
                "gaps or curved-support contacts {} kept changing status (open/closed or stick/slip) between \
                 iterations, a cycle between contact states; smaller steps were measured not to settle such \
                 cycles, so no setting is advised",
                name_list(chattering)
            ),
            Self::Stalled { flipping, .. } if !flipping.is_empty() => format!(
                "{} film elements switched between taut, wrinkled and slack between the last iterations \
                 (a region on the verge of wrinkling): move the inputs by less per step ({finer}); more \
                 prestress keeps a film taut; a free film edge in compression has no unique tension-field \
                 equilibrium: if the film may carry compression there, give the material \
                 \"wrinkling\": \"none\" (the paper's linear film, which a file without the entry got before)",
                flipping.len()
            ),
            Self::Stalled { compressed, .. } if !compressed.is_empty() => format!(
                "{} film elements were in compression (a film without wrinkling carries it, a real ETFE \
                 film wrinkles): move the inputs by less per step ({finer}), or give the material \
                 \"wrinkling\": \"tension-field\" if the film may wrinkle there",
                compressed.len()
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
            Self::PathDependent { .. } => format!(
                "the increment slipped or yielded and needed many iterations: move the inputs by less \
                 per step ({finer})"
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
        let chatter = |f: &mut fmt::Formatter<'_>,
                       names: &[String],
                       elements: &[usize],
                       compressed: &[usize]| {
            if !compressed.is_empty() {
                let numbers: Vec<String> = compressed.iter().map(|e| e.to_string()).collect();
                write!(
                    f,
                    "; film elements in compression (no wrinkling): {}",
                    name_list(&numbers)
                )?;
            }
            if !names.is_empty() {
                write!(
                    f,
                    "; gaps or contacts changing status: {}",
                    name_list(names)
                )?;
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
                compressed,
                ..
            } => {
                write!(
                    f,
                    "no convergence within the iteration limit: at iteration {} (the last): {last}, {}; \
                     the residual was {first_residual:.3e} N at iteration 0",
                    last.iteration,
                    last.verdict()
                )?;
                chatter(f, chattering, flipping, compressed)
            }
            Self::Stalled {
                iteration,
                closest,
                chattering,
                flipping,
                compressed,
            } => {
                write!(
                    f,
                    "no progress (stopped at iteration {iteration}); closest to convergence at iteration {} \
                     of {iteration}: {closest}, {}",
                    closest.iteration,
                    closest.verdict()
                )?;
                chatter(f, chattering, flipping, compressed)
            }
            Self::PathDependent { iteration } => write!(
                f,
                "not converged after {iteration} iterations at an iterate that slips or yields: \
                 refused so that a shorter increment follows the path-dependent answer's load path"
            ),
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
    /// The step's loads pass a limit point (a largest load) that arc-length control followed
    /// beyond: no equilibrium at the step's end on this path (`arc_length.rs`).
    LimitPoint {
        /// The largest share of the step's load change reached.
        fraction: f64,
        /// The load levels there.
        levels: LoadLevels,
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
            Self::LimitPoint { fraction, levels } => format!(
                "the loads pass a limit point at {:.2}% of the step (pressures {:?} Pa, forces {:?} N): \
                 past it the film carries less, and arc-length control followed the path down without \
                 reaching the step's end; no equilibrium at the step's loads lies on this path, and the \
                 viscous stabilization reached none without taking out more work than the film stores. \
                 The last converged state is kept. What to change: keep the loads below the limit, or stiffen \
                 the model (a harder material, a support)",
                100.0 * fraction,
                levels.pressure,
                levels.force
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

#[cfg(test)]
mod advice_tests {
    use super::*;

    /// A stall of a linear film with elements in compression names them and points to the
    /// tension-field film; without compressed elements the advice does not.
    #[test]
    fn a_stall_with_a_compressed_linear_film_names_the_elements_and_the_tension_field_film() {
        let with = IncrementFailure::Stalled {
            iteration: 17,
            closest: record(2.0e-4, 3.2e-6),
            chattering: vec![],
            flipping: vec![],
            compressed: vec![4, 5, 6],
        };
        assert!(
            with.to_string()
                .ends_with("; film elements in compression (no wrinkling): 4, 5, 6"),
            "{with}"
        );
        let advice = with.advice(&SettingNames::CORE);
        assert!(
            advice.starts_with("3 film elements were in compression")
                && advice.contains("tension-field")
        );
        assert!(
            !stall(record(2.0e-4, 3.2e-6))
                .advice(&SettingNames::CORE)
                .contains("tension-field")
        );
    }

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
            compressed: vec![],
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
            compressed: vec![],
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

    /// Within the bound nothing is said; between it and the strain energy the step warns that
    /// its path is the damped flow's; beyond the strain energy (the new user's vault roof:
    /// 3.393e11 J) the warning names both energies and says the state is the damping's.
    #[test]
    fn a_step_that_dissipated_more_than_the_film_stores_is_warned_as_the_dampings_state() {
        let mut report = StepReport {
            strain_energy: 2.0,
            stabilization_dissipated: 0.05,
            stabilization_energy: 1e-3,
            ..StepReport::default()
        };
        assert!(report.dissipation_warning().is_none());
        report.stabilization_dissipated = 0.5;
        let path = report.dissipation_warning().expect("above the bound");
        assert!(
            path.contains("damped flow's") && !path.contains("damping's"),
            "{path}"
        );
        report.stabilization_dissipated = 3.393e11;
        let state = report.dissipation_warning().expect("far above");
        assert!(
            state.contains("3.393e11 J")
                && state.contains("2.000e0 J")
                && state.contains("the state reached is the damping's"),
            "{state}"
        );
        assert!(StepReport::default().dissipation_warning().is_none());
    }

    /// A stall with contacts cycling between statuses names them and advises no setting:
    /// smaller steps, the advice it had, were measured not to settle such cycles (held-out set).
    #[test]
    fn a_contact_status_cycle_is_named_and_no_smaller_steps_are_advised_for_it() {
        let mut failure = stall(record(2.0e-4, 1.0e-9));
        if let IncrementFailure::Stalled { chattering, .. } = &mut failure {
            *chattering = vec!["tube4.4".into(), "tube4.6".into()];
        }
        let advice = failure.advice(&SettingNames::CORE);
        assert!(
            advice.starts_with(
                "gaps or curved-support contacts tube4.4, tube4.6 kept changing status"
            ),
            "{advice}"
        );
        assert!(advice.contains("no setting is advised"), "{advice}");
        assert!(
            !advice.contains(SettingNames::CORE.finer_increments),
            "{advice}"
        );
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
