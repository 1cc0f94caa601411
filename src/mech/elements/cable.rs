//! Tension-only cables along film edges (edge cables, catenary edges): 2-node total-Lagrangian
//! truss segments, Green strain `ε = (l² − L²)/(2L²)`, axial force `N = max(0, N0 + EA ε)`.
//!
//! Force on the segment's first node `f_a = N (x_a − x_b)/L`, `f_b = −f_a`; tangent while taut
//! `K = EA/L³ d dᵀ + N/L I` on the blocks `[[K, −K], [−K, K]]` (`d = x_a − x_b`, current):
//! material and geometric stiffness, consistent with the force (finite-difference test in
//! `tests/cables.rs`). A slack segment carries nothing and adds nothing to the Newton matrix: it
//! runs along a triangle edge of the film, whose stiffness holds its nodes, so no regularisation
//! is needed. Each segment must be a triangle edge: its entries go through that triangle's slots
//! of the sparsity pattern (built once), so cables change neither the pattern nor its analysis.
//!
//! A cable is an element, not a load; it enters the residual and the Newton matrix through the
//! same [`ExternalLoad`] plumbing, with the opposite sign of a load (it is an internal force).

use nalgebra::{Matrix3, SMatrix, SVector, Vector3};
use serde::{Deserialize, Serialize};

use crate::mech::elements::load::{ExternalLoad, LoadLevels};
use crate::mech::elements::triangle::ElementMatrix;
use crate::mech::model::Model;
use crate::mech::solve::assembly::{System, node_vector};

/// Nodal forces of a segment (`[f_a; f_b]`).
pub type SegmentVector = SVector<f64, 6>;
/// Tangent of a segment on its six DOFs.
pub type SegmentMatrix = SMatrix<f64, 6, 6>;

/// Axial force `N` of a segment from `x_a`, `x_b` (current positions), its reference length `l0`,
/// axial stiffness `ea` and prestress force `n0`: tension only (never negative).
pub fn axial_force(x_a: &Vector3<f64>, x_b: &Vector3<f64>, l0: f64, ea: f64, n0: f64) -> f64 {
    let l2 = (x_a - x_b).norm_squared();
    let strain = (l2 - l0 * l0) / (2.0 * l0 * l0);
    (n0 + ea * strain).max(0.0)
}

/// Nodal forces `[f_a; f_b]` and, when taut, the consistent tangent of a segment.
pub fn segment_force_and_tangent(
    x_a: &Vector3<f64>,
    x_b: &Vector3<f64>,
    l0: f64,
    ea: f64,
    n0: f64,
) -> (SegmentVector, SegmentMatrix) {
    let n = axial_force(x_a, x_b, l0, ea, n0);
    let mut f = SegmentVector::zeros();
    let mut k = SegmentMatrix::zeros();
    if n > 0.0 {
        let d = x_a - x_b;
        let fa = d * (n / l0);
        f.fixed_rows_mut::<3>(0).copy_from(&fa);
        f.fixed_rows_mut::<3>(3).copy_from(&(-fa));
        let kb = d * d.transpose() * (ea / l0.powi(3)) + Matrix3::identity() * (n / l0);
        k.fixed_view_mut::<3, 3>(0, 0).copy_from(&kb);
        k.fixed_view_mut::<3, 3>(3, 3).copy_from(&kb);
        k.fixed_view_mut::<3, 3>(0, 3).copy_from(&(-kb));
        k.fixed_view_mut::<3, 3>(3, 0).copy_from(&(-kb));
    }
    (f, k)
}

/// One segment: its nodes, the triangle whose edge it is (with the nodes' positions in it),
/// and its constants.
#[derive(Clone, Debug, PartialEq)]
struct Segment {
    cable: usize,
    nodes: [usize; 2],
    triangle: usize,
    local: [usize; 2],
    l0: f64,
    ea: f64,
    n0: f64,
}

/// The model's cables, split into segments.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Cables {
    segments: Vec<Segment>,
    reference: Vec<Vector3<f64>>,
    count: usize,
}

/// Results of one cable.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct CableResult {
    /// Largest axial force of its segments (N).
    pub max_force: f64,
    /// Segments that carry nothing (slack).
    pub slack_segments: usize,
}

impl Cables {
    /// The cables of a validated `model` (validation checks that every segment is a triangle
    /// edge; a segment that is not is skipped here, never reached).
    pub fn new(model: &Model) -> Self {
        let mut segments = vec![];
        let edges = if model.cables.is_empty() {
            Default::default()
        } else {
            model.edge_triangles()
        };
        for (c, cable) in model.cables.iter().enumerate() {
            for pair in cable.nodes.windows(2) {
                let nodes = [pair[0], pair[1]];
                let Some(&(triangle, local)) = edges.get(&nodes) else {
                    continue;
                };
                let l0 = (Vector3::from(model.nodes[nodes[0]])
                    - Vector3::from(model.nodes[nodes[1]]))
                .norm();
                segments.push(Segment {
                    cable: c,
                    nodes,
                    triangle,
                    local,
                    l0,
                    ea: cable.youngs_modulus * cable.area,
                    n0: cable.prestress_force,
                });
            }
        }
        Self {
            segments,
            reference: model.nodes.iter().map(|&p| Vector3::from(p)).collect(),
            count: model.cables.len(),
        }
    }

    fn positions(&self, s: &Segment, u: &[f64]) -> [Vector3<f64>; 2] {
        s.nodes.map(|v| self.reference[v] + node_vector(u, v))
    }

    /// Largest force and slack segments of each cable at `u`.
    pub fn results(&self, u: &[f64]) -> Vec<CableResult> {
        let mut out = vec![
            CableResult {
                max_force: 0.0,
                slack_segments: 0
            };
            self.count
        ];
        for s in &self.segments {
            let [a, b] = self.positions(s, u);
            let n = axial_force(&a, &b, s.l0, s.ea, s.n0);
            let r = &mut out[s.cable];
            r.max_force = if n.is_nan() { n } else { r.max_force.max(n) };
            r.slack_segments += usize::from(n == 0.0);
        }
        out
    }
}

impl ExternalLoad for Cables {
    fn add_to(
        &self,
        system: &System,
        _levels: &LoadLevels,
        u: &[f64],
        residual: &mut [f64],
        mut values: Option<&mut [f64]>,
    ) {
        for s in &self.segments {
            let [a, b] = self.positions(s, u);
            let (f, k) = segment_force_and_tangent(&a, &b, s.l0, s.ea, s.n0);
            for (i, &v) in s.nodes.iter().enumerate() {
                for c in 0..3 {
                    residual[3 * v + c] += f[3 * i + c];
                }
            }
            if let Some(values) = values.as_deref_mut() {
                if k.iter().all(|&x| x == 0.0) {
                    continue;
                }
                // The 6×6 block into the triangle's 9×9 at the nodes' positions in it.
                let mut ke = ElementMatrix::zeros();
                for (i, &li) in s.local.iter().enumerate() {
                    for (j, &lj) in s.local.iter().enumerate() {
                        ke.fixed_view_mut::<3, 3>(3 * li, 3 * lj)
                            .copy_from(&k.fixed_view::<3, 3>(3 * i, 3 * j));
                    }
                }
                system.add_element_matrix(s.triangle, &ke, values);
            }
        }
    }
}
