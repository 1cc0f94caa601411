//! Global assembly: DOF numbering, the sparsity pattern (computed once per model), and the
//! scatter of element and gap forces and matrices (the `K_m + K_g`, `R_m + R_g` of eq. 2.11).
//!
//! Prescribed DOFs (supports, symmetry planes, boundary groups) are eliminated: equations are
//! numbered over free DOFs only. The pattern is built once from the triangles and the gaps
//! (node-to-node gaps never change it); every entry of every element matrix gets a precomputed
//! slot in the CSC value array, so an iteration only zeroes and adds values (top88's
//! `iK/jK` vs `sK`). A symmetric pattern keeps the lower triangle only.

use faer::sparse::{Pair, SparseColMatRef, SymbolicSparseColMat, SymbolicSparseColMatRef};
use nalgebra::{Matrix3, Vector3};

use super::element::{ElementMatrix, ElementVector, Material, MembraneTriangle};
use super::model::{GapSupport, Model};

const NO_SLOT: u32 = u32::MAX;

/// What a global DOF is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Dof {
    /// Unknown, with its equation number.
    Free(usize),
    /// Held at zero (support or symmetry plane).
    Fixed,
    /// Moved by boundary group `group` in component `component`.
    Prescribed { group: usize, component: usize },
}

/// Geometry of a gap element as assembly needs it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GapGeometry {
    /// Film node A.
    pub film_node: usize,
    /// Support node B, or `None` for a fixed point.
    pub support_node: Option<usize>,
    /// Rotation local ← global (rows x, y, z).
    pub rotation: Matrix3<f64>,
}

/// The discretized model: elements, gaps, DOF map and sparsity pattern.
#[derive(Clone, Debug)]
pub struct System {
    /// DOF kind for each of the `3 × nodes` global DOFs.
    pub dofs: Vec<Dof>,
    /// Number of free DOFs (equations).
    pub free_count: usize,
    /// Triangles with their node indices.
    pub triangles: Vec<([usize; 3], MembraneTriangle)>,
    /// Gap elements.
    pub gaps: Vec<GapGeometry>,
    /// Film material.
    pub material: Material,
    /// CSC pattern of the free–free tangent.
    symbolic: SymbolicSparseColMat<usize>,
    /// Slot in the value array for each element-matrix entry, in assembly order.
    slots: Vec<u32>,
    /// Offset of each gap's entries in `slots`.
    gap_offsets: Vec<usize>,
    /// Whether only the lower triangle is stored.
    lower_only: bool,
}

/// Why a system cannot be built (only for sizes beyond the index type).
#[derive(Clone, Debug, PartialEq)]
pub struct PatternError(pub String);

