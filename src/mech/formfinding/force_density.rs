//! A first shape by the force density method (Schek 1974): every mesh edge and cable segment is
//! a bar with the same force density `q = N/L`, so that nodal equilibrium is linear in the
//! coordinates, `Cᵀ Q C x = −Cᵀ Q C_f x_f` (Schek's eq. 8 with `Q = q I`). The net it finds has
//! no membrane stiffness, only equal force densities: a shape to start the updated reference
//! strategy from (a flat or folded input), not a result.

use super::{FormFindingError, held_dofs, solve_held};
use crate::mech::model::Model;

/// The edges of the triangles and the cable segments, each once (`[low, high]`).
pub fn bars(model: &Model) -> Vec<[usize; 2]> {
    let mut bars: Vec<[usize; 2]> = model
        .triangles
        .iter()
        .flat_map(|t| [[t[0], t[1]], [t[1], t[2]], [t[2], t[0]]])
        .chain(
            model
                .cables
                .iter()
                .flat_map(|c| c.nodes.windows(2).map(|w| [w[0], w[1]])),
        )
        .map(|[a, b]| [a.min(b), a.max(b)])
        .collect();
    bars.sort_unstable();
    bars.dedup();
    bars
}

/// The force density shape (Schek 1974, eq. 8) with one force density on every bar; the held
/// DOFs ([`held_dofs`]) stay where the model puts them.
pub fn force_density_shape(model: &Model) -> Result<Vec<[f64; 3]>, FormFindingError> {
    let mut triplets = Vec::new();
    for [a, b] in bars(model) {
        triplets.extend([(a, a, 1.0), (b, b, 1.0), (a, b, -1.0), (b, a, -1.0)]);
    }
    let mut x = model.nodes.clone();
    solve_held(&triplets, &held_dofs(model), &mut x)?;
    Ok(x)
}
