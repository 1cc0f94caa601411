//! Backtracking line search with a watchdog.

use crate::mech::elements::gap::{GapStatus, IterationMatrix};
use crate::mech::elements::load::LoadLevels;
use crate::mech::solve::analysis::Analysis;
use crate::mech::solve::assembly::Dof;

impl Analysis {
    /// Applies the Newton correction held in `work.rhs` to `u`, scaled by a backtracking line
    /// search on `φ(α) = ½‖R_free(u + αΔ)‖₂²` (the full step when line search is off). Returns
    /// the scale used, whether the workspace now holds the residual and Newton matrix at the
    /// new `u` (assembled for `next_iteration`), and whether the step decreased `φ` enough.
    ///
    /// Backtracking (Dennis & Schnabel, *Numerical Methods for Unconstrained Optimization*,
    /// §6.3.2): accept the first `α` with `φ(α) ≤ (1 − 2·10⁻⁴ α) φ(0)` (Armijo, with
    /// `φ'(0) = −‖R‖²` for a Newton direction); otherwise the next trial is the minimum of the
    /// parabola through `φ(0)`, `φ'(0)`, `φ(α)`, kept within `[α/10, α/2]`. A gap that opens or
    /// closes makes `R` only piecewise smooth: a closing penalty gap can raise `φ(1)` by orders of
    /// magnitude while the equilibrium lies at `α ≈ 10⁻³`, which the interpolation reaches in a
    /// few trials where plain halving would need ten. When no trial decreases `φ`, the best one
    /// is taken (with `α ≥ 1/8` for the Ju–Rowlands matrix); Newton continues from there and a
    /// cycle is caught by the stall test.
    pub(crate) fn line_search(
        &mut self,
        u: &mut [f64],
        levels: &LoadLevels,
        next_iteration: usize,
        watch: &mut Watchdog,
    ) -> (f64, bool, bool) {
        let apply = |u: &mut [f64], dofs: &[Dof], delta: &[f64], scale: f64| {
            for (i, d) in dofs.iter().enumerate() {
                if let Dof::Free(eq) = d {
                    u[i] += scale * delta[*eq];
                }
            }
        };
        let delta = std::mem::take(&mut self.work.rhs);
        if !self.settings.line_search {
            apply(u, &self.system.dofs, &delta, 1.0);
            self.work.rhs = delta;
            return (1.0, false, true);
        }
        let phi0 = 0.5 * self.free_norm2().powi(2);
        let consistent = self.settings.iteration_matrix == IterationMatrix::Consistent;
        // The contact statuses at an iterate (`self.parts.statuses()`): a full step that changes one crosses into
        // another branch of the piecewise law, where the watchdog's premise fails.
        if let Watchdog::Watching {
            start,
            phi,
            left,
            status,
        } = watch
        {
            // Full Newton steps while the excursion lasts; back to its start if it fails.
            apply(u, &self.system.dofs, &delta, 1.0);
            self.assemble_at(u, levels, Some(next_iteration));
            let now = 0.5 * self.free_norm2().powi(2);
            self.work.rhs = delta;
            let same = *status == self.parts.statuses();
            if same && now <= (1.0 - 2e-4) * *phi {
                // It paid: the next full step that raises the residual may be kept again.
                *watch = Watchdog::Ready;
            } else if same && now.is_finite() && *left > 1 {
                *left -= 1;
            } else {
                u.copy_from_slice(start);
                self.assemble_at(u, levels, Some(next_iteration));
                *watch = Watchdog::Used;
                // No correction measured: the restored iterate cannot pass for converged.
                return (f64::INFINITY, true, true);
            }
            return (1.0, true, true);
        }
        let (mut best, mut best_phi, mut applied) = (1.0, f64::INFINITY, 0.0);
        let mut scale: f64 = 1.0;
        let before = matches!(watch, Watchdog::Ready).then(|| self.parts.statuses());
        for trial in 0..Self::LINE_SEARCH_TRIALS {
            apply(u, &self.system.dofs, &delta, scale - applied);
            applied = scale;
            // The full step is usually accepted: assemble its tangent too, for the next iteration.
            let tangent = (trial == 0).then_some(next_iteration);
            self.assemble_at(u, levels, tangent);
            let phi = 0.5 * self.free_norm2().powi(2);
            if sufficient_decrease(phi, phi0, scale) {
                self.work.rhs = delta;
                return (scale, trial == 0, true);
            }
            // Only with room to spare: a failed excursion must not eat the iteration limit.
            if trial == 0
                && consistent
                && phi.is_finite()
                && next_iteration + 2 * Self::WATCHDOG_STEPS <= self.settings.max_iterations
                && before.as_ref().is_some_and(|b| *b == self.parts.statuses())
            {
                // A full Newton step that raises the residual is often the way to a
                // solution that backtracking crawls to (a flat film taking its first load:
                // 18 damped iterations against 6 full ones): keep it for a few iterations and
                // return to this point if the residual has not fallen below it by then.
                let mut start = u.to_vec();
                apply(&mut start, &self.system.dofs, &delta, -1.0);
                *watch = Watchdog::Watching {
                    start,
                    phi: phi0,
                    left: Self::WATCHDOG_STEPS,
                    status: self.parts.statuses(),
                };
                self.work.rhs = delta;
                return (1.0, true, true);
            }
            if phi < best_phi && (scale >= Self::SMALLEST_FALLBACK || consistent) {
                (best, best_phi) = (scale, phi);
            }
            scale = next_trial(phi0, phi, scale);
        }
        apply(u, &self.system.dofs, &delta, best - applied);
        self.work.rhs = delta;
        (best, false, false)
    }

