//! The increment controller of a step: cut-back, enlargement and the predictor.

use crate::mech::elements::gap::IterationMatrix;
use crate::mech::elements::load::LoadLevels;
use crate::mech::solve::analysis::Analysis;
use crate::mech::solve::assembly::Dof;
use crate::mech::solve::progress::IncrementNote;
use crate::mech::solve::report::{IncrementFailure, STABILIZATION_BOUND, StepError, StepReport};
use crate::mech::solve::state::{AnalysisState, GroupMotion};

impl Analysis {
    /// Moves every boundary group to the translation `target` (m) and the hinge angle
    /// `angles` (rad, one per group: 0 for a group without a hinge), and the loads to `loads`;
    /// see [`Self::step_to_with_loads`]. The angles are interpolated linearly like the
    /// translations, so a group turns about its hinge along the arc, not along the chord.
    pub fn step_to_motion(
        &mut self,
        target: &[[f64; 3]],
        angles: &[f64],
        loads: &LoadLevels,
        increments: usize,
    ) -> Result<StepReport, StepError> {
        self.check_targets(target)?;
        self.check_angles(angles)?;
        self.check_loads(loads)?;
        if increments == 0 {
            return Err(StepError::InvalidInput {
                message: "increments must be at least 1".into(),
            });
        }
        (self.work.stabilization, self.work.dissipated) = (0.0, 0.0);
        self.work.viscous = 0.0;
        let base = self.state.boundary.clone();
        let base_angles = self.state.angles.clone();
        let base_loads = self.state.loads.clone();
        let mut current = self.state.clone();
        // The start of the last converged increment (the linear response's, `sensitivity`).
        let mut last_start = None;
        let mut report = StepReport::default();
        // The work of the viscous stabilization over the last increment it acted in (J).
        let mut last_stabilized = 0.0;
        // `report.stabilized` when the larger dampings first carried an increment of this step.
        let mut last_resort_from = None;
        let largest = 1.0 / increments as f64;
        let smallest = largest / 2f64.powi(self.settings.max_cutbacks as i32);
        let (mut done, mut size) = (0.0_f64, largest);
        // Ju–Rowlands iterations converge linearly whatever the increment: never "hard".
        let hard = match self.settings.iteration_matrix {
            IterationMatrix::Consistent => {
                Self::HARD_ITERATIONS.min(self.settings.max_iterations / 2 + 1)
            }
            IterationMatrix::JuRowlands => usize::MAX,
        };
        // The group translations and angles at the fraction `f` of the step.
        let at = |f: f64| -> GroupMotion {
            GroupMotion {
                translation: base
                    .iter()
                    .zip(target)
                    .map(|(b, t)| std::array::from_fn(|c| b[c] + (t[c] - b[c]) * f))
                    .collect(),
                angles: base_angles
                    .iter()
                    .zip(angles)
                    .map(|(b, t)| b + (t - b) * f)
                    .collect(),
            }
        };
        while done < 1.0 {
            // A flow under the larger dampings that has not reached the step's target within its
            // budget is not settling (a slack film has no equilibrium to settle to): refused.
            if let Some(from) = last_resort_from
                && report.stabilized - from > Self::LAST_RESORT_INCREMENTS
            {
                self.parts.stabilization.switch_off();
                return Err(StepError::NotConverged {
                    fraction_done: done,
                    cutbacks: report.cutbacks,
                    last: IncrementFailure::Unsettled {
                        increments: report.stabilized - from,
                    },
                });
            }
            let next = if done + size > 1.0 - 1e-12 {
                1.0
            } else {
                done + size
            };
            let levels = base_loads.interpolate(loads, next);
            // Once an increment of this step has been cut back, the rest of the step is solved
            // by LU where the LU is cheap: the unpivoted LDLᵀ and its Woodbury or Krylov solves
            // are fast on ordinary iterations, but on the edge of a mechanism (a film slack
            // across, gaps opening) LU's pivoting was measured to converge where they stall
            // (robustness bench: arch-edge family with GMRES, two strip paths with Woodbury).
            // On large meshes the LU is not affordable (10 GiB at 1 M DOF): the fast paths stay,
            // every solution still checked.
            let lu_after_cutback = self.linear.lu_affordable();
            self.linear
                .set_fast(report.cutbacks == 0 || !lu_after_cutback);
            // Likewise the watchdog: after a cut-back, monotone backtracking only (a failed
            // excursion per halved increment was measured to turn a hard path into a failure).
            self.work.watchdog = report.cutbacks == 0;
            let (continued, damped) = (report.continued, self.parts.stabilization.is_on());
            let attempt = self.solve_or_continue(&current, &at(next), &levels, &mut report);
            if let Ok((state, _)) = &attempt {
                self.account_stabilized(&mut report, &state.displacement, &mut last_stabilized);
            }
            let how = if report.continued > continued {
                "continuation"
            } else if damped {
                "stabilized"
            } else {
                "Newton"
            };
            let outcome = attempt.as_ref().map(|(_, h)| h.as_slice());
            self.note_increment(done, next, how, outcome, report.cutbacks);
            match attempt {
                Ok((state, history)) => {
                    last_start = Some(std::mem::replace(&mut current, state));
                    done = next;
                    let iterations = history.len() - 1;
                    report.iterations.push(iterations);
                    report.residual = *history.last().unwrap_or(&0.0);
                    report.residual_history = history;
                    // Easy increments let the size grow back; hard ones shrink it before a
                    // failure does.
                    if iterations <= Self::EASY_ITERATIONS {
                        size = (2.0 * size).min(largest);
                    } else if iterations >= hard && size / 2.0 >= smallest {
                        size /= 2.0;
                    }
                }
                Err(last) => {
                    if size / 2.0 >= smallest * (1.0 - 1e-9) {
                        report.cutbacks += 1;
                        size /= 2.0;
                        continue;
                    }
                    // Every smaller increment failed. With curved contacts, the smallest one
                    // again with their statuses held (`ActiveSet` in `newton.rs`); only here, so
                    // that no increment the earlier attempts converge changes its friction path
                    // (tried before the continuation and after it: either changed the
                    // curved-support specimen's stick/slip states, tests/surfaces.rs).
                    let mut reached = None;
                    let mut held = false;
                    let before = report.clone();
                    if !self.parts.curved.is_empty() {
                        self.parts.curved.active_set = true;
                        if let Ok(converged) = self.solve_increment(&current, &at(next), &levels) {
                            report.active_set += 1;
                            reached = Some((next, converged));
                            held = true;
                        }
                        self.parts.curved.active_set = false;
                        self.parts.curved.frozen = None;
                    }
                    // Then larger ones.
                    let mut larger = 2.0 * largest;
                    while reached.is_none() && larger < 2.0 * (1.0 - done) {
                        let next = (done + larger).min(1.0);
                        let levels = base_loads.interpolate(loads, next);
                        self.linear.set_fast(!lu_after_cutback);
                        if let Ok(converged) = self.solve_increment(&current, &at(next), &levels) {
                            reached = Some((next, converged));
                        }
                        larger *= 2.0;
                    }
                    // Last, the viscous stabilization at the smallest increment, for the rest of
                    // the step, from the smallest damping (`contributions/stabilization.rs`):
                    // only here, so that no increment the attempts above converge carries its
                    // force.
                    if reached.is_none() && self.settings.stabilization {
                        // Already on (softened by `account_stabilized`): only larger dampings.
                        let from = self.parts.stabilization.coefficient;
                        let dampings = Self::STABILIZATION_DAMPING
                            .into_iter()
                            .filter(|&c| c > from);
                        let motion = at(next);
                        if let Some(converged) =
                            self.solve_damped(dampings, &current, &motion, &levels, &mut report)
                        {
                            reached = Some((next, converged));
                            held = true;
                        }
                    }
                    // Then, where the last attempt saw sliding-direction contacts lift off while
                    // holding the film across (the law's jump, with no equilibrium on either
                    // side), they lift off and land again within the increment, and it is tried
                    // again from the same start (docs/mechanics.md, "Lift-off with the paper's
                    // law"): only here, so that every path the attempts above converge is
                    // computed as before.
                    if reached.is_none()
                        && self.release_lift_off(last.lifting(), &mut current, &mut report)
                    {
                        continue;
                    }
                    // Then, with curved contacts or a tension-field film, the smoothing homotopy
                    // (`smoothing.rs`): only here, so that every path the attempts above converge
                    // is computed as before. Where it is refused naming contacts that lift off
                    // with more than μN across (its rounded problems see lift-offs the attempts
                    // above did not reach), they are released as above and the increment tried
                    // again.
                    if reached.is_none() && self.settings.smoothing && self.smoothing_applies() {
                        self.parts.stabilization.switch_off();
                        match self.solve_smoothed(&current, &at(next), &levels, &mut report) {
                            Ok(converged) => {
                                reached = Some((next, converged));
                                held = true;
                            }
                            Err(lifting) => {
                                if self.release_lift_off(&lifting, &mut current, &mut report) {
                                    continue;
                                }
                            }
                        }
                    }
                    // Last of all, the viscous stabilization with larger dampings
                    // ([`Self::STABILIZATION_LAST_RESORT`]): a step of the film that no damping
                    // up to the largest of [`Self::STABILIZATION_DAMPING`] and no rounded law
                    // carries across (held-out `arches#3`: contacts chattering while film elements
                    // switch between wrinkled and taut). Only here, so that every path the
                    // attempts above converge is computed as before; its work is accounted and
                    // released at the step's end like any damped increment's, and a step left
                    // above the bound is reported as such.
                    if reached.is_none() && self.settings.stabilization {
                        let dampings = Self::STABILIZATION_LAST_RESORT;
                        let motion = at(next);
                        if let Some(converged) =
                            self.solve_damped(dampings, &current, &motion, &levels, &mut report)
                        {
                            reached = Some((next, converged));
                            held = true;
                            report.damped_jumps += 1;
                            last_resort_from.get_or_insert(report.stabilized);
                        }
                    }
                    let Some((next, (state, history))) = reached else {
                        self.parts.stabilization.switch_off();
                        return Err(StepError::NotConverged {
                            fraction_done: done,
                            cutbacks: report.cutbacks,
                            last,
                        });
                    };
                    if !held {
                        report.enlarged += 1;
                    }
                    let how = report.ladder_rung(&before);
                    self.note_increment(done, next, how, Ok(&history), report.cutbacks);
                    self.account_stabilized(&mut report, &state.displacement, &mut last_stabilized);
                    last_start = Some(std::mem::replace(&mut current, state));
                    done = next;
                    report.iterations.push(history.len() - 1);
                    report.residual = *history.last().unwrap_or(&0.0);
                    report.residual_history = history;
                    size = largest;
                }
            }
        }
        if self.parts.stabilization.is_on()
            && last_stabilized
                > STABILIZATION_BOUND * self.strain_energy_at(&current.displacement).abs()
        {
            let motion = at(1.0);
            let levels = base_loads.interpolate(loads, 1.0);
            self.release_stabilization(
                &mut current,
                &mut last_start,
                &motion,
                &levels,
                &mut report,
                &mut last_stabilized,
            );
        }
        self.state = current;
        self.increment_start = last_start;
        self.linear.set_fast(true);
        self.parts.stabilization.switch_off();
        self.work.stabilization += last_stabilized;
        report.stabilization_energy = std::mem::take(&mut self.work.stabilization);
        report.stabilization_dissipated = std::mem::take(&mut self.work.dissipated);
        report.viscous_dissipated = std::mem::take(&mut self.work.viscous);
        report.strain_energy = self.strain_energy();
        Ok(report)
    }

