//! The increment controller of a step, its strategy table, and the predictor.

use crate::mech::elements::gap::IterationMatrix;
use crate::mech::elements::load::LoadLevels;
use crate::mech::solve::analysis::Analysis;
use crate::mech::solve::arc_length::ArcEnd;
use crate::mech::solve::assembly::Dof;
use crate::mech::solve::newton::max_abs;
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
    /// What the increments are sized by.
    pub control: Control,
}

/// What a row's increments are sized by.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Control {
    /// The share of the step's inputs (load or boundary motion), Newton's iteration.
    Share,
    /// The arc length of the displacements, the load factor an unknown (`arc_length.rs`;
    /// Riks 1979, Crisfield 1981): only for a step whose boundary stands still.
    ArcLength,
}

/// The strategy table: Newton with pseudo-transient continuation; for a step whose boundary
/// stands still, arc-length control from where Newton refused (a limit point of the load); then
/// Newton with the viscous stabilization for the rest of a step whose smallest increment it refused (a film
/// without a unique equilibrium), at four dampings, each a hundredfold the last (the fourth,
/// 1, carries held-out `reversal#0` step 44, refused at 1e-2) ([`SolverSettings::stabilization`] off: the
/// first two rows only).
///
/// [`SolverSettings::stabilization`]: crate::mech::solve::settings::SolverSettings::stabilization
pub const STRATEGIES: [Strategy; 6] = [
    Strategy {
        name: "Newton",
        damping: 0.0,
        control: Control::Share,
    },
    Strategy {
        name: "arc-length",
        damping: 0.0,
        control: Control::ArcLength,
    },
    Strategy {
        name: "stabilized",
        damping: 1e-6,
        control: Control::Share,
    },
    Strategy {
        name: "stabilized more",
        damping: 1e-4,
        control: Control::Share,
    },
    Strategy {
        name: "stabilized most",
        damping: 1e-2,
        control: Control::Share,
    },
    Strategy {
        name: "stabilized strongest",
        damping: 1.0,
        control: Control::Share,
    },
];

/// The straight path of a step in the inputs: groups, angles and load levels from the converged
/// state's to the step's targets.
pub(super) struct StepPath<'a> {
    base: Vec<[f64; 3]>,
    base_angles: Vec<f64>,
    base_loads: LoadLevels,
    target: &'a [[f64; 3]],
    angles: &'a [f64],
    loads: &'a LoadLevels,
}

impl StepPath<'_> {
    /// The group translations and angles at the fraction `f` of the step.
    pub(super) fn motion(&self, f: f64) -> GroupMotion {
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
    pub(super) fn levels(&self, f: f64) -> LoadLevels {
        self.base_loads.interpolate(self.loads, f)
    }

    /// Whether the boundary stands still over the step (its loads alone change).
    fn boundary_still(&self) -> bool {
        self.base.as_slice() == self.target && self.base_angles.as_slice() == self.angles
    }
}

/// The increment controller's state over one step (Ramm 1981; Crisfield 1991, §9.5).
struct Controller {
    /// The share of the step converged, the next increment's size and the strategy row.
    done: f64,
    size: f64,
    row: usize,
    /// The size of the last converged increment.
    last_size: f64,
    /// The largest increment (`1/increments`), the smallest (after `max_cutbacks` halvings),
    /// and the rows of [`STRATEGIES`] in use.
    largest: f64,
    smallest: f64,
    rows: usize,
}

impl Controller {
    /// A step cut into at least `increments`, halved at most `cutbacks` times, with `rows` rows.
    fn new(increments: usize, cutbacks: usize, rows: usize) -> Self {
        let largest = 1.0 / increments as f64;
        Self {
            done: 0.0,
            size: largest,
            row: 0,
            last_size: largest,
            largest,
            smallest: largest / 2f64.powi(cutbacks as i32),
            rows,
        }
    }

    /// The end of the next increment (the step's end where it is within roundoff).
    fn next(&self) -> f64 {
        if self.done + self.size > 1.0 - 1e-12 {
            1.0
        } else {
            self.done + self.size
        }
    }

