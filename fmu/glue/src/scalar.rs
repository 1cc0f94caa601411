//! The instance core of a model of Real scalars ([`ScalarModel`], e.g. the hydraulic jack): the
//! phases, values by reference checked against the variable table, stepping with refusal and
//! rollback (a refused step leaves the last good state), FMU states, logging. [`Scalar`]
//! implements [`Core`], so the C layers export it as it is. A Boolean variable of the table
//! (`VarType::Boolean`, e.g. the inflation unit's `snowMode`) is held by the model as a real 0
//! or 1 and read and written only as a Boolean.

use std::collections::HashMap;

use crate::core::{Core, Instantiation};
use crate::description::{Causality, Description, VarType, Variability};
use crate::logger::Logger;
use crate::phase::{Failure, Outcome, Phase};
use crate::status::Status;

/// A model of Real scalars: its table, its values, its step. Every method that can fail
/// returns the reason, ready for the log; the core has already checked the value reference.
pub trait ScalarModel: Clone + 'static {
    /// The variable table and the rest of the model description.
    fn description() -> &'static Description;
    /// The model at its start values.
    fn new() -> Self;
    /// The value of `vr`.
    fn get(&self, vr: u32) -> f64;
    /// Why `value` is refused for `vr` (finite, ranges).
    fn check(vr: u32, value: f64) -> Result<(), String>;
    /// Sets `vr` (already checked).
    fn set(&mut self, vr: u32, value: f64);
    /// The model's time.
    fn time(&self) -> f64;
    /// Sets the start time (`SetupExperiment`).
    fn set_time(&mut self, t: f64);
    /// Recomputes the outputs of the current time from the inputs (initialization mode).
    fn initialize(&mut self) -> Result<(), String>;
    /// One communication step of size `h > 0`; an error refuses it (the core keeps the state).
    fn step(&mut self, h: f64) -> Result<(), String>;
    /// `d unknown / d known` at the present state; `None` if `unknown` is not an output or
    /// `known` not an input.
    fn derivative(&self, unknown: u32, known: u32) -> Option<f64>;
    /// The whole state as numbers, for serialized FMU states; `None` (the default): the model
    /// does not serialize (its description says `canSerializeFMUstate` only where it does).
    fn to_numbers(&self) -> Option<Vec<f64>> {
        None
    }
    /// The model from [`Self::to_numbers`]' numbers, or why they are not a state of it.
    fn from_numbers(_numbers: &[f64]) -> Result<Self, String> {
        Err("serialized FMU states are not supported".into())
    }
}

/// The [`ScalarModel`] items every model whose state is a `values` array by value reference
/// and a `time` field shares: `description` (the static `$description`), `new` (`Default`),
/// `get`, `set`, `check` (the function `$check`), `time`, `set_time`. Invoked inside the model's
/// `impl ScalarModel`, beside its own `initialize`, `step` and `derivative`.
#[macro_export]
macro_rules! scalar_values {
    ($description:expr, $check:path) => {
        fn description() -> &'static $crate::description::Description {
            &$description
        }

        fn new() -> Self {
            <Self as ::core::default::Default>::default()
        }

        fn get(&self, vr: u32) -> f64 {
            self.values[vr as usize]
        }

        fn check(vr: u32, value: f64) -> ::core::result::Result<(), String> {
            $check(vr, value)
        }

        fn set(&mut self, vr: u32, value: f64) {
            self.values[vr as usize] = value;
        }

        fn time(&self) -> f64 {
            self.time
        }

        fn set_time(&mut self, t: f64) {
            self.time = t;
        }
    };
}

/// The phases a serialized state may hold, by their byte.
const SAVED_PHASES: [Phase; 5] = [
    Phase::Instantiated,
    Phase::Initialization,
    Phase::StepComplete,
    Phase::StepFailed,
    Phase::Terminated,
];

