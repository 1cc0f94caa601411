//! `fmi2GetDirectionalDerivative` (issue 21 item 1): derivatives of the Real outputs of the
//! converged state with respect to the inputs (group displacements and angles, pressures,
//! nodal forces, `mu`, and a chamber's `supplyPressure`, `heating` and `massFlow`: the air a
//! step of size `h` adds is `massFlow · h`, so its derivative is `h` times the air's, `h` the
//! last step's, 0 after a restored state), from the core's linear response (`Analysis::linear_response`: the last
//! increment's Newton equation linearized at its solution; the consistent tangent factorized at
//! the first call after a step or a restored state, each later call one solve with that
//! factor). One-sided where a gap sits on a switch; see the core's module doc. After a step of
//! more than one increment that slid a contact or yielded the film, the values are the last
//! increment's and the call returns `fmi2Warning` saying so ([`path_dependent`]).

use super::instance::Instance;
use super::phase::{Failure, Outcome};
use super::scalar_variable::{Binding, Causality, VarType};
use crate::mech::{GapStatus, OutputWeights, Results, Seed};

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
        // The response is linear in the seed: solved for the seed over its largest magnitude and
        // scaled back, so that a seed of 1e-320 or 1e308 gets the answer a seed of 1 does (issue
        // 47 item 6: both were refused as a singular matrix).
        let scale = seed.iter().fold(0.0_f64, |m, d| m.max(d.abs()));
        let mut s = Seed::zero(&built.analysis);
        for (&r, &d) in knowns.iter().zip(seed) {
            let v = named(r)?;
            if !d.is_finite() {
                return Err(Failure::error(format!(
                    "seed of {} = {d}: values must be finite",
                    v.name
                )));
            }
            let d = if scale > 0.0 { d / scale } else { d };
            if !add_to_seed(&mut s, &v.binding, d, built.step_size) {
                return Err(Failure::error(format!(
                    "known {} (value reference {r}) is not an input",
                    v.name
                )));
            }
        }
        let response = built
            .analysis
            .linear_response(&s)
            .map_err(|e| Failure::error(format!("no derivatives at this state: {e}")))?;
        let mut values = Vec::with_capacity(unknowns.len());
        for &r in unknowns {
            let binding = &variables[r as usize].binding;
            let unit = response
                .derivative(|res| super::outputs::state_result(binding, res).unwrap_or(f64::NAN));
            let value = unit * scale;
            if unit.is_finite() && !value.is_finite() {
                return Err(Failure::error(format!(
                    "the derivative of {} is {value} for this seed (largest {scale:e}): it \
                     overflows; scale the seed down",
                    variables[r as usize].name
                )));
            }
            values.push(value);
        }
        out.iter_mut().zip(values).for_each(|(o, v)| *o = v);
        match path_dependent(built.step_increments, &response.points[1]) {
            Some(what) => Err(path_warning(built.step_increments, &what)),
            None => Ok(()),
        }
    }
}

impl Instance {
    /// `fmi3GetAdjointDerivative` in one solve (`Analysis::adjoint_response`): `out = Jᵀ v`,
    /// when every unknown is a reaction (a group's, a support set's, the total) or an output
    /// point's displacement and every known an input, at any tangent (a sliding contact, a
    /// follower pressure: the transpose solve, the reactions' rows `K_rf` assembled; issue 45).
    /// None otherwise: the caller takes J's columns, which also name what is refused.
    pub(crate) fn adjoint_in_one_solve(
        &mut self,
        unknowns: &[u32],
        knowns: &[u32],
        v: &[f64],
        out: &mut [f64],
    ) -> Option<Outcome> {
        let variables = &self.description.variables;
        let built = self.analysis.as_mut()?;
        let mut weights = OutputWeights::zero(&built.analysis);
        for (&r, &x) in unknowns.iter().zip(v) {
            if !x.is_finite() || variables.get(r as usize)?.causality != Causality::Output {
                return None;
            }
            match variables[r as usize].binding {
                Binding::Reaction { group, axis } => weights.reactions[group][axis] += x,
                Binding::SupportReaction { set, axis } => weights.supports[set][axis] += x,
                Binding::TotalReaction(axis) => weights.total[axis] += x,
                Binding::PointDisplacement { point, axis } => weights.points[point][axis] += x,
                _ => return None,
            }
        }
        let mut seeds = Vec::with_capacity(knowns.len());
        for &r in knowns {
            let mut s = Seed::zero(&built.analysis);
            let binding = &variables.get(r as usize)?.binding;
            add_to_seed(&mut s, binding, 1.0, built.step_size).then_some(())?;
            seeds.push(s);
        }
        let values = built.analysis.adjoint_response(&weights, &seeds).ok()?;
        if let Some((&r, _)) = knowns.iter().zip(&values).find(|(_, x)| !x.is_finite()) {
            return Some(Err(Failure::error(format!(
                "the derivative at value reference {r} overflows for this seed: scale the seed down"
            ))));
        }
        out.copy_from_slice(&values);
        if built.step_increments <= 1 {
            return Some(Ok(()));
        }
        let results = built.analysis.results();
        Some(match path_dependent(built.step_increments, &results) {
            Some(what) => Err(path_warning(built.step_increments, &what)),
            None => Ok(()),
        })
    }
}

