//! The smoothing homotopy: an increment that every other attempt refused while contacts switch
//! between the branches of their law (open/closed, stick/slip) and film elements between taut,
//! wrinkled and slack from one iterate to the next is solved under the laws with those switches
//! rounded (`elements/smoothing.rs`, `curved_contact/smoothing.rs`): a C¹ problem, on which
//! Newton's iterates do not switch. The rounding starts at a width of its own scale (four times
//! the deepest contact penetration, at least 1e-3 of the tube radius; a strain of 1e-4 for the
//! film), tenfold wider (twice at most) where that problem is refused. From each rounded
//! solution the laws' own equilibrium is solved by Newton with the solver's own test, then, with
//! curved contacts, by Newton with the contacts' statuses at the rounded solution held (the
//! active set, changed only between converged solves); where both are refused, the rounded
//! solution itself is the answer if the laws' residual there is within
//! its tolerance (Newton's correction from it then runs along a soft mode of the film and is not
//! within the displacement tolerance: `StepReport::smoothed_on_residual`). Else the rounding is
//! reduced tenfold, the next problem started from the last solution (a refused one: a shorter
//! step in the width, its ratio square-rooted), up to 16 problems. The first problem starts from
//! the predictor's iterate; where that path is refused and the predictor extrapolated, the path
//! is tried once more from the converged start with only the prescribed DOFs moved; last, from
//! the predictor's iterate with the rounded problems Newton refuses solved damped. The
//! increment's answer is always the laws' own equilibrium; a rounded problem's solution is never
//! accepted unless it is one.
//!
//! This is the smoothing (noninterior) continuation for complementarity problems (Chen &
//! Harker, SIAM J. Matrix Anal. Appl. 14, 1993; Kanzow, SIAM J. Matrix Anal. Appl. 17, 1996):
//! the rounded problems' solutions follow a path as the width goes to 0 whose end is the laws'
//! equilibrium, and Newton started close to that end converges to it where the statuses there
//! are unambiguous. docs/mechanics.md, "Smoothing homotopy".

use crate::mech::elements::load::LoadLevels;
use crate::mech::elements::material::Wrinkling;
use crate::mech::solve::analysis::{Acceptance, Analysis};
use crate::mech::solve::report::{IncrementFailure, StepReport};
use crate::mech::solve::state::{AnalysisState, GroupMotion};

/// Where one of the homotopy's paths starts and how its rounded problems are solved.
struct SmoothingPath {
    /// The first rounded problem's first iterate (the predictor's if None).
    first: Option<Vec<f64>>,
    /// Whether rounded problems that Newton and the continuation refuse are solved damped.
    damped: bool,
}

impl Analysis {
    /// Most smoothed problems the homotopy solves in one increment.
    const SMOOTHING_SOLVES: usize = 16;
    /// The first strain width of the tension-field film's rounding (80 kPa on E = 800 MPa).
    const SMOOTHING_STRAIN: f64 = 1e-4;
    /// The first ratio of one width to the next.
    const SMOOTHING_RATIO: f64 = 0.1;
    /// Widths tried larger tenfold where the first smoothed problem is refused.
    const SMOOTHING_WIDER: usize = 2;

    /// Whether the model has a law the homotopy rounds: curved contacts, or an elastic
    /// tension-field film.
    pub(super) fn smoothing_applies(&self) -> bool {
        let film = &self.system.material;
        !self.parts.curved.is_empty()
            || (film.wrinkling == Wrinkling::TensionField && film.plastic_film().is_none())
    }

    /// The increment from `start` to `motion` and `levels` by the smoothing homotopy (module
    /// doc), counted in `report.smoothed`. Where it is refused (the increment's failure is that
    /// of the attempts before it): the sliding-direction contacts its refused attempts named as
    /// lifting off with more than the friction limit across (`IncrementFailure::lifting`), for
    /// the controller's lift-off release.
    pub(super) fn solve_smoothed(
        &mut self,
        start: &AnalysisState,
        motion: &GroupMotion,
        levels: &LoadLevels,
        report: &mut StepReport,
    ) -> Result<(AnalysisState, Vec<f64>), Vec<String>> {
        let mut lifting = Vec::new();
        // From the predictor's iterate; then, where the predictor extrapolated, from the start as
        // it was (an extrapolated film can be so far from equilibrium that no rounded problem
        // converges from it: first residuals of 1.3e5 N and 4.5e5 N on held-out `arches#15` and
        // `#21`); last, from the predictor's iterate with the rounded problems that Newton and
        // the continuation refuse tried damped (`solve_smoothed_problem`).
        let unextrapolated = self.unextrapolated(start, motion);
        let extrapolated = unextrapolated != self.predict(start, motion);
        let paths = [
            SmoothingPath {
                first: None,
                damped: false,
            },
            SmoothingPath {
                first: Some(unextrapolated),
                damped: false,
            },
            SmoothingPath {
                first: None,
                damped: true,
            },
        ];
        for path in paths {
            if path.first.is_some() && !extrapolated {
                continue;
            }
            if path.damped && !self.settings.stabilization {
                break;
            }
            let converged = self.smoothing_path(start, motion, levels, path, report, &mut lifting);
            if let Some(converged) = converged {
                return Ok(converged);
            }
        }
        Err(lifting)
    }

    /// Appends to `out` the contacts `failure` names as lifting off that it does not hold yet.
    fn note_lifting(failure: &IncrementFailure, out: &mut Vec<String>) {
        for name in failure.lifting() {
            if !out.contains(name) {
                out.push(name.clone());
            }
        }
    }

