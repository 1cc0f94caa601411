//! `fmi2GetDirectionalDerivative` (issue 21 item 1): derivatives of the Real outputs of the
//! converged state with respect to the inputs (group displacements and angles, pressures,
//! nodal forces, `mu`), from the core's linear response (`Analysis::linear_response`: the last
//! increment's Newton equation linearized at its solution; the consistent tangent factorized at
//! the first call after a step or a restored state, each later call one solve with that
//! factor). One-sided where a gap sits on a switch; see the core's module doc.

use super::instance::Instance;
use super::phase::{Failure, Outcome};
use super::scalar_variable::{Binding, Causality, VarType};
use crate::mech::Seed;

impl Instance {
    /// `dv_unknown[i] = Σ_j ∂unknown_i/∂known_j · dv_known[j]`; refuses, naming it, an unknown
    /// reference, a known that is not an input, an unknown that is not a Real result.
    pub(super) fn directional_derivative(
        &mut self,
        unknowns: &[u32],
        knowns: &[u32],
        seed: &[f64],
        out: &mut [f64],
    ) -> Outcome {
        let variables = &self.description.variables;
        let named = |r: u32| {
            variables
                .get(r as usize)
                .ok_or_else(|| Failure::error(format!("unknown value reference {r}")))
        };
        for &r in unknowns {
            let v = named(r)?;
            if v.causality != Causality::Output
                || v.var_type != VarType::Real
                || !super::outputs::is_state_result(&v.binding)
            {
                return Err(Failure::error(format!(
                    "unknown {} (value reference {r}) is not a Real output of the film's state",
                    v.name
                )));
            }
        }
        let Some(built) = self.analysis.as_mut() else {
            return Err(Failure::error(
                "no analysis yet: derivatives exist from fmi2ExitInitializationMode on".to_string(),
            ));
        };
        let mut s = Seed::zero(&built.analysis);
        for (&r, &d) in knowns.iter().zip(seed) {
            let v = named(r)?;
            if !d.is_finite() {
                return Err(Failure::error(format!(
                    "seed of {} = {d}: values must be finite",
                    v.name
                )));
            }
            match v.binding {
                Binding::GroupDisplacement { group, axis } => s.translation[group][axis] += d,
                Binding::GroupAngle(g) => s.angles[g] += d,
                Binding::Pressure(k) => s.pressure[k] += d,
                Binding::NodalForce { set, axis } => s.force[set][axis] += d,
                Binding::Friction => s.friction += d,
                _ => {
                    return Err(Failure::error(format!(
                        "known {} (value reference {r}) is not an input",
                        v.name
                    )));
                }
            }
        }
        let response = built
            .analysis
            .linear_response(&s)
            .map_err(|e| Failure::error(format!("no derivatives at this state: {e}")))?;
        for (o, &r) in out.iter_mut().zip(unknowns) {
            let binding = &variables[r as usize].binding;
            *o = response
                .derivative(|res| super::outputs::state_result(binding, res).unwrap_or(f64::NAN));
        }
        Ok(())
    }
}
