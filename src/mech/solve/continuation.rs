//! Pseudo-transient continuation (Ψtc) for the increments plain Newton does not converge
//! (issue 19).
//!
//! Kelley & Keyes, *Convergence analysis of pseudo-transient continuation*, SIAM J. Numer.
//! Anal. 35 (1998); Coffey, Kelley & Keyes, *Pseudotransient continuation and
//! differential-algebraic equations*, SIAM J. Sci. Comput. 25 (2003). Each iteration solves
//!
//! `(c k̄ M + K) ΔU = −R(U)`,   `U ← U + ΔU`,
//!
//! a backward-Euler step of the pseudo-dynamics `M U̇ = −R(U)/(c k̄)`: `M` is a lumped
//! pseudo-mass (each free DOF's node's tributary reference area over the mean: the film's mass
//! pattern, [`pseudo_mass`]), `k̄` the mean magnitude of the free diagonal of the Newton matrix at
//! the increment's first iterate (so that `c` is dimensionless), and `c = 1/δ` the inverse
//! pseudo-time step. `c` follows switched evolution relaxation (SER, `δ_{k+1} = δ_k
//! ‖R_{k−1}‖/‖R_k‖`), with at least a halving per accepted step, so that it goes to zero as the
//! residual does and the last iterations are Newton's; a step that raises `‖R‖₂` more than
//! [`Continuation::REJECT`]-fold (a contact closing under a penalty, a slack film overshooting)
//! or meets a singular matrix is taken back with `c` ten times larger (a shorter pseudo-time
//! step). Where `K` has no stiffness at all (a flat unstressed film under its own weight) the
//! pseudo-mass holds the film until its own stress does.
//!
//! **The converged answer is the equilibrium answer.** Only the iteration matrix carries the
//! pseudo-time term, never the residual: convergence is tested on the true `R` with the plain
//! Newton tolerances, and in addition the artificial force of the last correction,
//! `max |c k̄ M ΔU|`, must be within the residual tolerance. The artificial energy left at the
//! end of an increment is the work of that last correction, `ΔUᵀ c k̄ M ΔU`; it is reported per
//! step ([`crate::mech::solve::report::StepReport::stabilization_energy`]) with its ratio to the
//! film's elastic strain energy, and a ratio above
//! [`crate::mech::solve::report::STABILIZATION_BOUND`] is reported as a warning, not as plain
//! success. The work taken out over all the iterations (what Abaqus reports as the dissipated
//! stabilization energy, ALLSD) is reported beside it.
//!
//! Contact status changes happen inside the continuation: a change that raises the residual
//! raises `c`, which shortens the next pseudo-time step, instead of a line search that would cut
//! the step along a direction computed in the other status (the open ↔ closed chatter).
//!
//! Used by [`Analysis::step_to_motion`](crate::mech::solve::analysis::Analysis): an increment is
//! first tried by plain Newton (quadratic, no cost on easy increments); when that fails, the same
//! increment is solved by continuation before it is halved
//! ([`crate::mech::solve::settings::SolverSettings::continuation`]).

use crate::mech::elements::triangle::ElementVector;
use crate::mech::solve::analysis::Analysis;
use crate::mech::solve::assembly::{Dof, System};

/// The pseudo-time controller of one increment.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Continuation {
    /// `c`, the inverse pseudo-time step (dimensionless: the shift is `c k̄ M`).
    pub c: f64,
    /// `k̄`: mean magnitude of the free diagonal at the increment's first iterate (0 until known).
    pub scale: f64,
}

/// What the controller makes of a trial step.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum Verdict {
    /// Keep the step; `c` has been updated.
    Accept,
    /// Take the step back; `c` has been raised.
    Reject,
}

impl Continuation {
    /// First `c`: the shift is a tenth of the mean diagonal.
    pub const START: f64 = 0.1;
    /// Factor on `c` after a rejected step or a singular matrix.
    pub const GROW: f64 = 10.0;
    /// Smallest `c` after a rejection (from a `c` that had reached 0).
    pub const FLOOR: f64 = 1e-6;
    /// Below this `c` is dropped: plain Newton steps.
    pub const END: f64 = 1e-8;
    /// Largest factor on `c` after an accepted step (SER's ratio when the residual fell more).
    pub const SHRINK: f64 = 0.5;
    /// A step that raises `‖R‖₂` by more than this factor is rejected.
    pub const REJECT: f64 = 10.0;
    /// Iterations without progress before a continuation increment is declared stalled.
    pub const PATIENCE: usize = 30;

    /// The controller at the start of an increment.
    pub fn new() -> Self {
        Self {
            c: Self::START,
            scale: 0.0,
        }
    }

    /// Adds the shift `c k̄ M` to the diagonal slots of `values` (learning `k̄` from them at
    /// the first call).
    pub fn shift(&mut self, values: &mut [f64], diagonal: &[usize], mass: &[f64]) {
        if self.scale == 0.0 {
            self.scale = diagonal.iter().map(|&d| values[d].abs()).sum::<f64>()
                / diagonal.len().max(1) as f64;
        }
        if self.c > 0.0 {
            for (&d, m) in diagonal.iter().zip(mass) {
                values[d] += self.c * self.scale * m;
            }
        }
    }

    /// After a singular matrix: a shorter pseudo-time step.
    pub fn singular(&mut self) {
        self.c = (Self::GROW * self.c).max(Self::FLOOR);
    }