    /// Trials of the line search before it takes the best one.
    pub(crate) const LINE_SEARCH_TRIALS: usize = 8;
    /// Full Newton steps the watchdog allows beyond the one that raised the residual.
    pub(crate) const WATCHDOG_STEPS: usize = 6;
    /// Smallest scale the Ju–Rowlands iteration takes when no trial decreases `φ`: a tiny step
    /// would freeze it (its direction is not Newton's, it relies on moving on). With the
    /// consistent tangent the best trial is taken whatever its size: a full step that raised the
    /// residual by eight orders of magnitude was measured to wreck an increment that was one
    /// iteration from convergence.
    pub(crate) const SMALLEST_FALLBACK: f64 = 0.125;
}

/// The line search's watchdog (Chamberlain et al., 1982): a full Newton step that raised the
/// residual may be kept for a few more full steps; after an excursion that failed, the rest of
/// the increment backtracks monotonically.
pub(crate) enum Watchdog {
    /// May start an excursion (none yet in this increment, or the last one paid).
    Ready,
    /// Full steps since `start`, whose merit was `phi`; `left` of them remain while the
    /// contact statuses stay `status`.
    Watching {
        start: Vec<f64>,
        phi: f64,
        left: usize,
        status: Vec<GapStatus>,
    },
    /// An excursion failed: monotone backtracking for the rest of the increment.
    Used,
}

/// Armijo's condition for a Newton direction (`φ'(0) = −2φ(0)`):
/// `φ(α) ≤ (1 − 2·10⁻⁴ α) φ(0)`.
fn sufficient_decrease(phi: f64, phi0: f64, scale: f64) -> bool {
    phi <= (1.0 - 2e-4 * scale) * phi0
}

/// The next trial after `φ(α0) = phi` failed: the minimum of the parabola
/// `q(α) = φ0 − 2φ0 α + (φ − φ0 + 2φ0 α0) α²/α0²` through `φ(0)`, `φ'(0)`, `φ(α0)`, clamped to
/// `[α0/10, α0/2]` (half the step when the parabola has no minimum).
fn next_trial(phi0: f64, phi: f64, scale: f64) -> f64 {
    let curvature = (phi - phi0 + 2.0 * phi0 * scale) / (scale * scale);
    let next = if curvature.is_finite() && curvature > 0.0 {
        phi0 / curvature
    } else {
        0.5 * scale
    };
    next.clamp(0.1 * scale, 0.5 * scale)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// φ(α) = φ0 (1 − α)² along an exact Newton direction of a linear problem: the parabola
    /// through φ(0), φ'(0) = −2φ0 and φ(α0) is φ itself, so one interpolation lands on α = 1
    /// (clamped to α0/2 when that is below it), from any failed trial.
    #[test]
    fn interpolation_finds_the_minimum_of_a_quadratic_merit() {
        let phi0 = 3.0;
        let phi = |a: f64| phi0 * (1.0 - a).powi(2);
        // From a step four times too long: the minimum α = 1 lies inside [0.4, 2].
        assert!((next_trial(phi0, phi(4.0), 4.0) - 1.0).abs() < 1e-12);
        // From α0 = 1.5 the minimum is beyond α0/2 = 0.75 → clamped there.
        assert_eq!(next_trial(phi0, phi(1.5), 1.5), 0.75);
    }

    /// A closing penalty gap: φ(1) is orders of magnitude above φ(0), and the minimum is near
    /// 0: the next trial is the smallest allowed, a tenth of the step, not a half.
    #[test]
    fn a_huge_merit_at_the_full_step_shrinks_the_trial_tenfold() {
        assert_eq!(next_trial(1.0, 1e8, 1.0), 0.1);
        // A NaN merit (a step into an inverted element) halves the step.
        assert_eq!(next_trial(1.0, f64::NAN, 1.0), 0.5);
    }

    /// Armijo: a step that lowers φ by less than 2·10⁻⁴ α of φ(0) is refused, one that lowers it
    /// more is taken; NaN never passes.
    #[test]
    fn sufficient_decrease_needs_more_than_a_fraction_of_the_slope() {
        assert!(sufficient_decrease(0.5, 1.0, 1.0));
        assert!(!sufficient_decrease(1.0 - 1e-4, 1.0, 1.0));
        assert!(sufficient_decrease(1.0 - 3e-4, 1.0, 1.0));
        assert!(!sufficient_decrease(f64::NAN, 1.0, 1.0));
    }
}
