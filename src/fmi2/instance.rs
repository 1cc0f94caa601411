//! The FMU instance in safe Rust: the co-simulation state machine, the variable values, the
//! analysis, and the saved FMU states.
//!
//! # State machine (FMI 2.0 §4.2.4)
//!
//! ```text
//! Instantiate → Instantiated ─SetupExperiment, EnterInitializationMode→ Initialization
//!   ─ExitInitializationMode (builds the Analysis)→ StepComplete ─DoStep ok→ StepComplete
//!                                                    │  └DoStep Discard→ StepFailed
//!   Terminate (StepComplete | StepFailed) → Terminated;  Reset (any) → Instantiated
//!   a panic inside any call → Fatal (only fmi2FreeInstance is left)
//! ```
//! [`allowed`] holds one mask per function. Deviations from the standard's table, both so that
//! a master can retry a step the FMU refused:
//! * in `StepFailed` (after `fmi2Discard`), inputs may be set and `fmi2DoStep` called again from
//!   the same time: the instance kept its last converged state and time;
//! * a call that fails with `fmi2Error` (bad argument, unknown value reference, wrong state,
//!   invalid parameters at `fmi2ExitInitializationMode`) has no effect and leaves the instance
//!   in its state, instead of making it unusable.
//!
//! # Semantics
//! * Parameters are fixed. The model is rebuilt from them (for `ParallelArch`, regenerated from
//!   `archHeight`) when the analysis is built: at `fmi2ExitInitializationMode`, or earlier when an
//!   output is read in initialization mode.
//! * The initial outputs are those of the undeformed, prestressed film; inputs set during
//!   initialization are reached by the first step.
//! * `fmi2DoStep(t, h)` moves every group to its inputs, and the pressures and nodal forces to
//!   theirs, in `solver.incrementsPerStep` increments (`Analysis::step_to_with_loads`). The
//!   analysis starts unloaded: the first step ramps the loads from zero, gravity (a parameter,
//!   `gravity.x/.y/.z` with `film.density`) included. Time is a pseudo-time: only `t` = current time (to 1e-9 relative) and
//!   `h > 0` are required, and time becomes `t + h`.
//! * Never fmi2OK with a wrong answer: a step's outputs are checked finite (`checked_step`,
//!   `mech::check_results`; a step whose outputs are not is a Discard and the state before it is
//!   kept), and a deserialized state is checked against the model its parameters give
//!   (`state::check_analysis_state`) at `fmi2DeSerializeFMUstate` already.
//! * `results.directory` (String parameter, "" = off): after `fmi2ExitInitializationMode` and
//!   after every successful `fmi2DoStep` the instance writes `<dir>/<id>_film_NNNN.vtu` and
//!   `<dir>/<id>_gaps_NNNN.vtu` (NNNN = 0000 for the initial state, then the number of steps
//!   since initialization; encoded as `results.vtkFormat` says) and rewrites
//!   `<dir>/<id>_film.pvd` and `<dir>/<id>_gaps.pvd` listing every state written so far with its
//!   time (`<id>` = `modelIdentifier`; the directory is created if missing, a relative one is
//!   relative to the importer's working directory). A failed write is logged and returns
//!   `fmi2Warning`: the step (or initialization) itself stands. FMU states hold the step count
//!   and the list of states written, so after `fmi2SetFMUstate` the next step writes the files
//!   that follow the restored state (overwriting those of the abandoned branch) and the `.pvd`
//!   files list that branch only; until that step the `.pvd` files on disk are the old ones, and
//!   files of the abandoned branch beyond it stay on disk. `fmi2Reset` empties the list. Instances of one FMU writing to one directory overwrite each
//!   other's files: give each its own directory.
//! * `fmi2GetString` returns pointers into buffers of the instance that stay valid until the next
//!   `fmi2GetString` on the instance or `fmi2FreeInstance` (FMI 2.0 only promises "until the next
//!   call"); `fmi2SetString` copies the strings.

use std::collections::HashMap;
use std::ffi::{CString, c_char};
use std::path::{Path, PathBuf};

use super::description::{Description, describe};
use super::logger::Logger;
use super::resources::{Source, resource_dir};
use super::state::{self, Snapshot};
use super::types::{
    FMI2_CO_SIMULATION, FMI2_DO_STEP_STATUS, FMI2_LAST_SUCCESSFUL_TIME, FMI2_TERMINATED, Status,
};
use super::variables::{
    Binding, Causality, StepInputs, Value, VarType, Variable, article, message_real, step_inputs,
};
use crate::mech::elements::material::Wrinkling;
use crate::mech::elements::triangle::state_counts;
use crate::mech::{
    Analysis, GapStatus, IterationMatrix, LoadLevels, Model, Results, SettingNames, SolverSettings,
    StepError, StepReport, check_results,
    results::vtk,
    results::warnings::{model_warnings, result_warnings},
    solve::{IncrementFailure, MAX_THREADS},
};
use crate::specimens::ParallelArch;
use serde::{Deserialize, Serialize};

