//! Arc-length control: the strategy table's row for a step whose boundary stands still and
//! whose loads pass a limit point (docs/mechanics.md, "The nonlinear method").
//!
//! Riks, *An incremental approach to the solution of snapping and buckling problems*, Int. J.
//! Solids Struct. 15 (1979); Crisfield, *A fast incremental/iterative solution procedure that
//! handles "snap-through"*, Comput. Struct. 13 (1981), and *Non-linear Finite Element Analysis
//! of Solids and Structures* vol. 1 (1991), §9.3: the cylindrical arc length. The load factor
//! `λ` (the share of the step's load change) joins the unknowns; each increment from the
//! converged `(U₀, λ₀)` solves `R(U, λ) = 0` with `‖U − U₀‖₂ = Δs` over the free DOFs. Each
//! iteration solves `K a = −R` and `K b = q`, `q = −∂R/∂λ`, with one factorization, and takes
//! `δU = a + δλ b` with the root `δλ` of the constraint's quadratic whose `ΔU` turns least from
//! the last (Crisfield's angle test). The predictor is `Δλ = ±Δs/‖b‖`, the sign that of
//! `ΔU_prev · b` (Feng, Perić & Owen 1996), so that the path goes on past a limit point instead
//! of turning back. `Δs` follows the increments' rule: `Δs (N*/N)^½` within a factor
//! [`Analysis::GROWTH`], halved on failure up to `max_cutbacks` times.
//!
//! **How a step ends.** Where `λ` comes back to the step's end (a snap-through), the last
//! increment is load-controlled to `λ = 1` exactly. Where the path passes a largest `λ < 1` and
//! falls back below the load it started from, the load has no equilibrium on this path: the
//! step is refused as [`StepError::LimitPoint`] with that largest load, the last converged
//! state kept.
//!
//! [`StepError::LimitPoint`]: crate::mech::solve::report::StepError::LimitPoint

use crate::mech::solve::analysis::Analysis;
use crate::mech::solve::assembly::Dof;
use crate::mech::solve::increments::{STRATEGIES, StepPath};
use crate::mech::solve::newton::max_abs;
use crate::mech::solve::report::StepReport;
use crate::mech::solve::report::{IncrementFailure, IterationRecord};
use crate::mech::solve::state::AnalysisState;

/// How the arc-length row ended a step's path.
pub(super) enum ArcEnd {
    /// At the step's end (`λ = 1`); the start of its last increment.
    Reached { start: AnalysisState },
    /// Past a limit point: the largest share of the step reached (the converged `current` back
    /// at the arc's start).
    LimitPoint { peak: f64 },
    /// Refused at the smallest arc length before any limit point, at the share `at` (where
    /// the converged `current` is; the start of its last increment, if any).
    Failed {
        at: f64,
        start: Option<AnalysisState>,
        failure: IncrementFailure,
    },
}

/// A converged arc-length increment: the state, its load factor, its `ΔU` over the free DOFs
/// and its residuals.
pub(super) struct ArcStep {
    pub state: AnalysisState,
    pub lambda: f64,
    pub delta: Vec<f64>,
    pub residuals: Vec<f64>,
}

