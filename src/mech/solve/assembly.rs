//! Global assembly: DOF numbering, the sparsity pattern (computed once per model), and the
//! scatter of element and gap forces and matrices (the `K_m + K_g`, `R_m + R_g` of eq. 2.11).
//!
//! Prescribed DOFs (supports, symmetry planes, boundary groups) are eliminated: equations are
//! numbered over free DOFs only. The pattern is built once from the triangles and the gaps
//! (node-to-node gaps never change it); every entry of every element matrix gets a precomputed
//! slot in the CSC value array, so an iteration only zeroes and adds values (top88's
//! `iK/jK` vs `sK`). A symmetric pattern keeps the lower triangle only.
//!
//! With more than one thread ([`System::set_threads`]) the owner computes: the columns are cut
//! into one range per thread of about equal nonzeros; each thread owns its columns' slots of
//! `values` and the matching range of global DOFs of `internal`, computes every triangle with a
//! DOF in its range (in element order) and adds only the entries it owns. A triangle across two
//! ranges is computed by both (0.3–11 % of the triangles on the benchmarks' meshes); no two
//! threads write the same entry, and each entry receives the same additions in the same order as
//! in the serial loop: the result is bit-identical for every thread count. The threads are scoped
//! and joined one by one: they end before [`System::assemble`] returns, on Linux until the kernel
//! no longer lists them in `/proc/self/task` (see `worker`; no pool outlives a call, which an FMU
//! unloaded by `dlclose` needs), and a panic in one reaches the caller.

use faer::sparse::{Pair, SparseColMatRef, SymbolicSparseColMat, SymbolicSparseColMatRef};
use nalgebra::{Matrix3, Vector3};

use crate::mech::elements::layer_contact::{LayerContactSetup, PairMatrix};
use crate::mech::elements::triangle::{ElementMatrix, ElementVector, Material, MembraneTriangle};
use crate::mech::model::{GapSupport, Model};

const NO_SLOT: u32 = u32::MAX;

/// Below this many triangles the automatic thread count is 1: on the shared 2-core machine a
/// second thread lost time on every smaller mesh measured (docs/benchmarks.md, issue 11 item 3).
pub const PARALLEL_MIN_TRIANGLES: usize = 100_000;

/// Triangles per thread of the automatic count from [`PARALLEL_MIN_TRIANGLES`] up (two threads
/// at 100 000 triangles, eight at 400 000, never more than the available cores): each thread's
/// share stays far above the cost of starting it and of the triangles two threads compute.
pub const TRIANGLES_PER_THREAD: usize = 50_000;

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
    /// Film material at the model's temperature ([`Material::at_temperature`]).
    pub material: Material,
    /// CSC pattern of the free–free tangent.
    symbolic: SymbolicSparseColMat<usize>,
    /// Slot in the value array for each element-matrix entry, in assembly order.
    slots: Vec<u32>,
    /// Offset of each gap's entries in `slots`.
    gap_offsets: Vec<usize>,
    /// Offset of each layer-contact pair's entries in `slots`.
    pair_offsets: Vec<usize>,
    /// The layer contacts' slave nodes and candidate triangles (their pairs' blocks).
    pub layer_contacts: LayerContactSetup,
    /// Whether only the lower triangle is stored.
    lower_only: bool,
    /// Threads of an assembly (at least 1).
    threads: usize,
    /// What each thread of a parallel assembly owns (empty when serial).
    parts: Vec<Part>,
}

/// One thread's share of a parallel assembly: the global DOFs and slots it writes and
/// the triangles with a DOF among them (ascending), computed by every thread they touch.
#[derive(Clone, Debug)]
struct Part {
    dofs: std::ops::Range<usize>,
    slots: std::ops::Range<usize>,
    triangles: Vec<u32>,
}

/// Why a system cannot be built (only for sizes beyond the index type).
#[derive(Clone, Debug, PartialEq)]
pub struct PatternError(pub String);

