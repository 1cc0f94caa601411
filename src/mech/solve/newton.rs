//! Newton–Raphson for one increment.

use nalgebra::Vector2;

use crate::mech::elements::curved_contact::SurfaceContacts;
use crate::mech::elements::gap::{GapLaw, GapStatus, IterationMatrix};
use crate::mech::elements::load::{ExternalLoad, LoadLevels};
use crate::mech::elements::material::Wrinkling;
use crate::mech::elements::triangle::ElementVector;
use crate::mech::elements::triangle::MembraneTriangle;
use crate::mech::solve::analysis::{Analysis, Workspace};
use crate::mech::solve::assembly::{Dof, node_dofs};
use crate::mech::solve::line_search::Watchdog;
use crate::mech::solve::report::{IncrementFailure, IterationRecord};
use crate::mech::solve::state::{AnalysisState, GroupMotion};

impl Analysis {
    /// Newton–Raphson for one increment from the converged `start` to the group motion
    /// `motion` and the load levels `levels`.
    pub(crate) fn solve_increment(
        &mut self,
        start: &AnalysisState,
        motion: &GroupMotion,
        levels: &LoadLevels,
    ) -> Result<(AnalysisState, Vec<f64>), IncrementFailure> {
        let mut u = start.displacement.clone();
        // Predictor: when the boundary keeps moving the same way, extrapolate the free DOFs
        // along the last converged increment (fewer iterations, same converged answer).
        let (mut dot, mut old, mut new) = (0.0, 0.0, 0.0);
        for (i, d) in self.system.dofs.iter().enumerate() {
            if let Dof::Prescribed { group, component } = d {
                let value = self.prescribed_value(i, *group, *component, motion);
                let step = value - start.displacement[i];
                let last = start.last_increment.get(i).copied().unwrap_or(0.0);
                (dot, old, new) = (dot + step * last, old + last * last, new + step * step);
                u[i] = value;
            }
        }
        if old > 0.0 && dot > 0.99 * (old * new).sqrt() {
            // Not beyond twice the last increment: an enlarged increment (see `step_to`) would
            // otherwise extrapolate the film far outside the range where the last one tells
            // anything (residuals of 1e11 N were measured at its first iterate).
            let ratio = (dot / old).min(Self::PREDICTOR_LIMIT);
            for (i, d) in self.system.dofs.iter().enumerate() {
                if let Dof::Free(_) = d {
                    u[i] += ratio * start.last_increment[i];
                }
            }
        }
        let (laws, history) = self.laws_and_history(start);
        self.work.contact_start.clone_from(&start.contacts);
        self.work.latched.iter_mut().for_each(|l| *l = None);
        self.work.closed.iter_mut().for_each(|c| *c = false);
        // A model without free DOFs (every node prescribed or fixed: how single elements are
        // verified) has nothing to solve: the first assembly evaluates the forces, the gaps'
        // return mapping and the reactions at the prescribed configuration, and converges.
        let mut correction_norm = if self.system.free_count == 0 {
            0.0
        } else {
            f64::INFINITY
        };
        // The iterate before the last correction (to name elements whose state flips).
        let mut previous_u = u.clone();
        let mut residuals = Vec::new();
        let mut assembled = false;
        // Status of every gap at the previous iteration and the last iteration it changed.
        let mut previous: Vec<GapStatus> = start.status.clone();
        let mut changed_at: Vec<Option<usize>> = vec![None; previous.len()];
        let (mut best, mut best_correction, mut best_at) = (f64::INFINITY, f64::INFINITY, 0);
        // The iterate closest to meeting both tolerances (quoted if the increment stalls).
        let mut closest: Option<IterationRecord> = None;
        // Levenberg–Marquardt shift of the free diagonal, relative to its mean.
        let mut damping = 0.0_f64;
        // The watchdog of the line search: non-monotone excursions until one fails.
        let mut watch = if self.work.watchdog {
            Watchdog::Ready
        } else {
            Watchdog::Used
        };
        let s = self.settings;
        for iteration in 0..=s.max_iterations {
            let residual = if assembled {
                self.free_norm_inf()
            } else {
                self.assemble_at(&u, &laws, &history, levels, Some(iteration))
            };
            if !residual.is_finite() {
                return Err(IncrementFailure::Diverged { iteration });
            }
            residuals.push(residual);
            for (g, r) in self.work.responses.iter().enumerate() {
                if r.status != previous[g] {
                    previous[g] = r.status;
                    changed_at[g] = Some(iteration);
                }
            }
            let moved = max_abs_difference(&u, &start.displacement);
            let displacement_scale = moved.max(max_abs(&u)).max(1e-9 * self.length_scale);
            let force_scale = max_abs(&self.work.internal).max(self.force_floor);
            let tolerance = s.residual_tolerance * force_scale;
            let record = IterationRecord {
                iteration,
                residual,
                residual_tolerance: tolerance,
                correction: correction_norm,
                correction_tolerance: s.displacement_tolerance * displacement_scale,
            };
            let converged = (iteration > 0 || self.system.free_count == 0)
                && record.correction <= record.correction_tolerance
                && residual <= tolerance;
            if converged {
                let state = AnalysisState {
                    plastic_slip: self
                        .work
                        .responses
                        .iter()
                        .map(|r| r.plastic_slip.into())
                        .collect(),
                    contacts: SurfaceContacts::commit(
                        &self.work.contact_responses,
                        &start.contacts,
                    ),
                    boundary: motion.translation.clone(),
                    angles: motion.angles.clone(),
                    loads: levels.clone(),
                    friction: start.friction.clone(),
                    status: self.work.responses.iter().map(|r| r.status).collect(),
                    last_increment: u
                        .iter()
                        .zip(&start.displacement)
                        .map(|(a, b)| a - b)
                        .collect(),
                    displacement: u,
                };
                if !state.is_finite() {
                    return Err(IncrementFailure::Diverged { iteration });
                }
                return Ok((state, residuals));
            }
            // Gaps that changed status in the last few iterations: the usual cause of a stall.
            let recent = iteration.saturating_sub(Self::STALL_PATIENCE / 2);
            let chattering = || -> Vec<String> {
                changed_at
                    .iter()
                    .enumerate()
                    .filter(|(_, c)| c.is_some_and(|c| c > 0 && c >= recent))
                    .map(|(g, _)| self.model.gaps[g].name.clone())
                    .collect()
            };
            if iteration > 0 && closest.is_none_or(|c| record.distance() < c.distance()) {
                closest = Some(record);
            }
            if iteration == s.max_iterations {
                return Err(IncrementFailure::MaxIterations {
                    first_residual: residuals[0],
                    last: record,
                    matrix: s.iteration_matrix,
                    chattering: chattering(),
                    flipping: self.flipping_elements(&previous_u, &u),
                });
            }
            if iteration > 3 && residual > 1e6 * residuals[0].max(force_scale) {
                return Err(IncrementFailure::Diverged { iteration });
            }
            // Progress is a residual or a correction 10 % below the best so far: a cycle between
            // two states repeats both to round-off and never makes it, while the slow approach
            // along a soft direction of the film (small residual, shrinking corrections) does. The Ju–Rowlands matrix converges
            // linearly and slowly by design (docs/mechanics.md): it is judged by the limit only.
            if residual < Self::PROGRESS * best
                || correction_norm < Self::PROGRESS * best_correction
            {
                best = best.min(residual);
                best_correction = best_correction.min(correction_norm);
                best_at = iteration;
            } else if s.iteration_matrix == IterationMatrix::Consistent
                && iteration >= best_at + Self::STALL_PATIENCE
            {
                return Err(IncrementFailure::Stalled {
                    iteration,
                    closest: closest.unwrap_or(record),
                    chattering: chattering(),
                    flipping: self.flipping_elements(&previous_u, &u),
                });
            }
            for (i, d) in self.system.dofs.iter().enumerate() {
                if let Dof::Free(eq) = d {
                    self.work.rhs[*eq] = -self.work.internal[i];
                }
            }
            if damping > 0.0 {
                let values = &mut self.work.values;
                let mean = self
                    .work
                    .diagonal
                    .iter()
                    .map(|&d| values[d].abs())
                    .sum::<f64>()
                    / self.work.diagonal.len() as f64;
                for &d in &self.work.diagonal {
                    values[d] += damping * mean;
                }
            }
            let matrix = self.system.matrix(&self.work.values);
            self.linear
                .factorize_and_solve(matrix, &mut self.work.rhs)
                .map_err(|e| IncrementFailure::Singular { message: e.0 })?;
            correction_norm = max_abs(&self.work.rhs);
            if !correction_norm.is_finite() {
                return Err(IncrementFailure::Diverged { iteration });
            }
            previous_u.clone_from(&u);
            let (step, with_tangent, decreased) =
                self.line_search(&mut u, &laws, &history, levels, iteration + 1, &mut watch);
            assembled = with_tangent;
            if step.is_infinite() {
                // The watchdog went back to where its excursion started: the iterations spent
                // on it are not a stall of the iteration from here.
                best_at = iteration + 1;
            }
            correction_norm *= step;
            // Levenberg–Marquardt: a direction that cannot lower the residual (a mechanism of an
            // unstressed film, an indefinite compressed one) gets a diagonal shift, raised until
            // steps succeed and lowered again after full ones. Only the iteration matrix changes,
            // never the residual: the converged state is the same, and with the shift gone the
            // last iterations are Newton's again.
            if s.iteration_matrix == IterationMatrix::Consistent {
                damping = if !decreased {
                    (4.0 * damping).max(Self::DAMPING_START)
                } else if step == 1.0 && damping > 0.0 {
                    let lower = damping / 4.0;
                    if lower < Self::DAMPING_START / 64.0 {
                        0.0
                    } else {
                        lower
                    }
                } else {
                    damping
                };
            }
        }
        unreachable!("the loop returns at max_iterations")
    }