    /// The increment from `start` to `motion` and `levels` by plain Newton, then, where that fails
    /// and the continuation is on, by the continuation (counted in `report.continued`, the
    /// artificial energy of its last correction added to the step's). Err: the last attempt's.
    /// Tells the observer (`progress.rs`) how the increment from `from` to `to` of the step
    /// ended: converged by `how`, or refused.
    fn note_increment(
        &self,
        from: f64,
        to: f64,
        how: &'static str,
        outcome: Result<&[f64], &IncrementFailure>,
        cutbacks: usize,
    ) {
        self.observer.note(|| IncrementNote {
            from,
            to,
            attempt: how,
            iterations: outcome.map_or(0, |h| h.len().saturating_sub(1)),
            residual: outcome.map_or(f64::NAN, |h| h.last().copied().unwrap_or(0.0)),
            refused: outcome.err().map(IncrementFailure::phrase),
            cutbacks,
        });
    }

    fn solve_or_continue(
        &mut self,
        start: &AnalysisState,
        motion: &GroupMotion,
        levels: &LoadLevels,
        report: &mut StepReport,
    ) -> Result<(AnalysisState, Vec<f64>), IncrementFailure> {
        let plain = self.solve_increment(start, motion, levels);
        if plain.is_ok() || !self.settings.continuation {
            return plain;
        }
        self.work.continuation = true;
        let again = self.solve_increment(start, motion, levels);
        self.work.continuation = false;
        if again.is_ok() {
            report.continued += 1;
            self.work.stabilization += self.work.last_work;
        }
        again
    }

