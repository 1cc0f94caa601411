//! The increment controller of a step, its strategy table, and the predictor.

use crate::mech::elements::gap::IterationMatrix;
use crate::mech::elements::load::LoadLevels;
use crate::mech::solve::analysis::Analysis;
use crate::mech::solve::assembly::Dof;
use crate::mech::solve::progress::IncrementNote;
use crate::mech::solve::report::{Attempt, IncrementFailure, StepError, StepReport};
use crate::mech::solve::state::{AnalysisState, GroupMotion};

/// One row of the strategy table: how the increments of a step are solved once the rows before
/// it refused the smallest increment. The step's report lists the rows it used
/// ([`StepReport::attempts`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Strategy {
    /// Its name in reports and logs.
    pub name: &'static str,
    /// The viscous stabilization's damping per unit of the step's pseudo-time (0: none):
    /// the force `c k̄ M ΔU/Δλ` of an increment `Δλ` (`contributions/stabilization.rs`).
    pub damping: f64,
}

/// The strategy table: Newton with pseudo-transient continuation, then the same with the
/// viscous stabilization for the rest of a step whose smallest increment it refused (a film
/// without a unique equilibrium), at three dampings ([`SolverSettings::stabilization`] off: the
/// first row only).
///
/// [`SolverSettings::stabilization`]: crate::mech::solve::settings::SolverSettings::stabilization
pub const STRATEGIES: [Strategy; 4] = [
    Strategy {
        name: "Newton",
        damping: 0.0,
    },
    Strategy {
        name: "stabilized",
        damping: 1e-6,
    },
    Strategy {
        name: "stabilized more",
        damping: 1e-4,
    },
    Strategy {
        name: "stabilized most",
        damping: 1e-2,
    },
];

/// The straight path of a step in the inputs: groups, angles and load levels from the converged
/// state's to the step's targets.
struct StepPath<'a> {
    base: Vec<[f64; 3]>,
    base_angles: Vec<f64>,
    base_loads: LoadLevels,
    target: &'a [[f64; 3]],
    angles: &'a [f64],
    loads: &'a LoadLevels,
}

impl StepPath<'_> {
    /// The group translations and angles at the fraction `f` of the step.
    fn motion(&self, f: f64) -> GroupMotion {
        GroupMotion {
            translation: self
                .base
                .iter()
                .zip(self.target)
                .map(|(b, t)| std::array::from_fn(|c| b[c] + (t[c] - b[c]) * f))
                .collect(),
            angles: self
                .base_angles
                .iter()
                .zip(self.angles)
                .map(|(b, t)| b + (t - b) * f)
                .collect(),
        }
    }

    /// The load levels at the fraction `f` of the step.
    fn levels(&self, f: f64) -> LoadLevels {
        self.base_loads.interpolate(self.loads, f)
    }
}