/// An instance of a [`ScalarModel`].
pub struct Scalar<M: ScalarModel> {
    logger: Logger,
    phase: Phase,
    model: M,
    /// Saved FMU states by handle (the address of the box, only used as a key).
    states: HashMap<usize, Box<(M, Phase)>>,
}

impl<M: ScalarModel> Scalar<M> {
    /// The model as it stands.
    pub fn model(&self) -> &M {
        &self.model
    }

    fn name(vr: u32) -> String {
        M::description()
            .variable(vr)
            .map_or(format!("value reference {vr}"), |v| {
                format!("{} (value reference {vr})", v.name)
            })
    }

    /// Why `vr` is not a variable of type `t` (`time`, FMI 3.0's independent variable, is a
    /// Real).
    fn of_type(vr: u32, t: VarType) -> Outcome {
        let d = M::description();
        if vr == d.time_vr() && t == VarType::Real {
            return Ok(());
        }
        let v = (d.variable(vr))
            .ok_or_else(|| Failure::error(format!("unknown value reference {vr}")))?;
        if v.var_type != t {
            return Err(Failure::error(format!(
                "{} (value reference {vr}) is a {:?} variable, not a {t:?} one",
                v.name, v.var_type
            )));
        }
        Ok(())
    }

    /// Sets `values` (reals; a Boolean's 0 or 1) of `vr`, all or nothing: every value is
    /// checked, and in initialization mode the outputs they give, before any is kept.
    fn set_values(&mut self, vr: &[u32], values: &[f64]) -> Outcome {
        for (&r, &v) in vr.iter().zip(values) {
            self.settable(r)?;
            M::check(r, v).map_err(Failure::error)?;
        }
        let mut next = self.model.clone();
        for (&r, &v) in vr.iter().zip(values) {
            next.set(r, v);
        }
        if self.phase == Phase::Initialization {
            next.initialize().map_err(Failure::error)?;
        }
        self.model = next;
        Ok(())
    }

    /// Why `vr` may not be set now.
    fn settable(&self, vr: u32) -> Outcome {
        let v = (M::description().variable(vr))
            .ok_or_else(|| Failure::error(format!("unknown value reference {vr}")))?;
        if v.causality == Causality::Output {
            return Err(Failure::error(format!("{} is an output", v.name)));
        }
        let before = matches!(self.phase, Phase::Instantiated | Phase::Initialization);
        if v.variability == Variability::Fixed && !before {
            return Err(Failure::error(format!(
                "{} is a fixed parameter: set it before ExitInitializationMode",
                v.name
            )));
        }
        Ok(())
    }
}

impl<M: ScalarModel> Core for Scalar<M> {
    fn instantiate(args: Instantiation<'_>) -> Result<Self, String> {
        let d = M::description();
        if args.token != Some(d.token) {
            return Err(format!(
                "GUID {:?} is not this FMU's {}",
                args.token, d.token
            ));
        }
        Ok(Self {
            logger: Logger::new(args.sink, d.log_categories, args.logging_on),
            phase: Phase::Instantiated,
            model: M::new(),
            states: HashMap::new(),
        })
    }

    fn phase(&self) -> Phase {
        self.phase
    }

    fn mark_fatal(&mut self) {
        self.phase = Phase::Fatal;
    }

    fn log(&self, status: Status, message: &str) {
        self.logger.log(status, message);
    }

    fn set_debug_logging(&mut self, on: bool, names: &[&str]) -> Outcome {
        self.logger
            .set_debug_logging(on, names)
            .map_err(Failure::error)
    }

    fn setup_experiment(&mut self, start: f64, _stop: Option<f64>) -> Outcome {
        if !start.is_finite() {
            return Err(Failure::error(format!(
                "startTime = {start} must be finite"
            )));
        }
        self.model.set_time(start);
        Ok(())
    }

    fn enter_initialization_mode(&mut self) -> Outcome {
        self.model.initialize().map_err(Failure::error)?;
        self.phase = Phase::Initialization;
        Ok(())
    }