    /// The increment from `start` to `motion` and `levels` with the viscous stabilization on at
    /// each of `dampings` in turn, by plain Newton and then the continuation (a contact changing
    /// status raises the pseudo-time shift instead of cutting the step along a direction of the
    /// other status); the first that converges, the stabilization left on for the rest of the
    /// step. None, the stabilization off, where every one is refused.
    fn solve_damped(
        &mut self,
        dampings: impl IntoIterator<Item = f64>,
        start: &AnalysisState,
        motion: &GroupMotion,
        levels: &LoadLevels,
        report: &mut StepReport,
    ) -> Option<(AnalysisState, Vec<f64>)> {
        for c in dampings {
            self.parts.stabilization.switch_on(c);
            if let Ok(converged) = self.solve_or_continue(start, motion, levels, report) {
                return Some(converged);
            }
        }
        self.parts.stabilization.switch_off();
        None
    }

    /// Lets the viscous stabilization's force decay at the step's end (`current`: the last
    /// converged state, at the step's target `motion` and `levels`), where its last increment left
    /// more work than [`STABILIZATION_BOUND`] of the strain energy: the damping force is `c k̄ m ΔU`
    /// with `ΔU` the motion since the increment's start, so an increment at the same target from
    /// the damped equilibrium is the same load held for more pseudo-time, and its force is that of
    /// the (smaller) remaining motion. Each round tries the equilibrium without damping (plain
    /// Newton, then the continuation); failing that, one more damped increment (whose damping
    /// [`Self::account_stabilized`] softens; if the softened one fails, ten times larger ones up to
    /// the largest of [`Self::STABILIZATION_DAMPING`]). Ends within the bound, after
    /// [`Self::RELEASE_ROUNDS`], or at a failure, which keeps the last converged state. An
    /// increment converged here is counted in `report.released`.
    fn release_stabilization(
        &mut self,
        current: &mut AnalysisState,
        last_start: &mut Option<AnalysisState>,
        motion: &GroupMotion,
        levels: &LoadLevels,
        report: &mut StepReport,
        last_stabilized: &mut f64,
    ) {
        for _ in 0..Self::RELEASE_ROUNDS {
            let damping = self.parts.stabilization.coefficient;
            let scale = self.parts.stabilization.scale;
            self.parts.stabilization.switch_off();
            let plain = self.solve_or_continue(current, motion, levels, report);
            let mut released = None;
            if let Ok(converged) = plain {
                *last_stabilized = 0.0;
                released = Some(converged);
            } else {
                // The softened damping, and where that fails larger ones up to the largest the
                // step tries (shorter pseudo-time steps).
                let largest = Self::STABILIZATION_DAMPING[Self::STABILIZATION_DAMPING.len() - 1];
                let mut c = damping;
                while c <= largest * (1.0 + 1e-9) {
                    self.parts.stabilization.resume(c, scale);
                    if let Ok(converged) = self.solve_increment(current, motion, levels) {
                        self.account_stabilized(report, &converged.0.displacement, last_stabilized);
                        released = Some(converged);
                        break;
                    }
                    c *= 10.0;
                }
            }
            let Some((mut state, history)) = released else {
                return;
            };
            // The step's last increment, for the predictor of the next step, is the motion from
            // the start of the last loaded increment to here.
            for (l, a) in state.last_increment.iter_mut().zip(&current.last_increment) {
                *l += a;
            }
            report.released += 1;
            let how = "release at the step's end";
            self.note_increment(1.0, 1.0, how, Ok(&history), report.cutbacks);
            report.iterations.push(history.len() - 1);
            report.residual = *history.last().unwrap_or(&0.0);
            report.residual_history = history;
            *last_start = Some(std::mem::replace(current, state));
            if !self.parts.stabilization.is_on()
                || *last_stabilized
                    <= STABILIZATION_BOUND * self.strain_energy_at(&current.displacement).abs()
            {
                return;
            }
        }
    }

