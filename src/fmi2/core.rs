//! The instance as the shared glue's [`Core`]: what its FMI 2.0 and FMI 3.0 C layers
//! (`fmi_glue::export_fmi2!` in `exports.rs`, `fmi_glue::export_fmi3!` in `src/fmi3`) call.
//! Each method forwards to the instance's own, so both versions drive the same code; the FMI 3.0 directional
//! derivative is made of the 2.0 one's columns (one per known, [`Columns`]), so that the
//! adjoint is its exact transpose; an adjoint of reactions and point displacements is one
//! solve instead (`Instance::adjoint_in_one_solve`).

use std::path::Path;

use fmi_glue::core::{Columns, Core, Instantiation};

use super::instance::Instance;
use super::logger::Logger;
use super::phase::{Failure, Outcome, Phase};
use super::resources::resource_dir;
use super::types::{FMI2_CO_SIMULATION, FMI2_TERMINATED, Status};
use crate::fmi3::arrays::{Arrays, Field, State};

impl Core for Instance {
    fn instantiate(args: Instantiation<'_>) -> Result<Self, String> {
        let logger = Logger::with_sink(args.sink, args.logging_on);
        if args.fmi_version == 2 {
            let (name, token) = (args.name, args.token);
            return Instance::instantiate(name, FMI2_CO_SIMULATION, token, args.resources, logger);
        }
        let token = args.token.ok_or("instantiationToken is NULL")?;
        // FMI 3.0 §2.3.1: resourcePath is a path ending in a separator, not a URI (a file: URI
        // is read as one all the same, as some importers of the draft standard sent them).
        let dir = match args.resources.filter(|p| !p.is_empty()) {
            None => return Err("resourcePath is NULL or empty: the FMU needs its resources".into()),
            Some(uri) if uri.starts_with("file:") => resource_dir(uri)?,
            Some(path) => Path::new(path).to_path_buf(),
        };
        Instance::instantiate_in(&dir, token, logger)
    }

    fn phase(&self) -> Phase {
        Instance::phase(self)
    }

    fn mark_fatal(&mut self) {
        Instance::mark_fatal(self);
    }

    fn log(&self, status: Status, message: &str) {
        self.logger.log(status, message);
    }

    fn set_debug_logging(&mut self, on: bool, names: &[&str]) -> Outcome {
        Instance::set_debug_logging(self, on, names)
    }

    fn setup_experiment(&mut self, start: f64, stop: Option<f64>) -> Outcome {
        Instance::setup_experiment(self, start, stop)
    }

    fn enter_initialization_mode(&mut self) -> Outcome {
        Instance::enter_initialization_mode(self)
    }

    fn exit_initialization_mode(&mut self) -> Outcome {
        Instance::exit_initialization_mode(self)
    }

    fn terminate(&mut self) -> Outcome {
        Instance::terminate(self)
    }

    fn reset(&mut self) -> Outcome {
        Instance::reset(self)
    }

    fn get_real(&mut self, vr: &[u32], values: &mut [f64]) -> Outcome {
        Instance::get_real(self, vr, values)
    }

    fn set_real(&mut self, vr: &[u32], values: &[f64]) -> Outcome {
        Instance::set_real(self, vr, values)
    }

    fn get_float64(&mut self, vr: &[u32], values: &mut [f64]) -> Outcome {
        let state = self.converged_if(vr)?;
        let read = |r: u32, field: Field| {
            let state = state.as_ref().expect("read for an array");
            field
                .float64(state)
                .ok_or_else(|| not_of_type(r, "Float64"))
        };
        self.gather(vr, values, Instance::get_real, read)
    }

    fn get_int32(&mut self, vr: &[u32], values: &mut [i32]) -> Outcome {
        let state = self.converged_if(vr)?;
        let read = |r: u32, field: Field| {
            let state = state.as_ref().expect("read for an array");
            field.int32(state).ok_or_else(|| not_of_type(r, "Int32"))
        };
        self.gather(vr, values, Instance::get_integer, read)
    }

    fn get_uint64(&mut self, vr: &[u32], values: &mut [u64]) -> Outcome {
        let arrays = Arrays::of(&self.description);
        fmi_glue::core::scalars(vr.len(), values.len())?;
        for (&r, v) in vr.iter().zip(values.iter_mut()) {
            let count = arrays.field(r).and_then(|f| arrays.count(f));
            *v = count.ok_or_else(|| not_of_type(r, "UInt64"))?;
        }
        Ok(())
    }

    fn get_integer(&mut self, vr: &[u32], values: &mut [i32]) -> Outcome {
        Instance::get_integer(self, vr, values)
    }

    fn set_integer(&mut self, vr: &[u32], values: &[i32]) -> Outcome {
        Instance::set_integer(self, vr, values)
    }

    fn get_boolean(&mut self, vr: &[u32], values: &mut [bool]) -> Outcome {
        let mut ints = vec![0; values.len()];
        Instance::get_boolean(self, vr, &mut ints)?;
        values.iter_mut().zip(ints).for_each(|(b, i)| *b = i != 0);
        Ok(())
    }

    fn set_boolean(&mut self, vr: &[u32], values: &[bool]) -> Outcome {
        let ints: Vec<i32> = values.iter().map(|&b| i32::from(b)).collect();
        Instance::set_boolean(self, vr, &ints)
    }

    fn get_string(&mut self, vr: &[u32], values: &mut [*const core::ffi::c_char]) -> Outcome {
        Instance::get_string(self, vr, values)
    }

