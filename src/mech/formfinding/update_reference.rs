//! Form finding by the updated reference strategy (Bletzinger & Ramm 1999) with the homotopy
//! parameter `λ = 0`: the second Piola–Kirchhoff stress `S` is prescribed on the reference
//! configuration `X_k`, the step's equilibrium
//!
//! `r_k(x) = Σ_e t A_e F S ∇N_k = 0`, with `F = Σ_l x_l ∇N_lᵀ` (Bletzinger & Ramm, eq. 12 at
//! `λ = 0`),
//!
//! is linear in the new positions `x`, `K_kl = Σ_e t A_e (∇N_kᵀ S ∇N_l) I₃` (the initial-stress
//! block of the membrane tangent, paper eq. 2.7), and the solution becomes the next reference,
//! `X_{k+1} = x`. At the fixed point `x = X`, so `F = F0` and the Cauchy stress is `S`: the film
//! carries exactly the target prestress, in the element frame the solver uses (e1 ∥ the model's
//! `frame_axis` projected, global X without one: an orthotropic target's warp). Cables add `N/L` on their segments (`N` their `prestress_force`). The
//! out-of-balance of the target stress on the current shape, `r(X_k)`, measures convergence.
//! For an isotropic `S = σ I` the step is the cotangent-Laplacian step of Pinkall & Polthier
//! (1993), which converges to a discrete minimal surface.
//!
//! The updates converge fast across the film and slowly along it (the mesh's tangential modes,
//! which an isotropic stress hardly resists): the default tolerance, `1e-4` of `t |S| L̄`, leaves
//! the analysis of the found shape within about that fraction of the target stress. An
//! orthotropic `S` has an exact equilibrium shape only where the surface allows it: the
//! tangential out-of-balance is `(σ1 − σ2)` times the geodesic curvature of the frame's lines
//! (no surface of revolution between rings; `O(|∇z|²)` on a shallow one, where the updates
//! stall at that level); `λ > 0`, which lets the stress deviate, is left.

use super::{FormFindingError, held_dofs, solve_held};
use crate::mech::elements::triangle::{AXIS_NORMAL_COSINE, MembraneTriangle};
use crate::mech::model::Model;
use nalgebra::{Matrix2, Vector3};

/// Settings of [`find_shape`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct UpdateSettings {
    /// Largest out-of-balance force accepted, relative to `t |S| L̄` (`L̄` the mean edge length).
    pub tolerance: f64,
    /// Most reference updates.
    pub max_steps: usize,
}

impl Default for UpdateSettings {
    fn default() -> Self {
        Self {
            tolerance: 1e-4,
            max_steps: 5000,
        }
    }
}

/// A found shape and how it was reached.
#[derive(Clone, Debug, PartialEq)]
pub struct FoundShape {
    /// Node positions of the shape (m).
    pub nodes: Vec<[f64; 3]>,
    /// Reference updates made.
    pub steps: usize,
    /// Relative out-of-balance force before each update, and at the end.
    pub residuals: Vec<f64>,
}

/// The step matrix `K_kl = Σ_e t A_e ∇N_kᵀ S ∇N_l` (plus `N/L` per cable segment) on the
/// reference `nodes`, as scalar triplets applied to each coordinate (Bletzinger & Ramm eq. 12, `λ = 0`).
pub fn reference_stiffness(
    model: &Model,
    nodes: &[[f64; 3]],
    prestress: [f64; 3],
) -> Result<Vec<(usize, usize, f64)>, FormFindingError> {
    let s = Matrix2::new(prestress[0], prestress[2], prestress[2], prestress[1]);
    let t = model.material.thickness;
    let mut triplets = Vec::with_capacity(9 * model.triangles.len());
    for (e, tri) in model.triangles.iter().enumerate() {
        let element = model
            .element_on(e, nodes)
            .map_err(|_| FormFindingError::DegenerateElement { element: e })?;
        check_frame(model, &element, e)?;
        let g = element.shape_gradients();
        let volume = t * element.area();
        for k in 0..3 {
            for l in 0..3 {
                let kkl = volume * (g[k].transpose() * s * g[l])[0];
                triplets.push((tri[k], tri[l], kkl));
            }
        }
    }
    for cable in &model.cables {
        for w in cable.nodes.windows(2) {
            let length = (Vector3::from(nodes[w[0]]) - Vector3::from(nodes[w[1]])).norm();
            let q = cable.prestress_force / length;
            triplets.extend([
                (w[0], w[0], q),
                (w[1], w[1], q),
                (w[0], w[1], -q),
                (w[1], w[0], -q),
            ]);
        }
    }
    Ok(triplets)
}

/// Refuses triangle `e` of the current shape when the model's `frame_axis` lies within 5.7° of
/// its normal (its e1, and so the target's warp, would not follow the axis there).
fn check_frame(
    model: &Model,
    element: &MembraneTriangle,
    e: usize,
) -> Result<(), FormFindingError> {
    let Some(axis) = model.frame_axis else {
        return Ok(());
    };
    let (e1, e2) = element.local_axes();
    let cosine = e1.cross(&e2).dot(&Vector3::from(axis).normalize()).abs();
    if cosine >= AXIS_NORMAL_COSINE {
        return Err(FormFindingError::FrameAxisNormal { element: e });
    }
    Ok(())
}

/// Largest out-of-balance force `|r_k(X)|` of the free DOFs, `r = K X` ([`reference_stiffness`]).
pub fn out_of_balance(triplets: &[(usize, usize, f64)], held: &[[bool; 3]], x: &[[f64; 3]]) -> f64 {
    let mut r = vec![[0.0; 3]; x.len()];
    for &(i, j, k) in triplets {
        (0..3).for_each(|c| r[i][c] += k * x[j][c]);
    }
    let free = r
        .iter()
        .zip(held)
        .flat_map(|(r, h)| (0..3).filter(|&c| !h[c]).map(move |c| r[c].abs()));
    free.fold(0.0, f64::max)
}

/// The force scale `t |S| L̄` the out-of-balance is measured against.
fn force_scale(model: &Model, nodes: &[[f64; 3]], prestress: [f64; 3]) -> f64 {
    let edges = super::force_density::bars(model);
    let total: f64 = edges
        .iter()
        .map(|&[a, b]| (Vector3::from(nodes[a]) - Vector3::from(nodes[b])).norm())
        .sum();
    let stress = prestress.iter().fold(0.0f64, |m, s| m.max(s.abs()));
    model.material.thickness * stress * total / edges.len().max(1) as f64
}

/// Updates the reference from `start` until the target `prestress` (Voigt, element frame) is in
/// equilibrium (Bletzinger & Ramm 1999, eq. 12 with `λ = 0`).
pub fn find_shape(
    model: &Model,
    start: Vec<[f64; 3]>,
    prestress: [f64; 3],
    settings: UpdateSettings,
) -> Result<FoundShape, FormFindingError> {
    let held = held_dofs(model);
    let scale = force_scale(model, &start, prestress);
    let mut x = start;
    let mut residuals = Vec::new();
    for step in 0..=settings.max_steps {
        let triplets = reference_stiffness(model, &x, prestress)?;
        let residual = out_of_balance(&triplets, &held, &x) / scale;
        residuals.push(residual);
        if residual <= settings.tolerance {
            return Ok(FoundShape {
                nodes: x,
                steps: step,
                residuals,
            });
        }
        if step == settings.max_steps || !residual.is_finite() {
            return Err(FormFindingError::NotConverged {
                steps: step,
                residual,
            });
        }
        solve_held(&triplets, &held, &mut x)?;
    }
    unreachable!("the loop returns at its last step")
}