    fn exit_initialization_mode(&mut self) -> Outcome {
        self.model.initialize().map_err(Failure::error)?;
        self.phase = Phase::StepComplete;
        Ok(())
    }

    fn terminate(&mut self) -> Outcome {
        self.phase = Phase::Terminated;
        Ok(())
    }

    fn reset(&mut self) -> Outcome {
        self.model = M::new();
        self.phase = Phase::Instantiated;
        Ok(())
    }

    /// The table's variables, and `time` ([`Description::time_vr`], FMI 3.0's independent
    /// variable).
    fn get_real(&mut self, vr: &[u32], values: &mut [f64]) -> Outcome {
        let d = M::description();
        for &r in vr {
            Self::of_type(r, VarType::Real)?;
        }
        for (v, &r) in values.iter_mut().zip(vr) {
            *v = if r == d.time_vr() {
                self.model.time()
            } else {
                self.model.get(r)
            };
        }
        Ok(())
    }

    /// All or nothing: every value is checked, and in initialization mode the outputs they
    /// give, before any is kept.
    fn set_real(&mut self, vr: &[u32], values: &[f64]) -> Outcome {
        for &r in vr {
            Self::of_type(r, VarType::Real)?;
        }
        self.set_values(vr, values)
    }

    /// The table's Boolean variables.
    fn get_boolean(&mut self, vr: &[u32], values: &mut [bool]) -> Outcome {
        for &r in vr {
            Self::of_type(r, VarType::Boolean)?;
        }
        for (v, &r) in values.iter_mut().zip(vr) {
            *v = self.model.get(r) != 0.0;
        }
        Ok(())
    }

    /// As [`Core::set_real`], each value held as 0 or 1.
    fn set_boolean(&mut self, vr: &[u32], values: &[bool]) -> Outcome {
        for &r in vr {
            Self::of_type(r, VarType::Boolean)?;
        }
        let reals: Vec<f64> = values.iter().map(|&b| f64::from(u8::from(b))).collect();
        self.set_values(vr, &reals)
    }

    fn do_step(&mut self, t: f64, h: f64) -> Outcome {
        if !(h > 0.0 && h.is_finite()) {
            return Err(Failure::error(format!(
                "communicationStepSize = {h} must be > 0"
            )));
        }
        let now = self.model.time();
        if (t - now).abs() > 1e-9 * t.abs().max(1.0) {
            return Err(Failure::error(format!(
                "currentCommunicationPoint = {t} is not the FMU's time {now}"
            )));
        }
        let mut next = self.model.clone();
        match next.step(h) {
            Ok(()) => {
                self.model = next;
                self.phase = Phase::StepComplete;
                Ok(())
            }
            Err(m) => {
                self.phase = Phase::StepFailed;
                Err(Failure::discard(m))
            }
        }
    }

    fn last_successful_time(&self) -> f64 {
        self.model.time()
    }

    fn get_fmu_state(&mut self, handle: usize) -> Outcome<usize> {
        let saved = (self.model.clone(), self.phase);
        match self.states.get_mut(&handle) {
            Some(s) => {
                **s = saved;
                Ok(handle)
            }
            None if handle == 0 => {
                let b = Box::new(saved);
                let key = std::ptr::from_ref::<(M, Phase)>(&b).addr();
                self.states.insert(key, b);
                Ok(key)
            }
            None => Err(Failure::error("not an FMU state of this instance")),
        }
    }

    fn set_fmu_state(&mut self, handle: usize) -> Outcome {
        let (model, phase) = (self.states.get(&handle))
            .ok_or_else(|| Failure::error("not an FMU state of this instance"))?
            .as_ref()
            .clone();
        (self.model, self.phase) = (model, phase);
        Ok(())
    }

    fn free_fmu_state(&mut self, handle: usize) -> Outcome {
        self.states
            .remove(&handle)
            .map(drop)
            .ok_or_else(|| Failure::error("not an FMU state of this instance"))
    }

