//! The state machine's transitions: `fmi2SetupExperiment`, `fmi2EnterInitializationMode`,
//! `fmi2ExitInitializationMode`, `fmi2Terminate`, `fmi2Reset` and `fmi2SetDebugLogging` (which
//! call is allowed in which phase: `phase.rs`; `fmi2DoStep`: `stepping.rs`).

use super::instance::{Instance, start_values};
use super::phase::{Failure, Outcome, Phase};
use super::scalar_variable::{Binding, Causality, Value};
use super::types::Status;
use crate::mech::results::warnings::model_warnings;

impl Instance {
    pub fn setup_experiment(&mut self, start_time: f64, stop_time: Option<f64>) -> Outcome {
        if !start_time.is_finite() {
            return Err(Failure::error(format!(
                "startTime = {start_time} is not finite"
            )));
        }
        if let Some(stop) = stop_time
            && !(stop.is_finite() && stop >= start_time)
        {
            return Err(Failure::error(format!(
                "stopTime = {stop} must be finite and ≥ startTime = {start_time}"
            )));
        }
        self.start_time = start_time;
        self.time = start_time;
        self.stop_time = stop_time;
        Ok(())
    }

    pub fn enter_initialization_mode(&mut self) -> Outcome {
        self.phase = Phase::Initialization;
        self.time = self.start_time;
        Ok(())
    }

    pub fn exit_initialization_mode(&mut self) -> Outcome {
        self.initial_outputs()?;
        self.phase = Phase::StepComplete;
        self.steps = 0;
        self.vtk_steps.clear();
        self.event(|| {
            let m = self.analysis.as_ref().map(|b| b.analysis.model());
            let (nodes, gaps) = m.map_or((0, 0), |m| (m.nodes.len(), m.gaps.len()));
            let vtk = match self.results_directory() {
                None => String::new(),
                Some(dir) => format!(", VTK output to {}", dir.display()),
            };
            format!(
                "initialized: {nodes} nodes, {gaps} gaps, start time {}{vtk}",
                self.time
            )
        });
        if let Some(loads) = self.starting_loads() {
            self.logger.log(Status::Warning, &loads);
        }
        let written = self.write_results();
        let doubts = self
            .analysis
            .as_ref()
            .map_or_else(Vec::new, |b| model_warnings(b.analysis.model()));
        let written = if doubts.is_empty() {
            written
        } else {
            let mut message = format!("the model looks wrong: {}", doubts.join("; "));
            if let Err(f) = written {
                message = format!("{}; {message}", f.message);
            }
            Err(Failure::warning(message))
        };
        self.warn_about_assumptions(written)
    }

    /// The load inputs that the first fmi2DoStep applies at once, as they stand at the end of
    /// initialization (a pressure or force set's input starts at the model file's value), as a
    /// message naming each and its value; None where every one is 0.
    fn starting_loads(&self) -> Option<String> {
        let model = &self.analysis.as_ref()?.analysis.model().loads;
        let mut said = Vec::new();
        for (v, x) in self.description.variables.iter().zip(&self.values) {
            let (Value::Real(x), true) = (x, v.causality == Causality::Input) else {
                continue;
            };
            let from_file = match v.binding {
                Binding::Pressure(set) => model.pressures[set].pressure,
                Binding::NodalForce { set, axis } => model.forces[set].force[axis],
                _ => continue,
            };
            if *x != 0.0 {
                let origin = if *x == from_file {
                    " (the model file's value)"
                } else {
                    ""
                };
                said.push(format!("{} = {x} {}{origin}", v.name, v.unit.unwrap_or("")));
            }
        }
        (!said.is_empty()).then(|| {
            format!(
                "load inputs start at nonzero values, so the first DoStep applies these \
                 loads at once (from zero to the inputs' values then) unless the master changes \
                 them first: {}; set an input to 0 to apply its load in a later step",
                said.join(", ")
            )
        })
    }

    pub fn terminate(&mut self) -> Outcome {
        self.phase = Phase::Terminated;
        Ok(())
    }

    /// Back to the state just after instantiation: start values, time 0, no analysis. Saved FMU
    /// states and the logging settings stay.
    pub fn reset(&mut self) -> Outcome {
        self.phase = Phase::Instantiated;
        self.values = start_values(&self.description.variables);
        self.mu_set = false;
        self.time = 0.0;
        self.start_time = 0.0;
        self.stop_time = None;
        self.analysis = None;
        self.outputs_fresh = false;
        self.steps = 0;
        self.vtk_steps.clear();
        self.discarded = None;
        Ok(())
    }

    pub fn set_debug_logging(&mut self, on: bool, categories: &[&str]) -> Outcome {
        self.logger
            .set_debug_logging(on, categories)
            .map_err(Failure::error)
    }
}