impl System {
    /// Numbers the DOFs, builds the elements and the pattern. `model` must be validated.
    pub fn new(model: &Model, lower_only: bool) -> Result<Self, PatternError> {
        let (dofs, free_count) = number_dofs(model);
        let triangles = triangle_elements(model)?;
        let gaps = gap_geometries(model);
        let layer_contacts = LayerContactSetup::new(model);
        let mut entries =
            PatternEntries::collect(&dofs, &triangles, &gaps, &layer_contacts, lower_only);
        let (symbolic, slots) = entries.pattern(free_count)?;
        Ok(Self {
            dofs,
            free_count,
            triangles,
            gaps,
            material: model.material.at_temperature(),
            symbolic,
            slots,
            gap_offsets: entries.gap_offsets,
            pair_offsets: entries.pair_offsets,
            layer_contacts,
            lower_only,
            threads: 1,
            parts: vec![],
        })
    }

    /// Sets the threads of [`System::assemble`]: `requested` when positive, else the automatic
    /// count (1 below [`PARALLEL_MIN_TRIANGLES`] triangles, else one per
    /// [`TRIANGLES_PER_THREAD`] triangles up to the available cores).
    pub fn set_threads(&mut self, requested: usize) {
        self.threads = match requested {
            0 => automatic_threads(self.triangles.len()),
            n => n,
        };
        self.parts = if self.threads > 1 {
            self.partition(self.threads)
        } else {
            vec![]
        };
    }

    /// Cuts the free DOFs into `threads` ranges of consecutive columns holding about equal
    /// numbers of nonzeros; each part owns its columns' slots and the global DOFs from its
    /// first column's DOF up to the next part's (constrained DOFs go with the free DOF before).
    fn partition(&self, threads: usize) -> Vec<Part> {
        let col_ptr = self.symbolic.col_ptr();
        let nnz = self.nonzeros();
        let global_of: Vec<usize> = self
            .dofs
            .iter()
            .enumerate()
            .filter(|(_, d)| matches!(d, Dof::Free(_)))
            .map(|(g, _)| g)
            .collect();
        // Part t starts at column `first_column(t)` and at global DOF `first_dof(t)`.
        let first_column = |t: usize| {
            col_ptr
                .partition_point(|&p| p < nnz * t / threads)
                .min(self.free_count)
        };
        let first_dof = |t: usize| match first_column(t) {
            _ if t == 0 => 0,
            _ if t == threads => self.dofs.len(),
            c if c == self.free_count => self.dofs.len(),
            c => global_of[c],
        };
        let mut parts: Vec<Part> = (0..threads)
            .map(|t| {
                let (c0, c1) = (first_column(t), first_column(t + 1));
                let c1 = if t + 1 == threads {
                    self.free_count
                } else {
                    c1
                };
                Part {
                    dofs: first_dof(t)..first_dof(t + 1),
                    slots: col_ptr[c0]..col_ptr[c1],
                    triangles: vec![],
                }
            })
            .collect();
        for (e, (nodes, _)) in self.triangles.iter().enumerate() {
            for part in parts.iter_mut() {
                if node_dofs(nodes).iter().any(|g| part.dofs.contains(g)) {
                    part.triangles.push(e as u32);
                }
            }
        }
        parts
    }

