//! One increment: semismooth Newton on the laws' equations, globalized by pseudo-transient
//! continuation (docs/mechanics.md, "The nonlinear method").
//!
//! Each iteration solves `(K + c k̄ M) ΔU = −R(U)` and takes the full step `U ← U + ΔU`
//! (`continuation.rs`): `K` is the generalized (Clarke) Jacobian of the residual — the
//! consistent tangent of each law in the branch of the iterate (gap and curved-contact return
//! mappings, the film's taut, wrinkled or slack state, the plastic return) — and `c k̄ M` the
//! pseudo-time term, zero while full steps succeed (the iteration is then Newton's, locally
//! quadratic: semismooth Newton, Qi & Sun 1993; Alart & Curnier 1991 for contact) and raised
//! where a step is rejected (Kelley & Keyes 1998). Convergence is judged on the true residual.

use crate::mech::elements::gap::GapStatus;
use crate::mech::elements::load::LoadLevels;
use crate::mech::solve::analysis::Analysis;
use crate::mech::solve::assembly::Dof;
use crate::mech::solve::continuation::Continuation;
use crate::mech::solve::report::{IncrementFailure, IterationRecord};
use crate::mech::solve::state::{AnalysisState, GroupMotion};

/// What the Newton loop keeps of its iterates to judge progress and name a failure.
#[derive(Debug)]
struct Progress {
    /// Smallest residual and correction so far, and the iteration that set either.
    best: f64,
    best_correction: f64,
    best_at: usize,
    /// The iterate closest to meeting both tolerances (quoted if the increment fails).
    closest: Option<IterationRecord>,
    /// The contact statuses of each iterate (to name the contacts that keep switching).
    statuses: Vec<Vec<GapStatus>>,
}

impl Progress {
    /// Notes `record`; true when it improved on the best residual or correction by
    /// [`Analysis::PROGRESS`].
    fn note(&mut self, record: IterationRecord) -> bool {
        if record.iteration > 0
            && self
                .closest
                .is_none_or(|c| record.distance() < c.distance())
        {
            self.closest = Some(record);
        }
        let better = record.residual < Analysis::PROGRESS * self.best
            || record.correction < Analysis::PROGRESS * self.best_correction;
        if better {
            self.best = self.best.min(record.residual);
            self.best_correction = self.best_correction.min(record.correction);
            self.best_at = record.iteration;
        }
        better
    }
}

/// The hold of contacts that cycle between stick and slip (a generalized Newton iteration can
/// alternate between the two pieces of a kinked law whose solution lies near the kink): their
/// status is imposed, stick first, and Newton's iteration on the held laws converges on one
/// smooth piece; its answer is then judged on the true laws, and where it fails there, held in
/// slip instead (the active-set view of semismooth Newton: Hintermüller, Ito & Kunisch 2002).
/// Once both have failed the increment goes on without a hold. Convergence is always judged on
/// the true laws.
#[derive(Debug, Default)]
struct Hold {
    /// 0: none tried; 1: stick held; 2: slip held; 3: both tried.
    stage: u8,
    /// The statuses imposed now (empty: none).
    held: Vec<Option<GapStatus>>,
    /// The statuses of the hold the current iterate is judged without.
    judged: Vec<Option<GapStatus>>,
}

impl Hold {
    /// The statuses to impose from now on (Some(empty): none) given whether the current
    /// iterate `met` the tolerances and the statuses of the iterates so far; None: unchanged.
    fn next(&mut self, met: bool, statuses: &[Vec<GapStatus>]) -> Option<Vec<Option<GapStatus>>> {
        if !self.held.is_empty() {
            // Converged on the held laws: judged on the true ones next.
            return met.then(|| {
                self.judged = std::mem::take(&mut self.held);
                Vec::new()
            });
        }
        if !self.judged.is_empty() {
            let judged = std::mem::take(&mut self.judged);
            if met || self.stage != 1 {
                self.stage = 3;
                return None;
            }
            self.stage = 2;
            self.held = judged.iter().map(|h| h.map(|_| GapStatus::Slip)).collect();
            return Some(self.held.clone());
        }
        if self.stage != 0 {
            return None;
        }
        let held = cycling(statuses)?;
        self.stage = 1;
        self.held.clone_from(&held);
        Some(held)
    }
}