impl Analysis {
    /// One arc-length increment of length `ds` from the converged `start` at `lambda`,
    /// continuing the direction of the last converged `previous` `ΔU` (None: towards larger
    /// `λ`).
    pub(super) fn arc_increment(
        &mut self,
        start: &AnalysisState,
        path: &StepPath,
        (lambda, ds): (f64, f64),
        previous: Option<&[f64]>,
    ) -> Result<ArcStep, IncrementFailure> {
        for c in self.parts.all_mut() {
            c.restore(start);
        }
        let motion = path.motion(0.0);
        let mut u = start.displacement.clone();
        let b = self.load_tangent(&u, path, lambda, 0)?;
        let b_norm = dot(&b, &b).sqrt();
        let sign = previous.map_or(1.0, |p| if dot(p, &b) < 0.0 { -1.0 } else { 1.0 });
        let mut dl = sign * ds / b_norm;
        if !dl.is_finite() {
            return Err(IncrementFailure::Diverged { iteration: 0 });
        }
        let mut delta: Vec<f64> = b.iter().map(|v| dl * v).collect();
        add_free(&self.system.dofs, &mut u, &delta);
        let mut residuals = vec![self.free_norm_inf()];
        let mut last = None;
        // An increment that needs more than `2 N*` iterations is refused and halved, as the
        // controller refuses one (`Controller::keeps`).
        let most = self
            .settings
            .max_iterations
            .min(2 * Self::TARGET_ITERATIONS);
        for iteration in 1..=most {
            let b = self.load_tangent(&u, path, lambda + dl, iteration)?;
            let residual = self.free_norm_inf();
            if !residual.is_finite() {
                return Err(IncrementFailure::Diverged { iteration });
            }
            residuals.push(residual);
            let a = self.held_correction()?;
            let (step, theta) = constrained_step(&delta, &a, &b, ds)
                .ok_or(IncrementFailure::Diverged { iteration })?;
            let moved = max_abs(&delta).max(1e-9 * self.length_scale);
            let record = IterationRecord {
                iteration,
                residual,
                residual_tolerance: self.residual_tolerance(),
                correction: max_abs(&step),
                correction_tolerance: self.settings.displacement_tolerance * moved,
            };
            if record.residual <= record.residual_tolerance
                && record.correction <= record.correction_tolerance
            {
                let levels = path.levels(lambda + dl);
                let (state, residuals) =
                    self.commit_increment(start, &motion, &levels, u, residuals, iteration)?;
                return Ok(ArcStep {
                    state,
                    lambda: lambda + dl,
                    delta,
                    residuals,
                });
            }
            add_free(&self.system.dofs, &mut u, &step);
            for (d, s) in delta.iter_mut().zip(&step) {
                *d += s;
            }
            dl += theta;
            last = Some(record);
        }
        Err(
            last.map_or(IncrementFailure::Diverged { iteration: 0 }, |last| {
                IncrementFailure::MaxIterations {
                    first_residual: residuals[0],
                    last,
                    matrix: self.settings.iteration_matrix,
                    chattering: vec![],
                    flipping: vec![],
                    compressed: vec![],
                }
            }),
        )
    }

    /// `b = K⁻¹ q` at `(u, λ)`, `q = −∂R/∂λ` by a forward difference of the residual over the
    /// load factor, with the residual and the matrix at `(u, λ)` assembled last and `K`
    /// factorized (held for [`Self::held_correction`]).
    fn load_tangent(
        &mut self,
        u: &[f64],
        path: &StepPath,
        lambda: f64,
        iteration: usize,
    ) -> Result<Vec<f64>, IncrementFailure> {
        let h = 1e-6 * lambda.abs().max(1.0);
        self.assemble_at(u, &path.levels(lambda + h), None);
        let shifted = self.work.internal.clone();
        self.assemble_at(u, &path.levels(lambda), Some(iteration));
        for (i, d) in self.system.dofs.iter().enumerate() {
            if let Dof::Free(eq) = d {
                self.work.rhs[*eq] = (self.work.internal[i] - shifted[i]) / h;
            }
        }
        self.solve_factorized(true)
    }

    /// `a = −K⁻¹ R` with the factor [`Self::load_tangent`] left.
    fn held_correction(&mut self) -> Result<Vec<f64>, IncrementFailure> {
        for (i, d) in self.system.dofs.iter().enumerate() {
            if let Dof::Free(eq) = d {
                self.work.rhs[*eq] = -self.work.internal[i];
            }
        }
        self.solve_factorized(false)
    }

    /// Solves `K x = work.rhs` with the matrix in `work.values`, factorizing it (`factorize`)
    /// or with the factor held, the sealed chambers' low-rank term included; `x` also stays in
    /// `work.rhs`.
    fn solve_factorized(&mut self, factorize: bool) -> Result<Vec<f64>, IncrementFailure> {
        let mut rhs = std::mem::take(&mut self.work.rhs);
        let matrix = self.system.matrix(&self.work.values);
        let solved = if factorize {
            self.linear.factorize_and_solve(matrix, &mut rhs)
        } else {
            self.linear.solve_held(matrix, &mut rhs)
        };
        let solved = solved.and_then(|()| self.add_low_rank(&mut rhs));
        self.work.rhs.clone_from(&rhs);
        solved.map_err(|e| IncrementFailure::Singular { message: e.0 })?;
        Ok(rhs)
    }
}

