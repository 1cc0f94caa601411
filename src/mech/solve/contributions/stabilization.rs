//! Viscous stabilization (the rows of the strategy table after the first, `increments.rs`): a
//! damping force against the velocity of each free DOF in the step's pseudo-time, for the steps
//! whose equilibrium is not unique.
//!
//! Abaqus' automatic stabilization (`*STATIC, STABILIZE`, Abaqus Analysis User's Guide §7.1.1
//! "Automatic stabilization of unstable problems"): viscous forces `F_v = c M* v` with an
//! artificial mass `M*` and the velocity `v = ΔU/Δλ` over the increment's share `Δλ` of the
//! step, added to the residual and the Newton matrix. Here, per free equation `i`:
//!
//! `F_v,i = c k̄ m_i (U_i − U_i,start)/Δλ`,   `∂F_v,i/∂U_i = c k̄ m_i/Δλ`,
//!
//! `m_i` the pseudo-mass of [`pseudo_mass`](crate::mech::solve::continuation::pseudo_mass), `k̄`
//! the mean magnitude of the free diagonal of the step's first stabilized matrix (so that `c` is
//! dimensionless), `U_start` the increment's converged start. Its work over an increment,
//! `F_v·ΔU = c k̄ Σ m_i ΔU_i²/Δλ`, is what the damping took out (Abaqus' ALLSD): summed over the
//! step it is judged against the strain energy (`report.rs`), and the last increment's is the
//! work of the force the converged answer still carries.

use super::{Contribution, Evaluation};
use crate::mech::solve::assembly::{Dof, System};
use crate::mech::solve::state::AnalysisState;

/// The viscous stabilization of the current step ([module doc](self)).
#[derive(Clone, Debug)]
pub struct ViscousStabilization {
    /// `c`: the damping per unit pseudo-time, relative to the mean stiffness; 0: off.
    pub coefficient: f64,
    /// `Δλ`, the increment's share of the step.
    pseudo_time: f64,
    /// `k̄` (N/m), learned from the step's first Newton matrix it is added to (0 until then).
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
            pseudo_time: 1.0,
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

    /// A new step: `k̄` is learned again from its first stabilized matrix.
    pub fn start_step(&mut self) {
        self.scale = 0.0;
    }

    /// The damping `coefficient` (0: off) over an increment of `pseudo_time` (its share of the
    /// step, > 0).
    pub fn set(&mut self, coefficient: f64, pseudo_time: f64) {
        self.coefficient = coefficient;
        self.pseudo_time = pseudo_time.max(f64::MIN_POSITIVE);
    }

    /// The damping force per metre of motion of a unit pseudo-mass, `c k̄/Δλ` (N/m).
    fn stiffness(&self) -> f64 {
        self.coefficient * self.scale / self.pseudo_time
    }

    /// The work `c k̄ Σ m_i ΔU_i²/Δλ` (J) of the damping force over the increment from its start
    /// to `u`.
    pub fn work(&self, system: &System, u: &[f64]) -> f64 {
        let k = self.stiffness();
        let mut work = 0.0;
        for (i, d) in system.dofs.iter().enumerate() {
            if let Dof::Free(eq) = d {
                let du = u[i] - self.start.get(i).copied().unwrap_or(u[i]);
                work += k * self.mass[*eq] * du * du;
            }
        }
        work
    }
}

impl ViscousStabilization {
    /// The largest magnitude of the damping force `c k̄ m_i (U_i − U_i,start)/Δλ` (N) at `u`:
    /// the undamped residual of a state that balances the damped one.
    pub fn force_inf(&self, system: &System, u: &[f64]) -> f64 {
        let k = self.stiffness();
        let mut largest = 0.0_f64;
        for (i, d) in system.dofs.iter().enumerate() {
            if let Dof::Free(eq) = d {
                let du = u[i] - self.start.get(i).copied().unwrap_or(u[i]);
                largest = largest.max((k * self.mass[*eq] * du).abs());
            }
        }
        largest
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
            let k = self.stiffness();
            for (&d, m) in self.diagonal.iter().zip(&self.mass) {
                values[d] += k * m;
            }
        }
        let k = self.stiffness();
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
    /// adds (`c k̄ m_i/Δλ` on the equation's own DOF, nothing elsewhere), `k̄` is the mean free
    /// diagonal it found, and its work is the closed form of the module doc.
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

        let (c, dt) = (1e-3, 0.25);
        s.set(c, dt);
        let mut v = base.clone();
        let mut r0 = vec![0.0; dofs];
        s.add(&at(system, &u, &levels), &mut r0, Some(&mut v));
        let mean = diagonal.iter().map(|&d| base[d]).sum::<f64>() / diagonal.len() as f64;
        assert_eq!(s.scale, mean);
        let mean = mean / dt;
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
        // Work c k̄ Σ m ΔU²/Δλ: the force times the motion.
        let work = s.work(system, &u);
        let mut w = 0.0;
        for (i, d) in system.dofs.iter().enumerate() {
            if let Dof::Free(eq) = *d {
                let du = u[i] - start.displacement[i];
                w += c * mean * s.mass[eq] * du * du;
            }
        }
        assert!((work - w).abs() <= 1e-12 * w && w > 0.0, "{work} vs {w}");
    }
}