/// Stick for each contact whose status changed between stick and slip at least
/// [`Analysis::CYCLE`] times over the last [`Analysis::CYCLE`]` + 3` iterates, None for the
/// others; None where no contact did.
fn cycling(statuses: &[Vec<GapStatus>]) -> Option<Vec<Option<GapStatus>>> {
    let recent = &statuses[statuses.len().saturating_sub(Analysis::CYCLE + 3)..];
    let last = recent.last()?;
    let closed = |s: GapStatus| s != GapStatus::Open;
    let held: Vec<Option<GapStatus>> = (0..last.len())
        .map(|k| {
            let changes = recent
                .windows(2)
                .filter(|w| {
                    let (a, b) = (w[0].get(k).copied(), w[1].get(k).copied());
                    matches!((a, b), (Some(a), Some(b)) if a != b && closed(a) && closed(b))
                })
                .count();
            (changes >= Analysis::CYCLE).then_some(GapStatus::Stick)
        })
        .collect();
    held.iter().any(Option::is_some).then_some(held)
}

/// The iteration state of one increment.
struct Iterates {
    /// The iterate, and the one before the last correction.
    u: Vec<f64>,
    previous_u: Vec<f64>,
    /// `‖R_free‖∞` of every iterate.
    residuals: Vec<f64>,
    /// Whether the workspace holds the residual and the matrix at `u`.
    assembled: bool,
    /// `‖ΔU‖∞` of the last correction (infinite before the first).
    correction: f64,
    ptc: Continuation,
    /// The pseudo-time force of the last correction (N).
    artificial: f64,
    progress: Progress,
    /// `‖R‖₂` of the last accepted iterates (the nonmonotone line search's reference).
    merits: Vec<f64>,
    hold: Hold,
    /// The smallest positive `c` so far: the pseudo-time reached.
    lowest_c: f64,
}

impl Iterates {
    /// The state at the predictor `u`; `fixed`: a model without free DOFs (every node
    /// prescribed or fixed: how single elements are verified), converged at its first assembly.
    fn new(u: Vec<f64>, fixed: bool) -> Self {
        Self {
            previous_u: u.clone(),
            u,
            residuals: Vec::new(),
            assembled: false,
            correction: if fixed { 0.0 } else { f64::INFINITY },
            ptc: Continuation::new(),
            artificial: 0.0,
            progress: Progress {
                best: f64::INFINITY,
                best_correction: f64::INFINITY,
                best_at: 0,
                closest: None,
                statuses: Vec::new(),
            },
            merits: Vec::new(),
            hold: Hold::default(),
            lowest_c: f64::INFINITY,
        }
    }

    /// Notes `record`; true where it made progress: its residual or correction
    /// [`Analysis::PROGRESS`] below the best, or the continuation's `c` that much below its
    /// smallest (the pseudo-time step lengthens while the residual waits for it: a film held by
    /// the pseudo-mass until its own stiffness takes over).
    fn progressed(&mut self, record: IterationRecord) -> bool {
        let c = self.ptc.c;
        let continuing = c > 0.0 && c < Analysis::PROGRESS * self.lowest_c;
        if continuing {
            self.lowest_c = c;
            self.progress.best_at = record.iteration;
        }
        self.progress.note(record) || continuing
    }

    /// Whether the iterate `record` of an increment held to `limit` iterations is past it: at
    /// the limit, or (from the fourth) still moving (its correction above its tolerance) with
    /// a residual that fell by less than [`Analysis::PROGRESS`] a step over the last three
    /// iterations and, at that rate, would not reach its tolerance within the limit. A
    /// residual at its rounding floor stalls too, but its corrections are within tolerance.
    fn past(&self, limit: usize, record: &IterationRecord) -> bool {
        let (r, iteration) = (&self.residuals, record.iteration);
        let (n, tolerance) = (r.len(), record.residual_tolerance);
        if iteration >= limit {
            return iteration == limit;
        }
        if iteration < 4
            || r[n - 1] <= tolerance
            || record.correction <= record.correction_tolerance
        {
            return false;
        }
        let rate = (r[n - 1] / r[n - 4]).cbrt();
        let left = (limit - iteration) as f64;
        rate >= Analysis::PROGRESS
            && (rate >= 1.0 || (tolerance / r[n - 1]).ln() / rate.ln() > left)
    }