    /// Film elements whose tension-field state differs between the displacements `a` and `b`
    /// (none without wrinkling). Called once when an increment fails, never per iteration.
    pub(crate) fn flipping_elements(&self, a: &[f64], b: &[f64]) -> Vec<usize> {
        if self.system.material.wrinkling == Wrinkling::None {
            return vec![];
        }
        let state = |u: &[f64], nodes: &[usize; 3], tri: &MembraneTriangle| {
            let dofs = node_dofs(nodes);
            let ue = ElementVector::from_fn(|i, _| u[dofs[i]]);
            tri.stress_state(&self.system.material, &ue).state
        };
        self.system
            .triangles
            .iter()
            .enumerate()
            .filter(|(_, (nodes, tri))| state(a, nodes, tri) != state(b, nodes, tri))
            .map(|(e, _)| e)
            .collect()
    }

    /// Largest ratio of the predictor's extrapolation to the last converged increment.
    pub(crate) const PREDICTOR_LIMIT: f64 = 2.0;

    /// First Levenberg–Marquardt shift (fraction of the mean diagonal of the Newton matrix).
    pub(crate) const DAMPING_START: f64 = 1e-4;
    /// A residual below this fraction of the best so far counts as progress.
    pub(crate) const PROGRESS: f64 = 0.9;
    /// Iterations without progress before an increment is declared stalled and cut back.
    pub(crate) const STALL_PATIENCE: usize = 8;

