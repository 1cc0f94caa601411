//! Newton–Raphson for one increment.

use crate::mech::elements::gap::{GapStatus, IterationMatrix};
use crate::mech::elements::load::LoadLevels;
use crate::mech::solve::analysis::{Acceptance, Analysis};
use crate::mech::solve::assembly::Dof;
use crate::mech::solve::continuation::{Continuation, Verdict};
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
        let mut u = match self.work.guess.take() {
            Some(guess) => guess,
            None => self.predict(start, motion),
        };
        // Trial history from the converged start (also after a cut-back or for an enlarged retry).
        for c in self.parts.all_mut() {
            c.restore(start);
        }
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
        let (mut best, mut best_correction, mut best_at) = (f64::INFINITY, f64::INFINITY, 0);
        // The iterate closest to meeting both tolerances (quoted if the increment stalls).
        let mut closest: Option<IterationRecord> = None;
        // Levenberg–Marquardt shift of the free diagonal, relative to its mean.
        let mut damping = 0.0_f64;
        // Whether the last correction was solved with the shift (its size then says nothing
        // of progress: the shift alone shrinks it).
        let mut shifted = false;
        // The watchdog of the line search: non-monotone excursions until one fails.
        let mut watch = if self.work.watchdog {
            Watchdog::Ready
        } else {
            Watchdog::Used
        };
        // Pseudo-transient continuation instead of the line search and the shift
        // (`continuation.rs`), and the artificial force of its last correction.
        let mut ptc = self.work.continuation.then(Continuation::new);
        let mut artificial = 0.0_f64;
        // Active-set iteration (`ActiveSet`): the contacts' statuses are held fixed while Newton
        // converges, and changed only at a converged iterate, which is then solved again.
        let mut active = self.parts.curved.active_set.then(ActiveSet::default);
        self.parts.curved.frozen = None;
        self.work.last_work = 0.0;
        let s = self.settings;
        for iteration in 0..=s.max_iterations {
            let mut residual = if assembled {
                self.free_norm_inf()
            } else {
                self.assemble_at(&u, levels, Some(iteration))
            };
            if active.is_some() && self.parts.curved.frozen.is_none() {
                // The set of the first iterate (the predictor's).
                self.parts.curved.frozen = Some(self.parts.curved.natural());
                residual = self.assemble_at(&u, levels, Some(iteration));
            }
            if !residual.is_finite() {
                return Err(IncrementFailure::Diverged { iteration });
            }
            residuals.push(residual);
            for c in self.parts.all_mut() {
                c.note_iteration(iteration);
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
            let mut converged = match self.work.acceptance {
                Acceptance::Law => {
                    (iteration > 0 || self.system.free_count == 0)
                        && record.correction <= record.correction_tolerance
                }
                Acceptance::Residual => iteration > 0,
                Acceptance::Start => iteration == 0,
            } && residual <= tolerance
                && artificial <= tolerance;
            if converged && let Some(set) = active.as_mut() {
                let natural = self.parts.curved.natural();
                let frozen = self.parts.curved.frozen.take().unwrap_or_default();
                if natural != frozen {
                    // Equilibrium under the held statuses, not under the law's: solve again
                    // with the law's statuses at this iterate (a set seen before is a cycle).
                    if !set.next(frozen, &natural) {
                        return Err(IncrementFailure::Stalled {
                            iteration,
                            closest: closest.unwrap_or(record),
                            chattering: set.cycling(&self.parts.curved.names),
                            flipping: Vec::new(),
                            compressed: Vec::new(),
                            lifting: self.lifting_contacts(),
                        });
                    }
                    self.parts.curved.frozen = Some(natural);
                    residual = self.assemble_at(&u, levels, Some(iteration));
                    (best, best_correction, best_at) = (f64::INFINITY, f64::INFINITY, iteration);
                    (damping, watch) = (0.0, Watchdog::Used);
                    converged = false;
                } else {
                    self.parts.curved.frozen = Some(frozen);
                }
            }
            if !converged && self.work.acceptance == Acceptance::Start {
                // Only the first iterate is judged.
                return Err(IncrementFailure::Stalled {
                    iteration,
                    closest: record,
                    chattering: Vec::new(),
                    flipping: Vec::new(),
                    compressed: Vec::new(),
                    lifting: Vec::new(),
                });
            }
            if converged {
                let mut state = AnalysisState {
                    boundary: motion.translation.clone(),
                    angles: motion.angles.clone(),
                    loads: levels.clone(),
                    last_increment: u
                        .iter()
                        .zip(&start.displacement)
                        .map(|(a, b)| a - b)
                        .collect(),
                    displacement: u,
                    ..start.clone()
                };
                // Commit: the trial history of the converged iterate becomes the state's.
                for c in self.parts.all() {
                    c.commit(start, &mut state);
                }
                if !state.is_finite() {
                    return Err(IncrementFailure::Diverged { iteration });
                }
                return Ok((state, residuals));
            }
            // Gaps that changed status in the last few iterations: the usual cause of a stall.
            let recent = iteration.saturating_sub(Self::STALL_PATIENCE / 2);
            let chattering = || -> Vec<String> {
                let mut names = Vec::new();
                for c in self.parts.all() {
                    c.chattering(recent, &mut names);
                }
                names
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
                    compressed: self.compressed_elements(&u),
                    lifting: self.lifting_contacts(),
                });
            }
            if iteration > 3 && residual > 1e6 * residuals[0].max(force_scale) {
                return Err(IncrementFailure::Diverged { iteration });
            }
            // Progress (`made_progress`), else a stall after the patience. The Ju–Rowlands
            // matrix converges linearly and slowly by design (docs/mechanics.md): it is judged
            // by the limit only.
            if made_progress(residual, best, correction_norm, best_correction, shifted) {
                best = best.min(residual);
                best_correction = best_correction.min(correction_norm);
                best_at = iteration;
            } else if s.iteration_matrix == IterationMatrix::Consistent
                && iteration
                    >= best_at
                        + if ptc.is_some() {
                            Continuation::PATIENCE
                        } else {
                            Self::STALL_PATIENCE
                        }
            {
                return Err(IncrementFailure::Stalled {
                    iteration,
                    closest: closest.unwrap_or(record),
                    chattering: chattering(),
                    flipping: self.flipping_elements(&previous_u, &u),
                    compressed: self.compressed_elements(&u),
                    lifting: self.lifting_contacts(),
                });
            }
            shifted = damping > 0.0;
            correction_norm = match (self.correction(damping, ptc.as_mut()), ptc.as_mut()) {
                (Ok(norm), _) => norm,
                (Err(_), Some(p)) => {
                    // A singular matrix: a shorter pseudo-time step from the same iterate.
                    p.singular();
                    assembled = false;
                    continue;
                }
                (Err(e), None) => return Err(e),
            };
            if !correction_norm.is_finite() {
                return Err(IncrementFailure::Diverged { iteration });
            }
            previous_u.clone_from(&u);
            if let Some(p) = ptc.as_mut() {
                // The full pseudo-time step; `c` follows the residual (SER), a step that
                // raised it too far is taken back.
                let (before, c) = (self.free_norm2(), p.c);
                for (i, d) in self.system.dofs.iter().enumerate() {
                    if let Dof::Free(eq) = d {
                        u[i] += self.work.rhs[*eq];
                    }
                }
                self.assemble_at(&u, levels, Some(iteration + 1));
                assembled = true;
                if p.judge(before, self.free_norm2()) == Verdict::Reject {
                    u.clone_from(&previous_u);
                    assembled = false;
                    correction_norm = f64::INFINITY;
                } else {
                    let (work, force) = Continuation::work_and_force(
                        c,
                        p.scale,
                        &self.work.rhs,
                        &self.work.pseudo_mass,
                    );
                    self.work.dissipated += work;
                    self.work.last_work = work;
                    artificial = force;
                }
                continue;
            }
            let (step, with_tangent, decreased) =
                self.line_search(&mut u, levels, iteration + 1, &mut watch);
            assembled = with_tangent;
            if step.is_infinite() {
                // The watchdog went back to where its excursion started: the iterations spent
                // on it are not a stall of the iteration from here.
                best_at = iteration + 1;
            }
            correction_norm *= step;
            if s.iteration_matrix == IterationMatrix::Consistent {
                damping = next_damping(damping, step, decreased);
            }
        }
        unreachable!("the loop returns at max_iterations")
    }

    /// Film elements whose tension-field state differs between the displacements `a` and `b`
    /// (none without wrinkling). Called once when an increment fails, never per iteration.
    fn flipping_elements(&self, a: &[f64], b: &[f64]) -> Vec<usize> {
        let mut elements = Vec::new();
        for c in self.parts.all() {
            c.flipping(&self.system, a, b, &mut elements);
        }
        elements
    }

    /// Film elements in compression (`σ2 < 0`) at `u` where the film law carries compression
    /// (`wrinkling: "none"`, elastic or plastic). Called once when an increment fails.
    fn compressed_elements(&self, u: &[f64]) -> Vec<usize> {
        let mut elements = Vec::new();
        for c in self.parts.all() {
            c.compressed(&self.system, u, &mut elements);
        }
        elements
    }

    /// Contacts of the sliding-direction law that opened and closed in this attempt while
    /// holding more than `μN` across (`contributions::LiftOff`). Called once when an increment fails.
    fn lifting_contacts(&self) -> Vec<String> {
        let mut names = Vec::new();
        for c in self.parts.all() {
            c.lifting_off(&mut names);
        }
        names
    }

    /// First Levenberg–Marquardt shift (fraction of the mean diagonal of the Newton matrix).
    pub(crate) const DAMPING_START: f64 = 1e-4;
    /// A residual below this fraction of the best so far counts as progress.
    pub(crate) const PROGRESS: f64 = 0.9;
    /// Iterations without progress before an increment is declared stalled and cut back.
    pub(crate) const STALL_PATIENCE: usize = 8;

    /// The Newton correction `ΔU` of the free DOFs into `work.rhs` from the last assembly, with
    /// the pseudo-time shift of `ptc` or else the Levenberg–Marquardt shift `damping` (times the
    /// mean of the free diagonal's magnitudes) added to the matrix's diagonal; returns `‖ΔU‖∞`.
    fn correction(
        &mut self,
        damping: f64,
        ptc: Option<&mut Continuation>,
    ) -> Result<f64, IncrementFailure> {
        for (i, d) in self.system.dofs.iter().enumerate() {
            if let Dof::Free(eq) = d {
                self.work.rhs[*eq] = -self.work.internal[i];
            }
        }
        if let Some(p) = ptc {
            p.shift(
                &mut self.work.values,
                &self.work.diagonal,
                &self.work.pseudo_mass,
            );
        } else if damping > 0.0 {
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
        let mut rhs = std::mem::take(&mut self.work.rhs);
        let low_rank = self.add_low_rank(&mut rhs);
        self.work.rhs = rhs;
        low_rank.map_err(|e| IncrementFailure::Singular { message: e.0 })?;
        Ok(max_abs(&self.work.rhs))
    }

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
}