    /// The homotopy's `path` from the first rounded problem to the laws' equilibrium; None where
    /// it is refused (the contacts its refused attempts named as lifting off appended to
    /// `lifting`).
    fn smoothing_path(
        &mut self,
        start: &AnalysisState,
        motion: &GroupMotion,
        levels: &LoadLevels,
        SmoothingPath { first, damped }: SmoothingPath,
        report: &mut StepReport,
        lifting: &mut Vec<String>,
    ) -> Option<(AnalysisState, Vec<f64>)> {
        // The widths at level 1 (contacts, m; film, strain); `w` is the level.
        let contact_width = if self.parts.curved.is_empty() {
            0.0
        } else {
            self.parts
                .curved
                .smoothing_width(&start.displacement, &start.contacts)
        };
        let widths = (contact_width, Self::SMOOTHING_STRAIN);
        let mut w = 1.0;
        // The last smoothed solution and its width; the ratio to the next width.
        let mut solved: Option<(Vec<f64>, f64)> = None;
        let (mut ratio, mut wider) = (Self::SMOOTHING_RATIO, 0);
        for _ in 0..Self::SMOOTHING_SOLVES {
            let guess = solved
                .as_ref()
                .map(|(u, _)| u.clone())
                .or_else(|| first.clone());
            let widths = (w * widths.0, w * widths.1);
            let trial = self.solve_smoothed_problem(start, motion, levels, widths, &guess, damped);
            let trial = trial.map_err(|failure| Self::note_lifting(&failure, lifting));
            let Ok(u) = trial else {
                match &solved {
                    // Refused from the start: a wider rounding.
                    None if wider < Self::SMOOTHING_WIDER => {
                        wider += 1;
                        w *= 10.0;
                    }
                    None => break,
                    // Refused after a solution: a shorter step in the width from it.
                    Some((_, from)) => {
                        ratio = ratio.sqrt();
                        if ratio > 0.9 {
                            break;
                        }
                        w = from * ratio;
                    }
                }
                continue;
            };
            // The law itself from the smoothed solution.
            self.work.guess = Some(u.clone());
            match self.solve_increment(start, motion, levels) {
                Ok(converged) => {
                    report.smoothed += 1;
                    return Some(converged);
                }
                Err(failure) => Self::note_lifting(&failure, lifting),
            }
            // Newton on the law refused where it switches a contact back and forth across its
            // corner: the law with the contacts' statuses at the smoothed solution held
            // (`ActiveSet`), changed only between converged solves.
            if !self.parts.curved.is_empty() {
                self.work.guess = Some(u.clone());
                self.parts.curved.active_set = true;
                let held = self.solve_increment(start, motion, levels);
                self.parts.curved.active_set = false;
                self.parts.curved.frozen = None;
                if let Ok(converged) = held {
                    report.smoothed += 1;
                    return Some(converged);
                }
            }
            // Newton on the law refused (a correction along a soft mode of the film undoing
            // the solution): the smoothed solution itself where the law's residual there is
            // within its tolerance.
            self.work.guess = Some(u.clone());
            self.work.acceptance = Acceptance::Start;
            let at_start = self.solve_increment(start, motion, levels);
            self.work.acceptance = Acceptance::Law;
            if let Ok(converged) = at_start {
                report.smoothed += 1;
                report.smoothed_on_residual += 1;
                return Some(converged);
            }
            solved = Some((u, w));
            w *= ratio;
        }
        None
    }

    /// The rounded problem of widths `(contact, strain)` from `guess` (the predictor's iterate if
    /// none): plain Newton, then the continuation, then where `damped` Newton with the viscous
    /// stabilization at each of its dampings, each accepted on the residual alone; its
    /// displacements, or the last attempt's failure.
    fn solve_smoothed_problem(
        &mut self,
        start: &AnalysisState,
        motion: &GroupMotion,
        levels: &LoadLevels,
        (contact, strain): (f64, f64),
        guess: &Option<Vec<f64>>,
        damped: bool,
    ) -> Result<Vec<f64>, IncrementFailure> {
        self.parts.curved.smoothing = contact;
        self.parts.triangles.smoothing = strain;
        self.work.acceptance = Acceptance::Residual;
        self.work.guess.clone_from(guess);
        let mut smoothed = self.solve_increment(start, motion, levels);
        if smoothed.is_err() && self.settings.continuation {
            self.work.guess.clone_from(guess);
            self.work.continuation = true;
            smoothed = self.solve_increment(start, motion, levels);
            self.work.continuation = false;
        }
        // Then with the viscous stabilization's damping (a slack or wrinkled film's soft modes,
        // where Newton on the rounded problem stalls): its solution is only the start of the
        // next problem and of Newton on the laws, which carry no damping.
        if smoothed.is_err() && damped {
            for c in Self::STABILIZATION_DAMPING {
                self.work.guess.clone_from(guess);
                self.parts.stabilization.switch_on(c);
                smoothed = self.solve_increment(start, motion, levels);
                self.parts.stabilization.switch_off();
                if smoothed.is_ok() {
                    break;
                }
            }
        }
        self.work.acceptance = Acceptance::Law;
        self.parts.curved.smoothing = 0.0;
        self.parts.triangles.smoothing = 0.0;
        smoothed.map(|(state, _)| state.displacement)
    }
}