/// Adds the free-DOF vector `delta` to the displacements `u` of every DOF.
fn add_free(dofs: &[Dof], u: &mut [f64], delta: &[f64]) {
    for (i, d) in dofs.iter().enumerate() {
        if let Dof::Free(eq) = d {
            u[i] += delta[*eq];
        }
    }
}

/// Refused before any limit point: the rows below go on from the largest load factor reached
/// (`peak`: it, and that state with the start of its increment, if any), `current` moved there.
fn failed_from(
    current: &mut AnalysisState,
    peak: (f64, Option<(AnalysisState, AnalysisState)>),
    failure: IncrementFailure,
) -> ArcEnd {
    let start = peak.1.map(|(state, start)| {
        *current = state;
        start
    });
    ArcEnd::Failed {
        at: peak.0,
        start,
        failure,
    }
}

/// `Σ a·b`.
fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

/// The correction `a + θ b` and `θ` that keep `‖delta + a + θ b‖ = ds`, the root whose new
/// `ΔU` turns least from `delta` (Crisfield 1981); None where both roots are complex.
fn constrained_step(delta: &[f64], a: &[f64], b: &[f64], ds: f64) -> Option<(Vec<f64>, f64)> {
    let da: Vec<f64> = delta.iter().zip(a).map(|(d, a)| d + a).collect();
    let (qa, qb, qc) = (dot(b, b), 2.0 * dot(&da, b), dot(&da, &da) - ds * ds);
    let disc = qb * qb - 4.0 * qa * qc;
    if !(disc >= 0.0) || qa == 0.0 {
        return None;
    }
    let root = disc.sqrt();
    let roots = [(-qb + root) / (2.0 * qa), (-qb - root) / (2.0 * qa)];
    let turn = |t: f64| dot(&da, delta) + t * dot(b, delta);
    let theta = if turn(roots[0]) >= turn(roots[1]) {
        roots[0]
    } else {
        roots[1]
    };
    Some((a.iter().zip(b).map(|(a, b)| a + theta * b).collect(), theta))
}

impl Analysis {
    /// The arc-length row of a step (row `row` of the strategy table): follows `path` from the
    /// converged `current` at the share `from`, the first and smallest arc length that of the
    /// linear response to the smallest increment `smallest`, until the step's end, a limit
    /// point, or the smallest arc length refused; `current` is the last converged state.
    pub(super) fn follow_arc(
        &mut self,
        current: &mut AnalysisState,
        path: &StepPath,
        (from, smallest): (f64, f64),
        report: &mut StepReport,
        row: usize,
    ) -> ArcEnd {
        for c in self.parts.all_mut() {
            c.restore(current);
        }
        let origin = current.clone();
        // The linear response to the whole step's load change; none (a step that changes no
        // load) leaves no path to follow.
        let whole = match self.load_tangent(&current.displacement, path, from, 0) {
            Ok(b) => dot(&b, &b).sqrt(),
            Err(failure) => {
                return ArcEnd::Failed {
                    at: from,
                    start: None,
                    failure,
                };
            }
        };
        if !(whole > 0.0 && whole.is_finite()) {
            let failure = IncrementFailure::Diverged { iteration: 0 };
            return ArcEnd::Failed {
                at: from,
                start: None,
                failure,
            };
        }
        // From the smallest increment's arc: where Newton refused for another reason than a
        // limit point (a contact chattering, a film without a unique equilibrium), the arc is
        // refused at once, at the cost of one increment.
        let (mut ds, smallest) = (whole * smallest, whole * smallest);
        let (mut lambda, mut previous) = (from, None::<Vec<f64>>);
        // The converged state of the largest load factor and the start of its increment.
        let mut peak: (f64, Option<(AnalysisState, AnalysisState)>) = (from, None);
        let limit = Analysis::MAX_TARGET_PER_SIZE * self.length_scale;
        // At most as many increments as the step has at its smallest size.
        for _ in 0..1usize << self.settings.max_cutbacks.min(20) {
            let attempt = self.arc_increment(current, path, (lambda, ds), previous.as_deref());
            let to = attempt.as_ref().map_or(lambda, |s| s.lambda);
            let noted = attempt.as_ref().map(|s| s.residuals.as_slice());
            let how = (STRATEGIES[row].name, to < 1.0);
            self.note_attempt(report, row, (lambda, to), how, noted);
            let step = match attempt {
                Ok(step) if step.lambda >= 1.0 => {
                    match self.finish_arc(current, path, report, row, lambda) {
                        Some(start) => return ArcEnd::Reached { start },
                        None => Err(IncrementFailure::Diverged { iteration: 0 }),
                    }
                }
                other => other,
            };
            match step {
                Ok(step) => {
                    let n = self.sizing_iterations(&step.residuals);
                    report.note_converged(step.residuals, 0.0);
                    (lambda, previous) = (step.lambda, Some(step.delta));
                    let start = std::mem::replace(current, step.state);
                    if lambda > peak.0 {
                        peak = (lambda, Some((current.clone(), start)));
                    }
                    let ratio = (Analysis::TARGET_ITERATIONS as f64 / n).sqrt();
                    ds = (ds * ratio.clamp(1.0 / Analysis::GROWTH, Analysis::GROWTH)).min(whole);
                    let passed = lambda < 0.0 || max_abs(&current.displacement) > limit;
                    if passed && peak.0 > from {
                        *current = origin;
                        return ArcEnd::LimitPoint { peak: peak.0 };
                    }
                }
                Err(_) if ds / 2.0 < smallest * (1.0 - 1e-9) && peak.0 > from.max(lambda) => {
                    *current = origin;
                    return ArcEnd::LimitPoint { peak: peak.0 };
                }
                Err(failure) if ds / 2.0 < smallest * (1.0 - 1e-9) => {
                    return failed_from(current, peak, failure);
                }
                Err(_) => {
                    report.cutbacks += 1;
                    ds /= 2.0;
                }
            }
        }
        failed_from(current, peak, IncrementFailure::Diverged { iteration: 0 })
    }

