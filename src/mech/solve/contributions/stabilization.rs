//! Viscous stabilization of a step (issue 19): a damping force against the motion of each free
//! DOF since the start of its increment, for the steps whose equilibrium is not unique.
//!
//! Abaqus' automatic stabilization (`*STATIC, STABILIZE`, Abaqus Analysis User's Guide §7.1.1
//! "Automatic stabilization of unstable problems"): viscous forces `F_v = c M* v` with an
//! artificial mass `M*` and the velocity `v = ΔU/Δt` of the increment, added to the residual
//! and the Newton matrix, the damping chosen small against the model's stiffness and the
//! dissipated energy reported against the strain energy. Here, per free equation `i`:
//!
//! `F_v,i = c k̄ m_i (U_i − U_i,start)`,   `∂F_v,i/∂U_i = c k̄ m_i`,
//!
//! `m_i` the pseudo-mass of [`pseudo_mass`](crate::mech::solve::continuation::pseudo_mass) (the node's tributary area over the mean), `k̄` the
//! mean magnitude of the free diagonal of the Newton matrix where the stabilization starts (so
//! that `c` is dimensionless: the force is `c` times what the mean stiffness gives for the same
//! motion), `U_start` the converged state the increment starts from. A film with no stiffness in
//! some direction (a slack film, a wrinkled free edge, unloaded across its wrinkles) stays where it
//! was in that direction instead of having no unique position; everywhere else the force is
//! `c` of the elastic one. Unlike the pseudo-transient continuation, the force is in the
//! residual: the converged answer carries it, and the work it did, `½ c k̄ Σ m_i ΔU_i²` per
//! increment, is reported with the step ([`crate::mech::solve::report::StepReport`]) against the
//! strain energy and the bound [`crate::mech::solve::report::STABILIZATION_BOUND`].
//!
//! Off (`c = 0`) it adds nothing, so that every step that does not need it computes bit for bit
//! as without it; [`Analysis::step_to_motion`](crate::mech::solve::analysis::Analysis) turns it
//! on for the rest of a step whose increment neither plain Newton nor the continuation converge.

use super::{Contribution, Evaluation};
use crate::mech::solve::assembly::{Dof, System};
use crate::mech::solve::state::AnalysisState;

/// The viscous stabilization of the current step ([module doc](self)).
#[derive(Clone, Debug)]
pub struct ViscousStabilization {
    /// `c`: the damping relative to the mean stiffness; 0: off.
    pub coefficient: f64,
    /// `k̄` (N/m), learned from the first Newton matrix it is added to (0 until then).
    pub scale: f64,
    /// `m_i` per free equation.
    mass: Vec<f64>,
    /// The slot of each free equation's diagonal entry in the value array.
    diagonal: Vec<usize>,
    /// The displacements at the start of the increment (all DOFs).
    start: Vec<f64>,
}

impl ViscousStabilization {
    /// Off (`diagonal`: each free equation's diagonal slot; `mass`: its pseudo-mass,
    /// [`pseudo_mass`](crate::mech::solve::continuation::pseudo_mass)).
    pub fn new(diagonal: Vec<usize>, mass: Vec<f64>) -> Self {
        Self {
            coefficient: 0.0,
            scale: 0.0,
            mass,
            diagonal,
            start: Vec::new(),
        }
    }

    /// Whether it acts.
    pub fn is_on(&self) -> bool {
        self.coefficient > 0.0
    }

    /// Turns it on with the damping `coefficient`; `k̄` is learned again from the next matrix.
    pub fn switch_on(&mut self, coefficient: f64) {
        (self.coefficient, self.scale) = (coefficient, 0.0);
    }

    /// Turns it on again with the damping `coefficient` and the `scale` `k̄` it had (the release
    /// at a step's end, `increments.rs`).
    pub fn resume(&mut self, coefficient: f64, scale: f64) {
        (self.coefficient, self.scale) = (coefficient, scale);
    }

    /// A tenth of the damping for the next increments (not below [`Self::SMALLEST`]), `k̄` kept.
    pub fn soften(&mut self) {
        self.coefficient = (0.1 * self.coefficient).max(Self::SMALLEST);
    }

    /// The smallest damping [`Self::soften`] goes to.
    pub const SMALLEST: f64 = 1e-7;

    /// Turns it off (the end of a step).
    pub fn switch_off(&mut self) {
        (self.coefficient, self.scale) = (0.0, 0.0);
    }

    /// The work `½ c k̄ Σ m_i ΔU_i²` (J) of the damping force over the increment from its start to
    /// `u`, and the largest damping force `max c k̄ m_i |ΔU_i|` (N) left at `u`.
    pub fn work_and_force(&self, system: &System, u: &[f64]) -> (f64, f64) {
        let k = self.coefficient * self.scale;
        let (mut work, mut force) = (0.0, 0.0_f64);
        for (i, d) in system.dofs.iter().enumerate() {
            if let Dof::Free(eq) = d {
                let du = u[i] - self.start.get(i).copied().unwrap_or(u[i]);
                work += 0.5 * k * self.mass[*eq] * du * du;
                force = force.max(k * self.mass[*eq] * du.abs());
            }
        }
        (work, force)
    }
}

