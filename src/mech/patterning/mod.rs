//! Cutting patterns (issue 46, step 2): the found film is cut into strips along the user's seams,
//! each strip flattened with the least distortion, its distortion reported, and the flat strip
//! shrunk by the compensation.
//!
//! | file | what |
//! |---|---|
//! | [`seams`] | strips from seam planes or seam node lines |
//! | [`geodesic`] | geodesic seams at a strip width (Polthier & Schmies 1998) and their strips |
//! | [`split`] | the film split along seams that cross its triangles: new nodes on the edges crossed |
//! | [`cut`] | the whole pattern: every strip flattened, measured and compensated |
//! | [`flatten`] | least-squares conformal map of a strip (Lévy et al. 2002, eq. 4) |
//! | [`relax`] | least-squares strain relaxation (Gauss–Newton), flat or in space |
//! | [`distortion`] | the Green strain of the flat strip against the 3-D strip |
//! | [`compensate`] | uniform compensation, or from the target prestress `ε = D⁻¹σ` |
//! | [`erection`] | compensation by erection: erect, compare with the target, correct each strip |
//! | [`element_compensation`] | compensation by erection element by element: a fixed point on each triangle's reference metric |
//! | [`contact_stiffness`] | the curved supports' penalties per metre of contact line in the design loop |
//! | [`outline`] | the strips' outlines as SVG, with dimensions |
//! | [`reference`] | the film's compensated reference geometry and its erection model |
//!
//! Symbols: a strip's 3-D triangle has shape gradients `∇N_k` in its local frame
//! ([`MembraneTriangle`]); `y_k` are its flat node positions; `F = Σ y_k ∇N_kᵀ` (2×2) maps the
//! 3-D triangle onto the flat one and `E = ½(FᵀF − I)` is its Green strain.

pub mod compensate;
pub mod contact_stiffness;
pub mod cut;
pub mod distortion;
pub mod element_compensation;
pub mod erection;
pub mod flatten;
pub mod geodesic;
pub mod outline;
pub mod reference;
pub mod relax;
pub mod seams;
pub mod split;

use nalgebra::{Matrix2, Vector2, Vector3};

use crate::mech::elements::triangle::MembraneTriangle;
use crate::mech::model::Model;

/// A strip of the film and its flat pattern.
#[derive(Clone, Debug, PartialEq)]
pub struct Strip {
    /// The model's triangles the strip holds.
    pub triangles: Vec<usize>,
    /// The model's nodes the strip holds (a seam node belongs to every strip it bounds).
    pub nodes: Vec<usize>,
    /// The flat position of each of `nodes` (m).
    pub flat: Vec<[f64; 2]>,
}

/// A strip's triangle in the strip's node numbering with its 3-D geometry.
#[derive(Clone, Copy, Debug)]
pub struct StripTriangle {
    /// The three local node indices (into [`Strip::nodes`]).
    pub local: [usize; 3],
    /// The 3-D triangle (its frame, shape gradients and area).
    pub element: MembraneTriangle,
}

impl Strip {
    /// A strip of `triangles` with its nodes in first-use order, not yet flattened.
    pub fn new(model: &Model, triangles: Vec<usize>) -> Self {
        let mut nodes = Vec::new();
        for &t in &triangles {
            for v in model.triangles[t] {
                if !nodes.contains(&v) {
                    nodes.push(v);
                }
            }
        }
        let flat = vec![[0.0; 2]; nodes.len()];
        Self {
            triangles,
            nodes,
            flat,
        }
    }

    /// Each of the strip's model nodes → its index in [`Strip::nodes`].
    pub fn local_index(&self) -> std::collections::HashMap<usize, usize> {
        self.nodes
            .iter()
            .enumerate()
            .map(|(i, &v)| (v, i))
            .collect()
    }

    /// Model triangle `t` of the strip as cut: its flat positions (z = 0), in the model's node
    /// order (`local` from [`Strip::local_index`]).
    pub fn flat_element(
        &self,
        model: &Model,
        local: &std::collections::HashMap<usize, usize>,
        t: usize,
    ) -> Result<MembraneTriangle, String> {
        let flat = model.triangles[t].map(|v| {
            let p = self.flat[local[&v]];
            Vector3::new(p[0], p[1], 0.0)
        });
        MembraneTriangle::new(flat).map_err(|_| format!("cut triangle {t} has no area"))
    }

    /// The strip's triangles in its own numbering, on the 3-D positions `x` (frames along the
    /// model's `frame_axis`, in which its prestress is given).
    pub fn elements(&self, model: &Model, x: &[[f64; 3]]) -> Result<Vec<StripTriangle>, String> {
        let index: std::collections::HashMap<usize, usize> = self
            .nodes
            .iter()
            .enumerate()
            .map(|(i, &v)| (v, i))
            .collect();
        self.triangles
            .iter()
            .map(|&t| {
                let tri = model.triangles[t];
                let element = model
                    .element_on(t, x)
                    .map_err(|_| format!("triangle {t} has no area"))?;
                Ok(StripTriangle {
                    local: tri.map(|v| index[&v]),
                    element,
                })
            })
            .collect()
    }
}

/// `F = Σ y_k ∇N_kᵀ`, the map of a 3-D triangle onto its flat positions `y`.
pub fn flat_gradient(t: &StripTriangle, y: &[[f64; 2]]) -> Matrix2<f64> {
    let g = t.element.shape_gradients();
    (0..3).fold(Matrix2::zeros(), |f, k| {
        f + Vector2::from(y[t.local[k]]) * g[k].transpose()
    })
}

/// Green strain `E = ½(FᵀF − I)` of the map `F`.
pub fn green(f: &Matrix2<f64>) -> Matrix2<f64> {
    0.5 * (f.transpose() * f - Matrix2::identity())
}