    /// The token, the phase's byte, then [`ScalarModel::to_numbers`] (little-endian).
    fn serialize_fmu_state(&mut self, handle: usize) -> Outcome<Vec<u8>> {
        let (model, phase) = (self.states.get(&handle))
            .ok_or_else(|| Failure::error("not an FMU state of this instance"))?
            .as_ref();
        let numbers = (model.to_numbers())
            .ok_or_else(|| Failure::error("serialized FMU states are not supported"))?;
        let mut bytes = M::description().token.as_bytes().to_vec();
        let k = SAVED_PHASES.iter().position(|p| p == phase).unwrap_or(0);
        bytes.push(k as u8);
        bytes.extend(numbers.iter().flat_map(|x| x.to_le_bytes()));
        Ok(bytes)
    }

    /// Bytes of [`Core::serialize_fmu_state`] of this model (its token first) into `handle`.
    fn deserialize_fmu_state(&mut self, bytes: &[u8], handle: usize) -> Outcome<usize> {
        let token = M::description().token.as_bytes();
        let body = (bytes.strip_prefix(token))
            .ok_or_else(|| Failure::error("the bytes are not a serialized state of this FMU"))?;
        let (&k, numbers) = (body.split_first())
            .filter(|(_, rest)| rest.len() % 8 == 0)
            .ok_or_else(|| Failure::error("the serialized state is cut short"))?;
        let phase = *(SAVED_PHASES.get(k as usize)).ok_or_else(|| {
            Failure::error(format!("the serialized state's phase {k} is unknown"))
        })?;
        let numbers: Vec<f64> = (numbers.chunks_exact(8))
            .map(|c| f64::from_le_bytes(c.try_into().expect("chunks of 8")))
            .collect();
        let model = M::from_numbers(&numbers).map_err(Failure::error)?;
        let saved = Box::new((model, phase));
        match self.states.get_mut(&handle) {
            Some(s) => {
                *s = saved;
                Ok(handle)
            }
            None if handle == 0 => {
                let key = std::ptr::from_ref::<(M, Phase)>(&saved).addr();
                self.states.insert(key, saved);
                Ok(key)
            }
            None => Err(Failure::error("not an FMU state of this instance")),
        }
    }

    fn directional_derivative(
        &mut self,
        unknowns: &[u32],
        knowns: &[u32],
        seed: &[f64],
        out: &mut [f64],
    ) -> Outcome {
        let is_output = |r: u32| {
            M::description()
                .variable(r)
                .is_some_and(|v| v.causality == Causality::Output)
        };
        let mut result = vec![0.0; unknowns.len()];
        for (k, &u) in unknowns.iter().enumerate() {
            for (&kn, &s) in knowns.iter().zip(seed) {
                if !s.is_finite() {
                    let name = Self::name(kn);
                    return Err(Failure::error(format!(
                        "seed of {name} = {s}: values must be finite"
                    )));
                }
                match self.model.derivative(u, kn) {
                    Some(d) => result[k] += d * s,
                    None if !is_output(u) => {
                        let name = Self::name(u);
                        return Err(Failure::error(format!("unknown {name} is not an output")));
                    }
                    None => {
                        let name = Self::name(kn);
                        return Err(Failure::error(format!("known {name} is not an input")));
                    }
                }
            }
        }
        if let Some((k, d)) = result.iter().enumerate().find(|(_, d)| !d.is_finite()) {
            return Err(Failure::error(format!(
                "the derivative of {} overflows ({}): scale the seed down",
                Self::name(unknowns[k]),
                short(*d)
            )));
        }
        out.copy_from_slice(&result);
        Ok(())
    }
}

/// A real for a message: plain decimals between 1e-4 and 1e15, else the shortest exponent form
/// (`1e308`, not 309 digits; `1e-300`, not `0.000…`).
pub fn short(x: f64) -> String {
    if x == 0.0 || !x.is_finite() || (1e-4..1e15).contains(&x.abs()) {
        format!("{x}")
    } else {
        format!("{x:e}")
    }
}