#[cfg(test)]
impl Instance {
    /// Solves with the held tangent since the analysis was built (0 without one).
    pub(crate) fn tangent_solves(&self) -> usize {
        self.analysis
            .as_ref()
            .map_or(0, |b| b.analysis.tangent_solves())
    }
}

/// The warning of derivatives that are the last of a step's `increments` when `what` makes
/// the step's own differ ([`path_dependent`]).
fn path_warning(increments: usize, what: &str) -> Failure {
    Failure::warning(format!(
        "derivatives of the last of the step's {increments} increments, the earlier ones held: \
         {what}, whose response depends on the path, so the step repeated with other inputs \
         differs from them (set solver.incrementsPerStep = 1 for the step's own)"
    ))
}

/// Adds `d` along the input bound to `binding` to `seed`; false if it is not an input.
/// `<chamber>.massFlow` moves the air by `d · h` (`h`: the size of the step that reached the
/// state, 0 after a restored state: no step, no air).
fn add_to_seed(seed: &mut Seed, binding: &Binding, d: f64, h: f64) -> bool {
    match *binding {
        Binding::GroupDisplacement { group, axis } => seed.translation[group][axis] += d,
        Binding::GroupAngle(g) => seed.angles[g] += d,
        Binding::Pressure(k) => seed.pressure[k] += d,
        Binding::NodalForce { set, axis } => seed.force[set][axis] += d,
        Binding::Friction => seed.friction += d,
        Binding::ChamberSupply(k) => seed.supply[k] += d,
        Binding::ChamberHeating(k) => seed.heating[k] += d,
        Binding::ChamberMassFlow(k) => seed.air[k] += d * h,
        _ => return false,
    }
    true
}

/// What makes the derivatives of the last of a step's `increments` differ from the step's own
/// (`results`: at the converged state): a contact sliding or a film yielding over a step of more
/// than one increment (issue 47: frame.dx on the specimen after a 10-increment step, a gap's
/// slip derivative 0.070 against 0.042 of the step repeated). Sliding and yielding are the
/// laws whose increments do not add up to one over the whole step: a slipping contact pushed
/// across its slip direction turns it in each increment by an amount that depends on the
/// increment's slip (the return map's `μN k_s / |t*|` across), so the step's earlier
/// increments answer a seed too. An orifice that passes air does too: its transfer is
/// integrated over the increments, each of its own length, so the last increment's linear
/// response holds only that increment's share of it (issue 43). Open and sticking contacts, an
/// elastic film and sealed chambers without orifices do not: the step's end depends on its
/// end inputs alone.
fn path_dependent(increments: usize, results: &Results) -> Option<String> {
    if increments <= 1 {
        return None;
    }
    let sliding = results
        .gaps
        .iter()
        .map(|g| g.status)
        .chain(results.surface_contacts.iter().map(|c| c.status))
        .filter(|&s| s == GapStatus::Slip)
        .count();
    let yielded = results.plastic_summary().map_or(0, |p| p.yielded_elements);
    let passing = results
        .orifices
        .iter()
        .filter(|o| o.mass_flow != 0.0)
        .count();
    let mut what = vec![];
    if sliding > 0 {
        what.push(format!("{sliding} contacts slide"));
    }
    if yielded > 0 {
        what.push(format!("{yielded} film elements yielded"));
    }
    if passing > 0 {
        what.push(format!("{passing} orifices pass air"));
    }
    (!what.is_empty()).then(|| what.join(" and "))
}