    /// Marks the sliding-direction contacts `lifting` (named by a refused attempt as lifting off
    /// with more than μN across) as lifting off and landing again within the increment from
    /// `current` (`Contribution::release_lift_off`), up to [`Self::LIFT_OFF_RELEASES`] in a
    /// step; whether any was, the increment then to be tried again from the same start, without
    /// the damping.
    fn release_lift_off(
        &mut self,
        lifting: &[String],
        current: &mut AnalysisState,
        report: &mut StepReport,
    ) -> bool {
        if report.lifted_off.len() >= Self::LIFT_OFF_RELEASES || lifting.is_empty() {
            return false;
        }
        let before = report.lifted_off.len();
        for c in self.parts.all_mut() {
            c.release_lift_off(lifting, current, &mut report.lifted_off);
        }
        if report.lifted_off.len() == before {
            return false;
        }
        self.parts.stabilization.switch_off();
        true
    }

    /// Most cross holds [`Self::step_to_motion`] releases in a step at sliding-direction
    /// contacts lifting off (each contact at most once per increment).
    const LIFT_OFF_RELEASES: usize = 64;

    /// Most increments [`Self::release_stabilization`] adds to a step: the budget of damped
    /// increments of [`Self::LAST_RESORT_INCREMENTS`] (Abaqus' `*STEP, INC=100`). On a film
    /// creeping along a mechanism the remainder shrinks a few per cent a round: the 5-step hinged
    /// panel's step 4 reaches the bound in 45 rounds (8 left it at 3.9e-3 of the strain energy).
    const RELEASE_ROUNDS: usize = Self::LAST_RESORT_INCREMENTS;

