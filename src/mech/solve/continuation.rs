//! Pseudo-transient continuation (Ψtc), the one globalization of Newton's iteration
//! (`newton.rs`; docs/mechanics.md, "The nonlinear method").
//!
//! Kelley & Keyes, *Convergence analysis of pseudo-transient continuation*, SIAM J. Numer.
//! Anal. 35 (1998); Coffey, Kelley & Keyes, *Pseudotransient continuation and
//! differential-algebraic equations*, SIAM J. Sci. Comput. 25 (2003). Each iteration solves
//!
//! `(c k̄ M + K) ΔU = −R(U)`,   `U ← U + ΔU`,
//!
//! a backward-Euler step `δ = 1/c` of the pseudo-dynamics `M U̇ = −R(U)/k̄`: `M` is a lumped
//! pseudo-mass (each free DOF's node's tributary reference area over the mean, [`pseudo_mass`]),
//! `k̄` the mean magnitude of the free diagonal of the increment's first matrix (so that `c` is
//! dimensionless). `c` starts at 0: while full steps succeed the iteration is Newton's. A
//! correction along which the line search finds no step, or a singular matrix, shortens the
//! pseudo-time step [`Continuation::GROW`]-fold, the first to `c = 1/GROW` (a shift of a tenth of
//! the mean diagonal);
//! an accepted step scales `c` by switched evolution relaxation (SER:
//! `c_{k+1} = c_k ‖R_k‖/‖R_{k−1}‖`, at least halved), so that `c → 0` as the residual does and
//! the last iterations are Newton's again. Where `K` has no stiffness at all (an unstressed flat
//! film) the pseudo-mass holds the film until its own stress does; a contact changing status
//! raises `c` instead of cutting the step along a direction of the other status.
//!
//! **The converged answer is the equilibrium answer.** Only the iteration matrix carries the
//! pseudo-time term: convergence is tested on the true `R`, and in addition the pseudo-time
//! force of the last correction, `max |c k̄ M ΔU|`, must be within the residual tolerance.

use crate::mech::elements::triangle::ElementVector;
use crate::mech::solve::analysis::Analysis;
use crate::mech::solve::assembly::{Dof, System};

/// The pseudo-time controller of one increment.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Continuation {
    /// `c`, the inverse pseudo-time step (dimensionless: the shift is `c k̄ M`); 0: Newton.
    pub c: f64,
    /// `k̄`: mean magnitude of the free diagonal at the increment's first matrix (0 until known).
    pub scale: f64,
}

impl Continuation {
    /// Factor on `c` where the line search finds no step along a correction (from `1/GROW`).
    pub const GROW: f64 = 10.0;
    /// Largest factor on `c` after an accepted step (SER's ratio when the residual fell more).
    pub const SHRINK: f64 = 0.5;

    /// The controller at the start of an increment: Newton's iteration (`c = 0`).
    pub fn new() -> Self {
        Self { c: 0.0, scale: 0.0 }
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

    /// After a correction along which the line search found no step, or a singular matrix: a
    /// pseudo-time step [`Self::GROW`]-fold shorter, the first `c = 1/GROW`.
    pub fn reject(&mut self) {
        self.c = (Self::GROW * self.c).max(1.0 / Self::GROW);
    }

    /// After a full step that took `‖R‖₂` from `before` to `after`: SER, `c` scaled by their
    /// ratio, at least halved.
    pub fn accept(&mut self, before: f64, after: f64) {
        self.c *= (after / before).min(Self::SHRINK);
    }

    /// The work `ΔUᵀ c k̄ M ΔU` of the pseudo-time term over the correction `delta` (J) and its
    /// largest nodal force `max |c k̄ M ΔU|` (N), for the `c` the correction was solved with.
    pub fn work_and_force(&self, c: f64, delta: &[f64], mass: &[f64]) -> (f64, f64) {
        let k = c * self.scale;
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

    /// Newton's iteration until a correction is rejected; then SER: a full step scales `c` by
    /// the residual's ratio, at least halving it; a rejection makes it `GROW` times larger, from
    /// `1/GROW`.
    #[test]
    fn ser_follows_the_residual_and_a_rejection_shortens_the_pseudo_time_step() {
        const START: f64 = 0.1;
        let mut p = Continuation::new();
        p.accept(1.0, 5.0);
        assert_eq!(p.c, 0.0, "full steps are Newton's");
        p.reject();
        assert_eq!(p.c, START);
        p.accept(1.0, 0.9);
        assert_eq!(p.c, 0.5 * START);
        p.accept(1.0, 0.01);
        assert!((p.c - 0.01 * 0.5 * START).abs() < 1e-18);
        p.reject();
        assert_eq!(p.c, START);
        p.reject();
        assert_eq!(p.c, Continuation::GROW * START);
    }

    /// The shift is `c k̄ m_i` on each diagonal slot, `k̄` the mean |diagonal| of the first
    /// matrix it sees (a zero diagonal, the slack direction, counts in the mean).
    #[test]
    fn the_shift_is_the_pseudo_mass_times_c_and_the_mean_diagonal() {
        let mut p = Continuation { c: 0.1, scale: 0.0 };
        let mut values = vec![4.0, 9.0, -2.0, 0.0];
        p.shift(&mut values, &[0, 2, 3], &[1.0, 2.0, 0.5]);
        assert_eq!(p.scale, 2.0);
        assert_eq!(values, vec![4.0 + 0.2, 9.0, -2.0 + 0.4, 0.1]);
        let (work, force) = p.work_and_force(0.1, &[1.0, -2.0], &[1.0, 0.5]);
        assert!((work - (0.2 + 0.4)).abs() < 1e-15);
        assert!((force - 0.2).abs() < 1e-15);
    }
}