/// The FMU parameters that a refused step's advice names.
const SETTING_NAMES: SettingNames = SettingNames {
    max_iterations: "solver.maxIterations",
    finer_increments: "raise solver.incrementsPerStep or take a smaller communication step",
    residual_tolerance: "solver.residualTolerance",
    displacement_tolerance: "solver.displacementTolerance",
    consistent_tangent: "solver.useJuRowlands = false",
};

/// Why a call failed: the status to return and the message to log.
#[derive(Clone, Debug, PartialEq)]
pub struct Failure {
    pub status: Status,
    pub message: String,
}

impl Failure {
    pub fn error(message: impl Into<String>) -> Self {
        Self {
            status: Status::Error,
            message: message.into(),
        }
    }

    pub fn discard(message: impl Into<String>) -> Self {
        Self {
            status: Status::Discard,
            message: message.into(),
        }
    }

    /// The call did its work, but something on the side failed (the VTK output): logged under
    /// `logStatusWarning`, `fmi2Warning` returned, the instance's new state stands.
    pub fn warning(message: impl Into<String>) -> Self {
        Self {
            status: Status::Warning,
            message: message.into(),
        }
    }
}

/// The result of an instance method.
pub type Outcome<T = ()> = Result<T, Failure>;

/// The states of the co-simulation state machine this FMU can be in.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum Phase {
    Instantiated,
    Initialization,
    StepComplete,
    StepFailed,
    Terminated,
    /// A call panicked: only `fmi2FreeInstance` is left.
    Fatal,
}

impl Phase {
    const fn bit(self) -> u8 {
        1 << self as u8
    }
}

/// A set of phases.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Mask(u8);

impl Mask {
    const fn of(phases: &[Phase]) -> Self {
        let mut bits = 0;
        let mut i = 0;
        while i < phases.len() {
            bits |= phases[i].bit();
            i += 1;
        }
        Self(bits)
    }

    pub fn allows(self, phase: Phase) -> bool {
        self.0 & phase.bit() != 0
    }
}

/// In which phases each function may be called.
pub mod allowed {
    use super::Mask;
    use super::Phase::*;

    pub const SET_DEBUG_LOGGING: Mask = Mask::of(&[
        Instantiated,
        Initialization,
        StepComplete,
        StepFailed,
        Terminated,
    ]);
    pub const SETUP_EXPERIMENT: Mask = Mask::of(&[Instantiated]);
    pub const ENTER_INITIALIZATION: Mask = Mask::of(&[Instantiated]);
    pub const EXIT_INITIALIZATION: Mask = Mask::of(&[Initialization]);
    pub const TERMINATE: Mask = Mask::of(&[StepComplete, StepFailed]);
    pub const RESET: Mask = Mask::of(&[
        Instantiated,
        Initialization,
        StepComplete,
        StepFailed,
        Terminated,
    ]);
    pub const GET: Mask = Mask::of(&[Initialization, StepComplete, StepFailed, Terminated]);
    /// StepFailed: deviation, so that a refused step can be retried with other inputs.
    pub const SET: Mask = Mask::of(&[Instantiated, Initialization, StepComplete, StepFailed]);
    pub const FMU_STATE: Mask = Mask::of(&[
        Instantiated,
        Initialization,
        StepComplete,
        StepFailed,
        Terminated,
    ]);
    pub const DIRECTIONAL_DERIVATIVE: Mask =
        Mask::of(&[Initialization, StepComplete, StepFailed, Terminated]);
    pub const SET_INPUT_DERIVATIVES: Mask = Mask::of(&[Instantiated, Initialization, StepComplete]);
    pub const GET_OUTPUT_DERIVATIVES: Mask = Mask::of(&[StepComplete, StepFailed, Terminated]);
    /// StepFailed: deviation (retry after fmi2Discard).
    pub const DO_STEP: Mask = Mask::of(&[StepComplete, StepFailed]);
    /// Only in stepInProgress, which this synchronous FMU never enters.
    pub const CANCEL_STEP: Mask = Mask::of(&[]);
    pub const STATUS: Mask = Mask::of(&[StepComplete, StepFailed, Terminated]);
    /// Model Exchange stubs: any live instance gets the "not provided" error.
    pub const ANY: Mask = Mask::of(&[
        Instantiated,
        Initialization,
        StepComplete,
        StepFailed,
        Terminated,
    ]);
}