    /// `‖R_free‖∞` of the last assembly.
    pub(crate) fn free_norm_inf(&self) -> f64 {
        max_abs(
            self.system
                .dofs
                .iter()
                .zip(&self.work.internal)
                .filter(|(d, _)| matches!(d, Dof::Free(_)))
                .map(|(_, r)| r),
        )
    }

    /// `‖R_free‖₂` of the last assembly.
    pub(crate) fn free_norm2(&self) -> f64 {
        self.system
            .dofs
            .iter()
            .zip(&self.work.internal)
            .filter(|(d, _)| matches!(d, Dof::Free(_)))
            .map(|(_, r)| r * r)
            .sum::<f64>()
            .sqrt()
    }

    /// Assembles the residual `f_int − f_ext` over all DOFs (and the Newton matrix when
    /// `iteration` is given) at `u` with the loads at `levels`; returns `‖R_free‖∞`. Gap
    /// responses are left in the workspace.
    pub(crate) fn assemble_at(
        &mut self,
        u: &[f64],
        laws: &[GapLaw],
        history: &[Vector2<f64>],
        levels: &LoadLevels,
        iteration: Option<usize>,
    ) -> f64 {
        let mode = self.settings.iteration_matrix;
        let Workspace {
            internal,
            values,
            responses,
            latched,
            closed,
            contact_start,
            contact_responses,
            ..
        } = &mut self.work;
        let mut values = iteration.map(|_| values.as_mut_slice());
        self.system
            .assemble(u, internal, values.as_deref_mut(), |g, d| {
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
        self.loads
            .add_to(&self.system, levels, u, internal, values.as_deref_mut());
        self.cables
            .add_to(&self.system, levels, u, internal, values.as_deref_mut());
        self.surfaces.add_to(
            &self.system,
            u,
            contact_start,
            internal,
            values,
            contact_responses,
        );
        self.free_norm_inf()
    }

    /// Gap laws with the friction coefficients of `state`, and its slip history.
    pub(crate) fn laws_and_history(
        &self,
        state: &AnalysisState,
    ) -> (Vec<GapLaw>, Vec<Vector2<f64>>) {
        let laws = self
            .laws
            .iter()
            .zip(&state.friction)
            .map(|(l, &mu)| GapLaw { friction: mu, ..*l })
            .collect();
        let history = state
            .plastic_slip
            .iter()
            .map(|s| Vector2::from(*s))
            .collect();
        (laws, history)
    }
}

/// `max |v|`, NaN when any value is NaN (`f64::max` alone would skip a NaN and report the
/// rest: a NaN residual would then measure 0 and pass a convergence test).
pub fn max_abs<'a>(values: impl IntoIterator<Item = &'a f64>) -> f64 {
    values.into_iter().fold(0.0, |m, v| nan_max(m, v.abs()))
}

/// `max(m, v)` that keeps a NaN of either argument.
pub(crate) fn nan_max(m: f64, v: f64) -> f64 {
    if v.is_nan() || m.is_nan() {
        f64::NAN
    } else {
        m.max(v)
    }
}

/// `max |a − b|` over two equally long vectors, NaN-aware like [`max_abs`].
pub(crate) fn max_abs_difference(a: &[f64], b: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .fold(0.0, |m, (x, y)| nan_max(m, (x - y).abs()))
}