    /// Whether the last [`Analysis::MEMORY`] merits repeat with period two (each within
    /// 1e-3 of the one two before): Newton's map has a stable 2-cycle, which the same
    /// iteration never leaves.
    fn orbits(&self) -> bool {
        let m = &self.merits;
        m.len() == Analysis::MEMORY && (2..m.len()).all(|k| (m[k] - m[k - 2]).abs() <= 1e-3 * m[k])
    }

    /// Newton's iteration afresh from the same iterate at `iteration` (the laws were held or
    /// released).
    fn restart(&mut self, iteration: usize) {
        (self.assembled, self.correction) = (false, f64::INFINITY);
        self.merits.clear();
        self.ptc.c = 0.0;
        (self.progress.best, self.progress.best_correction) = (f64::INFINITY, f64::INFINITY);
        self.progress.best_at = iteration;
        self.lowest_c = f64::INFINITY;
    }

    /// After the line search moved `u` by the share `step` of the correction to the merit
    /// `merit`, with the pseudo-time force `force`: SER after a full step (a shortened one keeps
    /// `c`); a step back to the merit of two iterates ago is a two-cycle (between pieces of `R`
    /// the contact statuses do not name): a shorter pseudo-time step next.
    fn stepped(&mut self, step: f64, merit: f64, force: f64) {
        let n = self.merits.len();
        if n >= 2 && (merit - self.merits[n - 2]).abs() <= 1e-9 * merit {
            self.ptc.reject();
        } else if step == 1.0 {
            self.ptc.accept(self.merits[n - 1], merit);
        }
        self.assembled = step == 1.0;
        self.correction *= step;
        self.artificial = force;
        self.merits.push(merit);
        if self.merits.len() > Analysis::MEMORY {
            self.merits.remove(0);
        }
    }
}

impl Analysis {
    /// Newton's iteration for one increment from the converged `start` to the group motion
    /// `motion` and the load levels `levels`: the full correction of
    /// `(K + c k̄ M) ΔU = −R`, `c` by switched evolution relaxation (`continuation.rs`).
    /// Converged when the correction and the residual of the true laws are within their
    /// tolerances and the pseudo-time force of the last correction is within the residual's.
    pub(crate) fn solve_increment(
        &mut self,
        start: &AnalysisState,
        motion: &GroupMotion,
        levels: &LoadLevels,
        dissipative_limit: Option<usize>,
    ) -> Result<(AnalysisState, Vec<f64>), IncrementFailure> {
        let u = self.predict(start, motion, levels);
        for c in self.parts.all_mut() {
            c.restore(start);
        }
        let mut it = Iterates::new(u, self.system.free_count == 0);
        let s = self.settings;
        for iteration in 0..=s.max_iterations {
            if !it.assembled {
                self.assemble_at(&it.u, levels, Some(iteration));
            }
            let (record, force_scale) = self.observe(&mut it, start, iteration)?;
            let met = (iteration > 0 || self.system.free_count == 0)
                && record.correction <= record.correction_tolerance
                && record.residual <= record.residual_tolerance
                && it.artificial <= record.residual_tolerance;
            if met && it.hold.held.is_empty() {
                return self.commit_increment(start, motion, levels, it.u, it.residuals, iteration);
            }
            // An increment that changes a history is refused once it needs more iterations than
            // the controller keeps of one (`Controller::keeps`), or sooner where its residual
            // stagnates short of its tolerance: not after it converged.
            if dissipative_limit.is_some_and(|limit| it.past(limit, &record))
                && self.changes_history(start, motion, levels, &it.u)
            {
                return Err(IncrementFailure::PathDependent { iteration });
            }
            let improved = it.progressed(record);
            if iteration == s.max_iterations {
                return Err(self.failure(&it, record, false));
            }
            if let Some(held) = it.hold.next(met, &it.progress.statuses) {
                // The laws changed: the same iterate evaluated again, Newton's iteration afresh.
                self.parts.hold(&held);
                it.restart(iteration);
                continue;
            }
            // A 2-cycle of Newton's map on one piece of the laws: the same iteration never
            // leaves it (not at a residual within its tolerance: rounding, where the correction
            // decides).
            if it.orbits() && record.residual > record.residual_tolerance {
                return Err(self.failure(&it, record, true));
            }
            if iteration > 3 && record.residual > 1e6 * it.residuals[0].max(force_scale) {
                return Err(IncrementFailure::Diverged { iteration });
            }
            // Stalled after `2 N*` iterations without progress (more than the controller would
            // keep of a dissipative increment); the Ju–Rowlands matrix converges linearly by
            // design: judged by the limit only.
            if !improved
                && !self.converges_linearly()
                && iteration >= it.progress.best_at + 2 * Self::TARGET_ITERATIONS
            {
                return Err(self.failure(&it, record, true));
            }
            self.advance(&mut it, levels, iteration, record.residual_tolerance)?;
        }
        unreachable!("the loop returns at max_iterations")
    }