/// The analysis and what it was built from.
struct Built {
    analysis: Analysis,
    /// The parameter values it was built with (table order, model parameters only).
    parameters: Vec<Value>,
    increments: usize,
    /// The results of the state `checked_step` has just reached, already checked finite: the
    /// outputs are made of them (taken by `refresh_outputs`, so never stale).
    checked: Option<Results>,
    /// What the last outputs leave of the model's assumptions (`warnings::result_warnings`).
    warnings: Vec<String>,
}

/// One FMU instance.
pub struct Instance {
    pub(crate) logger: Logger,
    source: Source,
    description: Description,
    phase: Phase,
    values: Vec<Value>,
    mu_set: bool,
    time: f64,
    start_time: f64,
    stop_time: Option<f64>,
    analysis: Option<Built>,
    outputs_fresh: bool,
    /// Successful steps since initialization: the number of the next VTK file.
    steps: usize,
    /// The states written as VTK since initialization: `(time, state number)` (what the
    /// `.pvd` files list).
    vtk_steps: Vec<(f64, usize)>,
    /// The strings handed out by the last `fmi2GetString`; the pointers stay valid until the
    /// next `fmi2GetString` replaces them (or the instance is freed).
    strings_out: Vec<CString>,
    /// Saved FMU states; the key is the address of the boxed snapshot, handed out as the opaque
    /// `fmi2FMUstate`. It is only ever used as a key, never dereferenced.
    states: HashMap<usize, Box<Snapshot>>,
    /// The last step refused with `fmi2Discard`, while no step has succeeded since.
    discarded: Option<RefusedStep>,
}

/// A step refused with `fmi2Discard`: where it started and the inputs it was asked to reach.
#[derive(Clone, Debug, PartialEq)]
struct RefusedStep {
    time: f64,
    inputs: Vec<Value>,
    /// Whether the identical step (same start time and inputs) was asked again and refused
    /// again: then `fmi2GetBooleanStatus(fmi2Terminated)` is true.
    repeated: bool,
}

impl std::fmt::Debug for Instance {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Instance")
            .field("model", &self.description.model_identifier)
            .field("phase", &self.phase)
            .finish()
    }
}

impl Instance {
    /// `fmi2Instantiate`: reads the resources, rebuilds the interface and checks the GUID.
    pub fn instantiate(
        name: &str,
        fmu_type: i32,
        guid: Option<&str>,
        resource_location: Option<&str>,
        logger: Logger,
    ) -> Result<Self, String> {
        if name.trim().is_empty() {
            return Err("instanceName is empty".into());
        }
        if fmu_type != FMI2_CO_SIMULATION {
            return Err(format!(
                "fmuType = {fmu_type}: this FMU provides Co-Simulation (1) only"
            ));
        }
        let guid = guid.ok_or("fmuGUID is NULL")?;
        let uri = resource_location
            .filter(|u| !u.is_empty())
            .ok_or("fmuResourceLocation is NULL or empty: the FMU needs its resources folder")?;
        let source = Source::load(&resource_dir(uri)?)?;
        let instance = Self::from_source(source, logger)?;
        if instance.description.guid != guid {
            return Err(format!(
                "GUID mismatch: the importer passed {guid}, the FMU's resources give {} (modelDescription.xml and \
                 resources/ are from different FMUs, or the binary is from another version)",
                instance.description.guid
            ));
        }
        Ok(instance)
    }

    /// An instance of `source` without the URI and GUID checks (tests, benchmarks).
    pub fn from_source(source: Source, logger: Logger) -> Result<Self, String> {
        let description = describe(&source)?;
        let values = start_values(&description.variables);
        let instance = Self {
            logger,
            source,
            description,
            phase: Phase::Instantiated,
            values,
            mu_set: false,
            time: 0.0,
            start_time: 0.0,
            stop_time: None,
            analysis: None,
            outputs_fresh: false,
            steps: 0,
            vtk_steps: Vec::new(),
            strings_out: Vec::new(),
            states: HashMap::new(),
            discarded: None,
        };
        instance.event(|| {
            format!(
                "instantiated {} (GUID {})",
                instance.description.model_identifier, instance.description.guid
            )
        });
        Ok(instance)
    }

    pub fn phase(&self) -> Phase {
        self.phase
    }

    pub fn description(&self) -> &Description {
        &self.description
    }

    /// After a panic: the instance must not be used any more.
    pub(crate) fn mark_fatal(&mut self) {
        self.phase = Phase::Fatal;
    }

