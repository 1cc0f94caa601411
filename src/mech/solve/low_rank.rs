//! The chambers' pneumatic stiffness in the Newton correction (issue 43): the matrix is the
//! sparse `S` plus one rank-one term `a g gᵀ` per sealed chamber (`contributions/chambers.rs`),
//! solved by the Sherman–Morrison–Woodbury identity from `S`'s held factor (Golub & Van Loan,
//! *Matrix Computations*, §2.1.4): `x = y − Z (A⁻¹ + Gᵀ Z)⁻¹ Gᵀ y` with `y = S⁻¹ b`,
//! `Z = S⁻¹ G`, `A = diag(a)`. No dense row enters the sparse factorization.

use nalgebra::{DMatrix, DVector};

use crate::mech::solve::analysis::Analysis;
use crate::mech::solve::contributions::ChamberState;
use crate::mech::solve::linear::FactorizationError;

/// `Σ a_i b_i`.
fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

impl Analysis {
    /// Turns `rhs = S⁻¹ b` (the sparse matrix of the last assembly, factorized) into the
    /// solution with the chambers' rank-one terms added; nothing without a sealed chamber.
    pub(crate) fn add_low_rank(&mut self, rhs: &mut [f64]) -> Result<(), FactorizationError> {
        let terms: Vec<(f64, Vec<f64>)> = self
            .parts
            .chambers
            .low_rank()
            .iter()
            .filter(|(a, _)| *a > 0.0)
            .cloned()
            .collect();
        if terms.is_empty() {
            return Ok(());
        }
        let m = terms.len();
        let matrix = self.system.matrix(&self.work.values);
        let mut z = Vec::with_capacity(m);
        for (_, g) in &terms {
            let mut column = g.clone();
            self.linear.solve_held(matrix, &mut column)?;
            z.push(column);
        }
        let small = DMatrix::from_fn(m, m, |i, j| {
            dot(&terms[i].1, &z[j]) + if i == j { 1.0 / terms[i].0 } else { 0.0 }
        });
        let gy = DVector::from_fn(m, |i, _| dot(&terms[i].1, rhs));
        let w = small.lu().solve(&gy).ok_or_else(|| {
            FactorizationError("the chambers' pneumatic stiffness made the matrix singular".into())
        })?;
        for (j, column) in z.iter().enumerate() {
            for (r, zj) in rhs.iter_mut().zip(column) {
                *r -= w[j] * zj;
            }
        }
        Ok(())
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