    /// The figures of the assembled iterate `it.u` against the tolerances (and the force scale
    /// `F_ref`), noted in `it`.
    fn observe(
        &self,
        it: &mut Iterates,
        start: &AnalysisState,
        iteration: usize,
    ) -> Result<(IterationRecord, f64), IncrementFailure> {
        let residual = self.free_norm_inf();
        if !residual.is_finite() {
            return Err(IncrementFailure::Diverged { iteration });
        }
        it.residuals.push(residual);
        if it.merits.is_empty() {
            it.merits.push(self.free_norm2());
        }
        it.progress.statuses.push(self.parts.statuses());
        let moved = max_abs_difference(&it.u, &start.displacement);
        let displacement_scale = moved.max(max_abs(&it.u)).max(1e-9 * self.length_scale);
        let force_scale = max_abs(&self.work.internal).max(self.force_floor);
        let s = self.settings;
        let record = IterationRecord {
            iteration,
            residual,
            residual_tolerance: s.residual_tolerance * force_scale,
            correction: it.correction,
            correction_tolerance: s.displacement_tolerance * displacement_scale,
        };
        Ok((record, force_scale))
    }

    /// The failure of an increment at `record`: stalled, or at the iteration limit.
    fn failure(&self, it: &Iterates, record: IterationRecord, stalled: bool) -> IncrementFailure {
        let chattering = self.chattering(&it.progress.statuses);
        let flipping = self.flipping_elements(&it.previous_u, &it.u);
        let compressed = self.compressed_elements(&it.u);
        if stalled {
            IncrementFailure::Stalled {
                iteration: record.iteration,
                closest: it.progress.closest.unwrap_or(record),
                chattering,
                flipping,
                compressed,
            }
        } else {
            IncrementFailure::MaxIterations {
                first_residual: it.residuals[0],
                last: record,
                matrix: self.settings.iteration_matrix,
                chattering,
                flipping,
                compressed,
            }
        }
    }

    /// One iteration from the assembled `it.u`: the correction with the pseudo-time shift, then
    /// the line search along it ([`Self::step_along`]), `c` by SER after a full step and
    /// lengthened where no step is found or the matrix is singular.
    fn advance(
        &mut self,
        it: &mut Iterates,
        levels: &LoadLevels,
        iteration: usize,
        tolerance: f64,
    ) -> Result<(), IncrementFailure> {
        let c = it.ptc.c;
        match self.correction(&mut it.ptc) {
            Ok(norm) if norm.is_finite() => it.correction = norm,
            Ok(_) => return Err(IncrementFailure::Diverged { iteration }),
            Err(_) => {
                // A singular matrix: a shorter pseudo-time step from the same iterate.
                it.ptc.reject();
                it.assembled = false;
                return Ok(());
            }
        }
        let reference = [
            it.merits.iter().copied().fold(0.0, f64::max),
            it.merits[it.merits.len() - 1],
        ];
        it.previous_u.clone_from(&it.u);
        let statuses = it.progress.statuses.last().cloned().unwrap_or_default();
        let next = iteration + 1;
        match self.step_along(&mut it.u, levels, next, reference, tolerance, &statuses) {
            Some((step, merit)) => {
                let (work, force) =
                    it.ptc
                        .work_and_force(c * step, &self.work.rhs, &self.work.pseudo_mass);
                self.work.pseudo_time_work += work * step;
                it.stepped(step, merit, force);
            }
            None => {
                it.ptc.reject();
                (it.assembled, it.correction) = (false, f64::INFINITY);
            }
        }
        Ok(())
    }