    /// After the increment to `to` converged in `n` iterations: `Δλ (N*/N)^½`, within a factor
    /// [`Analysis::GROWTH`] of it, at most the largest and at least the smallest: where Newton
    /// needs more than `N*` iterations however small the increment (a contact or film state
    /// that changes within it), the rule would shrink it without end, a step in thousands of
    /// increments that a halving would have refused to make.
    fn converged(&mut self, to: f64, n: f64) {
        self.last_size = to - self.done;
        self.done = to;
        let ratio = (Analysis::TARGET_ITERATIONS as f64 / n).sqrt();
        self.size = (self.size * ratio.clamp(1.0 / Analysis::GROWTH, Analysis::GROWTH))
            .clamp(self.smallest, self.largest);
        // The weakest damping that carries the step: one row back after each converged
        // increment of a stronger one (the work taken out grows with `c`, not with the size).
        if self.row > 0 && STRATEGIES[self.row - 1].damping > 0.0 {
            self.row -= 1;
        }
    }

    /// Whether an increment that converged in `n` iterations, changing a history or not
    /// (`dissipative`), is kept: not where it took more than `2 N*`, changed a history and a
    /// halving is left. Newton's many iterations say the increment left the region where the
    /// last state predicts the path; where friction or plasticity make the answer depend on
    /// the path, the backward-Euler increment then may reach another equilibrium than the
    /// quasi-static one (the edge-cabled suction panel's last lowering step: mid −55.0 mm
    /// whole, −9.9 mm in ten increments). Without a history the answer is the same however the
    /// step is cut, and a slow increment stands. The same holds in every row: a stabilized
    /// increment's damping is sized by its pseudo-time, so a halved one is damped alike.
    fn keeps(&self, n: f64, dissipative: bool) -> bool {
        n <= 2.0 * Analysis::TARGET_ITERATIONS as f64 || !dissipative || !self.can_halve()
    }

    /// Whether the next increment can be halved within `max_cutbacks`.
    fn can_halve(&self) -> bool {
        self.size / 2.0 >= self.smallest * (1.0 - 1e-9)
    }

    /// After a refused increment: halved, else the next row from the largest size; false where
    /// no row is left.
    fn refused(&mut self, report: &mut StepReport) -> bool {
        if self.can_halve() {
            report.cutbacks += 1;
            self.size /= 2.0;
            true
        } else {
            self.next_row()
        }
    }

    /// The next row of the table from the largest size; false where none is left.
    fn next_row(&mut self) -> bool {
        if self.row + 1 < self.rows {
            (self.row, self.size) = (self.row + 1, self.largest);
            true
        } else {
            false
        }
    }
}

/// How one part of a step's path (the boundary motion, or the load levels) moves against the
/// last converged increment: `Σ new·last`, `Σ last²`, `Σ new²`.
#[derive(Default)]
struct Collinear {
    dot: f64,
    old: f64,
    new: f64,
}

impl Collinear {
    /// Adds one component's change `new` in this increment and `last` in the last one.
    fn add(&mut self, new: f64, last: f64) {
        (self.dot, self.old, self.new) = (
            self.dot + new * last,
            self.old + last * last,
            self.new + new * new,
        );
    }

    /// None where the part stands still in both increments; Some(ratio of this increment's
    /// change to the last's) where it keeps its direction (within 8°); Some(NaN) where it
    /// turns, stops or starts.
    fn ratio(&self) -> Option<f64> {
        if self.old == 0.0 && self.new == 0.0 {
            None
        } else if self.old > 0.0 && self.dot > 0.99 * (self.old * self.new).sqrt() {
            Some(self.dot / self.old)
        } else {
            Some(f64::NAN)
        }
    }

    /// The ratio a path with this boundary motion and `loads` extrapolates by: the motion's
    /// where it moves (a motion that turns or stops extrapolates nothing, whatever the loads
    /// do: the boundary then leaves the last increment's path), the loads' where the boundary
    /// stands still; None where neither keeps its direction.
    fn ratio_with(&self, loads: &Self) -> Option<f64> {
        self.ratio()
            .or_else(|| loads.ratio())
            .filter(|r| r.is_finite())
    }
}