impl System {
    /// Numbers the DOFs, builds the elements and the pattern. `model` must be validated.
    pub fn new(model: &Model, lower_only: bool) -> Result<Self, PatternError> {
        let n = model.nodes.len();
        let mut dofs = vec![Dof::Free(0); 3 * n];
        for s in &model.supports {
            for a in &s.fixed {
                dofs[3 * s.node + a.index()] = Dof::Fixed;
            }
        }
        for s in &model.symmetry {
            for &v in &s.nodes {
                dofs[3 * v + s.normal.index()] = Dof::Fixed;
            }
        }
        for (group, g) in model.groups.iter().enumerate() {
            let prescribed = g.prescribes();
            for &v in &g.nodes {
                for component in (0..3).filter(|&c| prescribed[c]) {
                    dofs[3 * v + component] = Dof::Prescribed { group, component };
                }
            }
        }
        let mut free_count = 0;
        for d in dofs.iter_mut() {
            if let Dof::Free(eq) = d {
                *eq = free_count;
                free_count += 1;
            }
        }
        let triangles = model
            .triangles
            .iter()
            .map(|t| {
                let x = t.map(|v| Vector3::from(model.nodes[v]));
                MembraneTriangle::new(x)
                    .map(|e| (*t, e))
                    .map_err(|_| PatternError(format!("triangle {t:?} is degenerate")))
            })
            .collect::<Result<Vec<_>, _>>()?;
        let gaps: Vec<GapGeometry> = model
            .gaps
            .iter()
            .map(|g| GapGeometry {
                film_node: g.film_node,
                support_node: match g.support {
                    GapSupport::Node(b) => Some(b),
                    GapSupport::Point(_) => None,
                },
                rotation: g.frame.rotation(),
            })
            .collect();

        // Pattern: one pair per element-matrix entry between free DOFs, in assembly order.
        let mut pairs: Vec<Pair<usize, usize>> =
            Vec::with_capacity(81 * triangles.len() + 36 * gaps.len());
        let mut entry_rows: Vec<Option<(usize, usize)>> = Vec::with_capacity(pairs.capacity());
        let mut push_block = |global: &[usize]| {
            // Column-major, like nalgebra's storage of the element matrix.
            for &gj in global {
                for &gi in global {
                    let entry = match (dofs[gi], dofs[gj]) {
                        (Dof::Free(i), Dof::Free(j)) if !lower_only || i >= j => Some((i, j)),
                        _ => None,
                    };
                    if let Some((i, j)) = entry {
                        pairs.push(Pair::new(i, j));
                    }
                    entry_rows.push(entry);
                }
            }
        };
        for (t, _) in &triangles {
            push_block(&node_dofs(t));
        }
        let mut gap_offsets = Vec::with_capacity(gaps.len());
        let mut offset = 81 * triangles.len();
        for g in &gaps {
            gap_offsets.push(offset);
            let block = gap_dofs(g);
            offset += block.len() * block.len();
            push_block(&block);
        }
        // Keep every diagonal entry so that a DOF whose stiffness vanishes stays in the pattern.
        for i in 0..free_count {
            pairs.push(Pair::new(i, i));
        }
        let (symbolic, _) =
            SymbolicSparseColMat::try_new_from_indices(free_count, free_count, &pairs)
                .map_err(|e| PatternError(format!("sparsity pattern: {e:?}")))?;
        if symbolic.compute_nnz() >= NO_SLOT as usize {
            return Err(PatternError("more than 2^32 nonzeros".into()));
        }
        let col_ptr = symbolic.col_ptr();
        let row_idx = symbolic.row_idx();
        let slots = entry_rows
            .iter()
            .map(|e| match e {
                None => NO_SLOT,
                Some((i, j)) => {
                    let rows = &row_idx[col_ptr[*j]..col_ptr[*j + 1]];
                    (col_ptr[*j] + rows.binary_search(i).expect("entry is in the pattern")) as u32
                }
            })
            .collect();
        Ok(Self {
            dofs,
            free_count,
            triangles,
            gaps,
            material: model.material,
            symbolic,
            slots,
            gap_offsets,
            lower_only,
        })
    }