    /// The converged iterate `u` of the increment from `start`: the state with the trial history
    /// of every contribution committed.
    pub(super) fn commit_increment(
        &self,
        start: &AnalysisState,
        motion: &GroupMotion,
        levels: &LoadLevels,
        u: Vec<f64>,
        residuals: Vec<f64>,
        iteration: usize,
    ) -> Result<(AnalysisState, Vec<f64>), IncrementFailure> {
        let mut state = AnalysisState {
            boundary: motion.translation.clone(),
            angles: motion.angles.clone(),
            loads: levels.clone(),
            last_increment: u
                .iter()
                .zip(&start.displacement)
                .map(|(a, b)| a - b)
                .collect(),
            last_load_increment: levels
                .path()
                .zip(start.loads.path())
                .map(|(a, b)| a - b)
                .collect(),
            displacement: u,
            ..start.clone()
        };
        for c in self.parts.all() {
            c.commit(start, &mut state);
        }
        if !state.is_finite() {
            return Err(IncrementFailure::Diverged { iteration });
        }
        Ok((state, residuals))
    }

    /// Whether the iterate `u` (assembled last) changes a history of the state `start`: a gap's
    /// slip, a plastic strain, a contact's status.
    fn changes_history(
        &self,
        start: &AnalysisState,
        motion: &GroupMotion,
        levels: &LoadLevels,
        u: &[f64],
    ) -> bool {
        self.commit_increment(start, motion, levels, u.to_vec(), Vec::new(), 0)
            .is_ok_and(|(state, _)| state.history_changed_from(start))
    }

    /// The contacts whose status changed within the last `2 N*` iterates of
    /// `statuses` (one status list per iterate). Called once when an increment fails.
    fn chattering(&self, statuses: &[Vec<GapStatus>]) -> Vec<String> {
        let names = self.parts.status_names();
        let recent = &statuses[statuses.len().saturating_sub(2 * Self::TARGET_ITERATIONS)..];
        let Some(last) = recent.last() else {
            return Vec::new();
        };
        (0..last.len())
            .filter(|&k| recent.iter().any(|s| s.get(k) != last.get(k)))
            .filter_map(|k| names.get(k).cloned())
            .collect()
    }

    /// Film elements whose tension-field state differs between the displacements `a` and `b`
    /// (none without wrinkling). Called once when an increment fails.
    fn flipping_elements(&self, a: &[f64], b: &[f64]) -> Vec<usize> {
        self.parts.triangles.flipping(&self.system, a, b)
    }

    /// Film elements in compression (`σ2 < 0`) at `u` where the film law carries compression.
    fn compressed_elements(&self, u: &[f64]) -> Vec<usize> {
        self.parts.triangles.compressed(&self.system, u)
    }

