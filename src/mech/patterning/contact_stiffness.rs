//! The design loop's contact stiffness (issue 46): a curved support's penalties read per metre of
//! its contact line, so that the erected prestress does not change with the mesh.
//!
//! A penalty `k` per node (N/m) makes a row of contact nodes `h` apart a spring of `k/h` per metre
//! of support: halving the cells doubles it, and the friction the settled film keeps beside an
//! arch with it. Read per metre (`k'`, N/m per m), each node gets `k' ℓ̄`, with `ℓ̄` the support's
//! mean tributary length: each contact node's half distance to its neighbours along the support's
//! contact line, the line being the film nodes on the tube's surface (`|gap|` within a tenth of the
//! tube's radius) and the support's own contact nodes, taken in order along the support (`ξ1` of a
//! curve, the axis of a cylinder), distances straight between neighbours. An end node has one neighbour. One number per support (the
//! contact law's): exact for evenly spaced nodes, the mean otherwise. A support touched over an
//! area (a film wrapped round a drum: two contact nodes side by side across it) has no length per
//! node; [`ContactStiffness::Auto`] keeps its penalties per node, [`ContactStiffness::PerLength`]
//! refuses it.

use std::str::FromStr;

use nalgebra::Vector3;

use crate::mech::elements::curved_contact::{Centreline, SurfaceContact};
use crate::mech::model::Model;

/// How the design loop reads the curved supports' `normal_stiffness` and `tangential_stiffness`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum ContactStiffness {
    /// Per metre of contact line where the support's nodes lie in a row along it, else per node.
    #[default]
    Auto,
    /// Per metre of contact line; a support touched over an area is refused.
    PerLength,
    /// Per node, as the analysis reads them.
    PerNode,
}

impl FromStr for ContactStiffness {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, String> {
        match s {
            "auto" => Ok(Self::Auto),
            "per-length" => Ok(Self::PerLength),
            "per-node" => Ok(Self::PerNode),
            _ => Err(format!(
                "contact stiffness {s:?}: auto, per-length or per-node"
            )),
        }
    }
}

/// The penalties one curved support's nodes get in the design loop.
#[derive(Clone, Debug, PartialEq)]
pub struct SupportStiffness {
    /// The support's name.
    pub name: String,
    /// Its mean tributary length `ℓ̄` (m) where its penalties are per metre; None: per node.
    pub tributary_length: Option<f64>,
    /// `k_n` of each of its nodes (N/m).
    pub normal_stiffness: f64,
    /// `k_s` of each of its nodes (N/m).
    pub tangential_stiffness: f64,
}

/// The mean tributary length of support `s`'s contact nodes along its contact line on the
/// positions `x` (module doc), or why it has none (the message names the support and the nodes).
pub fn tributary_length(model: &Model, s: usize, x: &[[f64; 3]]) -> Result<f64, String> {
    let support = &model.curved_supports[s];
    let project =
        |v: usize, near: f64| SurfaceContact::new(support, v).project(&Vector3::from(x[v]), near);
    // Angles unwrapped toward the first contact node's, so that the line does not break at ±π.
    let near = support
        .nodes
        .first()
        .map_or(0.0, |&v| project(v, 0.0).parameter);
    let along = |v: usize| {
        let p = project(v, near);
        let coordinate = match support.centreline {
            Centreline::Line { .. } => p.xi[1],
            _ => p.xi[0],
        };
        (p.gap, coordinate)
    };
    let tolerance = 0.1 * support.tube_radius;
    let mut line: Vec<(f64, usize)> = (0..x.len())
        .filter_map(|v| {
            let (gap, coordinate) = along(v);
            let on = support.nodes.contains(&v) || gap.abs() <= tolerance;
            (on && coordinate.is_finite()).then_some((coordinate, v))
        })
        .collect();
    line.sort_by(|a, b| a.0.total_cmp(&b.0));
    let distance = |a: usize, b: usize| (Vector3::from(x[a]) - Vector3::from(x[b])).norm();
    for w in line.windows(2) {
        let ((s0, a), (s1, b)) = (w[0], w[1]);
        if s1 - s0 < 0.5 * distance(a, b) {
            return Err(format!(
                "support '{}': nodes {a} and {b} lie side by side across it, not in a row along \
                 it (a contact over an area has no length per node)",
                support.name
            ));
        }
    }
    let total: f64 = (0..line.len())
        .filter(|&k| support.nodes.contains(&line[k].1))
        .map(|k| {
            let before = k
                .checked_sub(1)
                .map_or(0.0, |j| distance(line[j].1, line[k].1));
            let after = line.get(k + 1).map_or(0.0, |n| distance(n.1, line[k].1));
            0.5 * (before + after)
        })
        .sum();
    let mean = total / support.nodes.len() as f64;
    if mean > 0.0 && mean.is_finite() {
        Ok(mean)
    } else {
        Err(format!(
            "support '{}': its contact line has a single node (a length per node needs two)",
            support.name
        ))
    }
}

/// Each curved support's penalties in the design loop on `model`'s geometry by `basis` (module
/// doc); refused with [`ContactStiffness::PerLength`] where a support has no length per node.
pub fn support_stiffnesses(
    model: &Model,
    basis: ContactStiffness,
) -> Result<Vec<SupportStiffness>, String> {
    (0..model.curved_supports.len())
        .map(|s| {
            let support = &model.curved_supports[s];
            let length = match basis {
                ContactStiffness::PerNode => None,
                ContactStiffness::Auto => tributary_length(model, s, &model.nodes).ok(),
                ContactStiffness::PerLength => Some(
                    tributary_length(model, s, &model.nodes)
                        .map_err(|e| format!("contact stiffness per length: {e}"))?,
                ),
            };
            let scale = length.unwrap_or(1.0);
            Ok(SupportStiffness {
                name: support.name.clone(),
                tributary_length: length,
                normal_stiffness: support.normal_stiffness * scale,
                tangential_stiffness: support.tangential_stiffness * scale,
            })
        })
        .collect()
}

/// `model` with each curved support's penalties per node from `stiffnesses` (in its order).
pub fn with_node_stiffnesses(mut model: Model, stiffnesses: &[SupportStiffness]) -> Model {
    for (s, k) in model.curved_supports.iter_mut().zip(stiffnesses) {
        s.normal_stiffness = k.normal_stiffness;
        s.tangential_stiffness = k.tangential_stiffness;
    }
    model
}