    /// The symbolic structure of the free–free tangent.
    pub fn pattern(&self) -> SymbolicSparseColMatRef<'_, usize> {
        self.symbolic.as_ref()
    }

    /// Number of stored nonzeros.
    pub fn nonzeros(&self) -> usize {
        self.symbolic.row_idx().len()
    }

    /// Bytes held by the pattern, the slot table and the element data (not the values).
    pub fn memory_bytes(&self) -> usize {
        use std::mem::size_of;
        let pattern =
            (self.symbolic.col_ptr().len() + self.symbolic.row_idx().len()) * size_of::<usize>();
        pattern
            + self.slots.len() * size_of::<u32>()
            + self.dofs.len() * size_of::<Dof>()
            + self.triangles.len() * size_of::<([usize; 3], MembraneTriangle)>()
            + self.gaps.len() * size_of::<GapGeometry>()
    }

    /// Whether only the lower triangle is stored (symmetric iteration matrix).
    pub fn is_lower_only(&self) -> bool {
        self.lower_only
    }

    /// A matrix view over `values` (which must have [`System::nonzeros`] entries).
    pub fn matrix<'a>(&'a self, values: &'a [f64]) -> SparseColMatRef<'a, usize, f64> {
        SparseColMatRef::new(self.symbolic.as_ref(), values)
    }

    /// Adds a 9×9 matrix on the DOFs of triangle `e` (column-major, like the element tangent)
    /// into `values` through the triangle's slots: entries on constrained DOFs, and above the
    /// diagonal of a lower-only pattern, are dropped.
    pub fn add_element_matrix(&self, e: usize, k: &ElementMatrix, values: &mut [f64]) {
        let slots = &self.slots[81 * e..81 * (e + 1)];
        for (s, kij) in slots.iter().zip(k.iter()) {
            if *s != NO_SLOT {
                values[*s as usize] += kij;
            }
        }
    }

    /// Relative displacement `d = R (u_A − u_B)` of gap `g` in its local frame.
    pub fn gap_relative(&self, g: usize, u: &[f64]) -> Vector3<f64> {
        let gap = &self.gaps[g];
        let ua = node_vector(u, gap.film_node);
        let ub = gap
            .support_node
            .map_or(Vector3::zeros(), |b| node_vector(u, b));
        gap.rotation * (ua - ub)
    }

    /// Assembles the internal force over all DOFs (eqs. 2.6, 2.8) into `internal` and, when
    /// `values` is given, the tangent (eqs. 2.7, 2.9) into it. `gap(g, d)` returns the local
    /// force on node A and the local iteration matrix for gap `g` at relative displacement `d`.
    pub fn assemble(
        &self,
        u: &[f64],
        internal: &mut [f64],
        mut values: Option<&mut [f64]>,
        mut gap: impl FnMut(usize, Vector3<f64>) -> (Vector3<f64>, Matrix3<f64>),
    ) {
        internal.fill(0.0);
        if let Some(v) = values.as_deref_mut() {
            v.fill(0.0);
        }
        let with_tangent = values.is_some();
        for (e, (nodes, tri)) in self.triangles.iter().enumerate() {
            let global = node_dofs(nodes);
            let ue = ElementVector::from_fn(|i, _| u[global[i]]);
            let (r, k) = tri.force_and_tangent(&self.material, &ue, with_tangent);
            for (i, &gi) in global.iter().enumerate() {
                internal[gi] += r[i];
            }
            if let Some(v) = values.as_deref_mut() {
                let slots = &self.slots[81 * e..81 * (e + 1)];
                for (s, kij) in slots.iter().zip(k.iter()) {
                    if *s != NO_SLOT {
                        v[*s as usize] += kij;
                    }
                }
            }
        }
        for (g, geometry) in self.gaps.iter().enumerate() {
            let (force, k_local) = gap(g, self.gap_relative(g, u));
            let rt = geometry.rotation.transpose();
            let fa = rt * force;
            let ka = rt * k_local * geometry.rotation;
            let block = gap_dofs(geometry);
            for c in 0..3 {
                internal[block[c]] += fa[c];
                if block.len() == 6 {
                    internal[block[3 + c]] -= fa[c];
                }
            }
            if let Some(v) = values.as_deref_mut() {
                let m = block.len();
                let slots = &self.slots[self.gap_offsets[g]..self.gap_offsets[g] + m * m];
                for a in 0..m {
                    for b in 0..m {
                        let s = slots[b * m + a];
                        if s != NO_SLOT {
                            let sign = if (a < 3) == (b < 3) { 1.0 } else { -1.0 };
                            v[s as usize] += sign * ka[(a % 3, b % 3)];
                        }
                    }
                }
            }
        }
    }
}

/// The nine global DOFs of a triangle.
pub fn node_dofs(nodes: &[usize; 3]) -> [usize; 9] {
    std::array::from_fn(|i| 3 * nodes[i / 3] + i % 3)
}

/// The global DOFs of a gap: A's three, then B's three when B is a node (no allocation: it
/// runs for every gap in every assembly).
fn gap_dofs(g: &GapGeometry) -> GapDofs {
    let a = 3 * g.film_node;
    match g.support_node {
        Some(b) => GapDofs {
            dofs: [a, a + 1, a + 2, 3 * b, 3 * b + 1, 3 * b + 2],
            len: 6,
        },
        None => GapDofs {
            dofs: [a, a + 1, a + 2, 0, 0, 0],
            len: 3,
        },
    }
}

/// The 3 or 6 global DOFs of a gap.
struct GapDofs {
    dofs: [usize; 6],
    len: usize,
}

impl std::ops::Deref for GapDofs {
    type Target = [usize];
    fn deref(&self) -> &[usize] {
        &self.dofs[..self.len]
    }
}

/// Displacement of node `v` from the global vector.
pub fn node_vector(u: &[f64], v: usize) -> Vector3<f64> {
    Vector3::new(u[3 * v], u[3 * v + 1], u[3 * v + 2])
}