    /// Moves `u` along the correction in `work.rhs` by the first `α` of 1, then of a
    /// backtracking by quadratic interpolation of `φ(α) = ‖R(u + αΔ)‖₂²` (within `[α/10, α/2]`,
    /// [`Self::TRIALS`] in all), that meets the Armijo test `φ(α) ≤ (1 − 2·10⁻⁴ α) φ_ref`, or
    /// that ends with `‖R‖∞` within `tolerance`. `reference` = `[√φ_max, √φ(0)]`: on the smooth
    /// piece of the iterate (every contact's status as in `statuses`) `φ_ref` is the largest of
    /// the last [`Self::MEMORY`] merits, the nonmonotone test (Grippo, Lampariello & Lucidi
    /// 1986), and a full step is kept unless it raises `‖R‖₂` [`Continuation::GROW`]-fold;
    /// across a kink (a status changed) it is the iterate's own `φ(0)`, the monotone test, so
    /// that a contact cannot cycle between two statuses (open ↔ pressed) on the memory's
    /// allowance. Where no trial meets it, the best trial below `φ(0)`.
    /// Some((α, ‖R‖₂)) with the workspace holding the residual at the new `u` (and its matrix
    /// where α = 1); None with `u` back where it was.
    fn step_along(
        &mut self,
        u: &mut [f64],
        levels: &LoadLevels,
        next_iteration: usize,
        [reference, current]: [f64; 2],
        tolerance: f64,
        statuses: &[GapStatus],
    ) -> Option<(f64, f64)> {
        let apply = |u: &mut [f64], dofs: &[Dof], delta: &[f64], scale: f64| {
            for (i, d) in dofs.iter().enumerate() {
                if let Dof::Free(eq) = d {
                    u[i] += scale * delta[*eq];
                }
            }
        };
        let delta = std::mem::take(&mut self.work.rhs);
        let before = self.parts.gaps();
        let (phi_max, phi0) = (reference * reference, current * current);
        let (mut alpha, mut applied) = (1.0_f64, 0.0);
        let (mut accepted, mut best) = (None, (0.0, current));
        let mut at_event = false;
        for trial in 0..Self::TRIALS {
            apply(u, &self.system.dofs, &delta, alpha - applied);
            applied = alpha;
            let tangent = (trial == 0).then_some(next_iteration);
            self.assemble_at(u, levels, tangent);
            let merit = self.free_norm2();
            let phi = merit * merit;
            // A full step that leaves every contact's status as it was stays on the same smooth
            // piece of `R`, where Newton's model holds: kept unless it raises the residual
            // [`Continuation::GROW`]-fold (the flat film's first pressure step).
            let same = self.parts.statuses() == *statuses;
            // The event trial ends on the next piece's edge, where the merit's slope changes:
            // kept on the same allowance, so that the next iteration's tangent carries the
            // contact's new status.
            let same_piece = (trial == 0 && same || trial == 1 && at_event)
                && merit <= Continuation::GROW * reference;
            let phi_ref = if same { phi_max } else { phi0 };
            // A step to within the residual tolerance needs no decrease (at roundoff the merit
            // cannot fall).
            if phi <= (1.0 - 2e-4 * alpha) * phi_ref
                || same_piece
                || self.free_norm_inf() <= tolerance
            {
                accepted = Some((alpha, merit));
                break;
            }
            if merit < best.1 {
                best = (alpha, merit);
            }
            let event = if trial == 0 && !same {
                first_event(&before, &self.parts.gaps())
            } else {
                None
            };
            let curvature = (phi - phi0 + 2.0 * phi0 * alpha) / (alpha * alpha);
            let next = if curvature.is_finite() && curvature > 0.0 {
                phi0 / curvature
            } else {
                0.5 * alpha
            };
            at_event = event.is_some();
            alpha = event.unwrap_or_else(|| next.clamp(0.1 * alpha, 0.5 * alpha));
        }
        if accepted.is_none() {
            // No trial met the test: the best one that lowered the merit at all (across a kink
            // of `R` a generalized Newton direction need not be one of sufficient descent), else
            // none.
            apply(u, &self.system.dofs, &delta, best.0 - applied);
            if best.0 > 0.0 {
                self.assemble_at(u, levels, None);
                accepted = Some(best);
            }
        }
        self.work.rhs = delta;
        accepted
    }

    /// A residual or correction below this fraction of the best so far counts as progress.
    pub(crate) const PROGRESS: f64 = 0.9;
    /// Changes between stick and slip that make a contact's status a cycle ([`Hold`]).
    pub(crate) const CYCLE: usize = 3;
    /// Merits the nonmonotone line search compares against.
    pub(crate) const MEMORY: usize = 4;
    /// Trial steps of the line search before the pseudo-time step is shortened instead.
    pub(crate) const TRIALS: usize = 6;

