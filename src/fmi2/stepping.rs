//! Stepping: `fmi2DoStep` and what it drives (the step's inputs, μ, the checked core step,
//! the refused step kept for a retry), and the status queries that report on the last step.
//!
//! * `fmi2DoStep(t, h)` moves every group to its inputs, and the pressures and nodal forces to
//!   theirs, in `solver.incrementsPerStep` increments (`Analysis::step_to_with_loads`). The
//!   analysis starts unloaded: the first step ramps the loads from zero, gravity (a parameter,
//!   `gravity.x/.y/.z` with `film.density`) included. Time is a pseudo-time: only `t` = current time (to 1e-9 relative) and
//!   `h > 0` are required, and time becomes `t + h`.
//! * Never fmi2OK with a wrong answer: a step's outputs are checked finite (`checked_step`,
//!   `mech::check_results`; a step whose outputs are not is a Discard and the state before it is
//!   kept), and a deserialized state is checked against the model its parameters give
//!   (`state::check_analysis_state`) at `fmi2DeSerializeFMUstate` already.

use super::instance::{Built, Instance, RefusedStep};
use super::logger::Logger;
use super::phase::{Failure, Outcome, Phase};
use super::scalar_variable::message_real;
use super::types::{FMI2_DO_STEP_STATUS, FMI2_LAST_SUCCESSFUL_TIME, FMI2_TERMINATED, Status};
use super::variables::{StepInputs, step_inputs};
use crate::mech::solve::IncrementFailure;
use crate::mech::{
    Analysis, AnalysisState, LoadLevels, SettingNames, StepError, StepReport, check_results,
};

/// Each orifice's mass flow in the checked results of a step of `h` seconds made its average
/// over the step, `(moved − moved₀)/h` (`moved`: the air it has passed since the start, `moved₀`
/// before the step), not the last increment's.
fn step_average_flows(built: &mut Built, moved: &[f64], h: f64) {
    if let Some(results) = built.checked.as_mut() {
        for (k, o) in results.orifices.iter_mut().enumerate() {
            o.mass_flow = (o.moved - moved.get(k).copied().unwrap_or(0.0)) / h;
        }
    }
}

/// The FMU parameters that a refused step's advice names.
const SETTING_NAMES: SettingNames = SettingNames {
    max_iterations: "solver.maxIterations",
    finer_increments: "raise solver.incrementsPerStep or take a smaller communication step",
    residual_tolerance: "solver.residualTolerance",
    displacement_tolerance: "solver.displacementTolerance",
    consistent_tangent: "solver.useJuRowlands = false",
    isotropic_friction: "the parameter frictionLaw = \"isotropic\" (or \"friction_law\": \"isotropic\" on those supports or gaps in the model file)",
};

impl Instance {
    /// `fmi2DoStep`: moves every group to its inputs over `[t, t + h]`.
    pub fn do_step(&mut self, t: f64, h: f64) -> Outcome {
        self.check_step_times(t, h)?;
        let StepInputs {
            targets,
            angles,
            mut loads,
            mu,
            sealed,
        } = step_inputs(
            &self.description.model,
            &self.description.variables,
            &self.values,
            self.mu_set,
        );
        let built = self
            .analysis
            .as_mut()
            .ok_or_else(|| Failure::error("no analysis (not initialized)"))?;
        // Gravity is a parameter: the built model holds it, and the first step ramps it in.
        loads.gravity = built.analysis.model().loads.gravity;
        // The step's length moves air through the orifices (issue 43).
        loads.time = t + h;
        // Air fed into sealed chambers (`<chamber>.massFlow`, issue 43): its running total.
        let (table, values) = (&self.description.variables, &self.values);
        match super::variables::supplied_air(&built.analysis, table, values, &sealed, h) {
            Ok(air) => loads.air = air,
            Err(e) => {
                self.phase = Phase::StepFailed;
                return Err(Failure::discard(e));
            }
        }
        // μ and the chambers' valves change the state before the step; a refused step goes back.
        let before = change_state_for_step(&mut built.analysis, mu, &sealed)?;
        let moved = built.analysis.state().orifice_moved.clone();
        match checked_step(built, &targets, &angles, &loads, &self.logger) {
            Ok(report) => {
                step_average_flows(built, &moved, h);
                built.step_size = h;
                self.step_converged(t + h, &report)
            }
            Err(e) => {
                if let Some(before) = before {
                    built.analysis.set_state(before).map_err(Failure::error)?;
                    built.step_increments = 0;
                    built.step_size = 0.0;
                }
                Err(self.step_refused(t, h, e))
            }
        }
    }

