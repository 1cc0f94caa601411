//! The instance's saved FMU states: `fmi2GetFMUstate`, `fmi2SetFMUstate`, `fmi2FreeFMUstate`
//! and `fmi2(De)SerializeFMUstate`. What one state holds and its byte format: `state.rs`.
//!
//! A state is saved as a [`Snapshot`] in a box the instance owns; the handle given to the
//! importer is the box's address, used only as a key. A state restored, or read back from
//! bytes, is checked against the model its parameter values give before anything changes.

use super::instance::{Instance, parameters_of};
use super::phase::{Failure, Outcome, Phase};
use super::state::{self, Snapshot};

impl Instance {
    fn snapshot(&self) -> Snapshot {
        Snapshot {
            phase: self.phase,
            values: self.values.clone(),
            mu_set: self.mu_set,
            time: self.time,
            start_time: self.start_time,
            stop_time: self.stop_time,
            outputs_fresh: self.outputs_fresh,
            analysis: self.analysis.as_ref().map(|b| b.analysis.state().clone()),
            steps: self.steps,
            vtk_steps: self.vtk_steps.clone(),
        }
    }

    /// Checks that a snapshot (maybe deserialized) fits this FMU.
    fn check_snapshot(&self, s: &Snapshot) -> Result<(), String> {
        let table = &self.description.variables;
        if s.values.len() != table.len() {
            return Err(format!(
                "the state has {} variables, this FMU {}",
                s.values.len(),
                table.len()
            ));
        }
        for (v, x) in table.iter().zip(&s.values) {
            v.check_value(x)
                .map_err(|e| format!("the state's value of {}: {e}", v.name))?;
        }
        let times = [s.time, s.start_time, s.stop_time.unwrap_or(0.0)];
        let file_times = s.vtk_steps.iter().map(|(t, _)| *t);
        if times.into_iter().chain(file_times).any(|t| !t.is_finite()) {
            return Err("the state's times are not finite".into());
        }
        if s.vtk_steps.iter().any(|&(_, k)| k > s.steps) {
            return Err(format!(
                "the state lists VTK output beyond its {} steps",
                s.steps
            ));
        }
        let needs_analysis = matches!(
            s.phase,
            Phase::StepComplete | Phase::StepFailed | Phase::Terminated
        );
        if s.phase == Phase::Fatal || (needs_analysis && s.analysis.is_none()) {
            return Err(format!(
                "the state's phase {:?} is not one to continue from",
                s.phase
            ));
        }
        if let Some(analysis) = &s.analysis {
            let (model, _, _) = self
                .model_for(&s.values)
                .and_then(|(model, settings, increments)| {
                    model.validate().map_err(|e| e.to_string())?;
                    settings
                        .validate()
                        .map_err(|e| format!("solver settings: {e}"))?;
                    Ok((model, settings, increments))
                })
                .map_err(|e| format!("the state's parameters: {e}"))?;
            state::check_analysis_state(&model, analysis)?;
        }
        Ok(())
    }

    /// Makes the instance continue from `s` exactly; on error nothing changes.
    fn restore(&mut self, s: &Snapshot) -> Result<(), String> {
        self.check_snapshot(s)?;
        let parameters = parameters_of(&self.description.variables, &s.values);
        let analysis = match &s.analysis {
            None => None,
            Some(state) => {
                let reuse = matches!(&self.analysis, Some(b) if b.parameters == parameters);
                let mut built = match self.analysis.take() {
                    Some(b) if reuse => b,
                    other => {
                        self.analysis = other;
                        self.build(&s.values)
                            .map_err(|e| format!("the state's parameters: {e}"))?
                    }
                };
                if let Err(e) = built.analysis.set_state(state.clone()) {
                    if reuse {
                        // set_state changed nothing: keep the analysis that was there.
                        self.analysis = Some(built);
                    }
                    return Err(e);
                }
                // The restored state's derivatives are those of one increment from it.
                built.step_increments = 0;
                built.step_size = 0.0;
                Some(built)
            }
        };
        self.analysis = analysis;
        self.phase = s.phase;
        self.values = s.values.clone();
        self.mu_set = s.mu_set;
        self.time = s.time;
        self.start_time = s.start_time;
        self.stop_time = s.stop_time;
        // A restored state starts a new branch: no refused step on it yet.
        self.discarded = None;
        self.outputs_fresh = s.outputs_fresh && self.analysis.is_some();
        self.steps = s.steps;
        self.vtk_steps = s.vtk_steps.clone();
        Ok(())
    }

    /// `fmi2GetFMUstate`: saves into a new state (`reuse` = 0) or over the state `reuse`.
    pub fn get_fmu_state(&mut self, reuse: usize) -> Outcome<usize> {
        let snapshot = self.snapshot();
        self.store(snapshot, reuse)
    }

    fn store(&mut self, snapshot: Snapshot, reuse: usize) -> Outcome<usize> {
        if reuse != 0 {
            let slot = self
                .states
                .get_mut(&reuse)
                .ok_or_else(|| unknown_state(reuse))?;
            **slot = snapshot;
            return Ok(reuse);
        }
        let boxed = Box::new(snapshot);
        let handle = std::ptr::from_ref::<Snapshot>(&*boxed).addr();
        self.states.insert(handle, boxed);
        self.event(|| {
            format!(
                "FMU state saved at t = {} ({} states held)",
                self.time,
                self.states.len()
            )
        });
        Ok(handle)
    }

    fn saved(&self, handle: usize) -> Outcome<&Snapshot> {
        self.states
            .get(&handle)
            .map(|b| &**b)
            .ok_or_else(|| unknown_state(handle))
    }

    pub fn set_fmu_state(&mut self, handle: usize) -> Outcome {
        let snapshot = self.saved(handle)?.clone();
        self.restore(&snapshot)
            .map_err(|e| Failure::error(format!("cannot restore the FMU state: {e}")))?;
        self.event(|| {
            format!(
                "FMU state restored: t = {}, phase {:?}",
                self.time, self.phase
            )
        });
        Ok(())
    }

    pub fn free_fmu_state(&mut self, handle: usize) -> Outcome {
        self.states
            .remove(&handle)
            .map(drop)
            .ok_or_else(|| unknown_state(handle))
    }

    /// The serialized form of a saved state.
    pub fn serialize_fmu_state(&self, handle: usize) -> Outcome<Vec<u8>> {
        Ok(state::serialize(
            self.saved(handle)?,
            &self.description.guid,
        ))
    }

    /// Reads a serialized state into a new saved state (`reuse` = 0) or over `reuse`.
    pub fn deserialize_fmu_state(&mut self, bytes: &[u8], reuse: usize) -> Outcome<usize> {
        let snapshot = state::deserialize(bytes, &self.description.guid)
            .and_then(|s| self.check_snapshot(&s).map(|()| s))
            .map_err(|e| Failure::error(format!("refused: {e}")))?;
        self.store(snapshot, reuse)
    }

    /// Number of saved states held.
    pub fn saved_states(&self) -> usize {
        self.states.len()
    }
}

fn unknown_state(handle: usize) -> Failure {
    Failure::error(format!(
        "FMU state {handle:#x} was not created by this instance or was already freed (pass NULL to get a new state)"
    ))
}
