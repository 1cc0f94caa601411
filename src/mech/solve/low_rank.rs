//! The chambers' pneumatic stiffness in the Newton correction (issue 43): the matrix is the
//! sparse `S` plus `G A Gᵀ`, `G` the columns `g = ∂V/∂u` of the sealed chambers and
//! `A = −∂p/∂V` between them (`contributions/chambers.rs`: diagonal, one rank-one term per
//! chamber, unless an orifice couples two, unsymmetrically), solved by the
//! Sherman–Morrison–Woodbury identity from `S`'s held factor (Golub & Van Loan, *Matrix
//! Computations*, §2.1.4) in the form that needs no `A⁻¹`:
//! `x = y − Z A (I + Gᵀ Z A)⁻¹ Gᵀ y` with `y = S⁻¹ b`, `Z = S⁻¹ G`. No dense row enters the
//! sparse factorization.

use nalgebra::{DMatrix, DVector};

use crate::mech::solve::analysis::Analysis;
use crate::mech::solve::contributions::{ChamberState, LowRank};
use crate::mech::solve::linear::{FactorizationError, LinearSolver};

/// `Σ a_i b_i`.
fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

impl LowRank {
    /// Whether it adds nothing (no sealed chamber, or `A = 0`).
    pub fn is_empty(&self) -> bool {
        self.columns.is_empty() || self.matrix.iter().all(|&x| x == 0.0)
    }

    /// `Z = S⁻¹ G` (`S⁻ᵀ G` with `transpose`: an adjoint's), one solve per column with the
    /// factor `linear` holds for `matrix`.
    pub(crate) fn solved_columns(
        &self,
        linear: &mut LinearSolver,
        matrix: faer::sparse::SparseColMatRef<'_, usize, f64>,
        transpose: bool,
    ) -> Result<Vec<Vec<f64>>, FactorizationError> {
        let mut z = Vec::with_capacity(self.columns.len());
        for g in &self.columns {
            let mut column = g.clone();
            if transpose {
                linear.solve_held_transpose(matrix, &mut column)?;
            } else {
                linear.solve_held(matrix, &mut column)?;
            }
            z.push(column);
        }
        Ok(z)
    }

    /// Turns `rhs = S⁻¹ b` into `(S + G A Gᵀ)⁻¹ b` given `z = S⁻¹ G`; with `transpose`,
    /// `rhs = S⁻ᵀ b` into `(S + G A Gᵀ)⁻ᵀ b` given `z = S⁻ᵀ G` (the same identity with `Aᵀ`).
    pub(crate) fn correct(
        &self,
        z: &[Vec<f64>],
        rhs: &mut [f64],
        transpose: bool,
    ) -> Result<(), FactorizationError> {
        if self.is_empty() {
            return Ok(());
        }
        let (columns, m) = (&self.columns, self.columns.len());
        let a = if transpose {
            self.matrix.transpose()
        } else {
            self.matrix.clone()
        };
        let gz = DMatrix::from_fn(m, m, |i, j| dot(&columns[i], &z[j]));
        let small = DMatrix::identity(m, m) + gz * &a;
        let gy = DVector::from_fn(m, |i, _| dot(&columns[i], rhs));
        let t = small.lu().solve(&gy).ok_or_else(|| {
            FactorizationError("the chambers' pneumatic stiffness made the matrix singular".into())
        })?;
        let w = a * t;
        for (j, column) in z.iter().enumerate() {
            for (r, zj) in rhs.iter_mut().zip(column) {
                *r -= w[j] * zj;
            }
        }
        Ok(())
    }
}

impl Analysis {
    /// Turns `rhs = S⁻¹ b` (the sparse matrix of the last assembly, factorized) into the
    /// solution with the chambers' `G A Gᵀ` added; nothing without a sealed chamber.
    pub(crate) fn add_low_rank(&mut self, rhs: &mut [f64]) -> Result<(), FactorizationError> {
        let terms = self.parts.chambers.low_rank().clone();
        if terms.is_empty() {
            return Ok(());
        }
        let matrix = self.system.matrix(&self.work.values);
        let z = terms.solved_columns(&mut self.linear, matrix, false)?;
        terms.correct(&z, rhs, false)
    }

    /// Encloses the gas of every supplied chamber at its converged pressure and volume (the
    /// inflation unit's valve closes): from the next step on its pressure follows the gas law
    /// `(p + p_a) V^κ = C`. Err names a chamber that encloses no volume.
    pub fn seal_chambers(&mut self) -> Result<(), String> {
        self.set_chambers_sealed(&vec![true; self.state.chambers.len()])
    }

    /// Encloses the air of each chamber whose `sealed` is true and not yet enclosed (see
    /// [`Self::seal_chambers`]), and hands back to its supply each one whose `sealed` is false
    /// (the valve opens: the supply's pressure level applies from the next step on). Err names
    /// a chamber that encloses no volume, or a list of the wrong length.
    pub fn set_chambers_sealed(&mut self, sealed: &[bool]) -> Result<(), String> {
        if sealed.len() != self.state.chambers.len() {
            return Err(format!(
                "{} sealed flags for {} chambers",
                sealed.len(),
                self.state.chambers.len()
            ));
        }
        let mut chambers = self.state.chambers.clone();
        for (k, (c, &want)) in chambers.iter_mut().zip(sealed).enumerate() {
            *c = match (c.sealed, want) {
                (false, true) => self.parts.chambers.enclosed(k, c)?,
                (true, false) => ChamberState {
                    sealed: false,
                    constant: 0.0,
                    ..*c
                },
                _ => *c,
            };
        }
        self.state.chambers = chambers;
        Ok(())
    }
}