    /// The communication point `t` and step size `h` of `fmi2DoStep` against the FMU's time
    /// and stop time.
    fn check_step_times(&self, t: f64, h: f64) -> Outcome {
        if !(t.is_finite() && h.is_finite()) {
            return Err(Failure::error(format!(
                "currentCommunicationPoint = {} and step size = {} must be finite",
                message_real(t),
                message_real(h)
            )));
        }
        if h <= 0.0 {
            return Err(Failure::error(format!(
                "communicationStepSize = {} must be > 0",
                message_real(h)
            )));
        }
        let tolerance = 1e-9 * t.abs().max(self.time.abs()).max(1.0);
        if (t - self.time).abs() > tolerance {
            let stale = if self.discarded.is_some() {
                format!(
                    ". The step from t = {0} was refused (fmi2Discard) and the FMU stayed there: its outputs are \
                     those of t = {0}, not of later times. Retry from t = {0} with a smaller change of the inputs, \
                     or stop the simulation",
                    self.time
                )
            } else {
                String::new()
            };
            return Err(Failure::error(format!(
                "currentCommunicationPoint = {} differs from the FMU's time {} (the last converged communication point){stale}",
                message_real(t),
                message_real(self.time)
            )));
        }
        if let Some(stop) = self.stop_time
            && t + h > stop + tolerance
        {
            return Err(Failure::error(format!(
                "a step to {} goes beyond stopTime = {stop}",
                t + h
            )));
        }
        Ok(())
    }

    /// After a converged step to `time`: the time, phase, outputs, log line, results files and
    /// warnings.
    fn step_converged(&mut self, time: f64, report: &StepReport) -> Outcome {
        if let Some(b) = self.analysis.as_mut() {
            b.step_increments = report.iterations.len();
        }
        self.time = time;
        self.phase = Phase::StepComplete;
        self.discarded = None;
        self.refresh_outputs(Some(report))?;
        self.event(|| {
            format!(
                "step to t = {}: {} increments, {} Newton iterations, {} cut-backs, residual {:.3e} N{}",
                self.time,
                report.iterations.len(),
                report.total_iterations(),
                report.cutbacks,
                report.residual,
                report.attempts()
            )
        });
        self.steps += 1;
        let written = self.write_results();
        self.warn_about_assumptions(written)
    }

    /// The failure of a step from `t` over `h` that the solver refused with `e` (the state
    /// already restored): fmi2Discard for a step that did not converge, noting it so that the
    /// identical step asked again terminates; fmi2Error for invalid inputs.
    fn step_refused(&mut self, t: f64, h: f64, e: StepError) -> Failure {
        self.phase = Phase::StepFailed;
        let message = format!(
            "step from t = {t} to {}: {}",
            t + h,
            e.message(&SETTING_NAMES)
        );
        match e {
            StepError::NotConverged { .. } | StepError::LimitPoint { .. } => {
                let inputs = self.input_values();
                let repeated = self
                    .discarded
                    .as_ref()
                    .is_some_and(|d| d.time == self.time && d.inputs == inputs);
                self.discarded = Some(RefusedStep {
                    time: self.time,
                    inputs,
                    repeated,
                });
                Failure::discard(if repeated {
                    format!(
                        "{message}. The identical step was refused before: fmi2GetBooleanStatus(fmi2Terminated) \
                         (FMI 3.0: the step's terminateSimulation) is now true. Time stays {t}; only a smaller \
                         change of the inputs can succeed"
                    )
                } else {
                    format!(
                        "{message}. Time stays {t}: set a smaller change of the inputs and call DoStep again \
                         (asking the identical step again makes fmi2GetBooleanStatus(fmi2Terminated), in FMI 3.0 \
                         the step's terminateSimulation, true)"
                    )
                })
            }
            StepError::InvalidInput { .. } => Failure::error(message),
        }
    }

    // ---------------------------------------------------------------- status

    pub fn get_status(&self, kind: i32) -> Outcome<Status> {
        match kind {
            FMI2_DO_STEP_STATUS => Ok(if self.phase == Phase::StepFailed {
                Status::Discard
            } else {
                Status::Ok
            }),
            _ => Err(unavailable_status(kind, "fmi2GetStatus")),
        }
    }

