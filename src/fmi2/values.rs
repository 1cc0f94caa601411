//! The variable values: `fmi2Get*`/`fmi2Set*` of Real, Integer, Boolean and String by value
//! reference, with the checks of FMI 2.0 §4.2.4 (which variable may be set in which phase).
//!
//! * `fmi2GetString` returns pointers into buffers of the instance that stay valid until the next
//!   `fmi2GetString` on the instance or `fmi2FreeInstance` (FMI 2.0 only promises "until the next
//!   call"); `fmi2SetString` copies the strings.

use std::ffi::{CString, c_char};

use super::instance::Instance;
use super::phase::{Failure, Outcome, Phase};
use super::scalar_variable::{Binding, Causality, Value, VarType, Variable, article};

impl Instance {
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

    /// The current values of the inputs (table order).
    pub(super) fn input_values(&self) -> Vec<Value> {
        self.description
            .variables
            .iter()
            .zip(&self.values)
            .filter(|(v, _)| v.causality == Causality::Input)
            .map(|(_, x)| x.clone())
            .collect()
    }
}