    /// The last increment of an arc that passed the step's end: load-controlled from the
    /// converged `current` at `lambda` to `λ = 1`. Where it converged, `current` moves there
    /// and the state it left is returned.
    fn finish_arc(
        &mut self,
        current: &mut AnalysisState,
        path: &StepPath,
        report: &mut StepReport,
        row: usize,
        lambda: f64,
    ) -> Option<AnalysisState> {
        let attempt = self.solve_increment(current, &path.motion(0.0), &path.levels(1.0), None);
        let noted = attempt.as_ref().map(|(_, h)| h.as_slice());
        self.note_attempt(
            report,
            row,
            (lambda, 1.0),
            (STRATEGIES[row].name, true),
            noted,
        );
        match attempt {
            Ok((state, history)) => {
                report.note_converged(history, 0.0);
                Some(std::mem::replace(current, state))
            }
            Err(_) => None,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The correction keeps the increment on the sphere `‖ΔU‖ = Δs` and, of the two roots,
    /// takes the one whose new increment turns least from the old.
    #[test]
    fn the_constrained_step_stays_on_the_arc_and_turns_least() {
        let delta = [0.6, 0.8, 0.0];
        let (a, b) = ([0.05, -0.1, 0.02], [0.3, 0.1, -0.2]);
        let (step, theta) = constrained_step(&delta, &a, &b, 1.0).unwrap();
        let new: Vec<f64> = delta.iter().zip(&step).map(|(d, s)| d + s).collect();
        assert!((dot(&new, &new).sqrt() - 1.0).abs() < 1e-12);
        for (k, s) in step.iter().enumerate() {
            assert!((s - (a[k] + theta * b[k])).abs() < 1e-15);
        }
        // The other root of the same quadratic turns further (its new increment points away).
        let da: Vec<f64> = delta.iter().zip(&a).map(|(d, a)| d + a).collect();
        let other = -2.0 * dot(&da, &b) / dot(&b, &b) - theta;
        let far: Vec<f64> = (0..3).map(|k| da[k] + other * b[k]).collect();
        assert!((dot(&far, &far).sqrt() - 1.0).abs() < 1e-12);
        assert!(dot(&new, &delta) > dot(&far, &delta));
        // No real root: an arc the linearized path cannot reach.
        assert!(constrained_step(&[0.0; 3], &[2.0, 0.0, 0.0], &[0.0, 1e-3, 0.0], 1.0).is_none());
    }
}