    /// Judges a step that took `‖R‖₂` from `before` to `after` and updates `c` (SER on
    /// acceptance, growth on rejection).
    pub fn judge(&mut self, before: f64, after: f64) -> Verdict {
        if !after.is_finite() || after > Self::REJECT * before {
            self.singular();
            return Verdict::Reject;
        }
        self.c *= (after / before).min(Self::SHRINK);
        if self.c < Self::END {
            self.c = 0.0;
        }
        Verdict::Accept
    }

    /// The work `ΔUᵀ c k̄ M ΔU` of the pseudo-time term over the correction `delta` (J) and its
    /// largest nodal force `max |c k̄ M ΔU|` (N), for the `c` the correction was solved with.
    pub fn work_and_force(c: f64, scale: f64, delta: &[f64], mass: &[f64]) -> (f64, f64) {
        let k = c * scale;
        delta
            .iter()
            .zip(mass)
            .fold((0.0, 0.0_f64), |(w, f), (dx, m)| {
                (w + k * m * dx * dx, f.max(k * m * dx.abs()))
            })
    }
}

/// Pseudo-mass of each free equation: the tributary reference area of its node (a third of its
/// triangles') over the mean of the free equations' (1 for a node without triangles).
pub(crate) fn pseudo_mass(system: &System) -> Vec<f64> {
    let mut area = vec![0.0; system.dofs.len() / 3];
    for (nodes, tri) in &system.triangles {
        for &n in nodes {
            area[n] += tri.area() / 3.0;
        }
    }
    let mut mass = vec![1.0; system.free_count];
    for (i, d) in system.dofs.iter().enumerate() {
        if let Dof::Free(eq) = d {
            mass[*eq] = area[i / 3];
        }
    }
    let mean = mass.iter().sum::<f64>() / mass.len().max(1) as f64;
    mass.iter()
        .map(|&m| if m > 0.0 && mean > 0.0 { m / mean } else { 1.0 })
        .collect()
}

impl Analysis {
    /// Elastic strain energy of the film in the converged state (J): `Σ A t ½ (S − S0)·E` over
    /// the triangles (the prestress's share left out, so that it is never negative for the
    /// linear film; cables and contacts not included).
    pub fn strain_energy(&self) -> f64 {
        self.strain_energy_at(&self.state.displacement)
    }

    /// [`Self::strain_energy`] at the displacements `u` (J).
    pub(crate) fn strain_energy_at(&self, u: &[f64]) -> f64 {
        let m = &self.system.material;
        self.system
            .triangles
            .iter()
            .map(|(nodes, tri)| {
                let ue = ElementVector::from_fn(|i, _| u[3 * nodes[i / 3] + i % 3]);
                let e = tri.stress_state(m, &ue);
                let elastic: f64 = (0..3)
                    .map(|k| (e.stress[k] - m.prestress[k]) * e.strain[k])
                    .sum();
                0.5 * tri.area() * tri.thickness(m) * elastic
            })
            .sum()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// SER: an accepted step scales `c` by the residual's ratio, at least halving it, and
    /// drops it below `END`; a step that raises the residual past `REJECT` (or is not finite)
    /// is rejected with `c` ten times larger, from `FLOOR` when it had reached 0.
    #[test]
    fn ser_follows_the_residual_and_a_rejection_shortens_the_pseudo_time_step() {
        let mut p = Continuation::new();
        assert_eq!(p.judge(1.0, 0.9), Verdict::Accept);
        assert_eq!(p.c, 0.5 * Continuation::START);
        assert_eq!(p.judge(1.0, 0.01), Verdict::Accept);
        assert!((p.c - 0.01 * 0.5 * Continuation::START).abs() < 1e-18);
        // a modest rise is kept, and still halves c (no growth without rejection)
        assert_eq!(p.judge(1.0, 5.0), Verdict::Accept);
        let before = p.c;
        assert_eq!(p.judge(1.0, 11.0), Verdict::Reject);
        assert_eq!(p.c, 10.0 * before);
        assert_eq!(p.judge(1.0, f64::NAN), Verdict::Reject);
        p.c = 1e-8;
        assert_eq!(p.judge(1.0, 0.5), Verdict::Accept);
        assert_eq!(p.c, 0.0);
        assert_eq!(p.judge(1.0, 100.0), Verdict::Reject);
        assert_eq!(p.c, Continuation::FLOOR);
    }

    /// The shift is `c k̄ m_i` on each diagonal slot, `k̄` the mean |diagonal| of the first
    /// matrix it sees (a zero diagonal, the slack direction, counts in the mean).
    #[test]
    fn the_shift_is_the_pseudo_mass_times_c_and_the_mean_diagonal() {
        let mut p = Continuation::new();
        let mut values = vec![4.0, 9.0, -2.0, 0.0];
        p.shift(&mut values, &[0, 2, 3], &[1.0, 2.0, 0.5]);
        assert_eq!(p.scale, 2.0);
        assert_eq!(values, vec![4.0 + 0.2, 9.0, -2.0 + 0.4, 0.1]);
        let (work, force) = Continuation::work_and_force(0.1, 2.0, &[1.0, -2.0], &[1.0, 0.5]);
        assert!((work - (0.2 + 0.4)).abs() < 1e-15);
        assert!((force - 0.2).abs() < 1e-15);
    }
}
