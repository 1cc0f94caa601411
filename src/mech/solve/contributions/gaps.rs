//! The friction gaps as a contribution: the laws with the friction coefficients of the
//! converged state, the slip history, the responses at the last evaluation, and for the
//! Ju–Rowlands matrix the gaps latched in slip or found closed during the Newton loop (§3).

use nalgebra::Vector2;

use super::{Contribution, Evaluation};
use crate::mech::elements::gap::{GapLaw, GapResponse, GapStatus, IterationMatrix};
use crate::mech::model::Model;
use crate::mech::results::{GapResult, Results};
use crate::mech::solve::state::AnalysisState;

/// The gaps with their trial history.
#[derive(Clone, Debug)]
pub struct Gaps {
    /// The model's laws (the friction coefficient of each increment comes from its start).
    laws: Vec<GapLaw>,
    /// Laws of this increment, with the friction coefficients of its start.
    trial: Vec<GapLaw>,
    /// Slip history at the start of the increment.
    history: Vec<Vector2<f64>>,
    /// Responses at the last evaluation.
    responses: Vec<GapResponse>,
    /// Gaps latched in slip for the rest of the Newton loop (§3(f)) with their slip direction.
    latched: Vec<Option<Vector2<f64>>>,
    /// Gaps found closed at some iteration of the current Newton loop.
    closed: Vec<bool>,
    /// Names (for the advice of a stalled increment).
    pub names: Vec<String>,
}

impl Gaps {
    /// The gaps of `model`.
    pub fn new(model: &Model) -> Self {
        let laws: Vec<GapLaw> = model.gaps.iter().map(|g| g.law()).collect();
        let idle = laws
            .first()
            .map(|l| l.evaluate(nalgebra::Vector3::zeros(), Vector2::zeros()));
        let n = laws.len();
        Self {
            responses: idle.map_or_else(Vec::new, |r| vec![r; n]),
            latched: vec![None; n],
            closed: vec![false; n],
            trial: Vec::new(),
            history: Vec::new(),
            names: model.gaps.iter().map(|g| g.name.clone()).collect(),
            laws,
        }
    }

    /// The model's laws.
    pub fn laws(&self) -> &[GapLaw] {
        &self.laws
    }

    /// Laws with the friction coefficients of `state`, and its slip history.
    fn take_history(&mut self, state: &AnalysisState) {
        self.trial = self
            .laws
            .iter()
            .zip(&state.friction)
            .map(|(l, &mu)| GapLaw { friction: mu, ..*l })
            .collect();
        self.history = state
            .plastic_slip
            .iter()
            .map(|s| Vector2::from(*s))
            .collect();
    }
}

impl Contribution for Gaps {
    fn restore(&mut self, start: &AnalysisState) {
        self.take_history(start);
        self.latched.iter_mut().for_each(|l| *l = None);
        self.closed.iter_mut().for_each(|c| *c = false);
    }

    fn add(&mut self, at: &Evaluation<'_>, residual: &mut [f64], values: Option<&mut [f64]>) {
        let Self {
            trial: laws,
            history,
            responses,
            latched,
            closed,
            ..
        } = self;
        let (mode, iteration) = (at.matrix, at.iteration);
        at.system.add_gaps(at.u, residual, values, |g, d| {
            let law = &laws[g];
            let response = law.evaluate(d, history[g]);
            responses[g] = response;
            let matrix = match mode {
                IterationMatrix::Consistent => law.consistent_tangent(&response),
                IterationMatrix::JuRowlands => {
                    // §3(b): stick in the first iteration; §3(f): once slipping, the slip matrix is
                    // kept, with the slip direction (and its sign) found when the gap started
                    // slipping, until the loop ends.
                    // A latched gap keeps the slip matrix even if the law finds it open, and a gap
                    // that has closed in this loop keeps at least the stick matrix: both stop the
                    // open ↔ closed chatter of a symmetric matrix that has no cone direction.
                    closed[g] |= response.status != GapStatus::Open;
                    if response.status == GapStatus::Slip
                        && iteration != Some(0)
                        && latched[g].is_none()
                    {
                        latched[g] = Some(response.direction);
                    }
                    match (latched[g], response.status, iteration) {
                        (Some(direction), _, _) => {
                            law.ju_rowlands_matrix(GapStatus::Slip, direction)
                        }
                        (None, GapStatus::Open, _) if !closed[g] => {
                            law.ju_rowlands_matrix(GapStatus::Open, response.direction)
                        }
                        (None, _, _) => {
                            law.ju_rowlands_matrix(GapStatus::Stick, response.direction)
                        }
                    }
                }
            };
            (response.force, matrix)
        });
    }