    fn event(&self, message: impl FnOnce() -> String) {
        if self.logger.is_enabled(Status::Ok) {
            self.logger.log(Status::Ok, &message());
        }
    }

    // ---------------------------------------------------------------- lifecycle

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

    /// `outcome`, or `fmi2Warning` with the reasons when the current outputs leave the model's
    /// assumptions (a stress above the yield stress, strains beyond the small-strain range):
    /// the state and outputs stand, the importer is told once per step.
    fn warn_about_assumptions(&self, outcome: Outcome) -> Outcome {
        let warnings = self.analysis.as_ref().map_or(&[][..], |b| &b.warnings[..]);
        if warnings.is_empty() {
            return outcome;
        }
        let mut message = format!(
            "t = {}: the result is outside the model's assumptions: {}",
            self.time,
            warnings.join("; ")
        );
        if let Err(f) = outcome {
            if f.status != Status::Warning {
                return Err(f);
            }
            message = format!("{}; {message}", f.message);
        }
        Err(Failure::warning(message))
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

    // ---------------------------------------------------------------- variables

    /// The variable with value reference `vr`, which must be of type `want`.
    fn variable(&self, vr: u32, want: VarType) -> Outcome<&Variable> {
        let table = &self.description.variables;
        let v = table.get(vr as usize).ok_or_else(|| {
            Failure::error(format!(
                "value reference {vr} does not exist (this FMU has 0..{})",
                table.len() - 1
            ))
        })?;
        if v.var_type != want {
            return Err(Failure::error(format!(
                "value reference {vr} ({}) is a{} {}, not a{} {}",
                v.name,
                article(v.var_type),
                v.var_type.name(),
                article(want),
                want.name()
            )));
        }
        Ok(v)
    }

    /// Checks every value reference, computes the initial outputs if one is read in
    /// initialization mode, and returns the table positions.
    fn readable(&mut self, vrs: &[u32], want: VarType) -> Outcome<Vec<usize>> {
        let mut needs_outputs = false;
        for &vr in vrs {
            needs_outputs |= self.variable(vr, want)?.causality == Causality::Output;
        }
        if needs_outputs && !self.outputs_fresh {
            self.initial_outputs()?;
        }
        Ok(vrs.iter().map(|&vr| vr as usize).collect())
    }

    pub fn get_real(&mut self, vrs: &[u32], out: &mut [f64]) -> Outcome {
        for (i, o) in self.readable(vrs, VarType::Real)?.into_iter().zip(out) {
            *o = match (self.description.variables[i].binding, &self.values[i]) {
                (Binding::Time, _) => self.time,
                (_, Value::Real(v)) => *v,
                _ => unreachable!("values follow the table's types"),
            };
        }
        Ok(())
    }

    pub fn get_integer(&mut self, vrs: &[u32], out: &mut [i32]) -> Outcome {
        for (i, o) in self.readable(vrs, VarType::Integer)?.into_iter().zip(out) {
            let Value::Integer(v) = self.values[i] else {
                unreachable!("values follow the table's types")
            };
            *o = v;
        }
        Ok(())
    }

    /// Booleans as C ints (1/0).
    pub fn get_boolean(&mut self, vrs: &[u32], out: &mut [i32]) -> Outcome {
        for (i, o) in self.readable(vrs, VarType::Boolean)?.into_iter().zip(out) {
            let Value::Boolean(v) = self.values[i] else {
                unreachable!("values follow the table's types")
            };
            *o = i32::from(v);
        }
        Ok(())
    }

    /// Writes pointers to NUL-terminated copies held by the instance: they stay valid until the
    /// next `get_string` (which replaces them) or until the instance is dropped.
    pub fn get_string(&mut self, vrs: &[u32], out: &mut [*const c_char]) -> Outcome {
        let positions = self.readable(vrs, VarType::String)?;
        let mut copies = Vec::with_capacity(positions.len());
        for i in positions {
            let Value::String(s) = &self.values[i] else {
                unreachable!("values follow the table's types")
            };
            copies.push(CString::new(s.as_str()).map_err(|_| {
                Failure::error(format!(
                    "{} holds a NUL character",
                    self.description.variables[i].name
                ))
            })?);
        }
        // The pointers of the previous call end here, as FMI 2.0 allows.
        self.strings_out = copies;
        for (o, s) in out.iter_mut().zip(&self.strings_out) {
            *o = s.as_ptr();
        }
        Ok(())
    }

    /// Checks `values` for `vrs` ([`Variable::check_value`], after [`Self::settable`]) and
    /// stores them; the first bad one refuses the whole call.
    fn set_values(&mut self, vrs: &[u32], want: VarType, values: Vec<Value>) -> Outcome {
        for (&vr, x) in vrs.iter().zip(&values) {
            self.settable(vr, want)?
                .check_value(x)
                .map_err(Failure::error)?;
        }
        self.assign(vrs, values.into_iter());
        Ok(())
    }

    /// Copies the strings (the caller's may go away after the call).
    pub fn set_string(&mut self, vrs: &[u32], values: &[&str]) -> Outcome {
        let values = values.iter().map(|&x| Value::String(x.to_owned()));
        self.set_values(vrs, VarType::String, values.collect())
    }

    pub fn set_real(&mut self, vrs: &[u32], values: &[f64]) -> Outcome {
        let values = values.iter().map(|&x| Value::Real(x));
        self.set_values(vrs, VarType::Real, values.collect())
    }

    pub fn set_integer(&mut self, vrs: &[u32], values: &[i32]) -> Outcome {
        let values = values.iter().map(|&x| Value::Integer(x));
        self.set_values(vrs, VarType::Integer, values.collect())
    }

    /// Booleans as C ints (any non-zero is true).
    pub fn set_boolean(&mut self, vrs: &[u32], values: &[i32]) -> Outcome {
        let values = values.iter().map(|&x| Value::Boolean(x != 0));
        self.set_values(vrs, VarType::Boolean, values.collect())
    }

    /// Whether `vr` may be set now (FMI 2.0 §4.2.4 conditions (1), (3), (6)).
    fn settable(&self, vr: u32, want: VarType) -> Outcome<&Variable> {
        let v = self.variable(vr, want)?;
        let before_init = matches!(self.phase, Phase::Instantiated | Phase::Initialization);
        match v.causality {
            Causality::Input => Ok(v),
            Causality::Parameter if before_init => Ok(v),
            Causality::Parameter => Err(Failure::error(format!(
                "{} is a fixed parameter: set it before fmi2ExitInitializationMode (or after fmi2Reset)",
                v.name
            ))),
            Causality::Output => Err(Failure::error(format!(
                "{} is an output and cannot be set",
                v.name
            ))),
            Causality::Independent => Err(Failure::error(
                "time cannot be set: it advances with fmi2DoStep",
            )),
        }
    }

    /// Stores checked values; a changed model parameter drops the analysis built from the old
    /// ones (`results.directory` does not: the analysis does not depend on it).
    fn assign(&mut self, vrs: &[u32], values: impl Iterator<Item = Value>) {
        for (&vr, value) in vrs.iter().zip(values) {
            let i = vr as usize;
            if self.description.variables[i].is_model_parameter() && self.values[i] != value {
                self.analysis = None;
                self.outputs_fresh = false;
            }
            if self.description.variables[i].binding == Binding::Friction {
                self.mu_set = true;
            }
            self.values[i] = value;
        }
    }

    // ---------------------------------------------------------------- analysis

    /// Builds the analysis from the parameter values in `values`.
    fn build(&self, values: &[Value]) -> Result<Built, String> {
        let (model, settings, increments) = self.model_for(values)?;
        let analysis = Analysis::new(model, settings).map_err(|e| e.to_string())?;
        Ok(Built {
            analysis,
            parameters: parameters_of(&self.description.variables, values),
            increments,
            checked: None,
            warnings: vec![],
        })
    }

    /// The model, solver settings and increments per step that the parameter values in
    /// `values` give (the model is not validated here: `Analysis::new` does it).
    fn model_for(&self, values: &[Value]) -> Result<(Model, SolverSettings, usize), String> {
        let table = &self.description.variables;
        let real = |b: Binding| {
            table.iter().zip(values).find_map(|(v, x)| match x {
                Value::Real(x) if v.binding == b => Some(*x),
                _ => None,
            })
        };
        let mut model = match &self.source {
            Source::ParallelArch(spec) => {
                let arch_height = real(Binding::ArchHeight).unwrap_or(spec.arch_height);
                ParallelArch {
                    arch_height,
                    ..*spec
                }
                .model()
                .map_err(|e| format!("archHeight = {}: {e}", message_real(arch_height)))?
            }
            Source::Model(m) => m.clone(),
        };
        let base = &self.description.model;
        let names = |m: &crate::mech::Model| -> Vec<String> {
            m.gaps
                .iter()
                .map(|g| g.name.clone())
                .chain(m.groups.iter().map(|g| g.name.clone()))
                .chain(m.loads.pressures.iter().map(|p| p.name.clone()))
                .chain(m.loads.forces.iter().map(|f| f.name.clone()))
                .collect()
        };
        if names(&model) != names(base) {
            return Err(
                "the regenerated model's gaps, groups and load sets differ from the FMU's variables"
                    .into(),
            );
        }
        let mut settings = SolverSettings::default();
        let mut increments = 1;
        for (v, x) in table.iter().zip(values) {
            if !v.is_model_parameter() {
                continue;
            }
            let count = |x: i32, min: i32| {
                usize::try_from(x)
                    .ok()
                    .filter(|_| x >= min)
                    .ok_or_else(|| format!("{} = {x} must be ≥ {min}", v.name))
            };
            match (v.binding, x.clone()) {
                (Binding::ArchHeight, _) => {}
                (Binding::YoungsModulus, Value::Real(x)) => model.material.youngs_modulus = x,
                (Binding::PoissonRatio, Value::Real(x)) => model.material.poisson_ratio = x,
                (Binding::Thickness, Value::Real(x)) => model.material.thickness = x,
                (Binding::Prestress(c), Value::Real(x)) => model.material.prestress[c] = x,
                (Binding::Density, Value::Real(x)) => model.material.density = x,
                (Binding::Gravity(c), Value::Real(x)) => model.loads.gravity[c] = x,
                (Binding::Wrinkling, Value::Boolean(b)) => {
                    model.material.wrinkling = if b {
                        Wrinkling::TensionField
                    } else {
                        Wrinkling::None
                    }
                }
                (Binding::NormalStiffness(g), Value::Real(x)) => model.gaps[g].normal_stiffness = x,
                (Binding::TangentialStiffness(g), Value::Real(x)) => {
                    model.gaps[g].tangential_stiffness = x
                }
                (Binding::DisplacementTolerance, Value::Real(x)) => {
                    settings.displacement_tolerance = x
                }
                (Binding::ResidualTolerance, Value::Real(x)) => settings.residual_tolerance = x,
                (Binding::MaxIterations, Value::Integer(x)) => {
                    settings.max_iterations = count(x, 1)?
                }
                (Binding::MaxCutbacks, Value::Integer(x)) => settings.max_cutbacks = count(x, 0)?,
                (Binding::IncrementsPerStep, Value::Integer(x)) => increments = count(x, 1)?,
                (Binding::FrictionLaw, Value::String(name)) if name.is_empty() => {}
                (Binding::FrictionLaw, Value::String(name)) => {
                    model.set_friction_law(name.parse().map_err(|e| format!("{}: {e}", v.name))?)
                }
                (Binding::LineSearch, Value::Boolean(b)) => settings.line_search = b,
                (Binding::Threads, Value::Integer(x)) => {
                    settings.threads = count(x, 0)?;
                    if settings.threads > MAX_THREADS {
                        return Err(format!("{} = {x} must be at most {MAX_THREADS}", v.name));
                    }
                }
                (Binding::UseJuRowlands, Value::Boolean(b)) => {
                    settings.iteration_matrix = if b {
                        IterationMatrix::JuRowlands
                    } else {
                        IterationMatrix::Consistent
                    }
                }
                (b, x) => unreachable!("parameter {b:?} holds {x:?}"),
            }
        }
        Ok((model, settings, increments))
    }

    /// Builds the analysis if there is none (initialization) and computes the initial outputs.
    fn initial_outputs(&mut self) -> Outcome {
        if self.analysis.is_none() {
            let built = self
                .build(&self.values)
                .map_err(|e| Failure::error(format!("invalid parameters: {e}")))?;
            self.analysis = Some(built);
        }
        if !self.outputs_fresh {
            self.refresh_outputs(None)?;
        }
        Ok(())
    }

    /// Writes the results of the converged state (and the step's statistics) into the outputs;
    /// refuses (fmi2Discard, outputs unchanged) when one of them would not be finite.
    fn refresh_outputs(&mut self, report: Option<&StepReport>) -> Outcome {
        let Some(built) = self.analysis.as_mut() else {
            return Ok(());
        };
        let results = match built.checked.take() {
            Some(results) => results,
            None => {
                let results = built.analysis.results();
                let residual = report.map(|r| r.residual);
                check_results(built.analysis.model(), &results, residual).map_err(|e| {
                    Failure::discard(format!(
                        "{e}: the outputs are not updated (the state is not one the solver can reach)"
                    ))
                })?;
                results
            }
        };
        built.warnings = result_warnings(built.analysis.model(), &results);
        let max_stress = results.von_mises_range().1;
        let [_, wrinkled, slack] = state_counts(&results.elements);
        let count = |n: usize| Value::Integer(i32::try_from(n).unwrap_or(i32::MAX));
        for (v, x) in self
            .description
            .variables
            .iter()
            .zip(self.values.iter_mut())
        {
            *x = match v.binding {
                Binding::SlipX(g) => Value::Real(results.gaps[g].slip_x),
                Binding::SlipY(g) => Value::Real(results.gaps[g].slip_y),
                Binding::NormalForce(g) => Value::Real(results.gaps[g].normal_force),
                Binding::FrictionForce(g) => Value::Real(results.gaps[g].friction_force),
                // `GapResult::friction` is the force the film exerts on the support (the
                // equilibrium of the film's Z forces shows it): the film feels the opposite.
                Binding::GapFriction { gap, axis } => {
                    Value::Real(-results.gaps[gap].friction[axis])
                }
                Binding::GapStatus(g) => Value::Integer(match results.gaps[g].status {
                    GapStatus::Open => 0,
                    GapStatus::Stick => 1,
                    GapStatus::Slip => 2,
                }),
                Binding::Reaction { group, axis } => Value::Real(results.reactions[group][axis]),
                Binding::HingeMoment(group) => Value::Real(results.moments[group]),
                Binding::Iterations => count(report.map_or(0, StepReport::total_iterations)),
                Binding::Cutbacks => count(report.map_or(0, |r| r.cutbacks)),
                Binding::Residual => Value::Real(report.map_or(0.0, |r| r.residual)),
                Binding::MaxEquivalentStress => Value::Real(max_stress),
                Binding::WrinkledElements => count(wrinkled),
                Binding::SlackElements => count(slack),
                Binding::SupportReaction { set, axis } => {
                    Value::Real(results.support_reactions[set][axis])
                }
                Binding::TotalReaction(axis) => Value::Real(results.total_reaction[axis]),
                Binding::CableForce(c) => Value::Real(results.cables[c].max_force),
                Binding::SurfaceSlip(c) => Value::Real(results.surface_contacts[c].slip),
                Binding::SurfaceNormalForce(c) => {
                    Value::Real(results.surface_contacts[c].normal_force)
                }
                Binding::SurfaceFrictionForce(c) => {
                    Value::Real(results.surface_contacts[c].friction_force)
                }
                Binding::SurfaceStatus(c) => {
                    Value::Integer(results.surface_contacts[c].status as i32)
                }
                Binding::PointDisplacement { point, axis } => {
                    Value::Real(results.points[point][axis])
                }
                Binding::SetSummary { set, quantity } => {
                    Value::Real(quantity.of(&results.sets[set]))
                }
                _ => continue,
            };
        }
        self.outputs_fresh = true;
        Ok(())
    }

    /// `fmi2DoStep`: moves every group to its inputs over `[t, t + h]`.
    pub fn do_step(&mut self, t: f64, h: f64) -> Outcome {
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
        let StepInputs {
            targets,
            angles,
            mut loads,
            mu,
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
        // μ changes the state's friction (gaps and curved-support contacts) before the step; a
        // refused step must not keep it.
        let state = built.analysis.state();
        let changes = |mu: f64| {
            let contacts = state.contacts.iter().map(|c| &c.friction);
            state.friction.iter().chain(contacts).any(|&f| f != mu)
        };
        let before = match mu {
            Some(mu) if changes(mu) => {
                let before = built.analysis.state().clone();
                built.analysis.set_friction(mu).map_err(Failure::error)?;
                Some(before)
            }
            _ => None,
        };
        match checked_step(built, &targets, &angles, &loads, &self.logger) {
            Ok(report) => {
                self.time = t + h;
                self.phase = Phase::StepComplete;
                self.discarded = None;
                self.refresh_outputs(Some(&report))?;
                self.event(|| {
                    format!(
                        "step to t = {}: {} increments, {} Newton iterations, {} cut-backs, {} enlarged \
                         (larger than 1/solver.incrementsPerStep because every smaller one failed), residual {:.3e} N",
                        self.time,
                        report.iterations.len(),
                        report.total_iterations(),
                        report.cutbacks,
                        report.enlarged,
                        report.residual
                    )
                });
                self.steps += 1;
                let written = self.write_results();
                self.warn_about_assumptions(written)
            }
            Err(e) => {
                if let Some(before) = before {
                    built.analysis.set_state(before).map_err(Failure::error)?;
                }
                self.phase = Phase::StepFailed;
                let message = format!(
                    "step from t = {t} to {}: {}",
                    t + h,
                    e.message(&SETTING_NAMES)
                );
                Err(match e {
                    StepError::NotConverged { .. } => {
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
                                 is now true. Time stays {t}; only a smaller change of the inputs can succeed"
                            )
                        } else {
                            format!(
                                "{message}. Time stays {t}: set a smaller change of the inputs and call fmi2DoStep again \
                                 (asking the identical step again makes fmi2GetBooleanStatus(fmi2Terminated) true)"
                            )
                        })
                    }
                    StepError::InvalidInput { .. } => Failure::error(message),
                })
            }
        }
    }

    /// The current values of the inputs (table order).
    fn input_values(&self) -> Vec<Value> {
        self.description
            .variables
            .iter()
            .zip(&self.values)
            .filter(|(v, _)| v.causality == Causality::Input)
            .map(|(_, x)| x.clone())
            .collect()
    }

    // ---------------------------------------------------------------- VTK output

    /// The value of `results.directory`, `None` when it is empty (no output).
    fn results_directory(&self) -> Option<PathBuf> {
        self.description
            .variables
            .iter()
            .zip(&self.values)
            .find_map(|(v, x)| match (v.binding, x) {
                (Binding::ResultsDirectory, Value::String(dir)) if !dir.is_empty() => {
                    Some(PathBuf::from(dir))
                }
                _ => None,
            })
    }

    /// The value of `results.vtkFormat` (checked when it was set).
    fn vtk_encoding(&self) -> vtk::Encoding {
        self.description
            .variables
            .iter()
            .zip(&self.values)
            .find_map(|(v, x)| match (v.binding, x) {
                (Binding::VtkFormat, Value::String(name)) => name.parse().ok(),
                _ => None,
            })
            .unwrap_or_default()
    }

    /// Writes the converged state as `<dir>/<id>_film_NNNN.vtu` and `<dir>/<id>_gaps_NNNN.vtu`
    /// (NNNN = steps since initialization) and rewrites `<dir>/<id>_film.pvd` and
    /// `<dir>/<id>_gaps.pvd`, if `results.directory` is set. A failure is a warning: the
    /// analysis, time and outputs stand; a state whose files could not be written is not listed.
    fn write_results(&mut self) -> Outcome {
        let encoding = self.vtk_encoding();
        let (Some(dir), Some(built)) = (self.results_directory(), self.analysis.as_mut()) else {
            return Ok(());
        };
        let id = &self.description.model_identifier;
        let step = self.steps;
        let a = &mut built.analysis;
        let results = a.results();
        let written = std::fs::create_dir_all(&dir)
            .map_err(|e| format!("cannot create {}: {e}", dir.display()))
            .and_then(|()| {
                vtk::Block::of(a.model()).iter().try_for_each(|&block| {
                    let vtu = dir.join(vtk::state_file_name(id, block, step));
                    let u = &a.state().displacement;
                    std::fs::write(&vtu, vtk::grid(block, a.model(), u, &results, encoding))
                        .map_err(|e| format!("{}: {e}", vtu.display()))
                })
            });
        let outcome = written.and_then(|()| {
            self.vtk_steps.push((self.time, step));
            let blocks = vtk::Block::of(built.analysis.model());
            blocks.iter().try_for_each(|&block| {
                let entries: Vec<(f64, String)> = self
                    .vtk_steps
                    .iter()
                    .map(|&(t, k)| (t, vtk::state_file_name(id, block, k)))
                    .collect();
                let pvd = dir.join(vtk::collection_file_name(id, block));
                replace_file(&pvd, &vtk::collection(&entries))
                    .map_err(|e| format!("{}: {e}", pvd.display()))
            })
        });
        outcome.map_err(|e| {
            Failure::warning(format!(
                "VTK output at t = {} failed, the results are kept: {e}",
                self.time
            ))
        })
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

    // ---------------------------------------------------------------- FMU states

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

fn start_values(table: &[Variable]) -> Vec<Value> {
    table
        .iter()
        .map(|v| {
            v.start.clone().unwrap_or(match v.var_type {
                VarType::Real => Value::Real(0.0),
                VarType::Integer => Value::Integer(0),
                VarType::Boolean => Value::Boolean(false),
                VarType::String => Value::String(String::new()),
            })
        })
        .collect()
}

fn parameters_of(table: &[Variable], values: &[Value]) -> Vec<Value> {
    table
        .iter()
        .zip(values)
        .filter(|(v, _)| v.is_model_parameter())
        .map(|(_, x)| x.clone())
        .collect()
}

/// Replaces `path` by `text` through a temporary file and a rename, so that a reader (ParaView
/// reloading the `.pvd`) never sees a half-written file.
fn replace_file(path: &Path, text: &str) -> std::io::Result<()> {
    let mut tmp = path.as_os_str().to_owned();
    tmp.push(".tmp");
    std::fs::write(&tmp, text)?;
    std::fs::rename(&tmp, path)
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

fn unknown_state(handle: usize) -> Failure {
    Failure::error(format!(
        "FMU state {handle:#x} was not created by this instance or was already freed (pass NULL to get a new state)"
    ))
}