    /// The correction `ΔU` of the free DOFs into `work.rhs` from the last assembly, with the
    /// pseudo-time shift of `ptc` on the matrix's diagonal; returns `‖ΔU‖∞`.
    fn correction(&mut self, ptc: &mut Continuation) -> Result<f64, IncrementFailure> {
        for (i, d) in self.system.dofs.iter().enumerate() {
            if let Dof::Free(eq) = d {
                self.work.rhs[*eq] = -self.work.internal[i];
            }
        }
        ptc.shift(
            &mut self.work.values,
            &self.work.diagonal,
            &self.work.pseudo_mass,
        );
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

/// The event trial of the line search: where the full correction moved a contact across its
/// surface (a gap from `before` to `after` changed sign), the step just past the first such
/// crossing along the line, `1.01 α_k` with `α_k = g₀/(g₀ − g₁)` the smallest (a linear estimate
/// of the crossing): the end of the smooth piece on which Newton's model holds, and the first
/// iterate on the next piece, whose tangent then carries the contact's new status (an open
/// contact has no stiffness, so its correction pushes the node deep into the support; a pressed
/// one is pulled far off). None where no gap changed sign before the full step.
fn first_event(before: &[f64], after: &[f64]) -> Option<f64> {
    before
        .iter()
        .zip(after)
        .filter(|(g0, g1)| (**g0 > 0.0) != (**g1 > 0.0))
        .map(|(g0, g1)| g0 / (g0 - g1))
        .filter(|a| a.is_finite())
        .fold(None, |m: Option<f64>, a| Some(m.map_or(a, |m| m.min(a))))
        .map(|a| (1.01 * a).min(0.5))
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

    /// A contact whose status alternates between stick and slip three times is held in stick;
    /// once the held iteration meets the tolerances the hold is released to judge it on the true
    /// laws; failing there it is held in slip, and after a second failure nothing is held
    /// again. Changes to or from open, and fewer than three changes, are no cycle.
    #[test]
    fn a_contact_cycling_between_stick_and_slip_is_held_then_judged_on_the_true_laws() {
        use GapStatus::{Open, Slip, Stick};
        let iterates = |seq: &[[GapStatus; 2]]| -> Vec<Vec<GapStatus>> {
            seq.iter().map(|s| s.to_vec()).collect()
        };
        let open = iterates(&[[Open, Stick], [Stick, Stick], [Open, Stick], [Stick, Stick]]);
        assert_eq!(cycling(&open), None);
        assert_eq!(
            cycling(&iterates(&[[Stick, Stick], [Slip, Stick], [Stick, Stick]])),
            None
        );
        let cycle = iterates(&[[Stick, Open], [Slip, Stick], [Stick, Open], [Slip, Stick]]);
        assert_eq!(cycling(&cycle), Some(vec![Some(Stick), None]));
        let mut hold = Hold::default();
        assert_eq!(hold.next(false, &cycle[..2]), None, "no cycle yet");
        assert_eq!(hold.next(false, &cycle), Some(vec![Some(Stick), None]));
        assert_eq!(hold.next(false, &cycle), None, "held: iterating");
        assert_eq!(
            hold.next(true, &cycle),
            Some(vec![]),
            "converged held: released"
        );
        assert_eq!(
            hold.next(false, &cycle),
            Some(vec![Some(Slip), None]),
            "failed: slip"
        );
        assert_eq!(hold.next(true, &cycle), Some(vec![]));
        assert_eq!(
            hold.next(false, &cycle),
            None,
            "failed twice: no more holds"
        );
        assert_eq!(hold.next(false, &cycle), None);
        let mut hold = Hold::default();
        hold.next(false, &cycle);
        hold.next(true, &cycle);
        assert_eq!(
            hold.next(true, &cycle),
            None,
            "the stick hold met the true laws"
        );
        assert_eq!(hold.stage, 3);
    }

    /// Progress is a residual or a correction 10 % below its best; the closest iterate is the
    /// one nearest to both tolerances.
    #[test]
    fn progress_is_a_tenth_below_the_best_residual_or_correction() {
        let record = |iteration, residual, correction| IterationRecord {
            iteration,
            residual,
            residual_tolerance: 1.0,
            correction,
            correction_tolerance: 1.0,
        };
        let mut p = Progress {
            best: f64::INFINITY,
            best_correction: f64::INFINITY,
            best_at: 0,
            closest: None,
            statuses: Vec::new(),
        };
        assert!(p.note(record(1, 10.0, 5.0)));
        assert!(!p.note(record(2, 9.5, 4.6)));
        assert!(p.note(record(3, 9.5, 4.4)));
        assert_eq!(p.best_at, 3);
        assert!(p.note(record(4, 8.0, 100.0)));
        assert_eq!((p.best, p.best_correction), (8.0, 4.4));
        assert_eq!(p.closest.unwrap().iteration, 2);
    }
}

#[cfg(test)]
mod refusal_tests {
    use super::*;

    /// An iterate record with the residual `r` (tolerance 1) and the correction `dx` (tolerance 1).
    fn record(iteration: usize, r: f64, dx: f64) -> IterationRecord {
        IterationRecord {
            iteration,
            residual: r,
            residual_tolerance: 1.0,
            correction: dx,
            correction_tolerance: 1.0,
        }
    }

    /// Iterates whose residuals were `r` and whose merits were `m`.
    fn iterates(r: &[f64], m: &[f64]) -> Iterates {
        let mut it = Iterates::new(vec![0.0], false);
        it.residuals = r.to_vec();
        it.merits = m.to_vec();
        it
    }

    /// An increment held to 12 iterations is past its limit at the 12th; before it, from the
    /// fourth, only where the residual falls by less than a tenth a step over three
    /// iterations, the correction still moves, and the rate cannot reach the tolerance in the
    /// iterations left; a residual at its rounding floor (correction within tolerance) is not.
    #[test]
    fn an_increment_is_past_its_limit_where_its_residual_stagnates_while_it_still_moves() {
        let creeping = iterates(&[400.0, 14.3, 14.2, 14.05, 13.9], &[]);
        assert!(creeping.past(12, &record(4, 13.9, 8e-5 * 1e6)));
        assert!(
            !creeping.past(12, &record(3, 13.9, 1e2)),
            "not before the fourth"
        );
        assert!(
            !creeping.past(12, &record(4, 13.9, 0.5)),
            "the correction within its tolerance: a rounding floor"
        );
        let quadratic = iterates(&[400.0, 14.0, 1.4, 0.14, 1.2], &[]);
        assert!(!quadratic.past(12, &record(4, 1.2, 10.0)));
        let linear = iterates(&[400.0, 1000.0, 800.0, 640.0, 512.0], &[]);
        assert!(
            !linear.past(12, &record(4, 512.0, 10.0)),
            "a fifth off a step is progress, left to the limit however far"
        );
        let near = iterates(&[400.0, 1.3, 1.25, 1.2, 1.15], &[]);
        assert!(
            !near.past(12, &record(4, 1.15, 10.0)),
            "at that rate the tolerance is 3.4 iterations away, 8 are left"
        );
        assert!(near.past(7, &record(4, 1.15, 10.0)), "3 left");
        assert!(quadratic.past(12, &record(12, 1.2, 10.0)), "at the limit");
        assert!(!quadratic.past(12, &record(13, 1.2, 10.0)), "judged once");
    }

    /// Merits that repeat with period two, each within 1e-3 of the one two before, are an
    /// orbit; a slow fall, or a full memory not yet reached, is not.
    #[test]
    fn merits_repeating_with_period_two_are_an_orbit_and_a_slow_fall_is_not() {
        assert!(iterates(&[], &[2.304, 2.292, 2.3045, 2.2921]).orbits());
        assert!(!iterates(&[], &[2.304, 2.292, 2.304]).orbits());
        assert!(!iterates(&[], &[2.304, 2.292, 2.28, 2.27]).orbits());
        assert!(!iterates(&[], &[2.304, 1.0, 2.304, 0.5]).orbits());
    }
}