    fn commit(&self, _start: &AnalysisState, state: &mut AnalysisState) {
        state.plastic_slip = self
            .responses
            .iter()
            .map(|r| r.plastic_slip.into())
            .collect();
        state.status = self.responses.iter().map(|r| r.status).collect();
    }

    /// The law at the converged point with the updated history gives the same forces.
    fn at_converged(&mut self, state: &AnalysisState) {
        self.take_history(state);
    }

    fn statuses(&self, out: &mut Vec<GapStatus>) {
        out.extend(self.responses.iter().map(|r| r.status));
    }

    fn gaps(&self, out: &mut Vec<f64>) {
        let gap = |(r, l): (&GapResponse, &GapLaw)| l.initial_gap + r.relative.z;
        out.extend(self.responses.iter().zip(&self.laws).map(gap));
    }

    fn status_names(&self, out: &mut Vec<String>) {
        out.extend(self.names.iter().cloned());
    }

    /// The status is the one found when the increment converged.
    fn results(
        &self,
        _at: &Evaluation<'_>,
        state: &AnalysisState,
        _model: &Model,
        out: &mut Results,
    ) {
        out.gaps = self
            .responses
            .iter()
            .zip(&state.status)
            .map(|(r, &status)| GapResult {
                slip_x: r.relative.x,
                slip_y: r.relative.y,
                normal_force: r.normal_force,
                friction_force: (r.force.x.powi(2) + r.force.y.powi(2)).sqrt(),
                friction: [r.force.x, r.force.y],
                status,
            })
            .collect();
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mech::solve::Analysis;
    use crate::mech::solve::settings::SolverSettings;
    use crate::specimens::ParallelArch;

    /// The trial/commit/restore cycle: evaluating far from the converged state changes the
    /// trial responses but not the state; `commit` writes the trial slip; `restore` brings the
    /// trial back to the converged history, so re-evaluating at the converged displacements
    /// commits the converged slip again (what a cut-back or a restored FMU state relies on).
    #[test]
    fn gap_slip_history_changes_only_through_commit_and_restore_undoes_a_trial() {
        let spec = ParallelArch::default();
        let model = spec.model().unwrap();
        let targets = spec.boundary_targets(&model, 0.5);
        let mut analysis = Analysis::new(model, SolverSettings::default()).unwrap();
        analysis.step_to(&targets, 5).unwrap();
        let converged = analysis.state().clone();
        assert!(
            converged.plastic_slip.iter().flatten().any(|s| *s != 0.0),
            "the specimen's gaps should have slipped"
        );
        let Analysis { system, parts, .. } = &mut analysis;
        let gaps = &mut parts.gaps;
        let mut residual = vec![0.0; converged.displacement.len()];
        let mut evaluate = |gaps: &mut Gaps, u: &[f64]| {
            let at = Evaluation {
                system,
                u,
                levels: &converged.loads,
                iteration: Some(1),
                matrix: IterationMatrix::Consistent,
            };
            residual.fill(0.0);
            gaps.add(&at, &mut residual, None);
            let mut committed = converged.clone();
            gaps.commit(&converged, &mut committed);
            committed.plastic_slip
        };
        gaps.restore(&converged);
        let again = evaluate(gaps, &converged.displacement);
        // A trial that drags every film node 5 cm along x.
        let dragged: Vec<f64> = converged
            .displacement
            .iter()
            .enumerate()
            .map(|(i, u)| if i % 3 == 0 { u + 0.05 } else { *u })
            .collect();
        let trial = evaluate(gaps, &dragged);
        assert_ne!(trial, again, "dragging the film should make the gaps slip");
        gaps.restore(&converged);
        assert_eq!(evaluate(gaps, &converged.displacement), again);
        let close = again
            .iter()
            .flatten()
            .zip(converged.plastic_slip.iter().flatten())
            .all(|(a, b)| (a - b).abs() <= 1e-12);
        assert!(close, "re-evaluating the converged state moved its slip");
    }
}