    /// Accounts an increment converged at `u`: with the viscous stabilization on, counts it and
    /// adds its work to the work taken out; `last` becomes the work of the damping force the
    /// converged state carries (J): this increment's, and 0 for an increment solved without
    /// the damping (after the smoothing homotopy or a lift-off release switched it off), whose
    /// answer carries none of an earlier increment's.
    fn account_stabilized(&mut self, report: &mut StepReport, u: &[f64], last: &mut f64) {
        if self.parts.stabilization.is_on() {
            report.stabilized += 1;
            let (work, _) = self.parts.stabilization.work_and_force(&self.system, u);
            self.work.dissipated += work;
            self.work.viscous += work;
            *last = work;
            // Adaptive, as Abaqus' adaptive stabilization: an increment that left more than the
            // bound makes the damping of the next ones ten times smaller.
            if work > STABILIZATION_BOUND * self.strain_energy_at(u).abs() {
                self.parts.stabilization.soften();
            }
        } else {
            *last = 0.0;
        }
    }

    /// The damping coefficients `c` the viscous stabilization tries, in turn, on the increment
    /// that turns it on (relative to the mean stiffness: `contributions/stabilization.rs`).
    pub(crate) const STABILIZATION_DAMPING: [f64; 2] = [1e-5, 1e-3];

    /// The larger dampings the viscous stabilization tries, in turn, where every other attempt
    /// on the smallest increment was refused, the smoothing homotopy included: ten and a hundred
    /// times the largest of [`Self::STABILIZATION_DAMPING`]. Abaqus' adaptive stabilization
    /// likewise raises its damping factor where an increment does not converge (Abaqus Analysis
    /// User's Guide, "Automatic stabilization of unstable problems", adaptive scheme); the
    /// work left at the step's end is judged against the same bound ([`STABILIZATION_BOUND`]).
    pub(crate) const STABILIZATION_LAST_RESORT: [f64; 2] = [1e-2, 1e-1];

