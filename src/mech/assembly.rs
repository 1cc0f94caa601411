//! Global assembly: DOF numbering, the sparsity pattern (computed once per model), and the
//! scatter of element and gap forces and matrices (the `K_m + K_g`, `R_m + R_g` of eq. 2.11).
//!
//! Prescribed DOFs (supports, symmetry planes, boundary groups) are eliminated: equations are
//! numbered over free DOFs only. The pattern is built once from the triangles and the gaps
//! (node-to-node gaps never change it); every entry of every element matrix gets a precomputed
//! slot in the CSC value array, so an iteration only zeroes and adds values (top88's
//! `iK/jK` vs `sK`). A symmetric pattern keeps the lower triangle only.
//!
//! With more than one thread ([`System::set_threads`]) the triangles are assembled in blocks:
//! each thread computes its share of a block's element forces and tangents into its own buffer,
//! then every thread adds the whole block's entries that fall in its own range of `values` and
//! `internal`, in element order. Each entry thus receives the same additions in the same order
//! as in the serial loop: the result is bit-identical for every thread count. The threads are
//! scoped: they end before [`System::assemble`] returns (no pool outlives a call, which an FMU
//! unloaded by `dlclose` needs).

use std::panic::{AssertUnwindSafe, catch_unwind, resume_unwind};
use std::sync::{Barrier, PoisonError, RwLock};

use faer::sparse::{Pair, SparseColMatRef, SymbolicSparseColMat, SymbolicSparseColMatRef};
use nalgebra::{Matrix3, Vector3};

use super::element::{ElementMatrix, ElementVector, Material, MembraneTriangle};
use super::model::{GapSupport, Model};

const NO_SLOT: u32 = u32::MAX;

/// Triangles each thread computes per block of a parallel assembly (90 values each, 720 bytes:
/// a block's buffers stay in cache between the compute and the scatter phase).
pub const PARALLEL_BLOCK: usize = 1024;

/// Below this many triangles the automatic thread count is 1: spawning threads and their two
/// barriers per block cost more than the element work they share (docs/benchmarks.md,
/// issue 11 item 3).
pub const PARALLEL_MIN_TRIANGLES: usize = 4096;

