//! Form finding: the shape in which the film carries a prescribed prestress in equilibrium with
//! its fixed boundary (issue 46, step 1).
//!
//! | file | what |
//! |---|---|
//! | [`force_density`] | a first shape by the force density method (Schek 1974, eq. 8) |
//! | [`contact`] | the updated reference strategy with `λ > 0` against curved supports (each step by the analysis, `μ = 0`) |
//! | [`update_reference`] | the updated reference strategy (Bletzinger & Ramm 1999) with `λ = 0` |
//! | `sparse` | the sparse Cholesky solve both use |
//!
//! What is held: every DOF a support fixes, the normal DOF of a symmetry plane, the prescribed
//! components of a boundary group (at the positions the model gives them), and every node that
//! no triangle or cable touches. Gaps are not taken into account; curved supports are, by
//! [`contact`] (frictionless unilateral constraints).

pub mod contact;
pub mod force_density;
mod sparse;
pub mod update_reference;

pub use sparse::solve_spd;

use crate::mech::model::Model;
use crate::mech::model::restraint::held_axes;

/// Why a shape cannot be found.
#[derive(Clone, Debug, PartialEq)]
pub enum FormFindingError {
    /// A triangle of the current shape has (nearly) no area.
    DegenerateElement {
        /// The triangle.
        element: usize,
    },
    /// The model's `frame_axis` (the warp) lies within 5.7° of a triangle's normal.
    FrameAxisNormal {
        /// The triangle.
        element: usize,
    },
    /// The linear system of a step cannot be solved (a prestress that is not positive
    /// definite, a node held by nothing).
    Singular {
        /// Which coordinate's system (0 = x, 1 = y, 2 = z).
        coordinate: usize,
        /// What the factorization said.
        reason: String,
    },
    /// The shape did not reach equilibrium within the steps allowed.
    NotConverged {
        /// Steps made.
        steps: usize,
        /// Relative out-of-balance force at the last step.
        residual: f64,
    },
}

impl std::fmt::Display for FormFindingError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::DegenerateElement { element } => {
                write!(
                    f,
                    "form finding: triangle {element} has collapsed (no area)"
                )
            }
            Self::FrameAxisNormal { element } => write!(
                f,
                "form finding: the frame axis (warp) is within 5.7° of triangle {element}'s normal: the target's directions are not defined there"
            ),
            Self::Singular { coordinate, reason } => write!(
                f,
                "form finding: the {} system cannot be solved: {reason}",
                ["x", "y", "z"][*coordinate]
            ),
            Self::NotConverged { steps, residual } => write!(
                f,
                "form finding: no equilibrium after {steps} steps (relative out-of-balance {residual:.3e})"
            ),
        }
    }
}

impl std::error::Error for FormFindingError {}

/// Per node, whether form finding holds each of x, y, z where the model puts it: what a
/// support, symmetry plane or group holds ([`held_axes`]), and every node no triangle or cable
/// touches.
pub fn held_dofs(model: &Model) -> Vec<[bool; 3]> {
    let mut held = held_axes(model);
    let mut used = vec![false; model.nodes.len()];
    let nodes = model.triangles.iter().flatten();
    nodes
        .chain(model.cables.iter().flat_map(|c| c.nodes.iter()))
        .for_each(|&v| used[v] = true);
    held.iter_mut()
        .zip(used)
        .filter(|(_, u)| !u)
        .for_each(|(h, _)| *h = [true; 3]);
    held
}

/// Solves `Σ_j K_ij x_j = 0` on the free DOFs of each coordinate, the held ones kept: the
/// linear step shared by eq. (8) of Schek (1974) and the `λ = 0` step of Bletzinger & Ramm.
pub fn solve_held(
    triplets: &[(usize, usize, f64)],
    held: &[[bool; 3]],
    x: &mut [[f64; 3]],
) -> Result<(), FormFindingError> {
    for c in 0..3 {
        let mut index = vec![usize::MAX; x.len()];
        let mut n = 0;
        for (v, h) in held.iter().enumerate() {
            if !h[c] {
                index[v] = n;
                n += 1;
            }
        }
        let mut rhs = vec![0.0; n];
        let mut reduced = Vec::with_capacity(triplets.len());
        for &(i, j, k) in triplets {
            match (index[i], index[j]) {
                (usize::MAX, _) => {}
                (a, usize::MAX) => rhs[a] -= k * x[j][c],
                (a, b) => reduced.push((a, b, k)),
            }
        }
        let mut columns = [rhs];
        solve_spd(n, &reduced, &mut columns).map_err(|reason| FormFindingError::Singular {
            coordinate: c,
            reason,
        })?;
        for (v, &i) in index.iter().enumerate() {
            if i != usize::MAX {
                x[v][c] = columns[0][i];
            }
        }
    }
    Ok(())
}

/// The model with the found shape as its geometry and the target as its prestress.
pub fn form_found_model(model: &Model, nodes: Vec<[f64; 3]>, prestress: [f64; 3]) -> Model {
    let mut found = model.clone();
    found.nodes = nodes;
    found.material.prestress = prestress;
    found
}