    /// Most damped increments a step may take once [`Self::STABILIZATION_LAST_RESORT`] has
    /// carried one of them; beyond it the step is refused ([`IncrementFailure::Unsettled`]).
    /// Abaqus' default maximum number of increments in a step (`*STEP, INC=100`). Each damped
    /// increment is one pseudo-time step of a viscous flow towards the equilibrium; held-out
    /// `arches#3` reaches its target in 10, while the slack plastic film released in
    /// `examples/fig8_plastic.py` flowed on for 22 458 (164 s) before it came to rest.
    pub(crate) const LAST_RESORT_INCREMENTS: usize = 100;

    /// Converged increments with at most this many iterations let the increment grow.
    pub(crate) const EASY_ITERATIONS: usize = 5;
    /// Converged increments with at least this many iterations (or half the limit) shrink the
    /// next one (consistent tangent only).
    pub(crate) const HARD_ITERATIONS: usize = 15;

    /// The first iterate of an increment from the converged `start` to `motion`: the
    /// prescribed DOFs at their values and, when the boundary keeps moving the same way, the
    /// free DOFs extrapolated along the last converged increment (fewer iterations, same
    /// converged answer), then corrected by each contribution where the extrapolation leaves
    /// its constraint (`Contribution::correct_prediction`: closed curved-support contacts
    /// kept at their converged gap).
    pub(super) fn predict(&self, start: &AnalysisState, motion: &GroupMotion) -> Vec<f64> {
        let mut u = self.unextrapolated(start, motion);
        let (mut dot, mut old, mut new) = (0.0, 0.0, 0.0);
        for (i, d) in self.system.dofs.iter().enumerate() {
            if let Dof::Prescribed { .. } = d {
                let step = u[i] - start.displacement[i];
                let last = start.last_increment.get(i).copied().unwrap_or(0.0);
                (dot, old, new) = (dot + step * last, old + last * last, new + step * step);
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
            for c in self.parts.all() {
                c.correct_prediction(&self.system, start, &mut u);
            }
        }
        u
    }

    /// The converged `start` with the prescribed DOFs moved to `motion` and every other DOF
    /// where it was: the predictor without its extrapolation.
    pub(super) fn unextrapolated(&self, start: &AnalysisState, motion: &GroupMotion) -> Vec<f64> {
        let mut u = start.displacement.clone();
        for (i, d) in self.system.dofs.iter().enumerate() {
            if let Dof::Prescribed { group, component } = d {
                u[i] = self.prescribed_value(i, *group, *component, motion);
            }
        }
        u
    }

    /// Largest ratio of the predictor's extrapolation to the last converged increment.
    const PREDICTOR_LIMIT: f64 = 2.0;
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mech::solve::settings::{DEFAULT_INCREMENTS_PER_STEP, SolverSettings};
    use crate::specimens::ParallelArch;
    use crate::specimens::scenarios::ArchEdge;

    /// The predictor extrapolates the free DOFs along the last converged increment when the
    /// boundary keeps moving the same way (by the ratio of the moves, at most
    /// [`Analysis::PREDICTOR_LIMIT`] times), not at all when it turns back; the prescribed DOFs
    /// are at their new values and the fixed ones stay, either way.
    #[test]
    fn predictor_extrapolates_only_a_motion_that_keeps_its_direction() {
        let spec = ParallelArch::default();
        let model = spec.model().unwrap();
        let first = spec.boundary_targets(&model, 0.1);
        let mut a = Analysis::new(model, SolverSettings::default()).unwrap();
        a.step_to(&first, 1).unwrap();
        let start = a.state().clone();
        let motion = |scale: f64| GroupMotion {
            translation: first.iter().map(|t| t.map(|v| v * scale)).collect(),
            angles: vec![0.0; first.len()],
        };
        // Moves of 1×, −1× and 4× the last increment.
        let (same, back, far) = (
            a.predict(&start, &motion(2.0)),
            a.predict(&start, &motion(0.0)),
            a.predict(&start, &motion(5.0)),
        );
        let mut extrapolated = 0;
        for (i, d) in a.system.dofs.iter().enumerate() {
            let (u0, du) = (start.displacement[i], start.last_increment[i]);
            match *d {
                Dof::Free(_) => {
                    let near = |x: f64, y: f64| (x - y).abs() <= 1e-12 * (1.0 + y.abs());
                    assert!(
                        near(same[i], u0 + du),
                        "DOF {i}: {} vs {}",
                        same[i],
                        u0 + du
                    );
                    assert!(near(far[i], u0 + 2.0 * du), "DOF {i}");
                    assert_eq!(back[i], u0, "DOF {i}");
                    extrapolated += usize::from(du != 0.0);
                }
                Dof::Prescribed { group, component } => {
                    assert_eq!(same[i], 2.0 * first[group][component]);
                    assert_eq!(back[i], 0.0);
                }
                Dof::Fixed => assert_eq!((same[i], far[i], back[i]), (u0, u0, u0)),
            }
        }
        assert!(extrapolated > 0, "the first step moved no free DOF");
    }

    /// A step whose viscously stabilized last increment leaves more work than the bound is not
    /// left there: the damping is released at the step's target, and the answer is the
    /// undamped equilibrium (the 300 mm specimen without friction, so that the equilibrium
    /// does not depend on the path to it; the damping forced on at `c` = 0.1, ten thousand times
    /// what the controller starts with, for every increment).
    #[test]
    fn a_step_ending_above_the_stabilization_bound_is_released_to_the_undamped_equilibrium() {
        let spec = ParallelArch {
            friction: 0.0,
            ..ParallelArch::default()
        };
        let model = spec.model().unwrap();
        let target = spec.boundary_targets(&model, 0.1);
        let mut plain = Analysis::new(model.clone(), SolverSettings::default()).unwrap();
        let undamped = plain.step_to(&target, 1).unwrap();
        assert_eq!((undamped.stabilized, undamped.released), (0, 0));
        let mut damped = Analysis::new(model, SolverSettings::default()).unwrap();
        damped.parts.stabilization.switch_on(0.1);
        let report = damped.step_to(&target, 1).unwrap();
        assert!(report.stabilized >= 1 && report.released >= 1, "{report:?}");
        assert!(
            report.stabilization_ratio() <= STABILIZATION_BOUND,
            "{}",
            report.stabilization_ratio()
        );
        let (a, b) = (&plain.state().displacement, &damped.state().displacement);
        let scale = a.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
        let differ = a
            .iter()
            .zip(b)
            .fold(0.0_f64, |m, (x, y)| m.max((x - y).abs()));
        assert!(differ <= 1e-4 * scale, "{differ:e} m against {scale:e} m");
    }

    /// The first step of the 80-step arch edge (a film slack across its edge) does not converge
    /// by plain Newton in the FMU's tenth of a step: without continuation the controller
    /// enlarges the increment after the smallest one failed (and reports it); with it (the
    /// default) the continuation converges the FMU's increment itself, and reports that.
    #[test]
    fn arch_edge_first_step_is_continued_not_enlarged() {
        let increments = DEFAULT_INCREMENTS_PER_STEP;
        let edge = ArchEdge::default();
        let scenario = edge.lowered(0.5, 80, increments).unwrap();
        let target = [[0.0, 0.0, -0.5 * edge.arch_height / 80.0]];
        let plain = SolverSettings {
            continuation: false,
            ..SolverSettings::default()
        };
        let mut analysis = Analysis::new(scenario.model.clone(), plain).unwrap();
        let report = analysis.step_to(&target, increments).unwrap();
        assert!(report.enlarged >= 1 && report.continued == 0, "{report:?}");
        let mut analysis = Analysis::new(scenario.model, SolverSettings::default()).unwrap();
        let report = analysis.step_to(&target, increments).unwrap();
        assert!(report.continued >= 1 && report.enlarged == 0, "{report:?}");
        assert!(report.residual.is_finite());
        assert!(report.stabilization_ratio() <= crate::mech::solve::report::STABILIZATION_BOUND);
    }
}