/// Most threads the automatic thread count uses.
pub const AUTOMATIC_MAX_THREADS: usize = 2;

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
    /// Smallest and largest slot of each triangle's entries (`(NO_SLOT, 0)` when none): a
    /// thread skips triangles that have no entry in its range of `values`.
    spans: Vec<(u32, u32)>,
    /// Threads of an assembly (at least 1).
    threads: usize,
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
            .collect::<Vec<u32>>();
        let spans = slots[..81 * triangles.len()]
            .chunks(81)
            .map(|c| {
                c.iter()
                    .filter(|&&s| s != NO_SLOT)
                    .fold((NO_SLOT, 0), |(lo, hi), &s| (lo.min(s), hi.max(s)))
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
            spans,
            threads: 1,
        })
    }

    /// Sets the threads of [`System::assemble`]: `requested` when positive, else the automatic
    /// count (1 below [`PARALLEL_MIN_TRIANGLES`] triangles, else the available cores up to
    /// [`AUTOMATIC_MAX_THREADS`]).
    pub fn set_threads(&mut self, requested: usize) {
        self.threads = match requested {
            0 if self.triangles.len() < PARALLEL_MIN_TRIANGLES => 1,
            0 => std::thread::available_parallelism()
                .map_or(1, |n| n.get())
                .min(AUTOMATIC_MAX_THREADS),
            n => n,
        };
    }

    /// Threads [`System::assemble`] uses.
    pub fn threads(&self) -> usize {
        self.threads
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
            + self.spans.len() * size_of::<(u32, u32)>()
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
        if self.threads > 1 {
            self.assemble_triangles_parallel(u, internal, values.as_deref_mut());
        } else {
            let with_tangent = values.is_some();
            for e in 0..self.triangles.len() {
                let (r, k) = self.element(e, u, with_tangent);
                for (i, &gi) in node_dofs(&self.triangles[e].0).iter().enumerate() {
                    internal[gi] += r[i];
                }
                if let Some(v) = values.as_deref_mut() {
                    self.add_element_matrix(e, &k, v);
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

impl System {
    /// Force and tangent (zero unless `with_tangent`) of triangle `e` at `u`.
    fn element(&self, e: usize, u: &[f64], with_tangent: bool) -> (ElementVector, ElementMatrix) {
        let (nodes, tri) = &self.triangles[e];
        let global = node_dofs(nodes);
        let ue = ElementVector::from_fn(|i, _| u[global[i]]);
        tri.force_and_tangent(&self.material, &ue, with_tangent)
    }

    /// The triangles' part of [`System::assemble`] on `self.threads` scoped threads (see the
    /// module doc): per block, a compute phase into per-thread buffers, a barrier, a scatter
    /// phase in which thread `t` adds every entry of the block that lies in its parts of
    /// `internal` and `values`, and a barrier before the buffers are refilled.
    fn assemble_triangles_parallel(
        &self,
        u: &[f64],
        internal: &mut [f64],
        values: Option<&mut [f64]>,
    ) {
        let threads = self.threads;
        let with_tangent = values.is_some();
        let stride = if with_tangent { 90 } else { 9 };
        let buffers: Vec<RwLock<Vec<f64>>> = (0..threads)
            .map(|_| RwLock::new(vec![0.0; PARALLEL_BLOCK * stride]))
            .collect();
        let barrier = Barrier::new(threads);
        let internal_parts = split_even(internal, threads);
        let value_parts: Vec<Option<(usize, &mut [f64])>> = match values {
            Some(v) => split_even(v, threads).into_iter().map(Some).collect(),
            None => (0..threads).map(|_| None).collect(),
        };
        let block = threads * PARALLEL_BLOCK;
        let blocks = self.triangles.len().div_ceil(block);
        std::thread::scope(|scope| {
            let parts = internal_parts.into_iter().zip(value_parts).enumerate();
            for (t, ((d0, forces), mut matrix)) in parts {
                let (buffers, barrier) = (&buffers, &barrier);
                let mut work = move || {
                    // A panic is kept until every barrier has been passed (the other threads
                    // would wait for this one forever), then raised again: `scope` passes it on.
                    let mut panic = None;
                    for b in 0..blocks {
                        let start = b * block;
                        let end = (start + block).min(self.triangles.len());
                        if panic.is_none() {
                            let first = (start + t * PARALLEL_BLOCK).min(end);
                            let last = (first + PARALLEL_BLOCK).min(end);
                            let mut out =
                                buffers[t].write().unwrap_or_else(PoisonError::into_inner);
                            let computed = catch_unwind(AssertUnwindSafe(|| {
                                for (e, out) in (first..last).zip(out.chunks_exact_mut(stride)) {
                                    let (r, k) = self.element(e, u, with_tangent);
                                    out[..9].copy_from_slice(r.as_slice());
                                    if with_tangent {
                                        out[9..].copy_from_slice(k.as_slice());
                                    }
                                }
                            }));
                            panic = computed.err();
                        }
                        barrier.wait();
                        if panic.is_none() {
                            let scattered = catch_unwind(AssertUnwindSafe(|| {
                                for (owner, buffer) in buffers.iter().enumerate() {
                                    let first = (start + owner * PARALLEL_BLOCK).min(end);
                                    let last = (first + PARALLEL_BLOCK).min(end);
                                    let data =
                                        buffer.read().unwrap_or_else(PoisonError::into_inner);
                                    for (e, data) in (first..last).zip(data.chunks_exact(stride)) {
                                        self.scatter_part(
                                            e,
                                            data,
                                            (d0, &mut *forces),
                                            matrix.as_mut().map(|(v0, v)| (*v0, &mut **v)),
                                        );
                                    }
                                }
                            }));
                            panic = scattered.err();
                        }
                        barrier.wait();
                    }
                    if let Some(p) = panic {
                        resume_unwind(p);
                    }
                };
                if t + 1 < threads {
                    scope.spawn(work);
                } else {
                    work();
                }
            }
        });
    }

    /// Adds triangle `e`'s force and tangent (`data`: 9 force values, then the 81 matrix
    /// entries when present) to the parts of `internal` and `values` that start at global
    /// index `d0` and slot `v0`.
    fn scatter_part(
        &self,
        e: usize,
        data: &[f64],
        (d0, forces): (usize, &mut [f64]),
        matrix: Option<(usize, &mut [f64])>,
    ) {
        for (i, &gi) in node_dofs(&self.triangles[e].0).iter().enumerate() {
            // Indices below d0 wrap to huge values: `get_mut` skips them like those past the end.
            if let Some(x) = forces.get_mut(gi.wrapping_sub(d0)) {
                *x += data[i];
            }
        }
        let Some((v0, values)) = matrix else {
            return;
        };
        let (lo, hi) = self.spans[e];
        if lo == NO_SLOT || (hi as usize) < v0 || lo as usize >= v0 + values.len() {
            return;
        }
        let slots = &self.slots[81 * e..81 * (e + 1)];
        for (s, kij) in slots.iter().zip(&data[9..]) {
            // NO_SLOT lies past every part (nonzeros < NO_SLOT).
            if let Some(x) = values.get_mut((*s as usize).wrapping_sub(v0)) {
                *x += kij;
            }
        }
    }
}

/// `v` cut into `parts` consecutive pieces of (nearly) equal length, each with its offset.
fn split_even(v: &mut [f64], parts: usize) -> Vec<(usize, &mut [f64])> {
    let n = v.len();
    let mut rest = v;
    let mut offset = 0;
    (0..parts)
        .map(|p| {
            let len = n * (p + 1) / parts - offset;
            let (head, tail) = std::mem::take(&mut rest).split_at_mut(len);
            rest = tail;
            let piece = (offset, head);
            offset += len;
            piece
        })
        .collect()
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
