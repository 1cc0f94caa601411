//! The instance contract every C layer calls: one trait, [`Core`], implemented by each FMU's
//! instance ([`crate::scalar::Scalar`] for models of Real scalars such as the jack). The C
//! layers turn pointers into slices, check the phase against the function's mask, catch panics
//! and map an [`Outcome`] to the status; the instance does the work in safe Rust.

use core::ffi::c_char;

use crate::logger::Sink;
use crate::phase::{Failure, Outcome, Phase};
use crate::status::Status;

/// What `fmi2Instantiate` / `fmi3InstantiateCoSimulation` pass, checked and copied.
pub struct Instantiation<'a> {
    /// `instanceName`, not blank.
    pub name: &'a str,
    /// The GUID (FMI 2.0) or instantiation token (FMI 3.0) the importer read from the
    /// model description.
    pub token: Option<&'a str>,
    /// The resource location: a `file:` URI (FMI 2.0), a path ending in `/` (FMI 3.0).
    pub resources: Option<&'a str>,
    /// The importer's logger.
    pub sink: Sink,
    /// `loggingOn`.
    pub logging_on: bool,
    /// The FMI version of the C layer that instantiates (2 or 3): how `resources` is written.
    pub fmi_version: u8,
}

/// An FMU instance as the C layers see it.
pub trait Core: Sized {
    /// A new instance, or why not (logged by the C layer, which returns NULL).
    fn instantiate(args: Instantiation<'_>) -> Result<Self, String>;
    /// The phase the masks are checked against.
    fn phase(&self) -> Phase;
    /// After a panic: only freeing is left.
    fn mark_fatal(&mut self);
    /// Sends `message` to the importer if its category is enabled.
    fn log(&self, status: Status, message: &str);
    /// `SetDebugLogging`.
    fn set_debug_logging(&mut self, on: bool, names: &[&str]) -> Outcome;
    /// `fmi2SetupExperiment` (FMI 3.0: the arguments of `fmi3EnterInitializationMode`).
    fn setup_experiment(&mut self, start: f64, stop: Option<f64>) -> Outcome;
    /// `EnterInitializationMode`.
    fn enter_initialization_mode(&mut self) -> Outcome;
    /// `ExitInitializationMode`.
    fn exit_initialization_mode(&mut self) -> Outcome;
    /// `Terminate`.
    fn terminate(&mut self) -> Outcome;
    /// `Reset`: back to the state after instantiation.
    fn reset(&mut self) -> Outcome;
    /// `fmi2GetReal` / `fmi3GetFloat64` of scalars.
    fn get_real(&mut self, vr: &[u32], values: &mut [f64]) -> Outcome;
    /// `fmi2SetReal` / `fmi3SetFloat64` of scalars.
    fn set_real(&mut self, vr: &[u32], values: &[f64]) -> Outcome;
    /// `fmi3GetFloat64` of variables that may be arrays: `values` holds their values one after
    /// another (`nValues`); without arrays, [`Core::get_real`] of as many scalars.
    fn get_float64(&mut self, vr: &[u32], values: &mut [f64]) -> Outcome {
        scalars(vr.len(), values.len())?;
        self.get_real(vr, values)
    }
    /// `fmi3GetInt32` of variables that may be arrays (as [`Core::get_float64`]).
    fn get_int32(&mut self, vr: &[u32], values: &mut [i32]) -> Outcome {
        scalars(vr.len(), values.len())?;
        self.get_integer(vr, values)
    }
    /// `fmi3GetString`: scalars only (`nValues = nvr`).
    fn get_strings(&mut self, vr: &[u32], values: &mut [*const c_char]) -> Outcome {
        scalars(vr.len(), values.len())?;
        self.get_string(vr, values)
    }
    /// `fmi3GetUInt64` (structural parameters).
    fn get_uint64(&mut self, vr: &[u32], _values: &mut [u64]) -> Outcome {
        no_variables(vr, "UInt64")
    }
    /// `fmi2GetInteger` / `fmi3GetInt32`.
    fn get_integer(&mut self, vr: &[u32], _values: &mut [i32]) -> Outcome {
        no_variables(vr, "Integer")
    }
    /// `fmi2SetInteger` / `fmi3SetInt32`.
    fn set_integer(&mut self, vr: &[u32], _values: &[i32]) -> Outcome {
        no_variables(vr, "Integer")
    }
    /// `fmi2GetBoolean` / `fmi3GetBoolean`.
    fn get_boolean(&mut self, vr: &[u32], _values: &mut [bool]) -> Outcome {
        no_variables(vr, "Boolean")
    }
    /// `fmi2SetBoolean` / `fmi3SetBoolean`.
    fn set_boolean(&mut self, vr: &[u32], _values: &[bool]) -> Outcome {
        no_variables(vr, "Boolean")
    }
    /// `GetString`: the pointers stay valid until the next call.
    fn get_string(&mut self, vr: &[u32], _values: &mut [*const c_char]) -> Outcome {
        no_variables(vr, "String")
    }
    /// `SetString` (copied).
    fn set_string(&mut self, vr: &[u32], _values: &[&str]) -> Outcome {
        no_variables(vr, "String")
    }
    /// `DoStep` from `t` over `h`; a refused step (`Discard`) keeps the last converged state.
    fn do_step(&mut self, t: f64, h: f64) -> Outcome;
    /// The time of the last converged state (`fmi2LastSuccessfulTime`, FMI 3.0's
    /// `lastSuccessfulTime`).
    fn last_successful_time(&self) -> f64;
    /// Whether the FMU asks to stop (`fmi2Terminated`, FMI 3.0's `terminateSimulation`).
    fn terminate_requested(&self) -> bool {
        false
    }
    /// `fmi2GetStatus` of `kind` (`fmi2StatusKind`); by default not supported.
    fn get_status(&self, _kind: i32) -> Outcome<Status> {
        Err(not_supported("fmi2GetStatus"))
    }
    /// `fmi2GetRealStatus`: by default `fmi2LastSuccessfulTime` (2), `Discard` for another kind.
    fn get_real_status(&self, kind: i32) -> Outcome<f64> {
        match kind {
            2 => Ok(self.last_successful_time()),
            _ => Err(Failure::discard(format!(
                "status kind {kind}: no Real status"
            ))),
        }
    }
    /// `fmi2GetIntegerStatus`; by default not supported.
    fn get_integer_status(&self, _kind: i32) -> Outcome<i32> {
        Err(not_supported("fmi2GetIntegerStatus"))
    }
    /// `fmi2GetBooleanStatus`: by default `fmi2Terminated` (3), `Discard` for another kind.
    fn get_boolean_status(&self, kind: i32) -> Outcome<bool> {
        match kind {
            3 => Ok(self.terminate_requested()),
            _ => Err(Failure::discard(format!(
                "status kind {kind}: no Boolean status"
            ))),
        }
    }
    /// `fmi2GetStringStatus` (nothing is written); by default not supported.
    fn get_string_status(&self, _kind: i32) -> Outcome {
        Err(not_supported("fmi2GetStringStatus"))
    }
    /// `GetFMUstate` into the state `handle` (0: a new one); the handle of the saved state.
    fn get_fmu_state(&mut self, _handle: usize) -> Outcome<usize> {
        Err(not_supported("FMU states"))
    }
    /// `SetFMUstate`.
    fn set_fmu_state(&mut self, _handle: usize) -> Outcome {
        Err(not_supported("FMU states"))
    }
    /// `FreeFMUstate`.
    fn free_fmu_state(&mut self, _handle: usize) -> Outcome {
        Err(not_supported("FMU states"))
    }
    /// The bytes of a saved state (`SerializeFMUstate`).
    fn serialize_fmu_state(&mut self, _handle: usize) -> Outcome<Vec<u8>> {
        Err(not_supported("serialized FMU states"))
    }
    /// A saved state read back from bytes into `handle` (0: a new one).
    fn deserialize_fmu_state(&mut self, _bytes: &[u8], _handle: usize) -> Outcome<usize> {
        Err(not_supported("serialized FMU states"))
    }
    /// `GetDirectionalDerivative`: `out = J seed`, J the outputs' derivatives with respect to
    /// the knowns.
    fn directional_derivative(
        &mut self,
        _unknowns: &[u32],
        _knowns: &[u32],
        _seed: &[f64],
        _out: &mut [f64],
    ) -> Outcome {
        Err(not_supported("directional derivatives"))
    }
    /// `fmi2GetDirectionalDerivative`: by default [`Core::directional_derivative`], which the
    /// FMI 3.0 function calls (an FMU whose two versions answer differently overrides this).
    fn directional_derivative_fmi2(
        &mut self,
        unknowns: &[u32],
        knowns: &[u32],
        seed: &[f64],
        out: &mut [f64],
    ) -> Outcome {
        self.directional_derivative(unknowns, knowns, seed, out)
    }
    /// `GetAdjointDerivative`: `out = Jᵀ seed` (a seed per unknown, a value per known), J as
    /// [`Core::directional_derivative`] gives it. By default J's [`Columns`], one directional
    /// derivative per known, contracted with the seed: J's exact transpose, at the cost of
    /// `knowns.len()` directional derivatives. A warning of one of them (the film's
    /// path-dependent derivatives) is passed on once the whole product is written.
    fn adjoint_derivative(
        &mut self,
        unknowns: &[u32],
        knowns: &[u32],
        seed: &[f64],
        out: &mut [f64],
    ) -> Outcome {
        let columns = Columns::of(self, unknowns, knowns, Self::directional_derivative)?;
        columns.apply((unknowns, seed), knowns, true, out)
    }
}

/// A Jacobian as its columns `J e_j`, one directional derivative per known with a unit seed:
/// `J s` and `Jᵀ v` from the same numbers, so that `vᵀ (J s) = (Jᵀ v)ᵀ s` holds to rounding
/// whatever the directional derivative's own accuracy (the film's is a difference of results).
pub struct Columns {
    /// `values[j][i] = ∂unknown_i/∂known_j`.
    values: Vec<Vec<f64>>,
    /// The last warning a column came with, passed on with the product.
    warning: Option<Failure>,
}

impl Columns {
    /// The columns of `unknowns` along each of `knowns`, each from `column` (a directional
    /// derivative) with the seed 1.
    pub fn of<C>(
        core: &mut C,
        unknowns: &[u32],
        knowns: &[u32],
        column: impl Fn(&mut C, &[u32], &[u32], &[f64], &mut [f64]) -> Outcome,
    ) -> Outcome<Self> {
        let mut warning = None;
        let mut values = Vec::with_capacity(knowns.len());
        for &known in knowns {
            let mut c = vec![0.0; unknowns.len()];
            match column(core, unknowns, &[known], &[1.0], &mut c) {
                Ok(()) => {}
                Err(f) if f.status == Status::Warning => warning = Some(f),
                Err(f) => return Err(f),
            }
            values.push(c);
        }
        Ok(Self { values, warning })
    }