    fn set_string(&mut self, vr: &[u32], values: &[&str]) -> Outcome {
        Instance::set_string(self, vr, values)
    }

    fn do_step(&mut self, t: f64, h: f64) -> Outcome {
        Instance::do_step(self, t, h)
    }

    fn last_successful_time(&self) -> f64 {
        self.time
    }

    fn terminate_requested(&self) -> bool {
        self.get_boolean_status(FMI2_TERMINATED).unwrap_or(false)
    }

    fn get_status(&self, kind: i32) -> Outcome<Status> {
        Instance::get_status(self, kind)
    }

    fn get_real_status(&self, kind: i32) -> Outcome<f64> {
        Instance::get_real_status(self, kind)
    }

    fn get_integer_status(&self, kind: i32) -> Outcome<i32> {
        Instance::get_integer_status(self, kind)
    }

    fn get_boolean_status(&self, kind: i32) -> Outcome<bool> {
        Instance::get_boolean_status(self, kind)
    }

    fn get_string_status(&self, kind: i32) -> Outcome {
        Instance::get_string_status(self, kind)
    }

    fn get_fmu_state(&mut self, handle: usize) -> Outcome<usize> {
        Instance::get_fmu_state(self, handle)
    }

    fn set_fmu_state(&mut self, handle: usize) -> Outcome {
        Instance::set_fmu_state(self, handle)
    }

    fn free_fmu_state(&mut self, handle: usize) -> Outcome {
        Instance::free_fmu_state(self, handle)
    }

    fn serialize_fmu_state(&mut self, handle: usize) -> Outcome<Vec<u8>> {
        Instance::serialize_fmu_state(self, handle)
    }

    fn deserialize_fmu_state(&mut self, bytes: &[u8], handle: usize) -> Outcome<usize> {
        Instance::deserialize_fmu_state(self, bytes, handle)
    }

    /// FMI 2.0: one linear response to the combined seed, as before the FMI 3.0 columns.
    fn directional_derivative_fmi2(
        &mut self,
        unknowns: &[u32],
        knowns: &[u32],
        seed: &[f64],
        out: &mut [f64],
    ) -> Outcome {
        Instance::directional_derivative(self, unknowns, knowns, seed, out)
    }

    /// One solve with the held factor (`Instance::adjoint_in_one_solve`) where the unknowns
    /// are reactions and point displacements; else J's columns, the directional derivative's
    /// exact transpose.
    fn adjoint_derivative(
        &mut self,
        unknowns: &[u32],
        knowns: &[u32],
        seed: &[f64],
        out: &mut [f64],
    ) -> Outcome {
        if let Some(outcome) = self.adjoint_in_one_solve(unknowns, knowns, seed, out) {
            return outcome;
        }
        let columns = Columns::of(self, unknowns, knowns, Instance::directional_derivative)?;
        columns.apply((unknowns, seed), knowns, true, out)
    }

    fn directional_derivative(
        &mut self,
        unknowns: &[u32],
        knowns: &[u32],
        seed: &[f64],
        out: &mut [f64],
    ) -> Outcome {
        // J's columns, the ones the adjoint contracts (the glue's `Core::adjoint_derivative`):
        // `J s` is then linear in the seed to the last bit and `fmi3GetAdjointDerivative` its
        // exact transpose; one linear response per known, each from the held factor.
        let columns = Columns::of(self, unknowns, knowns, Instance::directional_derivative)?;
        columns.apply((knowns, seed), unknowns, false, out)
    }
}

/// The failure of reading `vr` with a getter of another type.
fn not_of_type(vr: u32, kind: &str) -> Failure {
    Failure::error(format!("value reference {vr} is not a {kind} variable"))
}

impl Instance {
    /// The converged state as the arrays read it (the analysis built first in initialization
    /// mode), if one of `vr` is an array of the FMI 3.0 interface.
    fn converged_if(&mut self, vr: &[u32]) -> Outcome<Option<State>> {
        let arrays = Arrays::of(&self.description);
        if !vr.iter().any(|&r| arrays.field(r).is_some()) {
            return Ok(None);
        }
        self.initial_outputs()?;
        let built = self.analysis.as_mut().expect("built by initial_outputs");
        let u = built.analysis.state().displacement.clone();
        let results = built.analysis.results();
        Ok(Some(State::new(built.analysis.model(), u, results)))
    }

    /// The values of `vr` one after another into `values` (`nValues` of them): scalars with
    /// `scalar`, the arrays of the FMI 3.0 interface with `array`.
    fn gather<T: Copy + Default>(
        &mut self,
        vr: &[u32],
        values: &mut [T],
        scalar: fn(&mut Instance, &[u32], &mut [T]) -> Outcome,
        array: impl Fn(u32, Field) -> Outcome<Vec<T>>,
    ) -> Outcome {
        let arrays = Arrays::of(&self.description);
        let mut out = Vec::with_capacity(values.len());
        for &r in vr {
            match arrays.field(r) {
                Some(field) if arrays.count(field).is_none() => out.extend(array(r, field)?),
                Some(_) => return Err(not_of_type(r, "Float64 or Int32")),
                None => {
                    let mut one = [T::default()];
                    scalar(self, &[r], &mut one)?;
                    out.push(one[0]);
                }
            }
        }
        if out.len() != values.len() {
            return Err(Failure::error(format!(
                "nValues = {}, but the {} variables hold {} values",
                values.len(),
                vr.len(),
                out.len()
            )));
        }
        values.copy_from_slice(&out);
        Ok(())
    }
}