/// Why a step's rows refused: the last increment's failure, and the largest share of a limit
/// point the arc-length row passed.
#[derive(Default)]
struct Refusal {
    failure: Option<IncrementFailure>,
    limit: Option<f64>,
}

impl Refusal {
    /// The step's error with `done` of it converged after `cutbacks` halvings: the limit point
    /// where the arc passed one, else the last failure.
    fn error(&mut self, path: &StepPath, done: f64, cutbacks: usize) -> StepError {
        match self.limit {
            Some(peak) => StepError::LimitPoint {
                fraction: peak,
                levels: path.levels(peak),
            },
            None => StepError::NotConverged {
                fraction_done: done,
                cutbacks,
                last: self
                    .failure
                    .take()
                    .unwrap_or(IncrementFailure::Diverged { iteration: 0 }),
            },
        }
    }
}

/// The first iteration (at least 1) whose residual in `history` (one per iterate, the
/// predictor's first) is within `tolerance`; the last where none is.
fn first_within(history: &[f64], tolerance: f64) -> usize {
    let last = history.len().saturating_sub(1).max(1);
    history
        .iter()
        .skip(1)
        .position(|r| *r <= tolerance)
        .map_or(last, |k| k + 1)
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
        self.check_step(target, angles, loads, increments)?;
        let path = StepPath {
            base: self.state.boundary.clone(),
            base_angles: self.state.angles.clone(),
            base_loads: self.state.loads.clone(),
            target,
            angles,
            loads,
        };
        let rows = if self.settings.stabilization {
            STRATEGIES.len()
        } else {
            2
        };
        let mut control = Controller::new(increments, self.settings.max_cutbacks, rows);
        let mut current = self.state.clone();
        let mut last_start = None;
        let (mut report, mut refusal) = (StepReport::default(), Refusal::default());
        self.parts.stabilization.start_step();
        while control.done < 1.0 {
            let (from, to, row) = (control.done, control.next(), control.row);
            if STRATEGIES[row].control == Control::ArcLength {
                let arc = (&mut current, &mut last_start, &mut report);
                if self.arc_row(&mut control, &path, arc, &mut refusal)? {
                    break;
                }
                continue;
            }
            self.parts
                .stabilization
                .set(STRATEGIES[row].damping, to - from);
            let limit = control.can_halve().then_some(2 * Self::TARGET_ITERATIONS);
            let attempt = self.solve_increment(&current, &path.motion(to), &path.levels(to), limit);
            let kept = attempt.as_ref().map_or(true, |(state, history)| {
                let n = self.judged_iterations(history.len() - 1);
                control.keeps(n, state.history_changed_from(&current))
            });
            let how = (STRATEGIES[row].name, kept);
            let outcome = attempt.as_ref().map(|(_, h)| h.as_slice());
            self.note_attempt(&mut report, row, (from, to), how, outcome);
            match attempt {
                Ok((state, history)) if kept => {
                    let force = self.account_stabilized(&mut report, &state.displacement);
                    last_start = Some(std::mem::replace(&mut current, state));
                    control.converged(to, self.sizing_iterations(&history));
                    report.note_converged(history, force);
                }
                Err(last) if !control.refused(&mut report) => {
                    self.parts.stabilization.set(0.0, 1.0);
                    refusal.failure = Some(last);
                    return Err(refusal.error(&path, control.done, report.cutbacks));
                }
                Ok(_) => _ = control.refused(&mut report),
                Err(last) => refusal.failure = Some(last),
            }
        }
        if STRATEGIES[control.row].damping > 0.0 {
            let release = (control.row, control.last_size);
            self.release_stabilization(&mut current, &mut last_start, &path, &mut report, release);
        }
        self.parts.stabilization.set(0.0, 1.0);
        report.strain_energy = self.strain_energy_at(&current.displacement);
        report.pseudo_time_work = std::mem::take(&mut self.work.pseudo_time_work);
        // Past a limit point the stabilization reaches the step's loads only by a state the
        // damping made where it took out more than the film stores: the limit stands.
        if refusal.limit.is_some() && report.stabilization_dissipated > report.strain_energy {
            return Err(refusal.error(&path, control.done, report.cutbacks));
        }
        self.state = current;
        self.increment_start = last_start;
        Ok(report)
    }

    /// The arc-length row of a step, from `control`'s share (`arc_length.rs`), for a step whose
    /// boundary stands still: Ok(true) where it reached the step's end, Ok(false) where the
    /// next row solves the rest (after a limit point too, noted in `refusal`: a snap-through
    /// the arc did not follow back may still end at the step's loads); Err where no row is
    /// left.
    fn arc_row(
        &mut self,
        control: &mut Controller,
        path: &StepPath,
        (current, last_start, report): (
            &mut AnalysisState,
            &mut Option<AnalysisState>,
            &mut StepReport,
        ),
        refusal: &mut Refusal,
    ) -> Result<bool, StepError> {
        if path.boundary_still() {
            let from = (control.done, control.smallest);
            match self.follow_arc(current, path, from, report, control.row) {
                ArcEnd::Reached { start } => {
                    (control.done, *last_start) = (1.0, Some(start));
                    return Ok(true);
                }
                ArcEnd::LimitPoint { peak } => refusal.limit = Some(peak),
                ArcEnd::Failed { at, start, failure } => {
                    if start.is_some() {
                        (control.done, *last_start) = (at, start);
                    }
                    // Newton's refusal says more of the step's difficulty than the arc's.
                    refusal.failure.get_or_insert(failure);
                }
            }
        }
        if control.next_row() {
            return Ok(false);
        }
        Err(refusal.error(path, control.done, report.cutbacks))
    }

    /// Checks a step's targets, angles, loads and smallest number of increments.
    fn check_step(
        &self,
        target: &[[f64; 3]],
        angles: &[f64],
        loads: &LoadLevels,
        increments: usize,
    ) -> Result<(), StepError> {
        self.check_targets(target)?;
        self.check_angles(angles)?;
        self.check_loads(loads)?;
        if increments == 0 {
            return Err(StepError::InvalidInput {
                message: "increments must be at least 1".into(),
            });
        }
        Ok(())
    }

    /// The iterations an increment took, `n`, as the controller keeps or refuses it by: `N*` for
    /// the Ju–Rowlands matrix, which converges linearly by design.
    fn judged_iterations(&self, n: usize) -> f64 {
        if self.converges_linearly() {
            Self::TARGET_ITERATIONS as f64
        } else {
            n.max(1) as f64
        }
    }

    /// The iterations `N` the controller sizes the next increment by, from the residuals
    /// `history` of a converged increment's iterates: those until the residual first met its
    /// tolerance (`N*` for the Ju–Rowlands matrix). Where the answer lies on a kink of the laws
    /// (a contact at the stick–slip limit, an element at the taut–wrinkled edge) Newton's last
    /// iterations converge linearly; the iterations the displacement criterion then adds grow
    /// only with the logarithm of the increment, so they do not measure its nonlinearity, and
    /// shrinking the increment for them multiplies the increments without removing them.
    pub(super) fn sizing_iterations(&self, history: &[f64]) -> f64 {
        if self.converges_linearly() {
            return Self::TARGET_ITERATIONS as f64;
        }
        first_within(history, self.residual_tolerance()) as f64
    }

    /// Whether Newton's iterations converge linearly by design: the Ju–Rowlands matrix with
    /// gaps or curved supports (without them it is the consistent tangent).
    pub(super) fn converges_linearly(&self) -> bool {
        self.settings.iteration_matrix == IterationMatrix::JuRowlands
            && (!self.parts.curved.is_empty() || !self.state.status.is_empty())
    }

    /// At the end of a step the stabilization carried: the undamped equilibrium at the step's
    /// target solved from the damped state, alternating with a pseudo-time march at the target
    /// (implicit Euler on the damped flow, unconditionally stable) whose pseudo-time step `τ` is
    /// sized like an increment ([`Controller::converged`]: `τ (N*/N)^½` within a factor
    /// [`Self::GROWTH`] after a round converged in `N` iterations, halved after a refused one),
    /// until the damping force `c k̄ m ΔU/τ` is within the residual tolerance: the state then
    /// balances the undamped model to the same tolerance as a Newton answer (switched evolution
    /// relaxation, Mulder & van Leer 1985: as `τ → ∞` each round becomes a Newton solve).
    /// Newton refused from a state is tried again only once the march has taken
    /// [`Self::PROGRESS`]'s tenth off the damping force. The march gives up after
    /// `max_cutbacks` rounds refused or without that progress; the last converged state then
    /// stays, its damping force's work reported against the bound.
    fn release_stabilization(
        &mut self,
        current: &mut AnalysisState,
        last_start: &mut Option<AnalysisState>,
        path: &StepPath<'_>,
        report: &mut StepReport,
        (row, last): (usize, f64),
    ) {
        let (motion, levels) = (path.motion(1.0), path.levels(1.0));
        let mut tau = last;
        // The damping force of the last converged round, and at the last refusal of the
        // undamped equilibrium (∞: before any converged round).
        let (mut force, mut refused_at) = (f64::INFINITY, None::<f64>);
        let mut setbacks = 0;
        while setbacks <= self.settings.max_cutbacks {
            // Each round tries the undamped equilibrium first (Newton from the damped state),
            // then one step of the march. Refused from a state, Newton is not tried again
            // before the march has taken a tenth off the damping force: its iterations are most
            // of the release's cost, and a wrinkled film without a unique equilibrium refuses
            // every one.
            for damped in [false, true] {
                if !damped && refused_at.is_some_and(|f| force >= Self::PROGRESS * f) {
                    continue;
                }
                let (row, how) = if damped {
                    (row, "release, damped")
                } else {
                    (0, "release")
                };
                self.parts.stabilization.set(STRATEGIES[row].damping, tau);
                // The undamped try is given up like an increment that slips past `2 N*`
                // iterations: the march goes on either way.
                let limit = (!damped).then_some(2 * Self::TARGET_ITERATIONS);
                let attempt = self.solve_increment(current, &motion, &levels, limit);
                let outcome = attempt.as_ref().map(|(_, h)| h.as_slice());
                self.note_attempt(report, row, (1.0, 1.0), (how, true), outcome);
                let Ok((state, history)) = attempt else {
                    if damped {
                        (tau, setbacks) = (tau / 2.0, setbacks + 1);
                    } else {
                        refused_at = Some(force);
                    }
                    continue;
                };
                let ratio = (Self::TARGET_ITERATIONS as f64 / self.sizing_iterations(&history))
                    .sqrt()
                    .clamp(1.0 / Self::GROWTH, Self::GROWTH);
                let before = force;
                force = self.released_round(current, last_start, report, state, history);
                if force <= self.residual_tolerance() {
                    return;
                }
                setbacks += usize::from(force > Self::PROGRESS * before);
                tau *= ratio;
            }
        }
    }

    /// Takes the converged release round `state` (residuals `history`) as the step's state;
    /// returns its damping force's largest magnitude (N).
    fn released_round(
        &mut self,
        current: &mut AnalysisState,
        last_start: &mut Option<AnalysisState>,
        report: &mut StepReport,
        mut state: AnalysisState,
        history: Vec<f64>,
    ) -> f64 {
        let force = self.account_stabilized(report, &state.displacement);
        // The step's last increment, for the next step's predictor, is the motion from the
        // start of the last loaded increment to here.
        for (l, a) in state.last_increment.iter_mut().zip(&current.last_increment) {
            *l += a;
        }
        let loads = state.last_load_increment.iter_mut();
        for (l, a) in loads.zip(&current.last_load_increment) {
            *l += a;
        }
        report.note_converged(history, force);
        *last_start = Some(std::mem::replace(current, state));
        force
    }

    /// The residual tolerance at the last assembly (N).
    pub(super) fn residual_tolerance(&self) -> f64 {
        self.settings.residual_tolerance * max_abs(&self.work.internal).max(self.force_floor)
    }

    /// Tells the observer (`progress.rs`) how the increment `from → to` of the step solved by
    /// row `row` of [`STRATEGIES`] (named `how`) ended, and lists it in the report's attempts.
    pub(super) fn note_attempt(
        &self,
        report: &mut StepReport,
        row: usize,
        (from, to): (f64, f64),
        (how, kept): (&'static str, bool),
        outcome: Result<&[f64], &IncrementFailure>,
    ) {
        let iterations = match outcome {
            Ok(h) => h.len().saturating_sub(1),
            Err(failure) => failure.iterations(),
        };
        self.observer.note(|| IncrementNote {
            from,
            to,
            attempt: how,
            iterations,
            residual: outcome.map_or(f64::NAN, |h| h.last().copied().unwrap_or(0.0)),
            refused: match outcome {
                Err(failure) => Some(failure.phrase()),
                Ok(_) if !kept => Some("more than 2 N* iterations"),
                Ok(_) => None,
            },
            cutbacks: report.cutbacks,
        });
        report.attempts.push(Attempt {
            strategy: row,
            from,
            to,
            iterations,
            converged: outcome.is_ok() && kept,
        });
    }

    /// Accounts an increment converged at `u` (the stabilization's work over it added to the
    /// step's dissipated work; the work of the force the state carries is this increment's);
    /// returns that force's largest magnitude (N; 0 without stabilization).
    fn account_stabilized(&mut self, report: &mut StepReport, u: &[f64]) -> f64 {
        if self.parts.stabilization.is_on() {
            report.stabilized += 1;
            let work = self.parts.stabilization.work(&self.system, u);
            report.stabilization_dissipated += work;
            report.stabilization_energy = work;
            self.parts.stabilization.force_inf(&self.system, u)
        } else {
            report.stabilization_energy = 0.0;
            0.0
        }
    }

    /// `N*`: the Newton iterations an increment is sized for (Ramm 1981).
    pub(crate) const TARGET_ITERATIONS: usize = 6;
    /// Largest factor between two successive increments, and on the predictor's extrapolation.
    pub(crate) const GROWTH: f64 = 2.0;

    /// The first iterate of an increment from the converged `start` to `motion` and `levels`:
    /// the prescribed DOFs at their values and, where the path keeps its direction (the boundary
    /// motion along its last converged increment's, or the boundary still and the load levels
    /// along their last change: [`Collinear::ratio_with`]), the free DOFs extrapolated along the
    /// last increment by the ratio of the moves (fewer iterations, same converged answer), then corrected by each contribution where the
    /// extrapolation leaves its constraint (`Contribution::correct_prediction`: closed
    /// curved-support contacts kept at their converged gap).
    pub(super) fn predict(
        &self,
        start: &AnalysisState,
        motion: &GroupMotion,
        levels: &LoadLevels,
    ) -> Vec<f64> {
        let mut u = self.unextrapolated(start, motion);
        let mut moved = Collinear::default();
        for (i, d) in self.system.dofs.iter().enumerate() {
            if let Dof::Prescribed { .. } = d {
                let last = start.last_increment.get(i).copied().unwrap_or(0.0);
                moved.add(u[i] - start.displacement[i], last);
            }
        }
        let mut loaded = Collinear::default();
        let steps = levels.path().zip(start.loads.path());
        for ((new, old), last) in steps.zip(&start.last_load_increment) {
            loaded.add(new - old, *last);
        }
        if let Some(ratio) = moved.ratio_with(&loaded) {
            // Not beyond twice the last increment: an enlarged increment (see `step_to`) would
            // otherwise extrapolate the film far outside the range where the last one tells
            // anything (residuals of 1e11 N were measured at its first iterate).
            let ratio = ratio.min(Self::GROWTH);
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

    /// Checks that each free DOF of `once` and `twice` is `start`'s plus one and two last
    /// increments, and of each of `unmoved` `start`'s; returns how many free DOFs moved.
    fn free_dofs_extrapolated(
        a: &Analysis,
        start: &AnalysisState,
        [once, twice]: [&[f64]; 2],
        unmoved: &[&[f64]],
    ) -> usize {
        let near = |x: f64, y: f64| (x - y).abs() <= 1e-12 * (1.0 + y.abs());
        let mut extrapolated = 0;
        for (i, d) in a.system.dofs.iter().enumerate() {
            let (u0, du) = (start.displacement[i], start.last_increment[i]);
            if let Dof::Free(_) = d {
                assert!(
                    near(once[i], u0 + du),
                    "DOF {i}: {} vs {}",
                    once[i],
                    u0 + du
                );
                assert!(near(twice[i], u0 + 2.0 * du), "DOF {i}");
                unmoved.iter().for_each(|u| assert_eq!(u[i], u0, "DOF {i}"));
                extrapolated += usize::from(du != 0.0);
            }
        }
        extrapolated
    }

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
        let levels = start.loads.clone();
        let (same, back, far) = (
            a.predict(&start, &motion(2.0), &levels),
            a.predict(&start, &motion(0.0), &levels),
            a.predict(&start, &motion(5.0), &levels),
        );
        let extrapolated = free_dofs_extrapolated(&a, &start, [&same, &far], &[&back]);
        for (i, d) in a.system.dofs.iter().enumerate() {
            let u0 = start.displacement[i];
            match *d {
                Dof::Free(_) => {}
                Dof::Prescribed { group, component } => {
                    assert_eq!(same[i], 2.0 * first[group][component]);
                    assert_eq!(back[i], 0.0);
                }
                Dof::Fixed => assert_eq!((same[i], far[i], back[i]), (u0, u0, u0)),
            }
        }
        assert!(extrapolated > 0, "the first step moved no free DOF");
    }

    /// A load path is extrapolated like a boundary motion: after two pressure steps of the
    /// same size the third's first iterate is the last state plus the last increment (twice
    /// it for a step twice as large), and nothing is extrapolated for a step back, a step that
    /// changes the load by another ratio than the motion, or a motion after a load step.
    #[test]
    fn a_load_path_that_keeps_its_direction_is_extrapolated_by_its_ratio() {
        let text = include_str!("../../../examples/circular_membrane.json");
        let model = crate::mech::model::Model::from_json(text).unwrap();
        let mut a = Analysis::new(model, SolverSettings::default()).unwrap();
        let still = a.state().boundary.clone();
        let initial = a.state().loads.clone();
        let pressure = |p: f64| {
            let mut levels = initial.clone();
            levels.pressure[0] = p;
            levels
        };
        let (one, two) = (pressure(100.0), pressure(200.0));
        a.step_to_with_loads(&still, &one, 1).unwrap();
        a.step_to_with_loads(&still, &two, 1).unwrap();
        let start = a.state().clone();
        let motion = |t: Vec<[f64; 3]>| GroupMotion {
            angles: vec![0.0; t.len()],
            translation: t,
        };
        let at = |levels: &LoadLevels| a.predict(&start, &motion(still.clone()), levels);
        let (same, double, back) = (at(&pressure(300.0)), at(&pressure(400.0)), at(&one));
        let moved: Vec<[f64; 3]> = still.iter().map(|t| [t[0], t[1], t[2] + 1e-3]).collect();
        let mixed = a.predict(&start, &motion(moved), &pressure(300.0));
        let extrapolated = free_dofs_extrapolated(&a, &start, [&same, &double], &[&back, &mixed]);
        assert!(extrapolated > 0, "the pressure step moved no free DOF");
    }

    /// An increment that slips is refused as soon as Newton passes the limit given, with the
    /// iteration it stopped at, not after it converged; one that changes no history (the
    /// pressurised disc) goes on past the limit to its equilibrium.
    #[test]
    fn an_increment_that_slips_is_refused_at_the_limit_and_one_without_history_goes_on() {
        let spec = ParallelArch::default();
        let model = spec.model().unwrap();
        let target = spec.boundary_targets(&model, 1.0);
        let mut a = Analysis::new(model, SolverSettings::default()).unwrap();
        let start = a.state().clone();
        let motion = GroupMotion {
            angles: vec![0.0; target.len()],
            translation: target,
        };
        let (state, history) = a
            .solve_increment(&start, &motion, &start.loads, None)
            .unwrap();
        assert!(state.history_changed_from(&start) && history.len() > 3);
        let refused = a.solve_increment(&start, &motion, &start.loads, Some(2));
        assert!(
            matches!(
                refused,
                Err(IncrementFailure::PathDependent { iteration: 2 })
            ),
            "{:?}",
            refused.map(|(_, history)| history)
        );
        let text = include_str!("../../../examples/circular_membrane.json");
        let model = crate::mech::model::Model::from_json(text).unwrap();
        let mut a = Analysis::new(model, SolverSettings::default()).unwrap();
        let start = a.state().clone();
        let mut levels = start.loads.clone();
        levels.pressure[0] = 100.0;
        let still = GroupMotion {
            translation: start.boundary.clone(),
            angles: start.angles.clone(),
        };
        let (state, history) = a.solve_increment(&start, &still, &levels, Some(2)).unwrap();
        assert!(!state.history_changed_from(&start) && history.len() > 3);
    }

    /// The controller sizes by the iterations until the residual met its tolerance: the
    /// linearly converging iterations after it are not counted; without a residual within it,
    /// every iteration counts.
    #[test]
    fn increments_are_sized_by_the_iterations_to_equilibrium_not_by_a_linear_tail() {
        let linear_tail = [1.0, 1e-4, 4e-6, 2e-6, 1e-6, 5e-7, 2e-7];
        assert_eq!(first_within(&linear_tail, 1e-5), 2);
        assert_eq!(first_within(&linear_tail, 1e-9), 6);
        assert_eq!(first_within(&[1e-6], 1e-5), 1, "a model without free DOFs");
        assert_eq!(first_within(&[1.0, 2e-6], 1e-5), 1);
    }

    /// The sizing rule `Δλ (N*/N)^½` shrinks an increment that needs many iterations, but
    /// never below the smallest a halving reaches (else a step whose increments all need
    /// `2 N*` iterations is cut into thousands), and never grows one above the largest.
    #[test]
    fn increments_are_sized_between_the_smallest_halving_and_the_largest() {
        let mut control = Controller::new(4, 3, 2);
        let slow = 2.0 * Analysis::TARGET_ITERATIONS as f64;
        for _ in 0..40 {
            let to = control.next();
            control.converged(to, slow);
        }
        assert_eq!(control.size, 0.25 / 8.0, "held at the smallest increment");
        assert!(!control.can_halve());
        for _ in 0..40 {
            let to = control.next();
            control.converged(to, 1.0);
        }
        assert_eq!(control.size, 0.25, "grown back to the largest, not past it");
    }

    /// A moving boundary extrapolates by its ratio where it keeps the direction (within 8°) of
    /// the last increment, and nothing where it turns, stops or starts; a still one by the
    /// loads' ratio on the same terms.
    #[test]
    fn a_path_extrapolates_by_the_motion_else_by_the_loads_where_they_keep_their_direction() {
        let part = |pairs: &[(f64, f64)]| {
            let mut c = Collinear::default();
            pairs.iter().for_each(|&(new, last)| c.add(new, last));
            c
        };
        let still = part(&[(0.0, 0.0)]);
        let along = part(&[(2.0, 1.0), (4.0, 2.0)]);
        let along_more = part(&[(3.0, 1.0)]);
        assert_eq!(still.ratio_with(&still), None);
        assert_eq!(along.ratio_with(&still), Some(2.0));
        assert_eq!(still.ratio_with(&along), Some(2.0));
        assert_eq!(along.ratio_with(&along), Some(2.0));
        assert_eq!(along.ratio_with(&along_more), Some(2.0), "the motion's");
        assert_eq!(
            along.ratio_with(&part(&[(0.0, 1.0)])),
            Some(2.0),
            "loads stopped"
        );
        assert_eq!(still.ratio_with(&along_more), Some(3.0));
        assert_eq!(part(&[(-1.0, 1.0)]).ratio_with(&along), None, "back");
        assert_eq!(still.ratio_with(&part(&[(-1.0, 1.0)])), None, "loads back");
        assert_eq!(part(&[(0.0, 1.0)]).ratio_with(&still), None, "stopped");
        assert_eq!(part(&[(1.0, 0.0)]).ratio_with(&still), None, "started");
        assert_eq!(
            part(&[(1.0, 1.0), (0.2, 0.0)]).ratio_with(&still),
            None,
            "turned 11°"
        );
    }
}