impl Contribution for ViscousStabilization {
    fn restore(&mut self, start: &AnalysisState) {
        self.start.clone_from(&start.displacement);
    }

    fn add(&mut self, at: &Evaluation<'_>, residual: &mut [f64], values: Option<&mut [f64]>) {
        if !self.is_on() {
            return;
        }
        if let Some(values) = values {
            // Last in the assembly order: `values` holds every other contribution's matrix.
            if self.scale == 0.0 {
                self.scale = self.diagonal.iter().map(|&d| values[d].abs()).sum::<f64>()
                    / self.diagonal.len().max(1) as f64;
            }
            for (&d, m) in self.diagonal.iter().zip(&self.mass) {
                values[d] += self.coefficient * self.scale * m;
            }
        }
        let k = self.coefficient * self.scale;
        for (i, d) in at.system.dofs.iter().enumerate() {
            if let Dof::Free(eq) = d {
                residual[i] += k * self.mass[*eq] * (at.u[i] - self.start[i]);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mech::elements::load::LoadLevels;
    use crate::mech::solve::analysis::{Analysis, diagonal_slots};
    use crate::mech::solve::continuation::pseudo_mass;
    use crate::mech::solve::settings::SolverSettings;
    use crate::specimens::ParallelArch;

    /// Off, it adds nothing; on, its residual's finite differences are exactly the diagonal it
    /// adds (`c k̄ m_i` on the equation's own DOF, nothing elsewhere), `k̄` is the mean free
    /// diagonal it found, and its work and force are the closed forms of the module doc.
    #[test]
    fn the_damping_force_is_consistent_with_its_matrix_and_off_adds_nothing() {
        let a = Analysis::new(
            ParallelArch::default().model().unwrap(),
            SolverSettings::default(),
        )
        .unwrap();
        let system = &a.system;
        let diagonal = diagonal_slots(system);
        let mut s = ViscousStabilization::new(diagonal.clone(), pseudo_mass(system));
        let dofs = system.dofs.len();
        let wave = |k: usize, a: f64| (0..dofs).map(|i| a * ((i * k) as f64).sin()).collect();
        let start = AnalysisState {
            displacement: wave(7, 1e-3),
            ..a.state().clone()
        };
        s.restore(&start);
        let u: Vec<f64> = wave(3, 2e-3);
        let levels = a.state().loads.clone();
        fn at<'a>(system: &'a System, u: &'a [f64], levels: &'a LoadLevels) -> Evaluation<'a> {
            Evaluation {
                system,
                u,
                levels,
                iteration: Some(1),
                matrix: SolverSettings::default().iteration_matrix,
            }
        }
        let nnz = system.pattern().row_idx().len();
        let base: Vec<f64> = (0..nnz).map(|k| 1.0 + (k % 5) as f64).collect();
        let (mut r, mut v) = (vec![0.0; dofs], base.clone());
        s.add(&at(system, &u, &levels), &mut r, Some(&mut v));
        assert!(r.iter().all(|&x| x == 0.0) && v == base, "off adds nothing");

        let c = 1e-3;
        s.switch_on(c);
        let mut v = base.clone();
        let mut r0 = vec![0.0; dofs];
        s.add(&at(system, &u, &levels), &mut r0, Some(&mut v));
        let mean = diagonal.iter().map(|&d| base[d]).sum::<f64>() / diagonal.len() as f64;
        assert_eq!(s.scale, mean);
        let h = 1e-7;
        let mut checked = 0;
        for (i, d) in system.dofs.iter().enumerate() {
            let Dof::Free(eq) = *d else { continue };
            let (mut up, mut um) = (u.clone(), u.clone());
            up[i] += h;
            um[i] -= h;
            let (mut rp, mut rm) = (vec![0.0; dofs], vec![0.0; dofs]);
            s.add(&at(system, &up, &levels), &mut rp, None);
            s.add(&at(system, &um, &levels), &mut rm, None);
            for j in 0..dofs {
                let fd = (rp[j] - rm[j]) / (2.0 * h);
                let added = if j == i {
                    v[diagonal[eq]] - base[diagonal[eq]]
                } else {
                    0.0
                };
                assert!(
                    (fd - added).abs() <= 1e-6 * c * mean,
                    "({j}, {i}): {fd} vs {added}"
                );
            }
            checked += 1;
            if checked == 40 {
                break;
            }
        }
        assert_eq!(checked, 40);
        // Work ½ c k̄ Σ m ΔU², force max c k̄ m |ΔU|.
        let (work, force) = s.work_and_force(system, &u);
        let (mut w, mut f) = (0.0, 0.0_f64);
        for (i, d) in system.dofs.iter().enumerate() {
            if let Dof::Free(eq) = *d {
                let du = u[i] - start.displacement[i];
                w += 0.5 * c * mean * s.mass[eq] * du * du;
                f = f.max(c * mean * s.mass[eq] * du.abs());
            }
        }
        assert!((work - w).abs() <= 1e-12 * w && w > 0.0, "{work} vs {w}");
        assert!((force - f).abs() <= 1e-12 * f && f > 0.0, "{force} vs {f}");
    }
}