    pub fn get_real_status(&self, kind: i32) -> Outcome<f64> {
        match kind {
            FMI2_LAST_SUCCESSFUL_TIME => Ok(self.time),
            _ => Err(unavailable_status(kind, "fmi2GetRealStatus")),
        }
    }

    pub fn get_integer_status(&self, kind: i32) -> Outcome<i32> {
        Err(unavailable_status(kind, "fmi2GetIntegerStatus"))
    }

    /// `fmi2Terminated`: true while the last step was refused (`fmi2Discard`) for the second
    /// time with the same start time and inputs. Retrying the identical step cannot succeed (the
    /// FMU already cut it down to its smallest increment), so a master that repeats it, as
    /// `fmpy.simulate_fmu` does, is told to stop; any other retry is still allowed.
    pub fn get_boolean_status(&self, kind: i32) -> Outcome<bool> {
        match kind {
            FMI2_TERMINATED => Ok(self.phase == Phase::StepFailed
                && self.discarded.as_ref().is_some_and(|d| d.repeated)),
            _ => Err(unavailable_status(kind, "fmi2GetBooleanStatus")),
        }
    }

    pub fn get_string_status(&self, kind: i32) -> Outcome {
        Err(unavailable_status(kind, "fmi2GetStringStatus"))
    }
}

/// Applies the inputs that change the converged state before a step: `mu` (the friction of every
/// gap and curved-support contact) and the chambers' valves `sealed`. Returns the state before
/// where anything changed (a refused step goes back to it); Err, with that state restored, where
/// a valve cannot close.
fn change_state_for_step(
    analysis: &mut Analysis,
    mu: Option<f64>,
    sealed: &[bool],
) -> Result<Option<AnalysisState>, Failure> {
    let state = analysis.state();
    let contacts = state.contacts.iter().map(|c| &c.friction);
    let friction = mu.filter(|&mu| state.friction.iter().chain(contacts).any(|&f| f != mu));
    let valves = state
        .chambers
        .iter()
        .zip(sealed)
        .any(|(c, &s)| c.sealed != s);
    if friction.is_none() && !valves {
        return Ok(None);
    }
    let before = state.clone();
    if let Some(mu) = friction {
        analysis.set_friction(mu).map_err(Failure::error)?;
    }
    // A chamber's valve closes (or opens) as the step starts.
    if valves && let Err(e) = analysis.set_chambers_sealed(sealed) {
        analysis.set_state(before).map_err(Failure::error)?;
        return Err(Failure::error(e));
    }
    Ok(Some(before))
}

/// `Analysis::step_to_motion`, then a check that every output of the new state is finite; a state
/// that is not is replaced by the one before the step and the step refused like a step that
/// does not converge (fmi2Discard: the master may retry with a smaller change). Defence in
/// depth: the solver itself rejects non-finite increments.
fn checked_step(
    built: &mut Built,
    targets: &[[f64; 3]],
    angles: &[f64],
    loads: &LoadLevels,
    logger: &Logger,
) -> Result<StepReport, StepError> {
    let analysis = &mut built.analysis;
    let before = analysis.state().clone();
    analysis.observe_increments(logger.increment_observer());
    let report = analysis.step_to_motion(targets, angles, loads, built.increments)?;
    let results = analysis.results();
    match check_results(analysis.model(), &results, Some(report.residual)) {
        Ok(()) => {
            built.checked = Some(results);
            Ok(report)
        }
        Err(e) => {
            if logger.is_enabled(Status::Discard) {
                logger.log(
                    Status::Discard,
                    &format!("step refused: {e}; the state before the step is kept"),
                );
            }
            analysis
                .set_state(before)
                .expect("the state before the step fits the analysis");
            Err(StepError::NotConverged {
                fraction_done: 0.0,
                cutbacks: report.cutbacks,
                last: IncrementFailure::Diverged {
                    iteration: report.total_iterations(),
                },
            })
        }
    }
}

fn unavailable_status(kind: i32, function: &str) -> Failure {
    let name = match kind {
        0 => "fmi2DoStepStatus",
        1 => "fmi2PendingStatus",
        2 => "fmi2LastSuccessfulTime",
        3 => "fmi2Terminated",
        _ => "an unknown fmi2StatusKind",
    };
    Failure::discard(format!(
        "{function}: {name} ({kind}) is not available from this synchronous FMU"
    ))
}