    /// `J s` (a value per known in `s`, a result per unknown).
    pub fn times(&self, s: &[f64]) -> Vec<f64> {
        let n = self.values.first().map_or(0, Vec::len);
        (0..n)
            .map(|i| self.values.iter().zip(s).map(|(c, s)| c[i] * s).sum())
            .collect()
    }

    /// `Jᵀ v` (a value per unknown in `v`, a result per known).
    pub fn transpose_times(&self, v: &[f64]) -> Vec<f64> {
        self.values
            .iter()
            .map(|c| c.iter().zip(v).map(|(c, v)| c * v).sum())
            .collect()
    }

    /// Writes `J seed` (`transpose` false: a seed per known, a value per unknown) or `Jᵀ seed`
    /// (true: a seed per unknown, a value per known) into `out`; `seed_refs` and `out_refs`
    /// name them. An error names a seed that is not finite or a value that overflows; else the
    /// columns' warning, if any, is the outcome.
    pub fn apply(
        self,
        (seed_refs, seed): (&[u32], &[f64]),
        out_refs: &[u32],
        transpose: bool,
        out: &mut [f64],
    ) -> Outcome {
        if let Some((r, d)) = seed_refs.iter().zip(seed).find(|(_, d)| !d.is_finite()) {
            return Err(Failure::error(format!(
                "seed of value reference {r} = {d}: values must be finite"
            )));
        }
        let result = if transpose {
            self.transpose_times(seed)
        } else {
            self.times(seed)
        };
        if let Some((r, _)) = out_refs.iter().zip(&result).find(|(_, x)| !x.is_finite()) {
            return Err(Failure::error(format!(
                "the derivative at value reference {r} overflows for this seed: scale the seed down"
            )));
        }
        out.copy_from_slice(&result);
        self.warning.map_or(Ok(()), Err)
    }
}

/// `nValues` of a call on scalars only: it must equal `nvr`.
pub fn scalars(nvr: usize, n_values: usize) -> Outcome {
    if n_values == nvr {
        Ok(())
    } else {
        Err(Failure::error(format!(
            "nValues = {n_values}, but {nvr} value references of scalars were given"
        )))
    }
}

/// The failure of a call of a capability the FMU does not claim.
pub fn not_supported(what: &str) -> Failure {
    Failure::error(format!("{what}: not supported by this FMU"))
}

/// Nothing to do for an empty list (libcosim asks for every type); an error naming the first
/// reference otherwise.
pub fn no_variables(vr: &[u32], kind: &str) -> Outcome {
    match vr.first() {
        None => Ok(()),
        Some(r) => Err(Failure::error(format!(
            "unknown value reference {r} (this FMU has no {kind} variables)"
        ))),
    }
}