impl Analysis {
    /// Moves every boundary group to the translation `target` (m) and the hinge angle
    /// `angles` (rad, one per group: 0 for a group without a hinge), and the loads to `loads`;
    /// see [`Self::step_to_with_loads`]. The angles are interpolated linearly like the
    /// translations, so a group turns about its hinge along the arc, not along the chord.
    ///
    /// The increment controller (Ramm 1981; Crisfield 1991, §9.5): the first increment is the
    /// step's `1/increments`; after one converged in `N` iterations the next is
    /// `Δλ (N*/N)^½` ([`Self::TARGET_ITERATIONS`]), within a factor [`Self::GROWTH`] of it and
    /// at most `1/increments`; a refused one is halved, up to `max_cutbacks` times, and below
    /// that the next row of [`STRATEGIES`] solves the rest of the step, from the largest
    /// increment again.
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
        let path = StepPath {
            base: self.state.boundary.clone(),
            base_angles: self.state.angles.clone(),
            base_loads: self.state.loads.clone(),
            target,
            angles,
            loads,
        };
        let mut current = self.state.clone();
        let mut last_start = None;
        let mut report = StepReport::default();
        let largest = 1.0 / increments as f64;
        let smallest = largest / 2f64.powi(self.settings.max_cutbacks as i32);
        let rows = if self.settings.stabilization {
            STRATEGIES.len()
        } else {
            1
        };
        let (mut done, mut size, mut row) = (0.0_f64, largest, 0);
        // The share of the step of the last converged increment.
        let mut last_size = largest;
        self.parts.stabilization.start_step();
        while done < 1.0 {
            let next = if done + size > 1.0 - 1e-12 {
                1.0
            } else {
                done + size
            };
            self.parts
                .stabilization
                .set(STRATEGIES[row].damping, next - done);
            let attempt = self.solve_increment(&current, &path.motion(next), &path.levels(next));
            let outcome = attempt.as_ref().map(|(_, h)| h.as_slice());
            let how = STRATEGIES[row].name;
            self.note_increment(done, next, how, outcome, report.cutbacks);
            report.attempts.push(Attempt {
                strategy: row,
                from: done,
                to: next,
                iterations: attempt.as_ref().map_or(0, |(_, h)| h.len() - 1),
                converged: attempt.is_ok(),
            });
            match attempt {
                Ok((state, history)) => {
                    self.account_stabilized(&mut report, &state.displacement);
                    last_start = Some(std::mem::replace(&mut current, state));
                    last_size = next - done;
                    done = next;
                    // The Ju–Rowlands matrix converges linearly by design: its iterations do
                    // not measure the increment's nonlinearity.
                    let linear = self.settings.iteration_matrix == IterationMatrix::JuRowlands
                        && (!self.parts.curved.is_empty() || !self.state.status.is_empty());
                    let n = if linear {
                        Self::TARGET_ITERATIONS
                    } else {
                        history.len().saturating_sub(1).max(1)
                    } as f64;
                    let ratio = (Self::TARGET_ITERATIONS as f64 / n).sqrt();
                    size = (size * ratio.clamp(1.0 / Self::GROWTH, Self::GROWTH)).min(largest);
                    report.iterations.push(history.len() - 1);
                    report.residual = *history.last().unwrap_or(&0.0);
                    report.residual_history = history;
                }
                Err(_) if size / 2.0 >= smallest * (1.0 - 1e-9) => {
                    report.cutbacks += 1;
                    size /= 2.0;
                }
                Err(_) if row + 1 < rows => (row, size) = (row + 1, largest),
                Err(last) => {
                    self.parts.stabilization.set(0.0, 1.0);
                    return Err(StepError::NotConverged {
                        fraction_done: done,
                        cutbacks: report.cutbacks,
                        last,
                    });
                }
            }
        }
        if row > 0 {
            let damping = (STRATEGIES[row].damping, last_size);
            self.release_stabilization(&mut current, &mut last_start, &path, &mut report, damping);
        }
        self.parts.stabilization.set(0.0, 1.0);
        report.strain_energy = self.strain_energy_at(&current.displacement);
        report.pseudo_time_work = std::mem::take(&mut self.work.pseudo_time_work);
        self.state = current;
        self.increment_start = last_start;
        Ok(report)
    }

    /// At the end of a step the stabilization carried: the undamped equilibrium at the step's
    /// target, solved from the damped one; where Newton refuses it, one more damped increment at
    /// the target (the same pseudo-time step `last`: the film creeps on towards equilibrium and
    /// the damping force falls with its motion), then the undamped one again, up to
    /// [`Self::RELEASE_ROUNDS`] times. Where the undamped solve converges the answer carries no
    /// damping force (`report.stabilization_energy` 0); else the damped state stays, its force's
    /// work over the last increment reported against the bound.
    fn release_stabilization(
        &mut self,
        current: &mut AnalysisState,
        last_start: &mut Option<AnalysisState>,
        path: &StepPath<'_>,
        report: &mut StepReport,
        (damping, last): (f64, f64),
    ) {
        let (motion, levels) = (path.motion(1.0), path.levels(1.0));
        for round in 0..2 * Self::RELEASE_ROUNDS {
            let damped = round % 2 == 1;
            self.parts
                .stabilization
                .set(if damped { damping } else { 0.0 }, last);
            let attempt = self.solve_increment(current, &motion, &levels);
            let how = if damped { "release, damped" } else { "release" };
            let outcome = attempt.as_ref().map(|(_, h)| h.as_slice());
            self.note_increment(1.0, 1.0, how, outcome, report.cutbacks);
            report.attempts.push(Attempt {
                strategy: usize::from(damped),
                from: 1.0,
                to: 1.0,
                iterations: attempt.as_ref().map_or(0, |(_, h)| h.len() - 1),
                converged: attempt.is_ok(),
            });
            let Ok((mut state, history)) = attempt else {
                if damped {
                    return;
                }
                continue;
            };
            self.account_stabilized(report, &state.displacement);
            // The step's last increment, for the next step's predictor, is the motion from the
            // start of the last loaded increment to here.
            for (l, a) in state.last_increment.iter_mut().zip(&current.last_increment) {
                *l += a;
            }
            report.iterations.push(history.len() - 1);
            report.residual = *history.last().unwrap_or(&0.0);
            report.residual_history = history;
            *last_start = Some(std::mem::replace(current, state));
            if !damped {
                return;
            }
        }
    }

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

    /// Most damped increments [`Self::release_stabilization`] adds at a step's end.
    pub(crate) const RELEASE_ROUNDS: usize = 20;

    /// Accounts an increment converged at `u` (the stabilization's work over it added to the
    /// step's dissipated work; the work of the force the state carries is this increment's).
    fn account_stabilized(&mut self, report: &mut StepReport, u: &[f64]) {
        if self.parts.stabilization.is_on() {
            report.stabilized += 1;
            let work = self.parts.stabilization.work(&self.system, u);
            report.stabilization_dissipated += work;
            report.stabilization_energy = work;
        } else {
            report.stabilization_energy = 0.0;
        }
    }

    /// `N*`: the Newton iterations an increment is sized for (Ramm 1981).
    pub(crate) const TARGET_ITERATIONS: usize = 6;
    /// Largest factor between two successive increments, and on the predictor's extrapolation.
    pub(crate) const GROWTH: f64 = 2.0;

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
            let ratio = (dot / old).min(Self::GROWTH);
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
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mech::solve::settings::SolverSettings;
    use crate::specimens::ParallelArch;

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
}
