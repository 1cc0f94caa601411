//! The FMU instance in safe Rust: what it holds, how it is created, and the analysis its
//! parameter values build. The instance's duties are `impl Instance` blocks in their own files
//! (see the module doc of `fmi2`): the phases and masks in `phase.rs`, the transitions in
//! `lifecycle.rs`, get/set in `values.rs`, outputs in `outputs.rs`, `fmi2DoStep` in
//! `stepping.rs`, VTK files in `vtk_output.rs`, FMU states in `fmu_states.rs`. None of them is
//! imported here: this file is the bottom of the instance's layers.
//!
//! # Semantics
//! * Parameters are fixed. The model is rebuilt from them (for `ParallelArch`, regenerated from
//!   `archHeight`) when the analysis is built: at `fmi2ExitInitializationMode`, or earlier when an
//!   output is read in initialization mode.

use std::collections::HashMap;
use std::ffi::CString;
use std::path::Path;

use super::description::{Description, describe};
use super::logger::Logger;
use super::resources::{Source, resource_dir};
use super::scalar_variable::{Binding, Value, VarType, Variable, message_real};
use super::state::Snapshot;
use super::types::{FMI2_CO_SIMULATION, Status};
use crate::mech::{
    Analysis, IterationMatrix, Model, Results, SolverSettings, Wrinkling, solve::MAX_THREADS,
};
use crate::specimens::ParallelArch;

/// The phases, masks and failures, also under their former path `fmi2::instance`.
pub use super::phase::{Failure, Mask, Outcome, Phase, allowed};

/// The analysis and what it was built from.
pub(super) struct Built {
    pub(super) analysis: Analysis,
    /// The parameter values it was built with (table order, model parameters only).
    pub(super) parameters: Vec<Value>,
    pub(super) increments: usize,
    /// Increments of the step that reached the present state (0: no step since the analysis
    /// was built or a state restored): the derivatives are the last increment's
    /// (`derivatives.rs`), which are the step's only where this is 1 or the path did not
    /// matter.
    pub(super) step_increments: usize,
    /// The size `h` of the step that reached the present state (0 where
    /// [`Self::step_increments`] is): `<chamber>.massFlow` added `massFlow · h` of air over it,
    /// so its derivatives are `h` times the air's.
    pub(super) step_size: f64,
    /// The results of the state `checked_step` has just reached, already checked finite: the
    /// outputs are made of them (taken by `refresh_outputs`, so never stale).
    pub(super) checked: Option<Results>,
    /// What the last outputs leave of the model's assumptions (`summary::result_warnings`).
    pub(super) warnings: Vec<String>,
}

/// One FMU instance.
pub struct Instance {
    pub(crate) logger: Logger,
    pub(super) source: Source,
    pub(super) description: Description,
    pub(super) phase: Phase,
    pub(super) values: Vec<Value>,
    pub(super) mu_set: bool,
    pub(super) time: f64,
    pub(super) start_time: f64,
    pub(super) stop_time: Option<f64>,
    pub(super) analysis: Option<Built>,
    pub(super) outputs_fresh: bool,
    /// Successful steps since initialization: the number of the next VTK file.
    pub(super) steps: usize,
    /// The states written as VTK since initialization: `(time, state number)` (what the
    /// `.pvd` files list).
    pub(super) vtk_steps: Vec<(f64, usize)>,
    /// The strings handed out by the last `fmi2GetString`; the pointers stay valid until the
    /// next `fmi2GetString` replaces them (or the instance is freed).
    pub(super) strings_out: Vec<CString>,
    /// Saved FMU states; the key is the address of the boxed snapshot, handed out as the opaque
    /// `fmi2FMUstate`. It is only ever used as a key, never dereferenced.
    pub(super) states: HashMap<usize, Box<Snapshot>>,
    /// The last step refused with `fmi2Discard`, while no step has succeeded since.
    pub(super) discarded: Option<RefusedStep>,
}

/// A step refused with `fmi2Discard`: where it started and the inputs it was asked to reach.
#[derive(Clone, Debug, PartialEq)]
pub(super) struct RefusedStep {
    pub(super) time: f64,
    pub(super) inputs: Vec<Value>,
    /// Whether the identical step (same start time and inputs) was asked again and refused
    /// again: then `fmi2GetBooleanStatus(fmi2Terminated)` is true.
    pub(super) repeated: bool,
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
        Self::instantiate_in(&resource_dir(uri)?, guid, logger)
    }

    /// An instance of the FMU whose resources are in `dir`, if its GUID (FMI 3.0: its
    /// instantiation token) is `guid`.
    pub fn instantiate_in(dir: &Path, guid: &str, logger: Logger) -> Result<Self, String> {
        let source = Source::load(dir)?;
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

    pub(super) fn event(&self, message: impl FnOnce() -> String) {
        if self.logger.is_enabled(Status::Ok) {
            self.logger.log(Status::Ok, &message());
        }
    }

    /// Builds the analysis from the parameter values in `values`.
    pub(super) fn build(&self, values: &[Value]) -> Result<Built, String> {
        let (model, settings, increments) = self.model_for(values)?;
        let analysis = Analysis::new(model, settings).map_err(|e| e.to_string())?;
        Ok(Built {
            analysis,
            parameters: parameters_of(&self.description.variables, values),
            increments,
            step_increments: 0,
            step_size: 0.0,
            checked: None,
            warnings: vec![],
        })
    }

    /// The model, solver settings and increments per step that the parameter values in
    /// `values` give (the model is not validated here: `Analysis::new` does it).
    pub(super) fn model_for(
        &self,
        values: &[Value],
    ) -> Result<(Model, SolverSettings, usize), String> {
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
                (Binding::Temperature, Value::Real(x)) => model.material.temperature = x,
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
                (Binding::Stabilization, Value::Boolean(b)) => settings.stabilization = b,
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
}

pub(super) fn start_values(table: &[Variable]) -> Vec<Value> {
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

pub(super) fn parameters_of(table: &[Variable], values: &[Value]) -> Vec<Value> {
    table
        .iter()
        .zip(values)
        .filter(|(v, _)| v.is_model_parameter())
        .map(|(_, x)| x.clone())
        .collect()
}