/// Whether an iterate made progress: a residual or a correction [`Analysis::PROGRESS`] times
/// the best so far. A cycle between two states repeats both to round-off and never makes it,
/// while the slow approach along a soft direction of the film (small residual, shrinking
/// corrections) does. A correction solved with the Levenberg–Marquardt shift (`shifted`) does
/// not count by its size: the shift alone shrinks it (to 1e-65 m over a 100-iteration attempt,
/// which then ran to the iteration limit instead of being cut back as stalled).
fn made_progress(
    residual: f64,
    best: f64,
    correction: f64,
    best_correction: f64,
    shifted: bool,
) -> bool {
    residual < Analysis::PROGRESS * best
        || (!shifted && correction < Analysis::PROGRESS * best_correction)
}

/// The Levenberg–Marquardt shift after a line search that took `step` and `decreased` (or
/// not) the merit: a direction that cannot lower the residual (a mechanism of an unstressed
/// film, an indefinite compressed one) gets a diagonal shift, raised until steps succeed and
/// lowered again after full ones, to 0 below [`Analysis::DAMPING_START`]`/64`. Only the
/// iteration matrix changes, never the residual: the converged state is the same, and with the
/// shift gone the last iterations are Newton's again.
fn next_damping(damping: f64, step: f64, decreased: bool) -> f64 {
    if !decreased {
        (4.0 * damping).max(Analysis::DAMPING_START)
    } else if step == 1.0 && damping > 0.0 {
        let lower = damping / 4.0;
        if lower < Analysis::DAMPING_START / 64.0 {
            0.0
        } else {
            lower
        }
    } else {
        damping
    }
}

