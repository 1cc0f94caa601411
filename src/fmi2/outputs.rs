//! The outputs: computed from the converged state's results (and the last step's statistics),
//! checked finite, and the warnings when they leave the model's assumptions.
//!
//! * The initial outputs are those of the undeformed, prestressed film; inputs set during
//!   initialization are reached by the first step.

use super::instance::Instance;
use super::phase::{Failure, Outcome};
use super::scalar_variable::{Binding, Value};
use super::types::Status;
use crate::mech::elements::triangle::state_counts;
use crate::mech::results::warnings::result_warnings;
use crate::mech::{GapStatus, Results, StepReport, check_results};

impl Instance {
    /// Builds the analysis if there is none (initialization) and computes the initial outputs.
    pub(super) fn initial_outputs(&mut self) -> Outcome {
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
    pub(super) fn refresh_outputs(&mut self, report: Option<&StepReport>) -> Outcome {
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
        if let Some(w) = report.and_then(StepReport::stabilization_warning) {
            built.warnings.push(w);
        }
        if let Some(w) = report.and_then(StepReport::dissipation_warning) {
            built.warnings.push(w);
        }
        if let Some(w) = report.and_then(StepReport::dissipation_warning) {
            built.warnings.push(w);
        }
        let [_, wrinkled, slack] = state_counts(&results.elements);
        let plastic = results.plastic_summary();
        let count = |n: usize| Value::Integer(i32::try_from(n).unwrap_or(i32::MAX));
        for (v, x) in self
            .description
            .variables
            .iter()
            .zip(self.values.iter_mut())
        {
            *x = match v.binding {
                Binding::GapStatus(g) => Value::Integer(match results.gaps[g].status {
                    GapStatus::Open => 0,
                    GapStatus::Stick => 1,
                    GapStatus::Slip => 2,
                }),
                Binding::Iterations => count(report.map_or(0, StepReport::total_iterations)),
                Binding::Cutbacks => count(report.map_or(0, |r| r.cutbacks)),
                Binding::Residual => Value::Real(report.map_or(0.0, |r| r.residual)),
                Binding::StabilizationEnergy => {
                    Value::Real(report.map_or(0.0, |r| r.stabilization_energy))
                }
                Binding::StabilizationRatio => {
                    Value::Real(report.map_or(0.0, |r| r.stabilization_ratio()))
                }
                Binding::StabilizedIncrements => count(report.map_or(0, |r| r.stabilized)),
                Binding::DissipationRatio => {
                    Value::Real(report.map_or(0.0, |r| r.dissipation_ratio()))
                }
                Binding::WrinkledElements => count(wrinkled),
                Binding::SlackElements => count(slack),
                Binding::YieldedElements => count(plastic.map_or(0, |p| p.yielded_elements)),
                Binding::MinThickness => Value::Real(plastic.map_or(f64::NAN, |p| p.min_thickness)),
                Binding::SetMaxPlasticStrain(set) => {
                    Value::Real(results.sets[set].max_plastic_strain)
                }
                Binding::SurfaceStatus(c) => {
                    Value::Integer(results.surface_contacts[c].status as i32)
                }
                ref b => match state_result(b, &results) {
                    Some(r) => Value::Real(r),
                    None => continue,
                },
            };
        }
        self.outputs_fresh = true;
        Ok(())
    }

    /// `outcome`, or `fmi2Warning` with the reasons when the current outputs leave the model's
    /// assumptions (a stress above the yield stress, strains beyond the small-strain range):
    /// the state and outputs stand, the importer is told once per step.
    pub(super) fn warn_about_assumptions(&self, outcome: Outcome) -> Outcome {
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
}

/// The Real output bound to `binding` that is a result of the film's state (the ones
/// `fmi2GetDirectionalDerivative` differentiates), or None (inputs, parameters, statuses, the
/// last step's statistics).
pub(super) fn state_result(binding: &Binding, results: &Results) -> Option<f64> {
    Some(match *binding {
        Binding::SlipX(g) => results.gaps[g].slip_x,
        Binding::SlipY(g) => results.gaps[g].slip_y,
        Binding::NormalForce(g) => results.gaps[g].normal_force,
        Binding::FrictionForce(g) => results.gaps[g].friction_force,
        // `GapResult::friction` is the force the film exerts on the support (the equilibrium
        // of the film's Z forces shows it): the film feels the opposite.
        Binding::GapFriction { gap, axis } => -results.gaps[gap].friction[axis],
        Binding::Reaction { group, axis } => results.reactions[group][axis],
        Binding::HingeMoment(group) => results.moments[group],
        Binding::MaxEquivalentStress => results.von_mises_range().1,
        Binding::SupportReaction { set, axis } => results.support_reactions[set][axis],
        Binding::TotalReaction(axis) => results.total_reaction[axis],
        Binding::CableForce(c) => results.cables[c].max_force,
        Binding::SurfaceSlip(c) => results.surface_contacts[c].slip,
        Binding::SurfaceNormalForce(c) => results.surface_contacts[c].normal_force,
        Binding::SurfaceFrictionForce(c) => results.surface_contacts[c].friction_force,
        Binding::PointDisplacement { point, axis } => results.points[point][axis],
        Binding::SetSummary { set, quantity } => quantity.of(&results.sets[set]),
        Binding::ChamberPressure(k) => results.chambers[k].pressure,
        Binding::ChamberVolume(k) => results.chambers[k].volume,
        Binding::ChamberTemperature(k) => results.chambers[k].temperature,
        Binding::ChamberMass(k) => results.chambers[k].mass,
        Binding::LayerNormalForce(k) => totals(results, k).0,
        Binding::LayerMaxSlip(k) => totals(results, k).1,
        Binding::OrificeMassFlow(k) => results.orifices[k].mass_flow,
        _ => return None,
    })
}

/// Layer contact `k`'s total normal force and largest slip.
fn totals(results: &Results, k: usize) -> (f64, f64) {
    let t = crate::mech::elements::layer_contact::Totals::of(results, k);
    (t.normal_force, t.max_slip)
}

/// Whether `binding` is one of [`state_result`]'s.
pub(super) fn is_state_result(binding: &Binding) -> bool {
    matches!(
        binding,
        Binding::SlipX(_)
            | Binding::SlipY(_)
            | Binding::NormalForce(_)
            | Binding::FrictionForce(_)
            | Binding::GapFriction { .. }
            | Binding::Reaction { .. }
            | Binding::HingeMoment(_)
            | Binding::MaxEquivalentStress
            | Binding::SupportReaction { .. }
            | Binding::TotalReaction(_)
            | Binding::CableForce(_)
            | Binding::SurfaceSlip(_)
            | Binding::SurfaceNormalForce(_)
            | Binding::SurfaceFrictionForce(_)
            | Binding::PointDisplacement { .. }
            | Binding::SetSummary { .. }
            | Binding::ChamberPressure(_)
            | Binding::ChamberVolume(_)
            | Binding::ChamberTemperature(_)
            | Binding::ChamberMass(_)
            | Binding::LayerNormalForce(_)
            | Binding::LayerMaxSlip(_)
            | Binding::OrificeMassFlow(_)
    )
}