    /// Triangles computed per assembly over all threads, relative to the triangle count (1 when
    /// serial; above 1 by the triangles computed by two threads or more).
    pub fn computed_share(&self) -> f64 {
        if self.parts.is_empty() {
            return 1.0;
        }
        let computed: usize = self.parts.iter().map(|p| p.triangles.len()).sum();
        computed as f64 / self.triangles.len().max(1) as f64
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
            + self
                .parts
                .iter()
                .map(|p| p.triangles.len() * size_of::<u32>())
                .sum::<usize>()
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

    /// Adds a layer-contact pair's 12×12 matrix (slave node, then the triangle's nodes;
    /// column-major) into `values` through the slots of block `b`
    /// ([`LayerContactSetup::blocks`]), dropping what [`System::add_element_matrix`] drops.
    pub fn add_pair_matrix(&self, b: usize, k: &PairMatrix, values: &mut [f64]) {
        let o = self.pair_offsets[b];
        for (s, kij) in self.slots[o..o + 144].iter().zip(k.iter()) {
            if *s != NO_SLOT {
                values[*s as usize] += kij;
            }
        }
    }

    /// A serial copy of the system whose value array goes on past [`System::nonzeros`] with the
    /// rows of the constrained DOFs, which the pattern drops: every element-matrix entry at a
    /// constrained row and a free column gets a slot of its own there, and `rows[k]` is (the
    /// global row, the free column) of slot `nonzeros() + k`. Assembled into `nonzeros() +
    /// rows.len()` values by the same contributions, its first `nonzeros()` are the system's
    /// matrix bit for bit and the rest sum to `K_rf` (a reaction's gradient; the adjoint's
    /// `K_rfᵀ v`, `solve/sensitivity.rs`).
    pub fn with_constrained_rows(&self) -> Result<(System, Vec<(usize, usize)>), PatternError> {
        let mut copy = self.clone();
        copy.set_threads(1);
        let nnz = self.nonzeros();
        let (mut k, mut rows) = (0, vec![]);
        for_each_entry(
            &self.triangles,
            &self.gaps,
            &self.layer_contacts,
            |gi, gj| {
                if let (Dof::Fixed | Dof::Prescribed { .. }, Dof::Free(j)) =
                    (self.dofs[gi], self.dofs[gj])
                {
                    copy.slots[k] = (nnz + rows.len()) as u32;
                    rows.push((gi, j));
                }
                k += 1;
            },
        );
        if nnz + rows.len() >= NO_SLOT as usize {
            return Err(PatternError(
                "more than 2^32 entries with the constrained rows".into(),
            ));
        }
        Ok((copy, rows))
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
        gap: impl FnMut(usize, Vector3<f64>) -> (Vector3<f64>, Matrix3<f64>),
    ) {
        internal.fill(0.0);
        if let Some(v) = values.as_deref_mut() {
            v.fill(0.0);
        }
        self.add_triangles(u, internal, values.as_deref_mut());
        self.add_gaps(u, internal, values, gap);
    }

    /// Adds the triangles' internal forces (eq. 2.6) into `internal` and, when `values` is
    /// given, their tangents (eq. 2.7), in element order (on threads when set: same sums).
    pub fn add_triangles(&self, u: &[f64], internal: &mut [f64], values: Option<&mut [f64]>) {
        self.add_triangles_keeping(
            u,
            internal,
            values,
            |_, tri, ue, with_tangent| {
                let (r, k) = tri.force_and_tangent(&self.material, ue, with_tangent);
                (r, k, ())
            },
            &mut [],
        );
    }

    /// [`System::add_triangles`] with the element computed by `element(e, triangle, u_e,
    /// with_tangent)`, which also returns a value per triangle kept in `kept[e]` (a plastic
    /// film's trial history; `kept` may be empty for `()`). On threads when set: a triangle
    /// computed by two threads is kept from the first, and every result is the same bits.
    pub fn add_triangles_keeping<X: Send>(
        &self,
        u: &[f64],
        internal: &mut [f64],
        values: Option<&mut [f64]>,
        element: impl Fn(
            usize,
            &MembraneTriangle,
            &ElementVector,
            bool,
        ) -> (ElementVector, ElementMatrix, X)
        + Sync,
        kept: &mut [X],
    ) {
        if self.threads > 1 {
            for (e, x) in self.assemble_triangles_owned(u, internal, values, &element) {
                if let Some(slot) = kept.get_mut(e) {
                    *slot = x;
                }
            }
        } else {
            self.add_triangles_with(u, internal, values, |e, tri, ue, with_tangent| {
                let (r, k, x) = element(e, tri, ue, with_tangent);
                if let Some(slot) = kept.get_mut(e) {
                    *slot = x;
                }
                (r, k)
            });
        }
    }

    /// Adds every triangle's force and, when `values` is given, its matrix, serially in
    /// triangle order; `element(e, triangle, u_e, with_tangent)` computes them.
    pub fn add_triangles_with(
        &self,
        u: &[f64],
        internal: &mut [f64],
        mut values: Option<&mut [f64]>,
        mut element: impl FnMut(
            usize,
            &MembraneTriangle,
            &ElementVector,
            bool,
        ) -> (ElementVector, ElementMatrix),
    ) {
        let with_tangent = values.is_some();
        for (e, (nodes, tri)) in self.triangles.iter().enumerate() {
            let global = node_dofs(nodes);
            let ue = ElementVector::from_fn(|i, _| u[global[i]]);
            let (r, k) = element(e, tri, &ue, with_tangent);
            for (i, &gi) in global.iter().enumerate() {
                internal[gi] += r[i];
            }
            if let Some(v) = values.as_deref_mut() {
                self.add_element_matrix(e, &k, v);
            }
        }
    }

    /// Adds the gaps' forces (eq. 2.8) and, when `values` is given, their iteration matrices
    /// (eq. 2.9), in gap order; `gap(g, d)` as in [`Self::assemble`].
    pub fn add_gaps(
        &self,
        u: &[f64],
        internal: &mut [f64],
        mut values: Option<&mut [f64]>,
        mut gap: impl FnMut(usize, Vector3<f64>) -> (Vector3<f64>, Matrix3<f64>),
    ) {
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
    /// The triangles' part of [`System::assemble`] on scoped threads, owner computes (see the
    /// module doc): thread `t` computes every triangle of its part with `element` and adds the
    /// entries that fall in its own DOFs and slots. Returns each triangle's kept value, from the
    /// first part that computes it.
    fn assemble_triangles_owned<X: Send>(
        &self,
        u: &[f64],
        internal: &mut [f64],
        values: Option<&mut [f64]>,
        element: &(
             impl Fn(usize, &MembraneTriangle, &ElementVector, bool) -> (ElementVector, ElementMatrix, X)
             + Sync
         ),
    ) -> Vec<(usize, X)> {
        let with_tangent = values.is_some();
        let mut forces = internal;
        let mut matrix = values;
        let mut last = vec![];
        std::thread::scope(|scope| {
            let mut workers = Vec::with_capacity(self.parts.len());
            for (t, part) in self.parts.iter().enumerate() {
                let (mine, rest) = std::mem::take(&mut forces).split_at_mut(part.dofs.len());
                forces = rest;
                let mine_values = match matrix.take() {
                    Some(v) => {
                        let (mine, rest) = v.split_at_mut(part.slots.len());
                        matrix = Some(rest);
                        Some((part.slots.start, mine))
                    }
                    None => None,
                };
                let earlier = &self.parts[..t];
                let work = move || {
                    let mut mine_values = mine_values;
                    let mut kept = vec![];
                    for &e in &part.triangles {
                        let first = earlier
                            .iter()
                            .all(|p| p.triangles.binary_search(&e).is_err());
                        let e = e as usize;
                        let (nodes, tri) = &self.triangles[e];
                        let global = node_dofs(nodes);
                        let ue = ElementVector::from_fn(|i, _| u[global[i]]);
                        let (r, k, x) = element(e, tri, &ue, with_tangent);
                        self.scatter_part(
                            e,
                            (&r, &k),
                            (part.dofs.start, &mut *mine),
                            mine_values.as_mut().map(|(v0, v)| (*v0, &mut **v)),
                        );
                        if first {
                            kept.push((e, x));
                        }
                    }
                    kept
                };
                if t + 1 < self.parts.len() {
                    let worker = std::thread::Builder::new()
                        .name(format!("assembly {t}"))
                        .spawn_scoped(scope, move || (work(), worker::own_task()))
                        .expect("the system gives a thread for the assembly");
                    workers.push(worker);
                } else {
                    last = work();
                }
            }
            let mut kept = vec![];
            for worker in workers {
                match worker.join() {
                    Ok((part, task)) => {
                        worker::wait_until_gone(task);
                        kept.extend(part);
                    }
                    Err(panic) => std::panic::resume_unwind(panic),
                }
            }
            kept.append(&mut last);
            kept
        })
    }

    /// Adds triangle `e`'s force `r` and, when `matrix` is given, its tangent `k` to the parts of
    /// `internal` and `values` that start at global DOF `d0` and slot `v0`.
    fn scatter_part(
        &self,
        e: usize,
        (r, k): (&ElementVector, &ElementMatrix),
        (d0, forces): (usize, &mut [f64]),
        matrix: Option<(usize, &mut [f64])>,
    ) {
        for (i, &gi) in node_dofs(&self.triangles[e].0).iter().enumerate() {
            // Indices below d0 wrap to huge values: `get_mut` skips them like those past the end.
            if let Some(x) = forces.get_mut(gi.wrapping_sub(d0)) {
                *x += r[i];
            }
        }
        if let Some((v0, values)) = matrix {
            let slots = &self.slots[81 * e..81 * (e + 1)];
            for (s, kij) in slots.iter().zip(k.iter()) {
                // NO_SLOT lies past every part (nonzeros < NO_SLOT).
                if let Some(x) = values.get_mut((*s as usize).wrapping_sub(v0)) {
                    *x += kij;
                }
            }
        }
    }
}

/// Each global DOF's kind (supports and symmetry planes fix, boundary groups prescribe) with
/// the free ones numbered in order, and the number of free DOFs.
fn number_dofs(model: &Model) -> (Vec<Dof>, usize) {
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
    (dofs, free_count)
}

/// The model's triangles as elements, each with its layer's thickness where a layer selects it.
fn triangle_elements(model: &Model) -> Result<Vec<([usize; 3], MembraneTriangle)>, PatternError> {
    let mut thickness = vec![None; model.triangles.len()];
    for l in &model.layers {
        for e in model.selected_triangles(&l.elements) {
            thickness[e] = Some(l.thickness);
        }
    }
    model
        .triangles
        .iter()
        .zip(thickness)
        .enumerate()
        .map(|(k, (t, layer))| {
            model
                .element_on(k, &model.nodes)
                .map(|e| (*t, layer.map_or(e, |h| e.with_thickness(h))))
                .map_err(|_| PatternError(format!("triangle {t:?} is degenerate")))
        })
        .collect()
}

/// The model's gaps as assembly needs them.
fn gap_geometries(model: &Model) -> Vec<GapGeometry> {
    model
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
        .collect()
}

/// The entries of every element matrix, in assembly order: triangles, gaps, layer-contact pairs.
struct PatternEntries {
    /// One pair per entry between free DOFs (only the lower triangle's when `lower_only`).
    pairs: Vec<Pair<usize, usize>>,
    /// Each entry's (row, column) equation, or `None` where it has a non-free DOF.
    entry_rows: Vec<Option<(usize, usize)>>,
    /// Offset of each gap's entries.
    gap_offsets: Vec<usize>,
    /// Offset of each layer-contact pair's entries.
    pair_offsets: Vec<usize>,
}

impl PatternEntries {
    /// Lists the entries of the triangles', gaps' and layer contacts' blocks.
    fn collect(
        dofs: &[Dof],
        triangles: &[([usize; 3], MembraneTriangle)],
        gaps: &[GapGeometry],
        layer_contacts: &LayerContactSetup,
        lower_only: bool,
    ) -> Self {
        // Pattern: one pair per element-matrix entry between free DOFs, in assembly order.
        let mut pairs: Vec<Pair<usize, usize>> =
            Vec::with_capacity(81 * triangles.len() + 36 * gaps.len());
        let mut entry_rows: Vec<Option<(usize, usize)>> = Vec::with_capacity(pairs.capacity());
        let (gap_offsets, pair_offsets) =
            for_each_entry(triangles, gaps, layer_contacts, |gi, gj| {
                let entry = match (dofs[gi], dofs[gj]) {
                    (Dof::Free(i), Dof::Free(j)) if !lower_only || i >= j => Some((i, j)),
                    _ => None,
                };
                if let Some((i, j)) = entry {
                    pairs.push(Pair::new(i, j));
                }
                entry_rows.push(entry);
            });
        Self {
            pairs,
            entry_rows,
            gap_offsets,
            pair_offsets,
        }
    }

    /// The CSC pattern of the entries over `free_count` equations, every diagonal entry in it,
    /// and each entry's slot in its value array.
    fn pattern(
        &mut self,
        free_count: usize,
    ) -> Result<(SymbolicSparseColMat<usize>, Vec<u32>), PatternError> {
        let pairs = &mut self.pairs;
        // Keep every diagonal entry so that a DOF whose stiffness vanishes stays in the pattern.
        for i in 0..free_count {
            pairs.push(Pair::new(i, i));
        }
        let (symbolic, _) =
            SymbolicSparseColMat::try_new_from_indices(free_count, free_count, pairs)
                .map_err(|e| PatternError(format!("sparsity pattern: {e:?}")))?;
        if symbolic.compute_nnz() >= NO_SLOT as usize {
            return Err(PatternError("more than 2^32 nonzeros".into()));
        }
        let col_ptr = symbolic.col_ptr();
        let row_idx = symbolic.row_idx();
        let slots = self
            .entry_rows
            .iter()
            .map(|e| match e {
                None => NO_SLOT,
                Some((i, j)) => {
                    let rows = &row_idx[col_ptr[*j]..col_ptr[*j + 1]];
                    (col_ptr[*j] + rows.binary_search(i).expect("entry is in the pattern")) as u32
                }
            })
            .collect();
        Ok((symbolic, slots))
    }
}

/// Calls `entry(row, column)` with the global DOFs of every element-matrix entry in assembly
/// order (the order of the slot table): each triangle's 9×9, each gap's 3×3 or 6×6, each
/// layer-contact pair's 12×12, column-major like nalgebra's storage. Returns the offsets of
/// the gaps' and the pairs' entries.
fn for_each_entry(
    triangles: &[([usize; 3], MembraneTriangle)],
    gaps: &[GapGeometry],
    layer_contacts: &LayerContactSetup,
    mut entry: impl FnMut(usize, usize),
) -> (Vec<usize>, Vec<usize>) {
    let mut block = |global: &[usize]| {
        for &gj in global {
            for &gi in global {
                entry(gi, gj);
            }
        }
    };
    for (t, _) in triangles {
        block(&node_dofs(t));
    }
    let mut gap_offsets = Vec::with_capacity(gaps.len());
    let mut offset = 81 * triangles.len();
    for g in gaps {
        gap_offsets.push(offset);
        let dofs = gap_dofs(g);
        offset += dofs.len() * dofs.len();
        block(&dofs);
    }
    let mut pair_offsets = Vec::with_capacity(layer_contacts.blocks.len());
    for (v, tri) in &layer_contacts.blocks {
        pair_offsets.push(offset);
        offset += 144;
        let mut dofs = [0; 12];
        dofs[..3].copy_from_slice(&[3 * v, 3 * v + 1, 3 * v + 2]);
        dofs[3..].copy_from_slice(&node_dofs(tri));
        block(&dofs);
    }
    (gap_offsets, pair_offsets)
}

/// The automatic assembly thread count for `triangles` triangles (see [`System::set_threads`]).
pub fn automatic_threads(triangles: usize) -> usize {
    if triangles < PARALLEL_MIN_TRIANGLES {
        return 1;
    }
    (triangles / TRIANGLES_PER_THREAD).clamp(1, idle_cores())
}

/// The available cores less those other processes keep busy: the one-minute load average
/// beyond this process's own running thread, rounded (Linux; elsewhere the available cores),
/// at least 1. A second thread on a core that another process holds lost 1.5–1.8× on the
/// shared 2-core machine (docs/benchmarks.md, issue 42), so the automatic counts take the idle
/// cores only; a study's workers, one per core, keep them busy and get one thread.
pub fn idle_cores() -> usize {
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    let load = std::fs::read_to_string("/proc/loadavg").ok().and_then(|t| {
        t.split_whitespace()
            .next()
            .and_then(|v| v.parse::<f64>().ok())
    });
    match load {
        Some(load) => {
            let busy = (load - 1.0).max(0.0);
            ((cores as f64 - busy).round() as usize).clamp(1, cores)
        }
        None => cores,
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

/// Making "no thread outlives the call" hold to the operating system's eyes. `join` returns
/// when the thread's code has ended (its pthread's tid is cleared), but the kernel lists the
/// task until it has finished tearing it down: on Linux a joined worker was still in
/// `/proc/self/task` after about 40 % of the FMU's calls on the shared 2-core machine
/// (`tests/threads.rs`). So on Linux a worker reports its task id, and the caller waits, after
/// the join, until that task is gone (a few microseconds; bounded).
pub(crate) mod worker {
    /// Longest wait for the kernel to remove a joined thread's task.
    #[cfg(target_os = "linux")]
    const LONGEST_WAIT: std::time::Duration = std::time::Duration::from_millis(200);

    /// The calling thread's task id (`/proc/thread-self` → `<pid>/task/<tid>`), Linux only.
    pub(crate) fn own_task() -> Option<std::ffi::OsString> {
        #[cfg(target_os = "linux")]
        {
            std::fs::read_link("/proc/thread-self")
                .ok()
                .and_then(|p| p.file_name().map(|f| f.to_owned()))
        }
        #[cfg(not(target_os = "linux"))]
        None
    }

    /// Waits until the joined thread's `task` has left `/proc/self/task` (at most
    /// [`LONGEST_WAIT`]: beyond it the thread's code has ended anyway).
    pub(crate) fn wait_until_gone(task: Option<std::ffi::OsString>) {
        #[cfg(target_os = "linux")]
        if let Some(task) = task {
            let path = std::path::Path::new("/proc/self/task").join(task);
            let start = std::time::Instant::now();
            let mut round = 0u32;
            while path.exists() && start.elapsed() < LONGEST_WAIT {
                // Hand the core to the exiting thread first, then sleep a little.
                if round < 16 {
                    std::thread::yield_now();
                } else {
                    std::thread::sleep(std::time::Duration::from_micros(50));
                }
                round += 1;
            }
        }
        #[cfg(not(target_os = "linux"))]
        let _ = task;
    }
}

#[cfg(test)]
mod thread_count_tests {
    use super::*;

    #[test]
    fn automatic_assembly_threads_are_one_below_the_threshold_and_within_the_cores_above() {
        let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
        assert_eq!(automatic_threads(PARALLEL_MIN_TRIANGLES - 1), 1);
        for triangles in [PARALLEL_MIN_TRIANGLES, 10 * PARALLEL_MIN_TRIANGLES] {
            let t = automatic_threads(triangles);
            assert!(
                (1..=cores).contains(&t),
                "{triangles} triangles: {t} threads"
            );
            assert!(t <= triangles / TRIANGLES_PER_THREAD);
        }
        assert!((1..=cores).contains(&idle_cores()));
    }
}