/// The active-set strategy for the curved contacts (Wriggers, *Computational Contact
/// Mechanics*, 2nd ed. 2006, §6.3.2 and §5.2; Alart & Curnier 1991 for the semi-smooth view it
/// avoids): Newton iterates with each contact's status (open, stick, slip) held at the set of
/// the increment's first iterate, so that the residual is smooth and no status switches between
/// iterations; at a converged iterate the law's own statuses are compared with the held ones,
/// and if any differs the set is replaced by the law's and the increment solved again from
/// there. Sets already tried are remembered: a set that comes back is a cycle (the increment
/// fails and names the contacts that switch). A converged increment's statuses are the law's,
/// so its answer is the equilibrium of the contact law, not of the held set.
#[derive(Debug, Default)]
struct ActiveSet {
    /// The sets tried so far in this increment.
    tried: Vec<Vec<GapStatus>>,
}

impl ActiveSet {
    /// Most sets tried in one increment.
    const MAX_SETS: usize = 12;

    /// Records the set `held` (just converged) before `next` replaces it; false when `next` was
    /// tried before or too many sets were.
    fn next(&mut self, held: Vec<GapStatus>, next: &[GapStatus]) -> bool {
        self.tried.push(held);
        !self.tried.iter().any(|t| t == next) && self.tried.len() < Self::MAX_SETS
    }

    /// The contacts whose status differs between the tried sets (named by `names`).
    fn cycling(&self, names: &[String]) -> Vec<String> {
        let first = self.tried.first().cloned().unwrap_or_default();
        (0..first.len())
            .filter(|&k| self.tried.iter().any(|t| t.get(k) != first.get(k)))
            .filter_map(|k| names.get(k).cloned())
            .collect()
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

#[cfg(test)]
mod tests {
    use super::*;

    /// A NaN anywhere makes the norm NaN (so it fails every `≤ tolerance` test); without NaN
    /// it is the largest magnitude, signs ignored.
    #[test]
    fn a_nan_residual_never_measures_small() {
        assert_eq!(max_abs(&[1.0, -3.0, 2.0]), 3.0);
        assert!(max_abs(&[0.0, f64::NAN, 1.0]).is_nan());
        assert!(max_abs(&[f64::NAN, 5.0]).is_nan());
        assert!(max_abs_difference(&[1.0, 2.0], &[1.0, f64::NAN]).is_nan());
        assert_eq!(max_abs_difference(&[1.0, -2.0], &[0.5, 1.0]), 3.0);
        assert_eq!(max_abs(&[]), 0.0);
    }

    /// The active set accepts new sets and refuses one tried before (a cycle between two sets
    /// of statuses) and more than `MAX_SETS`; the contacts it names as cycling are those whose
    /// status differs between the sets tried.
    #[test]
    fn active_set_refuses_a_set_tried_before_and_names_the_contacts_that_switch() {
        use GapStatus::{Open, Slip, Stick};
        let names: Vec<String> = ["a", "b", "c"].iter().map(|n| n.to_string()).collect();
        let mut set = ActiveSet::default();
        assert!(set.next(vec![Open, Stick, Stick], &[Stick, Stick, Stick]));
        assert!(set.next(vec![Stick, Stick, Stick], &[Stick, Slip, Stick]));
        // back to the first set: a cycle
        assert!(!set.next(vec![Stick, Slip, Stick], &[Open, Stick, Stick]));
        assert_eq!(set.cycling(&names), vec!["a".to_string(), "b".to_string()]);
        let mut long = ActiveSet::default();
        let mut fresh = true;
        for k in 0..ActiveSet::MAX_SETS {
            let held = vec![if k % 2 == 0 { Open } else { Stick }; k + 1];
            fresh = long.next(held, &vec![Slip; k + 2]);
        }
        assert!(!fresh, "more than MAX_SETS sets accepted");
    }

    /// Progress is a residual or a correction 10 % below its best; a correction shrunk by the
    /// Levenberg–Marquardt shift is not progress, a smaller residual still is.
    #[test]
    fn shifted_corrections_are_not_progress_by_their_size() {
        let (best, best_correction) = (1.0, 1e-3);
        assert!(made_progress(0.5, best, 1.0, best_correction, false));
        assert!(made_progress(0.5, best, 1.0, best_correction, true));
        assert!(made_progress(1.0, best, 1e-6, best_correction, false));
        assert!(!made_progress(1.0, best, 1e-6, best_correction, true));
        assert!(!made_progress(0.95, best, 0.95e-3, best_correction, false));
    }

    /// The shift starts at `DAMPING_START` when a step fails to decrease the merit, grows
    /// fourfold while they keep failing, falls fourfold after each full step and vanishes
    /// below `DAMPING_START / 64`; partial steps keep it.
    #[test]
    fn damping_grows_on_failures_and_vanishes_after_full_steps() {
        let start = Analysis::DAMPING_START;
        assert_eq!(next_damping(0.0, 1.0, false), start);
        assert_eq!(next_damping(start, 0.1, false), 4.0 * start);
        assert_eq!(next_damping(4.0 * start, 0.5, true), 4.0 * start);
        let mut d = 4.0 * start;
        let mut full_steps = 0;
        while d > 0.0 {
            d = next_damping(d, 1.0, true);
            full_steps += 1;
        }
        // 4·s → s → s/4 → s/16 → s/64 → 0 (s/256 is below s/64).
        assert_eq!(full_steps, 5);
        assert_eq!(next_damping(0.0, 1.0, true), 0.0);
    }
}
